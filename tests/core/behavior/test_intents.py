"""The intents leaves write (no robot): MOVE_BASE goals sent once and re-sent only when they move,
the robot's status read once per tick, a base no leaf drove stopped once, a goal given up
cancelled, and the tick's last base intent being the one sent."""

from __future__ import annotations

import pytest

from pfctl.core.behavior.intents import (
    RESEND_DISTANCE,
    CancelGoal,
    HeadAngles,
    Intents,
    LookAt,
    Navigate,
    Stop,
    Velocity,
)
from pfctl.core.behavior.world import WorldModel
from pfctl.core.control import ControlParams
from pfctl.core.mapping.grid import OccupancyGrid
from pfctl.core.mapping.house import HouseLayout
from pfctl.core.mapping.planning import GridPlanner
from pfctl.core.mapping.regions import RegionMap, SearchParams
from pfctl.core.robot import STOP, NavStatus, Pose2D, Twist2D

HALL = Pose2D(3.9, 4.5, 0.0)  # free floor in the hall of missions/house.yaml


@pytest.fixture
def intents(planner: GridPlanner, layout: HouseLayout) -> Intents:
    grid = OccupancyGrid(planner.geometry)
    world = WorldModel(grid, planner, RegionMap(layout), SearchParams())
    return Intents(ControlParams(), world)


def _tick(intents: Intents, status: NavStatus = NavStatus.IDLE, t: float = 0.0) -> None:
    intents.navigation.status = status  # what observe() reads from the robot
    intents.begin(t, HALL)


def test_a_goal_is_sent_once_and_again_only_when_it_moved(intents: Intents) -> None:
    _tick(intents)
    assert intents.go_to((3.9, 6.0), tolerance=0.4) == "running"
    assert isinstance(intents.base, Navigate) and intents.navigation.goal == (3.9, 6.0)
    assert intents.navigation.status is NavStatus.ACTIVE and intents.base_mode == "move_base"
    _tick(intents, NavStatus.ACTIVE, 0.1)
    assert intents.go_to((3.9, 6.0 + RESEND_DISTANCE / 2), tolerance=0.4) == "running"
    assert intents.base is None and intents.base_claimed  # driving on: nothing to send
    assert intents.navigation.goal == (3.9, 6.0)
    _tick(intents, NavStatus.ACTIVE, 0.2)
    intents.go_to((3.9, 6.0 + 2 * RESEND_DISTANCE), tolerance=0.4)
    assert isinstance(intents.base, Navigate) and intents.base.goal.y == pytest.approx(6.8)


def test_the_robot_status_decides_arrival_failure_and_resending(intents: Intents) -> None:
    _tick(intents)
    intents.go_to((3.9, 6.0), tolerance=0.4)
    _tick(intents, NavStatus.SUCCEEDED, 0.1)
    assert intents.go_to((3.9, 6.0), tolerance=0.4) == "arrived"
    assert isinstance(intents.base, CancelGoal) and intents.navigation.goal is None
    assert intents.base_mode == "hold"
    _tick(intents, NavStatus.SUCCEEDED, 0.2)
    intents.go_to((3.9, 6.0), tolerance=0.4)
    _tick(intents, NavStatus.ABORTED, 0.3)
    assert intents.go_to((3.9, 6.0), tolerance=0.4) == "failed"
    assert intents.base is None and intents.navigation.goal is None  # the robot dropped it
    _tick(intents, NavStatus.ABORTED, 0.4)
    intents.go_to((3.9, 6.0), tolerance=0.4)
    _tick(intents, NavStatus.PREEMPTED, 0.5)
    assert intents.go_to((3.9, 6.0), tolerance=0.4) == "running"
    assert isinstance(intents.base, Navigate)  # no longer driven to: sent again


def test_no_free_place_near_the_goal_fails_and_sends_nothing(intents: Intents) -> None:
    _tick(intents)
    assert intents.go_to((40.0, 40.0), tolerance=0.4) == "failed"
    assert intents.base is None and intents.base_claimed


def test_a_base_no_leaf_drove_is_stopped_once_and_a_goal_no_leaf_wants_is_cancelled(
    intents: Intents,
) -> None:
    _tick(intents)
    intents.end()
    assert intents.base == Stop() and intents.base_mode == "stop"
    _tick(intents, t=0.1)
    intents.end()
    assert intents.base is None  # already stopped: STOP is not sent every tick
    intents.go_to((3.9, 6.0), tolerance=0.4)
    intents.end()
    _tick(intents, NavStatus.ACTIVE, 0.2)
    intents.end()
    assert isinstance(intents.base, CancelGoal) and intents.navigation.goal is None
    _tick(intents, NavStatus.PREEMPTED, 0.3)
    intents.end()
    assert intents.base is None


def test_the_last_base_intent_of_the_tick_is_sent(intents: Intents) -> None:
    _tick(intents)
    intents.turn(0.5)
    intents.stop()
    assert intents.base == Stop(cancel_goal=False)
    intents.go_to((3.9, 6.0), tolerance=0.4)
    intents.release()  # a preempted leaf gives up the goal just written
    assert isinstance(intents.base, CancelGoal) and intents.navigation.goal is None
    _tick(intents, t=0.1)
    intents.go_to((3.9, 6.0), tolerance=0.4)
    intents.stop()
    assert intents.base == Stop(cancel_goal=True)
    _tick(intents, t=0.2)
    intents.turn(0.5)
    intents.go_to((HALL.x, HALL.y + 0.1), tolerance=0.4)  # arrived, no goal: nothing to send
    assert intents.base == Velocity(Twist2D(0.0, 0.0, 0.5)) and intents.base_mode == "hold"


def test_head_intents_are_kept_in_order(intents: Intents) -> None:
    _tick(intents)
    assert intents.gaze_source == "none"
    intents.look_at((5.0, 5.0))
    intents.set_pan(0.7)
    assert intents.head == [LookAt((5.0, 5.0), "target"), HeadAngles(0.7, 0.0, "sweep")]
    assert intents.gaze_source == "sweep"


def test_follow_without_fresh_sensors_stops(intents: Intents) -> None:
    _tick(intents)
    assert intents.follow((5.0, 4.5)) == "stop"  # no scan yet: stale sensors
    assert intents.base == Velocity(STOP)
