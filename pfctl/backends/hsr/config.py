"""What the HSR backend talks to and within which limits: plain values, built from a mission by
``pfctl.app.hsr``.

The mission declares each value's default, unit and meaning (``backend.hsr`` for the topics,
frames and timeouts, ``robot`` for the limits: ``pfctl mission schema``); :class:`HsrConfig` only
carries them to :class:`~pfctl.backends.hsr.robot.HsrRobot` and to the simulator's bridge
(:mod:`~pfctl.backends.hsr.sim_bridge`), which never read a mission.
"""

from __future__ import annotations

from dataclasses import dataclass

from pfctl.core.robot import RobotLimits


@dataclass(frozen=True)
class HsrConfig:
    """The ROS 1 interface of the HSR (topics, tf frames, timeouts), the robot's limits, the
    control period and the least pixels of a person the camera detections count."""

    laser: str
    rgb: str
    depth: str
    camera_info: str
    person_labels: str | None
    person_keypoints: str | None
    joint_states: str
    odom: str
    pose: str | None
    command_velocity: str
    head_command: str
    move_base: str
    speech: str | None
    viewpoint_stop: str | None
    ground_truth: str | None
    map_frame: str
    odom_frame: str
    base_frame: str
    stale_timeout: float
    connect_timeout: float
    limits: RobotLimits
    tick_period: float
    """Seconds (``1 / behavior.tick_hz``)."""
    min_pixels: int
    """``perception.vision.min_pixels``."""


__all__ = ["HsrConfig"]
