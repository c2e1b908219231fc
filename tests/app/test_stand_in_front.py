"""Where the simulated target stands to be learned: a spot in front of the robot that nobody else
stands on, waited for while a bystander walks off it (`pfctl learn-target` in the simulator)."""

from __future__ import annotations

import math

import pytest

from pfctl.app.homes import make_home
from pfctl.app.learn_target import STAND_DISTANCE, stand_in_front
from pfctl.app.sim import sim_config
from pfctl.backends.pybullet.simulation import SimRobot
from pfctl.backends.pybullet.walkers import PERSON_RADIUS
from pfctl.core.homes import HomeOptions
from pfctl.errors import UserError
from pfctl.mission import loads_mission

pytestmark = pytest.mark.sim

#: A corridor 1 m wide: the only spot 1.4 m from the robot is straight ahead, at (2.4, 3.0),
#: where Bob starts his ``{route}``.
CORRIDOR = """
name: corridor
map:
  regions:
    - {{name: corridor, polygon: [[0, 2.5], [9, 2.5], [9, 3.5], [0, 3.5]]}}
robot: {{start: {{x: 1.0, y: 3.0, theta: 0.0}}}}
scenario:
  seed: 3
  target: alice
  people:
    - {{name: alice, clothes: {{upper: [200, 30, 40], lower: [40, 40, 120]}}, route: [[6.0, 3.0]]}}
    - name: bob
      clothes: {{upper: [30, 120, 200], lower: [60, 60, 60]}}
      route: {route}
"""


def _others_off(robot: SimRobot, x: float, y: float) -> float:
    """How far the nearest person other than the target stands from ``(x, y)``, metres."""
    return min(math.hypot(w.x - x, w.y - y) for w in robot.people if not w.is_target)


def test_the_target_waits_for_a_bystander_to_walk_off_the_spot_in_front() -> None:
    walks_off = CORRIDOR.format(route="[[2.4, 3.0], [8.5, 3.0]]")
    mission = loads_mission(walks_off, source="corridor.yaml")
    with SimRobot(sim_config(mission)) as robot:
        assert _others_off(robot, 1.0 + STAND_DISTANCE, 3.0) < 2 * PERSON_RADIUS
        x, y, bearing = stand_in_front(robot, source="corridor.yaml")
        assert robot.time > 0.0  # it waited for Bob
        assert (x, y, bearing) == pytest.approx((1.0 + STAND_DISTANCE, 3.0, 0.0), abs=1e-6)
        assert _others_off(robot, x, y) >= 2 * PERSON_RADIUS
        target = next(w for w in robot.people if w.is_target)
        assert (target.x, target.y) == pytest.approx((x, y))
        assert robot.pose.x == pytest.approx(1.0) and robot.pose.y == pytest.approx(3.0)


def test_a_bystander_who_stays_on_the_spot_is_a_one_line_error_after_the_wait() -> None:
    he_stays = CORRIDOR.format(route="[[2.4, 3.0]]")
    mission = loads_mission(he_stays, source="corridor.yaml")
    with SimRobot(sim_config(mission)) as robot:
        with pytest.raises(UserError, match=r"^corridor\.yaml: no free spot 1\.4 m .* for 2 s$"):
            stand_in_front(robot, source="corridor.yaml", wait_s=2.0)
        assert robot.time == pytest.approx(2.0, abs=0.15)


def test_the_generated_home_whose_look_alike_starts_on_the_target_learns_her() -> None:
    """Home 8 of the look-alike homes (`pfctl mission generate --seed 8 --look-alikes 2`): Bob,
    a look-alike, starts 0.15 m from her, on every free spot in front of the robot; `pfctl
    bench` failed there before the target waited for him."""
    home = make_home(HomeOptions(seed=8, look_alikes=2)).text
    mission = loads_mission(home, source="home-08.yaml")
    with SimRobot(sim_config(mission, 1)) as robot:
        x, y, _ = stand_in_front(robot, source="home-08.yaml")
        assert robot.time > 0.0
        assert _others_off(robot, x, y) >= 2 * PERSON_RADIUS
