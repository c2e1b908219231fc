"""The region map (§II-B) and Algorithm 1, *way-point search* (§II-B/C/D).

The house is a set of named polygons (rooms, hall) joined by doors. :class:`RegionMap` answers
"which region is this point in", "which regions are next to it" and "which regions lie between
two regions" (a networkx graph: nodes are regions, edges are doors).

**Algorithm 1** (way-point search), used when the target is lost and its predicted position has
been searched in vain:

1. *Heading region* (:func:`heading_region`). Over the last T seconds of the target's pose
   history, for each neighbour n of the region the target is in now, take the mean change of the
   distance to n between consecutive samples; the heading region l* is the neighbour with the most
   negative mean — the one being approached. None when no neighbour is being approached.
2. *Frontier search* (:func:`waypoint_search`). Extract the frontier clusters of the occupancy
   grid (Eq. 2, :mod:`pfctl.core.mapping.frontiers`); for each cluster take its point closest to l*;
   score it with the utility of Eq. 3, ``α·N − (d(x, c) + d(c, l*))`` with grid path lengths
   (:mod:`pfctl.core.mapping.paths`); the way-point is the best cluster point. With no frontier, the
   way-point is l* itself.

``choice="nearest"`` replaces step 2's utility by the nearest reachable frontier (the classic
nearest-frontier exploration of Yamauchi, 1997): a baseline that shows what Eq. 3 and l* add.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Literal

import networkx as nx
import numpy as np
import shapely
from numpy.typing import ArrayLike, NDArray
from shapely.geometry import Point as ShapelyPoint
from shapely.geometry import Polygon

from pfctl.core.mapping.frontiers import (
    FrontierCluster,
    closest_points,
    cluster_utilities,
    frontiers_from_states,
)
from pfctl.core.mapping.grid import FREE_THRESH, OCCUPIED, OCCUPIED_THRESH, UNKNOWN, GridGeometry
from pfctl.core.mapping.house import Door, HouseLayout
from pfctl.core.mapping.paths import distance_fields, traversability
from pfctl.core.mapping.walls import wall_mask
from pfctl.core.params import param

if TYPE_CHECKING:
    from pfctl.core.mapping.grid import OccupancyGrid


__all__ = [
    "SEARCH_STRATEGIES",
    "WAYPOINT_CHOICES",
    "RegionMap",
    "SearchParams",
    "SearchStrategy",
    "WaypointChoice",
    "WaypointDecision",
    "heading_region",
    "heading_scores",
    "waypoint_search",
]

XY = tuple[float, float]


class RegionMap:
    """The polygon region map of §II-B and its connectivity graph.

    ``graph`` is a ``networkx.Graph``: one node per region (attributes ``polygon``, ``centroid``),
    one edge per pair of regions joined by at least one door. Edge attributes: ``segment`` and
    ``midpoint`` of the door (the one giving the shortest way when several join the same pair),
    ``doors`` (all of them), and ``weight`` = ‖centroid_a − midpoint‖ + ‖midpoint − centroid_b‖,
    the length of the way between the region centroids through the door.

    Raises ValueError when a door names a region the layout does not have.
    """

    def __init__(self, layout: HouseLayout) -> None:
        self.layout = layout
        self._order = [r.name for r in layout.regions]
        if len(set(self._order)) != len(self._order):
            raise ValueError(f"region names are not unique: {self._order}")
        self._polygons: dict[str, Polygon] = {}
        self._points: dict[str, XY] = {}
        graph = nx.Graph()
        for region in layout.regions:
            poly = Polygon(region.polygon)
            if not poly.is_valid or poly.area <= 0:
                raise ValueError(f"region {region.name!r} has an invalid polygon")
            shapely.prepare(poly)
            self._polygons[region.name] = poly
            graph.add_node(region.name, polygon=poly, centroid=self.region_point(region.name))
        for door in layout.doors:
            a, b = door.between
            for name in (a, b):
                if name not in self._polygons:
                    raise ValueError(f"door {door.between} names unknown region {name!r}")
            mid = _midpoint(door)
            weight = float(
                np.hypot(*np.subtract(graph.nodes[a]["centroid"], mid))
                + np.hypot(*np.subtract(mid, graph.nodes[b]["centroid"]))
            )
            if graph.has_edge(a, b):
                data = graph.edges[a, b]
                data["doors"] = (*data["doors"], door)
                if weight >= data["weight"]:
                    continue
            else:
                graph.add_edge(a, b, doors=(door,))
            graph.edges[a, b].update(segment=door.segment, midpoint=mid, weight=weight)
        self.graph = graph
        self._blocked_masks: dict[GridGeometry, NDArray[np.bool_]] = {}

    @property
    def names(self) -> list[str]:
        """Region names in layout order."""
        return list(self._order)

    def polygon(self, name: str) -> Polygon:
        """The shapely polygon of region ``name`` (KeyError if unknown)."""
        return self._polygons[name]

    def locate(self, point: ArrayLike) -> str | None:
        """The region containing ``point``; None outside every region.

        Points on the boundary count as inside (``covers``); a point on an edge shared by several
        regions belongs to the first of them in layout order.
        """
        x, y = (float(v) for v in np.asarray(point, dtype=float)[:2])
        for name in self._order:
            if shapely.intersects_xy(self._polygons[name], x, y):
                return name
        return None

    def locate_all(self, points: ArrayLike) -> NDArray[np.intp]:
        """:meth:`locate` of each of ``points`` (``(n, 2)``) at once, as the index of the region
        in :attr:`names` (−1 outside every region): one vectorised shapely test per region,
        same rule (``intersects``, the first region in layout order)."""
        pts = np.asarray(points, dtype=float).reshape(-1, 2)
        x, y = pts[:, 0], pts[:, 1]
        hits = np.array([shapely.intersects_xy(self._polygons[r], x, y) for r in self._order])
        if not len(hits):
            return np.full(len(pts), -1, dtype=np.intp)
        found: NDArray[np.intp] = np.where(hits.any(axis=0), hits.argmax(axis=0), -1)
        return found

    def neighbours(self, name: str) -> list[str]:
        """Regions joined to ``name`` by a door, in layout order (KeyError if unknown)."""
        if name not in self._polygons:
            raise KeyError(name)
        adjacent = set(self.graph.neighbors(name))
        return [n for n in self._order if n in adjacent]

    def region_path(self, a: str, b: str) -> list[str]:
        """The regions on the shortest way from ``a`` to ``b`` (by edge ``weight``), both included.

        KeyError for an unknown region, ``networkx.NetworkXNoPath`` if no doors join them.
        """
        for name in (a, b):
            if name not in self._polygons:
                raise KeyError(name)
        return list(nx.shortest_path(self.graph, a, b, weight="weight"))

    def distance_to_region(self, point: ArrayLike, name: str) -> float:
        """Euclidean distance from ``point`` to the polygon of region ``name``; 0 inside."""
        x, y = (float(v) for v in np.asarray(point, dtype=float)[:2])
        return float(self._polygons[name].distance(ShapelyPoint(x, y)))

    def doors_between(self, a: str, b: str) -> tuple[Door, ...]:
        """The doors joining regions ``a`` and ``b`` (empty if they are not neighbours)."""
        if not self.graph.has_edge(a, b):
            return ()
        return tuple(self.graph.edges[a, b]["doors"])

    def door_midpoints(self, name: str) -> list[XY]:
        """The midpoint of every door of region ``name``, in the order of :meth:`neighbours`
        (KeyError if unknown)."""
        return [_midpoint(d) for n in self.neighbours(name) for d in self.doors_between(name, n)]

    def blocked_mask(self, geometry: GridGeometry) -> NDArray[np.bool_]:
        """Cells of a grid with ``geometry`` that the region map alone says nobody can be in or
        pass through: outside every region (more than a cell away), or on a region boundary that
        is not a door — a wall (:func:`pfctl.core.mapping.walls.wall_mask`, two cells thick, one on
        each side of the boundary line): regions are joined only by their doors (§II-B). Computed
        once per geometry and cached; read-only.
        """
        mask = self._blocked_masks.get(geometry)
        if mask is None:
            house = shapely.unary_union(list(self._polygons.values())).buffer(geometry.resolution)
            shapely.prepare(house)
            centres = geometry.cell_to_world(*np.indices(geometry.shape))
            inside = shapely.contains_xy(house, centres[..., 0], centres[..., 1])
            mask = ~inside | wall_mask(self.layout, geometry, 2.0 * geometry.resolution)
            mask.flags.writeable = False
            self._blocked_masks[geometry] = mask
        return mask

    def region_point(self, name: str) -> XY:
        """The point that stands for region ``name``: its centroid, or a point surely inside
        (shapely's ``representative_point``) when the centroid of a concave region falls outside.
        """
        point = self._points.get(name)
        if point is None:  # once per region: the map is static
            poly = self._polygons[name]
            c = poly.centroid
            if not poly.covers(c):
                c = poly.representative_point()
            point = self._points[name] = (float(c.x), float(c.y))
        return point


def _midpoint(door: Door) -> XY:
    (x0, y0), (x1, y1) = door.segment
    return ((x0 + x1) / 2.0, (y0 + y1) / 2.0)


def _window(history: ArrayLike, window_s: float) -> NDArray[np.float64]:
    h = np.asarray(history, dtype=float)
    if h.ndim != 2 or h.shape[1] < 3:
        raise ValueError("history must be a sequence of (t, x, y)")
    if len(h) == 0:
        return h[:, :3]
    h = h[np.argsort(h[:, 0], kind="stable"), :3]
    return h[h[:, 0] >= h[-1, 0] - window_s]


def heading_scores(
    history: ArrayLike, region_map: RegionMap, window_s: float
) -> tuple[str | None, dict[str, float]]:
    """The first half of Algorithm 1, with its numbers: (current region, {neighbour: mean change}).

    ``history`` is a sequence of ``(t, x, y)`` (sorted by t here); the window is the samples with
    ``t ≥ t_last − window_s``. The current region is ``locate`` of the last sample. For each
    neighbour n of it, the distance of each sample to n is the distance to the midpoint of the
    door between the current region and n (the nearest one if several) — a point inside a
    corridor comes closer to the office door as it walks toward it, while its distance to the
    office polygon (the whole north wall of the hall) would not change. The score is the mean over
    the window of the change of that distance between consecutive samples, which telescopes to
    ``(d_last − d_first) / (k − 1)`` for k samples (metres per sample; negative = approaching).
    No scores (empty dict) when the last sample is outside every region or the window holds fewer
    than two samples.
    """
    w = _window(history, window_s)
    if len(w) == 0:
        return None, {}
    current = region_map.locate(w[-1, 1:3])
    if current is None or len(w) < 2:
        return current, {}
    scores: dict[str, float] = {}
    for n in region_map.neighbours(current):
        mids = np.array([_midpoint(d) for d in region_map.doors_between(current, n)])
        dists = np.linalg.norm(w[:, None, 1:3] - mids[None, :, :], axis=-1).min(axis=1)
        scores[n] = float(np.mean(np.diff(dists)))
    return current, scores


def heading_region(
    history: ArrayLike,
    region_map: RegionMap,
    window_s: float,
    min_speed: float = 0.0,
) -> str | None:
    """Algorithm 1, first half: the heading region l* of a pose history (§II-B).

    l* is the neighbour of the current region whose door the last ``window_s`` seconds of
    ``history`` approached fastest: the most negative mean change of distance (see
    :func:`heading_scores` for the exact definition). None when no neighbour is being approached
    — every mean ≥ 0, or the approach slower than ``min_speed`` (m/s, measured as the distance
    gained over the window's duration; 0 keeps the paper's "most negative" rule) — or when the
    current region is unknown; the caller then falls back (:func:`waypoint_search` uses the
    current region itself). Ties are broken by region name.
    """
    _, scores = heading_scores(history, region_map, window_s)
    best = _approached(scores)
    if best is None:
        return None
    if min_speed > 0.0:
        w = _window(history, window_s)
        duration = w[-1, 0] - w[0, 0]
        gained = -scores[best] * (len(w) - 1)
        if duration <= 0 or gained / duration <= min_speed:
            return None
    return best


def _approached(scores: dict[str, float]) -> str | None:
    """The neighbour of :func:`heading_scores` approached fastest (the most negative mean, ties
    by name); None when there is none or it is not approached (mean ≥ 0)."""
    if not scores:
        return None
    best = min(sorted(scores), key=lambda n: scores[n])
    return None if scores[best] >= 0.0 else best


WaypointChoice = Literal["utility", "nearest"]
"""How Algorithm 1 picks among the frontier clusters (:func:`waypoint_search`)."""
WAYPOINT_CHOICES: tuple[WaypointChoice, ...] = ("utility", "nearest")

SearchStrategy = Literal["belief", "paper"]
"""How the lost target is looked for (:class:`SearchParams.strategy`)."""
SEARCH_STRATEGIES: tuple[SearchStrategy, ...] = ("belief", "paper")

PredictionGoal = Literal["path", "room"]
"""Where go_to_prediction drives (:class:`SearchParams.prediction_goal`)."""

SearchGaze = Literal["unseen", "goal"]
"""Where the head looks in a search when the gaze rule has nothing (:class:`SearchParams.gaze`)."""


@dataclass(frozen=True)
class SearchParams:
    """Eq. 2, Eq. 3 and Algorithm 1 settings (the mission's ``search`` section)."""

    alpha: float = param(0.05, "Utility per unknown cell a frontier borders (Eq. 3).", ge=0)
    beta: float = param(1.0, "Weight of obstacle boundaries in the frontier map (Eq. 2).", ge=0)
    frontier_threshold: float = param(0.1, "F above which a cell is a frontier cell.", gt=0)
    min_frontier_cells: int = param(5, "Smaller frontier clusters are dropped.", ge=1)
    heading_window_s: float = param(
        3.0, "T: the pose history Algorithm 1 looks back over.", unit="s", gt=0
    )
    waypoint_choice: WaypointChoice = param(
        "utility",
        "How Algorithm 1 picks the frontier to search: ``utility`` (Eq. 3, the paper) or"
        " ``nearest`` (the reachable frontier nearest the robot by path length, whatever its size"
        " or l*: the nearest-frontier baseline, ``missions/baselines/``).",
    )
    strategy: SearchStrategy = param(
        "paper",
        "How way-point search looks for the lost target: ``paper`` (the paper literally:"
        " Algorithm 1's way-points) or ``belief`` (where she can be, spread along the"
        " doors since she was last seen and emptied where the camera looked; the next place is"
        " the most probable room over the time to get there and look, from its doorway first;"
        " ``missions/house_belief_search.yaml``).",
    )
    never_seen_strategy: SearchStrategy = param(
        "paper",
        "How way-point search looks for a target not seen yet in the run (``pfctl search``):"
        " ``paper`` (Algorithm 1's frontiers, with no heading region) or ``belief`` (every room"
        " she can be in alike, emptied where the camera looked; the next place is the most"
        " probable room over the time to get there and look, from its doorway first).",
    )
    prediction_goal: PredictionGoal = param(
        "path",
        "Where go_to_prediction drives after a loss: ``path`` (§II-E, the paper: the end of"
        " her predicted path, clipped to the map) or ``room`` (the doorway of the room the"
        " belief over where she can be ranks first a few seconds on).",
    )
    gaze: SearchGaze = param(
        "unseen",
        "Where the head looks while she is lost (or not seen yet) and no target, belief peak or"
        " leg candidate draws it: ``unseen`` (the most probable place not seen since the loss"
        " that is in sight, e.g. into each room the robot drives past;"
        " :mod:`pfctl.core.search.gaze`) or ``goal`` (where the base is going).",
    )
    look_s: float = param(
        6.0,
        "How long the head sweeps a room from a place to look (strategy belief).",
        unit="s",
        gt=0,
    )


@dataclass(frozen=True, eq=False)
class WaypointDecision:
    """What Algorithm 1 decided, and why (for the behaviour tree, the log and the plots).

    ``waypoint``: where to go. ``heading_region``: l* of the first half (None when no neighbour
    was approached). ``target_region``/``target_point``: the l* actually used and its point,
    after the fallback (the current region of the history, then the robot's region; None when
    even that fails). ``reason``: ``"frontier"`` (best frontier cluster point),
    ``"no_frontier_fallback"`` (no frontier cluster: go to l*'s point),
    ``"unreachable_frontier_fallback"`` (clusters, none reachable: go to l*'s point) or
    ``"no_target"`` (nothing at all: stay at the robot's position). ``clusters``, ``goals`` (the
    cluster point closest to l*), ``utilities`` (Eq. 3) line up; ``best`` indexes them. With
    ``choice`` ``"nearest"`` the goals are the cluster points closest to the robot and the
    utilities are −d(x, c), so the best is the nearest.
    """

    waypoint: XY
    heading_region: str | None
    target_region: str | None
    target_point: XY | None
    reason: str
    clusters: tuple[FrontierCluster, ...] = field(default=(), repr=False)
    goals: tuple[XY, ...] = field(default=(), repr=False)
    utilities: tuple[float, ...] = ()
    best: int | None = None
    choice: WaypointChoice = "utility"


def waypoint_search(
    grid: OccupancyGrid,
    region_map: RegionMap,
    history: Sequence[tuple[float, float, float]] | ArrayLike,
    robot_xy: ArrayLike,
    alpha: float,
    beta: float,
    frontier_threshold: float,
    min_frontier_cells: int,
    window_s: float,
    *,
    downsample: int | None = None,
    free_thresh: float = FREE_THRESH,
    occupied_thresh: float = OCCUPIED_THRESH,
    confine_to_regions: bool = True,
    robot_region_fallback: bool = True,
    choice: WaypointChoice = "utility",
) -> WaypointDecision:
    """**Algorithm 1**, way-point search, end to end (§II-B/C/D).

    1. l* = :func:`heading_region` of ``history`` over ``window_s``; if None, the region the
       history ends in; if that is None too, the robot's region. Its point is
       :meth:`RegionMap.region_point` (the centroid): frontiers *inside* l* score better than
       frontiers at its door.
    2. Frontier clusters of ``grid`` (Eq. 2, :func:`pfctl.core.mapping.frontiers.find_frontiers`
    with
       ``beta``, ``frontier_threshold``, ``min_frontier_cells``).
    3. For each cluster its point c closest to l*'s point, and U = α·N − (d(x, c) + d(c, l*))
       (Eq. 3) with d the grid path lengths of :mod:`pfctl.core.mapping.paths` (non-occupied cells
       traversable, ``downsample`` coarsening, None: ~0.2 m cells; one Dijkstra from the robot,
       one from l*, confined to the known map and the two start points grown by
       ``paths.SEARCH_MARGIN`` = 2 m). With
       no l* at all the d(c, l*) term is dropped and c is the point closest to the robot.
    ``robot_region_fallback`` False drops the last fallback (with no history at all — a target
    never seen — l* stays None: anchoring the search to the room the robot happens to be in
    would keep it there).
    With ``confine_to_regions`` (the default), the cells of :meth:`RegionMap.blocked_mask` count
    as obstacles — outside every region, and the walls between regions: the person is somewhere
    in the house, so frontiers outside it are not worth a look; a wall the robot has not seen yet
    is still a wall, so the free cells along it are no frontier; and a path must not cut through
    unexplored space beyond or across the walls (it would underestimate d).

    4. The way-point is the c of the best utility (first cluster on ties; clusters come largest
       first). Without any reachable cluster: l*'s point — moved to the nearest non-occupied
       cell of the region if the grid has it occupied — or, lacking l*, the robot's position.

    ``choice="nearest"`` is the nearest-frontier baseline instead of Eq. 3 in steps 3-4: c is
    each cluster's point closest to the robot, its score −d(x, c) (the same grid path length),
    and the way-point the nearest reachable c; N and l* play no part in the choice (l* still
    gives the way-point when no frontier is reachable).
    """
    if choice not in WAYPOINT_CHOICES:
        raise ValueError(
            f"unknown choice {choice!r}; expected one of {', '.join(WAYPOINT_CHOICES)}"
        )
    nearest = choice == "nearest"
    robot = np.asarray(robot_xy, dtype=float)[:2]
    # heading_region, keeping the region the history ends in for the fallback
    current, scores = heading_scores(history, region_map, window_s)
    heading = _approached(scores)
    target = heading if heading is not None else current
    if target is None and robot_region_fallback:
        target = region_map.locate(robot)
    target_point = region_map.region_point(target) if target is not None else None

    geometry = grid.geometry
    states = grid.states(free_thresh, occupied_thresh)
    if confine_to_regions:  # (states is a new array)
        np.copyto(states, np.int8(OCCUPIED), where=region_map.blocked_mask(geometry))
    clusters = frontiers_from_states(states, geometry, beta, frontier_threshold, min_frontier_cells)
    goals: list[XY] = []
    utilities: list[float] = []
    best: int | None = None
    if clusters:
        tr = traversability(
            states != OCCUPIED,
            geometry=geometry,
            downsample=downsample,
            known=states != UNKNOWN,
        )
        anchor = robot if target_point is None or nearest else np.asarray(target_point)
        starts = [robot] if target_point is None or nearest else [robot, anchor]
        fields = distance_fields(tr, np.array(starts))
        # Eq. 3 for all clusters at once, one vectorised field lookup per term.
        goal_array = closest_points(clusters, anchor)
        from_robot = fields[0](goal_array)
        if nearest:
            u = -from_robot
        else:
            to_l_star = fields[1](goal_array) if len(starts) == 2 else None
            u = cluster_utilities([c.n_unknown for c in clusters], from_robot, to_l_star, alpha)
        goals = [(gx, gy) for gx, gy in goal_array.tolist()]
        utilities = u.tolist()
        if np.isfinite(u).any():
            best = int(np.argmax(np.where(np.isfinite(u), u, -np.inf)))
    common = dict(
        heading_region=heading,
        target_region=target,
        target_point=target_point,
        clusters=tuple(clusters),
        goals=tuple(goals),
        utilities=tuple(utilities),
        choice=choice,
    )
    if best is not None:
        return WaypointDecision(waypoint=goals[best], reason="frontier", best=best, **common)
    if target is not None and target_point is not None:
        reason = "unreachable_frontier_fallback" if clusters else "no_frontier_fallback"
        point = _free_point_in_region(states, geometry, region_map.polygon(target), target_point)
        return WaypointDecision(waypoint=point, reason=reason, **common)
    return WaypointDecision(
        waypoint=(float(robot[0]), float(robot[1])), reason="no_target", **common
    )


def _free_point_in_region(
    states: NDArray[np.int8], geometry: GridGeometry, polygon: Polygon, point: XY
) -> XY:
    """``point`` if its cell is not occupied, else the nearest non-occupied cell centre inside
    ``polygon`` (``point`` itself if there is none or it is off the grid)."""
    r, c = geometry.world_to_cell(np.asarray(point))
    if not geometry.in_bounds(r, c) or states[r, c] != OCCUPIED:
        return point
    xmin, ymin, xmax, ymax = polygon.bounds
    r0, c0 = geometry.world_to_cell(np.array([xmin, ymin]))
    r1, c1 = geometry.world_to_cell(np.array([xmax, ymax]))
    r0, c0 = max(int(r0), 0), max(int(c0), 0)
    r1, c1 = min(int(r1), geometry.height - 1), min(int(c1), geometry.width - 1)
    rr, cc = np.mgrid[r0 : r1 + 1, c0 : c1 + 1]
    ok = states[rr, cc] != OCCUPIED
    centres = geometry.cell_to_world(rr[ok], cc[ok])
    inside = shapely.contains_xy(polygon, centres[:, 0], centres[:, 1])
    centres = centres[inside]
    if len(centres) == 0:
        return point
    i = int(np.argmin(np.sum((centres - np.asarray(point)) ** 2, axis=1)))
    return (float(centres[i, 0]), float(centres[i, 1]))
