"""Automatic room segmentation (distance transform + watershed) and door proposals."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from shapely.geometry import LineString, Polygon

from pfctl.core.mapping.grid import FREE, OCCUPIED, UNKNOWN, GridGeometry
from pfctl.core.mapping.house import Door, HouseLayout, Region
from pfctl.core.mapping.rooms import (
    RoomParams,
    match_regions,
    name_after,
    polygon_iou,
    segment_free_space,
    segment_rooms,
)
from pfctl.core.mapping.walls import rasterize_house
from pfctl.mission import load_mission

HOUSE = Path(__file__).resolve().parents[3] / "missions" / "house.yaml"


@pytest.fixture(scope="module")
def segmentation(layout: HouseLayout):
    return segment_rooms(rasterize_house(layout, 0.05))


def test_every_room_of_the_house_is_found_once(segmentation, layout: HouseLayout) -> None:
    """IoU of shapely polygons, proposed vs. true; one-to-one."""
    proposed = segmentation.layout().regions
    assert len(proposed) == len(layout.regions)
    matches = match_regions(proposed, layout.regions, min_iou=0.8)
    assert sorted(rn for rn, _ in matches.values()) == sorted(r.name for r in layout.regions)
    for region in layout.regions:
        best = [
            polygon_iou(Polygon(p.polygon), Polygon(region.polygon))
            for p in proposed
            if polygon_iou(Polygon(p.polygon), Polygon(region.polygon)) >= 0.8
        ]
        assert len(best) == 1, region.name
        assert best[0] >= 0.95, (region.name, best[0])


def test_doors_are_found_where_the_house_has_them(segmentation, layout: HouseLayout) -> None:
    named = name_after(segmentation, layout)
    assert {r.name for r in named.rooms} == {r.name for r in layout.regions}
    found = {frozenset(d.between): d for d in named.doors}
    assert len(found) == len(layout.doors) == len(named.doors)
    for true in layout.doors:
        d = found[frozenset(true.between)]
        assert LineString(d.segment).hausdorff_distance(LineString(true.segment)) <= 0.051
        assert abs(d.width - math.dist(*true.segment)) <= 0.051


def test_names_are_deterministic_south_to_north_west_to_east(segmentation) -> None:
    centroids = [Polygon(r.polygon).centroid for r in segmentation.rooms]
    assert [r.name for r in segmentation.rooms] == [f"room_{i}" for i in range(1, 6)]
    assert centroids[0].x < centroids[1].x and centroids[0].y < 4 < centroids[2].y
    assert segmentation.rooms == segment_rooms(segmentation_grid()).rooms


def segmentation_grid():
    return rasterize_house(load_mission(HOUSE).layout(), 0.05)


def test_polygons_of_neighbours_share_their_wall(segmentation) -> None:
    """Polygons snap to the wall middle lines, so neighbours touch and never overlap."""
    shapes = {r.name: Polygon(r.polygon) for r in segmentation.rooms}
    for d in segmentation.doors:
        a, b = (shapes[n] for n in d.between)
        assert a.intersection(b).area < 1e-9
        assert a.boundary.intersection(b.boundary).buffer(1e-6).covers(LineString(d.segment))


def test_the_labels_cover_free_space_and_walls_but_not_outside(segmentation) -> None:
    grid = segmentation_grid()
    states = grid.states()
    labels = segmentation.labels
    assert labels.shape == states.shape
    assert np.all(labels[states == FREE] > 0)
    assert np.all(labels[states == UNKNOWN] == 0)
    assert set(np.unique(labels).tolist()) == {0, 1, 2, 3, 4, 5}


def _two_rooms(door: float | None) -> HouseLayout:
    regions = (
        Region("a", ((0, 0), (4, 0), (4, 3), (0, 3))),
        Region("b", ((4, 0), (8, 0), (8, 3), (4, 3))),
    )
    doors = () if door is None else (Door(("a", "b"), ((4, 1.0), (4, 1.0 + door))),)
    return HouseLayout(regions=regions, doors=doors)


@pytest.mark.parametrize("door", [0.8, 0.9, 1.0])
def test_two_rooms_with_a_door_are_two_rooms_and_one_door(door: float) -> None:
    seg = segment_rooms(rasterize_house(_two_rooms(door), 0.05))
    assert [r.name for r in seg.rooms] == ["room_1", "room_2"]
    assert [d.between for d in seg.doors] == [("room_1", "room_2")]
    assert seg.doors[0].segment == ((4.0, 1.0), (4.0, round(1.0 + door, 3)))


def test_a_closed_wall_gives_two_rooms_and_no_door() -> None:
    seg = segment_rooms(rasterize_house(_two_rooms(None), 0.1))
    assert len(seg.rooms) == 2 and seg.doors == ()


def test_an_opening_wider_than_door_width_joins_the_rooms() -> None:
    seg = segment_rooms(rasterize_house(_two_rooms(2.0), 0.05), RoomParams(door_width=1.0))
    assert len(seg.rooms) == 1
    seg = segment_rooms(rasterize_house(_two_rooms(2.0), 0.05), RoomParams(door_width=2.2))
    assert len(seg.rooms) == 2


def test_segment_free_space_on_a_plain_array() -> None:
    states = np.full((40, 60), OCCUPIED, dtype=np.int8)
    states[1:-1, 1:-1] = FREE
    geometry = GridGeometry(0.1, 60, 40, (0.0, 0.0))
    seg = segment_free_space(states, geometry)
    assert len(seg.rooms) == 1
    assert polygon_iou(seg.rooms[0].shape(), Polygon.from_bounds(0, 0, 6, 4)) > 0.99


def test_no_free_core_is_an_error() -> None:
    states = np.full((10, 10), OCCUPIED, dtype=np.int8)
    with pytest.raises(ValueError, match="no room found"):
        segment_free_space(states, GridGeometry(0.1, 10, 10))
    with pytest.raises(ValueError, match="do not match"):
        segment_free_space(states, GridGeometry(0.1, 11, 10))


@pytest.mark.parametrize("resolution", [0.05, 0.1])
def test_speckle_of_a_mapped_house_does_not_split_rooms(layout, resolution) -> None:
    """1 % of the free cells turned occupied and 1 % unknown, as in a noisy SLAM map."""
    grid = rasterize_house(layout, resolution)
    states = grid.states().copy()
    rng = np.random.default_rng(0)
    free = states == FREE
    states[free & (rng.random(states.shape) < 0.01)] = OCCUPIED
    states[free & (rng.random(states.shape) < 0.01)] = UNKNOWN
    seg = segment_free_space(states, grid.geometry)
    assert len(seg.rooms) == len(layout.regions) and len(seg.doors) == len(layout.doors)
    matches = match_regions(seg.layout().regions, layout.regions, min_iou=0.9)
    assert len(matches) == len(layout.regions)
