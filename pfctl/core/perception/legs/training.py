"""Training and scoring the leg classifier: labelled segments, the forest, precision/recall.

The paper's leg detector is a random forest over segment features (§II-E; features of Arras et
al. 2007). Labelled segments come from two kinds of data:

- simulated scans with the true leg circles: a segment is a leg when most of its returns lie on
  a leg (:func:`label_by_circles`);
- real scans with labelled leg positions (the centres of the leg clusters, as the
  leg_tracker data set of Leigh et al. 2015 gives them): a segment is a leg when its centroid is
  within :data:`LABEL_RADIUS` of a label (:func:`label_by_positions`); every other segment of
  the scan is not.

:func:`train_forest` fits a seeded scikit-learn ``RandomForestClassifier`` (unweighted
classes: balanced weights in trees of limited depth called far too many segments legs) and
:func:`score` gives precision, recall and F1, optionally restricted to a band of ranges.
"""

from __future__ import annotations

import datetime
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from pfctl.core.perception.legs.detector import LegParams, describe_segments
from pfctl.core.perception.legs.evidence import LegEvidence
from pfctl.core.perception.legs.features import FEATURE_NAMES, Segments
from pfctl.core.perception.legs.model import LegModel
from pfctl.core.robot import LaserScan

#: A real segment is a leg when its centroid is this close to a labelled leg position, metres.
LABEL_RADIUS = 0.1
#: Unlabelled real segments this close to a labelled leg are left out (see label_by_positions).
IGNORE_RADIUS = 0.4
#: The label of a segment left out of training and scoring.
IGNORE = -1
#: A simulated return lies on a leg when it is this much farther from the axis than the radius.
ON_LEG_TOLERANCE = 0.03
#: Forest size and shape (30–50 trees of limited depth keep the shipped file small).
N_TREES = 32
MAX_DEPTH = 18
MIN_SAMPLES_LEAF = 3
#: The band of ranges the goals are stated for, metres.
EVAL_BAND = (0.5, 5.0)

_DISTANCE = FEATURE_NAMES.index("distance")


@dataclass
class LegDataset:
    """Labelled segments: features ``(n, f)``, labels ``(n,)`` (1 = leg), and the group each
    came from (``groups[group[i]]``: a bag, a topic, a simulated seed) for grouped validation."""

    name: str
    features: np.ndarray = field(default_factory=lambda: np.empty((0, len(FEATURE_NAMES))))
    labels: np.ndarray = field(default_factory=lambda: np.empty(0, dtype=np.int8))
    group: np.ndarray = field(default_factory=lambda: np.empty(0, dtype=np.int32))
    groups: list[str] = field(default_factory=list)
    scans: int = 0

    def __len__(self) -> int:
        return len(self.labels)

    @property
    def positives(self) -> int:
        return int(self.labels.sum())

    def add(self, group: str, features: np.ndarray, labels: np.ndarray, scans: int = 1) -> None:
        """Append segments of ``group`` (created on first use)."""
        if group not in self.groups:
            self.groups.append(group)
        g = self.groups.index(group)
        self.features = np.vstack([self.features, features])
        self.labels = np.concatenate([self.labels, np.asarray(labels, dtype=np.int8)])
        self.group = np.concatenate([self.group, np.full(len(labels), g, dtype=np.int32)])
        self.scans += scans

    def subset(self, mask: np.ndarray, name: str | None = None) -> LegDataset:
        """The segments where ``mask`` holds (groups kept by name)."""
        return LegDataset(
            name or self.name,
            self.features[mask],
            self.labels[mask],
            self.group[mask],
            list(self.groups),
            self.scans,
        )

    def without_group(self, name: str) -> LegDataset:
        """Every segment not from group ``name``."""
        if name not in self.groups:
            return self
        return self.subset(self.group != self.groups.index(name))

    def only_group(self, name: str) -> LegDataset:
        """The segments from group ``name``."""
        if name not in self.groups:
            return self.subset(np.zeros(len(self), dtype=bool), name)
        return self.subset(self.group == self.groups.index(name), name)


def concat(name: str, parts: list[LegDataset]) -> LegDataset:
    """One data set of several (groups renamed ``part/group``)."""
    out = LegDataset(name)
    for part in parts:
        for g, gname in enumerate(part.groups):
            m = part.group == g
            out.add(f"{part.name}/{gname}", part.features[m], part.labels[m], 0)
        out.scans += part.scans
    return out


def label_by_positions(centroids: np.ndarray, positions: np.ndarray) -> np.ndarray:
    """Labels ``(k,)`` int8 of segments by their centroid ``(k, 2)`` and labelled leg
    positions ``(m, 2)`` (same frame): 1 (leg) within :data:`LABEL_RADIUS` of a label,
    :data:`IGNORE` within :data:`IGNORE_RADIUS` of one (a piece of a labelled leg cut off by a
    different segmentation, or the unlabelled other leg of the same person: neither a fair
    positive nor a fair negative), 0 (not a leg) otherwise."""
    out = np.zeros(len(centroids), dtype=np.int8)
    pos = np.asarray(positions, dtype=float).reshape(-1, 2)
    if len(pos) == 0 or len(centroids) == 0:
        return out
    d = np.hypot(centroids[:, None, 0] - pos[None, :, 0], centroids[:, None, 1] - pos[None, :, 1])
    near = d.min(axis=1)
    out[near <= IGNORE_RADIUS] = IGNORE
    out[near <= LABEL_RADIUS] = 1
    return out


def label_by_circles(segments: Segments, pose: Any, circles: np.ndarray) -> np.ndarray:
    """Leg labels of segments most of whose returns lie on a leg circle ``[x, y, r]`` (map
    frame; ``pose`` is the laser's :class:`~pfctl.core.robot.Pose2D`): within ``r +``
    :data:`ON_LEG_TOLERANCE` of its axis."""
    k = len(segments)
    circles = np.asarray(circles, dtype=float).reshape(-1, 3)
    if len(circles) == 0 or k == 0:
        return np.zeros(k, dtype=bool)
    pts = pose.transform(segments.xy)
    d = np.hypot(pts[:, None, 0] - circles[None, :, 0], pts[:, None, 1] - circles[None, :, 1])
    on = (d <= circles[None, :, 2] + ON_LEG_TOLERANCE).any(axis=1)
    share = np.add.reduceat(on.astype(float), segments.start) / segments.count
    return share > 0.5


@dataclass(frozen=True)
class ScanSegments:
    """The segments of one scan that the detector classifies: features ``(k, f)``, labels
    ``(k,)`` (1 leg, 0 not, :data:`IGNORE` unlabelled) and centroids ``(k, 2)``, laser frame."""

    features: np.ndarray
    labels: np.ndarray
    xy: np.ndarray


def scan_segments(
    scan: LaserScan,
    params: LegParams,
    circles: np.ndarray | None = None,
    positions: np.ndarray | None = None,
    labelled_arc: tuple[float, float, float] | None = None,
) -> ScanSegments:
    """Every segment of one scan that the detector would classify (``min_points``,
    ``max_range``), labelled by true leg ``circles`` (map frame) or labelled leg ``positions``
    (laser frame; with ``labelled_arc`` ``(min_deg, max_deg, max_range)`` segments whose
    centroid lies outside the labelled part of the scan are :data:`IGNORE`); with neither,
    every segment is a non-leg."""
    segs, feats, ok = describe_segments(scan, params)
    cen = segs.centroids()
    if circles is not None:
        labels = label_by_circles(segs, scan.pose, circles).astype(np.int8)
    elif positions is not None:
        labels = label_by_positions(cen, positions)
        if labelled_arc is not None:
            lo, hi, far = labelled_arc
            bearing = np.degrees(np.arctan2(cen[:, 1], cen[:, 0]))
            inside = (bearing > lo) & (bearing < hi) & (np.hypot(*cen.T) < far)
            labels[~inside] = IGNORE
    else:
        labels = np.zeros(len(segs), dtype=np.int8)
    return ScanSegments(feats[ok], labels[ok], cen[ok])


def scan_samples(
    scan: LaserScan,
    params: LegParams,
    circles: np.ndarray | None = None,
    positions: np.ndarray | None = None,
    labelled_arc: tuple[float, float, float] | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Features and boolean labels of the labelled segments of :func:`scan_segments` (those
    labelled :data:`IGNORE` left out)."""
    s = scan_segments(scan, params, circles, positions, labelled_arc)
    keep = s.labels != IGNORE
    return s.features[keep], s.labels[keep] == 1


def train_forest(
    data: LegDataset,
    seed: int,
    n_trees: int = N_TREES,
    max_depth: int = MAX_DEPTH,
    metadata: dict[str, Any] | None = None,
) -> LegModel:
    """Fit a seeded ``RandomForestClassifier`` on ``data`` and return it as a :class:`LegModel`
    (metadata: sizes, seed, date, forest parameters, plus the caller's ``metadata``, e.g. the
    data sets and the pfctl version)."""
    from sklearn.ensemble import RandomForestClassifier

    if len(data) == 0 or data.positives == 0 or data.positives == len(data):
        raise ValueError("training needs both leg and non-leg segments")
    forest = RandomForestClassifier(
        n_estimators=n_trees,
        max_depth=max_depth,
        min_samples_leaf=MIN_SAMPLES_LEAF,
        class_weight=None,
        random_state=seed,
        n_jobs=-1,
    )
    forest.fit(data.features.astype(np.float32), data.labels)
    meta = {
        "seed": seed,
        "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "forest": {
            "n_estimators": n_trees,
            "max_depth": max_depth,
            "min_samples_leaf": MIN_SAMPLES_LEAF,
            "class_weight": None,
        },
        "segments": len(data),
        "legs": data.positives,
        "groups": list(data.groups),
    }
    meta.update(metadata or {})
    return LegModel.from_forest(forest, FEATURE_NAMES, meta)


@dataclass(frozen=True)
class Score:
    """Segment-level precision, recall and F1 (legs are the positive class)."""

    tp: int
    fp: int
    fn: int
    segments: int

    @property
    def precision(self) -> float:
        return self.tp / (self.tp + self.fp) if self.tp + self.fp else float("nan")

    @property
    def recall(self) -> float:
        return self.tp / (self.tp + self.fn) if self.tp + self.fn else float("nan")

    @property
    def f1(self) -> float:
        p, r = self.precision, self.recall
        return 2 * p * r / (p + r) if p + r > 0 else float("nan")

    def __add__(self, other: Score) -> Score:
        return Score(
            self.tp + other.tp,
            self.fp + other.fp,
            self.fn + other.fn,
            self.segments + other.segments,
        )


def score(
    labels: np.ndarray,
    probability: np.ndarray,
    threshold: float,
    distance: np.ndarray | None = None,
    band: tuple[float, float] | None = None,
) -> Score:
    """Counts of legs found (P ≥ ``threshold``) against ``labels``, only segments whose
    ``distance`` lies in ``band`` when given."""
    y = np.asarray(labels).astype(bool)
    hit = np.asarray(probability) >= threshold
    if band is not None and distance is not None:
        keep = (distance >= band[0]) & (distance <= band[1])
        y, hit = y[keep], hit[keep]
    return Score(int(np.sum(y & hit)), int(np.sum(~y & hit)), int(np.sum(y & ~hit)), len(y))


def evaluate_model(model: LegModel, data: LegDataset, threshold: float) -> tuple[Score, Score]:
    """(score in :data:`EVAL_BAND`, score at all ranges) of ``model`` on ``data``."""
    prob = model.predict_proba(data.features)
    dist = data.features[:, _DISTANCE]
    return (
        score(data.labels, prob, threshold, dist, EVAL_BAND),
        score(data.labels, prob, threshold),
    )


def evaluate_sequence(
    model: LegModel, scans: list[ScanSegments], threshold: float, history: int
) -> tuple[Score, Score]:
    """(score in :data:`EVAL_BAND`, score at all ranges) of ``model`` on a sequence of scans of
    one laser, each segment's P(leg) averaged over ``history`` scans of its track
    (:class:`~pfctl.core.perception.legs.evidence.LegEvidence`, in the laser frame: the bags carry
    no odometry, so a moving laser's segments are followed only as far as they stay within its
    radius between scans)."""
    evidence = LegEvidence(history)
    labels, prob, dist = [], [], []
    for s in scans:
        p = model.predict_proba(s.features) if len(s.features) else np.empty(0)
        p = evidence.update(s.xy, p)
        keep = s.labels != IGNORE
        labels.append(s.labels[keep] == 1)
        prob.append(p[keep])
        dist.append(s.features[keep, _DISTANCE])
    y, pr, d = (np.concatenate(a) if a else np.empty(0) for a in (labels, prob, dist))
    return score(y, pr, threshold, d, EVAL_BAND), score(y, pr, threshold)


__all__ = [
    "EVAL_BAND",
    "LABEL_RADIUS",
    "LegDataset",
    "ScanSegments",
    "Score",
    "concat",
    "evaluate_model",
    "evaluate_sequence",
    "label_by_circles",
    "label_by_positions",
    "scan_samples",
    "scan_segments",
    "score",
    "train_forest",
]
