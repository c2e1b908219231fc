"""Laser segments and their geometric features for leg detection (§II-E).

The paper detects legs in the 2-D base laser "from segments of the scan described by geometric
features and classified by a random forest"; the features are those of Arras, Mozos and Burgard,
"Using Boosted Features for the Detection of People in 2D Range Data" (ICRA 2007), plus the
segment's distance from the laser (the point density of a leg falls with range) and three
features of its surroundings: the nearest other leg-sized segment and the clutter around.

:func:`segment_scan` splits a scan at jumps (Arras et al. 2007, §III-A: "jump distance
condition"); :func:`segment_features` computes every feature of every segment in one vectorised
pass (no Python loop over segments).

All coordinates are in the laser's own frame (x ahead, y left); beams are in scan order (CCW).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from pfctl.core.robot import LaserScan

#: Feature order of :func:`segment_features` (the columns of its matrix). A leg model stores
#: the names it was trained with and is refused when they differ (``leg_model``).
FEATURE_NAMES: tuple[str, ...] = (
    "points",
    "std_centroid",
    "mad_median",
    "jump_preceding",
    "jump_succeeding",
    "width",
    "linearity",
    "circularity",
    "radius",
    "boundary_length",
    "boundary_regularity",
    "mean_curvature",
    "mean_angular_difference",
    "distance",
    "partner_distance",
    "partner_width",
    "neighbours",
)

#: Jumps to a neighbour farther than this (or with no neighbour at all) are reported as this, m.
MAX_JUMP = 3.0
#: Fitted circle radii are clipped to this (a straight segment has an unbounded radius), m.
MAX_RADIUS = 3.0
#: A possible other leg: a segment of at least this many returns ...
PARTNER_MIN_POINTS = 3
#: ... and at most this wide, m.
PARTNER_MAX_WIDTH = 0.3
#: ``neighbours`` counts the other segments whose centroid is this close, m.
NEIGHBOUR_RADIUS = 1.0


@dataclass(frozen=True)
class Segments:
    """The segments of one scan: returns ``xy`` ``(n, 2)`` (laser frame, scan order) and each
    segment's first index ``start`` and length ``count`` into them, plus the beam index of every
    return (``beam``). Segments of several scans, one scan after the other
    (:func:`segment_scans`), carry each segment's scan index in ``scan``."""

    xy: np.ndarray
    beam: np.ndarray
    start: np.ndarray
    count: np.ndarray
    scan: np.ndarray | None = None
    """``(k,)``: the scan of each segment (0, 1, …), or None: all of one scan."""

    def __len__(self) -> int:
        return len(self.start)

    def points(self, k: int) -> np.ndarray:
        """The returns ``(m, 2)`` of segment ``k``."""
        s = int(self.start[k])
        return self.xy[s : s + int(self.count[k])]

    def centroids(self) -> np.ndarray:
        """Each segment's mean point ``(k, 2)``, laser frame."""
        if len(self.start) == 0:
            return np.empty((0, 2))
        return np.add.reduceat(self.xy, self.start, axis=0) / self.count[:, None]

    def widths(self) -> np.ndarray:
        """Each segment's width ``(k,)``: from its first return to its last, m."""
        last = self.start + self.count - 1
        return np.hypot(*(self.xy[last] - self.xy[self.start]).T)

    def subset(self, which: np.ndarray) -> Segments:
        """The segments at the indices ``which`` (ascending), with only their returns."""
        count = self.count[which]
        if len(count) == len(self.count):
            return self
        total = int(count.sum())
        start = np.concatenate(([0], np.cumsum(count)[:-1])).astype(np.intp)
        rows = np.arange(total) + np.repeat(self.start[which] - start, count)
        scan = None if self.scan is None else self.scan[which]
        return Segments(self.xy[rows], self.beam[rows], start, count, scan)

    def split(self, scans: int) -> list[tuple[slice, Segments]]:
        """Per scan of ``scans``: which of these segments are its (a slice) and its segments
        alone, as :func:`segment_scan` gives them."""
        if self.scan is None:
            return [(slice(0, len(self)), self)]
        bounds = np.concatenate(([0], np.cumsum(np.bincount(self.scan, minlength=scans))))
        ends = np.append(self.start, len(self.xy))
        out = []
        for a, b in zip(bounds[:-1].tolist(), bounds[1:].tolist(), strict=True):
            p, q = int(ends[a]), int(ends[b])
            segs = Segments(self.xy[p:q], self.beam[p:q], self.start[a:b] - p, self.count[a:b])
            out.append((slice(a, b), segs))
        return out


def valid_returns(
    ranges: np.ndarray, range_min: float | np.ndarray, range_max: float | np.ndarray
) -> np.ndarray:
    """Which beams returned: finite and within ``[range_min, range_max]`` (REP-117; real drivers
    also write 0 or −inf for no return)."""
    r = np.asarray(ranges, dtype=float)
    with np.errstate(invalid="ignore"):
        return np.isfinite(r) & (r >= np.maximum(range_min, 1e-6)) & (r <= range_max)


def segment_scan(
    ranges: np.ndarray,
    angle_min: float,
    angle_increment: float,
    range_min: float,
    range_max: float,
    jump_distance: float,
) -> Segments:
    """Split a scan into segments (Arras et al. 2007, §III-A).

    Consecutive returns belong to the same segment while the Euclidean distance between them is
    below ``jump_distance``; beams with no return (``inf``, NaN, 0, out of range) are skipped,
    not a break, as in leg_tracker's clustering (Leigh et al. 2015, ``laser_processor.cpp``:
    real lasers drop single returns on dark cloth, and cutting a leg there gives segments that
    match far fewer of the leg clusters labelled in its bags). Every return
    is in exactly one segment (segments of one point included; the detector drops the short
    ones).
    """
    return _segment(
        np.asarray(ranges, dtype=float),
        None,
        angle_min,
        angle_increment,
        range_min,
        range_max,
        jump_distance,
    )


def segment_scans(scans: Sequence[LaserScan], jump_distance: float) -> Segments:
    """:func:`segment_scan` of several scans in one pass: their segments one scan after the
    other, each segment's scan in :attr:`Segments.scan` (a segment never spans two scans).
    :meth:`Segments.split` gives each scan's segments as :func:`segment_scan` would."""
    sizes = [len(s.ranges) for s in scans]
    scan = np.repeat(np.arange(len(scans)), sizes)

    def per_beam(values: list[float]) -> np.ndarray:
        return np.asarray(values, dtype=float)[scan]

    return _segment(
        np.concatenate([np.asarray(s.ranges, dtype=float) for s in scans]),
        scan,
        per_beam([s.angle_min for s in scans]),
        per_beam([s.angle_increment for s in scans]),
        per_beam([s.range_min for s in scans]),
        per_beam([s.range_max for s in scans]),
        jump_distance,
        offsets=np.cumsum([0, *sizes[:-1]]),
    )


def _segment(
    r: np.ndarray,
    scan: np.ndarray | None,
    angle_min: float | np.ndarray,
    angle_increment: float | np.ndarray,
    range_min: float | np.ndarray,
    range_max: float | np.ndarray,
    jump_distance: float,
    offsets: np.ndarray | None = None,
) -> Segments:
    """Segments of the beams ``r`` of one scan (``scan`` None, the parameters scalars) or of
    several scans joined (``scan``: each beam's scan, the parameters per beam, ``offsets``:
    each scan's first beam in ``r``); a new scan always starts a new segment."""
    flat = np.flatnonzero(valid_returns(r, range_min, range_max))
    if scan is None:
        beam, a = flat, angle_min + angle_increment * flat
    else:
        assert offsets is not None
        beam = flat - offsets[scan[flat]]
        a = np.asarray(angle_min)[flat] + np.asarray(angle_increment)[flat] * beam
    xy = np.column_stack((r[flat] * np.cos(a), r[flat] * np.sin(a)))
    if len(flat) == 0:
        empty = np.empty(0, dtype=np.intp)
        return Segments(xy, beam, empty, empty, None if scan is None else empty)
    jump = np.hypot(*np.diff(xy, axis=0).T) >= jump_distance
    if scan is not None:
        jump |= scan[flat[1:]] != scan[flat[:-1]]
    breaks = np.flatnonzero(jump) + 1
    start = np.concatenate(([0], breaks)).astype(np.intp)
    count = np.diff(np.concatenate((start, [len(beam)]))).astype(np.intp)
    return Segments(xy, beam, start, count, None if scan is None else scan[flat[start]])


def segment_features(segments: Segments, shape: np.ndarray | None = None) -> np.ndarray:
    """The feature matrix ``(k, len(FEATURE_NAMES))`` of every segment, columns in
    :data:`FEATURE_NAMES` order (Arras, Mozos, Burgard 2007, §IV "Features"):

    - ``points`` n — number of returns.
    - ``std_centroid`` — standard deviation from the centroid c: sqrt(Σ‖xᵢ−c‖² / (n−1)).
    - ``mad_median`` — mean average deviation from the median m̃ (coordinate-wise median):
      Σ‖xᵢ−m̃‖ / n (robust to outlying returns).
    - ``jump_preceding`` / ``jump_succeeding`` — distance from the first return to the last
      return of the preceding segment / from the last return to the first of the succeeding one
      (the segments next to it in beam order, across beams without return); :data:`MAX_JUMP`
      when there is none or it is farther.
    - ``width`` — distance from the first to the last return.
    - ``linearity`` — residual Σ dᵢ² of the total-least-squares line fit (the smaller eigenvalue
      of the scatter matrix): ≈ 0 for a straight segment.
    - ``circularity`` — residual Σ (R − ‖xᵢ−c_c‖)² of the algebraic (Kåsa) circle fit: ≈ 0 for
      an arc.
    - ``radius`` — R of that circle, clipped to :data:`MAX_RADIUS`.
    - ``boundary_length`` — Σ ‖xᵢ−xᵢ₋₁‖, the polyline through the returns.
    - ``boundary_regularity`` — standard deviation of those inter-return distances.
    - ``mean_curvature`` — mean of k̂ = 4A / (dₐ d_b d_c) over consecutive triples of returns
      (the inverse radius of the circle through them; A the triangle's area, d its sides).
    - ``mean_angular_difference`` — mean signed angle between consecutive boundary vectors
      xᵢ₋₁xᵢ and xᵢxᵢ₊₁ (rad); consistently of one sign for a convex object such as a leg.
    - ``distance`` — range of the centroid from the laser (not in Arras et al.; the point
      density of a leg depends on it).
    - ``partner_distance`` / ``partner_width`` — distance to the centroid of the nearest other
      segment that could be a leg (at least :data:`PARTNER_MIN_POINTS` returns, at most
      :data:`PARTNER_MAX_WIDTH` wide) and that segment's width; :data:`MAX_JUMP` and 0 when
      there is none. People have two legs a few decimetres apart, which leg trackers use when
      pairing legs into people (Arras et al. 2007 §V; Leigh et al. 2015 §III); as a feature it
      lets the forest tell a leg from a lone leg-shaped object.
    - ``neighbours`` — how many other segments have their centroid within
      :data:`NEIGHBOUR_RADIUS` (clutter: chair and table legs come in groups).

    On the real leg_tracker bags (a forest on them alone, leave-one-bag-out) these three context
    features raised precision/recall at P ≥ 0.5 from 0.58/0.29 to 0.75/0.54: most non-legs
    there are leg-shaped on their own.

    Segments of one return get zeros for the shape features; two returns give an undefined
    circle, reported as a zero residual and :data:`MAX_RADIUS`.

    ``shape``: the indices (ascending) of the segments whose shape features (``std_centroid``,
    ``mad_median``, the line and circle fits, the boundary and curvature) are computed; the
    others get zeros there. The detector passes the segments it classifies: the shape features
    cost per return, and the walls it does not classify hold most returns of a scan. The
    features of a segment do not depend on which others are in ``shape``. None: every segment.

    Segments of several scans (:func:`segment_scans`) get the features each has in its own
    scan: no jump or context across scans. A tick brings several scans (a 40 Hz laser, a 10 Hz
    tick), and most of the cost of this function is a fixed one per call.
    """
    k = len(segments.start)
    out = np.zeros((k, len(FEATURE_NAMES)))
    if k == 0:
        return out
    xy, start, n = segments.xy, segments.start, segments.count
    c = np.add.reduceat(xy, start, axis=0) / n[:, None]
    out[:, 0] = n
    last = start + n - 1
    first_pt, last_pt = xy[start], xy[last]
    jp = np.full(k, MAX_JUMP)
    js = np.full(k, MAX_JUMP)
    if k > 1:
        gaps = np.hypot(*(first_pt[1:] - last_pt[:-1]).T)
        if segments.scan is not None:  # no neighbour across the end of a scan
            gaps[segments.scan[1:] != segments.scan[:-1]] = MAX_JUMP
        jp[1:] = np.minimum(gaps, MAX_JUMP)
        js[:-1] = np.minimum(gaps, MAX_JUMP)
    out[:, 3], out[:, 4] = jp, js
    out[:, 5] = np.hypot(*(last_pt - first_pt).T)
    out[:, 13] = np.hypot(*c.T)
    _context_features(out, c, n, segments.scan)
    which = np.arange(k) if shape is None else np.asarray(shape, dtype=np.intp)
    if len(which):
        out[np.ix_(which, _SHAPE_COLUMNS)] = _shape_features(segments.subset(which))
    return out


#: The columns of :func:`_shape_features` in :data:`FEATURE_NAMES`.
_SHAPE_COLUMNS = np.array([1, 2, 6, 7, 8, 9, 10, 11, 12])


def _context_features(
    out: np.ndarray, c: np.ndarray, n: np.ndarray, scan: np.ndarray | None
) -> None:
    """Fill ``partner_distance``, ``partner_width`` and ``neighbours`` of ``out`` (whose
    ``width`` is filled) from the centroids ``c`` and return counts ``n`` (k × k, k is small),
    among the segments of the same ``scan``."""
    k = len(c)
    gap = np.hypot(c[:, None, 0] - c[None, :, 0], c[:, None, 1] - c[None, :, 1])
    np.fill_diagonal(gap, np.inf)
    if scan is not None:
        gap[scan[:, None] != scan[None, :]] = np.inf
    out[:, 16] = np.sum(gap <= NEIGHBOUR_RADIUS, axis=1)
    legish = (n >= PARTNER_MIN_POINTS) & (out[:, 5] <= PARTNER_MAX_WIDTH)
    gap[:, ~legish] = np.inf
    nearest = np.argmin(gap, axis=1)
    near = gap[np.arange(k), nearest]
    found = near < MAX_JUMP
    out[:, 14] = np.where(found, near, MAX_JUMP)
    out[:, 15] = np.where(found, out[nearest, 5], 0.0)


def _shape_features(segments: Segments) -> np.ndarray:
    """The shape features ``(k, 9)`` of every segment, in :data:`_SHAPE_COLUMNS` order
    (see :func:`segment_features`)."""
    k = len(segments.start)
    out = np.zeros((k, len(_SHAPE_COLUMNS)))
    xy, start, n = segments.xy, segments.start, segments.count
    nf = n.astype(float)
    seg_id = np.repeat(np.arange(k), n)

    def seg_sum(values: np.ndarray) -> np.ndarray:
        return np.add.reduceat(values, start, axis=0)

    c = seg_sum(xy) / nf[:, None]
    d = xy - c[seg_id]
    sq = np.sum(d * d, axis=1)
    out[:, 0] = np.sqrt(seg_sum(sq) / np.maximum(nf - 1.0, 1.0))

    # Coordinate-wise median: sort each coordinate within its segment.
    med = np.empty((k, 2))
    lo = start + (n - 1) // 2
    hi = start + n // 2
    for j in range(2):
        order = np.lexsort((xy[:, j], seg_id))
        v = xy[order, j]
        med[:, j] = 0.5 * (v[lo] + v[hi])
    out[:, 1] = seg_sum(np.hypot(*(xy - med[seg_id]).T)) / nf

    # Line fit (total least squares) from the centred scatter matrix.
    sxx = seg_sum(d[:, 0] ** 2)
    syy = seg_sum(d[:, 1] ** 2)
    sxy = seg_sum(d[:, 0] * d[:, 1])
    half_tr = 0.5 * (sxx + syy)
    disc = np.sqrt(np.maximum(0.25 * (sxx - syy) ** 2 + sxy**2, 0.0))
    out[:, 2] = np.maximum(half_tr - disc, 0.0)

    # Kåsa circle fit, centred: [[Suu Suv][Suv Svv]] [a b]ᵀ = ½ [Suuu+Suvv, Svvv+Svuu].
    u, v = d[:, 0], d[:, 1]
    r2 = u * u + v * v
    b1 = 0.5 * seg_sum(u * r2)
    b2 = 0.5 * seg_sum(v * r2)
    det = sxx * syy - sxy * sxy
    scale = np.maximum((sxx + syy) ** 2, 1e-30)
    good = (det > 1e-9 * scale) & (n >= 3)
    with np.errstate(divide="ignore", invalid="ignore"):
        a = np.where(good, (b1 * syy - b2 * sxy) / det, 0.0)
        b = np.where(good, (b2 * sxx - b1 * sxy) / det, 0.0)
    radius = np.sqrt(a * a + b * b + (sxx + syy) / nf)
    dist_c = np.hypot(u - a[seg_id], v - b[seg_id])
    resid = seg_sum((radius[seg_id] - dist_c) ** 2)
    out[:, 3] = np.where(good, resid, out[:, 2])
    out[:, 4] = np.where(good, np.minimum(radius, MAX_RADIUS), MAX_RADIUS)

    # Boundary: steps between consecutive returns of the same segment.
    step = np.diff(xy, axis=0)
    step_len = np.hypot(*step.T)
    inner = seg_id[1:] == seg_id[:-1]
    sid = seg_id[1:][inner]
    sl = step_len[inner]
    m_steps = np.bincount(sid, minlength=k).astype(float)
    blen = np.bincount(sid, weights=sl, minlength=k)
    out[:, 5] = blen
    with np.errstate(divide="ignore", invalid="ignore"):
        mean_step = np.where(m_steps > 0, blen / m_steps, 0.0)
        var = np.bincount(sid, weights=(sl - mean_step[sid]) ** 2, minlength=k)
        out[:, 6] = np.where(m_steps > 0, np.sqrt(var / np.maximum(m_steps, 1.0)), 0.0)

    # Triples xᵢ₋₁ xᵢ xᵢ₊₁ within one segment: curvature and angular difference.
    if len(xy) >= 3:
        e1, e2 = step[:-1], step[1:]
        trip = (seg_id[:-2] == seg_id[2:]) & inner[:-1]
        tid = seg_id[1:-1][trip]
        e1, e2 = e1[trip], e2[trip]
        cross = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]
        dot = np.sum(e1 * e2, axis=1)
        la, lb = step_len[:-1][trip], step_len[1:][trip]
        lc = np.hypot(*(e1 + e2).T)
        with np.errstate(divide="ignore", invalid="ignore"):
            curv = np.where(la * lb * lc > 1e-12, 2.0 * np.abs(cross) / (la * lb * lc), 0.0)
        ang = np.arctan2(cross, dot)
        m_trip = np.bincount(tid, minlength=k).astype(float)
        denom = np.maximum(m_trip, 1.0)
        out[:, 7] = np.bincount(tid, weights=curv, minlength=k) / denom
        out[:, 8] = np.bincount(tid, weights=ang, minlength=k) / denom
    return out


__all__ = [
    "FEATURE_NAMES",
    "MAX_JUMP",
    "MAX_RADIUS",
    "NEIGHBOUR_RADIUS",
    "PARTNER_MAX_WIDTH",
    "PARTNER_MIN_POINTS",
    "Segments",
    "segment_features",
    "segment_scan",
    "segment_scans",
    "valid_returns",
]
