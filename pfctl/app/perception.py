"""The perception of a mission: core parameters from its YAML sections, and a whole pipeline.

``core`` never reads the mission; this module turns ``perception``, ``tracking``, ``belief`` and
``sensors.camera`` into the core's parameter values and builds a
:class:`~pfctl.core.perception.pipeline.Perception` for a command or a backend.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike

from pfctl.app.leg_models import load_leg_model
from pfctl.app.profiles import check_target_profile
from pfctl.core.mapping.grid import GridGeometry
from pfctl.core.perception.belief import BeliefParams, HumanBelief
from pfctl.core.perception.clothes import ClothesParams
from pfctl.core.perception.face_worker import FaceWorker
from pfctl.core.perception.identity.identifier import TargetIdentifier
from pfctl.core.perception.identity.params import (
    FaceTiming,
    IdentityParams,
    resolve_face_timing,
)
from pfctl.core.perception.identity.profile import TargetProfile
from pfctl.core.perception.legs.detector import LegDetector, LegParams
from pfctl.core.perception.pipeline import Perception
from pfctl.core.perception.tracking import MultiPersonTracker, TrackerParams
from pfctl.core.perception.vision import PersonDetector
from pfctl.mission import Mission
from pfctl.mission.params import core_params


def leg_params(mission: Mission) -> LegParams:
    """The leg detector's parameters (``perception.legs``)."""
    return core_params(LegParams, mission.perception.legs)


def tracker_params(mission: Mission) -> TrackerParams:
    """The tracker's parameters (``tracking``)."""
    return core_params(TrackerParams, mission.tracking)


def belief_params(mission: Mission) -> BeliefParams:
    """The human belief's parameters (``belief``)."""
    return core_params(BeliefParams, mission.belief)


def face_timing(mission: Mission, robot: Literal["sim", "real"] = "sim") -> FaceTiming:
    """``perception.identity.face_timing`` with ``auto`` resolved: deterministic in the
    simulator (reproducible episodes), realtime on a real robot."""
    return resolve_face_timing(mission.perception.identity.face_timing, on_robot=robot == "real")


def identity_params(
    mission: Mission, robot: Literal["sim", "real"] = "sim", timing: FaceTiming | None = None
) -> IdentityParams:
    """The identification parameters (``perception.identity``); the face worker's timing for
    ``robot`` (see :func:`face_timing`) unless ``timing`` is given."""
    cfg = mission.perception.identity
    return core_params(
        IdentityParams,
        cfg,
        clothes=core_params(ClothesParams, cfg),
        face_timing=timing or face_timing(mission, robot),
    )


def build_perception(
    mission: Mission,
    *,
    detector: PersonDetector | None = None,
    profile: TargetProfile | None = None,
    belief_grid: tuple[GridGeometry, ArrayLike] | None = None,
    occupied: tuple[GridGeometry, ArrayLike] | None = None,
    leg_model: Path | None = None,
    face_worker: bool | FaceWorker = False,
    face_timing: FaceTiming | None = None,
    robot: Literal["sim", "real"] = "sim",
    handoff: bool = True,
) -> Perception:
    """The mission's perception: its leg model (``leg_model`` overrides
    ``perception.legs.model``; neither: the shipped model), tracker, and — when given — a
    camera ``detector``, a target ``profile`` to identify, and a human belief over
    ``belief_grid`` = (geometry, blocked mask); ``occupied`` = (geometry, the static map's
    occupied cells), where no leg counts (:class:`~pfctl.core.perception.pipeline.Perception`).

    ``face_worker``: True starts a :class:`~pfctl.core.perception.face_worker.FaceWorker` for the
    identifier's face searches (only with a ``profile`` that has faces), or pass one; False
    searches faces inline. Its timing is ``face_timing``, else the mission's for ``robot``; with
    ``realtime`` timing the worker runs at the lowest priority (nice 19, ``SCHED_IDLE``), with
    ``deterministic`` at the normal one (the loop waits for it). The perception then owns the
    worker: :meth:`Perception.close` stops it. ``handoff`` False: no one is handed off at
    the start (``perception.identity.handoff_s``; for ``pfctl search``, where she was never
    shown to the robot).
    """
    model = load_leg_model(leg_model or mission.perception.legs.model)
    identifier = None
    if profile is not None:
        params = identity_params(mission, robot, face_timing)
        if not handoff:
            params = replace(params, handoff_s=0.0)
        check_target_profile(profile, params)
        worker: FaceWorker | None = None
        if isinstance(face_worker, FaceWorker):
            worker = face_worker
        elif face_worker and params.faces and len(profile.faces) > 0:
            # realtime: the loop never waits for the worker, which runs in its idle time at the
            # lowest priority; deterministic: the loop waits for due results, so the worker must
            # not starve behind other processes (SCHED_IDLE would invert the priorities)
            realtime = params.face_timing == "realtime"
            worker = FaceWorker(params.face, nice=19 if realtime else 0, idle=realtime)
        identifier = TargetIdentifier(profile, params, worker=worker)
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
        occupied=None if occupied is None else (occupied[0], np.asarray(occupied[1], dtype=bool)),
    )


__all__ = [
    "belief_params",
    "build_perception",
    "face_timing",
    "identity_params",
    "leg_params",
    "tracker_params",
]
