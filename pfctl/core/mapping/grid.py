"""Occupancy grid of the paper (§II-B/C): p(m) per cell, O=1, F=0, U=0.5.

Layout: ``logodds`` has shape ``(height, width)``; row ``r`` is the y index and column ``c`` the x
index, so cell ``(r, c)`` covers ``[ox + c·res, ox + (c+1)·res) × [oy + r·res, oy + (r+1)·res)`` in
the map frame (REP-103: x forward, y left), with ``(ox, oy) = origin`` the lower-left corner of cell
``(0, 0)`` — the same convention as nav_msgs/OccupancyGrid (row-major, first row at the origin).

The grid keeps the log-odds ``l = log(p / (1 − p))`` of each cell; the prior p(m) = 0.5 is l = 0.
Laser scans are fused with the binary Bayes filter of Eq. 1 through an inverse sensor model
(:class:`InverseSensorModel`, :meth:`OccupancyGrid.update_scan`), and the map's uncertainty is its
entropy H(M) (:meth:`OccupancyGrid.entropy`, §II-C). Grids are converted to and from
nav_msgs/OccupancyGrid data; the ROS map_server files (YAML + PGM) are read and written outside
core (:mod:`pfctl.mission.map_server`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.special import entr

from pfctl.core.params import param

FREE = 0
OCCUPIED = 1
UNKNOWN = -1

#: Default trinary thresholds of ROS map_server / map_saver: p < FREE_THRESH is free,
#: p > OCCUPIED_THRESH is occupied, anything in between is unknown.
FREE_THRESH = 0.196
OCCUPIED_THRESH = 0.65

#: Probabilities 0 and 1 (a map file's "certainly free / occupied") are stored as
#: p = SATURATION and 1 − SATURATION, i.e. log-odds ±SATURATION_LOGODDS (≈ ±20.7), so the
#: log-odds stay finite. A later scan update clamps such a cell to the sensor model's bounds.
SATURATION = 1e-9
SATURATION_LOGODDS = math.log((1.0 - SATURATION) / SATURATION)

_EDGE = 1e-6  # beams are clipped to the grid shrunk by this many cells, so floor() stays inside


def logit(p: ArrayLike) -> NDArray[np.float64]:
    """log(p / (1 − p)), the log-odds of a probability."""
    p = np.asarray(p, dtype=float)
    return np.log(p / (1.0 - p))


def inv_logit(log_odds: ArrayLike) -> NDArray[np.float64]:
    """The probability of a log-odds value l: 1 / (1 + exp(−l))."""
    return 1.0 / (1.0 + np.exp(-np.asarray(log_odds, dtype=float)))


def _saturated_logit(p: ArrayLike) -> NDArray[np.float64]:
    """logit(p) with p clipped to [SATURATION, 1 − SATURATION], so 0 and 1 stay finite."""
    return logit(np.clip(np.asarray(p, dtype=float), SATURATION, 1.0 - SATURATION))


@dataclass(frozen=True)
class GridGeometry:
    """Where a grid lies in the map frame: cell size (m), cells in x and y, lower-left corner."""

    resolution: float
    width: int
    height: int
    origin: tuple[float, float] = (0.0, 0.0)

    def world_to_cell(self, xy: ArrayLike) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
        """(rows, cols) of the cells containing points ``xy`` (shape (..., 2)); may be outside."""
        xy = np.asarray(xy, dtype=float)
        cols = np.floor((xy[..., 0] - self.origin[0]) / self.resolution).astype(np.intp)
        rows = np.floor((xy[..., 1] - self.origin[1]) / self.resolution).astype(np.intp)
        return rows, cols

    def cell_to_world(self, rows: ArrayLike, cols: ArrayLike) -> NDArray[np.float64]:
        """Centres (..., 2) of cells ``(rows, cols)`` in the map frame."""
        rows = np.asarray(rows, dtype=float)
        cols = np.asarray(cols, dtype=float)
        x = self.origin[0] + (cols + 0.5) * self.resolution
        y = self.origin[1] + (rows + 0.5) * self.resolution
        return np.stack([x, y], axis=-1)

    def in_bounds(self, rows: ArrayLike, cols: ArrayLike) -> NDArray[np.bool_]:
        """True where ``(rows, cols)`` is a cell of this grid."""
        rows = np.asarray(rows)
        cols = np.asarray(cols)
        return (rows >= 0) & (rows < self.height) & (cols >= 0) & (cols < self.width)

    @property
    def shape(self) -> tuple[int, int]:
        return (self.height, self.width)

    @property
    def extent(self) -> tuple[float, float, float, float]:
        """(xmin, xmax, ymin, ymax) in metres, e.g. for matplotlib's ``imshow(origin='lower')``."""
        ox, oy = self.origin
        return (ox, ox + self.width * self.resolution, oy, oy + self.height * self.resolution)


@dataclass(frozen=True)
class InverseSensorModel:
    """Inverse sensor model p(m | z_t) of a laser beam, and the bounds of the Bayes filter (Eq. 1).

    A cell where a beam ends (a valid return) is occupied with probability ``p_hit``; a cell a beam
    passes through is occupied with probability ``p_miss`` (the mission's ``map.sensor_model``).

    Eq. 1 of the paper is the binary Bayes filter of one cell m::

        p(m | z_1:t) = [1 + (1 − p(m|z_t)) / p(m|z_t)
                          · (1 − p(m|z_1:t−1)) / p(m|z_1:t−1)
                          · p(m) / (1 − p(m))]^−1

    which, in log-odds l = log(p / (1 − p)), is the sum

        l_t = l_{t−1} + logit(p(m | z_t)) − logit(p(m)).

    With the prior p(m) = 0.5 (unknown, U = 0.5) the last term is 0, so a hit adds
    ``logit(p_hit)`` and a miss adds ``logit(p_miss)``. After each update l_t is clamped to
    ``[logit(p_min), logit(p_max)]`` so that a cell can always change its mind again (a door opens).
    """

    p_hit: float = param(0.7, "p(occupied | the beam ended in the cell).", gt=0.5, lt=1)
    p_miss: float = param(0.4, "p(occupied | the beam passed through the cell).", gt=0, lt=0.5)
    p_min: float = param(
        0.02, "Lower clamp of p(m), so that a cell can always change its mind again.", gt=0, lt=1
    )
    p_max: float = param(0.98, "Upper clamp of p(m); greater than p_min.", gt=0, lt=1)

    def __post_init__(self) -> None:
        for name in ("p_hit", "p_miss", "p_min", "p_max"):
            value = getattr(self, name)
            if not 0.0 < value < 1.0:
                raise ValueError(f"InverseSensorModel.{name} must be in (0, 1), got {value}")
        if not self.p_miss < 0.5 < self.p_hit:
            raise ValueError(
                f"InverseSensorModel needs p_miss < 0.5 < p_hit, got {self.p_miss}, {self.p_hit}"
            )
        if not self.p_min < 0.5 < self.p_max:
            raise ValueError(
                f"InverseSensorModel needs p_min < 0.5 < p_max, got {self.p_min}, {self.p_max}"
            )

    @property
    def l_hit(self) -> float:
        """logit(p_hit): what a hit adds to a cell's log-odds (Eq. 1)."""
        return float(logit(self.p_hit))

    @property
    def l_miss(self) -> float:
        """logit(p_miss): what a pass-through adds to a cell's log-odds (Eq. 1); negative."""
        return float(logit(self.p_miss))

    @property
    def l_min(self) -> float:
        """logit(p_min), the lower clamp of the log-odds."""
        return float(logit(self.p_min))

    @property
    def l_max(self) -> float:
        """logit(p_max), the upper clamp of the log-odds."""
        return float(logit(self.p_max))


def _crossings(
    first: NDArray[np.float64],
    slope: NDArray[np.float64],
    minor0: NDArray[np.float64],
    counts: NDArray[np.intp],
    width: int,
    along_x: bool,
) -> NDArray[np.int32]:
    """The cells a scan's beams pass through, for Eq. 1's update: flat cell indices
    ``row · width + col`` of the grid-line crossings of beams along their major axis (x when
    ``along_x``). Beam b crosses the lines ``first[b] + k``, k = 0 … counts[b] − 1, at the
    minor coordinate ``minor0[b] + k · slope[b]``; the cell returned is the one past the line
    (the caller marks the one before it too).

    All beams' crossings go in one flat array, with no padding to the longest beam. In-place
    int32 arithmetic; truncation is floor() here since all points are ≥ 0. Each beam's values
    are repeated over its crossings (``numpy.repeat``, a sequential copy) rather than gathered
    through a per-crossing beam index: the same numbers.
    """
    k = np.arange(int(counts.sum()), dtype=np.int32)
    k -= np.repeat((np.cumsum(counts) - counts).astype(np.int32), counts)
    minor_f = k * np.repeat(slope, counts)
    minor_f += np.repeat(minor0, counts)
    minor = minor_f.astype(np.int32)
    line = k
    line += np.repeat(first.astype(np.int32), counts)
    if along_x:  # line = column i, minor = row: cells (row, i) and (row, i − 1)
        minor *= width
        minor += line
    else:  # line = row j, minor = column: cells (j, col) and (j − 1, col)
        line *= width
        minor += line
    return minor


class OccupancyGrid:
    """A probabilistic occupancy grid: the log-odds of p(m) per cell, updated by Eq. 1.

    ``logodds`` has shape ``(geometry.height, geometry.width)`` (see the module docstring for the
    layout); 0 is the prior p(m) = 0.5. The constructor copies ``logodds``. ``sensor_model`` is the
    inverse sensor model used by :meth:`update_scan` and :meth:`update_cells`.
    """

    def __init__(
        self,
        geometry: GridGeometry,
        logodds: ArrayLike | None = None,
        sensor_model: InverseSensorModel | None = None,
    ) -> None:
        if not (math.isfinite(geometry.resolution) and geometry.resolution > 0):
            raise ValueError(f"grid resolution must be > 0, got {geometry.resolution}")
        if geometry.width < 1 or geometry.height < 1:
            raise ValueError(f"grid must have at least one cell, got {geometry.shape}")
        self.geometry = geometry
        if logodds is None:
            self.logodds: NDArray[np.float64] = np.zeros(geometry.shape, dtype=np.float64)
        else:
            array = np.array(logodds, dtype=np.float64)
            if array.shape != geometry.shape:
                raise ValueError(f"logodds has shape {array.shape}, geometry says {geometry.shape}")
            self.logodds = array
        self.sensor_model = sensor_model if sensor_model is not None else InverseSensorModel()

    # ----------------------------------------------------------------------------- construction

    @classmethod
    def empty(
        cls,
        width_m: float,
        height_m: float,
        resolution: float,
        origin: tuple[float, float] = (0.0, 0.0),
        sensor_model: InverseSensorModel | None = None,
    ) -> OccupancyGrid:
        """An all-unknown grid (p = 0.5) covering at least ``width_m × height_m`` metres."""
        if not (resolution > 0 and width_m > 0 and height_m > 0):
            raise ValueError(
                f"need positive size and resolution, got {width_m} × {height_m} m at {resolution}"
            )
        # 1e-9 forgives float noise: 20 m / 0.05 m is 400 cells, not 401.
        width = max(1, math.ceil(width_m / resolution - 1e-9))
        height = max(1, math.ceil(height_m / resolution - 1e-9))
        geometry = GridGeometry(float(resolution), width, height, _origin(origin))
        return cls(geometry, sensor_model=sensor_model)

    @classmethod
    def from_probabilities(
        cls,
        p: ArrayLike,
        resolution: float,
        origin: tuple[float, float] = (0.0, 0.0),
        sensor_model: InverseSensorModel | None = None,
    ) -> OccupancyGrid:
        """A grid with p(m) = ``p`` (shape (height, width), row 0 at the origin).

        0 and 1 are stored as SATURATION and 1 − SATURATION so the log-odds stay finite.
        """
        p = np.asarray(p, dtype=float)
        if p.ndim != 2 or p.size == 0:
            raise ValueError(f"probabilities must be a non-empty 2-D array, got shape {p.shape}")
        if not np.all((p >= 0.0) & (p <= 1.0)):
            raise ValueError("probabilities must lie in [0, 1] (and not be NaN)")
        geometry = GridGeometry(float(resolution), p.shape[1], p.shape[0], _origin(origin))
        return cls(geometry, _saturated_logit(p), sensor_model)

    @classmethod
    def from_occupancy_values(
        cls,
        data: ArrayLike,
        width: int,
        height: int,
        resolution: float,
        origin: tuple[float, float] = (0.0, 0.0),
        sensor_model: InverseSensorModel | None = None,
    ) -> OccupancyGrid:
        """A grid from nav_msgs/OccupancyGrid ``data`` (row-major, row 0 at the origin).

        A value v in 0..100 becomes p = v / 100 (0 and 100 saturated, see SATURATION); −1 (and
        any other negative value) is unknown, p = 0.5. Values above 100 raise ValueError.
        """
        values = np.asarray(data).astype(np.int64).ravel()
        if values.size != width * height:
            raise ValueError(f"{values.size} occupancy values for a {width} × {height} grid")
        if np.any(values > 100):
            raise ValueError(f"occupancy values must be −1 or 0..100, got {int(values.max())}")
        p = np.where(values < 0, 0.5, values / 100.0).reshape(height, width)
        return cls.from_probabilities(p, resolution, origin, sensor_model)

    def copy(self) -> OccupancyGrid:
        """An independent copy (the log-odds array is copied)."""
        return OccupancyGrid(self.geometry, self.logodds, self.sensor_model)

    def __repr__(self) -> str:
        g = self.geometry
        return (
            f"OccupancyGrid({g.width}×{g.height} cells at {g.resolution} m, origin={g.origin}, "
            f"{self.sensor_model})"
        )

    # ------------------------------------------------------------------------------ properties

    @property
    def resolution(self) -> float:
        return self.geometry.resolution

    @property
    def origin(self) -> tuple[float, float]:
        return self.geometry.origin

    @property
    def width(self) -> int:
        return self.geometry.width

    @property
    def height(self) -> int:
        return self.geometry.height

    @property
    def shape(self) -> tuple[int, int]:
        return self.geometry.shape

    def prob(self) -> NDArray[np.float64]:
        """p(m) of every cell, shape (height, width)."""
        return inv_logit(self.logodds)

    def states(
        self, free_thresh: float = FREE_THRESH, occupied_thresh: float = OCCUPIED_THRESH
    ) -> NDArray[np.int8]:
        """FREE (0) where p < free_thresh, OCCUPIED (1) where p > occupied_thresh, else UNKNOWN.

        The paper's three cell values O = 1, F = 0, U = 0.5 (§II-C) are these states; the default
        thresholds are those of ROS map_server. Computed on the log-odds (p < t ⇔ l < logit(t)),
        which spares an exp() per cell.
        """
        lo = self.logodds
        occupied = lo > logit(occupied_thresh)  # wins over free when the thresholds cross
        known = occupied | (lo < logit(free_thresh))
        # OCCUPIED 1, FREE 0, UNKNOWN -1 by arithmetic on the masks' bytes (no masked writes)
        out: NDArray[np.int8] = occupied.view(np.int8) - (~known).view(np.int8)
        return out

    def entropy(self, base: float = 2.0) -> float:
        """Map entropy H(M) = −Σ_m [p log p + (1 − p) log(1 − p)] over all cells (§II-C).

        0 log 0 = 0. The default base is 2, so H is in bits; pass ``base=math.e`` for nats. An
        all-unknown grid (p = 0.5 everywhere) of N cells has H = N·log_base(2), i.e. N bits; a
        grid whose cells are all certainly free or occupied has H ≈ 0.
        """
        if not (base > 0 and base != 1):
            raise ValueError(f"entropy base must be > 0 and ≠ 1, got {base}")
        p = self.prob()
        return float(np.sum(entr(p) + entr(1.0 - p)) / math.log(base))

    # ---------------------------------------------------------------------------------- update

    def update_cells(self, hit_mask: ArrayLike, free_mask: ArrayLike) -> None:
        """Apply one observation to each marked cell with Eq. 1, in log-odds.

        Cells of ``hit_mask`` get l += logit(p_hit); cells of ``free_mask`` that are not hits get
        l += logit(p_miss) (a cell both hit and passed through counts as hit). The prior term
        −logit(p(m)) of Eq. 1 is 0 for p(m) = 0.5. The updated cells are then clamped to
        [logit(p_min), logit(p_max)]; other cells are left exactly as they were.
        """
        hit = np.asarray(hit_mask, dtype=bool)
        free = np.asarray(free_mask, dtype=bool)
        if hit.shape != self.shape or free.shape != self.shape:
            raise ValueError(f"masks must have the grid's shape {self.shape}")
        model = self.sensor_model
        lo = self.logodds
        np.add(lo, model.l_miss, out=lo, where=free & ~hit)
        np.add(lo, model.l_hit, out=lo, where=hit)
        np.clip(lo, model.l_min, model.l_max, out=lo, where=hit | free)

    def update_scan(
        self,
        pose: Sequence[float],
        ranges: ArrayLike,
        angle_min: float,
        angle_increment: float,
        range_max: float,
        range_min: float = 0.0,
        max_update_range: float | None = None,
    ) -> None:
        """Fuse one laser scan into the grid with the Bayes filter of Eq. 1.

        ``pose`` = (x, y, θ) of the sensor in the map frame; beam k points at θ + angle_min +
        k·angle_increment. Every cell in the field of view is updated once per scan (see
        :meth:`scan_masks` for which cells, and :meth:`update_cells` for the update).
        """
        hit, free = self.scan_masks(
            pose, ranges, angle_min, angle_increment, range_max, range_min, max_update_range
        )
        self.update_cells(hit, free)

    def scan_masks(
        self,
        pose: Sequence[float],
        ranges: ArrayLike,
        angle_min: float,
        angle_increment: float,
        range_max: float,
        range_min: float = 0.0,
        max_update_range: float | None = None,
    ) -> tuple[NDArray[np.bool_], NDArray[np.bool_]]:
        """The (hit, free) cell masks of one scan, each of shape (height, width).

        Range semantics follow REP-117:

        - ``range_min ≤ r ≤ range_max`` (and ``r ≤ max_update_range`` if given): a return. The
          cell containing the end point is a hit; the cells the beam passes through up to there
          are free; nothing beyond the hit is touched.
        - ``+inf`` or ``r > range_max``: no return within range; the beam is free up to
          ``range_max`` and has no hit.
        - ``r > max_update_range``: free up to ``max_update_range``, no hit.
        - ``−inf`` (too close), NaN (invalid) and ``r < range_min``: the beam changes nothing.

        Beams are clipped to the grid; cells outside are ignored. The traversal is exact (every cell
        the segment enters, like a DDA / Amanatides–Woo walk) and vectorised over the beams: along
        each beam's major axis it finds the crossings of the grid lines and marks the two cells
        either side of each crossing, plus the first and last cell.
        """
        x, y, theta = (float(v) for v in pose)
        if not all(math.isfinite(v) for v in (x, y, theta, angle_min, angle_increment)):
            raise ValueError(f"scan pose and angles must be finite, got {pose}")
        r = np.asarray(ranges, dtype=float).ravel()
        geometry = self.geometry
        res = geometry.resolution
        W, H = geometry.width, geometry.height
        hit = np.zeros(H * W, dtype=bool)
        free = np.zeros(H * W, dtype=bool)
        if r.size == 0:
            return hit.reshape(H, W), free.reshape(H, W)

        reach = float(range_max)
        if max_update_range is not None:
            reach = min(reach, float(max_update_range))
        with np.errstate(invalid="ignore"):
            returned = (r >= range_min) & (r <= range_max) & (r <= reach)
            no_return = np.isposinf(r) | (r > range_max)
            # r beyond max_update_range but within range_max: free up to reach, no hit.
            no_return |= (r > reach) & (r <= range_max)
        use = returned | no_return
        if not np.any(use) or reach <= 0:
            return hit.reshape(H, W), free.reshape(H, W)
        index = np.flatnonzero(use)
        angles = theta + angle_min + index * angle_increment
        cx = np.cos(angles)
        cy = np.sin(angles)
        is_hit = returned[index]
        length = np.where(is_hit, r[index], reach) / res  # in cells
        x0 = (x - geometry.origin[0]) / res
        y0 = (y - geometry.origin[1]) / res

        # Hits: the cell containing the end point, if it is in the grid.
        hx = x0 + length * cx
        hy = y0 + length * cy
        hc = np.floor(hx)
        hr = np.floor(hy)
        hit_ok = is_hit & (hc >= 0) & (hc < W) & (hr >= 0) & (hr < H)
        hit[(hr[hit_ok] * W + hc[hit_ok]).astype(np.intp)] = True

        # Clip each segment [0, length] to the grid box shrunk by _EDGE (Liang–Barsky).
        t_lo = np.zeros_like(length)
        t_hi = length.copy()
        for p0, d, size in ((x0, cx, W), (y0, cy, H)):
            lo_edge, hi_edge = _EDGE, size - _EDGE
            moving = np.abs(d) > 1e-12
            with np.errstate(divide="ignore", invalid="ignore"):
                ta = (lo_edge - p0) / d
                tb = (hi_edge - p0) / d
            t_lo = np.where(moving, np.maximum(t_lo, np.minimum(ta, tb)), t_lo)
            t_hi = np.where(moving, np.minimum(t_hi, np.maximum(ta, tb)), t_hi)
            if not lo_edge <= p0 <= hi_edge:  # parallel beams outside this slab never enter
                t_hi = np.where(moving, t_hi, -1.0)
        inside = t_lo <= t_hi
        if not np.any(inside):
            return hit.reshape(H, W), free.reshape(H, W)
        cx, cy, t_lo, t_hi = cx[inside], cy[inside], t_lo[inside], t_hi[inside]
        xs, ys = x0 + t_lo * cx, y0 + t_lo * cy
        xe, ye = x0 + t_hi * cx, y0 + t_hi * cy

        # First and last cell of every segment.
        ends_c = np.floor(np.concatenate([xs, xe])).astype(np.intp)
        ends_r = np.floor(np.concatenate([ys, ye])).astype(np.intp)
        free[ends_r * W + ends_c] = True

        # Crossings of the grid lines along the major axis; for x-major beams the crossing of
        # the line x = i at height y marks cells (⌊y⌋, i − 1) and (⌊y⌋, i).
        free2 = free.reshape(H, W)
        x_major = np.abs(cx) >= np.abs(cy)
        for along_x, major, ms, me, ns, d_major, d_minor in (
            (True, x_major, xs, xe, ys, cx, cy),
            (False, ~x_major, ys, ye, xs, cy, cx),
        ):
            if not np.any(major):
                continue
            a, b = ms[major], me[major]
            m = d_minor[major] / d_major[major]  # change of the minor coordinate per major cell
            lo = np.floor(np.minimum(a, b))
            n = (np.floor(np.maximum(a, b)) - lo).astype(np.intp)  # grid lines in (min, max]
            keep = n > 0
            if not np.any(keep):
                continue
            first = lo[keep] + 1.0  # the first grid line crossed
            m = m[keep]
            minor0 = ns[major][keep] + (first - a[keep]) * m  # the minor coordinate there
            minor = _crossings(first, m, minor0, n[keep], W, along_x)
            # The cell past each crossed line and the one before it, marked in place: the
            # lines crossed are 1 … W − 1 (rows: 1 … H − 1) since the segments stay _EDGE
            # inside the grid, so the cell before is always in the same row (column).
            free[minor] = True
            minor -= 1 if along_x else W
            free[minor] = True
        return hit.reshape(H, W), free2

    # -------------------------------------------------------------------------------- nav_msgs

    def to_occupancy_values(
        self, free_thresh: float = FREE_THRESH, occupied_thresh: float = OCCUPIED_THRESH
    ) -> NDArray[np.int8]:
        """nav_msgs/OccupancyGrid ``data``: int8, row-major, row 0 at the origin, length W·H.

        A cell is unknown (−1) when its state is UNKNOWN under the trinary thresholds
        (free_thresh ≤ p ≤ occupied_thresh), so a merely glimpsed cell is not reported as known.
        Known cells get round(100·p), nudged where needed so that the value keeps its state:
        free cells at most the largest v with v/100 < free_thresh (19 by default), occupied cells
        at least the smallest v with v/100 > occupied_thresh (66). So
        :meth:`from_occupancy_values` gives back the same :meth:`states`.
        """
        p = self.prob()
        states = self.states(free_thresh, occupied_thresh)
        values = np.rint(100.0 * p)
        grades = np.arange(101)
        below = grades[grades / 100.0 < free_thresh]
        above = grades[grades / 100.0 > occupied_thresh]
        out = np.full(p.shape, -1, dtype=np.int8)
        if below.size:
            free = states == FREE
            out[free] = np.minimum(values[free], below.max())
        if above.size:
            occupied = states == OCCUPIED
            out[occupied] = np.maximum(values[occupied], above.min())
        return out.ravel()


# ------------------------------------------------------------------------------------ helpers


def _origin(origin: Sequence[float]) -> tuple[float, float]:
    if len(origin) != 2:
        raise ValueError(f"origin must be (x, y), got {origin!r}")
    return (float(origin[0]), float(origin[1]))
