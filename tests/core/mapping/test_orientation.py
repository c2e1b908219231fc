"""The dominant wall orientation of a map, and the map turned by an angle."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pfctl.core.homes.home import HomeOptions, generate_home
from pfctl.core.mapping.grid import FREE, OCCUPIED, UNKNOWN, GridGeometry
from pfctl.core.mapping.house import HouseLayout, Region
from pfctl.core.mapping.noise import slam_noise
from pfctl.core.mapping.orientation import rotate_points, rotated_map, wall_orientation
from pfctl.core.mapping.walls import rasterize_house


def _home_map(seed: int) -> tuple[np.ndarray, GridGeometry]:
    """The exported map of the home ``pfctl mission generate --seed SEED`` draws."""
    home = generate_home(
        HomeOptions(seed=seed),
        resolution=0.05,
        wall_thickness=0.1,
        robot_radius=0.215,
        person_radius=0.25,
    )
    grid = rasterize_house(home.layout, 0.05, wall_thickness=0.1)
    return grid.states(), grid.geometry


@pytest.mark.parametrize("degrees", [17.0, 33.0, -20.0, 44.0])
@pytest.mark.parametrize("seed", [1, 4])
def test_the_walls_of_a_turned_home_are_found_within_a_degree(seed: int, degrees: float) -> None:
    """A generated home turned by ``degrees`` and noised as a SLAM map: the angle (modulo 90°)
    within 1°, and a clearly dominant orientation."""
    states, geometry = _home_map(seed)
    turned, _ = rotated_map(states, geometry, math.radians(degrees))
    turned = slam_noise(turned, 0.05, np.random.default_rng([seed, 25]))
    angle, strength = wall_orientation(turned == OCCUPIED)
    error = (math.degrees(angle) - degrees + 45.0) % 90.0 - 45.0
    assert abs(error) <= 1.0
    assert strength > 0.5


def test_an_axis_aligned_map_has_its_walls_at_exactly_zero() -> None:
    states, _ = _home_map(2)
    noisy = slam_noise(states, 0.05, np.random.default_rng([2, 25]))
    assert wall_orientation(states == OCCUPIED)[0] == 0.0
    assert wall_orientation(noisy == OCCUPIED)[0] == 0.0


def test_walls_in_every_direction_have_no_dominant_orientation() -> None:
    """A round room (a 24-gon): its walls vote for every angle, so the strength is low."""
    ring = tuple(
        (3.0 * math.cos(2 * math.pi * k / 24), 3.0 * math.sin(2 * math.pi * k / 24))
        for k in range(24)
    )
    grid = rasterize_house(HouseLayout(regions=(Region("round", ring),)), 0.05)
    assert wall_orientation(grid.states() == OCCUPIED)[1] < 0.2
    assert wall_orientation(np.zeros((10, 10), dtype=bool)) == (0.0, 0.0)


def test_a_turned_map_keeps_each_cell_where_its_point_went() -> None:
    """Every old cell centre, turned, lands in a new cell of the same state; outside is
    unknown; the new grid covers the turned old one at the same resolution."""
    rng = np.random.default_rng(3)
    geometry = GridGeometry(0.1, 30, 20, origin=(-1.0, 0.5))
    states = rng.choice([FREE, OCCUPIED, UNKNOWN], size=geometry.shape).astype(np.int8)
    angle = math.radians(90.0)
    turned, new = rotated_map(states, geometry, angle)
    assert new.resolution == 0.1 and new.shape == (30, 20)
    centres = geometry.cell_to_world(*np.indices(geometry.shape))
    rows, cols = new.world_to_cell(rotate_points(centres, angle) + 1e-9)
    assert np.array_equal(turned[rows, cols], states)
    free = np.full(geometry.shape, FREE, dtype=np.int8)
    turned, new = rotated_map(free, geometry, math.radians(30.0))
    assert turned[0, 0] == UNKNOWN and turned[-1, -1] == UNKNOWN
    assert np.count_nonzero(turned == FREE) == pytest.approx(free.size, rel=0.05)
