"""Path lengths on the occupancy grid: the distances d(·,·) of the utility (Eq. 3, §II-D).

The utility of a frontier cluster ``c`` charges the way there and on to the heading region,
``d(x, c) + d(c, l*)``. Straight-line distances would make a frontier behind a wall look as close
as one in the same room, so here ``d(a, b)`` is

* the straight-line length ``‖a − b‖`` when the **line of sight** between ``a`` and ``b`` is free
  (no blocked fine cell along the segment), and otherwise
* the length of the shortest **8-connected grid path** through traversable cells (Dijkstra,
  ``scipy.sparse.csgraph.dijkstra``), never less than ``‖a − b‖``.

Which cells are traversable. By default every cell that is not occupied (``grid.states()`` !=
OCCUPIED) — free *and unknown* — because exploration has to plan through space it has not seen yet
(the frontier it heads for borders unknown space, and the heading region l* may be entirely
unknown). ``unknown_traversable=False`` restricts paths to known-free cells.

Speed: a Dijkstra over every cell of a house-sized map at 0.05 m is too slow for a tick
(benchmarks/README.md, ``bench_map_core.py``), so the paths are searched on a **coarser grid** of
``downsample`` × ``downsample`` fine cells per coarse cell (default: the factor giving cells closest
to ``COARSE_RESOLUTION`` = 0.2 m, i.e. 4 at 0.05 m, 16 times fewer cells; ``downsample=1`` searches
the fine grid itself). The coarsening is conservative: a coarse cell is blocked as soon as any of
its fine cells is blocked, so walls never leak; openings narrower than about two coarse cells may
close (the doors of a house are ~0.9 m wide), and paths keep up to a coarse cell from walls, so they
come out a little longer than on the fine grid. Diagonal steps may not cut the corner of a blocked
cell. The exact end points are joined to the coarse grid by straight segments to the centres of the
3 × 3 coarse cells around them, each kept only when its line of sight is free on the fine grid — so
a robot standing in a coarse cell that a nearby wall blocks still gets a path, and no shortcut
crosses a wall. On the fine grid (``downsample=1``) a path length lies between the Euclidean
shortest path length and ~1.08 times it (the 8-connected metric, 1/cos 22.5°).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property, lru_cache
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import dijkstra

from pfctl.core.mapping.grid import FREE_THRESH, OCCUPIED, OCCUPIED_THRESH, UNKNOWN, GridGeometry

if TYPE_CHECKING:
    from pfctl.core.mapping.grid import OccupancyGrid

__all__ = [
    "COARSE_RESOLUTION",
    "SEARCH_MARGIN",
    "DistanceField",
    "Traversability",
    "auto_downsample",
    "distance_fields",
    "grid_distances",
    "line_of_sight",
    "traversability",
]

_SQRT2 = float(np.sqrt(2.0))

#: How far (m) path searches may reach beyond the known part of the map and the start points.
SEARCH_MARGIN = 2.0

#: Target cell size (m) of the coarse grid paths are searched on, when ``downsample`` is None.
COARSE_RESOLUTION = 0.2


def auto_downsample(resolution: float) -> int:
    """The default coarsening factor: fine cells per coarse cell side, ≈ COARSE_RESOLUTION."""
    return max(1, round(COARSE_RESOLUTION / resolution))


_NEIGHBOURS_3X3 = np.array([(dr, dc) for dr in (-1, 0, 1) for dc in (-1, 0, 1)], dtype=np.intp)


@dataclass(frozen=True, eq=False)
class Traversability:
    """Which cells a path may enter, on the fine grid and on the coarse grid the search runs on.

    ``blocked`` is the fine ``(height, width)`` mask of cells no path may enter (and no line of
    sight may cross); ``coarse_free`` is the ``(ceil(height/f), ceil(width/f))`` mask of coarse
    cells, free only when none of their fine cells is blocked (``f = factor``); fine cells beyond
    the map edge that pad the last coarse row/column do not block.

    ``search_box`` = ``(row0, row1, col0, col1)`` (coarse, end exclusive) bounds the Dijkstra
    search: the known (not unknown) cells grown by the search margin; each search also covers
    its start points grown by the margin. None: the whole grid.
    """

    geometry: GridGeometry
    blocked: NDArray[np.bool_]
    factor: int
    coarse_geometry: GridGeometry
    coarse_free: NDArray[np.bool_]
    search_box: tuple[int, int, int, int] | None = None
    margin_cells: int = 0

    @cached_property
    def framed(self) -> NDArray[np.bool_]:
        """``blocked`` framed by blocked cells, flattened: the lookup of :func:`_sight` (made
        once: each distance field tests many segments against it)."""
        return _framed(self.blocked)


def traversability(
    grid_or_free_mask: OccupancyGrid | ArrayLike,
    *,
    geometry: GridGeometry | None = None,
    downsample: int | None = None,
    unknown_traversable: bool = True,
    free_thresh: float = FREE_THRESH,
    occupied_thresh: float = OCCUPIED_THRESH,
    known: ArrayLike | None = None,
    search_margin: float = SEARCH_MARGIN,
) -> Traversability:
    """The :class:`Traversability` of an occupancy grid or of a boolean traversable-cell mask.

    With an ``OccupancyGrid``, traversable cells are the non-occupied ones of
    ``grid.states(free_thresh, occupied_thresh)`` (or only the free ones if
    ``unknown_traversable`` is False). With a boolean ``(height, width)`` mask (True = traversable),
    ``geometry`` is required and the thresholds are ignored. ``downsample`` is the coarsening
    factor (None: :func:`auto_downsample`).

    Searches are confined to the bounding box of the ``known`` cells (bool mask; from a grid,
    the non-unknown cells) and of the start points, each grown by ``search_margin`` metres: a
    path that would have to leave that box through unexplored space is not found (its length is
    ``inf``). With no ``known`` mask, or no known cell, the whole grid is searched.
    """
    if downsample is not None and downsample < 1:
        raise ValueError(f"downsample must be >= 1, got {downsample}")
    if hasattr(grid_or_free_mask, "states"):
        grid: Any = grid_or_free_mask
        states = grid.states(free_thresh=free_thresh, occupied_thresh=occupied_thresh)
        blocked = states == OCCUPIED
        if known is None:
            known = states != UNKNOWN
        if not unknown_traversable:
            blocked |= states == UNKNOWN
        geometry = grid.geometry
    else:
        if geometry is None:
            raise ValueError("a traversable mask needs its GridGeometry")
        blocked = ~np.asarray(grid_or_free_mask, dtype=bool)
    assert geometry is not None
    if blocked.shape != geometry.shape:
        raise ValueError(f"mask shape {blocked.shape} != grid shape {geometry.shape}")
    f = auto_downsample(geometry.resolution) if downsample is None else int(downsample)
    hc, wc = -(-geometry.height // f), -(-geometry.width // f)
    padded = np.zeros((hc * f, wc * f), dtype=bool)
    padded[: geometry.height, : geometry.width] = blocked
    coarse_blocked = _any_blocks(padded, f)
    coarse_geometry = GridGeometry(geometry.resolution * f, wc, hc, geometry.origin)
    margin = max(1, int(np.ceil(search_margin / coarse_geometry.resolution)))
    box = None
    if known is not None:
        known_mask = np.asarray(known, dtype=bool)
        if known_mask.shape != geometry.shape:
            raise ValueError(f"known mask shape {known_mask.shape} != grid shape {geometry.shape}")
        rows = np.flatnonzero(known_mask.any(axis=1))
        cols = np.flatnonzero(known_mask.any(axis=0))
        if rows.size:
            box = (
                max(int(rows[0]) // f - margin, 0),
                min(int(rows[-1]) // f + margin + 1, hc),
                max(int(cols[0]) // f - margin, 0),
                min(int(cols[-1]) // f + margin + 1, wc),
            )
    return Traversability(geometry, blocked, f, coarse_geometry, ~coarse_blocked, box, margin)


#: Unsigned integers as wide as f booleans: a row of f fine cells read as one number.
_BLOCK_WORDS: dict[int, type[np.unsignedinteger[Any]]] = {
    1: np.uint8,
    2: np.uint16,
    4: np.uint32,
    8: np.uint64,
}


def _any_blocks(mask: NDArray[np.bool_], f: int) -> NDArray[np.bool_]:
    """True for each ``f`` × ``f`` block of the C-contiguous ``(hc·f, wc·f)`` ``mask`` with any
    True cell: ``mask.reshape(hc, f, wc, f).any(axis=(1, 3))``, without numpy's slow reduction
    over two short axes (each row's ``f`` cells are read as one integer when ``f`` is 1, 2, 4
    or 8)."""
    hf, wf = mask.shape
    word = _BLOCK_WORDS.get(f)
    if word is not None:
        cols = np.ascontiguousarray(mask).view(word) != 0
    else:
        cols = mask.reshape(hf, wf // f, f).any(axis=2)
    out: NDArray[np.bool_] = cols.reshape(hf // f, f, wf // f).any(axis=1)
    return out


def _framed(blocked: ArrayLike) -> NDArray[np.bool_]:
    """``blocked`` (``(height, width)``) inside a frame of blocked cells, flattened: a segment
    sample off the map lands on the frame (:func:`_sight`)."""
    b = np.asarray(blocked)
    framed = np.ones((b.shape[0] + 2, b.shape[1] + 2), dtype=bool)
    framed[1:-1, 1:-1] = b
    return framed.ravel()


def _samples(longest: float, step: float) -> int:
    """Samples per segment of :func:`line_of_sight`: the longest segment every ``step``, both
    ends included."""
    return int(np.ceil(longest / step)) + 1


@lru_cache(maxsize=64)
def _fractions(n: int) -> NDArray[np.float64]:
    """``np.linspace(0, 1, max(n, 2))``, read-only: where along a segment the samples lie."""
    t = np.linspace(0.0, 1.0, max(n, 2))
    t.flags.writeable = False
    return t


def _sight(
    framed: NDArray[np.bool_],
    geometry: GridGeometry,
    a: NDArray[np.float64],
    d: NDArray[np.float64],
    n: int,
) -> NDArray[np.bool_]:
    """:func:`line_of_sight` of the segments ``a → a + d`` (``a`` and ``d`` broadcast against
    each other, ``(..., 2)``) at ``n`` samples each, over the :func:`_framed` blocked cells of a
    grid with ``geometry``.

    The samples and their cells are computed as :func:`line_of_sight` and
    :meth:`GridGeometry.world_to_cell` do, one coordinate at a time (each operation runs along
    the samples); cells off the map are clamped onto the frame (blocked), so one lookup replaces
    the bounds test.
    """
    t = _fractions(n)
    cells = []
    for axis, size in ((0, geometry.width), (1, geometry.height)):
        u = a[..., axis, None] + d[..., axis, None] * t
        u -= geometry.origin[axis]
        u /= geometry.resolution
        np.floor(u, out=u)
        np.fmin(u, float(size), out=u)  # fmin/fmax: NaN goes to the frame too
        np.fmax(u, -1.0, out=u)
        cells.append(u)
    cols, index = cells
    width = geometry.width + 2
    index *= width  # (row + 1) · width + (col + 1)
    index += cols
    index += width + 1
    hit = framed[index.astype(np.intp)]
    clear: NDArray[np.bool_] = ~hit.any(axis=-1)
    return clear


def line_of_sight(
    blocked: NDArray[np.bool_],
    geometry: GridGeometry,
    a: ArrayLike,
    b: ArrayLike,
    step: float | None = None,
) -> NDArray[np.bool_]:
    """True where the segment(s) ``a → b`` cross no blocked cell and stay inside the map.

    ``a`` and ``b`` broadcast against each other with shape ``(..., 2)``; the result has shape
    ``(...)``. The segments are sampled every ``step`` metres (default a third of a cell), the
    end points included. ValueError when ``blocked`` is not of ``geometry``'s shape.
    """
    a = np.asarray(a, dtype=float)
    d = np.asarray(b, dtype=float) - a
    step = geometry.resolution / 3.0 if step is None else step
    if np.shape(blocked) != geometry.shape:
        raise ValueError(f"blocked mask shape {np.shape(blocked)} != grid shape {geometry.shape}")
    n = _samples(np.linalg.norm(d, axis=-1).max(initial=0.0), step)
    return _sight(_framed(blocked), geometry, a, d, n)


@dataclass(frozen=True, eq=False)
class DistanceField:
    """Path lengths from one start point to everywhere: ``field(points)`` is d(start, points).

    ``distances[r, c]`` is the shortest-path length (metres) from ``start`` to the centre of coarse
    cell ``(r, c)`` of ``traversability.coarse_geometry`` (``inf`` where unreachable).
    """

    traversability: Traversability
    start: NDArray[np.float64]
    distances: NDArray[np.float64] = field(repr=False)

    def at(self, points: ArrayLike) -> NDArray[np.float64]:
        """The grid-path length to ``points`` (shape ``(..., 2)``), without the straight-line rule.

        The minimum over the 3 × 3 coarse cells around each point of (distance to the cell's
        centre + straight segment from it to the point), over cells whose segment is in line of
        sight; ``inf`` where no such cell is reachable.
        """
        return self._at(np.asarray(points, dtype=float))

    def _at(
        self, pts: NDArray[np.float64], need: NDArray[np.bool_] | None = None
    ) -> NDArray[np.float64]:
        """:meth:`at` of ``pts``; with ``need`` (shape ``pts.shape[:-1]``) only of those points
        (the others come out ``inf``), each as :meth:`at` of all of them gives it: the segments
        are sampled as :func:`line_of_sight` would sample all of them (by the longest)."""
        tr = self.traversability
        cg = tr.coarse_geometry
        rows, cols = cg.world_to_cell(pts)
        nr = rows[..., None] + _NEIGHBOURS_3X3[:, 0]
        nc = cols[..., None] + _NEIGHBOURS_3X3[:, 1]
        inside = cg.in_bounds(nr, nc)
        nr_c = np.clip(nr, 0, cg.height - 1)
        nc_c = np.clip(nc, 0, cg.width - 1)
        base = np.where(inside, self.distances[nr_c, nc_c], np.inf)
        centres = cg.cell_to_world(nr_c, nc_c)
        join = np.linalg.norm(centres - pts[..., None, :], axis=-1)
        finite = np.isfinite(base)
        if finite.any():
            # Samples per segment as line_of_sight(centres[finite], pts[finite]) takes them.
            n = _samples(join[finite].max(), tr.geometry.resolution / 3.0)
            test = finite if need is None else finite & need[..., None]
            seen = np.zeros(base.shape, dtype=bool)
            if test.any():
                ends = np.broadcast_to(pts[..., None, :], centres.shape)[test]
                seen[test] = _sight(tr.framed, tr.geometry, centres[test], ends - centres[test], n)
            base = np.where(seen, base + join, np.inf)
        return base.min(axis=-1)

    def __call__(self, points: ArrayLike) -> NDArray[np.float64]:
        """d(start, points): ``‖start − p‖`` where the line of sight is free, else the grid path.

        The grid path is never reported shorter than the straight line. Shape ``(...)`` for
        points of shape ``(..., 2)``.
        """
        tr = self.traversability
        pts = np.asarray(points, dtype=float)
        away = pts - self.start
        straight = np.linalg.norm(away, axis=-1)
        n = _samples(straight.max(initial=0.0), tr.geometry.resolution / 3.0)
        los = _sight(tr.framed, tr.geometry, self.start, away, n)
        if np.all(los):
            return straight
        # The grid path only where the line of sight is blocked.
        return np.where(los, straight, np.maximum(straight, self._at(pts, ~los)))


_STEPS = tuple((dr, dc) for dr in (-1, 0, 1) for dc in (-1, 0, 1) if dr or dc)
_STEP_LENGTHS = np.array([_SQRT2 if dr and dc else 1.0 for dr, dc in _STEPS])


def distance_fields(tr: Traversability, starts: ArrayLike) -> list[DistanceField]:
    """One :class:`DistanceField` per start point (shape ``(k, 2)``), in one Dijkstra call.

    The coarse grid inside the search window (``tr.search_box`` ∪ the starts' cells, grown by
    ``tr.margin_cells``) becomes an 8-connected graph — no diagonal step past a blocked corner —
    and each start joins it through a virtual node connected to the (traversable, line-of-sight)
    centres of the 3 × 3 coarse cells around it.
    """
    starts = np.atleast_2d(np.asarray(starts, dtype=float))
    k = len(starts)
    cg = tr.coarse_geometry
    H, W = cg.height, cg.width
    rows, cols = cg.world_to_cell(starts)
    # The search window, in coarse cells (end exclusive).
    m = tr.margin_cells
    r0, r1 = int(np.min(rows)) - m, int(np.max(rows)) + m + 1
    c0, c1 = int(np.min(cols)) - m, int(np.max(cols)) + m + 1
    if tr.search_box is None:
        r0, r1, c0, c1 = 0, H, 0, W
    else:
        br0, br1, bc0, bc1 = tr.search_box
        r0, r1, c0, c1 = min(r0, br0), max(r1, br1), min(c0, bc0), max(c1, bc1)
    r0, r1, c0, c1 = max(r0, 0), min(r1, H), max(c0, 0), min(c1, W)
    h, w = max(r1 - r0, 0), max(c1 - c0, 0)
    # Window padded by one blocked cell all round, so every neighbour index stays in range.
    wp = w + 2
    free = np.zeros((h + 2, wp), dtype=bool)
    free[1:-1, 1:-1] = tr.coarse_free[r0:r1, c0:c1]
    free = free.ravel()
    n = free.size
    step = np.array([dr * wp + dc for dr, dc in _STEPS])
    # ok[v, j]: node v and the node of step j from it are free (a diagonal step also needs both
    # cells it passes between). Shifted slices: every node off the pad has all its neighbours
    # in range, and a node on the pad is not free.
    ok = np.zeros((n, len(_STEPS)), dtype=bool)
    for j, (dr, dc) in enumerate(_STEPS):
        shifts = (step[j], dr * wp, dc) if dr and dc else (step[j],)
        lo, hi = max(0, -min(shifts)), n - max(0, max(shifts))
        both = free[lo:hi] & free[lo + step[j] : hi + step[j]]
        if dr and dc:
            both &= free[lo + dr * wp : hi + dr * wp] & free[lo + dc : hi + dc]
        ok[lo:hi, j] = both
    edges = np.flatnonzero(ok)  # node by node, steps in order
    sources, steps = edges >> 3, edges & 7  # divmod by len(_STEPS) == 8
    # Virtual start nodes n .. n+k-1: edges to the 3×3 coarse cells around each start.
    nr = rows[:, None] + _NEIGHBOURS_3X3[:, 0]
    nc = cols[:, None] + _NEIGHBOURS_3X3[:, 1]
    inside = (nr >= r0) & (nr < r1) & (nc >= c0) & (nc < c1)
    nr_c, nc_c = np.clip(nr, 0, H - 1), np.clip(nc, 0, W - 1)
    centres = cg.cell_to_world(nr_c, nc_c)
    joinable = inside & tr.coarse_free[nr_c, nc_c]
    offsets = centres - starts[:, None, :]
    join = np.linalg.norm(offsets, axis=-1)
    if joinable.any():
        n_samples = _samples(join[joinable].max(), tr.geometry.resolution / 3.0)
        joinable[joinable] = _sight(
            tr.framed,
            tr.geometry,
            np.broadcast_to(starts[:, None, :], centres.shape)[joinable],
            offsets[joinable],
            n_samples,
        )
    join_len = join / cg.resolution
    counts = np.concatenate([np.bincount(sources, minlength=n), joinable.sum(axis=1)])
    # The index arrays in the dtype scipy would cast them to (it checks them otherwise).
    index_dtype = np.int32 if n + k + len(edges) + joinable.size < 2**31 else np.int64
    indptr = np.concatenate([[0], np.cumsum(counts)]).astype(index_dtype)
    indices = np.concatenate(
        [sources + step[steps], ((nr_c - r0 + 1) * wp + (nc_c - c0 + 1))[joinable]]
    ).astype(index_dtype)
    weights = np.concatenate([_STEP_LENGTHS[steps], join_len[joinable]])
    graph = csr_matrix((weights, indices, indptr), shape=(n + k, n + k))
    dist = np.atleast_2d(dijkstra(graph, directed=True, indices=np.arange(n, n + k)))
    window = dist[:, :n].reshape(k, h + 2, wp)[:, 1:-1, 1:-1] * cg.resolution
    out = []
    for i in range(k):
        full = np.full((H, W), np.inf)
        full[r0:r1, c0:c1] = window[i]
        out.append(DistanceField(tr, starts[i].copy(), full))
    return out


def grid_distances(
    grid_or_free_mask: OccupancyGrid | ArrayLike,
    start_xy: ArrayLike,
    *,
    geometry: GridGeometry | None = None,
    downsample: int | None = None,
    unknown_traversable: bool = True,
    free_thresh: float = FREE_THRESH,
    occupied_thresh: float = OCCUPIED_THRESH,
) -> DistanceField:
    """Path lengths from ``start_xy`` over the 8-connected grid of traversable cells (Dijkstra).

    ``grid_or_free_mask`` is an ``OccupancyGrid`` or a boolean traversable mask with its
    ``geometry``; see :func:`traversability` for the options and the module docstring for the
    metric. ``result(points)`` gives d(start, points) with the straight-line rule,
    ``result.at(points)`` the pure grid-path length, ``result.distances`` the coarse field.
    """
    tr = traversability(
        grid_or_free_mask,
        geometry=geometry,
        downsample=downsample,
        unknown_traversable=unknown_traversable,
        free_thresh=free_thresh,
        occupied_thresh=occupied_thresh,
    )
    return distance_fields(tr, np.asarray(start_xy, dtype=float)[None, :])[0]
