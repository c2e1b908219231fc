"""The static scene around the laser: where the scan has been occupied persistently (Leigh 2015).

Leigh, Pineau, Olmedo and Zhang ("Person tracking and following with 2D laser scanners", ICRA
2015) keep a local occupancy grid in the odometry frame, updated from every scan, and start person
tracks only from clusters in free space: walls, furniture and anything else that stays put is
where people are not, and a classifier threshold low enough to find real legs at a distance
would otherwise fill the tracker with the scene's leg-like clutter. :class:`StaticScene` is that
grid for the leg detector, in the fixed frame the scans are posed in (the robot moves, the scene
does not), with occupancy counted in **seconds**, not scans, so any laser at any rate builds the
same scene:

- every cell holds the seconds of evidence that it is occupied, from −M to M =
  :data:`MEMORY_FACTOR` × ``static_after_s`` (negative: seen free): a scan adds its period (the
  time since the previous scan folded in, at most :data:`MAX_PERIOD_S`; scans come in at most
  every :data:`FOLD_PERIOD_S`) to the cells of its returns that the previous folds left
  occupied (from at least 0; a cell seen occupied for the first time holds no duration yet: it
  is known occupied from this scan on, and counting a whole period for it made a 3.75 Hz laser
  call a cell static after two scans, 0.27 s apart, where a 7.5 Hz one needed four) and takes
  :data:`FREE_RATE` × its period from the cells its beams pass through before their return;
- a cell is **static** once it holds ``static_after_s`` seconds: a wall or a chair seen from a
  moving robot gets there, a walking person's leg (a cell hit for a fraction of a second, then
  seen through) does not;
- a segment is static when at least :data:`STATIC_FRACTION` of its returns fall on static cells
  or their eight neighbours (a return jitters by a cell from scan to scan: pose and range noise).

The grid covers a square of :data:`WINDOW_M` around the laser and moves with it (cells that leave
the window are forgotten). The caller chooses which returns count as hits
(:meth:`StaticScene.update`'s ``keep_out``): the returns of people already tracked are left out,
so a person who stands still does not become scene.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pfctl.core.robot import LaserScan

#: Cell size of the grid, m (a leg is 0.1–0.15 m wide).
RESOLUTION = 0.1
#: Side of the square window around the laser that the grid covers, m.
WINDOW_M = 24.0
#: A scan's period counts at most this much (a gap in the scans is no evidence), s.
MAX_PERIOD_S = 0.5
#: Scans are folded in at most this often, each with the time since the last one folded: the
#: scene changes over seconds, so a 40 Hz laser costs what a 10 Hz one does, s.
FOLD_PERIOD_S = 0.1
#: A beam passing through a cell takes this many seconds per second of evidence away.
FREE_RATE = 1.0
#: A cell remembers at most this many times ``static_after_s`` (a wall seen for a minute comes
#: back to free in a bounded time when it was a parked trolley).
MEMORY_FACTOR = 2.0
#: A segment is static when at least this fraction of its returns are on static cells.
STATIC_FRACTION = 0.5
#: Beams without a return clear the cells up to this far, m (or the laser's range_max).
NO_RETURN_FREE_M = 8.0

#: The evidence of a cell seen occupied for the first time: positive (occupied now), no duration.
_JUST_HIT = 1e-9

_NEIGHBOURS = np.array([(dr, dc) for dr in (-1, 0, 1) for dc in (-1, 0, 1)])


class StaticScene:
    """Seconds of occupancy per cell of a window around the laser, in the scans' fixed frame."""

    def __init__(self, static_after_s: float, resolution: float = RESOLUTION) -> None:
        if not (math.isfinite(static_after_s) and static_after_s > 0):
            raise ValueError(f"static_after_s must be > 0 s, got {static_after_s}")
        self.static_after_s = float(static_after_s)
        self.resolution = float(resolution)
        self.size = math.ceil(WINDOW_M / self.resolution)
        self.reset()

    def reset(self) -> None:
        """Forget the scene (a new sequence of scans)."""
        self.seconds: NDArray[np.float64] = np.zeros((self.size, self.size))
        """Seconds of occupancy, ``[row, col]`` = ``[y, x]`` cell relative to :attr:`corner`."""
        self.corner: tuple[int, int] | None = None
        """Absolute (row, col) cell index of ``seconds[0, 0]``; None before the first scan."""
        self._last_stamp: float | None = None

    # ----------------------------------------------------------------------------- geometry

    def _cells(self, xy: ArrayLike) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
        """Window (rows, cols) of fixed-frame points ``(n, 2)``; may lie outside the window."""
        pts = np.asarray(xy, dtype=float).reshape(-1, 2)
        assert self.corner is not None
        rows = np.floor(pts[:, 1] / self.resolution).astype(np.intp) - self.corner[0]
        cols = np.floor(pts[:, 0] / self.resolution).astype(np.intp) - self.corner[1]
        return rows, cols

    def _follow(self, x: float, y: float) -> None:
        """Move the window so that it stays centred on ``(x, y)`` within a quarter of its side."""
        half = self.size // 2
        want = (
            math.floor(y / self.resolution) - half,
            math.floor(x / self.resolution) - half,
        )
        if self.corner is None:
            self.corner = want
            return
        dr, dc = want[0] - self.corner[0], want[1] - self.corner[1]
        if max(abs(dr), abs(dc)) <= self.size // 4:
            return
        moved = np.zeros_like(self.seconds)
        n = self.size
        src_r, dst_r = slice(max(dr, 0), n + min(dr, 0)), slice(max(-dr, 0), n + min(-dr, 0))
        src_c, dst_c = slice(max(dc, 0), n + min(dc, 0)), slice(max(-dc, 0), n + min(-dc, 0))
        if abs(dr) < n and abs(dc) < n:
            moved[dst_r, dst_c] = self.seconds[src_r, src_c]
        self.seconds = moved
        self.corner = want

    # ------------------------------------------------------------------------------ queries

    def static_fraction(self, xy: ArrayLike) -> NDArray[np.float64]:
        """For fixed-frame points ``(n, 2)``: 1.0 where the point's cell or one of its eight
        neighbours is static, else 0.0 (outside the window or before any scan: 0)."""
        pts = np.asarray(xy, dtype=float).reshape(-1, 2)
        out = np.zeros(len(pts))
        if self.corner is None or len(pts) == 0:
            return out
        rows, cols = self._cells(pts)
        r = rows[:, None] + _NEIGHBOURS[None, :, 0]
        c = cols[:, None] + _NEIGHBOURS[None, :, 1]
        inside = (r >= 0) & (r < self.size) & (c >= 0) & (c < self.size)
        held = np.zeros(r.shape)
        held[inside] = self.seconds[r[inside], c[inside]]
        out[(held >= self.static_after_s).any(axis=1)] = 1.0
        return out

    def cell_seconds(self, xy: ArrayLike) -> NDArray[np.float64]:
        """Seconds held by the cells of fixed-frame points (outside the window: 0)."""
        pts = np.asarray(xy, dtype=float).reshape(-1, 2)
        out = np.zeros(len(pts))
        if self.corner is None or len(pts) == 0:
            return out
        rows, cols = self._cells(pts)
        inside = (rows >= 0) & (rows < self.size) & (cols >= 0) & (cols < self.size)
        out[inside] = self.seconds[rows[inside], cols[inside]]
        return out

    def static_segments(
        self, xy: ArrayLike, start: ArrayLike, count: ArrayLike
    ) -> NDArray[np.bool_]:
        """Which segments are static: returns ``xy`` ``(n, 2)`` (fixed frame, segment by
        segment), each segment's ``start`` and ``count`` into them."""
        start = np.asarray(start, dtype=np.intp)
        count = np.asarray(count, dtype=np.intp)
        if len(start) == 0:
            return np.zeros(0, dtype=bool)
        on = np.add.reduceat(self.static_fraction(xy), start) / np.maximum(count, 1)
        return on >= STATIC_FRACTION

    # ------------------------------------------------------------------------------- update

    def update(self, scan: LaserScan, keep_out: NDArray[np.bool_] | None = None) -> None:
        """Fold ``scan`` (posed in the fixed frame) into the scene: its period of occupancy to
        the cells of its returns — except the beams marked in ``keep_out`` (one flag per beam:
        the returns of tracked people) — and the period times :data:`FREE_RATE` taken from the
        cells its beams cross before their return."""
        pose = scan.pose
        self._follow(pose.x, pose.y)
        if self._last_stamp is None or scan.stamp < self._last_stamp:
            self._last_stamp = scan.stamp
            return
        period = scan.stamp - self._last_stamp
        if period < FOLD_PERIOD_S - 1e-9:
            return
        self._last_stamp = scan.stamp
        period = min(period, MAX_PERIOD_S)
        if len(scan.ranges) == 0:
            return
        ranges = np.asarray(scan.ranges, dtype=float)
        with np.errstate(invalid="ignore"):
            returned = (
                np.isfinite(ranges)
                & (ranges >= max(scan.range_min, 1e-6))
                & (ranges <= scan.range_max)
            )
        angles = scan.angle_min + scan.angle_increment * np.arange(len(ranges))
        cos, sin = np.cos(angles), np.sin(angles)
        far = min(scan.range_max, NO_RETURN_FREE_M, 0.5 * WINDOW_M)
        reach = np.where(returned, np.minimum(ranges, far) - 1.5 * self.resolution, far)
        reach = np.nan_to_num(reach, nan=0.0, posinf=0.0, neginf=0.0)
        # every stride-th beam clears: neighbouring rays at most a cell apart at ``far``
        stride = max(1, int(self.resolution / max(abs(scan.angle_increment) * far, 1e-9)))
        rays = np.arange(0, len(ranges), stride)
        steps = np.arange(0.0, max(float(reach[rays].max(initial=0.0)), 0.0), self.resolution)
        beam, step = np.nonzero(steps[None, :] < reach[rays, None])
        beam = rays[beam]
        dist = steps[step]
        free = self._flat(pose.transform(np.column_stack((dist * cos[beam], dist * sin[beam]))))
        hit = returned if keep_out is None else returned & ~np.asarray(keep_out, dtype=bool)
        hits = self._flat(
            pose.transform(np.column_stack((ranges[hit] * cos[hit], ranges[hit] * sin[hit])))
        )
        # a cell listed twice gets the same value twice: no need for unique indices
        memory = MEMORY_FACTOR * self.static_after_s
        flat = self.seconds.reshape(-1)
        # A cell seen occupied now has been occupied since the last scan that saw it so (its
        # evidence positive), not for a whole period: a first hit is no duration yet.
        was_occupied = flat[hits] > 0.0
        flat[free] = np.maximum(flat[free] - FREE_RATE * period, -memory)
        held = np.minimum(np.maximum(flat[hits], 0.0) + period, memory)
        flat[hits] = np.where(was_occupied, held, _JUST_HIT)

    def _flat(self, xy: NDArray[np.float64]) -> NDArray[np.intp]:
        """Flat indices of the window's cells holding points ``xy`` (outside: dropped)."""
        rows, cols = self._cells(xy)
        inside = (rows >= 0) & (rows < self.size) & (cols >= 0) & (cols < self.size)
        return rows[inside] * self.size + cols[inside]


__all__ = ["StaticScene"]
