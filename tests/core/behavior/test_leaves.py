"""The behavior tree's search leaves on the real follower and the simulated house (no people,
no camera): go to the prediction and look there, way-point search (Algorithm 1), stop, and the
follower's close."""

from __future__ import annotations

import itertools
import math
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import numpy as np
import py_trees
import pytest
from py_trees.common import Access, Status

from pfctl.app.follower import build_follower
from pfctl.app.perception import build_perception
from pfctl.app.sim import sim_config
from pfctl.backends.pybullet.simulation import SimOptions, SimRobot
from pfctl.core.behavior.blackboard import (
    PredictionState,
    Sighting,
    TargetState,
    new_namespace,
)
from pfctl.core.behavior.intents import Intents, LookAt, Stop
from pfctl.core.behavior.leaves import LookAround, WaypointSearch
from pfctl.core.control import ControlParams
from pfctl.core.episode import TickRecord
from pfctl.core.follower import Follower
from pfctl.core.mapping.frontiers import FrontierCluster
from pfctl.core.mapping.regions import WaypointDecision
from pfctl.core.robot import STOP, Pose2D, Twist2D
from pfctl.core.search.next_look import STEP_IN
from pfctl.mission import Mission, load_mission

pytestmark = pytest.mark.sim

HOUSE = Path(__file__).resolve().parents[3] / "missions" / "house.yaml"


@pytest.fixture(scope="module")
def empty_house() -> Mission:
    mission = load_mission(HOUSE)
    return mission.model_copy(
        update={"scenario": mission.scenario.model_copy(update={"people": ()})}
    )


def _follower(mission: Mission, robot: SimRobot, tree: dict[str, Any]) -> Follower:
    behavior = type(mission.behavior).model_validate(
        {**mission.behavior.model_dump(exclude_none=True), "tree": tree}
    )
    m = mission.model_copy(update={"behavior": behavior})
    return build_follower(m, robot, build_perception(m))


def _run(follower: Follower, robot: SimRobot, seconds: float) -> list[TickRecord]:
    records = []
    end = robot.time + seconds
    while robot.time < end - 1e-9:
        records.append(follower.tick())
        robot.step()
    return records


PREDICT_AND_LOOK = {
    "sequence": {
        "name": "predict_and_look",
        "children": [
            {"condition": "prediction_available"},
            {"action": "go_to_prediction"},
            {"action": "look_around", "params": {"seconds": 3.0}},
        ],
    }
}


def test_go_to_the_prediction_then_look_around_then_the_prediction_is_used(
    empty_house: Mission,
) -> None:
    with SimRobot(sim_config(empty_house), SimOptions(camera=False)) as robot:
        follower = _follower(empty_house, robot, PREDICT_AND_LOOK)
        goal = (2.0, 5.0)  # in the hall, from the kitchen through its door
        prediction = PredictionState(0.0, (2.5, 3.5), np.array([goal]), goal, "hall")
        follower._prediction = prediction
        records = _run(follower, robot, 25.0)
        follower.close()
    actions = [r.action for r in records]
    going = [r for r in records if r.action == "go_to_prediction"]
    looking = [r for r in records if r.action == "look_around"]
    # it drives there with MOVE_BASE (RUNNING all the way), arrives, then looks around
    assert going and all(r.awareness == "predicted" for r in going)
    assert sum(r.base_mode == "move_base" for r in going) > 0.8 * len(going)
    assert actions.index("look_around") > actions.index("go_to_prediction")
    start_look = looking[0].pose
    assert math.dist((start_look.x, start_look.y), goal) <= 0.5 + 0.1
    # the look: the base turns in place, the head sweeps, for the leaf's 3 s
    # (its last tick is the one that gives up: the base stops there)
    assert {r.base_mode for r in looking[:-1]} == {"turn"} and looking[-1].base_mode == "stop"
    assert {r.gaze for r in looking[:-1]} == {"sweep"}
    assert looking[-1].t - looking[0].t == pytest.approx(3.0, abs=0.25)
    assert math.dist((looking[-1].pose.x, looking[-1].pose.y), (start_look.x, start_look.y)) < 0.1
    # then the prediction is used up: the sequence fails and nothing drives the base
    assert prediction.reached and prediction.used and not prediction.available
    after = records[records.index(looking[-1]) + 1 :]
    assert after and all(r.action is None and r.base_mode == "stop" for r in after)


def test_a_prediction_off_the_map_fails_at_once_and_is_used_up(empty_house: Mission) -> None:
    with SimRobot(sim_config(empty_house), SimOptions(camera=False)) as robot:
        follower = _follower(empty_house, robot, PREDICT_AND_LOOK)
        goal = (20.0, 20.0)  # outside the house: no free cell near it
        prediction = PredictionState(0.0, (2.5, 3.5), np.array([goal]), goal, None)
        follower._prediction = prediction
        records = _run(follower, robot, 1.0)
        follower.close()
    assert prediction.used and not prediction.reached
    assert records[0].action == "go_to_prediction"  # tried once, failed on the same tick
    assert all(r.action is None and r.base_mode == "stop" for r in records[1:])
    assert robot.commanded == STOP


def test_waypoint_search_explores_toward_the_heading_region(empty_house: Mission) -> None:
    tree = {"action": "waypoint_search"}
    with SimRobot(sim_config(empty_house), SimOptions(camera=False)) as robot:
        follower = _follower(empty_house, robot, tree)
        # the target was last seen walking up the hall toward the office door
        t = np.linspace(0.0, 3.0, 31)
        path = np.column_stack([t, np.full_like(t, 3.9), 4.5 + 0.4 * t])
        follower._last_seen = Sighting(3.0, (3.9, 5.7), path)
        known_before = int(np.count_nonzero(follower.grid.states() != -1))
        records = _run(follower, robot, 20.0)
        known_after = int(np.count_nonzero(follower.grid.states() != -1))
        follower.close()
    assert all(r.action == "waypoint_search" and r.awareness == "searching" for r in records)
    waypoints = follower.log.waypoints
    # the first decision, before any scan, has no frontier yet: it heads for l* itself
    assert waypoints[0].reason == "no_frontier_fallback"
    assert any(w.reason == "frontier" for w in waypoints)
    assert {w.heading_region for w in waypoints} == {"office"}
    # it drove (MOVE_BASE) and the map filled in as it went
    path_len = sum(
        math.dist((a.pose.x, a.pose.y), (b.pose.x, b.pose.y))
        for a, b in itertools.pairwise(records)
    )
    assert path_len > 2.0 and known_after > known_before
    assert sum(r.base_mode == "move_base" for r in records) > len(records) / 2
    end = records[-1].pose
    assert follower.regions.locate((end.x, end.y)) in {"hall", "office"}


def _with_strategy(mission: Mission, strategy: str) -> Mission:
    search = mission.search.model_copy(update={"strategy": strategy})
    return mission.model_copy(update={"search": search})


def _lost_walking_to_the_office(follower: Follower) -> None:
    """The target was last seen at t = 0 walking up the hall toward the office door."""
    t = np.linspace(-3.0, 0.0, 31)
    path = np.column_stack([t, np.full_like(t, 3.9), 5.7 + 0.4 * t])
    seen = Sighting(0.0, (3.9, 5.7), path)
    follower._last_seen = seen
    follower._lost(0.0, seen)


def test_belief_search_looks_into_the_likely_room_from_its_doorway(empty_house: Mission) -> None:
    tree = {"action": "waypoint_search"}
    mission = _with_strategy(empty_house, "belief")
    with SimRobot(sim_config(mission), SimOptions(camera=False)) as robot:
        follower = _follower(mission, robot, tree)
        _lost_walking_to_the_office(follower)
        assert follower.log.room_predictions[-1].ranked[0] == "office"
        assert follower.log.room_predictions[-1].heading == "office"
        records = _run(follower, robot, 30.0)
        follower.close()
    assert all(r.action == "waypoint_search" and r.awareness == "searching" for r in records)
    # from the kitchen it looks into the hall from its door (she was there at the loss), then
    # drives to the office doorway and stands there sweeping the head: no tour of other rooms
    office_door = (3.95, 6.0)
    goals = [r.goal for r in records if r.goal is not None]
    assert any(math.dist(g, office_door) < 0.3 + STEP_IN for g in goals)  # a step in
    looks = [r for r in records if r.base_mode != "move_base"]
    assert sum(r.gaze == "sweep" for r in looks) >= len(looks) - 3  # a look's last tick: none
    assert any(math.dist((r.pose.x, r.pose.y), office_door) < 0.6 + STEP_IN for r in looks)
    rooms = {follower.regions.locate((r.pose.x, r.pose.y)) for r in records}
    assert rooms <= {"kitchen", "hall", "office"}
    assert follower.log.waypoints == []  # Algorithm 1 was not needed


def test_the_paper_strategy_keeps_algorithm_1(empty_house: Mission) -> None:
    mission = _with_strategy(empty_house, "paper")
    with SimRobot(sim_config(mission), SimOptions(camera=False)) as robot:
        follower = _follower(mission, robot, {"action": "waypoint_search"})
        _lost_walking_to_the_office(follower)
        _run(follower, robot, 5.0)
        follower.close()
    waypoints = follower.log.waypoints
    assert waypoints and {w.heading_region for w in waypoints} == {"office"}


def _never_seen(mission: Mission, strategy: str) -> Mission:
    """``mission`` with the strategy for a target not seen yet (the lost one's stays paper)."""
    search = mission.search.model_copy(
        update={"strategy": "paper", "never_seen_strategy": strategy}
    )
    return mission.model_copy(update={"search": search})


@pytest.mark.parametrize("strategy", ["belief", "paper"])
def test_a_target_never_seen_is_searched_for_by_never_seen_strategy(
    empty_house: Mission, strategy: str
) -> None:
    """pfctl search's case: nobody seen yet. With ``belief`` the robot drives to a room's
    doorway and sweeps the head over rooms, Algorithm 1 unused; with ``paper`` it goes by
    Algorithm 1's frontiers."""
    mission = _never_seen(empty_house, strategy)
    with SimRobot(sim_config(mission), SimOptions(camera=False)) as robot:
        follower = _follower(mission, robot, {"action": "waypoint_search"})
        records = _run(follower, robot, 20.0)
        follower.close()
    assert all(r.action == "waypoint_search" for r in records)
    if strategy == "paper":
        assert follower.log.waypoints
        return
    assert follower.log.waypoints == []
    doors = [
        (0.5 * (d.segment[0][0] + d.segment[1][0]), 0.5 * (d.segment[0][1] + d.segment[1][1]))
        for d in mission.layout().doors
    ]
    goals = [r.goal for r in records if r.goal is not None]
    assert any(min(math.dist(g, d) for d in doors) < 0.3 + STEP_IN for g in goals)
    assert any(r.gaze == "sweep" for r in records)


def _leaf_with_pose(pose: Pose2D) -> WaypointSearch:
    namespace = new_namespace()
    writer = py_trees.blackboard.Client(name="test", namespace=namespace)
    for key in ("pose", "t", "world"):
        writer.register_key(key, access=Access.WRITE)
    writer.pose, writer.t = pose, 0.0
    writer.world = SimpleNamespace(whereabouts=None)  # no belief: every frontier counts
    leaf = WaypointSearch("waypoint_search", namespace, {"tolerance": 0.4})
    leaf.initialise()
    return leaf


def _decision(points: np.ndarray, target: tuple[float, float]) -> WaypointDecision:
    cluster = FrontierCluster(
        cells=np.zeros((len(points), 2), dtype=np.intp),
        points=points,
        centroid=(float(points[:, 0].mean()), float(points[:, 1].mean())),
        n_unknown=len(points),
    )
    i = int(np.argmin(np.hypot(points[:, 0] - target[0], points[:, 1] - target[1])))
    goal = (float(points[i, 0]), float(points[i, 1]))
    return WaypointDecision(
        waypoint=goal,
        heading_region="office",
        target_region="office",
        target_point=target,
        reason="frontier",
        clusters=(cluster,),
        goals=(goal,),
        utilities=(1.0,),
        best=0,
    )


def test_a_visited_frontier_still_there_is_followed_along_not_dropped() -> None:
    # a frontier along y = 7.8 from x = 0.5 to 2.7 (behind a bookshelf), l* at (3, 7.5)
    points = np.column_stack([np.linspace(0.5, 2.7, 23), np.full(23, 7.8)])
    leaf = _leaf_with_pose(Pose2D(3.2, 7.6))
    fresh = leaf._unvisited(_decision(points, (3.0, 7.5)))
    assert fresh.waypoint == pytest.approx((2.7, 7.8))  # its point nearest l*
    leaf._visited.append(fresh.waypoint)
    along = leaf._unvisited(_decision(points, (3.0, 7.5)))
    assert along.reason == "frontier"
    assert math.dist(along.waypoint, fresh.waypoint) >= leaf.VISITED_RADIUS
    assert along.waypoint[0] < 2.7 - leaf.VISITED_RADIUS + 0.051  # the next point along
    # every point visited: the cluster is out, and the way-point is l*'s point
    leaf._visited.extend([(0.5, 7.8), (1.3, 7.8), (2.0, 7.8)])
    done = leaf._unvisited(_decision(points, (3.0, 7.5)))
    assert done.reason == "visited_fallback" and done.waypoint == (3.0, 7.5)


@pytest.mark.parametrize(
    ("leaf_class", "params"),
    [
        (LookAround, {"seconds": 8.0, "pan": 1.4, "turn": True}),
        (WaypointSearch, {"tolerance": 0.4}),
    ],
)
def test_a_target_named_during_a_search_is_looked_back_at(
    leaf_class: type[LookAround | WaypointSearch], params: dict[str, Any]
) -> None:
    """Seed 6 of the randomized house: the sweep showed her at 33.8 s, her face named her on
    that frame, and the sweep turned on, so she was lost again. Named during the search but
    not detected lately, she is looked back at with the base stopped; a track coasting since
    before the search began is not."""
    namespace = new_namespace()
    writer = py_trees.blackboard.Client(name="test", namespace=namespace)
    for key in ("t", "target", "intents"):
        writer.register_key(key, access=Access.WRITE)
    intents = Intents(ControlParams(), None)  # type: ignore[arg-type]  # stop, look_at only
    writer.t, writer.target, writer.intents = 10.0, None, intents
    leaf = leaf_class(leaf_class.spec.name, namespace, params)
    leaf.initialise()  # the search begins at 10 s
    writer.t = 11.0
    writer.target = TargetState(7, 2.0, 3.0, 0.0, 0.0, last_detected=10.2)
    intents.begin(11.0, Pose2D(0.0, 0.0))
    assert leaf.act() is Status.RUNNING
    assert intents.base == Stop() and intents.base_mode == "stop"
    assert intents.head == [LookAt((2.0, 3.0), "target")]
    writer.target = TargetState(7, 2.0, 3.0, 0.0, 0.0, last_detected=9.5)
    intents.begin(11.0, Pose2D(0.0, 0.0))
    assert not leaf.hold_on_target(10.0)
    assert intents.base is None and intents.head == []


def test_stop_leaf_succeeds_and_close_stops_the_base_twice_safely(empty_house: Mission) -> None:
    with SimRobot(sim_config(empty_house), SimOptions(camera=False)) as robot:
        follower = _follower(empty_house, robot, {"action": "stop"})
        robot.command(Twist2D(0.3, 0.0, 0.0))  # moving when the tree takes over
        records = _run(follower, robot, 0.5)
        assert follower.root.status is Status.SUCCESS
        assert all(r.action == "stop" and r.base_mode == "stop" for r in records)
        assert robot.commanded == STOP
        follower.close()
        follower.close()
        assert robot.commanded == STOP
