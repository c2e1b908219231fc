"""The perception of a mission: core parameters from its YAML sections, and a whole pipeline.

``core`` never reads the mission; this module turns ``perception``, ``tracking``, ``belief`` and
``sensors.camera`` into the core's parameter values and builds a
:class:`~pfctl.core.perception.Perception` for a command or a backend.
"""

from __future__ import annotations

from pathlib import Path
from typing import Literal

from numpy.typing import ArrayLike

from pfctl.core.belief import BeliefParams, HumanBelief
from pfctl.core.clothes import ClothesParams
from pfctl.core.grid import GridGeometry
from pfctl.core.identity import IdentityParams, TargetIdentifier, TargetProfile
from pfctl.core.legs import LegDetector, LegParams, load_leg_model
from pfctl.core.perception import Perception
from pfctl.core.tracking import MultiPersonTracker, TrackerParams
from pfctl.core.vision import PersonDetector
from pfctl.mission import Mission


def leg_params(mission: Mission) -> LegParams:
    """The leg detector's parameters (``perception.legs``)."""
    c = mission.perception.legs
    return LegParams(
        probability=c.probability,
        jump_distance=c.jump_distance,
        min_points=c.min_points,
        max_range=c.max_range,
        pair_distance=c.pair_distance,
        history_scans=c.history_scans,
    )


def tracker_params(mission: Mission) -> TrackerParams:
    """The tracker's parameters (``tracking``)."""
    return TrackerParams(**mission.tracking.model_dump())


def belief_params(mission: Mission) -> BeliefParams:
    """The human belief's parameters (``belief``)."""
    return BeliefParams(**mission.belief.model_dump())


def identity_params(mission: Mission) -> IdentityParams:
    """The identification parameters (``perception.identity``)."""
    cfg = mission.perception.identity
    space: Literal["hsv", "rgb", "lab"] = cfg.color_space
    h, s, v = (int(b) for b in cfg.bins)
    return IdentityParams(
        face_distance=float(cfg.face_distance),
        clothes_similarity=float(cfg.clothes_similarity),
        clothes=ClothesParams(space, (h, s, v)),
    )


def build_perception(
    mission: Mission,
    *,
    detector: PersonDetector | None = None,
    profile: TargetProfile | None = None,
    belief_grid: tuple[GridGeometry, ArrayLike] | None = None,
    leg_model: Path | None = None,
) -> Perception:
    """The mission's perception: its leg model (``leg_model`` overrides
    ``perception.legs.model``; neither: the shipped model), tracker, and — when given — a
    camera ``detector``, a target ``profile`` to identify, and a human belief over
    ``belief_grid`` = (geometry, blocked mask)."""
    model = load_leg_model(leg_model or mission.perception.legs.model)
    identifier = None
    if profile is not None:
        identifier = TargetIdentifier(profile, identity_params(mission))
    belief = None
    if belief_grid is not None:
        geometry, blocked = belief_grid
        belief = HumanBelief(geometry, belief_params(mission), blocked=blocked)
    camera = mission.sensors.camera
    return Perception(
        LegDetector(model, leg_params(mission)),
        MultiPersonTracker(tracker_params(mission)),
        detector=detector,
        identifier=identifier,
        belief=belief,
        camera_range=(camera.range_min, camera.range_max),
    )


__all__ = [
    "belief_params",
    "build_perception",
    "identity_params",
    "leg_params",
    "tracker_params",
]
