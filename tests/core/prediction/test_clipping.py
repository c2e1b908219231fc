"""Map-aware clipping: a predicted path stops at the first wall, never ends in an occupied cell."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from pfctl.core.mapping.grid import OCCUPIED, GridGeometry, OccupancyGrid
from pfctl.core.mapping.house import HouseLayout
from pfctl.core.mapping.regions import RegionMap
from pfctl.core.mapping.walls import rasterize_house
from pfctl.core.prediction.clipping import blocked_cells, clip_path, clip_prediction

GEOMETRY = GridGeometry(0.1, 50, 40, (-1.0, -2.0))  # 5 m × 4 m


def _cell_blocked(geometry: GridGeometry, blocked: np.ndarray, p: np.ndarray) -> bool:
    rows, cols = geometry.world_to_cell(p)
    r, c = int(rows), int(cols)
    if not (0 <= r < geometry.height and 0 <= c < geometry.width):
        return True
    return bool(blocked[r, c])


def _segment_hits(
    geometry: GridGeometry, blocked: np.ndarray, a: np.ndarray, b: np.ndarray
) -> bool:
    """Dense sampling of a→b (a check independent of the traversal under test)."""
    for s in np.linspace(0.0, 1.0, 400):
        if _cell_blocked(geometry, blocked, a + s * (b - a)):
            return True
    return False


def test_free_path_is_unchanged() -> None:
    blocked = np.zeros(GEOMETRY.shape, dtype=bool)
    path = np.array([[0.5, 0.0], [1.5, 0.5], [2.5, 1.0]])
    out = clip_path([0.0, 0.0], path, GEOMETRY, blocked)
    assert not out.clipped and out.stop_index is None
    np.testing.assert_array_equal(out.xy, path)


def test_stops_before_a_wall_and_holds_there() -> None:
    blocked = np.zeros(GEOMETRY.shape, dtype=bool)
    blocked[:, 25] = True  # a wall at x ∈ [1.5, 1.6)
    path = np.array([[0.5, 0.0], [1.2, 0.1], [2.0, 0.2], [3.0, 0.3]])
    out = clip_path([0.0, 0.0], path, GEOMETRY, blocked)
    assert out.stop_index == 2
    np.testing.assert_array_equal(out.xy[:2], path[:2])
    assert 1.49 < out.xy[2, 0] < 1.5  # just before the wall, on the segment
    assert abs(out.xy[2, 1] - (0.1 + 0.1 * (1.5 - 1.2) / 0.8)) < 1e-3
    np.testing.assert_array_equal(out.xy[3], out.xy[2])


def test_path_cannot_slip_between_diagonal_wall_cells() -> None:
    blocked = np.zeros(GEOMETRY.shape, dtype=bool)
    for k in range(40):
        blocked[k, k] = True  # a diagonal wall, cells touching at corners only
    start = GEOMETRY.cell_to_world(10, 5)
    end = GEOMETRY.cell_to_world(5, 10)  # the other side, straight through a corner
    out = clip_path(start, [end], GEOMETRY, blocked)
    assert out.clipped
    assert not _segment_hits(GEOMETRY, blocked, start, out.xy[0])


def test_start_in_a_wall_is_snapped_out() -> None:
    blocked = np.zeros(GEOMETRY.shape, dtype=bool)
    blocked[20, :] = True
    start = GEOMETRY.cell_to_world(20, 10)
    out = clip_path(start, [start + np.array([0.0, -0.5])], GEOMETRY, blocked)
    assert not _cell_blocked(GEOMETRY, blocked, out.start)
    assert np.linalg.norm(out.start - start) <= 0.1 + 1e-9
    assert not _cell_blocked(GEOMETRY, blocked, out.xy[0])


def test_leaving_the_map_stops_at_its_edge() -> None:
    blocked = np.zeros(GEOMETRY.shape, dtype=bool)
    out = clip_path([3.5, 0.0], [[3.8, 0.0], [6.0, 0.0]], GEOMETRY, blocked)  # grid ends at x=4
    assert out.stop_index == 1
    assert 3.9 < out.xy[1, 0] < 4.0


def test_house_clipping_and_region(layout: HouseLayout) -> None:
    """Walking north in the hall past the office door: stopped at the office wall, in the hall;
    walking through the office door: reaches the office."""
    grid = rasterize_house(layout, 0.05)
    regions = RegionMap(layout)
    wall = clip_prediction([5.0, 5.0], [[5.0, 5.8], [5.0, 6.6], [5.0, 7.4]], grid, regions)
    assert wall.stop_index == 1 and wall.region == "hall"
    assert 5.8 < wall.end[1] < 6.0
    door = clip_prediction([3.95, 5.0], [[3.95, 5.8], [3.95, 6.6], [3.95, 7.4]], grid, regions)
    assert not door.clipped and door.region == "office"
    blocked = blocked_cells(grid, regions)
    for p in (*wall.xy, *door.xy):
        assert not _cell_blocked(grid.geometry, blocked, np.asarray(p))


def test_blocked_cells_are_the_occupied_ones_without_regions() -> None:
    p = np.full((4, 5), 0.5)
    p[1, 2] = 1.0
    p[2, 2] = 0.0
    grid = OccupancyGrid.from_probabilities(p, 0.1)
    blocked = blocked_cells(grid)
    assert blocked.sum() == 1 and blocked[1, 2]
    assert (grid.states() == OCCUPIED).sum() == 1


# ---- property: over random walls and tracks, no returned point is in an occupied cell ----

walls = st.lists(
    st.tuples(
        st.integers(0, 39), st.integers(0, 49), st.integers(1, 12), st.integers(1, 12)
    ),  # row, col, height, width of an occupied rectangle
    min_size=0,
    max_size=8,
)
coords = st.tuples(st.floats(-1.5, 4.5), st.floats(-2.5, 2.5))  # partly outside the grid


@pytest.mark.slow
@settings(max_examples=150, deadline=None)
@given(
    rects=walls,
    start=coords,
    path=st.lists(coords, min_size=1, max_size=12),
    unknown=st.integers(0, 2**31 - 1),
)
def test_clipped_points_are_never_in_an_occupied_cell(
    rects: list[tuple[int, int, int, int]],
    start: tuple[float, float],
    path: list[tuple[float, float]],
    unknown: int,
) -> None:
    p = np.zeros(GEOMETRY.shape)
    rng = np.random.default_rng(unknown)
    p[rng.random(GEOMETRY.shape) < 0.2] = 0.5  # some unknown cells, passable
    for r, c, h, w in rects:
        p[r : r + h, c : c + w] = 1.0
    if (p == 1.0).all():
        p[0, 0] = 0.0
    grid = OccupancyGrid.from_probabilities(p, GEOMETRY.resolution, GEOMETRY.origin)
    blocked = blocked_cells(grid)
    out = clip_prediction(start, path, grid)
    assert out.xy.shape == (len(path), 2)
    assert not _cell_blocked(grid.geometry, blocked, out.start)
    here = out.start
    for q in out.xy:
        assert not _cell_blocked(grid.geometry, blocked, q)  # the property of the issue
        assert not _segment_hits(grid.geometry, blocked, here, q)  # and no wall is crossed
        here = q
    if out.stop_index is not None:
        np.testing.assert_array_equal(
            out.xy[out.stop_index :], out.xy[-1][None, :].repeat(len(path) - out.stop_index, axis=0)
        )
    else:
        np.testing.assert_array_equal(out.xy, np.asarray(path, dtype=float))
