"""Frontiers of the occupancy grid (Eq. 2, §II-C) and their utility (Eq. 3, §II-D).

A frontier is the border between known-free and unknown space: going there reveals the unknown.
The paper finds frontier cells with the frontier map of **Eq. 2**,

    F = ‖∇Λ‖₁ − β (‖∇Λ_o‖₁ + Λ_o − 0.5),

clusters them, and scores each cluster ``c`` for a robot at ``x`` heading to region ``l*`` with
the utility of **Eq. 3**, ``U(c, x, l*) = α·N − (d(x, c) + d(c, l*))``, with ``N`` the number of
unknown cells the cluster borders. Precisely, here:

* **Λ** is the trinary map built from the grid's states (``grid.states()``): occupied 1, free 0,
  unknown 0.5 — so sensor noise inside free space (p = 0.1 vs 0.15) never shows as a gradient.
* **Λ_o** is the obstacle map: 1 on occupied cells, 0.5 elsewhere; so ``Λ_o − 0.5`` is 0.5 on
  obstacles and 0 elsewhere.
* **‖∇X‖₁** at a cell is the L1 norm of its eight neighbour differences (the forward and backward
  differences along x, y and both diagonals): ``Σ_{n ∈ N8(c)} |X(n) − X(c)|``, with the map edge
  replicated (no gradient across the border of the map). Any cell with a differently valued
  8-neighbour lights up, on both sides of a border: a free cell with ``k_u`` unknown and ``k_o``
  occupied neighbours has ``F = 0.5·k_u + (1 − β/2)·k_o``; an unknown cell next to an obstacle
  has ``‖∇Λ‖₁`` contributions of 0.5 per obstacle neighbour, cancelled at β ≥ 1; obstacle cells
  get the extra −β/2. At β = 2 every border touching an obstacle cancels (free cells keep
  ``0.5·k_u``, obstacle cells go negative); the shipped mission's β = 1 leaves the free side of
  walls at ``0.5·k_o``.

Eq. 2 alone thus lights up both sides of every border, and with β < 2 also the free side of
walls. The frontier cells of :func:`find_frontiers` are therefore, exactly:

    F > threshold  ∧  the cell is known free  ∧  an 8-neighbour is unknown  ∧  no 8-neighbour is
    occupied,

i.e. the known-free side of the free/unknown border, minus the cells that touch a wall (those
would send the robot into the wall's corner, and a wall seen edge-on is not a way into unknown
space). For ``0 ≤ threshold < 0.5`` the F test is implied by the others (F ≥ 0.5 there), so the
frontier cells are exactly "free, 8-adjacent to unknown, not 8-adjacent to occupied". Clusters are
the 8-connected components of frontier cells (``scipy.ndimage.label``); smaller than
``min_cells`` are dropped.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import ndimage

from pfctl.core.mapping.grid import (
    FREE,
    FREE_THRESH,
    OCCUPIED,
    OCCUPIED_THRESH,
    UNKNOWN,
    GridGeometry,
)

if TYPE_CHECKING:
    from pfctl.core.mapping.grid import OccupancyGrid

__all__ = [
    "FrontierCluster",
    "closest_point",
    "closest_points",
    "cluster_utilities",
    "find_frontiers",
    "frontier_map",
    "frontiers_from_states",
    "gradient_l1",
    "trinary_map",
    "utility",
]

_EIGHT = np.ones((3, 3), dtype=bool)
_OFFSETS = ((-1, -1), (-1, 0), (-1, 1), (0, -1), (0, 1), (1, -1), (1, 0), (1, 1))

#: d(·) of Eq. 3 as a function of points: (k, 2) → (k,) metres.
DistanceFn = Callable[[NDArray[np.float64]], NDArray[np.float64]]


def gradient_l1(x: ArrayLike) -> NDArray[np.float64]:
    """‖∇X‖₁ of Eq. 2: ``Σ_{n ∈ N8(c)} |X(n) − X(c)|`` per cell, map edge replicated."""
    x = np.asarray(x, dtype=np.float64)
    p = np.pad(x, 1, mode="edge")
    h, w = x.shape
    out = np.zeros_like(x)
    for dr, dc in _OFFSETS:
        out += np.abs(p[1 + dr : 1 + dr + h, 1 + dc : 1 + dc + w] - x)
    return out


def trinary_map(states: ArrayLike) -> NDArray[np.float64]:
    """Λ of Eq. 2 from FREE/OCCUPIED/UNKNOWN states: O = 1, F = 0, U = 0.5."""
    s = np.asarray(states)
    lam = np.full(s.shape, 0.5)
    lam[s == FREE] = 0.0
    lam[s == OCCUPIED] = 1.0
    return lam


def frontier_map(
    grid_prob: ArrayLike, obstacle_mask: ArrayLike, beta: float
) -> NDArray[np.float64]:
    """The frontier map of **Eq. 2**: F = ‖∇Λ‖₁ − β (‖∇Λ_o‖₁ + Λ_o − 0.5).

    ``grid_prob`` is Λ, the map as probabilities — meant to be the trinary map (occupied 1,
    free 0, unknown 0.5; see :func:`trinary_map`) so that noise in free space shows no gradient.
    ``obstacle_mask`` (bool, same shape) marks the obstacles; Λ_o is 1 there and 0.5 elsewhere.
    ‖∇·‖₁ is :func:`gradient_l1` (the eight neighbour differences). See the module docstring for
    what the terms do at each kind of border.
    """
    lam = np.asarray(grid_prob, dtype=np.float64)
    obstacles = np.asarray(obstacle_mask, dtype=bool)
    if lam.shape != obstacles.shape:
        raise ValueError(f"Λ has shape {lam.shape} but the obstacle mask {obstacles.shape}")
    lam_o = np.where(obstacles, 1.0, 0.5)
    return gradient_l1(lam) - beta * (gradient_l1(lam_o) + lam_o - 0.5)


@dataclass(frozen=True, eq=False)
class FrontierCluster:
    """One cluster of frontier cells (§II-C).

    ``cells`` are ``(row, col)`` grid indices (k, 2); ``points`` their centres in the map frame
    (k, 2) (from :func:`frontiers_from_states`: read-only slices of arrays its clusters share);
    ``centroid`` the mean of ``points``; ``n_unknown`` is N of Eq. 3: the number of distinct
    unknown cells in the 8-neighbourhoods of the cluster's cells.
    """

    cells: NDArray[np.intp] = field(repr=False)
    points: NDArray[np.float64] = field(repr=False)
    centroid: tuple[float, float]
    n_unknown: int

    @property
    def size(self) -> int:
        """Number of frontier cells."""
        return len(self.cells)


def find_frontiers(
    grid: OccupancyGrid,
    beta: float,
    threshold: float,
    min_cells: int,
    free_thresh: float = FREE_THRESH,
    occupied_thresh: float = OCCUPIED_THRESH,
) -> list[FrontierCluster]:
    """Frontier clusters of an occupancy grid (Eq. 2, §II-C), largest first.

    Frontier cells are ``F > threshold ∧ free ∧ 8-adjacent to unknown ∧ not 8-adjacent to
    occupied`` (module docstring), with the states of ``grid.states(free_thresh,
    occupied_thresh)``; clusters are their 8-connected components of at least ``min_cells`` cells.
    Ties in size are broken by the first cell in row-major order, so the order is deterministic.
    """
    states = grid.states(free_thresh, occupied_thresh)
    return frontiers_from_states(states, grid.geometry, beta, threshold, min_cells)


def _dilate8(mask: NDArray[np.bool_]) -> NDArray[np.bool_]:
    """Binary dilation by the 3 × 3 square (separable: rows, then columns)."""
    rows = mask.copy()
    rows[:, 1:] |= mask[:, :-1]
    rows[:, :-1] |= mask[:, 1:]
    out = rows.copy()
    out[1:, :] |= rows[:-1, :]
    out[:-1, :] |= rows[1:, :]
    return out


def _squeeze(index: NDArray[np.intp], size: int) -> tuple[NDArray[np.intp], int]:
    """New positions of the lines ``index`` (of ``size``) with the unused lines dropped but one
    after each run of used ones, and the new size: lines next to each other stay so, lines
    apart stay apart, the order is kept."""
    used = np.zeros(size + 1, dtype=bool)
    used[index] = True
    keep = used.copy()
    keep[1:] |= used[:-1]
    position = np.cumsum(keep) - 1
    return position[index], int(position[-1]) + 1


def frontiers_from_states(
    states: ArrayLike,
    geometry: GridGeometry,
    beta: float,
    threshold: float,
    min_cells: int,
) -> list[FrontierCluster]:
    """:func:`find_frontiers` on a FREE/OCCUPIED/UNKNOWN state array with its geometry.

    For speed, Eq. 2 is evaluated only at the cells the other three conditions leave (free, an
    unknown and no occupied 8-neighbour) — the same values :func:`frontier_map` gives there.
    """
    s = np.asarray(states, dtype=np.int8)
    h, w = s.shape
    unknown = s == UNKNOWN
    occupied = s == OCCUPIED
    candidate = (s == FREE) & _dilate8(unknown) & ~_dilate8(occupied)
    # Cells are handled by their index in the map framed by one cell all round (frame width wf):
    # one flat lookup per neighbour offset. np.flatnonzero: row-major, as np.nonzero (faster).
    wf = w + 2
    rr, cc = np.divmod(np.flatnonzero(candidate), w)
    at = (rr + 1) * wf + (cc + 1)
    offsets = np.array([dr * wf + dc for dr, dc in _OFFSETS])
    if rr.size:
        # Eq. 2 at the candidates, their 3×3 neighbourhood of states with the map edge
        # replicated. A candidate is free and none of those cells is occupied (the replicated
        # ones are cells of that neighbourhood too), so Λ_o is 0.5 all over it: ‖∇Λ_o‖₁ and
        # Λ_o − 0.5 vanish and ‖∇Λ‖₁ is 0.5 per unknown neighbour, exactly the sums of
        # frontier_map (β·0 kept: an infinite β makes F undefined there too).
        framed = np.empty((h + 2, wf), dtype=np.int8)
        framed[1:-1, 1:-1] = s
        framed[0, 1:-1], framed[-1, 1:-1] = s[0], s[-1]
        framed[:, 0], framed[:, -1] = framed[:, 1], framed[:, -2]
        neigh = framed.ravel()[at[:, None] + offsets]
        F = 0.5 * np.count_nonzero(neigh == UNKNOWN, axis=1) - beta * 0.0
        keep = threshold < F
        rr, cc, at = rr[keep], cc[keep], at[keep]
    if rr.size == 0:
        return []
    # Label the 8-connected components on the map squeezed to the rows and columns that hold
    # frontier cells (an empty line kept between runs of them): the same neighbours, the same
    # raster order, far fewer cells for ndimage.label.
    r2, rows = _squeeze(rr, h)
    c2, cols = _squeeze(cc, w)
    frontier = np.zeros((rows, cols), dtype=bool)
    frontier[r2, c2] = True
    labels, n = ndimage.label(frontier, structure=_EIGHT)
    lab = labels[r2, c2]  # rr, cc are in row-major order
    sizes = np.bincount(lab, minlength=n + 1)
    # N: distinct unknown cells in the 8-neighbourhood of each cluster (cells off the map are
    # not unknown), as (label, framed cell index) pairs.
    upad = np.zeros((h + 2, wf), dtype=bool)
    upad[1:-1, 1:-1] = unknown
    around = at[:, None] + offsets
    hit = upad.ravel()[around]
    pairs = lab[:, None].astype(np.int64) * upad.size + around
    pairs = np.sort(pairs[hit])
    distinct = np.ones(pairs.shape, dtype=bool)
    distinct[1:] = pairs[1:] != pairs[:-1]
    n_unknown = np.bincount(pairs[distinct] // upad.size, minlength=n + 1)
    order = np.argsort(lab, kind="stable")
    bounds = np.searchsorted(lab[order], np.arange(1, n + 2)).tolist()
    # Every cluster's cells and points are slices of these (read-only), in row-major order.
    cells_all = np.stack([rr[order], cc[order]], axis=1).astype(np.intp)
    points_all = geometry.cell_to_world(cells_all[:, 0], cells_all[:, 1])
    cells_all.flags.writeable = False
    points_all.flags.writeable = False
    first_cell = (cells_all[:, 0] * w + cells_all[:, 1]).tolist()
    sizes_list, n_unknown_list = sizes.tolist(), n_unknown.tolist()
    clusters: list[tuple[int, int, FrontierCluster]] = []
    for i in range(1, n + 1):
        if sizes_list[i] < min_cells:
            continue
        a, b = bounds[i - 1], bounds[i]
        points = points_all[a:b]
        centroid = np.add.reduce(points, axis=0) / (b - a)  # points.mean(axis=0)
        cluster = FrontierCluster(
            cells_all[a:b], points, (float(centroid[0]), float(centroid[1])), n_unknown_list[i]
        )
        clusters.append((-sizes_list[i], first_cell[a], cluster))
    clusters.sort(key=lambda t: (t[0], t[1]))
    return [c for _, _, c in clusters]


def closest_point(cluster: FrontierCluster, target: ArrayLike) -> NDArray[np.float64]:
    """The point of ``cluster`` closest (Euclidean) to ``target``: the goal c of Algorithm 1."""
    t = np.asarray(target, dtype=float)
    i = int(np.argmin(np.sum((cluster.points - t) ** 2, axis=1)))
    return cluster.points[i].copy()


def closest_points(clusters: Sequence[FrontierCluster], target: ArrayLike) -> NDArray[np.float64]:
    """:func:`closest_point` of every cluster, ``(len(clusters), 2)``: the squared distances of
    all their points to ``target`` in one go, then each cluster's first least one."""
    if not clusters:
        return np.empty((0, 2))
    t = np.asarray(target, dtype=float)
    sizes = [len(c.points) for c in clusters]
    points = np.concatenate([c.points for c in clusters])
    d2 = np.sum((points - t) ** 2, axis=1)
    starts = np.cumsum([0, *sizes[:-1]])
    least = np.minimum.reduceat(d2, starts)
    if np.isnan(least).any():  # np.argmin takes the first NaN: cluster by cluster
        picks = [a + int(np.argmin(d2[a : a + k])) for a, k in zip(starts, sizes, strict=True)]
        closest: NDArray[np.float64] = points[picks]
        return closest
    # The first point of each cluster at its least d²: every cluster has one.
    at_least = np.flatnonzero(d2 == np.repeat(least, sizes))
    closest = points[at_least[np.searchsorted(at_least, starts)]]
    return closest


def utility(
    cluster: FrontierCluster,
    x: ArrayLike,
    l_star: ArrayLike | None,
    alpha: float,
    distance_from_robot: DistanceFn | None = None,
    distance_to_l_star: DistanceFn | None = None,
) -> float:
    """The utility of **Eq. 3**: U(c, x, l*) = α·N − (d(x, c) + d(c, l*)).

    ``c`` is the cluster's point closest to ``l_star`` (Algorithm 1; :func:`closest_point`),
    N = ``cluster.n_unknown``. ``distance_from_robot(points)`` is d(x, ·) and
    ``distance_to_l_star(points)`` is d(·, l*), vectorised over ``(k, 2)`` points (e.g. a
    :class:`pfctl.core.mapping.paths.DistanceField` from x and from l*); Euclidean when omitted.
    With ``l_star`` None there is no heading region: c is the point closest to x and the d(c, l*)
    term is dropped (pure exploration).
    """
    xa = np.asarray(x, dtype=float)
    d_cl: list[float] | None = None
    if l_star is None:
        c = closest_point(cluster, xa)
    else:
        la = np.asarray(l_star, dtype=float)
        c = closest_point(cluster, la)
        d_cl = [_eval(distance_to_l_star, c, la)]
    d_xc = [_eval(distance_from_robot, c, xa)]
    return float(cluster_utilities([cluster.n_unknown], d_xc, d_cl, alpha)[0])


def cluster_utilities(
    n_unknown: ArrayLike,
    from_robot: ArrayLike,
    to_l_star: ArrayLike | None,
    alpha: float,
) -> NDArray[np.float64]:
    """**Eq. 3** for several clusters at once: U = α·N − (d(x, c) + d(c, l*)).

    ``n_unknown`` is each cluster's N, ``from_robot`` d(x, c) and ``to_l_star`` d(c, l*) of its
    goal c (None: no heading region, the term is dropped). The one implementation of Eq. 3:
    Algorithm 1 (:func:`pfctl.core.mapping.regions.waypoint_search`) scores all clusters with it,
    :func:`utility` one cluster.
    """
    cost = np.asarray(from_robot, dtype=float)
    if to_l_star is not None:
        cost = cost + np.asarray(to_l_star, dtype=float)
    return alpha * np.asarray(n_unknown, dtype=float) - cost


def _eval(fn: DistanceFn | None, point: NDArray[np.float64], other: NDArray[np.float64]) -> float:
    if fn is None:
        return float(np.linalg.norm(point - other))
    value: Any = fn(point[None, :])
    return float(np.asarray(value, dtype=float).reshape(-1)[0])
