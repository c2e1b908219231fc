"""Walls implied by a HouseLayout, and the house rasterised into an occupancy grid."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from scipy import ndimage
from shapely.geometry import LineString, MultiLineString, Point, Polygon
from shapely.ops import unary_union

from pfctl.core.mapping.grid import FREE, OCCUPIED, UNKNOWN
from pfctl.core.mapping.house import HouseLayout
from pfctl.core.mapping.walls import (
    house_geometry,
    rasterize_house,
    wall_boxes,
    wall_footprint,
    wall_segments,
)

HOUSE = Path(__file__).resolve().parents[3] / "missions" / "house.yaml"


def _state_at(grid, x: float, y: float) -> int:
    rows, cols = grid.geometry.world_to_cell(np.array([x, y]))
    return int(grid.states()[int(rows), int(cols)])


def test_walls_are_the_region_boundaries_minus_exactly_the_doors(layout: HouseLayout) -> None:
    walls = MultiLineString(wall_segments(layout))
    doors = unary_union([LineString(d.segment) for d in layout.doors])
    boundaries = unary_union([Polygon(r.polygon).boundary for r in layout.regions])
    # walls + doors are all the boundaries, with nothing missing and nothing added
    assert unary_union([walls, doors]).symmetric_difference(boundaries).length < 1e-9
    # every door is a gap: no wall runs along it (touching its end points is fine)
    for d in layout.doors:
        assert walls.intersection(LineString(d.segment)).length < 1e-9
    # shared edges are counted once: the segments do not overlap
    assert math.isclose(sum(s.length for s in walls.geoms), unary_union(walls).length)


def test_wall_segments_are_deterministic_and_straight(layout: HouseLayout) -> None:
    segments = wall_segments(layout)
    assert segments == wall_segments(layout)
    assert segments == sorted(segments)
    # the house's walls are axis-aligned, so each segment is horizontal or vertical
    assert all(a[0] == b[0] or a[1] == b[1] for a, b in segments)
    assert ((5.0, 0.0), (5.0, 1.5)) in segments  # kitchen | living room, below the door


def test_wall_boxes_close_corners_but_keep_doors_open(layout: HouseLayout) -> None:
    footprint = wall_footprint(layout, 0.1)
    assert len(wall_boxes(layout, 0.1)) == len(wall_segments(layout))
    for a, b in wall_segments(layout):
        assert footprint.buffer(1e-9).covers(LineString([a, b]))
    for corner in [(0, 0), (12, 0), (12, 9), (0, 9)]:
        assert footprint.buffer(1e-9).covers(Point(corner).buffer(0.049))
    for d in layout.doors:
        opening = LineString(d.segment).buffer(0.04, cap_style="flat")
        assert footprint.intersection(opening).area < 1e-9, d


def test_rasterised_house_free_inside_occupied_walls_unknown_outside(layout) -> None:
    grid = rasterize_house(layout, 0.05)
    for d in layout.doors:  # the middle of every opening is free, in both wall rows
        (x0, y0), (x1, y1) = d.segment
        mx, my = (x0 + x1) / 2, (y0 + y1) / 2
        length = math.dist((x0, y0), (x1, y1))
        nx, ny = (y1 - y0) / length, (x0 - x1) / length  # unit normal of the door
        for s in (-0.025, 0.025):
            assert _state_at(grid, mx + s * nx, my + s * ny) == FREE, d
    assert _state_at(grid, 5.0, 3.2) == OCCUPIED  # kitchen | living room wall
    assert _state_at(grid, 1.0, 4.0) == OCCUPIED  # kitchen | hall wall
    assert _state_at(grid, 0.0, 7.0) == OCCUPIED  # outer wall
    assert _state_at(grid, -0.3, -0.3) == UNKNOWN
    assert _state_at(grid, 12.4, 8.0) == UNKNOWN
    assert _state_at(grid, 3.0, 1.5) == FREE  # kitchen floor
    assert _state_at(grid, 1.8, 2.4) == OCCUPIED  # dining table
    no_furniture = rasterize_house(layout, 0.05, include_obstacles=False)
    assert _state_at(no_furniture, 1.8, 2.4) == FREE
    probabilities = np.unique(np.round(grid.prob(), 6))
    assert set(probabilities.tolist()) == {0.0, 0.5, 1.0}


def test_grid_covers_the_house_plus_margin_with_snapped_origin(layout: HouseLayout) -> None:
    g = house_geometry(layout, 0.05, margin=0.5)
    assert g.origin == (-0.5, -0.5)
    _, xmax, _, ymax = g.extent
    assert xmax >= 12.5 - 1e-9 and ymax >= 9.5 - 1e-9
    g = house_geometry(layout, 0.07, margin=0.3)
    for o in g.origin:
        assert abs(o / 0.07 - round(o / 0.07)) < 1e-6
    assert g.extent[0] <= -0.3 and g.extent[1] >= 12.3


@pytest.mark.parametrize("resolution", [0.05, 0.1, 0.2])
def test_walls_stay_closed_at_coarse_resolutions(layout: HouseLayout, resolution) -> None:
    closed = HouseLayout(regions=layout.regions, doors=(), obstacles=())
    free = rasterize_house(closed, resolution).states() == FREE
    _, rooms = ndimage.label(free)
    assert rooms == len(layout.regions)
    free = rasterize_house(layout, resolution).states() == FREE
    _, connected = ndimage.label(free)
    assert connected == 1  # the doors join everything
