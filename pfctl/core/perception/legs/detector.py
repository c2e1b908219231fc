"""Leg detection in the 2-D base laser and legs paired into person candidates (§II-E).

The paper finds people around the robot from its base laser: the scan is cut into segments,
each segment is described by geometric features and a random forest says whether it is a leg;
legs close together are one person. Here:

1. :func:`~pfctl.core.perception.legs.features.segment_scan` cuts the scan at jumps wider than
   ``jump_distance`` and at beams without return (Arras, Mozos, Burgard 2007, §III-A);
2. segments with at least ``min_points`` returns whose centroid is within ``max_range`` are
   described by :func:`~pfctl.core.perception.legs.features.segment_features` (Arras et al. 2007,
   §IV, plus the distance from the laser);
3. the forest (:class:`~pfctl.core.perception.legs.model.LegModel`, trained by ``pfctl legs train``)
gives
   P(leg), averaged over the last ``history_scans`` scans of the segment's track when that is
   more than 1 (:class:`~pfctl.core.perception.legs.evidence.LegEvidence`); segments with P ≥
   ``probability`` are legs — with ``static_after_s`` > 0, not those on the static scene (cells
   of the fixed frame seen occupied that long,
   :class:`~pfctl.core.perception.legs.static_scene.StaticScene`) unless beside a person already
   tracked;
4. :func:`pair_legs` matches legs closer than ``pair_distance`` two by two, closest pairs first
   (greedy matching by distance), into person candidates at the midpoint; a leg left alone
   with P ≥ ``single_leg_probability`` is a candidate too (a person with one leg occluded), with
   its confidence halved; the other lone legs are reported apart (``lone_legs``);
5. with ``weak_probability`` < 1 (dual thresholds), the segments with P ≥ ``weak_probability``
   that made no candidate are paired the same way into weak candidates (``weak``), which may
   keep a track going but not start one
   (:class:`~pfctl.core.perception.tracking.Detection`'s ``spawn``).

Legs and people are reported in the map frame (through ``scan.pose``). A leg's position is its
segment's centroid moved :data:`LEG_DEPTH` farther along the beam: the laser sees the front of
the leg, its axis is behind.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from pfctl.core.params import param
from pfctl.core.perception.legs.evidence import LegEvidence
from pfctl.core.perception.legs.features import (
    FEATURE_NAMES,
    Segments,
    segment_features,
    segment_scan,
)
from pfctl.core.perception.legs.model import LegModel
from pfctl.core.perception.legs.static_scene import StaticScene
from pfctl.core.robot import LaserScan

#: From a leg's visible surface to its axis along the beam, metres (≈ 0.75 × a 6 cm leg radius:
#: the centroid of the visible half of a circle sampled evenly across).
LEG_DEPTH = 0.045
#: A candidate from one leg gets this fraction of the leg's probability.
SINGLE_LEG_FACTOR = 0.5
#: A segment whose centroid is this close to a tracked person is that person's: never static
#: scene, and its returns are not folded into the scene, m.
TRACKED_RADIUS = 0.5
_DISTANCE = FEATURE_NAMES.index("distance")


@dataclass(frozen=True)
class LegParams:
    """Detector parameters (the mission's ``perception.legs``)."""

    probability: float = param(
        0.5, "P(leg), the random forest's score, at or above which a segment is a leg.", gt=0, lt=1
    )
    jump_distance: float = param(
        0.13,
        "A segment ends where two neighbouring returns are farther apart than this.",
        unit="m",
        gt=0,
    )
    min_points: int = param(3, "Segments with fewer returns are not classified.", ge=2)
    max_range: float = param(
        6.0,
        "Segments whose centroid is farther from the laser than this are not classified.",
        unit="m",
        gt=0,
    )
    pair_distance: float = param(
        0.45, "Two legs closer than this form one person candidate.", unit="m", gt=0
    )
    single_leg_probability: float = 0.8
    """A leg without a partner is still a person candidate when its P(leg) is at least this."""
    lone_leg_probability: float = 0.25
    """A segment that made no candidate is a lone leg (:attr:`LegDetections.lone_legs`) when
    its P(leg) is at least this, also below ``probability``: beside a person the camera sees it
    is that person's, and the camera's detection is the evidence the forest's score lacks (a
    target standing side-on shows one segment for both legs, scored about 0.3-0.6)."""
    weak_probability: float = param(
        1.0,
        "Dual thresholds: a segment with at least this P(leg) that made no person candidate"
        " (below ``probability``, or a lone leg below ``single_leg_probability``) is a weak"
        " candidate, paired with a weak neighbour as legs are: it may update the track of a"
        " person already tracked but never starts one (1: off).",
        gt=0,
        le=1,
    )
    history_scans: int = param(
        10,
        "P(leg) of a segment is averaged over this many scans of its track (1: each scan alone).",
        ge=1,
        le=100,
    )
    static_after_s: float = param(
        0.0,
        "Segments on cells of the fixed frame that the laser has seen occupied for this long"
        " (walls, furniture: the static scene) are no legs, unless beside a tracked person"
        " (0: off).",
        unit="s",
        ge=0,
    )


@dataclass(frozen=True)
class Leg:
    """A detected leg in the map frame and its P(leg)."""

    x: float
    y: float
    probability: float


@dataclass(frozen=True)
class PersonCandidate:
    """A person seen by the laser: the midpoint of two legs (or one leg), map frame."""

    x: float
    y: float
    probability: float
    legs: tuple[Leg, ...]


@dataclass(frozen=True)
class LegDetections:
    """The legs and person candidates of one scan."""

    stamp: float
    legs: tuple[Leg, ...]
    people: tuple[PersonCandidate, ...]
    lone_legs: tuple[Leg, ...] = ()
    """The leg segments that made no candidate: legs with no partner within ``pair_distance``
    and P(leg) below ``single_leg_probability``, and segments scored from
    ``lone_leg_probability`` up to ``probability`` — one segment of a person standing side-on,
    or clutter (a table's leg). Alone they are no one; the perception counts one beside a
    person the camera sees (:class:`~pfctl.core.perception.pipeline.Perception`)."""
    weak: tuple[PersonCandidate, ...] = ()
    """Weak candidates (``weak_probability``): segments that made no candidate, paired as legs
    are; the tracker lets them update a track but not start one."""


@dataclass(frozen=True)
class ClassifiedSegments:
    """Every segment of a scan with what the detector made of it (for evaluation and plots).

    ``classified`` marks segments that passed ``min_points`` and ``max_range``; ``probability``
    is P(leg) for those and 0 for the others; ``features`` has a row per segment (laser frame).
    """

    segments: Segments
    features: np.ndarray
    classified: np.ndarray
    probability: np.ndarray


def describe_segments(
    scan: LaserScan, params: LegParams
) -> tuple[Segments, np.ndarray, np.ndarray]:
    """Segments of the scan, their features ``(k, f)`` and which of them the detector classifies
    (at least ``min_points`` returns, centroid within ``max_range``)."""
    segs = segment_scan(
        scan.ranges,
        scan.angle_min,
        scan.angle_increment,
        scan.range_min,
        scan.range_max,
        params.jump_distance,
    )
    feats = segment_features(segs)
    ok = (segs.count >= params.min_points) & (feats[:, _DISTANCE] <= params.max_range)
    return segs, feats, ok


def classify_segments(scan: LaserScan, model: LegModel, params: LegParams) -> ClassifiedSegments:
    """Segment the scan, compute the features and P(leg) of every segment that qualifies."""
    segs, feats, ok = describe_segments(scan, params)
    prob = np.zeros(len(segs))
    if ok.any():
        prob[ok] = model.predict_proba(feats[ok])
    return ClassifiedSegments(segs, feats, ok, prob)


def pair_legs(xy: np.ndarray, probability: np.ndarray, params: LegParams) -> list[tuple[int, ...]]:
    """Group legs into people: pairs closer than ``pair_distance``, closest first (greedy
    matching by distance), then each unmatched leg with P ≥ ``single_leg_probability`` alone.
    Returns tuples of leg indices."""
    n = len(xy)
    groups: list[tuple[int, ...]] = []
    used = np.zeros(n, dtype=bool)
    if n >= 2:
        d = np.hypot(xy[:, None, 0] - xy[None, :, 0], xy[:, None, 1] - xy[None, :, 1])
        i, j = np.triu_indices(n, 1)
        close = d[i, j] < params.pair_distance
        i, j, dist = i[close], j[close], d[i, j][close]
        for k in np.argsort(dist, kind="stable"):
            a, b = int(i[k]), int(j[k])
            if not used[a] and not used[b]:
                used[a] = used[b] = True
                groups.append((a, b))
    for a in range(n):
        if not used[a] and probability[a] >= params.single_leg_probability:
            groups.append((a,))
    return groups


class LegDetector:
    """Laser leg detector (§II-E): ``detect(scan)`` → legs and person candidates, map frame.

    With ``history_scans`` > 1 it remembers the segments of the previous scans (one detector per
    laser; :meth:`reset` between unrelated sequences)."""

    def __init__(self, model: LegModel, params: LegParams | None = None) -> None:
        self.model = model
        self.params = params or LegParams()
        self.evidence = (
            LegEvidence(self.params.history_scans) if self.params.history_scans > 1 else None
        )
        self.scene = (
            StaticScene(self.params.static_after_s) if self.params.static_after_s > 0 else None
        )

    def reset(self) -> None:
        """Forget the segments and the scene of earlier scans."""
        if self.evidence is not None:
            self.evidence.reset()
        if self.scene is not None:
            self.scene.reset()

    def detect(self, scan: LaserScan, tracked: np.ndarray | None = None) -> LegDetections:
        """Legs (P ≥ ``probability``) and the people they make in one scan, and the lone legs
        (:attr:`LegDetections.lone_legs`). ``tracked``: where the people already tracked are
        ``(k, 2)``, map frame — with ``static_after_s`` their segments are never static scene
        (:mod:`~pfctl.core.perception.legs.static_scene`)."""
        c = classify_segments(scan, self.model, self.params)
        if self.evidence is not None:
            seen = np.flatnonzero(c.classified)
            where = scan.pose.transform(c.segments.centroids()[seen])
            c.probability[seen] = self.evidence.update(where, c.probability[seen])
        if self.scene is not None:
            self._drop_static(scan, c, tracked)
        low = min(
            self.params.probability, self.params.lone_leg_probability, self.params.weak_probability
        )
        idx = np.flatnonzero(c.classified & (c.probability >= low))
        if len(idx) == 0:
            return LegDetections(scan.stamp, (), ())
        local = c.segments.centroids()[idx]
        rng = np.maximum(np.hypot(*local.T), 1e-9)
        local = local * ((rng + LEG_DEPTH) / rng)[:, None]
        found = scan.pose.transform(local)
        p_found = c.probability[idx]
        is_leg = p_found >= self.params.probability
        world, prob = found[is_leg], p_found[is_leg]
        legs = tuple(
            Leg(float(x), float(y), float(p)) for (x, y), p in zip(world, prob, strict=True)
        )
        people = []
        groups = pair_legs(world, prob, self.params)
        grouped = {g for group in groups for g in group}
        for group in groups:
            pts = world[list(group)]
            p = float(prob[list(group)].mean())
            if len(group) == 1:
                p *= SINGLE_LEG_FACTOR
            mid = pts.mean(axis=0)
            people.append(
                PersonCandidate(float(mid[0]), float(mid[1]), p, tuple(legs[g] for g in group))
            )
        lone = [leg for i, leg in enumerate(legs) if i not in grouped]
        lone += [
            Leg(float(x), float(y), float(p))
            for (x, y), p in zip(found[~is_leg], p_found[~is_leg], strict=True)
            if p >= self.params.lone_leg_probability
        ]
        weak = self._weak_candidates(found, p_found, np.flatnonzero(is_leg)[list(grouped)])
        return LegDetections(scan.stamp, legs, tuple(people), tuple(lone), weak)

    def _weak_candidates(
        self, xy: np.ndarray, probability: np.ndarray, used: np.ndarray
    ) -> tuple[PersonCandidate, ...]:
        """The weak candidates (``weak_probability``) among the segments at ``xy`` with
        ``probability`` not ``used`` by a candidate: paired as :func:`pair_legs` pairs legs,
        every one left alone a candidate too (with half its P(leg), as a lone leg)."""
        if self.params.weak_probability >= 1.0:
            return ()
        free = np.ones(len(xy), dtype=bool)
        free[used.astype(np.intp)] = False
        idx = np.flatnonzero(free & (probability >= self.params.weak_probability))
        if len(idx) == 0:
            return ()
        pts, prob = xy[idx], probability[idx]
        out = []
        for group in pair_legs(pts, prob, replace(self.params, single_leg_probability=0.0)):
            g = list(group)
            p = float(prob[g].mean()) * (SINGLE_LEG_FACTOR if len(g) == 1 else 1.0)
            mid = pts[g].mean(axis=0)
            legs = tuple(
                Leg(float(x), float(y), float(q)) for (x, y), q in zip(pts[g], prob[g], strict=True)
            )
            out.append(PersonCandidate(float(mid[0]), float(mid[1]), p, legs))
        return tuple(out)

    def _drop_static(
        self, scan: LaserScan, c: ClassifiedSegments, tracked: np.ndarray | None
    ) -> None:
        """P(leg) = 0 for the segments on the static scene, then the scan folded into it (the
        returns of segments beside ``tracked`` people left out of both)."""
        assert self.scene is not None
        segs = c.segments
        near = np.zeros(len(segs), dtype=bool)
        if tracked is not None and len(tracked) and len(segs):
            centres = scan.pose.transform(segs.centroids())
            pts = np.asarray(tracked, dtype=float).reshape(-1, 2)
            d = np.hypot(
                centres[:, None, 0] - pts[None, :, 0], centres[:, None, 1] - pts[None, :, 1]
            )
            near = (d < TRACKED_RADIUS).any(axis=1)
        if len(segs):
            static = self.scene.static_segments(
                scan.pose.transform(segs.xy), segs.start, segs.count
            )
            c.probability[static & ~near] = 0.0
        keep_out = np.zeros(len(scan.ranges), dtype=bool)
        if near.any():
            keep_out[segs.beam[np.repeat(near, segs.count)]] = True
        self.scene.update(scan, keep_out)


__all__ = [
    "LEG_DEPTH",
    "TRACKED_RADIUS",
    "ClassifiedSegments",
    "Leg",
    "LegDetections",
    "LegDetector",
    "LegParams",
    "PersonCandidate",
    "classify_segments",
    "describe_segments",
    "pair_legs",
]
