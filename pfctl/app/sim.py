"""The simulated house of a mission: the simulator's config built from the mission, and the
simulator opened with it.

The only place where mission values become the simulator's parameters
(:class:`~pfctl.backends.pybullet.config.SimConfig`). Importing this module loads PyBullet: a
command imports it when it needs the simulator.
"""

from __future__ import annotations

from pfctl.app.sections import from_section
from pfctl.backends.pybullet.config import (
    CameraConfig,
    HouseConfig,
    LaserConfig,
    PoseNoise,
    ScenarioConfig,
    SimConfig,
)
from pfctl.backends.pybullet.simulation import SimOptions, SimRobot
from pfctl.core.mapping.planning import NoPathError
from pfctl.core.robot import Pose2D, RobotLimits
from pfctl.errors import UserError
from pfctl.mission import Mission


def house_config(mission: Mission) -> HouseConfig:
    """The static house of ``mission`` (its ``map``)."""
    return from_section(HouseConfig, mission.map, layout=mission.layout())


def sim_config(mission: Mission, seed: int | None = None) -> SimConfig:
    """What the simulator simulates for ``mission``; ``seed`` None: ``scenario.seed``."""
    sensors = mission.sensors
    return SimConfig(
        house=house_config(mission),
        robot=from_section(RobotLimits, mission.robot),
        start=Pose2D(*mission.start_pose()),
        laser=from_section(LaserConfig, sensors.laser),
        camera=from_section(CameraConfig, sensors.camera),
        pose_noise=from_section(PoseNoise, sensors.pose),
        scenario=from_section(ScenarioConfig, mission.scenario),
        seed=mission.scenario.seed if seed is None else seed,
        tick_period=1.0 / mission.behavior.tick_hz,
    )


def sim_robot(
    mission: Mission, seed: int | None, source: str, options: SimOptions | None = None
) -> SimRobot:
    """The simulated house of ``mission`` run with ``options``; a person's route that cannot be
    walked is a UserError naming ``source`` (the mission file)."""
    try:
        return SimRobot(sim_config(mission, seed), options)
    except NoPathError as err:
        raise UserError(f"{source}: scenario.people: a route cannot be walked: {err}") from None


__all__ = ["house_config", "sim_config", "sim_robot"]
