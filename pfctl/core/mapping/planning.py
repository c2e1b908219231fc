"""Grid path planning on a static map inflated by a robot's radius (the MOVE_BASE global planner).

:class:`GridPlanner` marks the occupied (and, optionally, unknown) cells of an
:class:`~pfctl.core.mapping.grid.OccupancyGrid` as obstacles, inflates them by the robot's radius
with a Euclidean distance transform, and runs Dijkstra (``scipy.sparse.csgraph``) on the 8-connected
graph of the remaining cells. Edges are the step length times a cost that grows near obstacles, so
paths keep to the middle of doors and corridors; the cell path is then shortcut by line of sight
(a segment is kept only where its clearance is no worse than the path it replaces, up to a
comfortable margin), giving a few straight way-points in metres.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import ndimage, sparse
from scipy.sparse import csgraph

from pfctl.core.mapping.grid import OCCUPIED, UNKNOWN, GridGeometry, OccupancyGrid

#: Extra clearance (m) beyond the radius that paths prefer; edges closer than this cost more.
COMFORT_MARGIN = 0.25

#: Edge cost multiplier right at the inflated boundary (falls linearly to 1 at the margin).
NEAR_COST = 4.0

#: How far (m) a start inside the inflated obstacles may be moved to the nearest free cell.
START_SNAP = 0.5

#: How far (m) a goal (a predicted place, a way-point, where the target was seen) may be moved
#: into free space for the robot (:meth:`GridPlanner.free_goal`).
GOAL_SNAP = 1.5


class NoPathError(ValueError):
    """No collision-free path: the goal is in (or too close to) an obstacle, or unreachable."""


@dataclass(frozen=True)
class _Graph:
    graph: sparse.csr_matrix
    free: NDArray[np.bool_]


class GridPlanner:
    """Shortest collision-free paths for a disc of ``robot_radius`` on ``static``.

    A cell is free when its centre is at least ``robot_radius`` from every obstacle cell centre
    (minus half a cell, so a door exactly ``2·radius`` wide stays open). ``unknown_is_obstacle``
    treats unknown cells (outside the house) as obstacles.
    """

    def __init__(
        self,
        static: OccupancyGrid,
        robot_radius: float,
        unknown_is_obstacle: bool = True,
        *,
        _extra: NDArray[np.bool_] | None = None,
    ) -> None:
        if robot_radius < 0:
            raise ValueError(f"robot_radius must be >= 0, got {robot_radius}")
        self.static = static
        self.robot_radius = float(robot_radius)
        self.unknown_is_obstacle = unknown_is_obstacle
        self.geometry: GridGeometry = static.geometry
        states = static.states()
        obstacle = states == OCCUPIED
        if unknown_is_obstacle:
            obstacle |= states == UNKNOWN
        if _extra is not None:
            obstacle |= _extra
        self.obstacle: NDArray[np.bool_] = obstacle
        res = self.geometry.resolution
        #: Distance (m) from each cell centre to the nearest obstacle cell centre.
        self.clearance: NDArray[np.float64] = (
            ndimage.distance_transform_edt(~obstacle) * res
            if obstacle.any()
            else np.full(obstacle.shape, np.inf)
        )
        self.free: NDArray[np.bool_] = self.clearance >= max(self.robot_radius - res / 2, res / 2)
        self._graph: _Graph | None = None

    # ----------------------------------------------------------------------------------------
    # queries

    def _cells(self, xy: ArrayLike) -> tuple[NDArray[np.intp], NDArray[np.intp], NDArray[np.bool_]]:
        rows, cols = self.geometry.world_to_cell(np.asarray(xy, dtype=float))
        inside = self.geometry.in_bounds(rows, cols)
        return np.where(inside, rows, 0), np.where(inside, cols, 0), inside

    def is_free(self, xy: ArrayLike) -> bool:
        """True when a disc of the robot's radius centred at ``xy`` touches no obstacle."""
        r, c, inside = self._cells(np.asarray(xy, dtype=float).reshape(2))
        return bool(inside and self.free[r, c])

    def free_mask(self, xy: ArrayLike) -> NDArray[np.bool_]:
        """:meth:`is_free` for many points ``(..., 2)``."""
        r, c, inside = self._cells(xy)
        return inside & self.free[r, c]

    def clearance_at(self, xy: ArrayLike) -> NDArray[np.float64]:
        """Distance (m) from points ``(..., 2)`` to the nearest obstacle (0 outside the grid)."""
        r, c, inside = self._cells(xy)
        return np.where(inside, self.clearance[r, c], 0.0)

    def nearest_free(self, xy: ArrayLike, max_distance: float = START_SNAP) -> np.ndarray | None:
        """The centre of the free cell nearest ``xy`` within ``max_distance`` m, or None."""
        p = np.asarray(xy, dtype=float).reshape(2)
        if self.is_free(p):
            return p
        res = self.geometry.resolution
        r0, c0 = (int(v) for v in self.geometry.world_to_cell(p))
        k = math.ceil(max_distance / res) + 1
        rs = slice(max(r0 - k, 0), max(min(r0 + k + 1, self.geometry.height), 0))
        cs = slice(max(c0 - k, 0), max(min(c0 + k + 1, self.geometry.width), 0))
        window = self.free[rs, cs]
        if not window.any():
            return None
        rr, cc = np.nonzero(window)
        centres = self.geometry.cell_to_world(rr + rs.start, cc + cs.start)
        d = np.linalg.norm(centres - p, axis=1)
        i = int(np.argmin(d))
        return centres[i] if d[i] <= max_distance else None

    def free_goal(self, xy: ArrayLike) -> tuple[float, float] | None:
        """``xy`` moved to the nearest cell free for the robot (within :data:`GOAL_SNAP`), or
        None: where the robot can go to look at a place."""
        p = self.nearest_free(np.asarray(xy, dtype=float), max_distance=GOAL_SNAP)
        return None if p is None else (float(p[0]), float(p[1]))

    def with_obstacles(self, points: ArrayLike, radius: float) -> GridPlanner:
        """A copy whose map also has discs of ``radius`` m around ``points`` (n, 2) as obstacles.

        The discs are obstacles like furniture: the robot's radius is added on top of them.
        """
        pts = np.asarray(points, dtype=float).reshape(-1, 2)
        extra = np.zeros(self.geometry.shape, dtype=bool)
        if len(pts):
            r, c, inside = self._cells(pts)
            seeds = np.zeros(self.geometry.shape, dtype=bool)
            seeds[r[inside], c[inside]] = True
            if seeds.any():
                d = ndimage.distance_transform_edt(~seeds) * self.geometry.resolution
                extra = d <= radius
        return GridPlanner(
            self.static, self.robot_radius, self.unknown_is_obstacle, _extra=self.obstacle | extra
        )

    def with_radius(self, radius: float) -> GridPlanner:
        """The same map planned for a disc of another radius (e.g. a person's)."""
        states = self.static.states()
        base = states == OCCUPIED
        if self.unknown_is_obstacle:
            base |= states == UNKNOWN
        return GridPlanner(
            self.static, radius, self.unknown_is_obstacle, _extra=self.obstacle & ~base
        )

    # ----------------------------------------------------------------------------------------
    # planning

    def _build_graph(self) -> _Graph:
        """The 8-connected graph of free cells; weights = step length × obstacle-proximity cost."""
        if self._graph is not None:
            return self._graph
        h, w = self.geometry.shape
        res = self.geometry.resolution
        free = self.free
        margin = max(COMFORT_MARGIN, 1e-9)
        excess = np.clip((self.clearance - self.robot_radius) / margin, 0.0, 1.0)
        cost = 1.0 + (NEAR_COST - 1.0) * (1.0 - excess)
        idx = np.arange(h * w).reshape(h, w)
        pf = np.pad(free, 1, constant_values=False)
        pc = np.pad(cost, 1, constant_values=np.inf)

        def shifted(arr: np.ndarray, dr: int, dc: int) -> np.ndarray:
            return arr[1 + dr : h + 1 + dr, 1 + dc : w + 1 + dc]

        rows_i, cols_i, weights = [], [], []
        for dr, dc in ((0, 1), (1, 0), (1, 1), (1, -1)):
            ok = free & shifted(pf, dr, dc)
            if dr and dc:  # no corner cutting: both orthogonal neighbours free
                ok &= shifted(pf, dr, 0) & shifted(pf, 0, dc)
            length = res * (math.sqrt(2.0) if dr and dc else 1.0)
            rows_i.append(idx[ok])
            cols_i.append(idx[ok] + dr * w + dc)
            weights.append(length * 0.5 * (cost[ok] + shifted(pc, dr, dc)[ok]))
        graph = sparse.csr_matrix(
            (np.concatenate(weights), (np.concatenate(rows_i), np.concatenate(cols_i))),
            shape=(h * w, h * w),
        )
        self._graph = _Graph(graph, free)
        return self._graph

    def plan(self, start_xy: ArrayLike, goal_xy: ArrayLike) -> np.ndarray:
        """Way-points ``(n, 2)`` in metres from ``start_xy`` to ``goal_xy``, both included.

        A start inside the inflated obstacles (a robot pushed against a wall) is first moved to
        the nearest free cell within :data:`START_SNAP`. Raises :class:`NoPathError` if the goal
        is not free or cannot be reached.
        """
        start = np.asarray(start_xy, dtype=float).reshape(2)
        goal = np.asarray(goal_xy, dtype=float).reshape(2)
        if not self.is_free(goal):
            raise NoPathError(
                f"goal ({goal[0]:.2f}, {goal[1]:.2f}) is inside an obstacle or off the map"
            )
        snapped = self.nearest_free(start)
        if snapped is None:
            raise NoPathError(f"start ({start[0]:.2f}, {start[1]:.2f}) is not near any free cell")
        g = self._build_graph()
        w = self.geometry.width
        (sr,), (sc,) = (np.atleast_1d(v) for v in self.geometry.world_to_cell(snapped))
        (gr,), (gc,) = (np.atleast_1d(v) for v in self.geometry.world_to_cell(goal))
        s, t = int(sr) * w + int(sc), int(gr) * w + int(gc)
        if s == t:
            cells = np.array([s])
        else:
            dist, pred = csgraph.dijkstra(
                g.graph, directed=False, indices=s, return_predecessors=True
            )
            if not np.isfinite(dist[t]):
                raise NoPathError(
                    f"goal ({goal[0]:.2f}, {goal[1]:.2f}) cannot be reached from "
                    f"({start[0]:.2f}, {start[1]:.2f})"
                )
            chain = [t]
            while chain[-1] != s:
                chain.append(int(pred[chain[-1]]))
            cells = np.array(chain[::-1])
        centres = self.geometry.cell_to_world(cells // w, cells % w)
        raw = np.vstack([start[None], snapped[None], centres[1:-1], goal[None]])
        keep = np.ones(len(raw), dtype=bool)
        keep[1:][np.all(np.abs(np.diff(raw, axis=0)) < 1e-12, axis=1)] = False
        return self._shortcut(raw[keep])

    def distances_from(self, start_xy: ArrayLike) -> NDArray[np.float64]:
        """The cost (m) of the planner's shortest path from ``start_xy`` to every cell (shape
        ``geometry.shape``; ``inf`` where no path reaches): the metres :meth:`plan`'s Dijkstra
        minimises, step lengths weighted near obstacles. A start inside the inflated obstacles
        is moved to the nearest free cell first (:data:`START_SNAP`); one with none near is
        :class:`NoPathError`."""
        snapped = self.nearest_free(np.asarray(start_xy, dtype=float).reshape(2))
        if snapped is None:
            raise NoPathError(f"start {tuple(np.round(start_xy, 2))} is not near any free cell")
        g = self._build_graph()
        r, c = (int(v) for v in self.geometry.world_to_cell(snapped))
        dist = csgraph.dijkstra(g.graph, directed=False, indices=r * self.geometry.width + c)
        out: NDArray[np.float64] = np.asarray(dist, dtype=float).reshape(self.geometry.shape)
        return out

    def _segment_clearance(self, a: np.ndarray, b: np.ndarray) -> float:
        """The smallest clearance along segment ``a → b`` (sampled every third of a cell)."""
        step = self.geometry.resolution / 3.0
        n = max(math.ceil(float(np.linalg.norm(b - a)) / step) + 1, 2)
        t = np.linspace(0.0, 1.0, n)[:, None]
        return float(self.clearance_at(a + (b - a) * t).min())

    def _shortcut(self, path: np.ndarray) -> np.ndarray:
        """Greedy line-of-sight shortcut: from each kept point, the farthest reachable point.

        A shortcut is accepted when its clearance is at least the smaller of the clearance of
        the cells it replaces and ``radius + COMFORT_MARGIN`` (so it never hugs a wall more
        than the Dijkstra path did), and never below the radius.
        """
        if len(path) <= 2:
            return path
        clear = self.clearance_at(path)
        want = self.robot_radius + COMFORT_MARGIN
        out = [path[0]]
        i = 0
        floor = max(self.robot_radius - self.geometry.resolution / 2, 0.0)
        while i < len(path) - 1:
            j = i + 1
            lo = min(float(clear[i + 1 : j + 1].min()), want)
            while j + 1 < len(path):
                need = max(min(lo, float(clear[j + 1]), want), floor)
                if self._segment_clearance(path[i], path[j + 1]) + 1e-9 < need:
                    break
                j += 1
                lo = min(lo, float(clear[j]))
            out.append(path[j])
            i = j
        return np.array(out)


def path_length(path: ArrayLike) -> float:
    """Length (m) of a polyline ``(n, 2)``."""
    p = np.asarray(path, dtype=float).reshape(-1, 2)
    return float(np.linalg.norm(np.diff(p, axis=0), axis=1).sum())


__all__ = ["COMFORT_MARGIN", "GOAL_SNAP", "GridPlanner", "NoPathError", "path_length"]
