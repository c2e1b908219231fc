"""The core options the baselines of ``missions/baselines/`` need, each changing the decision as
intended on a small constructed case: the nearest frontier instead of Eq. 3's utility, the
constant-velocity prediction instead of the SVR (§II-E) in the follower, and the trees of the
reactive, go-to-last-seen and oracle baselines on the real leaves."""

from __future__ import annotations

import math
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import numpy as np
import py_trees
import pytest
import shapely
import yaml
from py_trees.common import Access, Status
from shapely.geometry import LineString
from shapely.ops import unary_union

from pfctl.app.follower import build_follower, follower_params
from pfctl.core.behavior.blackboard import KEYS, Sighting, TargetState, new_namespace
from pfctl.core.behavior.leaves import (
    LEAF_CLASSES,
    PRIVILEGED_LEAVES,
    OracleSearch,
    WaypointSearch,
    leaf_factory,
)
from pfctl.core.behavior.tree import build_tree
from pfctl.core.behavior.world import WorldModel
from pfctl.core.control import ControlParams
from pfctl.core.mapping.frontiers import FrontierCluster
from pfctl.core.mapping.grid import OccupancyGrid
from pfctl.core.mapping.paths import distance_fields, traversability
from pfctl.core.mapping.planning import GridPlanner
from pfctl.core.mapping.regions import RegionMap, SearchParams, WaypointDecision, waypoint_search
from pfctl.core.perception.belief import visible_mask
from pfctl.core.perception.tracking import FieldOfView
from pfctl.core.perception.viewpoints import nearest_viewpoint
from pfctl.core.prediction.models import make_model
from pfctl.core.robot import Pose2D
from pfctl.core.search.whereabouts import Whereabouts
from pfctl.mission import load_mission
from tests.core.search.test_gaze import _walls as _three_room_walls
from tests.core.search.test_whereabouts import GEOMETRY as THREE_ROOMS_GRID
from tests.core.search.test_whereabouts import HOME as THREE_ROOMS
from tests.core.search.test_whereabouts import PARAMS as WHEREABOUTS

MISSIONS = Path(__file__).resolve().parents[3] / "missions"
BASELINES = MISSIONS / "baselines"
RES = 0.05
SEARCH = dict(alpha=0.05, beta=1.0, frontier_threshold=0.1, min_frontier_cells=5, window_s=3.0)


def _walk(start: tuple[float, float], end: tuple[float, float], seconds: float = 3.0):
    t = np.linspace(0.0, seconds, int(seconds * 10) + 1)
    return np.column_stack([t, np.linspace(start, end, len(t))])


# --------------------------------------------------------------------------------------------
# nearest frontier instead of Eq. 3
# --------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def house() -> tuple[RegionMap, OccupancyGrid]:
    """The house's region map, and a grid with every room seen but the office and the bedroom
    (walls on the region edges except the doors)."""
    layout = load_mission(MISSIONS / "house.yaml").layout()
    walls = unary_union([shapely.Polygon(r.polygon).boundary for r in layout.regions])
    doors = unary_union(
        [LineString(d.segment).buffer(0.06, cap_style="flat") for d in layout.doors]
    )
    walls = walls.buffer(0.05, cap_style="flat").difference(doors)
    rr, cc = np.mgrid[0 : round(9 / RES), 0 : round(12 / RES)]
    x, y = (cc + 0.5) * RES, (rr + 0.5) * RES
    p = np.zeros(x.shape)
    for name in ("office", "bedroom"):
        p[shapely.contains_xy(shapely.Polygon(layout.region(name).polygon), x, y)] = 0.5
    p[shapely.contains_xy(walls, x, y)] = 1.0
    return RegionMap(layout), OccupancyGrid.from_probabilities(p, RES)


def test_nearest_frontier_goes_to_the_closer_door_where_eq3_follows_the_heading(
    house: tuple[RegionMap, OccupancyGrid],
) -> None:
    rmap, grid = house
    robot = (6.0, 5.0)  # in the hall, nearer the office door (x 3.5-4.4) than the bedroom's
    to_bedroom = _walk((6.0, 5.5), (8.5, 5.5))  # the target walked east: l* is the bedroom
    utility = waypoint_search(grid, rmap, to_bedroom, robot, **SEARCH)
    nearest = waypoint_search(grid, rmap, to_bedroom, robot, **SEARCH, choice="nearest")
    assert utility.choice == "utility" and nearest.choice == "nearest"
    assert utility.heading_region == nearest.heading_region == "bedroom"
    assert utility.reason == nearest.reason == "frontier" and len(nearest.clusters) == 2
    assert utility.waypoint[0] > 9.0  # Eq. 3: toward l*
    assert 3.5 <= nearest.waypoint[0] <= 4.45  # nearest: the office door, l* or not
    # the nearest's goals are the clusters' points nearest the robot, scored by -d(x, c)
    states = grid.states()
    tr = traversability(states != 1, geometry=grid.geometry, known=states != -1)
    (from_x,) = distance_fields(tr, np.array([robot]))
    for cluster, goal, score in zip(
        nearest.clusters, nearest.goals, nearest.utilities, strict=True
    ):
        d = np.hypot(cluster.points[:, 0] - robot[0], cluster.points[:, 1] - robot[1])
        assert math.dist(goal, cluster.points[int(np.argmin(d))]) < 1e-9
        assert score == pytest.approx(-float(from_x(np.array([goal]))[0]))
    assert nearest.best == int(np.argmax(nearest.utilities))
    with pytest.raises(ValueError, match="unknown choice 'closest'"):
        waypoint_search(grid, rmap, to_bedroom, robot, **SEARCH, choice="closest")  # type: ignore[arg-type]


def test_waypoint_search_follows_a_visited_frontier_along_from_the_robot_when_nearest() -> None:
    """A visited frontier still there is followed along from its next point: the one nearest
    l* with Eq. 3, the one nearest the robot with the nearest-frontier choice."""
    points = np.column_stack([np.linspace(0.5, 2.7, 23), np.full(23, 7.8)])  # y = 7.8
    cluster = FrontierCluster(
        cells=np.zeros((len(points), 2), dtype=np.intp),
        points=points,
        centroid=(1.6, 7.8),
        n_unknown=len(points),
    )
    ns = new_namespace()
    writer = py_trees.blackboard.Client(name="test", namespace=ns)
    for key in ("pose", "t", "world"):
        writer.register_key(key, access=Access.WRITE)
    writer.pose = Pose2D(1.6, 7.4)  # below the middle of the frontier; l* at its east end
    writer.t = 0.0
    writer.world = SimpleNamespace(whereabouts=None)  # no belief: every frontier counts
    leaf = WaypointSearch("waypoint_search", ns, {"tolerance": 0.4})
    leaf.initialise()
    leaf._visited.append((1.6, 7.8))
    picked = {}
    for choice in ("utility", "nearest"):
        decision = WaypointDecision(
            waypoint=(1.6, 7.8),
            heading_region="office",
            target_region="office",
            target_point=(3.0, 7.5),
            reason="frontier",
            clusters=(cluster,),
            goals=((1.6, 7.8),),
            utilities=(1.0,),
            best=0,
            choice=choice,  # type: ignore[arg-type]
        )
        picked[choice] = leaf._unvisited(decision).waypoint
    assert picked["utility"] == pytest.approx((2.7, 7.8))  # the end nearest l*
    assert math.dist(picked["nearest"], (1.6, 7.8)) == pytest.approx(leaf.VISITED_RADIUS, abs=0.1)


def test_the_nearest_frontier_baselines_set_the_choice_for_the_follower() -> None:
    for base in ("house", "house_crowd"):
        mission = load_mission(BASELINES / f"{base}_nearest_frontier.yaml")
        assert follower_params(mission).search.waypoint_choice == "nearest"
        assert mission.behavior.tree == load_mission(MISSIONS / f"{base}.yaml").behavior.tree
    assert follower_params(load_mission(MISSIONS / "house.yaml")).search.waypoint_choice == (
        "utility"
    )


# --------------------------------------------------------------------------------------------
# constant-velocity prediction instead of the SVR
# --------------------------------------------------------------------------------------------


class _Idle:
    """A robot and a perception that are never asked for anything (the follower's prediction
    needs neither); close() and command() are called when the follower closes, and the
    camera's range is read when it is built."""

    camera_range = (0.4, 8.0)

    def command(self, *args: Any) -> None:
        pass

    def close(self) -> None:
        pass


def test_the_cv_baseline_predicts_at_constant_velocity_where_the_svr_bends() -> None:
    # In the living room: east at 0.5 m/s for 2 s, then north for 1 s; lost at t = 103.
    t1, t2 = np.arange(0.0, 2.0, 0.1), np.arange(2.0, 3.01, 0.1)
    xy = np.vstack(
        [
            np.column_stack([6.5 + 0.5 * t1, np.full_like(t1, 1.6)]),
            np.column_stack([np.full_like(t2, 7.5), 1.6 + 0.5 * (t2 - 2.0)]),
        ]
    )
    t = np.concatenate([t1, t2]) + 100.0
    seen = Sighting(float(t[-1]), (float(xy[-1, 0]), float(xy[-1, 1])), np.column_stack([t, xy]))
    paths = {}
    for name, path in (
        ("svr", MISSIONS / "house.yaml"),
        ("cv", BASELINES / "house_cv_prediction.yaml"),
    ):
        mission = load_mission(path)
        assert mission.prediction.model == name
        follower = build_follower(mission, _Idle(), _Idle())  # type: ignore[arg-type]
        try:
            state = follower._fit_prediction(seen.t + 0.1, seen)
        finally:
            follower.close()
        assert state is not None
        paths[name] = state.path
    # cv: the mean velocity over the last 0.8 s (due north), continued
    cv = make_model("cv").fit(t - t[0], xy).predict(seen.t + np.arange(1, 13) * 0.25 - t[0])
    assert np.allclose(paths["cv"][:4], cv[:4])
    assert np.allclose(paths["cv"][:, 0], 7.5)
    assert paths["svr"][-1, 0] > 7.55  # the SVR's end velocity still leans east
    assert not np.allclose(paths["svr"], paths["cv"], atol=0.05)


def test_the_prediction_goal_is_the_path_end_or_the_likely_rooms_doorway() -> None:
    # Up the hall toward the office door at 0.4 m/s, lost at t = 3 (the robot in the kitchen).
    t = np.linspace(0.0, 3.0, 31)
    path = np.column_stack([t, np.full_like(t, 3.9), 4.5 + 0.4 * t])
    seen = Sighting(3.0, (3.9, 5.7), path)
    goals = {}
    for goal in ("path", "room"):
        mission = load_mission(MISSIONS / "house.yaml")
        search = mission.search.model_copy(update={"strategy": "belief", "prediction_goal": goal})
        mission = mission.model_copy(update={"search": search})
        follower = build_follower(mission, _Idle(), _Idle())  # type: ignore[arg-type]
        try:
            follower.robot_pose = (2.5, 2.0)
            follower._lost(3.0, seen)
            state = follower._fit_prediction(3.1, seen)
        finally:
            follower.close()
        assert state is not None
        goals[goal] = state
    # path (the paper, whatever the way-point strategy): where her predicted path ends, on
    # past the office door into the office
    end = goals["path"]
    assert end.goal[1] > 6.0 and math.dist(end.goal, tuple(end.path[-1])) < 0.5
    # room: the office (the belief's first room), looked into from its doorway
    door = goals["room"]
    assert door.region == "office"
    assert math.dist(door.goal, (3.95, 6.0)) < 0.3
    assert math.dist(end.goal, door.goal) > 0.5


# --------------------------------------------------------------------------------------------
# the reactive and go-to-last-seen trees on the real leaves
# --------------------------------------------------------------------------------------------


class FakeIntents:
    """Intents that record what the leaves ask for; ``go_to`` answers ``nav``."""

    def __init__(self) -> None:
        self.control = ControlParams()
        self.nav = "running"
        self.calls: list[tuple[str, Any]] = []

    def claim(self, action: str) -> None:
        self.calls.append(("claim", action))

    def release(self) -> None:
        pass

    def follow(self, xy: tuple[float, float], distance: float | None = None) -> str:
        self.calls.append(("follow", xy))
        return "go_straight"

    def go_to(self, xy: tuple[float, float], tolerance: float) -> str:
        self.calls.append(("go_to", xy))
        return self.nav

    def stop(self) -> None:
        self.calls.append(("stop", None))

    def turn(self, wz: float) -> None:
        self.calls.append(("turn", wz))

    def set_pan(self, pan: float) -> None:
        self.calls.append(("pan", pan))

    def look_at(self, xy: tuple[float, float], source: str = "target") -> None:
        self.calls.append(("look_at", xy))

    def kinds(self) -> list[str]:
        out, self.calls = [c[0] for c in self.calls if c[0] != "claim"], []
        return out


class TreeRig:
    """A baseline's tree on the real leaves, the blackboard written as the follower does."""

    def __init__(self, tree_file: str) -> None:
        layout = yaml.safe_load((MISSIONS / "trees" / tree_file).read_text())
        self.ns = new_namespace()
        self.now = 0.0
        self.intents = FakeIntents()
        defaults = {"follow_target": {"distance": 1.0}, "oracle_search": {"range": 5.0}}
        self.root = build_tree(layout, leaf_factory(self.ns, defaults), lambda: self.now)
        self.root.setup_with_descendants()
        self.bb = py_trees.blackboard.Client(name="rig", namespace=self.ns)
        for key in KEYS:
            self.bb.register_key(key, access=Access.WRITE)
        # no belief over where she can be is kept here: a look-around sweeps its full length
        self.bb.world = SimpleNamespace(unseen_in_sight=lambda t, pose: None)

    def tick(
        self,
        now: float,
        target: TargetState | None = None,
        seen: Sighting | None = None,
        pose: Pose2D | None = None,
    ) -> tuple[Status, str | None]:
        self.now = now
        self.bb.t, self.bb.target = now, target
        self.bb.pose = pose if pose is not None else Pose2D(0.0, 0.0)
        self.bb.last_seen, self.bb.prediction, self.bb.intents = seen, None, self.intents
        self.root.tick_once()
        tip = self.root.tip()
        return self.root.status, tip.name if tip is not None else None


def _target(now: float) -> TargetState:
    return TargetState(1, 2.0, 1.0, 0.0, 0.0, now)


@pytest.mark.sim
def test_the_reactive_tree_follows_and_otherwise_only_stops() -> None:
    rig = TreeRig("reactive.yaml")
    assert rig.tick(0.0, _target(0.0)) == (Status.RUNNING, "follow_target")
    assert rig.intents.kinds() == ["follow"]
    seen = Sighting(0.0, (2.0, 1.0), np.array([[0.0, 2.0, 1.0]]))
    for k in range(1, 30):  # lost: stop, every tick, and nothing else
        assert rig.tick(k * 0.1, None, seen) == (Status.SUCCESS, "stop")
        assert rig.intents.kinds() == ["stop"]
    assert rig.tick(3.0, _target(3.0), seen) == (Status.RUNNING, "follow_target")


def test_the_last_seen_tree_drives_there_then_looks_around_and_keeps_its_arrival() -> None:
    rig = TreeRig("last_seen.yaml")
    seen = Sighting(0.0, (2.0, 1.0), np.array([[0.0, 2.0, 1.0]]))
    assert rig.tick(0.0, _target(0.0)) == (Status.RUNNING, "follow_target")
    rig.intents.kinds()
    # lost: RUNNING while driving to the last seen place
    assert rig.tick(1.0, None, seen) == (Status.RUNNING, "go_to_last_seen")
    assert rig.intents.calls[-1] == ("go_to", (2.0, 1.0)) and rig.intents.kinds() == ["go_to"]
    rig.intents.nav = "arrived"
    # arrival: go_to_last_seen succeeds and look_around sweeps the head and turns the base
    assert rig.tick(1.1, None, seen) == (Status.RUNNING, "look_around")
    assert rig.intents.kinds() == ["go_to", "pan", "turn"]
    # drifting off the place while turning does not send the robot back: the arrival holds
    rig.intents.nav = "running"
    for k in range(2, 100):
        status, tip = rig.tick(1.0 + k * 0.1, None, seen)
        if tip != "look_around":
            break
    assert "go_to" not in rig.intents.kinds()
    # the 8 s sweep ended without the target: one tick of stop, then looking again
    assert (status, tip) == (Status.SUCCESS, "stop") and rig.now == pytest.approx(9.1)
    assert rig.tick(9.2, None, seen) == (Status.RUNNING, "look_around")
    # a place that cannot be reached: failure, held for that sighting: stop, no re-planning
    other = Sighting(5.0, (9.0, 9.0), np.array([[5.0, 9.0, 9.0]]))
    rig.intents.nav = "failed"
    assert rig.tick(10.0, None, other) == (Status.SUCCESS, "stop")
    assert rig.tick(10.1, None, other) == (Status.SUCCESS, "stop")
    assert rig.intents.kinds().count("go_to") == 1
    # seen again: follow
    assert rig.tick(11.0, _target(11.0), other) == (Status.RUNNING, "follow_target")


def _world_of_three_rooms(lost_at: tuple[float, float]) -> WorldModel:
    """The search tests' corridor with three rooms off it (``tests/core/search``), its walls
    blocking the camera, and a belief over where she can be since she was lost at ``lost_at``
    20 s before t = 0 (she can be in any room by now)."""
    walls = _three_room_walls()
    wb = Whereabouts(RegionMap(THREE_ROOMS), THREE_ROOMS_GRID, ~walls, WHEREABOUTS)
    wb.lost(-20.0, lost_at)
    grid = OccupancyGrid.from_probabilities(walls.astype(float), THREE_ROOMS_GRID.resolution)
    return WorldModel(
        grid,
        GridPlanner(grid, 0.2),
        RegionMap(THREE_ROOMS),
        SearchParams(),
        wb,
        sight_blocked=walls,
        camera_range=(0.4, 8.0),
    )


#: Where the look-around tests stand (the mid room's door) and the sighting that sent them there.
MID_DOOR = Pose2D(4.5, 1.0, 0.0)
MID_DOOR_SEEN = Sighting(0.0, (4.5, 1.0), np.array([[0.0, 4.5, 1.0]]))


def _looking_round_at_the_mid_door() -> tuple[TreeRig, WorldModel]:
    """The last-seen tree, arrived at ``MID_DOOR`` (where she was last seen), in the world of
    :func:`_world_of_three_rooms`."""
    rig = TreeRig("last_seen.yaml")
    world = _world_of_three_rooms((MID_DOOR.x, MID_DOOR.y))
    rig.bb.world = world
    rig.intents.nav = "arrived"
    return rig, world


def test_a_look_around_ends_once_every_place_in_sight_has_been_seen() -> None:
    """At the mid room's door: once the camera has seen all it can from there (the corridor
    and the mid room through the door), the sweep ends — after ``min_seconds``, not 8 s —
    and the tree moves on; the rooms behind the walls are not in sight and do not hold it."""
    rig, world = _looking_round_at_the_mid_door()
    assert rig.tick(0.1, None, MID_DOOR_SEEN, MID_DOOR) == (Status.RUNNING, "look_around")
    unseen = world.unseen_in_sight(0.1, MID_DOOR)
    assert unseen is not None and unseen > 10.0  # nothing seen yet: corridor and mid room
    all_round = FieldOfView(MID_DOOR, math.pi, 0.4, 8.0)
    world.whereabouts.observe(0.5, visible_mask(THREE_ROOMS_GRID, all_round, world.sight_blocked))
    assert world.unseen_in_sight(0.5, MID_DOOR) == 0.0
    # within min_seconds it sweeps on; after, it has looked: on with the tree
    assert rig.tick(0.6, None, MID_DOOR_SEEN, MID_DOOR) == (Status.RUNNING, "look_around")
    assert rig.tick(1.2, None, MID_DOOR_SEEN, MID_DOOR) == (Status.SUCCESS, "stop")


def test_a_look_around_with_places_in_sight_unseen_sweeps_on() -> None:
    """The same, but the camera has seen only the corridor: the mid room, in sight through its
    door, is not seen yet, so the sweep goes on."""
    rig, world = _looking_round_at_the_mid_door()
    corridor = world.whereabouts.labels == world.regions.names.index("corridor")
    world.whereabouts.observe(0.05, corridor)
    for k in range(1, 60):
        assert rig.tick(k * 0.1, None, MID_DOOR_SEEN, MID_DOOR) == (Status.RUNNING, "look_around")


# --------------------------------------------------------------------------------------------
# the oracle (privileged) on the real leaf
# --------------------------------------------------------------------------------------------


def _two_rooms() -> GridPlanner:
    """8 m × 4 m, walled round, a wall at x = 4 m with a 1 m door at y 0.5–1.5 m."""
    p = np.zeros((round(4 / RES), round(8 / RES)))
    p[:2, :] = p[-2:, :] = p[:, :2] = p[:, -2:] = 1.0
    p[:, 79:81] = 1.0
    p[10:30, 79:81] = 0.0
    return GridPlanner(OccupancyGrid.from_probabilities(p, RES), 0.2)


def test_only_the_oracle_leaf_reads_the_truth() -> None:
    readers = [c for c in LEAF_CLASSES.values() if "true_target" in c.reads]
    assert readers == [OracleSearch] and OracleSearch.spec.name in PRIVILEGED_LEAVES
    assert "PRIVILEGED" in OracleSearch.spec.doc


def test_the_oracle_drives_to_the_nearest_place_that_sees_her_and_replans_as_she_walks() -> None:
    rig = TreeRig("oracle.yaml")
    planner = _two_rooms()
    rig.bb.world = SimpleNamespace(planner=planner)
    here = Pose2D(1.0, 3.0)
    assert rig.tick(0.0, _target(0.0), pose=here) == (Status.RUNNING, "follow_target")
    rig.intents.kinds()
    seen = Sighting(0.0, (2.0, 1.0), np.array([[0.0, 2.0, 1.0]]))
    # no truth (the app gives none): the oracle fails, nothing is driven
    rig.bb.true_target = None
    assert rig.tick(0.5, None, seen, here) == (Status.FAILURE, "oracle_search")
    assert "go_to" not in rig.intents.kinds()
    # the truth: she is in the east room; the goal is the nearest place with her in sight
    her = (6.0, 3.0)
    rig.bb.true_target = her
    assert rig.tick(1.0, None, seen, here) == (Status.RUNNING, "oracle_search")
    want = nearest_viewpoint(planner, (here.x, here.y), her, 5.0, 0.6, 0.25)
    assert want is not None and ("go_to", want.xy) in rig.intents.calls
    assert ("look_at", her) in rig.intents.calls
    rig.intents.kinds()
    # she walks on: the place is kept for a second, then re-planned (head on her at once)
    rig.bb.true_target = (7.0, 1.0)
    rig.tick(1.5, None, seen, here)
    assert ("go_to", want.xy) in rig.intents.calls and ("look_at", (7.0, 1.0)) in rig.intents.calls
    rig.intents.kinds()
    rig.tick(2.1, None, seen, here)
    again = nearest_viewpoint(planner, (here.x, here.y), (7.0, 1.0), 5.0, 0.6, 0.25)
    assert again is not None and again.xy != want.xy and ("go_to", again.xy) in rig.intents.calls
    # seen: follow again
    assert rig.tick(3.0, _target(3.0), seen, here) == (Status.RUNNING, "follow_target")


def test_the_oracle_asks_for_a_clearer_sight_when_she_stays_unseen_at_the_place() -> None:
    """A line that just clears a jamb shows the camera too little of her: after ``settle`` s
    at the place without seeing her, the place is chosen again with 0.25 m more clearance."""
    rig = TreeRig("oracle.yaml")
    planner = _two_rooms()
    rig.bb.world = SimpleNamespace(planner=planner)
    here = Pose2D(1.0, 3.0)
    rig.tick(0.0, _target(0.0), pose=here)
    seen = Sighting(0.0, (2.0, 1.0), np.array([[0.0, 2.0, 1.0]]))
    her = (6.0, 3.0)
    rig.bb.true_target = her
    assert rig.tick(1.0, None, seen, here) == (Status.RUNNING, "oracle_search")
    first = nearest_viewpoint(planner, (here.x, here.y), her, 5.0, 0.6, 0.25)
    clearer = nearest_viewpoint(planner, (here.x, here.y), her, 5.0, 0.6, 0.5)
    assert first is not None and clearer is not None and clearer.xy != first.xy
    rig.intents.nav = "arrived"  # at the place, and still she is not detected
    for now in (1.2, 2.2, 3.1):  # less than settle (2 s) since the arrival at 1.2 s
        rig.tick(now, None, seen, here)
    assert {xy for kind, xy in rig.intents.calls if kind == "go_to"} == {first.xy}
    rig.intents.kinds()
    rig.tick(3.2, None, seen, here)  # 2 s at the place: ask for more clearance
    rig.tick(3.3, None, seen, here)
    assert ("go_to", clearer.xy) in rig.intents.calls
