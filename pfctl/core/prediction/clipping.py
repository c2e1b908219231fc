"""Map-aware clipping of a predicted path: never send the robot into a wall (§II-E, §III-B).

The predictors of :mod:`pfctl.core.prediction.models` know nothing of the house: a person walking
toward a wall is predicted to walk through it. The robot goes to the predicted point to look for
the person, so this module stops a predicted path where it first meets a blocked cell and keeps
every point of it in free space:

1. *Blocked cells* (:func:`blocked_cells`): the occupied cells of the occupancy grid (states of
   :meth:`pfctl.core.mapping.grid.OccupancyGrid.states`), plus, with a region map, the cells the
   region map says nobody can be in or pass through (outside the house, walls between regions that
   are not doors; :meth:`pfctl.core.mapping.regions.RegionMap.blocked_mask`). Cells outside the grid
   are blocked too. Unknown cells are passable — the person may well walk where the robot has not
   looked yet.
2. *The start* — the last observed position — is snapped to the centre of the nearest unblocked
   cell if it lies in a blocked one (a detection on a wall cell).
3. *Walking the path* (:func:`clip_path`): the polyline start → p₀ → p₁ → … is traversed cell by
   cell (Amanatides & Woo's exact grid traversal, 4-connected, so a path cannot slip between two
   diagonal wall cells). At the first blocked cell the path stops at the last point before it,
   clamped inside the last free cell; every later predicted point is that stop point (the person
   is assumed to wait at the wall, the robot will look there).
4. *The region* of the final point (:meth:`pfctl.core.mapping.regions.RegionMap.locate`) names the
room
   the robot should search.

Every returned point lies in an unblocked cell (asserted by a property test over random walls
and tracks).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.ndimage import distance_transform_edt

from pfctl.core.mapping.grid import OCCUPIED, GridGeometry, OccupancyGrid
from pfctl.core.mapping.regions import RegionMap

__all__ = ["ClippedPath", "blocked_cells", "clip_path", "clip_prediction"]

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]

#: How far inside its cell a clamped point is kept, as a fraction of the cell size.
_MARGIN = 1e-3


@dataclass(frozen=True, eq=False)
class ClippedPath:
    """A predicted path after clipping.

    ``xy`` (n, 2): the predicted points, those from ``stop_index`` on replaced by the stop point;
    ``start``: the start actually used (snapped if it was in a blocked cell); ``stop_index``: the
    first predicted point that could not be reached, or None if the whole path is free;
    ``region``: the region of the final point (None without a region map or outside every
    region).
    """

    xy: FloatArray
    start: FloatArray
    stop_index: int | None
    region: str | None = None

    @property
    def clipped(self) -> bool:
        return self.stop_index is not None

    @property
    def end(self) -> FloatArray:
        return self.xy[-1] if len(self.xy) else self.start


def blocked_cells(grid: OccupancyGrid, regions: RegionMap | None = None) -> BoolArray:
    """Cells a predicted path may not enter: occupied, or blocked by the region map's walls."""
    blocked = grid.states() == OCCUPIED
    if regions is not None:
        blocked = blocked | regions.blocked_mask(grid.geometry)
    return blocked


def _is_blocked(geometry: GridGeometry, blocked: BoolArray, row: int, col: int) -> bool:
    if not (0 <= row < geometry.height and 0 <= col < geometry.width):
        return True
    return bool(blocked[row, col])


def _cell_of(geometry: GridGeometry, p: FloatArray) -> tuple[int, int]:
    rows, cols = geometry.world_to_cell(p)
    return int(rows), int(cols)


def _clamp_into(geometry: GridGeometry, p: FloatArray, row: int, col: int) -> FloatArray:
    """``p`` moved (if needed) to lie strictly inside cell (row, col)."""
    res = geometry.resolution
    m = _MARGIN * res
    lo = np.array([geometry.origin[0] + col * res, geometry.origin[1] + row * res])
    out = np.clip(p, lo + m, lo + res - m)
    if _cell_of(geometry, out) != (row, col):  # float rounding at a far origin: use the centre
        out = geometry.cell_to_world(row, col)
    return out


def _nearest_free(geometry: GridGeometry, blocked: BoolArray, p: FloatArray) -> FloatArray:
    """The centre of the unblocked cell nearest to ``p`` (ValueError if every cell is blocked)."""
    if blocked.all():
        raise ValueError("every cell of the map is blocked; nowhere to put a prediction")
    row, col = _cell_of(geometry, p)
    if 0 <= row < geometry.height and 0 <= col < geometry.width:
        _, (rows, cols) = distance_transform_edt(blocked, return_indices=True)
        return geometry.cell_to_world(rows[row, col], cols[row, col])
    free_rows, free_cols = np.nonzero(~blocked)
    centres = geometry.cell_to_world(free_rows, free_cols)
    k = int(np.argmin(np.sum((centres - p) ** 2, axis=1)))
    return centres[k]


def _first_blocked(
    geometry: GridGeometry, blocked: BoolArray, a: FloatArray, b: FloatArray
) -> tuple[float, int, int] | None:
    """Walk segment a→b cell by cell; (t, row, col) of the last free cell before the first
    blocked one, t ∈ [0, 1] the parameter where the blocked cell is entered; None if all free.
    """
    res = geometry.resolution
    u0 = (a - np.asarray(geometry.origin)) / res
    u1 = (b - np.asarray(geometry.origin)) / res
    col, row = math.floor(u0[0]), math.floor(u0[1])
    d = u1 - u0
    step_c = 1 if d[0] > 0 else -1
    step_r = 1 if d[1] > 0 else -1
    inf = math.inf
    t_delta_c = abs(1.0 / d[0]) if d[0] != 0 else inf
    t_delta_r = abs(1.0 / d[1]) if d[1] != 0 else inf
    next_c = col + (1 if step_c > 0 else 0)
    next_r = row + (1 if step_r > 0 else 0)
    t_max_c = (next_c - u0[0]) / d[0] if d[0] != 0 else inf
    t_max_r = (next_r - u0[1]) / d[1] if d[1] != 0 else inf
    end_col, end_row = math.floor(u1[0]), math.floor(u1[1])
    # the number of cell boundaries crossed bounds the loop (robust to float ties)
    for _ in range(abs(end_col - col) + abs(end_row - row) + 2):
        if (col, row) == (end_col, end_row) and min(t_max_c, t_max_r) > 1.0:
            return None
        if t_max_c < t_max_r:
            t_enter, nc, nr = t_max_c, col + step_c, row
            t_max_c += t_delta_c
        else:
            t_enter, nc, nr = t_max_r, col, row + step_r
            t_max_r += t_delta_r
        if t_enter > 1.0:
            return None
        if _is_blocked(geometry, blocked, nr, nc):
            return max(0.0, min(1.0, t_enter)), row, col
        col, row = nc, nr
    return None


def clip_path(
    start: ArrayLike, path: ArrayLike, geometry: GridGeometry, blocked: BoolArray
) -> ClippedPath:
    """Stop the polyline ``start`` → ``path[0]`` → … at the first blocked cell (module docstring).

    ``blocked`` has the grid's shape (rows = y, cols = x); cells outside the grid are blocked.
    """
    start = np.asarray(start, dtype=float).reshape(2)
    pts = np.asarray(path, dtype=float).reshape(-1, 2)
    if blocked.shape != geometry.shape:
        raise ValueError(f"blocked mask has shape {blocked.shape}, geometry {geometry.shape}")
    if not (np.all(np.isfinite(start)) and np.all(np.isfinite(pts))):
        raise ValueError("start and path must be finite")
    if _is_blocked(geometry, blocked, *_cell_of(geometry, start)):
        start = _nearest_free(geometry, blocked, start)
    out = pts.copy()
    here = start
    for i, p in enumerate(pts):
        hit = _first_blocked(geometry, blocked, here, p)
        if hit is None and not _is_blocked(geometry, blocked, *_cell_of(geometry, p)):
            here = p
            continue
        if hit is None:  # float tie at the end point's boundary: stay where we are
            stop = here
        else:
            t, row, col = hit
            stop = _clamp_into(geometry, here + t * (p - here), row, col)
        out[i:] = stop
        return ClippedPath(out, start, i)
    return ClippedPath(out, start, None)


def clip_prediction(
    start: ArrayLike,
    path: ArrayLike,
    grid: OccupancyGrid,
    regions: RegionMap | None = None,
) -> ClippedPath:
    """Clip a predicted path to the map and name the region of its final point.

    ``start`` is the last observed position, ``path`` the predicted points in time order.
    Blocked cells are :func:`blocked_cells` of ``grid`` and ``regions``.
    """
    clipped = clip_path(start, path, grid.geometry, blocked_cells(grid, regions))
    region = regions.locate(clipped.end) if regions is not None else None
    return ClippedPath(clipped.xy, clipped.start, clipped.stop_index, region)
