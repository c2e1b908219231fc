"""Kinematic people: routes through doors at their speed, leg patterns, pauses, determinism."""

from __future__ import annotations

import numpy as np
import pytest
import shapely

from pfctl.app.sim import sim_config
from pfctl.backends.pybullet.config import Clothes
from pfctl.backends.pybullet.simulation import PERSON_CONTACT_RADIUS, PERSON_COURTESY
from pfctl.backends.pybullet.walkers import (
    ATTEND_S,
    HEARING_RANGE,
    LEG_RADIUS,
    PERSON_RADIUS,
    REACTION_S,
    STEP_ROUND_AFTER,
    TURN_RATE,
    Earshot,
    Walker,
    make_walkers,
)
from pfctl.core.mapping.planning import GridPlanner
from pfctl.core.mapping.walls import wall_footprint
from pfctl.mission import Mission, ScenarioConfig

pytestmark = pytest.mark.sim

DT = 0.05


def _make_walkers(mission: Mission, planner: GridPlanner, seed: int) -> list[Walker]:
    return make_walkers(sim_config(mission).scenario, mission.layout(), planner, seed)


def _run(mission: Mission, planner: GridPlanner, seed: int, seconds: float) -> dict:
    walkers = _make_walkers(mission, planner, seed)
    log: dict[str, list] = {w.name: [] for w in walkers}
    for _ in range(int(seconds / DT)):
        for w in walkers:
            w.step(DT)
            s = w.state
            log[w.name].append((s.x, s.y, s.theta, s.speed, *s.legs.ravel(), s.paused))
    return {k: np.array(v) for k, v in log.items()}


def test_walkers_follow_routes_through_doors_at_their_speed(
    mission: Mission, planner: GridPlanner
) -> None:
    log = _run(mission, planner, seed=3, seconds=60.0)
    layout = mission.layout()
    walls = wall_footprint(layout, mission.map.wall_thickness)
    regions = {r.name: shapely.Polygon(r.polygon) for r in layout.regions}
    people = {p.name: p for p in mission.scenario.people}
    walkers = {w.name: w for w in _make_walkers(mission, planner, 3)}
    assert walkers["alice"].is_target and not walkers["bob"].is_target
    for name, rows in log.items():
        xy = rows[:, :2]
        # never inside a wall: the body centre keeps a person's radius from every wall
        assert shapely.distance(walls, shapely.points(xy)).min() > PERSON_RADIUS - 0.06
        # starts in the first region, visits every stop, ends in the last one (no loop)
        # (a stop is a region's name or a point, reached within 0.3 m)
        route = [
            regions[s] if isinstance(s, str) else shapely.Point(s).buffer(0.3)
            for s in people[name].route
        ]
        for stop in route:
            assert shapely.contains_xy(stop, xy[:, 0], xy[:, 1]).any()
        assert route[0].contains(shapely.Point(xy[0]))
        assert route[-1].contains(shapely.Point(xy[-1]))
        # speed: cruises at the mission's speed, never faster; real displacement matches
        speed = rows[:, 3]
        assert speed.max() == pytest.approx(people[name].speed, abs=1e-9)
        step = np.linalg.norm(np.diff(xy, axis=0), axis=1) / DT
        assert step.max() <= people[name].speed + 1e-6
        assert (speed[speed > 0] > 0.9 * people[name].speed).mean() > 0.5
        # pauses at the intermediate stop, and stands at the end
        assert rows[-1, -1] == 1.0 and rows[-1, 3] == 0.0
    # alice: kitchen -> hall -> office, through the kitchen-hall door and the office's door
    a = log["alice"][:, :2]
    for y_wall, (x0, x1) in ((4.0, (2.0, 2.9)), (6.0, (3.5, 4.4))):
        k = np.flatnonzero(np.diff(np.sign(a[:, 1] - y_wall)) != 0)
        assert len(k) == 1 and x0 < a[k[0], 0] < x1


def test_legs_swing_while_walking_and_stand_together_when_paused(
    mission: Mission, planner: GridPlanner
) -> None:
    rows = _run(mission, planner, seed=3, seconds=60.0)["alice"]
    legs = rows[:, 4:10].reshape(-1, 2, 3)
    assert np.all(legs[:, :, 2] == LEG_RADIUS)
    gap = np.linalg.norm(legs[:, 0, :2] - legs[:, 1, :2], axis=1)
    walking = rows[:, 3] > 0.5
    assert walking.sum() > 100
    assert gap[walking].min() >= 0.1 and gap[walking].max() <= 0.4
    assert gap[walking].max() - gap[walking].min() > 0.08  # they really swing
    # the legs are on either side of the body centre
    centre = legs[:, :, :2].mean(axis=1)
    assert np.linalg.norm(centre - rows[:, :2], axis=1).max() < 1e-9
    still = rows[:, -1] == 1.0
    assert still.sum() > 20
    assert np.allclose(gap[still][-10:], 0.2, atol=0.01)


def test_same_seed_same_trajectories_other_seed_differs(
    mission: Mission, planner: GridPlanner
) -> None:
    a = _run(mission, planner, seed=11, seconds=20.0)
    b = _run(mission, planner, seed=11, seconds=20.0)
    c = _run(mission, planner, seed=12, seconds=20.0)
    assert all(np.array_equal(a[k], b[k]) for k in a)
    assert any(not np.array_equal(a[k], c[k]) for k in a)


def test_look_alike_loop_and_random_people(mission: Mission, planner: GridPlanner) -> None:
    people = [p.model_dump() for p in mission.scenario.people]
    people[1]["loop"] = True
    people[2]["clothes"] = people[0]["clothes"]  # carol dressed like the target
    scenario = {**mission.scenario.model_dump(), "people": people, "random_people": 2}
    m = mission.model_copy(update={"scenario": ScenarioConfig.model_validate(scenario)})
    walkers = _make_walkers(m, planner, seed=5)
    names = [w.name for w in walkers]
    assert names[-2:] == ["walker_0", "walker_1"] and len(walkers) == 5
    target = next(w for w in walkers if w.is_target)
    look_alikes = [w for w in walkers if w.clothes == target.clothes and w is not target]
    assert look_alikes
    bob = walkers[1]
    for _ in range(int(150 / DT)):
        bob.step(DT)
    assert not bob.done  # a looping person keeps walking
    again = _make_walkers(m, planner, seed=5)
    assert [w.clothes for w in again] == [w.clothes for w in walkers]


#: How near the simulator lets a person come to the robot's centre (its radius, a body, courtesy).
CLEAR = 0.215 + PERSON_CONTACT_RADIUS + PERSON_COURTESY


def _walk_past_a_robot(planner: GridPlanner, start, end, robot_xy, seconds: float) -> np.ndarray:
    """A person walks ``start`` → ``end`` while a robot stands still at ``robot_xy``."""
    walker = Walker(
        "p",
        [np.array(start), np.array(end)],
        planner.with_radius(PERSON_RADIUS),
        speed=0.8,
        clothes=Clothes((0, 0, 0), (0, 0, 0)),
    )
    track = []
    for _ in range(int(seconds / DT)):
        walker.step(DT, keep_clear=(*robot_xy, CLEAR))
        track.append((walker.x, walker.y))
        if walker.done:
            break
    return np.array(track)


def test_a_person_steps_round_a_robot_standing_in_the_hall_but_waits_in_a_door(
    planner: GridPlanner,
) -> None:
    """Along the hall (y = 5 m) a robot stands on the person's way: the person waits a little
    (STEP_ROUND_AFTER), then walks round it, never within the courtesy distance, and arrives.
    A robot standing in the kitchen's door to the hall leaves no room: the person waits."""
    hall = _walk_past_a_robot(planner, (1.0, 5.0), (8.0, 5.0), (4.0, 5.0), 30.0)
    assert np.linalg.norm(hall[-1] - (8.0, 5.0)) < 1e-6  # arrived
    gap = np.linalg.norm(hall - (4.0, 5.0), axis=1)
    assert gap.min() >= CLEAR - 0.05
    still = np.linalg.norm(np.diff(hall, axis=0), axis=1) < 1e-9
    assert DT * still.sum() >= STEP_ROUND_AFTER - DT  # it did wait first
    door = _walk_past_a_robot(planner, (1.5, 3.2), (2.5, 5.0), (2.3, 4.0), 30.0)
    assert np.linalg.norm(door - (2.3, 4.0), axis=1).min() >= CLEAR - 0.05
    assert np.linalg.norm(door[-1] - (2.5, 5.0)) > 1.0  # never got through


@pytest.mark.parametrize("robot_x", [4.4, 4.5])
def test_a_person_whose_stop_the_robot_stands_on_stops_short_and_walks_on(
    planner: GridPlanner, robot_x: float
) -> None:
    """A person walks along the hall to a stop at (4, 5) and back; a robot stands just past the
    stop, so the stop itself is within the distance the person keeps from it. The person stops
    short of it (at once when a few centimetres short, else after waiting STEP_ROUND_AFTER), and
    walks back, never within the courtesy distance (traced, the house, seed 46: a person stood
    1.5 cm from their stop, by the robot, until the robot gave way)."""
    walker = Walker(
        "p",
        [np.array((1.0, 5.0)), np.array((4.0, 5.0)), np.array((1.0, 5.0))],
        planner.with_radius(PERSON_RADIUS),
        speed=0.8,
        clothes=Clothes((0, 0, 0), (0, 0, 0)),
        pause_s=1.0,
    )
    track = []
    for _ in range(int(30.0 / DT)):
        walker.step(DT, keep_clear=(robot_x, 5.0, CLEAR))
        track.append((walker.x, walker.y))
        if walker.done:
            break
    track_xy = np.array(track)
    assert walker.done
    assert np.linalg.norm(track_xy[-1] - (1.0, 5.0)) < 1e-6
    assert np.linalg.norm(track_xy - (robot_x, 5.0), axis=1).min() >= CLEAR - 0.05


def test_the_robot_is_heard_in_its_room_and_through_a_door_not_through_a_wall(
    mission: Mission,
) -> None:
    """The robot speaks in the hall at (2.45, 5): heard in the kitchen through its door
    (x 2.0-2.9 on y = 4), not through the wall beside it, and not beyond HEARING_RANGE."""
    earshot = Earshot(mission.layout())
    robot = (2.45, 5.0)
    assert earshot.hears(robot, (5.0, 5.0))  # the hall, 2.55 m off
    assert earshot.hears(robot, (2.45, 2.5))  # the kitchen, straight through the door
    assert not earshot.hears(robot, (4.5, 3.0))  # the kitchen, through the wall
    assert not earshot.hears(robot, (2.45 + HEARING_RANGE + 0.1, 5.0))  # the hall, too far


def test_a_person_standing_turns_to_the_robots_voice_and_back_one_walking_walks_on(
    planner: GridPlanner,
) -> None:
    """She walks east along the hall and stands facing east; the robot speaks 1.5 m behind
    her. After REACTION_S she turns to face it, as fast as she turns, looks at it for ATTEND_S
    and turns back east. Spoken to while walking, she walks on facing her way."""
    walker = Walker(
        "her",
        [np.array((1.0, 5.0)), np.array((2.0, 5.0))],
        planner.with_radius(PERSON_RADIUS),
        speed=0.8,
        clothes=Clothes((0, 0, 0), (0, 0, 0)),
    )
    walker.hear(0.5, 5.0)  # walking: not turned
    heading = []
    while not walker.done:
        walker.step(DT)
        heading.append(walker.theta)
    assert max(abs(h) for h in heading) < 0.05  # faced east all the way
    walker.hear(0.5, 5.0)
    seen = []
    for k in range(int((REACTION_S + ATTEND_S + 3.0) / DT)):
        walker.step(DT)
        seen.append(((k + 1) * DT, walker.theta))
    west = [t for t, h in seen if abs(abs(h) - np.pi) < 0.05]
    assert west, "never faced the robot"
    turn = np.pi / TURN_RATE
    assert REACTION_S + turn - 2 * DT <= west[0] <= REACTION_S + turn + 2 * DT
    assert REACTION_S + ATTEND_S - 2 * DT <= west[-1] <= REACTION_S + ATTEND_S + DT
    assert all(abs(h) < 1e-9 for t, h in seen if t >= REACTION_S + ATTEND_S + turn + 2 * DT)
    assert all(abs(h) < 1e-9 for t, h in seen if t < REACTION_S)  # the reaction
