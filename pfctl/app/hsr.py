"""The HSR backend's config of a mission: the only place where mission values become the
parameters of :class:`~pfctl.backends.hsr.robot.HsrRobot` and of the simulator's HSR bridge."""

from __future__ import annotations

from pfctl.app.sections import from_section
from pfctl.backends.hsr.config import HsrConfig
from pfctl.core.robot import RobotLimits
from pfctl.mission import Mission


def hsr_config(mission: Mission) -> HsrConfig:
    """``backend.hsr`` with the ``robot`` limits, the control period and the camera
    detections' least pixels of ``mission``."""
    return from_section(
        HsrConfig,
        mission.backend.hsr,
        limits=from_section(RobotLimits, mission.robot),
        tick_period=1.0 / mission.behavior.tick_hz,
        min_pixels=mission.perception.vision.min_pixels,
    )


__all__ = ["hsr_config"]
