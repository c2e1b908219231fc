"""Frontiers (Eq. 2), utility (Eq. 3) and grid path lengths, on small hand-checked maps."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pfctl.core.mapping.frontiers import (
    FrontierCluster,
    closest_point,
    find_frontiers,
    frontier_map,
    frontiers_from_states,
    gradient_l1,
    trinary_map,
    utility,
)
from pfctl.core.mapping.grid import FREE, OCCUPIED, UNKNOWN, GridGeometry, OccupancyGrid
from pfctl.core.mapping.paths import grid_distances, line_of_sight, traversability

RES = 0.1


def _cell_set(clusters: list[FrontierCluster]) -> set[tuple[int, int]]:
    return {(int(r), int(c)) for cl in clusters for r, c in cl.cells}


def _expected_frontier(states: np.ndarray) -> set[tuple[int, int]]:
    """The rule, by plain loops: free, an unknown 8-neighbour, no occupied 8-neighbour."""
    h, w = states.shape
    out = set()
    for r in range(h):
        for c in range(w):
            if states[r, c] != FREE:
                continue
            around = [
                states[r + dr, c + dc]
                for dr in (-1, 0, 1)
                for dc in (-1, 0, 1)
                if (dr or dc) and 0 <= r + dr < h and 0 <= c + dc < w
            ]
            if UNKNOWN in around and OCCUPIED not in around:
                out.add((r, c))
    return out


def _half_explored_room() -> np.ndarray:
    """20 × 30 cells: walls all round, columns 1–14 known free, columns 15–28 unknown."""
    p = np.full((20, 30), 0.5)
    p[:, :15] = 0.0
    p[0, :] = p[-1, :] = p[:, 0] = p[:, -1] = 1.0
    return p


# ------------------------------------------------------------------------------------ Eq. 2


def test_eq2_on_a_hand_written_5x5_map() -> None:
    lam = np.array(
        [
            [0.0, 0.0, 0.5, 0.5, 0.5],
            [0.0, 0.0, 0.5, 0.5, 0.5],
            [0.0, 0.0, 0.5, 0.5, 0.5],
            [0.0, 0.0, 0.0, 0.0, 0.0],
            [1.0, 1.0, 1.0, 1.0, 1.0],
        ]
    )
    obstacles = lam == 1.0
    # By hand: ‖∇Λ‖₁ sums |Λ(n) − Λ(c)| over the 8 neighbours (edge replicated); Λ_o is 1 on
    # the bottom row, 0.5 elsewhere.
    #   (0,0) free, all neighbours free:                         F = 0
    #   (1,1) free, 3 unknown neighbours:                        F = 3·0.5 = 1.5
    #   (1,2) unknown, 3 free neighbours:                        F = 1.5
    #   (0,2) unknown, 3 free neighbours (edge replicated):      F = 1.5
    #   (2,3) unknown, 3 free neighbours below:                  F = 1.5
    #   (3,2) free, 2 unknown + 3 obstacle neighbours:  ∇Λ = 1 + 3 = 4, ∇Λ_o = 1.5 → F = 4 − 1.5β
    #   (3,4) free, 3 unknown (edge) + 3 obstacle:      ∇Λ = 1.5 + 3,   ∇Λ_o = 1.5 → F = 4.5 − 1.5β
    #   (4,2) obstacle, 3 free neighbours:              ∇Λ = 3, ∇Λ_o = 1.5, Λ_o − .5 = .5 → 3 − 2β
    #   (4,0) obstacle, 2 free neighbours + (3,-1)→(3,0) free: as (4,2) → 3 − 2β
    #   (3,0) free, 3 obstacle neighbours (2 + edge):   ∇Λ = 3, ∇Λ_o = 1.5 → 3 − 1.5β
    expected_beta1 = {
        (0, 0): 0.0,
        (1, 1): 1.5,
        (1, 2): 1.5,
        (0, 2): 1.5,
        (2, 3): 1.5,
        (3, 2): 2.5,
        (3, 4): 3.0,
        (4, 2): 1.0,
        (4, 0): 1.0,
        (3, 0): 1.5,
    }
    F1 = frontier_map(lam, obstacles, beta=1.0)
    for cell, value in expected_beta1.items():
        assert F1[cell] == pytest.approx(value), cell
    F2 = frontier_map(lam, obstacles, beta=2.0)
    assert F2[3, 2] == pytest.approx(1.0)
    assert F2[4, 2] == pytest.approx(-1.0)
    assert F2[1, 1] == pytest.approx(1.5)  # free/unknown borders do not depend on β
    assert gradient_l1(np.zeros((3, 3))).sum() == 0.0


def test_eq2_rejects_mismatched_shapes() -> None:
    with pytest.raises(ValueError, match="shape"):
        frontier_map(np.zeros((3, 3)), np.zeros((3, 4), dtype=bool), 1.0)


# ------------------------------------------------------------------------------- clustering


def test_frontier_is_exactly_the_known_unknown_border_away_from_walls() -> None:
    p = _half_explored_room()
    grid = OccupancyGrid.from_probabilities(p, RES)
    states = grid.states()
    clusters = find_frontiers(grid, beta=1.0, threshold=0.1, min_cells=1)
    # By hand: the free column 14 borders the unknown column 15; rows 1 and 18 touch the walls.
    by_hand = {(r, 14) for r in range(2, 18)}
    assert _cell_set(clusters) == by_hand == _expected_frontier(states)
    assert len(clusters) == 1
    cl = clusters[0]
    assert cl.size == 16
    assert cl.n_unknown == 18  # column 15, rows 1..18
    # Nothing on or next to a wall.
    for r, c in cl.cells:
        assert states[r, c] == FREE
        assert not np.any(states[r - 1 : r + 2, c - 1 : c + 2] == OCCUPIED)
    # Points are the cell centres; the centroid is their mean.
    np.testing.assert_allclose(cl.points[:, 0], 1.45)
    assert cl.centroid == pytest.approx((1.45, 1.0))


def test_obstacle_on_the_border_splits_the_frontier_and_is_avoided() -> None:
    p = _half_explored_room()
    p[8:11, 13:17] = 1.0  # a box straddling the border
    grid = OccupancyGrid.from_probabilities(p, RES)
    clusters = find_frontiers(grid, beta=1.0, threshold=0.1, min_cells=1)
    assert _cell_set(clusters) == _expected_frontier(grid.states())
    assert [sorted(int(r) for r, _ in cl.cells) for cl in clusters] == [
        list(range(12, 18)),
        list(range(2, 7)),
    ]
    assert find_frontiers(grid, beta=1.0, threshold=0.1, min_cells=6)[0].size == 6
    assert len(find_frontiers(grid, beta=1.0, threshold=0.1, min_cells=7)) == 0


def test_noise_in_free_space_is_no_frontier() -> None:
    p = _half_explored_room()
    rng = np.random.default_rng(3)
    p[1:-1, 1:15] = rng.uniform(0.0, 0.19, size=(18, 14))  # all still below free_thresh
    grid = OccupancyGrid.from_probabilities(p, RES)
    clusters = find_frontiers(grid, beta=1.0, threshold=0.1, min_cells=1)
    assert _cell_set(clusters) == {(r, 14) for r in range(2, 18)}


def test_two_unknown_pockets_give_two_clusters_with_hand_counted_n() -> None:
    states = np.full((8, 9), FREE, dtype=np.int8)
    states[2, 2] = UNKNOWN  # one unknown cell: a ring of 8 frontier cells, N = 1
    states[4:6, 6:8] = UNKNOWN  # a 2×2 pocket: a ring of 16 − 4 = 12 cells, N = 4
    geometry = GridGeometry(RES, 9, 8)
    clusters = frontiers_from_states(states, geometry, beta=1.0, threshold=0.1, min_cells=1)
    assert [cl.size for cl in clusters] == [12, 8]  # largest first
    assert [cl.n_unknown for cl in clusters] == [4, 1]
    assert {(int(r), int(c)) for r, c in clusters[1].cells} == {
        (r, c) for r in (1, 2, 3) for c in (1, 2, 3) if (r, c) != (2, 2)
    }
    assert clusters[1].centroid == pytest.approx((0.25, 0.25))
    assert [cl.size for cl in frontiers_from_states(states, geometry, 1.0, 0.1, 9)] == [12]


def test_n_counts_each_unknown_cell_once() -> None:
    states = np.full((5, 7), FREE, dtype=np.int8)
    states[:, 3] = UNKNOWN  # a full unknown column splits the map in two
    clusters = frontiers_from_states(states, GridGeometry(RES, 7, 5), 1.0, 0.1, 1)
    # Columns 2 and 4 are two separate clusters (column 3 between them is unknown); each
    # borders all 5 unknown cells, counted once per cluster.
    assert [cl.size for cl in clusters] == [5, 5]
    assert [cl.n_unknown for cl in clusters] == [5, 5]


# ------------------------------------------------------------------------------------ Eq. 3


def _line_cluster() -> FrontierCluster:
    points = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]])
    cells = np.array([[0, 0], [0, 10], [0, 20]])
    return FrontierCluster(cells, points, (1.0, 0.0), n_unknown=10)


def test_utility_eq3_by_hand() -> None:
    cl = _line_cluster()
    l_star = (5.0, 4.0)
    np.testing.assert_allclose(closest_point(cl, l_star), [2.0, 0.0])
    # c = (2, 0); d(x, c) = 3, d(c, l*) = 5 (a 3-4-5 triangle); U = 0.5·10 − (3 + 5) = −3.
    assert utility(cl, (2.0, -3.0), l_star, alpha=0.5) == pytest.approx(-3.0)
    # Given distance functions are used instead of Euclid.
    u = utility(
        cl,
        (2.0, -3.0),
        l_star,
        alpha=0.5,
        distance_from_robot=lambda p: np.full(len(p), 7.0),
        distance_to_l_star=lambda p: np.full(len(p), 1.0),
    )
    assert u == pytest.approx(5.0 - (7.0 + 1.0))
    # Without l*: c is the point closest to x and the second term is dropped.
    assert utility(cl, (0.0, -1.0), None, alpha=0.5) == pytest.approx(5.0 - 1.0)


# ----------------------------------------------------------------------------- path lengths


def _wall_map() -> tuple[np.ndarray, GridGeometry]:
    """5 m × 5 m at 0.1 m, all traversable but a wall x ∈ [2.5, 2.6], y ∈ [1.0, 4.0]."""
    free = np.ones((50, 50), dtype=bool)
    free[10:40, 25] = False
    return free, GridGeometry(RES, 50, 50)


def test_path_around_a_wall_is_the_hand_computed_length() -> None:
    free, geometry = _wall_map()
    a, b = np.array([1.0, 2.5]), np.array([4.0, 2.5])
    # By hand: the shortest way passes the wall's top corners (2.5, 4.0) and (2.6, 4.0).
    shortest = math.hypot(1.5, 1.5) + 0.1 + math.hypot(1.4, 1.5)  # 4.273
    field = grid_distances(free, a, geometry=geometry, downsample=1)
    d = float(field(b))
    assert d > 3.0 + 1.0  # much longer than the straight line, 3 m
    assert shortest - RES <= d <= shortest * 1.0824 + RES  # the 8-connected metric's error bound
    assert float(field.at(b)) == pytest.approx(d)
    # The default coarse search is longer (it keeps a coarse cell from the wall) but close.
    coarse = float(grid_distances(free, a, geometry=geometry)(b))
    assert shortest <= coarse <= shortest * 1.25
    # The path is symmetric.
    back = float(grid_distances(free, b, geometry=geometry, downsample=1)(a))
    assert back == pytest.approx(d, abs=2 * RES)


def test_straight_line_when_in_sight_and_inf_when_walled_in() -> None:
    free, geometry = _wall_map()
    field = grid_distances(free, (1.0, 2.5), geometry=geometry)
    assert float(field(np.array([1.0, 0.5]))) == pytest.approx(2.0)
    np.testing.assert_allclose(field(np.array([[2.0, 2.5], [0.0, 2.5]])), [1.0, 1.0])
    boxed = free.copy()
    boxed[30:35, 40] = boxed[30:35, 44] = boxed[30, 40:45] = boxed[34, 40:45] = False
    inside = (4.25, 3.25)
    assert math.isinf(float(grid_distances(boxed, (1.0, 2.5), geometry=geometry)(inside)))
    assert math.isinf(float(grid_distances(boxed, inside, geometry=geometry)((1.0, 2.5))))


def test_a_start_next_to_a_wall_does_not_leak_through_it() -> None:
    free, geometry = _wall_map()
    # 5 cm from the wall's west face: the coarse cell of the start is blocked by the wall.
    start = (2.45, 2.5)
    field = grid_distances(free, start, geometry=geometry)
    across = float(field((2.65, 2.5)))
    assert across > 2 * 1.5  # has to go round the wall's end (1.5 m away) and back
    assert float(field((2.0, 2.5))) == pytest.approx(0.45)


def test_paths_may_cross_unknown_space_unless_told_not_to() -> None:
    p = np.zeros((30, 30))
    p[:, 15] = 1.0
    p[25:, 15] = 0.5  # the only gap in the wall is unknown
    grid = OccupancyGrid.from_probabilities(p, RES)
    a, b = (0.5, 1.0), (2.5, 1.0)
    through_unknown = float(grid_distances(grid, a, downsample=1)(b))
    assert 2.0 < through_unknown < 6.0
    assert math.isinf(float(grid_distances(grid, a, downsample=1, unknown_traversable=False)(b)))
    tr = traversability(grid, unknown_traversable=False)
    assert tr.blocked[27, 15] and not tr.blocked[27, 14]


def test_line_of_sight() -> None:
    free, geometry = _wall_map()
    blocked = ~free
    assert bool(line_of_sight(blocked, geometry, (1.0, 2.5), (2.4, 2.5)))
    assert not bool(line_of_sight(blocked, geometry, (1.0, 2.5), (4.0, 2.5)))
    assert not bool(line_of_sight(blocked, geometry, (1.0, 2.5), (6.0, 2.5)))  # leaves the map
    both = line_of_sight(blocked, geometry, (1.0, 2.5), np.array([[1.0, 4.5], [4.0, 2.0]]))
    assert both.tolist() == [True, False]


def test_fast_paths_agree_with_the_plain_definitions() -> None:
    rng = np.random.default_rng(11)
    p = rng.choice([0.02, 0.1, 0.3, 0.5, 0.6, 0.8, 0.98], size=(40, 50))
    grid = OccupancyGrid.from_probabilities(p, RES)
    states = grid.states()  # thresholds the log-odds; the plain definition thresholds p:
    prob = grid.prob()
    plain_states = np.where(prob < 0.196, FREE, np.where(prob > 0.65, OCCUPIED, UNKNOWN))
    np.testing.assert_array_equal(states, plain_states)
    # Eq. 2 evaluated at the candidates only == frontier_map over the whole map, thresholded.
    F = frontier_map(trinary_map(states), states == OCCUPIED, beta=1.0)
    for threshold in (0.1, 0.7, 1.2):
        plain = {(r, c) for r, c in _expected_frontier(states) if F[r, c] > threshold}
        assert _cell_set(find_frontiers(grid, 1.0, threshold, 1)) == plain
