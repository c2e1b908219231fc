"""Navigator with a kinematic omnidirectional robot in the shipped house."""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
import pytest
import shapely

from pfctl.backends.pybullet.navigation import (
    DETOUR_WAIT_S,
    MARKED_GOAL_TOLERANCE,
    PERSON_MARGIN,
    RECENT_PEOPLE_S,
    WALL_MARGIN,
    Navigator,
    keep_clear,
)
from pfctl.core.mapping.planning import GridPlanner
from pfctl.core.mapping.walls import wall_footprint
from pfctl.core.robot import LaserScan, NavStatus, Pose2D, Twist2D
from pfctl.mission import Mission

pytestmark = pytest.mark.sim

DT = 0.1


def _navigator(mission: Mission, planner: GridPlanner) -> Navigator:
    return Navigator(planner, mission.robot.max_linear_speed, mission.robot.max_angular_speed)


def _move(pose: Pose2D, cmd: Twist2D, dt: float) -> Pose2D:
    """A perfect omnidirectional base: integrate the robot-frame twist."""
    c, s = math.cos(pose.theta), math.sin(pose.theta)
    return Pose2D(
        pose.x + (c * cmd.vx - s * cmd.vy) * dt,
        pose.y + (s * cmd.vx + c * cmd.vy) * dt,
        pose.theta + cmd.wz * dt,
    )


def _drive(nav: Navigator, pose: Pose2D, seconds: float, obstacles=None):
    poses, cmds = [pose], []
    for _ in range(int(seconds / DT)):
        pts = obstacles(pose) if obstacles else None
        cmd = nav.update(pose, DT, pts)
        cmds.append(cmd)
        pose = _move(pose, cmd, DT)
        poses.append(pose)
        if nav.status is not NavStatus.ACTIVE:
            break
    return poses, cmds


def _ring(center: tuple[float, float], radius: float = 0.2) -> np.ndarray:
    """A person's outline as the laser sees it: 24 points round ``center``."""
    angles = np.linspace(0, 2 * np.pi, 24)
    return np.asarray(center) + radius * np.column_stack((np.cos(angles), np.sin(angles)))


def _seen_for(points: np.ndarray, seconds: float) -> Callable[[Pose2D], np.ndarray]:
    """Obstacle points the laser shows for the first ``seconds`` of a drive, then nothing."""
    clock = {"t": 0.0}

    def seen(pose: Pose2D) -> np.ndarray:
        clock["t"] += DT
        return points if clock["t"] <= seconds else np.empty((0, 2))

    return seen


def test_reaches_a_goal_in_another_room_within_limits(
    mission: Mission, planner: GridPlanner
) -> None:
    nav = _navigator(mission, planner)
    start = Pose2D(1.0, 3.3, 0.0)
    goal = Pose2D(3.0, 7.5, math.pi / 2)  # kitchen -> office, two doors
    nav.start(goal, start)
    assert nav.status is NavStatus.ACTIVE
    poses, cmds = _drive(nav, start, 200.0)
    assert nav.status is NavStatus.SUCCEEDED
    end = poses[-1]
    assert end.distance_to(goal) <= nav.goal_tolerance
    assert abs((end.theta - goal.theta + math.pi) % (2 * math.pi) - math.pi) <= nav.yaw_tolerance
    lin = np.array([math.hypot(c.vx, c.vy) for c in cmds])
    ang = np.array([abs(c.wz) for c in cmds])
    assert lin.max() <= mission.robot.max_linear_speed + 1e-9
    assert ang.max() <= mission.robot.max_angular_speed + 1e-9
    assert lin.max() > 0.9 * mission.robot.max_linear_speed  # it really uses the speed
    walls = wall_footprint(mission.layout(), mission.map.wall_thickness)
    xy = np.array([(p.x, p.y) for p in poses])
    assert shapely.distance(walls, shapely.points(xy)).min() > mission.robot.radius - 0.03
    assert nav.update(end, DT) == Twist2D()  # done: stands still


def test_goal_in_a_wall_is_aborted_at_once(mission: Mission, planner: GridPlanner) -> None:
    nav = _navigator(mission, planner)
    nav.start(Pose2D(5.0, 3.0), Pose2D(1.0, 3.3))
    assert nav.status is NavStatus.ABORTED
    assert "obstacle" in nav.reason
    assert nav.update(Pose2D(1.0, 3.3), DT) == Twist2D()


def test_replans_around_a_blocker(mission: Mission, planner: GridPlanner) -> None:
    """A person stands in the hall on the straight path; the laser sees its legs."""
    nav = _navigator(mission, planner)
    start, goal = Pose2D(1.0, 5.0), Pose2D(8.0, 5.0)
    blocker = np.array([6.0, 5.0])
    ring = blocker + 0.2 * np.column_stack(
        (np.cos(np.linspace(0, 2 * np.pi, 24)), np.sin(np.linspace(0, 2 * np.pi, 24)))
    )
    nav.start(goal, start)
    first = nav.path.copy()
    # the first plan goes straight through the person
    assert np.abs(first[:, 1] - 5.0).max() < 0.3

    def seen(pose: Pose2D) -> np.ndarray:
        near = np.linalg.norm(ring - (pose.x, pose.y), axis=1) < 4.0
        return ring[near]

    poses, _ = _drive(nav, start, 120.0, seen)
    assert nav.status is NavStatus.SUCCEEDED
    assert nav.total_replans >= 1
    xy = np.array([(p.x, p.y) for p in poses])
    assert np.linalg.norm(xy - blocker, axis=1).min() > 0.2 + mission.robot.radius


def test_a_door_blocked_for_a_moment_is_taken_once_clear(
    mission: Mission, planner: GridPlanner
) -> None:
    """A person stands in the kitchen's door to the hall for the first 4 s, then walks off out
    of sight. The robot plans round her (through the living room), forgets her once the laser
    no longer shows her there, and goes through that door after all: not round the house."""
    nav = _navigator(mission, planner)
    start, goal = Pose2D(1.0, 3.3), Pose2D(3.0, 7.5, math.pi / 2)  # kitchen -> office
    nav.start(goal, start)
    poses, _ = _drive(nav, start, 200.0, _seen_for(_ring((2.3, 4.0)), 4.0))
    assert nav.status is NavStatus.SUCCEEDED
    assert nav.total_replans >= 1  # it did plan round her
    xy = np.array([(p.x, p.y) for p in poses])
    assert not np.any(xy[:, 0] > 5.0)  # never into the living room, east of x = 5 m
    through_door = (np.abs(xy[:, 1] - 4.0) < 0.15) & (xy[:, 0] > 1.9) & (xy[:, 0] < 2.7)
    assert through_door.any()
    assert len(poses) * DT < 60.0  # the kitchen door's way takes ~35 s; round the house ~75 s


def test_a_goal_a_person_stands_on_is_reached_as_near_as_free(
    mission: Mission, planner: GridPlanner
) -> None:
    """The place to look from is where a person stands (the search's look just inside a door,
    where she is): the re-plan round her legs plans to the nearest point free of them, within
    MARKED_GOAL_TOLERANCE, and the robot arrives there (move_base's planner tolerance) instead
    of failing its re-plans until ABORTED."""
    nav = _navigator(mission, planner)
    start, goal = Pose2D(1.0, 5.0), Pose2D(6.0, 5.0)
    circle = np.linspace(0, 2 * np.pi, 12, endpoint=False)
    leg = 0.06 * np.column_stack((np.cos(circle), np.sin(circle)))
    legs = np.vstack([leg + np.array(feet) for feet in ((6.12, 5.0), (6.12, 4.8))])  # past the goal
    nav.start(goal, start)
    poses, _ = _drive(nav, start, 60.0, lambda pose: legs)
    assert nav.status is NavStatus.SUCCEEDED, nav.reason
    assert nav.total_replans >= 1  # it did plan round her
    end = np.array([poses[-1].x, poses[-1].y])
    assert np.linalg.norm(end - (goal.x, goal.y)) <= MARKED_GOAL_TOLERANCE + nav.goal_tolerance
    xy = np.array([(p.x, p.y) for p in poses])
    gap = np.linalg.norm(xy[:, None] - legs[None], axis=2).min()
    assert gap >= planner.robot_radius + PERSON_MARGIN - 0.07  # never into her
    assert nav.update(poses[-1], DT, legs) == Twist2D()  # done: stands still


def test_fully_blocked_door_aborts_after_bounded_replans(
    mission: Mission, planner: GridPlanner
) -> None:
    """The office door is closed by people standing in it: no way in, so ABORTED."""
    nav = _navigator(mission, planner)
    start, goal = Pose2D(3.9, 5.0, math.pi / 2), Pose2D(3.9, 7.5)
    wall = np.column_stack((np.linspace(3.5, 4.4, 30), np.full(30, 5.8)))
    nav.start(goal, start)
    poses, _ = _drive(nav, start, 120.0, lambda pose: wall)
    assert nav.status is NavStatus.ABORTED
    assert nav.replans >= 1
    assert max(p.y for p in poses) < 5.8 - mission.robot.radius


def test_cancel_and_new_goal(mission: Mission, planner: GridPlanner) -> None:
    nav = _navigator(mission, planner)
    assert nav.status is NavStatus.IDLE
    nav.start(Pose2D(3.0, 2.5), Pose2D(1.0, 3.3))
    nav.cancel()
    assert nav.status is NavStatus.PREEMPTED
    assert nav.update(Pose2D(1.0, 3.3), DT) == Twist2D()


def test_keep_clear_slides_along_walls_and_stops_short_of_people() -> None:
    here, r = np.array([0.0, 0.0]), 0.2
    none = np.empty((0, 2))
    v = np.array([0.3, 0.1])
    assert np.allclose(keep_clear(v, here, none, none, r), v)  # nothing near: unchanged
    wall = np.array([[r + WALL_MARGIN - 0.01, 0.0]])  # a wall point just ahead
    assert np.allclose(keep_clear(v, here, none, wall, r), [0.0, 0.1])  # slides along it
    far_wall = np.array([[r + WALL_MARGIN + 0.05, 0.0]])
    assert np.allclose(keep_clear(v, here, none, far_wall, r), v)
    leg = np.array([[0.25, 0.25]])  # a person's leg within the radius + PERSON_MARGIN
    assert np.hypot(*leg[0]) < r + PERSON_MARGIN
    out = keep_clear(v, here, leg, none, r)
    assert out @ (leg[0] / np.linalg.norm(leg[0])) <= 1e-12  # no approach
    assert np.allclose(keep_clear(-v, here, leg, none, r), -v)  # moving away is free
    # a doorway: jambs left and right, straight through stays possible
    jambs = np.array([[0.0, r + 0.03], [0.0, -(r + 0.03)]])
    assert np.allclose(keep_clear(np.array([0.3, 0.0]), here, none, jambs, r), [0.3, 0.0])
    # two walls in a corner: neither is approached after the two passes
    corner = np.array([[r, 0.0], [0.0, r]])
    out = keep_clear(np.array([0.3, 0.3]), here, none, corner, r)
    assert out[0] <= 1e-12 and out[1] <= 1e-12


def test_navigator_does_not_drive_into_a_person_standing_on_its_path(
    planner: GridPlanner,
) -> None:
    nav = Navigator(planner, 0.6, 1.2)
    pose = Pose2D(1.0, 5.0, 0.0)
    nav.start(Pose2D(6.0, 5.0, 0.0), pose)  # along the hall
    person = np.array([1.6, 5.0])
    legs = person + np.array([[0.0, 0.1], [0.0, -0.1]])
    for _ in range(40):
        cmd = nav.update(pose, DT, legs)
        c, s = math.cos(pose.theta), math.sin(pose.theta)
        vx, vy = c * cmd.vx - s * cmd.vy, s * cmd.vx + c * cmd.vy
        pose = Pose2D(pose.x + vx * DT, pose.y + vy * DT, pose.theta + cmd.wz * DT)
        gap = np.linalg.norm(legs - (pose.x, pose.y), axis=1).min()
        assert gap >= planner.robot_radius + PERSON_MARGIN - 0.07  # one step of overshoot


def test_a_person_seen_a_moment_ago_behind_the_robot_is_still_kept_clear_of(
    planner: GridPlanner,
) -> None:
    """The laser saw a person beside the way back a moment ago; now they are in its blind
    sector (the scans show nothing). The base sets off that way and must not close on them
    for RECENT_PEOPLE_S seconds (the person walked round the robot and stood, as in the crowd)."""
    nav = Navigator(planner, 0.22, 0.8)
    pose = Pose2D(4.0, 5.0, 0.0)  # facing east, in the hall
    nav.start(Pose2D(1.0, 5.0, math.pi), pose)  # the way back west
    angles = np.linspace(0, 2 * np.pi, 12, endpoint=False)
    leg = np.array([3.6, 5.35]) + 0.06 * np.column_stack((np.cos(angles), np.sin(angles)))
    reach = planner.robot_radius + PERSON_MARGIN
    seen = {"t": 0.0}

    def scan(pose: Pose2D) -> np.ndarray:
        seen["t"] += DT
        return leg if seen["t"] <= DT else np.empty((0, 2))  # one scan, then out of view

    poses, _ = _drive(nav, pose, RECENT_PEOPLE_S - DT, scan)
    xy = np.array([(p.x, p.y) for p in poses])
    assert xy[-1, 0] < 3.9  # it did set off
    assert np.linalg.norm(xy[:, None] - leg[None], axis=2).min() >= reach - 0.03


def test_a_person_crossing_the_door_ahead_is_waited_for_not_gone_round(
    mission: Mission, planner: GridPlanner
) -> None:
    """Traced, the shipped house (randomized, seed 46): people walking through the kitchen's
    door to the hall sent the robot round the dining table toward the living room each time
    and back when they had passed, for 50 s. A person in the door for 2 s: the way round her
    (through the living room) is far longer than the path through the door, so the robot stands
    and waits for her to pass instead of planning round her."""
    nav = _navigator(mission, planner)
    start, goal = Pose2D(1.0, 3.3), Pose2D(3.0, 7.5, math.pi / 2)  # kitchen -> office
    nav.start(goal, start)
    poses, cmds = _drive(nav, start, 200.0, _seen_for(_ring((2.3, 4.0)), 2.0))
    assert nav.status is NavStatus.SUCCEEDED
    assert nav.total_replans == 0  # never planned round her
    assert any(c == Twist2D() for c in cmds[:20])  # it stood while she was in the door
    xy = np.array([(p.x, p.y) for p in poses])
    assert not np.any(xy[:, 0] > 5.0)
    assert xy[:, 1].min() > start.y - 0.1  # never back toward the living room's door
    through_door = (np.abs(xy[:, 1] - 4.0) < 0.15) & (xy[:, 0] > 1.9) & (xy[:, 0] < 2.7)
    assert through_door.any()


def test_a_short_way_round_a_person_is_taken_without_waiting(
    mission: Mission, planner: GridPlanner
) -> None:
    """A person stands in the 2 m wide hall: the way round her is a little longer than the
    path through her (less than DETOUR_EXTRA), so the robot goes round at once."""
    nav = _navigator(mission, planner)
    start, goal = Pose2D(1.0, 5.0), Pose2D(8.0, 5.0)
    person = _ring((3.0, 5.0))
    nav.start(goal, start)
    _, cmds = _drive(nav, start, 120.0, lambda pose: person)
    assert nav.status is NavStatus.SUCCEEDED
    assert nav.total_replans >= 1
    still = longest = 0
    for c in cmds:
        still = still + 1 if c == Twist2D() else 0
        longest = max(longest, still)
    assert longest * DT < DETOUR_WAIT_S


def _scan(pose: Pose2D, ranges: np.ndarray) -> LaserScan:
    return LaserScan(0.0, -3 * math.pi / 4, math.radians(0.5), 0.05, 10.0, ranges, pose)


def test_marks_the_laser_sees_through_are_forgotten(planner: GridPlanner) -> None:
    """A person blocked the hall and was marked. A scan whose beams pass beyond the marks, with
    no return near them, clears them (move_base's ray-trace clearing); a return at the marks (she
    is still there) or before them (something hides them) keeps them."""
    pose = Pose2D(1.0, 5.0, 0.0)
    beams = 541
    legs = np.array([[2.0, 5.1], [2.0, 4.9]])

    def marked() -> Navigator:
        nav = Navigator(planner, 0.22, 0.8)
        nav.start(Pose2D(8.0, 5.0), pose)
        nav.update(pose, DT, legs)
        assert len(nav.marks) == 2
        return nav

    nav = marked()
    nav.clear_seen(_scan(pose, np.full(beams, np.inf)))  # nothing there now
    assert len(nav.marks) == 0

    nav = marked()
    nav.clear_seen(_scan(pose, np.full(beams, 0.6)))  # something nearer hides the spot
    assert len(nav.marks) == 2

    nav = marked()
    angles = -3 * math.pi / 4 + math.radians(0.5) * np.arange(beams)
    ranges = np.full(beams, np.inf)
    for leg in legs:  # her legs still return the beams toward them
        bearing = math.atan2(leg[1] - pose.y, leg[0] - pose.x)
        k = int(np.argmin(np.abs(angles - bearing)))
        ranges[k - 2 : k + 3] = math.dist(leg, (pose.x, pose.y)) - 0.03
    nav.clear_seen(_scan(pose, ranges))
    assert len(nav.marks) == 2


def test_waiting_for_a_person_is_bounded_over_goals_sent_while_following(
    mission: Mission, planner: GridPlanner
) -> None:
    """Following her, MOVE_BASE gets a new goal every few of her steps. A person who stays in
    the kitchen's door is waited on for DETOUR_WAIT_S in all, not afresh for every goal (the
    robot would stand there while she walks away), and then gone round."""
    nav = _navigator(mission, planner)
    pose = Pose2D(1.0, 3.3)
    person = _ring((2.3, 4.0))
    stood = 0.0
    for k in range(100):  # 10 s
        if k % 5 == 0:  # her next steps: a new goal every 0.5 s, 0.4 m farther on
            nav.start(Pose2D(3.0 + 0.04 * k, 7.5, math.pi / 2), pose)
        cmd = nav.update(pose, DT, person)
        stood += DT if cmd == Twist2D() else 0.0
        pose = _move(pose, cmd, DT)
    assert nav.status is NavStatus.ACTIVE
    assert DETOUR_WAIT_S - DT <= stood <= DETOUR_WAIT_S + 1.5  # + the re-plans' own pauses
    assert math.dist((pose.x, pose.y), (1.0, 3.3)) > 1.0  # on its way round her


def test_a_short_way_round_taken_does_not_spend_the_wait_for_a_long_one(
    mission: Mission, planner: GridPlanner
) -> None:
    """Traced, the shipped house (randomized, seed 40, on `08c2de1`): a person in the kitchen
    was gone round by a short way (5.7 -> 4.9 m); a second later another in the kitchen's door
    blocked that path, and the way round through the living room (15.4 m) was taken at once,
    with no wait: the short way had marked the blockage as waited on. Each blocking is weighed
    anew until the robot has stood for one."""
    nav = _navigator(mission, planner)
    start, goal = Pose2D(1.0, 3.3), Pose2D(3.0, 7.5, math.pi / 2)  # kitchen -> office
    first, second = _ring((1.5, 3.1), 0.1), _ring((2.3, 4.0))
    clock = {"t": 0.0}

    def seen(pose: Pose2D) -> np.ndarray:
        clock["t"] += DT
        if clock["t"] <= 1.0:
            return first  # a short way round him
        return second if clock["t"] <= 3.5 else np.empty((0, 2))  # then her in the door

    nav.start(goal, start)
    poses, _ = _drive(nav, start, 200.0, seen)
    assert nav.status is NavStatus.SUCCEEDED
    xy = np.array([(p.x, p.y) for p in poses])
    assert not np.any(xy[:, 0] > 5.0)  # never toward the living room
    assert xy[:, 1].min() > 2.9  # nor round the dining table
