"""The parameters of Algorithm 2 (§II-E): its thresholds, and how faces and clothes are measured
and when they are measured again (``perception.identity``)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

from pfctl.core.perception.clothes import ClothesParams
from pfctl.core.perception.faces import FaceParams

FaceTiming = Literal["deterministic", "realtime"]
"""When a face worker's results are folded in (:mod:`pfctl.core.perception.identity.identifier`)."""


@dataclass(frozen=True)
class IdentityParams:
    """Thresholds of Algorithm 2 and how appearances are measured (``perception.identity``)."""

    face_distance: float = 0.6
    """Face-embedding distance below which faces match (dlib's operating point)."""
    clothes_similarity: float = 0.6
    """Histogram intersection S at or above which clothes match."""
    clothes: ClothesParams = field(default_factory=ClothesParams)
    face: FaceParams = field(default_factory=FaceParams)
    faces: bool = True
    """Look for faces at all (False: clothes only, e.g. without dlib's models)."""
    face_settled: int = 3
    """A track with this many face samples is settled: its face is looked at again only every
    ``face_recheck_s`` (an embedding costs ~90 ms on one core; see benchmarks/bench_identity)."""
    face_recheck_s: float = 1.0
    """How often a settled track's face is embedded again, seconds."""
    face_miss_limit: int = 3
    """After this many face searches in a row found no face (the back of the head), the track
    is searched only every ``face_miss_backoff_s`` until a face is found again."""
    face_miss_backoff_s: float = 0.5
    """How often a track whose face searches keep missing is searched, seconds."""
    clothes_settled: int = 10
    """A track with this many clothes samples is settled when a face decides it or its mean
    similarity is at least ``clothes_margin`` from ``clothes_similarity``
    (:mod:`~pfctl.core.perception.identity.identifier`)."""
    clothes_margin: float = 0.15
    """How far from the threshold a settled track's mean clothes similarity is."""
    clothes_recheck_s: float = 0.5
    """How often a settled track's clothes are measured, seconds (0: every observation)."""
    face_timing: FaceTiming = "deterministic"
    """With a face worker: ``deterministic`` (simulator) or ``realtime`` (robot)."""
    face_latency_s: float = 0.1
    """With a face worker in ``deterministic`` timing: a search of the frame stamped t counts
    from the first observation stamped t + this (about what an embedding takes)."""


__all__ = ["FaceTiming", "IdentityParams"]
