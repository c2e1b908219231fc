"""Algorithm 1's fast code gives exactly what the plain definitions give (issue 24).

One call of Algorithm 1 (:meth:`pfctl.core.behavior.world.WorldModel.next_waypoint`) was made
cheaper by vectorising and caching; these tests hold each fast part to a straightforward
reference written here — point-by-point region lookup, Eq. 2 over the whole map, line of sight by
sampling with a bounds test, the path graph built edge by edge — on grids explored the way the
follower explores them: the shipped house's walls and furniture (plus a few people) seen by
simulated laser scans from seeded random poses, fused with Eq. 1. Equality is exact: same cells,
same floats, same order.
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from scipy import ndimage
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import dijkstra

from pfctl.core.behavior.world import WorldModel, since_region_entered
from pfctl.core.mapping.frontiers import (
    FrontierCluster,
    closest_point,
    closest_points,
    frontier_map,
    frontiers_from_states,
    trinary_map,
)
from pfctl.core.mapping.grid import FREE, OCCUPIED, UNKNOWN, GridGeometry, OccupancyGrid
from pfctl.core.mapping.house import HouseLayout
from pfctl.core.mapping.paths import (
    DistanceField,
    Traversability,
    distance_fields,
    line_of_sight,
    traversability,
)
from pfctl.core.mapping.regions import RegionMap, SearchParams
from pfctl.core.mapping.walls import rasterize_house

RES = 0.05
BEAMS = 361  # a 270° scan every 0.75°
RANGE = 8.0


def _scan(truth: np.ndarray, geometry: GridGeometry, pose: tuple[float, float, float]):
    """Ranges of a 270° scan from ``pose`` over the boolean ``truth`` (ray marching)."""
    x, y, theta = pose
    angles = theta - 0.75 * np.pi + np.arange(BEAMS) * (1.5 * np.pi / (BEAMS - 1))
    steps = np.arange(1, int(RANGE / (RES / 3)) + 1) * (RES / 3)
    px = x + np.cos(angles)[:, None] * steps
    py = y + np.sin(angles)[:, None] * steps
    rows, cols = geometry.world_to_cell(np.stack([px, py], axis=-1))
    inside = geometry.in_bounds(rows, cols)
    hit = np.ones(rows.shape, dtype=bool)
    hit[inside] = truth[rows[inside], cols[inside]]
    first = np.where(hit.any(axis=1), hit.argmax(axis=1), -1)
    return np.where(first >= 0, steps[first], np.inf), -0.75 * np.pi, 1.5 * np.pi / (BEAMS - 1)


@pytest.fixture(scope="module")
def rmap(layout: HouseLayout) -> RegionMap:
    return RegionMap(layout)


@pytest.fixture(scope="module")
def explored(
    layout: HouseLayout, rmap: RegionMap
) -> list[tuple[OccupancyGrid, tuple[float, float]]]:
    """Grids of the shipped house seen from 1, 2, 4 and 7 seeded random poses (five scans at
    each; three people standing about), each with the robot at its last pose."""
    rng = np.random.default_rng(24)
    static = rasterize_house(layout, RES)
    geometry = static.geometry
    truth = static.states() == OCCUPIED
    centres = geometry.cell_to_world(*np.indices(geometry.shape))
    free_cells = np.argwhere(static.states() == FREE)
    for _ in range(3):  # people: discs of 0.2 m
        r, c = free_cells[rng.integers(len(free_cells))]
        truth |= np.hypot(*(centres - centres[r, c]).transpose(2, 0, 1)) < 0.2
    ok = np.argwhere(~ndimage.binary_dilation(truth, iterations=6) & (static.states() == FREE))
    grid = OccupancyGrid(geometry)
    states = []
    for k in range(1, 8):
        r, c = ok[rng.integers(len(ok))]
        x, y = (float(v) for v in centres[r, c])
        pose = (x, y, float(rng.uniform(-np.pi, np.pi)))
        ranges, a0, da = _scan(truth, geometry, pose)
        for _ in range(5):  # half a second standing there
            grid.update_scan(pose, ranges, a0, da, RANGE)
        if k in (1, 2, 4, 7):
            states.append((grid.copy(), (x, y)))
    return states


def _history(rng: np.random.Generator, rmap: RegionMap) -> np.ndarray:
    """A (t, x, y) walk at 10 Hz between two random regions' points, through the doors."""
    names = rmap.names
    a, b = rng.choice(len(names), size=2, replace=False)
    way = [rmap.region_point(n) for n in rmap.region_path(names[a], names[b])]
    xy = np.concatenate([np.linspace(p, q, 15, endpoint=False) for p, q in itertools.pairwise(way)])
    xy = np.vstack([xy, way[-1]]) + rng.normal(0.0, 0.03, (len(xy) + 1, 2))
    return np.column_stack([np.arange(len(xy)) / 10.0, xy])


# -------------------------------------------------------------------------- plain references


def _plain_line_of_sight(blocked, geometry, a, b, step=None) -> np.ndarray:
    """Sample every segment at the same n points, look each sample's cell up (off-map: blocked)."""
    a, b = np.broadcast_arrays(np.asarray(a, dtype=float), np.asarray(b, dtype=float))
    step = geometry.resolution / 3.0 if step is None else step
    n = int(np.ceil(np.linalg.norm(b - a, axis=-1).max(initial=0.0) / step)) + 1
    t = np.linspace(0.0, 1.0, max(n, 2))
    rows, cols = geometry.world_to_cell(a[..., None, :] + (b - a)[..., None, :] * t[:, None])
    inside = geometry.in_bounds(rows, cols)
    hit = np.ones(rows.shape, dtype=bool)
    hit[inside] = blocked[rows[inside], cols[inside]]
    return ~hit.any(axis=-1)


def _plain_frontiers(states, geometry, beta, threshold, min_cells) -> list[tuple]:
    """Eq. 2 over the whole map and the rule of the frontiers module, cluster by cluster:
    (cells, points, centroid, N) largest first, ties by first cell."""
    h, w = states.shape
    F = frontier_map(trinary_map(states), states == OCCUPIED, beta)
    unknown = np.pad(states == UNKNOWN, 1)
    occupied = np.pad(states == OCCUPIED, 1)
    around = [(dr, dc) for dr in (-1, 0, 1) for dc in (-1, 0, 1) if dr or dc]

    def near(mask: np.ndarray) -> np.ndarray:
        return np.any([mask[1 + dr : 1 + dr + h, 1 + dc : 1 + dc + w] for dr, dc in around], 0)

    frontier = (threshold < F) & (states == FREE) & near(unknown) & ~near(occupied)
    labels, n = ndimage.label(frontier, structure=np.ones((3, 3), dtype=bool))
    out = []
    for i in range(1, n + 1):
        cells = np.argwhere(labels == i)  # row-major
        if len(cells) < min_cells:
            continue
        points = geometry.cell_to_world(cells[:, 0], cells[:, 1])
        seen = {
            (r + dr, c + dc)
            for r, c in cells.tolist()
            for dr, dc in around
            if unknown[r + dr + 1, c + dc + 1]
        }
        centroid = points.mean(axis=0)
        out.append((cells.tolist(), points.tolist(), (centroid[0], centroid[1]), len(seen)))
    out.sort(key=lambda x: (-len(x[0]), x[0][0]))
    return out


def _as_tuples(clusters: list[FrontierCluster]) -> list[tuple]:
    return [(c.cells.tolist(), c.points.tolist(), c.centroid, c.n_unknown) for c in clusters]


def _plain_since_region_entered(history: np.ndarray, rmap: RegionMap) -> np.ndarray:
    if len(history) == 0:
        return history
    last = rmap.locate(history[-1, 1:3])
    start = len(history)
    while start > 0 and rmap.locate(history[start - 1, 1:3]) == last:
        start -= 1
    return history[start:]


def _plain_distances(tr: Traversability, starts: np.ndarray) -> np.ndarray:
    """The coarse path lengths from each start: the 8-connected graph of the search window
    built edge by edge, each start joined to the 3 × 3 coarse cells around it in sight."""
    cg = tr.coarse_geometry
    H, W = cg.height, cg.width
    rows, cols = cg.world_to_cell(starts)
    m = tr.margin_cells
    r0, r1 = int(rows.min()) - m, int(rows.max()) + m + 1
    c0, c1 = int(cols.min()) - m, int(cols.max()) + m + 1
    if tr.search_box is None:
        r0, r1, c0, c1 = 0, H, 0, W
    else:
        br0, br1, bc0, bc1 = tr.search_box
        r0, r1, c0, c1 = min(r0, br0), max(r1, br1), min(c0, bc0), max(c1, bc1)
    r0, r1, c0, c1 = max(r0, 0), min(r1, H), max(c0, 0), min(c1, W)
    h, w = r1 - r0, c1 - c0
    free = np.zeros((h + 2, w + 2), dtype=bool)
    free[1:-1, 1:-1] = tr.coarse_free[r0:r1, c0:c1]
    k = len(starts)
    rows_of, cols_of, lengths = [], [], []
    for r in range(h + 2):
        for c in range(w + 2):
            if not free[r, c]:
                continue
            for dr in (-1, 0, 1):
                for dc in (-1, 0, 1):
                    if (dr or dc) and free[r + dr, c + dc]:
                        if dr and dc and not (free[r + dr, c] and free[r, c + dc]):
                            continue
                        rows_of.append(r * (w + 2) + c)
                        cols_of.append((r + dr) * (w + 2) + c + dc)
                        lengths.append(np.sqrt(2.0) if dr and dc else 1.0)
    n = free.size
    for i, start in enumerate(starts):
        for dr in (-1, 0, 1):
            for dc in (-1, 0, 1):
                r, c = rows[i] + dr, cols[i] + dc
                if not (r0 <= r < r1 and c0 <= c < c1 and tr.coarse_free[r, c]):
                    continue
                centre = cg.cell_to_world(r, c)
                if _plain_line_of_sight(tr.blocked, tr.geometry, start, centre):
                    rows_of.append(n + i)
                    cols_of.append((r - r0 + 1) * (w + 2) + c - c0 + 1)
                    lengths.append(float(np.linalg.norm(centre - start)) / cg.resolution)
    graph = csr_matrix((lengths, (rows_of, cols_of)), shape=(n + k, n + k))
    dist = dijkstra(graph, directed=True, indices=np.arange(n, n + k))
    full = np.full((k, H, W), np.inf)
    full[:, r0:r1, c0:c1] = dist[:, :n].reshape(k, h + 2, w + 2)[:, 1:-1, 1:-1] * cg.resolution
    return full


def _plain_field(field: DistanceField, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(field(points), field.at(points)) by the definitions, with the plain line of sight."""
    tr = field.traversability
    cg = tr.coarse_geometry
    rows, cols = cg.world_to_cell(points)
    out = []
    for p, r, c in zip(points, rows, cols, strict=True):
        cells = [(r + dr, c + dc) for dr in (-1, 0, 1) for dc in (-1, 0, 1)]
        reach = [
            (field.distances[rr, cc], cg.cell_to_world(rr, cc))
            for rr, cc in (np.clip(rc, 0, [cg.height - 1, cg.width - 1]) for rc in cells)
        ]
        reach = [
            (d, centre) if cg.in_bounds(*rc) else (np.inf, centre)
            for (d, centre), rc in zip(reach, cells, strict=True)
        ]
        out.append((reach, p))
    # every (cell, point) segment of a finite cell, sampled together as at() samples them
    segs = [(centre, p) for reach, p in out for d, centre in reach if np.isfinite(d)]
    seen = iter(
        _plain_line_of_sight(tr.blocked, tr.geometry, [s[0] for s in segs], [s[1] for s in segs])
        if segs
        else []
    )
    at = []
    for reach, p in out:
        best = np.inf
        for d, centre in reach:
            if np.isfinite(d) and next(seen):
                best = min(best, d + np.linalg.norm(centre - p))
        at.append(best)
    at_arr = np.array(at)
    straight = np.linalg.norm(points - field.start, axis=-1)
    los = _plain_line_of_sight(tr.blocked, tr.geometry, field.start, points)
    return np.where(los, straight, np.maximum(straight, at_arr)), at_arr


# ----------------------------------------------------------------------------------- tests


def test_line_of_sight_is_the_plain_sampling(explored) -> None:
    rng = np.random.default_rng(1)
    for grid, robot in explored:
        g = grid.geometry
        blocked = grid.states() == OCCUPIED
        x0, x1, y0, y1 = g.extent
        a = rng.uniform([x0 - 1, y0 - 1], [x1 + 1, y1 + 1], (200, 2))  # some off the map
        b = rng.uniform([x0 - 1, y0 - 1], [x1 + 1, y1 + 1], (200, 2))
        for step in (None, 0.01, 0.3):
            got = line_of_sight(blocked, g, a, b, step)
            np.testing.assert_array_equal(got, _plain_line_of_sight(blocked, g, a, b, step))
        np.testing.assert_array_equal(
            line_of_sight(blocked, g, robot, b), _plain_line_of_sight(blocked, g, robot, b)
        )
        assert line_of_sight(blocked, g, robot, b[0]) == _plain_line_of_sight(
            blocked, g, robot, b[0]
        )
    with pytest.raises(ValueError, match="shape"):
        line_of_sight(np.zeros((3, 3), dtype=bool), g, a, b)


@pytest.mark.parametrize(
    ("beta", "threshold", "min_cells"), [(1.0, 0.1, 5), (1.0, 1.2, 1), (2.0, 0.6, 3), (0.0, 0, 1)]
)
def test_frontiers_are_eq2_over_the_whole_map(explored, beta, threshold, min_cells) -> None:
    for grid, _ in explored:
        states = grid.states()
        got = _as_tuples(frontiers_from_states(states, grid.geometry, beta, threshold, min_cells))
        assert got == _plain_frontiers(states, grid.geometry, beta, threshold, min_cells)
        assert got, "the explored grids have frontiers"


def test_closest_points_are_closest_point_of_each_cluster(explored, rmap: RegionMap) -> None:
    for grid, robot in explored:
        clusters = frontiers_from_states(grid.states(), grid.geometry, 1.0, 0.1, 1)
        for target in (robot, *(rmap.region_point(n) for n in rmap.names)):
            want = np.array([closest_point(c, target) for c in clusters])
            np.testing.assert_array_equal(closest_points(clusters, target), want)
    assert closest_points([], (0.0, 0.0)).shape == (0, 2)


def test_region_lookup_and_the_trailing_region_are_point_by_point(rmap: RegionMap) -> None:
    rng = np.random.default_rng(2)
    x0, y0, x1, y1 = np.array([rmap.polygon(n).bounds for n in rmap.names]).T
    points = rng.uniform([x0.min() - 1, y0.min() - 1], [x1.max() + 1, y1.max() + 1], (500, 2))
    # and points on the boundaries: shared edges, corners, door lines (first region wins)
    corners = np.concatenate([np.asarray(rmap.polygon(n).exterior.coords) for n in rmap.names])
    mids = (corners[:-1] + corners[1:]) / 2.0
    points = np.concatenate([points, corners, mids])
    want = [rmap.names.index(n) if n is not None else -1 for n in map(rmap.locate, points)]
    assert rmap.locate_all(points).tolist() == want
    assert rmap.locate_all(np.empty((0, 2))).tolist() == []
    for _ in range(30):
        h = _history(rng, rmap)
        for cut in (len(h), len(h) // 2, 1, 0):
            np.testing.assert_array_equal(
                since_region_entered(h[:cut], rmap), _plain_since_region_entered(h[:cut], rmap)
            )
    outside = np.array([[0.0, -50.0, -50.0], [0.1, 1.0, 1.0], [0.2, -50.0, -50.0]])
    np.testing.assert_array_equal(
        since_region_entered(outside, rmap), _plain_since_region_entered(outside, rmap)
    )


@pytest.mark.parametrize("downsample", [None, 2, 3, 5])
def test_path_lengths_are_the_plain_graph(explored, rmap: RegionMap, downsample) -> None:
    rng = np.random.default_rng(3)
    for grid, robot in explored[1::2]:
        states = grid.states()
        tr = traversability(
            states != OCCUPIED,
            geometry=grid.geometry,
            downsample=downsample,
            known=states != UNKNOWN,
        )
        f = tr.factor
        hc, wc = tr.coarse_geometry.height, tr.coarse_geometry.width
        padded = np.zeros((hc * f, wc * f), dtype=bool)
        padded[: grid.geometry.height, : grid.geometry.width] = tr.blocked
        np.testing.assert_array_equal(tr.coarse_free, ~padded.reshape(hc, f, wc, f).any((1, 3)))
        starts = np.array([robot, rmap.region_point(rmap.names[0])])
        fields = distance_fields(tr, starts)
        # the same lengths, summed along tied shortest paths in whichever order Dijkstra takes
        # them: equal to far below a millimetre, not always to the last bit
        np.testing.assert_allclose(
            np.array([fl.distances for fl in fields]),
            _plain_distances(tr, starts),
            rtol=0.0,
            atol=1e-9,
        )
        clusters = frontiers_from_states(states, grid.geometry, 1.0, 0.1, 5)
        points = np.concatenate(
            [closest_points(clusters, starts[1]), rng.uniform(0.0, 10.0, (10, 2))]
        )
        for fl in fields:
            want, want_at = _plain_field(fl, points)
            np.testing.assert_allclose(fl(points), want, rtol=0.0, atol=1e-9)
            np.testing.assert_allclose(fl.at(points), want_at, rtol=0.0, atol=1e-9)


def test_next_waypoint_is_eq3_over_the_plain_parts(explored, rmap: RegionMap) -> None:
    """End to end: the decision's goals and utilities are Eq. 3 with the plain frontiers, the
    plain closest points and the plain path lengths, for l* the decision names."""
    rng = np.random.default_rng(4)
    params = SearchParams()
    for grid, robot in explored:
        world = WorldModel(grid, None, rmap, params)  # type: ignore[arg-type]  # no planner used
        decision = world.next_waypoint(_history(rng, rmap), robot)
        assert decision.reason == "frontier" and decision.target_point is not None
        states = grid.states()
        np.copyto(states, np.int8(OCCUPIED), where=rmap.blocked_mask(grid.geometry))
        plain = _plain_frontiers(states, grid.geometry, params.beta, params.frontier_threshold, 5)
        assert _as_tuples(list(decision.clusters)) == plain
        anchor = np.array(decision.target_point)
        goals = np.array(
            [
                np.asarray(points)[np.argmin(np.sum((np.asarray(points) - anchor) ** 2, 1))]
                for _, points, _, _ in plain
            ]
        )
        assert decision.goals == tuple(map(tuple, goals.tolist()))
        tr = traversability(states != OCCUPIED, geometry=grid.geometry, known=states != UNKNOWN)
        fields = distance_fields(tr, np.array([robot, anchor]))
        d_x = _plain_field(fields[0], goals)[0]
        d_l = _plain_field(fields[1], goals)[0]
        n = np.array([c[3] for c in plain], dtype=float)
        assert decision.utilities == tuple((params.alpha * n - (d_x + d_l)).tolist())
