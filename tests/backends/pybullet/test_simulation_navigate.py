"""MOVE_BASE timing: ``navigate`` only takes the goal, the next step plans it (as move_base plans
in its own process), and the status right after ``navigate`` speaks of the new goal."""

from __future__ import annotations

from pathlib import Path

import pytest

from pfctl.app.sim import sim_config
from pfctl.backends.pybullet.navigation import Navigator
from pfctl.backends.pybullet.simulation import SimOptions, SimRobot
from pfctl.core.mapping.planning import GridPlanner
from pfctl.core.mapping.walls import rasterize_house
from pfctl.core.robot import NavStatus, Pose2D, Twist2D
from pfctl.mission import Mission, load_mission, loads_mission

pytestmark = pytest.mark.sim

HOUSE = Path(__file__).resolve().parents[3] / "missions" / "house.yaml"

ROOM = """
name: one-room
map:
  regions:
    - {name: room, polygon: [[0, 0], [6, 0], [6, 4], [0, 4]]}
robot: {start: {x: 1.0, y: 2.0, theta: 0.0}}
scenario: {seed: 1, people: []}
"""


@pytest.fixture(scope="module")
def room() -> Mission:
    return loads_mission(ROOM, source="room.yaml")


def test_navigate_takes_the_goal_and_the_next_step_plans_it(room: Mission) -> None:
    with SimRobot(sim_config(room), SimOptions(camera=False)) as robot:
        robot.navigate(Pose2D(2.0, 2.0))
        assert robot.nav_status() is NavStatus.ACTIVE
        assert robot.navigator.path is None  # not planned inside navigate
        robot.step()
        assert robot.navigator.path is not None
        assert robot.pose.x > 1.0  # and it already drove in that step
        while robot.nav_status() is NavStatus.ACTIVE and robot.time < 30:
            robot.step()
        assert robot.nav_status() is NavStatus.SUCCEEDED
        # a new goal: ACTIVE at once, not the old goal's SUCCEEDED
        robot.navigate(Pose2D(4.0, 2.0))
        assert robot.nav_status() is NavStatus.ACTIVE
        robot.step()
        assert robot.nav_status() is NavStatus.ACTIVE
        # a goal in the wall is refused at once; a direct command before the plan cancels it
        robot.navigate(Pose2D(6.0, 2.0))
        assert robot.nav_status() is NavStatus.ABORTED
        assert robot.commanded == Twist2D()
        robot.navigate(Pose2D(4.0, 3.0))
        robot.command(Twist2D())
        assert robot.nav_status() is NavStatus.PREEMPTED
        robot.step()
        assert robot.navigator.path is None


def test_an_unreachable_goal_is_aborted_by_the_first_update() -> None:
    mission = load_mission(HOUSE)
    grid = rasterize_house(mission.layout(), mission.map.resolution, mission.map.wall_thickness)
    fat = GridPlanner(grid, 0.5)  # wider than every door: other rooms are free but unreachable
    goal = next(g for g in (Pose2D(1.5, 7.5), Pose2D(8.0, 7.5)) if fat.is_free((g.x, g.y)))
    nav = Navigator(fat, 0.22, 0.8)
    nav.accept(goal)
    assert nav.status is NavStatus.ACTIVE and nav.path is None
    assert nav.update(Pose2D(2.5, 2.0 + 1.2), 0.1) == Twist2D()
    assert nav.status is NavStatus.ABORTED and "cannot be reached" in nav.reason
    nav.accept(Pose2D(5.0, 3.0))  # in the kitchen/living-room wall
    assert nav.status is NavStatus.ABORTED and "obstacle" in nav.reason
