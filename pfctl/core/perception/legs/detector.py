"""Leg detection in the 2-D base laser and legs paired into person candidates (§II-E).

The paper finds people around the robot from its base laser: the scan is cut into segments,
each segment is described by geometric features and a random forest says whether it is a leg;
legs close together are one person. Here:

1. :func:`~pfctl.core.perception.legs.features.segment_scan` cuts the scan at jumps wider than
   ``jump_distance`` and at beams without return (Arras, Mozos, Burgard 2007, §III-A);
2. segments with at least ``min_points`` returns, at most ``max_width`` wide (no leg is wider:
   the widest of the legs labelled in the real bags is 0.48 m, and the forest scores the real
   segments wider than 0.6 m below 0.05), whose centroid is within ``max_range`` are
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

from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from pfctl.core.params import param
from pfctl.core.perception.legs.evidence import LegEvidence
from pfctl.core.perception.legs.features import (
    Segments,
    segment_features,
    segment_scans,
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
    max_width: float = param(
        0.8,
        "Segments wider than this (first to last return) are not classified: no leg.",
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
    (at least ``min_points`` returns, at most ``max_width`` wide, centroid within
    ``max_range``). The shape features are computed for those only (zeros for the others)."""
    return describe_scans([scan], params)[0]


def describe_scans(
    scans: Sequence[LaserScan], params: LegParams
) -> list[tuple[Segments, np.ndarray, np.ndarray]]:
    """:func:`describe_segments` of several scans, segmented and described in one pass
    (:func:`~pfctl.core.perception.legs.features.segment_scans`)."""
    if not scans:
        return []
    joined = segment_scans(scans, params.jump_distance)
    ok = (
        (joined.count >= params.min_points)
        & (joined.widths() <= params.max_width)
        & (np.hypot(*joined.centroids().T) <= params.max_range)
    )
    feats = segment_features(joined, shape=np.flatnonzero(ok))
    return [(segs, feats[rows], ok[rows]) for rows, segs in joined.split(len(scans))]


def classify_segments(scan: LaserScan, model: LegModel, params: LegParams) -> ClassifiedSegments:
    """Segment the scan, compute the features and P(leg) of every segment that qualifies."""
    return classify_scans([scan], model, params)[0]


def classify_scans(
    scans: Sequence[LaserScan], model: LegModel, params: LegParams
) -> list[ClassifiedSegments]:
    """:func:`classify_segments` of several scans: one pass of features and one forest call for
    all (each scan's segments alone are a few dozen rows, and most of the cost of either is a
    fixed one per call)."""
    described = describe_scans(scans, params)
    rows = [feats[ok] for _, feats, ok in described]
    probs = model.predict_proba(np.concatenate(rows)) if sum(map(len, rows)) else np.empty(0)
    out, at = [], 0
    for (segs, feats, ok), r in zip(described, rows, strict=True):
        prob = np.zeros(len(segs))
        prob[ok] = probs[at : at + len(r)]
        at += len(r)
        out.append(ClassifiedSegments(segs, feats, ok, prob))
    return out


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


def _legs(xy: np.ndarray, probability: np.ndarray) -> tuple[Leg, ...]:
    """A :class:`Leg` per row of ``xy`` ``(n, 2)`` with its ``probability``."""
    return tuple(Leg(x, y, p) for (x, y), p in zip(xy.tolist(), probability.tolist(), strict=True))


def _candidates(
    xy: np.ndarray, probability: np.ndarray, groups: list[tuple[int, ...]], legs: tuple[Leg, ...]
) -> list[PersonCandidate]:
    """The person candidate of each group of :func:`pair_legs` (indices into ``xy``,
    ``probability`` and ``legs``): at the midpoint of a pair with its mean P(leg), or at a lone
    leg with :data:`SINGLE_LEG_FACTOR` of its P(leg)."""
    if not groups:
        return []
    first = np.fromiter((g[0] for g in groups), np.intp, len(groups))
    last = np.fromiter((g[-1] for g in groups), np.intp, len(groups))
    mid = ((xy[first] + xy[last]) / 2).tolist()
    p = (probability[first] + probability[last]) / 2
    p = np.where(first == last, p * SINGLE_LEG_FACTOR, p).tolist()
    return [
        PersonCandidate(x, y, q, tuple(legs[i] for i in g))
        for (x, y), q, g in zip(mid, p, groups, strict=True)
    ]


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

    def classify(self, scans: Sequence[LaserScan]) -> list[ClassifiedSegments]:
        """The segments of ``scans`` classified in one pass (:func:`classify_scans`), each to be
        handed to :meth:`detect` with its scan, in order: what a tick's scans cost at once."""
        return classify_scans(scans, self.model, self.params)

    def detect(
        self,
        scan: LaserScan,
        tracked: np.ndarray | None = None,
        classified: ClassifiedSegments | None = None,
    ) -> LegDetections:
        """Legs (P ≥ ``probability``) and the people they make in one scan, and the lone legs
        (:attr:`LegDetections.lone_legs`). ``tracked``: where the people already tracked are
        ``(k, 2)``, map frame — with ``static_after_s`` their segments are never static scene
        (:mod:`~pfctl.core.perception.legs.static_scene`). ``classified``: this scan's segments
        as :meth:`classify` gave them (None: classified here)."""
        if classified is None:
            c = classify_segments(scan, self.model, self.params)
        else:  # P(leg) is revised below: the caller's copy stays as classified
            c = replace(classified, probability=classified.probability.copy())
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
        legs = _legs(world, prob)
        groups = pair_legs(world, prob, self.params)
        people = _candidates(world, prob, groups, legs)
        grouped = {g for group in groups for g in group}
        lone = [leg for i, leg in enumerate(legs) if i not in grouped]
        p_lone = p_found[~is_leg]
        near_leg = p_lone >= self.params.lone_leg_probability
        lone += _legs(found[~is_leg][near_leg], p_lone[near_leg])
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
        groups = pair_legs(pts, prob, replace(self.params, single_leg_probability=0.0))
        return tuple(_candidates(pts, prob, groups, _legs(pts, prob)))

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
    "classify_scans",
    "classify_segments",
    "describe_scans",
    "describe_segments",
    "pair_legs",
]
