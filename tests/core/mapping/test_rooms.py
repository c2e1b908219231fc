"""Automatic room segmentation (wall-line openings or distance transform, watershed) and door
proposals, on the shipped house, small layouts and generated homes with and without noise."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from shapely.geometry import LineString, Polygon

from pfctl.core.homes.home import HomeOptions, generate_home
from pfctl.core.mapping.grid import FREE, OCCUPIED, UNKNOWN, GridGeometry
from pfctl.core.mapping.house import Door, HouseLayout, Obstacle, Region
from pfctl.core.mapping.noise import slam_noise
from pfctl.core.mapping.orientation import rotate_points, rotated_map
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


def _two_rooms(door: float | None, start: float = 1.0) -> HouseLayout:
    regions = (
        Region("a", ((0, 0), (4, 0), (4, 3), (0, 3))),
        Region("b", ((4, 0), (8, 0), (8, 3), (4, 3))),
    )
    doors = () if door is None else (Door(("a", "b"), ((4, start), (4, start + door))),)
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
    two = rasterize_house(_two_rooms(2.0, start=0.5), 0.05)  # wall on both sides of the opening
    seg = segment_rooms(two, RoomParams(door_width=1.0))
    assert len(seg.rooms) == 1
    seg = segment_rooms(two, RoomParams(door_width=2.2))
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


def _generated(seed: int) -> HouseLayout:
    """The home ``pfctl mission generate --seed SEED`` draws (robot 0.215 m, person 0.25 m)."""
    home = generate_home(
        HomeOptions(seed=seed),
        resolution=0.05,
        wall_thickness=0.1,
        robot_radius=0.215,
        person_radius=0.25,
    )
    return home.layout


def _doors_found(truth: tuple[Door, ...], proposed: tuple[Door, ...]) -> int:
    """True doors with a proposed door on them (within 0.25 m, overlapping half the shorter)."""
    left = list(proposed)
    found = 0
    for door in truth:
        a = LineString(door.segment)
        for d in left:
            b = LineString(d.segment)
            near = a.distance(b) <= 0.25
            if near and b.intersection(a.buffer(0.25)).length >= 0.5 * min(a.length, b.length):
                left.remove(d)
                found += 1
                break
    return found


@pytest.mark.parametrize("noise", [False, True], ids=["clean", "noisy"])
@pytest.mark.parametrize("seed", [1, 2, 4, 7])  # corridor, open plan, L-shaped, hall
def test_a_generated_home_is_segmented_into_its_rooms_and_doors(seed: int, noise: bool) -> None:
    """The exported map (walls, doors, furniture), with or without SLAM noise: every region
    matched at IoU ≥ 0.7, at least 90 % of the doors found, at most 5 % spurious (none here)."""
    truth = _generated(seed)
    grid = rasterize_house(truth, 0.05, wall_thickness=0.1)
    states = grid.states()
    if noise:
        states = slam_noise(states, 0.05, np.random.default_rng([seed, 25]))
    seg = segment_free_space(states, grid.geometry)
    proposal = seg.layout()
    matches = match_regions(proposal.regions, truth.regions, min_iou=0.7)
    assert len(matches) == len(truth.regions) == len(proposal.regions)
    found = _doors_found(truth.doors, proposal.doors)
    assert found >= 0.9 * len(truth.doors)
    assert len(proposal.doors) - found == 0


def _turned(layout: HouseLayout, angle: float) -> HouseLayout:
    """The regions and doors of ``layout`` turned by ``angle`` radians about the origin."""

    def turn(points) -> tuple[tuple[float, float], ...]:
        return tuple((float(x), float(y)) for x, y in rotate_points(np.asarray(points), angle))

    return HouseLayout(
        regions=tuple(Region(r.name, turn(r.polygon)) for r in layout.regions),
        doors=tuple(Door(d.between, turn(d.segment)) for d in layout.doors),  # type: ignore[arg-type]
    )


@pytest.mark.parametrize("degrees", [17.0, 33.0])
@pytest.mark.parametrize("seed", [1, 2, 7])  # corridor, open plan, hall
def test_a_turned_generated_home_is_segmented_into_its_rooms_and_doors(
    seed: int, degrees: float
) -> None:
    """A SLAM map is turned by wherever the mapping started: the exported map turned by
    ``degrees`` (and the truth with it), with SLAM noise, is segmented at its wall angle into its
    true rooms (IoU ≥ 0.7) and ≥ 90 % of its doors, in the map's own frame and grid; the rooms
    still tile without overlap and each door's ends are vertices of both its rooms."""
    angle = math.radians(degrees)
    layout = _generated(seed)
    grid = rasterize_house(layout, 0.05, wall_thickness=0.1)
    states, geometry = rotated_map(grid.states(), grid.geometry, angle)
    states = slam_noise(states, 0.05, np.random.default_rng([seed, 25]))
    truth = _turned(layout, angle)
    seg = segment_free_space(states, geometry)
    assert abs(math.degrees(seg.wall_angle) - degrees) <= 1.0
    assert seg.labels.shape == geometry.shape and seg.warnings == ()
    proposal = seg.layout()
    matches = match_regions(proposal.regions, truth.regions, min_iou=0.7)
    assert len(matches) == len(truth.regions) == len(proposal.regions)
    found = _doors_found(truth.doors, proposal.doors)
    assert found >= 0.9 * len(truth.doors)
    assert len(proposal.doors) - found <= 0.05 * len(proposal.doors)
    shapes = {r.name: Polygon(r.polygon) for r in proposal.regions}
    for a in shapes:
        for b in shapes:
            if a < b:
                assert shapes[a].intersection(shapes[b]).area <= 1e-6
    for d in proposal.doors:
        for name in d.between:
            assert set(d.segment) <= set(seg.room(name).polygon)


def _hexagon(cx: float, cy: float, r: float = 3.0) -> tuple[tuple[float, float], ...]:
    return tuple(
        (
            round(cx + r * math.cos(math.radians(60 * k)), 6),
            round(cy + r * math.sin(math.radians(60 * k)), 6),
        )
        for k in range(6)
    )


def test_walls_in_no_dominant_direction_fall_back_to_the_distance_method() -> None:
    """Two hexagonal rooms (walls at 0°, 60° and 120°) and a 1 m door between them: no wall
    angle to turn to, so the distance transform segments them, with one warning saying so."""
    door = ((2.5, round(math.sqrt(3) / 2, 6)), (2.0, round(math.sqrt(3), 6)))
    layout = HouseLayout(
        regions=(Region("a", _hexagon(0, 0)), Region("b", _hexagon(4.5, 1.5 * math.sqrt(3)))),
        doors=(Door(("a", "b"), door),),
    )
    seg = segment_rooms(rasterize_house(layout, 0.05))
    assert len(seg.warnings) == 1 and "distance transform" in seg.warnings[0]
    assert len(match_regions(seg.layout().regions, layout.regions, min_iou=0.9)) == 2
    assert len(seg.doors) == 1 and seg.wall_angle == 0.0
    assert segment_rooms(rasterize_house(_two_rooms(0.9), 0.05)).warnings == ()


def test_a_gap_between_two_pieces_of_furniture_is_not_a_door() -> None:
    """A sofa and a bookshelf across a room, 1 m apart: one room, no door (the distance method
    cuts it)."""
    room = Region("room", ((0, 0), (6, 0), (6, 3), (0, 3)))
    furniture = (
        Obstacle(name="sofa", polygon=((2.5, 0.05), (3.4, 0.05), (3.4, 1.0), (2.5, 1.0))),
        Obstacle(name="shelf", polygon=((2.6, 2.0), (3.0, 2.0), (3.0, 2.95), (2.6, 2.95))),
    )
    grid = rasterize_house(HouseLayout(regions=(room,), obstacles=furniture), 0.05)
    seg = segment_rooms(grid)
    assert len(seg.rooms) == 1 and seg.doors == ()
    assert len(segment_rooms(grid, RoomParams(method="distance", door_width=1.0)).rooms) == 2


def test_a_corridor_narrower_than_its_doors_is_one_room() -> None:
    """A 1.2 m corridor with 1.4 m doors to two rooms: three rooms, two doors."""
    regions = (
        Region("a", ((0, 0), (4, 0), (4, 3), (0, 3))),
        Region("b", ((4, 0), (8, 0), (8, 3), (4, 3))),
        Region("corridor", ((0, 3), (8, 3), (8, 4.2), (0, 4.2))),
    )
    doors = (
        Door(("a", "corridor"), ((1.0, 3), (2.4, 3))),
        Door(("b", "corridor"), ((5.0, 3), (6.4, 3))),
    )
    layout = HouseLayout(regions=regions, doors=doors)
    seg = segment_rooms(rasterize_house(layout, 0.05))
    assert len(match_regions(seg.layout().regions, regions, min_iou=0.9)) == 3
    assert sorted(d.segment for d in seg.doors) == [
        ((1.0, 3.0), (2.4, 3.0)),
        ((5.0, 3.0), (6.4, 3.0)),
    ]


def test_an_unknown_method_is_an_error() -> None:
    grid = rasterize_house(_two_rooms(0.9), 0.1)
    with pytest.raises(ValueError, match="expected method"):
        segment_rooms(grid, RoomParams(method="voronoi"))


def test_a_wardrobe_against_a_shared_wall_stays_in_its_room() -> None:
    """Furniture is given whole to the room it stands in, not split with the room behind."""
    layout = _two_rooms(0.9)
    wardrobe = Obstacle(
        name="wardrobe", polygon=((4.05, 2.2), (4.65, 2.2), (4.65, 2.95), (4.05, 2.95))
    )
    grid = rasterize_house(HouseLayout(layout.regions, layout.doors, (wardrobe,)), 0.05)
    seg = segment_rooms(grid)
    a, b = (Polygon(r.polygon) for r in seg.rooms)
    centre = Polygon(wardrobe.polygon).centroid
    assert b.contains(centre) and not a.contains(centre)
    assert polygon_iou(a, Polygon(layout.regions[0].polygon)) > 0.95
