"""The human belief grid of Kim et al. (§II-E, Eq. 4): p(human in cell) over the map.

Every cell holds the probability ``P(h)`` that a person is in it, starting at the ``prior``. When
the camera delivers a frame, the cells it can see — inside its field of view on the floor and not
hidden behind a wall or furniture (:func:`visible_mask`) — get a Bayes update with the detector's
outcome: the cells within ``detection_radius`` of a detected person with ``o`` (person observed),
every other visible cell with ``¬o``. Cells the camera cannot see keep their value, apart from an
optional slow exponential decay toward the prior (``decay_per_s``, 0 = off), so that a room looked
at long ago becomes worth a look again. The gaze controller looks at :meth:`HumanBelief.argmax` /
:meth:`HumanBelief.most_likely`.

**Eq. 4, corrected.** The update is Bayes' rule for the binary event h (a human in the cell)::

    P(h | o)  =        P(o | h) P(h)        / (P(o | h) P(h) + P(o | hᶜ) P(hᶜ))
    P(h | ¬o) = (1 − P(o | h)) P(h)        / ((1 − P(o | h)) P(h) + (1 − P(o | hᶜ)) P(hᶜ))

with ``P(hᶜ) = 1 − P(h)``. **The paper prints P(o) in the numerator of Eq. 4; it must be P(h)**
(with P(o) the numerator would not even depend on the cell's belief, and the two posteriors of a
cell would not sum to one). The result is clipped to ``[p_min, p_max]`` so that no cell ever
locks at 0 or 1 and a person can always be found (or lost) again.

**Visibility.** :func:`visible_mask` casts rays across the wedge of a
:class:`~pfctl.core.perception.tracking.FieldOfView` (angular step the finer of 0.5° and one cell at
the far range, samples at half-cell steps), finds where each ray first meets a blocked cell, and
marks a cell visible when it lies in the wedge, between ``range_min`` and ``range_max`` (horizontal
distance from the camera, depth-limited), and nearer than the first blocked cell along its
nearest ray. Everything is vectorised and confined to the wedge's bounding box, cut to the
longest free ray (nothing beyond it can be seen) and to the box of the rays' free ends; the
arctangent of the bearing is taken only for the cells in range and inside a slightly wider
wedge. The rays are cast two metres at a time and a ray that has met a blocked cell is not cast
further (most end at a wall a few metres away); the grid's border counts as blocked through a
padded copy of ``blocked`` made once per belief. The cells are exactly those of casting every
ray to the far range over the whole box (tested).

**Peaks.** :meth:`HumanBelief.most_likely` (the gaze's candidates) ranks cells by belief, then
by cell index, and picks greedily those at least ``min_separation`` apart. The best cells are
found by counting, not sorting (:func:`_kth_largest`: a belief grid is mostly a few equal
values, the prior, p_min and 0, on which ``numpy.argpartition`` is slow).

Cells outside ``walkable`` (walls, furniture, outside the house) hold probability 0 and are never
updated, so the belief's maxima are always places where a person can stand.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pfctl.core.mapping.grid import GridGeometry
from pfctl.core.params import param
from pfctl.core.perception.tracking import FieldOfView

#: Coarsest angle between two visibility rays, radians (finer when a cell at the far range is
#: narrower than this).
RAY_STEP = math.radians(0.5)

__all__ = [
    "RAY_STEP",
    "BeliefParams",
    "HumanBelief",
    "bayes_update",
    "visible_mask",
]


@dataclass(frozen=True)
class BeliefParams:
    """Parameters of Eq. 4 and of the grid's housekeeping (mission ``belief``)."""

    prior: float = param(0.05, "P(h): a person is in a cell nobody has looked at.", gt=0, lt=1)
    p_o_given_h: float = param(0.9, "P(o | h): a person in the cell is detected.", gt=0, le=1)
    p_o_given_not_h: float = param(
        0.05, "P(o | hᶜ): a person is detected although the cell is empty.", ge=0, lt=1
    )
    decay_per_s: float = param(
        0.0, "Rate of the exponential return toward the prior (0: none).", unit="1/s", ge=0
    )
    p_min: float = 0.001
    p_max: float = 0.999
    detection_radius: float = 0.3
    """Cells within this distance of a detected person are updated with o, m."""

    def __post_init__(self) -> None:
        if not 0.0 < self.p_min < self.p_max < 1.0:
            raise ValueError(f"need 0 < p_min < p_max < 1, got {self.p_min}, {self.p_max}")
        if not self.p_min <= self.prior <= self.p_max:
            raise ValueError(f"prior must lie in [p_min, p_max], got {self.prior}")
        if not 0.0 <= self.p_o_given_not_h < self.p_o_given_h <= 1.0:
            raise ValueError(
                "need 0 ≤ p_o_given_not_h < p_o_given_h ≤ 1, got "
                f"{self.p_o_given_not_h}, {self.p_o_given_h}"
            )
        if not (self.decay_per_s >= 0.0 and math.isfinite(self.decay_per_s)):
            raise ValueError(f"decay_per_s must be ≥ 0, got {self.decay_per_s}")
        if not self.detection_radius >= 0.0:
            raise ValueError(f"detection_radius must be ≥ 0, got {self.detection_radius}")


def bayes_update(
    p_h: ArrayLike, observed: bool | ArrayLike, p_o_given_h: float, p_o_given_not_h: float
) -> NDArray[np.float64]:
    """Eq. 4 (corrected: P(h), not P(o), in the numerator): the posterior P(h | o) where
    ``observed`` is true and P(h | ¬o) where it is false, elementwise, unclipped."""
    p = np.asarray(p_h, dtype=float)
    obs = np.asarray(observed, dtype=bool)
    like_h = np.where(obs, p_o_given_h, 1.0 - p_o_given_h)
    like_not_h = np.where(obs, p_o_given_not_h, 1.0 - p_o_given_not_h)
    num = like_h * p
    return num / (num + like_not_h * (1.0 - p))


def _window(
    geometry: GridGeometry, fov: FieldOfView, reach: float = math.inf
) -> tuple[int, int, int, int, float] | None:
    """Rows ``[r0, r1)`` and columns ``[c0, c1)`` of the grid that hold the wedge out to
    ``reach`` (default: its far range), and its effective far range (``range_max`` clipped to
    the grid and to ``reach``); None if the wedge misses the grid."""
    ox, oy = geometry.origin
    res = geometry.resolution
    x0, y0 = fov.origin.x, fov.origin.y
    corners = [
        (ox, oy),
        (ox + geometry.width * res, oy),
        (ox, oy + geometry.height * res),
        (ox + geometry.width * res, oy + geometry.height * res),
    ]
    far = min(fov.range_max, max(math.dist((x0, y0), c) for c in corners), reach)
    if fov.half_angle >= math.pi:
        xs, ys = [x0 - far, x0 + far], [y0 - far, y0 + far]
    else:
        angles = [fov.origin.theta - fov.half_angle, fov.origin.theta + fov.half_angle]
        for k in range(4):  # the arc's extreme points where it crosses an axis direction
            a = k * math.pi / 2
            if abs(math.remainder(a - fov.origin.theta, 2 * math.pi)) <= fov.half_angle:
                angles.append(a)
        xs = [x0] + [x0 + far * math.cos(a) for a in angles]
        ys = [y0] + [y0 + far * math.sin(a) for a in angles]
    c0 = max(0, math.floor((min(xs) - ox) / res))
    c1 = min(geometry.width, math.floor((max(xs) - ox) / res) + 1)
    r0 = max(0, math.floor((min(ys) - oy) / res))
    r1 = min(geometry.height, math.floor((max(ys) - oy) / res) + 1)
    if r0 >= r1 or c0 >= c1:
        return None
    return r0, r1, c0, c1, far


#: The visible cells' bearings are computed only for the cells within the wedge widened by
#: this angle, radians (a product test, no arctangent; far wider than its round-off).
_WEDGE_MARGIN = 0.01

#: Samples per ray cast at once (2 m at 0.05 m cells); rays that hit stop there. Fewer,
#: larger chunks cost less than casting a few samples too many (crowd benchmark: 80 against
#: 40 took ~18 % off the ray casting).
_RAY_CHUNK = 80


def _padded(blocked: NDArray[np.bool_]) -> NDArray[np.bool_]:
    """``blocked`` with a border of blocked cells, flattened: a sample outside the grid, its
    cell clipped to the border, ends its ray as leaving the grid does."""
    h, w = blocked.shape
    out = np.ones((h + 2, w + 2), dtype=bool)
    out[1:-1, 1:-1] = blocked
    return out.ravel()


def _first_blocked(
    geometry: GridGeometry,
    fov: FieldOfView,
    angles: NDArray[np.float64],
    s: NDArray[np.float64],
    padded: NDArray[np.bool_],
) -> NDArray[np.intp]:
    """Per ray (``angles`` from the camera), the index into ``s`` (distances along the ray) of
    the first sample in a blocked cell or outside the grid; ``len(s)`` for none (the occlusion
    of Eq. 4's visible cells, module docstring).

    The samples are cast ``_RAY_CHUNK`` at a time and a ray that has hit is not cast further:
    the same samples and the same first hit as casting them all (most rays end at a wall a few
    metres away)."""
    res = geometry.resolution
    ox, oy = geometry.origin
    h, w = geometry.shape
    x0, y0 = fov.origin.x, fov.origin.y
    first = np.full(len(angles), len(s), dtype=np.intp)
    active = np.arange(len(angles))
    cos_a, sin_a = np.cos(angles), np.sin(angles)
    for start in range(0, len(s), _RAY_CHUNK):
        chunk = s[None, start : start + _RAY_CHUNK]
        # cell column and row of x0 + cos·s and y0 + sin·s, in place: the same arithmetic
        # as floor((x0 + cos·s − ox) / res), clipped to [−1, w] (and rows to [−1, h])
        cells = np.zeros((len(active), chunk.shape[1]), dtype=np.intp)
        for trig, start_xy, origin, size, scale in (
            (sin_a, y0, oy, h, w + 2),
            (cos_a, x0, ox, w, 1),
        ):
            q = trig[active][:, None] * chunk
            q += start_xy
            q -= origin
            q /= res
            np.floor(q, out=q)
            np.maximum(q, -1, out=q)
            np.minimum(q, size, out=q)
            index = q.astype(np.intp)
            index += 1
            if scale != 1:
                index *= scale
            cells += index
        hit = padded[cells]
        ended = hit.any(axis=1)
        first[active[ended]] = start + hit[ended].argmax(axis=1)
        active = active[~ended]
        if not len(active):
            break
    return first


def _hull_window(
    geometry: GridGeometry,
    fov: FieldOfView,
    window: tuple[int, int, int, int, float],
    angles: NDArray[np.float64],
    ends: NDArray[np.float64],
    ray_step: float,
) -> tuple[int, int, int, int, float]:
    """``window`` cut to the bounding box of the camera and the rays' free ends (``ends``
    along ``angles``), widened by half a ray step at the longest end and two cells: a visible
    cell is nearer than the free end of its nearest ray (at most half a ray step off it), so
    its centre lies in that box, and the cells cut away are not visible (fewer cells for the
    tests of :func:`_visible_window`, the same visible ones)."""
    r0, r1, c0, c1, far = window
    x0, y0 = fov.origin.x, fov.origin.y
    xs = x0 + ends * np.cos(angles)
    ys = y0 + ends * np.sin(angles)
    pad = float(ends.max(initial=0.0)) * ray_step / 2 + 2 * geometry.resolution
    ox, oy = geometry.origin
    res = geometry.resolution
    c0 = max(c0, math.floor((min(float(xs.min()), x0) - pad - ox) / res))
    c1 = min(c1, math.floor((max(float(xs.max()), x0) + pad - ox) / res) + 1)
    r0 = max(r0, math.floor((min(float(ys.min()), y0) - pad - oy) / res))
    r1 = min(r1, math.floor((max(float(ys.max()), y0) + pad - oy) / res) + 1)
    if r0 >= r1 or c0 >= c1:  # nothing visible: an empty box at the window's corner
        return window[0], window[0], window[2], window[2], far
    return r0, r1, c0, c1, far


def _visible_window(
    geometry: GridGeometry,
    fov: FieldOfView,
    blocked: NDArray[np.bool_] | None,
    padded: NDArray[np.bool_] | None = None,
) -> tuple[tuple[int, int, int, int], NDArray[np.bool_]] | None:
    """The visible cells inside the wedge's bounding box, those Eq. 4 updates:
    ``((r0, r1, c0, c1), mask)``.

    ``padded`` is :func:`_padded` of ``blocked`` (computed when not given). With ``blocked``
    the box only reaches as far as the longest free ray: no cell beyond it can be seen.
    """
    window = _window(geometry, fov)
    if window is None:
        return None
    far = window[4]
    res = geometry.resolution
    half = min(fov.half_angle, math.pi)
    if blocked is not None:
        # Rays across the wedge, sampled every half cell out to the far range.
        step = min(RAY_STEP, res / max(far, res))
        n_rays = max(2, math.ceil(2.0 * half / step) + 1)
        ray_step = 2.0 * half / (n_rays - 1)
        ray_angles = fov.origin.theta - half + ray_step * np.arange(n_rays)
        s = np.arange(0.0, far + res, res / 2.0)
        first = _first_blocked(
            geometry, fov, ray_angles, s, _padded(blocked) if padded is None else padded
        )
        free = np.append(s, np.inf)[first]  # distance to the first blocked sample per ray
        reach = float(free.max())
        if reach < far:
            window = _window(geometry, fov, reach)
            if window is None:
                return None
        window = _hull_window(geometry, fov, window, ray_angles, np.minimum(free, far), ray_step)
    r0, r1, c0, c1, _ = window
    x = geometry.origin[0] + (np.arange(c0, c1) + 0.5) * res - fov.origin.x
    y = geometry.origin[1] + (np.arange(r0, r1) + 0.5) * res - fov.origin.y
    dx, dy = x[None, :], y[:, None]
    dist = np.hypot(dx, dy)
    mask = (dist >= fov.range_min) & (dist <= fov.range_max)
    if blocked is not None:
        mask &= ~blocked[r0:r1, c0:c1]
    if half + _WEDGE_MARGIN < math.pi:
        # Only cells within the wedge widened by _WEDGE_MARGIN can pass the bearing test
        # below: a product test (no arctangent) leaves out the others first.
        cos_t, sin_t = math.cos(fov.origin.theta), math.sin(fov.origin.theta)
        ahead = dx * cos_t + dy * sin_t
        mask &= ahead >= dist * math.cos(half + _WEDGE_MARGIN)
    # The bearing, the wedge and the occlusion tests on the cells still in: the same
    # arithmetic, cell by cell, as over the whole box.
    cells = np.flatnonzero(mask)
    rows, cols = np.divmod(cells, c1 - c0)
    cdx, cdy, cdist = x[cols], y[rows], dist.ravel()[cells]
    bearing = np.arctan2(cdy, cdx) - fov.origin.theta
    bearing = (bearing + np.pi) % (2.0 * np.pi) - np.pi
    keep = np.abs(bearing) <= half
    if blocked is not None:
        ray = np.rint((bearing + half) / ray_step).astype(np.intp)
        np.clip(ray, 0, n_rays - 1, out=ray)
        keep &= cdist < free[ray]
    mask.ravel()[cells] = keep
    return (r0, r1, c0, c1), mask


def visible_mask(
    geometry: GridGeometry, fov: FieldOfView, blocked: ArrayLike | None = None
) -> NDArray[np.bool_]:
    """Cells (shape ``geometry.shape``) the sensor of ``fov`` can see: inside the wedge and its
    range interval, and in front of the first cell of ``blocked`` (walls, furniture; same shape,
    True = blocks the line of sight) along the line of sight. Blocked cells are never visible."""
    blocked_arr = None if blocked is None else _blocked(geometry, blocked)
    out = np.zeros(geometry.shape, dtype=bool)
    got = _visible_window(geometry, fov, blocked_arr)
    if got is not None:
        (r0, r1, c0, c1), mask = got
        out[r0:r1, c0:c1] = mask
    return out


def _blocked(geometry: GridGeometry, blocked: ArrayLike) -> NDArray[np.bool_]:
    arr = np.asarray(blocked, dtype=bool)
    if arr.shape != geometry.shape:
        raise ValueError(f"blocked mask has shape {arr.shape}, the grid is {geometry.shape}")
    return arr


def _top_cells(flat: NDArray[np.float64], pool: int) -> NDArray[np.intp]:
    """Indices of the ``pool`` largest values of ``flat`` (equal values: the lower index
    first), ordered by value descending, then index ascending (the candidates of the gaze's
    belief peaks, §II-E).

    The ``pool``-th largest value v is found by counting, not sorting (:func:`_kth_largest`);
    the result is then every index above v and the first indices equal to v.
    """
    n = flat.size
    if pool <= 0:
        return np.zeros(0, dtype=np.intp)
    if pool >= n:
        idx = np.arange(n)
    else:
        v = _kth_largest(flat, pool)
        above = np.flatnonzero(flat > v)
        tied = np.flatnonzero(flat == v)[: pool - above.size]
        idx = np.concatenate((above, tied))
    return idx[np.lexsort((idx, -flat[idx]))]


def _kth_largest(flat: NDArray[np.float64], k: int) -> float:
    """The ``k``-th largest value of ``flat`` (1 ≤ k ≤ size, counted with multiplicity).

    A belief grid holds many equal values (the prior, 0, p_min), on which ``numpy.partition``
    is slow (benchmarks/README.md). For finite values ≥ 0 the IEEE
    bits read as integers are ordered like the values, so 12 bits at a time, from the top, are
    ordered buckets: a bincount finds the bucket that holds the k-th value, and the search goes
    on inside it until its values are all equal (at most six rounds) or few.
    """
    values = np.asarray(flat, dtype=np.float64).ravel()
    lo, hi = float(values.min()), float(values.max())
    if not (lo >= 0.0 and math.isfinite(hi)):  # NaN fails both
        return float(np.partition(values, values.size - k)[values.size - k])
    bits = (values + 0.0).view(np.int64)  # + 0.0: −0.0 becomes 0.0 (sign bit clear)
    shift = 52
    while True:
        if lo == hi:
            return lo
        if values.size <= 64:
            return float(np.partition(values, values.size - k)[values.size - k])
        keys = (bits >> shift) & 0xFFF  # the same higher bits inside the bucket: ordered
        from_top = np.cumsum(np.bincount(keys, minlength=4096)[::-1])
        j = int(np.searchsorted(from_top, k))  # from_top[j] ≥ k > from_top[j − 1]
        k -= int(from_top[j - 1]) if j else 0
        inside = keys == 4095 - j
        values, bits = values[inside], bits[inside]
        lo, hi = float(values.min()), float(values.max())
        shift = max(shift - 12, 0)


class HumanBelief:
    """The human belief grid of Eq. 4 over a map (Kim et al., §II-E).

    ``blocked`` (True = blocks the camera's line of sight, e.g. the occupied cells of the static
    map) defaults to nothing; ``walkable`` (where a person can be) defaults to ``~blocked``. The
    probabilities are :attr:`p` (shape ``geometry.shape``, row = y, column = x as in
    :mod:`pfctl.core.mapping.grid`); cells that are not walkable stay 0.
    """

    def __init__(
        self,
        geometry: GridGeometry,
        params: BeliefParams | None = None,
        blocked: ArrayLike | None = None,
        walkable: ArrayLike | None = None,
    ) -> None:
        self.geometry = geometry
        self.params = params or BeliefParams()
        self.blocked = None if blocked is None else _blocked(geometry, blocked).copy()
        if walkable is not None:
            self.walkable = _blocked(geometry, walkable).copy()
        elif self.blocked is not None:
            self.walkable = ~self.blocked
        else:
            self.walkable = np.ones(geometry.shape, dtype=bool)
        self.p: NDArray[np.float64] = np.where(self.walkable, self.params.prior, 0.0)
        self.time: float | None = None
        self._padded: tuple[NDArray[np.bool_], NDArray[np.bool_]] | None = None

    def _padded_blocked(self) -> NDArray[np.bool_] | None:
        """:func:`_padded` of :attr:`blocked`, made once per blocked array (which is not
        changed in place)."""
        if self.blocked is None:
            return None
        if self._padded is None or self._padded[0] is not self.blocked:
            self._padded = (self.blocked, _padded(self.blocked))
        return self._padded[1]

    def reset(self) -> None:
        """Back to the prior everywhere (the clock is kept)."""
        self.p = np.where(self.walkable, self.params.prior, 0.0)

    def advance(self, t: float) -> None:
        """Move the clock to ``t`` (s), decaying every cell toward the prior by
        ``exp(−decay_per_s · dt)``; an earlier ``t`` is ignored."""
        if self.time is not None and t > self.time and self.params.decay_per_s > 0:
            keep = math.exp(-self.params.decay_per_s * (t - self.time))
            prior = self.params.prior
            self.p = np.where(self.walkable, prior + (self.p - prior) * keep, 0.0)
        if self.time is None or t > self.time:
            self.time = float(t)

    def update(
        self, fov: FieldOfView, detections: ArrayLike | Sequence[Sequence[float]], t: float
    ) -> NDArray[np.bool_]:
        """One camera frame: decay to ``t``, then Eq. 4 on the visible cells — with o within
        ``detection_radius`` of each detected person (``(n, 2)`` map positions), ¬o elsewhere.

        A detection whose surroundings are all hidden (e.g. a depth just past ``range_max``)
        still updates its walkable, unblocked cells with o. Returns the visible mask (full grid).
        """
        self.advance(t)
        prm, geo = self.params, self.geometry
        res, radius = geo.resolution, prm.detection_radius
        span = math.ceil(radius / res) + 1
        boxes: list[tuple[int, int, int, int]] = []  # rows [a0, a1), cols [b0, b1) per person
        pts = np.asarray(detections, dtype=float).reshape(-1, 2)
        for x, y in pts:
            (row,), (col,) = geo.world_to_cell(np.array([[x, y]]))
            box = (max(0, row - span), min(geo.height, row + span + 1),
                   max(0, col - span), min(geo.width, col + span + 1))  # fmt: skip
            boxes.append(box)
        got = _visible_window(geo, fov, self.blocked, self._padded_blocked())
        windows = [b for b in boxes if b[0] < b[1] and b[2] < b[3]]
        if got is not None:
            windows.append(got[0])
        visible = np.zeros(geo.shape, dtype=bool)
        if not windows:
            return visible
        # Work inside the union of the wedge's and the detections' boxes only.
        r0, r1 = min(w[0] for w in windows), max(w[1] for w in windows)
        c0, c1 = min(w[2] for w in windows), max(w[3] for w in windows)
        vis = visible[r0:r1, c0:c1]  # a view: filling it fills ``visible``
        if got is not None:
            (a0, a1, b0, b1), mask = got
            vis[a0 - r0 : a1 - r0, b0 - c0 : b1 - c0] = mask
        walkable = self.walkable[r0:r1, c0:c1]
        vis &= walkable
        observed = np.zeros(vis.shape, dtype=bool)
        for (x, y), (a0, a1, b0, b1) in zip(pts, boxes, strict=True):
            if a0 >= a1 or b0 >= b1:
                continue
            cx = geo.origin[0] + (np.arange(b0, b1) + 0.5) * res
            cy = geo.origin[1] + (np.arange(a0, a1) + 0.5) * res
            near = np.hypot(cx[None, :] - x, cy[:, None] - y) <= max(radius, res / 2)
            sub = (slice(a0 - r0, a1 - r0), slice(b0 - c0, b1 - c0))
            near &= walkable[sub]
            seen = near & vis[sub]
            if not seen.any():  # hidden surroundings: trust the detection, not the wedge
                seen = near if self.blocked is None else near & ~self.blocked[a0:a1, b0:b1]
            observed[sub] |= seen
        touched = vis | observed
        p = self.p[r0:r1, c0:c1]  # a view: updated in place
        post = bayes_update(p[touched], observed[touched], prm.p_o_given_h, prm.p_o_given_not_h)
        p[touched] = np.clip(post, prm.p_min, prm.p_max)
        return visible

    # -------------------------------------------------------------------------------- queries

    def argmax(self) -> tuple[float, float]:
        """Centre (x, y) of the cell with the highest belief (the first one on ties)."""
        row, col = np.unravel_index(int(np.argmax(self.p)), self.p.shape)
        x, y = self.geometry.cell_to_world(row, col)
        return float(x), float(y)

    def most_likely(
        self, k: int, min_separation: float = 0.0, *, at_least: float = 0.0
    ) -> list[tuple[float, float, float]]:
        """Up to ``k`` cells ``(x, y, p)`` by decreasing belief, at least ``min_separation`` m
        apart (greedy: a cell closer than that to an already chosen one is skipped).

        The candidates are the ``k`` best cells, or with a separation the best
        ``max(64 k, 1024)``, in the order of belief and then of cell index (row-major), so equal
        beliefs are taken top-left first; cells at 0 are never returned. The selection
        (:func:`_top_cells`) costs a count over the grid, not a sort; the greedy picks are
        vectorised (one distance pass per pick).

        ``at_least`` > 0 returns only the cells of belief ≥ ``at_least``: the leading cells of
        the list without it (the picks come by decreasing belief and a pick depends only on
        the picks before it), and when no more than the candidates are that likely (a belief
        grid holds few: the people), the candidates are those cells alone, found by one
        comparison over the grid instead of the count of :func:`_top_cells` (the gaze rule's
        peaks, :func:`~pfctl.core.control.gaze_rule`, ask for those above its threshold).
        """
        if k <= 0:
            return []
        flat = self.p.ravel()
        pool = min(k if min_separation <= 0 else max(64 * k, 1024), flat.size)
        idx = np.flatnonzero(flat >= at_least) if at_least > 0.0 else None
        if idx is not None and idx.size <= pool:
            # all of them are among the ``pool`` best, in the same order (belief, then index)
            idx = idx[np.lexsort((idx, -flat[idx]))]
        else:
            idx = _top_cells(flat, pool)
            idx = idx[flat[idx] >= at_least] if at_least > 0.0 else idx
        idx = idx[flat[idx] > 0.0]
        rows, cols = np.unravel_index(idx, self.p.shape)
        centres = self.geometry.cell_to_world(rows, cols)
        if min_separation <= 0:
            chosen = np.arange(min(k, len(idx)))
        else:
            alive = np.ones(len(idx), dtype=bool)
            picks: list[int] = []
            while len(picks) < k:
                left = np.flatnonzero(alive)
                if not len(left):
                    break
                j = int(left[0])
                picks.append(j)
                d = np.hypot(centres[:, 0] - centres[j, 0], centres[:, 1] - centres[j, 1])
                alive &= d >= min_separation
            chosen = np.array(picks, dtype=np.intp)
        return [(float(centres[j, 0]), float(centres[j, 1]), float(flat[idx[j]])) for j in chosen]

    def at(self, xy: ArrayLike) -> NDArray[np.float64]:
        """The belief at map points ``(..., 2)`` (0 outside the grid)."""
        rows, cols = self.geometry.world_to_cell(xy)
        ok = self.geometry.in_bounds(rows, cols)
        out = np.zeros(np.shape(rows), dtype=float)
        out[ok] = self.p[rows[ok], cols[ok]]
        return out
