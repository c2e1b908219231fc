"""The oracle baseline's geometry (issue 22, item 4) on small hand-made grids: the chosen place is
free for the robot, has the person in sight (checked with the project's independent segment test,
:func:`~pfctl.core.mapping.paths.line_of_sight`) within range, and no other such place is nearer
along the planner's paths."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pfctl.core.mapping.grid import OccupancyGrid
from pfctl.core.mapping.paths import line_of_sight
from pfctl.core.mapping.planning import GridPlanner
from pfctl.core.perception.viewpoints import face_viewpoint, nearest_viewpoint, viewpoint_mask

RES = 0.05
RADIUS = 0.2


def _rooms(door: bool = True) -> GridPlanner:
    """An 8 m × 4 m flat, walled round, split by a wall at x = 4 m with (``door``) a 1 m door at
    y 0.5–1.5 m; a 1 m × 1 m pillar at (6, 2.5) in the east room."""
    p = np.zeros((round(4 / RES), round(8 / RES)))
    p[:2, :] = p[-2:, :] = p[:, :2] = p[:, -2:] = 1.0
    p[:, 79:81] = 1.0
    if door:
        p[10:30, 79:81] = 0.0
    p[40:60, 110:130] = 1.0
    return GridPlanner(OccupancyGrid.from_probabilities(p, RES), RADIUS)


def _in_sight(planner: GridPlanner, a: tuple[float, float], b: tuple[float, float]) -> bool:
    return bool(line_of_sight(planner.obstacle, planner.geometry, np.array(a), np.array(b)))


def test_the_place_sees_her_and_no_place_that_sees_her_is_nearer() -> None:
    planner = _rooms()
    robot, her = (1.0, 3.0), (6.0, 3.5)  # she is in the east room, behind the wall
    place = nearest_viewpoint(planner, robot, her, range_max=5.0)
    assert place is not None
    assert planner.is_free(place.xy)
    assert _in_sight(planner, place.xy, her) and math.dist(place.xy, her) <= 5.0
    # every free cell that sees her (independent segment test) costs at least as much to reach
    cost = planner.distances_from(robot)
    rows, cols = np.nonzero(planner.free & np.isfinite(cost))
    centres = planner.geometry.cell_to_world(rows, cols)
    near = np.linalg.norm(centres - her, axis=1) <= 5.0 - RES
    sees = np.zeros(len(rows), dtype=bool)
    sees[near] = line_of_sight(
        planner.obstacle, planner.geometry, centres[near], np.broadcast_to(her, centres[near].shape)
    )
    assert sees.any()
    assert place.cost <= cost[rows[sees], cols[sees]].min() + 1e-9
    assert place.xy[0] > 3.8  # through the door, not over the wall


def test_a_robot_that_already_sees_her_stays_where_it_is() -> None:
    planner = _rooms()
    place = nearest_viewpoint(planner, (5.0, 1.0), (7.0, 1.0), range_max=5.0)
    assert place is not None and place.cost == 0.0
    assert math.dist(place.xy, (5.0, 1.0)) < RES


def test_the_range_and_the_pillar_hide_her() -> None:
    planner = _rooms()
    her = (7.2, 2.5)  # east of the pillar (x 5.5–6.5, y 2–3)
    mask = viewpoint_mask(planner, her, range_max=3.0)
    rows, cols = np.nonzero(mask)
    centres = planner.geometry.cell_to_world(rows, cols)
    assert np.all(np.linalg.norm(centres - her, axis=1) <= 3.0 + RES)
    assert not mask[planner.geometry.world_to_cell((5.0, 2.5))]  # behind the pillar
    assert mask[planner.geometry.world_to_cell((6.0, 1.0))]  # beside it, in the open
    assert not mask[planner.geometry.world_to_cell((4.5, 1.0))]  # in the open, out of range


def test_the_clearance_keeps_the_line_of_sight_off_the_corners() -> None:
    planner = _rooms()
    her = (7.2, 3.05)
    grazing = (5.0, 3.15)  # the line to her passes ~0.1 m over the pillar's top (y = 3)
    assert viewpoint_mask(planner, her, 3.0)[planner.geometry.world_to_cell(grazing)]
    assert not viewpoint_mask(planner, her, 3.0, clearance=0.25)[
        planner.geometry.world_to_cell(grazing)
    ]
    # the clearance does not hide her where she stands close to a wall (0.1 m off the south
    # wall, seen from straight north of her)
    assert viewpoint_mask(planner, (7.0, 0.2), 3.0, clearance=0.25)[
        planner.geometry.world_to_cell((7.0, 1.3))
    ]


def test_no_place_when_she_cannot_be_reached_or_seen() -> None:
    planner = _rooms(door=False)
    assert nearest_viewpoint(planner, (1.0, 2.0), (6.0, 1.0), range_max=5.0) is None
    with pytest.raises(ValueError, match="range_min"):
        viewpoint_mask(planner, (6.0, 1.0), range_max=1.0, range_min=2.0)


def _open_room() -> GridPlanner:
    """8 m × 6 m, walled round, empty."""
    p = np.zeros((round(6 / RES), round(8 / RES)))
    p[:2, :] = p[-2:, :] = p[:, :2] = p[:, -2:] = 1.0
    return GridPlanner(OccupancyGrid.from_probabilities(p, RES), RADIUS)


def _off_facing(place: tuple[float, float], her: tuple[float, float], facing: float) -> float:
    bearing = math.atan2(place[1] - her[1], place[0] - her[0])
    return abs((bearing - facing + math.pi) % (2 * math.pi) - math.pi)


def test_a_place_nearer_head_on_comes_first_where_the_robot_can_reach_one() -> None:
    """Crowd seed 4: the cheapest place within 60° of the way she was taken to face lay about
    50° off it, and her face was not found from there. With ``head_on``, the places within
    that angle of her facing come first; where there are none, the rest of the 60° do."""
    planner = _open_room()
    her, east = (4.0, 3.0), 0.0
    robot = (4.0, 5.5)  # at her side, north of her
    cheapest = face_viewpoint(planner, robot, her, east, 1.0, 2.2)
    assert cheapest is not None
    assert _off_facing(cheapest.xy, her, east) > math.radians(40)  # the premise
    head_on = face_viewpoint(planner, robot, her, east, 1.0, 2.2, head_on=math.radians(30))
    assert head_on is not None
    assert _off_facing(head_on.xy, her, east) <= math.radians(30) + 1e-9
    assert 1.0 <= math.dist(head_on.xy, her) <= 2.2 + 1e-9
    assert head_on.cost > cheapest.cost
    # facing the east wall 1 m off: no place that near head-on, so one of the 60° is taken
    at_wall = (7.0, 3.0)
    fallback = face_viewpoint(planner, robot, at_wall, east, 1.0, 2.2, head_on=math.radians(30))
    assert fallback is not None
    assert math.radians(30) < _off_facing(fallback.xy, at_wall, east) <= math.radians(60) + 1e-9
