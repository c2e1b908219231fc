"""The parameters of Algorithm 2 (§II-E): its thresholds, and how faces and clothes are measured
and when they are measured again (``perception.identity``)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

from pfctl.core.params import param
from pfctl.core.perception.clothes import ClothesParams
from pfctl.core.perception.faces import FaceParams
from pfctl.core.perception.identity.log_odds import LogOddsWeights

FaceTiming = Literal["deterministic", "realtime"]
"""When a face worker's results are folded in (:mod:`pfctl.core.perception.identity.identifier`)."""
FaceTimingSetting = Literal["auto", "deterministic", "realtime"]
""":data:`FaceTiming`, or ``auto``: ``deterministic`` in the simulator, ``realtime`` on a robot
(:func:`resolve_face_timing`)."""


@dataclass(frozen=True)
class IdentityParams:
    """Thresholds of Algorithm 2 and how appearances are measured (``perception.identity``)."""

    face_distance: float = param(
        0.6, "Face-embedding distance below which two faces match (dlib's operating point).", gt=0
    )
    clothes_similarity: float = param(
        0.6, "Histogram intersection S at or above which clothes match.", ge=0, le=1
    )
    clothes: ClothesParams = field(default_factory=ClothesParams)
    face: FaceParams = field(default_factory=FaceParams)
    faces: bool = True
    """Look for faces at all (False: clothes only, e.g. without dlib's models)."""
    face_settled: int = 3
    """A track with this many face samples is settled: its face is looked at again only every
    ``face_recheck_s`` (an embedding is the costliest step of Algorithm 2;
    benchmarks/bench_identity.py measures it)."""
    face_recheck_s: float = 1.0
    """How often a settled track's face is embedded again, seconds."""
    face_recent: int = param(
        5,
        "A track's face evidence is the median distance of its newest this many face samples"
        " (a track swapped onto someone else shows it within a few faces).",
        ge=1,
    )
    min_face_px: int = param(
        12,
        "Faces less than this many pixels high (far from the camera) are too coarse to tell her"
        " from others and are not used as evidence. In the simulator at 320x240, her own face"
        " 4 m away (10-11 px) lies 0.56-0.66 from her profile, at 2.4-3.2 m (14-18 px) 0.3-0.4.",
        unit="px",
        ge=0,
    )
    face_miss_limit: int = param(
        3,
        "After this many face searches of a track in a row found no face (the back of the head),"
        " its face is searched only every ``face_miss_backoff_s`` until one is found again.",
        ge=1,
    )
    face_miss_backoff_s: float = param(
        0.5, "How often a track whose face searches keep missing is searched again.", unit="s", ge=0
    )
    clothes_settled: int = 10
    """A track with this many clothes samples is settled when a face decides it or its mean
    similarity is at least ``clothes_margin`` from ``clothes_similarity``
    (:mod:`~pfctl.core.perception.identity.identifier`)."""
    clothes_margin: float = 0.15
    """How far from the threshold a settled track's clothes similarity (the median of its
    newest ``clothes_recent`` samples) is."""
    clothes_recheck_s: float = 0.5
    """How often a settled track's clothes are measured, seconds (0: every observation)."""
    face_timing: FaceTimingSetting = param(
        "auto",
        "When a face worker's results count: ``deterministic`` (a search of the frame at t counts"
        " from t + ``face_latency_s``, waiting for the worker if needed: reproducible episodes),"
        " ``realtime`` (whatever has come back, never wait), ``auto``: deterministic in the"
        " simulator, realtime on a robot.",
    )
    face_latency_s: float = param(
        0.1,
        "Deterministic timing: the latency of a face search (about one embedding).",
        unit="s",
        ge=0,
    )

    weights: LogOddsWeights = field(default_factory=LogOddsWeights)
    """How much each cue moves a track's log-odds of being the target
    (:mod:`~pfctl.core.perception.identity.log_odds`)."""
    confirm_frames: int = param(
        5,
        "A new track is named the target without a face match only after this many camera"
        " frames in a row at the accepting log-odds (OCL-RPF's confirmation).",
        ge=1,
    )
    confirm_s: float = param(
        2.0,
        "... and over at least this long (time for the robot to go and see the face).",
        unit="s",
        ge=0,
    )
    face_to_rename: bool = param(
        True,
        "Once she has been named, a track that never held her name is named only on her face"
        " (or as the track that took her on from hers): someone in her clothes whom the robot"
        " has not seen yet may be about at any time, and no one is followed on clothes alone."
        " False: also on her clothes, confirmed over ``confirm_frames`` and ``confirm_s``, while"
        " no look-alike is known to be about — she is found sooner where no one dresses like"
        " her and the robot cannot ask her to turn (no voice), at the risk of following a"
        " look-alike it has not seen yet.",
    )
    doubt_s: float = param(
        1.0,
        "A named track whose belief stays below the accepting log-odds this long (a face that"
        " does not quite match, clothes that stopped matching) loses the name: she is lost"
        " rather than followed on doubt.",
        unit="s",
        ge=0,
    )
    handoff_s: float = param(
        3.0,
        "Hand-off at the start of a run: within this long of the first frame, the one person"
        " tracked within ``handoff_range`` of the camera (seen by it, legs tracked, in her"
        " clothes, no face of someone else) is the person the robot was just shown, and is named"
        " at once, look-alikes about or not (0: never; ``pfctl search``, where she was never"
        " shown, does not hand off).",
        unit="s",
        ge=0,
    )
    handoff_range: float = param(
        2.5,
        "... the distance from the camera within which she stands to be handed off; a second"
        " person tracked that close at any time in the window makes it ambiguous: no hand-off.",
        unit="m",
        gt=0,
    )
    clothes_recent: int = param(
        5,
        "A track's clothes evidence is the median similarity of its newest this many samples"
        " (a track the tracker slid onto someone else shows it within a few samples).",
        ge=1,
    )
    look_alike_memory_s: float = param(
        120.0,
        "After a person in her clothes was found not to be her (by face, or seen beside her or"
        " farther off than she can have walked since she was last tracked, or two people in her"
        " clothes were tracked apart at once), her clothes are no evidence"
        " for this long (a look-alike is about).",
        unit="s",
        ge=0,
    )
    coexist_distance: float = param(
        1.0,
        "A person tracked this far or farther from her face-confirmed track at the same time is"
        " not her.",
        unit="m",
        gt=0,
    )
    swap_distance: float = param(
        0.6,
        "Another person this close to her named track, where the camera cannot tell them apart"
        " (in her clothes, or her track out of the camera's view), may have been swapped with"
        " her by the tracker: the name goes.",
        unit="m",
        gt=0,
    )
    update_clearance: float = param(
        1.0,
        "Her appearance model learns from a frame only when no other person is this close.",
        unit="m",
        ge=0,
    )
    update_rate: float = param(
        0.1,
        "How much one frame moves her online appearance model (0: never learn online).",
        ge=0,
        le=1,
    )

    @property
    def timing(self) -> FaceTiming:
        """``face_timing`` as the identifier applies it: ``auto`` is ``deterministic`` there,
        since the identifier knows no robot (the app resolves ``auto`` for a real one first,
        :func:`resolve_face_timing`)."""
        return "realtime" if self.face_timing == "realtime" else "deterministic"


def resolve_face_timing(setting: FaceTimingSetting, on_robot: bool) -> FaceTiming:
    """``setting`` with ``auto`` resolved: ``deterministic`` in the simulator (reproducible
    episodes), ``realtime`` on a real robot (the loop never waits for the worker)."""
    if setting == "auto":
        return "realtime" if on_robot else "deterministic"
    return setting


__all__ = ["FaceTiming", "FaceTimingSetting", "IdentityParams", "resolve_face_timing"]
