"""What the simulated house simulates: plain values, built from a mission by ``pfctl.app.sim``.

The mission declares each value's default, unit and meaning (``pfctl mission schema``: the
sections named below); these classes only carry the values to the simulator, which never reads
a mission. :class:`SimConfig` is the whole of it; :class:`~pfctl.backends.pybullet.simulation.
SimOptions` says how to run it (window, pacing, laser model).
"""

from __future__ import annotations

from dataclasses import dataclass

from pfctl.core.mapping.house import HouseLayout
from pfctl.core.robot import Pose2D, RobotLimits


@dataclass(frozen=True)
class HouseConfig:
    """The static house: regions, doors and furniture, and the walls' size (``map``)."""

    layout: HouseLayout
    resolution: float
    wall_thickness: float
    wall_height: float


@dataclass(frozen=True)
class LaserConfig:
    """The base laser (``sensors.laser``)."""

    rate_hz: float
    fov_deg: float
    resolution_deg: float
    range_min: float
    range_max: float
    noise_std: float
    mount_x: float
    mount_height: float


@dataclass(frozen=True)
class CameraConfig:
    """The RGB-D camera on the head (``sensors.camera``)."""

    rate_hz: float
    width: int
    height: int
    hfov_deg: float
    mount_height: float
    forward_offset: float
    range_min: float
    range_max: float
    depth_noise: float


@dataclass(frozen=True)
class PoseNoise:
    """Noise of the robot's own pose estimates (``sensors.pose``)."""

    localization_xy: float
    localization_theta: float
    odometry_linear: float
    odometry_angular: float


@dataclass(frozen=True)
class Clothes:
    """A person's clothes colours, RGB 0..255 (``scenario.people[*].clothes``; also the
    simulator's distractors')."""

    upper: tuple[int, int, int]
    lower: tuple[int, int, int]


@dataclass(frozen=True)
class PersonConfig:
    """A person of the scenario (``scenario.people[*]``); a route stop is a region's name or an
    ``(x, y)`` point."""

    name: str
    clothes: Clothes
    speed: float
    route: tuple[str | tuple[float, float], ...]
    height: float
    pause_s: float
    loop: bool


@dataclass(frozen=True)
class Randomization:
    """What else the seed varies (``scenario.randomize``)."""

    speed_scale: tuple[float, float]
    route_jitter: float
    extra_people: tuple[int, int]
    look_alikes: tuple[int, int]
    look_alike_jitter: int


@dataclass(frozen=True)
class ScenarioConfig:
    """The people in the house and which of them is the target (``scenario``)."""

    target: str | None
    people: tuple[PersonConfig, ...]
    random_people: int
    randomize: Randomization
    turn_to_voice: bool
    """People standing within earshot turn to the robot when it speaks
    (:class:`~pfctl.backends.pybullet.walkers.Earshot`)."""


@dataclass(frozen=True)
class SimConfig:
    """Everything the simulator simulates."""

    house: HouseConfig
    robot: RobotLimits
    start: Pose2D
    """Where the robot starts (``robot.start``, or a point inside the first region)."""
    laser: LaserConfig
    camera: CameraConfig
    pose_noise: PoseNoise
    scenario: ScenarioConfig
    seed: int
    """Seed of everything random."""
    tick_period: float
    """The control period, seconds (``1 / behavior.tick_hz``): one :meth:`SimRobot.step`."""


__all__ = [
    "CameraConfig",
    "Clothes",
    "HouseConfig",
    "LaserConfig",
    "PersonConfig",
    "PoseNoise",
    "Randomization",
    "ScenarioConfig",
    "SimConfig",
]
