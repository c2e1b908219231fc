"""SimRobot first cut: clamping, a wall stops the base and counts a collision, determinism."""

from pathlib import Path

from pfctl.backends.pybullet.simulation import SimOptions, SimRobot
from pfctl.core.robot import Twist2D
from pfctl.mission import load_mission

HOUSE = Path(__file__).parents[2] / "missions" / "house.yaml"


def test_clamp_and_wall_collision_and_determinism() -> None:
    mission = load_mission(HOUSE)
    runs = []
    for _ in range(2):
        with SimRobot(mission, SimOptions(seed=3)) as robot:
            robot.command(Twist2D(5.0, 0.0, 9.0))
            assert abs(robot._cmd.vx - mission.robot.max_linear_speed) < 1e-9
            robot.command(Twist2D(5.0, 0.0, 0.0))
            for _ in range(600):
                robot.step()
            obs = robot.observe()
            assert obs.scan is not None
            assert robot.collisions > 0
            runs.append((robot.pose, [w.truth() for w in robot.people]))
    assert runs[0] == runs[1]
