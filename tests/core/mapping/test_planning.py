"""GridPlanner on the shipped house: through doors, never through walls, NoPathError in a wall."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
import shapely

from pfctl.core.mapping.house import HouseLayout
from pfctl.core.mapping.planning import GridPlanner, NoPathError, path_length
from pfctl.core.mapping.walls import rasterize_house, wall_footprint

RADIUS = 0.215


@pytest.fixture(scope="module")
def planner(layout: HouseLayout) -> GridPlanner:
    return GridPlanner(rasterize_house(layout, 0.05, 0.1), RADIUS)


def _densify(path: np.ndarray, step: float = 0.01) -> np.ndarray:
    pts = [path[0]]
    for a, b in itertools.pairwise(path):
        n = max(int(np.ceil(np.linalg.norm(b - a) / step)), 1)
        pts.extend(a + (b - a) * t for t in np.linspace(0, 1, n + 1)[1:])
    return np.array(pts)


def test_path_to_another_room_goes_through_doors_clear_of_walls(
    planner: GridPlanner, layout: HouseLayout
) -> None:
    start, goal = (1.0, 3.3), (3.0, 7.5)  # kitchen -> office: kitchen-hall and hall-office doors
    path = planner.plan(start, goal)
    assert np.allclose(path[0], start) and np.allclose(path[-1], goal)
    dense = _densify(path)
    walls = wall_footprint(layout, 0.1)
    clearance = shapely.distance(walls, shapely.points(dense))
    assert clearance.min() > RADIUS - 0.05  # the disc never overlaps a wall (within a cell)
    # it crosses y = 4 inside the kitchen-hall door and y = 6 inside the hall-office door
    for y_wall, (x0, x1) in ((4.0, (2.0, 2.9)), (6.0, (3.5, 4.4))):
        k = np.flatnonzero(np.diff(np.sign(dense[:, 1] - y_wall)) != 0)
        assert len(k) >= 1
        assert all(x0 + RADIUS - 0.06 <= dense[i, 0] <= x1 - RADIUS + 0.06 for i in k)
    straight = np.hypot(goal[0] - start[0], goal[1] - start[1])
    assert straight < path_length(path) < 2.0 * straight
    assert len(path) < 15  # shortcut: a few way-points, not one per cell


def test_every_room_is_reachable_and_paths_stay_free(planner: GridPlanner) -> None:
    goals = [(4.0, 2.5), (10.5, 2.0), (6.0, 5.0), (1.5, 7.0), (8.0, 7.5)]
    for goal in goals:
        dense = _densify(planner.plan((1.0, 3.3), goal))
        assert planner.free_mask(dense[1:]).all()


def test_goal_in_a_wall_or_furniture_or_outside_raises(planner: GridPlanner) -> None:
    # a wall, the hall's south wall, the dining table, outside the house, outside the grid
    for goal in [(5.0, 3.0), (6.0, 4.0), (1.8, 2.4), (-0.3, 2.0), (20.0, 20.0)]:
        with pytest.raises(NoPathError):
            planner.plan((1.0, 3.3), goal)
    assert not planner.is_free((5.0, 3.0))
    assert planner.is_free((1.0, 3.3))


def test_unreachable_goal_raises(layout: HouseLayout) -> None:
    # a radius wider than every door: the office is free inside but cannot be reached
    fat = GridPlanner(rasterize_house(layout, 0.05, 0.1), 0.5)
    assert fat.is_free((1.5, 7.5))
    with pytest.raises(NoPathError, match="cannot be reached"):
        fat.plan((2.5, 2.0 + 1.2), (1.5, 7.5))


def test_with_obstacles_replans_around_a_blocker(planner: GridPlanner) -> None:
    start, goal = (1.0, 5.0), (11.0, 5.0)  # along the hall
    blocker = np.array([[6.0, 5.0]])
    around = planner.with_obstacles(blocker, 0.3)
    assert planner.is_free((6.0, 5.0)) and not around.is_free((6.0, 5.0))
    dense = _densify(around.plan(start, goal))
    assert np.linalg.norm(dense - blocker, axis=1).min() >= 0.3 + RADIUS - 0.05
    assert planner.is_free((6.0, 5.0))  # the original is unchanged


def test_start_pushed_into_a_wall_is_snapped(planner: GridPlanner) -> None:
    path = planner.plan((4.85, 3.0), (1.0, 3.3))  # 0.15 m from the kitchen/living wall
    assert np.allclose(path[0], (4.85, 3.0))
    assert planner.is_free(path[1])


def test_with_radius_for_a_person(planner: GridPlanner) -> None:
    person = planner.with_radius(0.25)
    assert person.robot_radius == 0.25
    assert person.plan((1.0, 3.3), (8.0, 7.5)).shape[1] == 2
