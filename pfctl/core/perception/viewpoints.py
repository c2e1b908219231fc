"""Where a person can be seen from: the nearest place for the robot with her in sight.

The oracle baseline (``oracle_search``, issue 22) drives to the nearest place from which the
target's *true* position is in view; this module is the geometry of that choice, on any grid and
any position (it does not know where the position comes from). A cell is a viewpoint of a person
at ``xy`` when the robot may stand there (free on the planner's map, inflated by the robot's
radius) and the person is in sight from it: within ``[range_min, range_max]`` and with no wall or
furniture of the static map on the line between them (:func:`~pfctl.core.perception.belief.
visible_mask` from her position, all around: sight is symmetric). Of the viewpoints, the nearest
is the one the planner's path from the robot costs least to (:meth:`~pfctl.core.mapping.planning.
GridPlanner.distances_from`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pfctl.core.mapping.planning import GridPlanner, NoPathError
from pfctl.core.perception.belief import visible_mask
from pfctl.core.perception.tracking import FieldOfView
from pfctl.core.robot import Pose2D


@dataclass(frozen=True)
class Viewpoint:
    """A place for the robot from which a person is in sight, and the way there."""

    xy: tuple[float, float]
    """The cell's centre (map frame, m)."""
    cost: float
    """The planner's path cost from the robot to it, m (0: the robot is there already)."""


def viewpoint_mask(
    planner: GridPlanner,
    person_xy: ArrayLike,
    range_max: float,
    range_min: float = 0.0,
    clearance: float = 0.0,
) -> NDArray[np.bool_]:
    """The cells (shape ``planner.geometry.shape``) from which a person at ``person_xy`` is in
    sight within ``[range_min, range_max]`` m and where the robot may stand. The static map's
    obstacles (``planner.obstacle``: walls, furniture, outside the house) block the line of
    sight, and so does everything within ``clearance`` m of them — a person is not a point:
    a line that grazes a shelf's corner shows a sliver of her, not her legs and clothes —
    except around the person herself (she may stand close to a wall); her own cell never
    blocks."""
    if not range_max > range_min >= 0.0:
        raise ValueError(f"expected 0 <= range_min < range_max, got {range_min}, {range_max}")
    if not clearance >= 0.0:
        raise ValueError(f"expected clearance >= 0, got {clearance}")
    x, y = (float(v) for v in np.asarray(person_xy, dtype=float).reshape(2))
    geometry = planner.geometry
    blocked = planner.obstacle.copy()
    if clearance > 0.0:
        rows, cols = np.indices(geometry.shape)
        centres = geometry.cell_to_world(rows, cols)
        near_her = (
            np.hypot(centres[..., 0] - x, centres[..., 1] - y) <= clearance + geometry.resolution
        )
        blocked |= (planner.clearance < clearance) & ~near_her
    r, c = (int(v) for v in geometry.world_to_cell((x, y)))
    if geometry.in_bounds(r, c):
        blocked[r, c] = False
    fov = FieldOfView(Pose2D(x, y, 0.0), math.pi, range_min, range_max)
    return visible_mask(geometry, fov, blocked) & planner.free


def nearest_viewpoint(
    planner: GridPlanner,
    robot_xy: ArrayLike,
    person_xy: ArrayLike,
    range_max: float,
    range_min: float = 0.0,
    clearance: float = 0.0,
) -> Viewpoint | None:
    """Of the :func:`viewpoint_mask` cells, the one the robot at ``robot_xy`` reaches at the
    least path cost (ties: the one nearer the person); None when no viewpoint can be reached
    (or the robot is nowhere near a free cell)."""
    mask = viewpoint_mask(planner, person_xy, range_max, range_min, clearance)
    rows, cols = np.indices(planner.geometry.shape)
    centres = planner.geometry.cell_to_world(rows, cols)
    away = np.linalg.norm(centres - np.asarray(person_xy, dtype=float).reshape(2), axis=-1)
    return _cheapest(planner, robot_xy, mask, away)


def _cheapest(
    planner: GridPlanner,
    robot_xy: ArrayLike,
    mask: NDArray[np.bool_],
    tie: NDArray[np.float64],
    first: NDArray[np.bool_] | None = None,
) -> Viewpoint | None:
    """Of the cells in ``mask``, the one the robot at ``robot_xy`` reaches at the least path
    cost, ties to the least ``tie`` (per cell) — of those also in ``first`` if the robot can
    reach any; None when none can be reached."""
    if not mask.any():
        return None
    try:
        cost = planner.distances_from(robot_xy)
    except NoPathError:
        return None
    reachable = mask & np.isfinite(cost)
    if first is not None and (reachable & first).any():
        reachable &= first
    rows, cols = np.nonzero(reachable)
    if len(rows) == 0:
        return None
    best = int(np.lexsort((tie[rows, cols], cost[rows, cols]))[0])
    xy = planner.geometry.cell_to_world(rows[best], cols[best])
    return Viewpoint((float(xy[0]), float(xy[1])), float(cost[rows[best], cols[best]]))


def face_viewpoint(
    planner: GridPlanner,
    robot_xy: ArrayLike,
    person_xy: ArrayLike,
    facing: float,
    range_min: float,
    range_max: float,
    *,
    half_angle: float = math.radians(60.0),
    aside: float = 0.0,
    clearance: float = 0.0,
    head_on: float | None = None,
) -> Viewpoint | None:
    """Where to see the face of a person at ``person_xy`` who faces ``facing`` (rad, map
    frame; issue 23, item 3): of the :func:`viewpoint_mask` cells ``range_min``..``range_max``
    from them, those within ``half_angle`` of the direction they face and at least ``aside``
    off it (a walker's own path ahead is left free: not in their way) — the one the robot
    reaches at the least path cost; None when there is none. With ``head_on``, the cells
    within that angle of their facing come first when the robot can reach any: a face turned
    further than that from the camera may not be found at all (traced, the crowd, seed 4: the
    cheapest place within 60° of her assumed facing lay about 50° off it and 70° off the way
    she really faced, and her face was not found from there in 10 s)."""
    mask = viewpoint_mask(planner, person_xy, range_max, range_min, clearance)
    px, py = (float(v) for v in np.asarray(person_xy, dtype=float).reshape(2))
    rows, cols = np.indices(planner.geometry.shape)
    centres = planner.geometry.cell_to_world(rows, cols)
    bearing = np.arctan2(centres[..., 1] - py, centres[..., 0] - px)
    off = np.abs((bearing - facing + math.pi) % (2 * math.pi) - math.pi)
    mask &= (off <= half_angle) & (off >= aside)
    first = None if head_on is None else off <= head_on
    return _cheapest(planner, robot_xy, mask, off, first)


__all__ = ["Viewpoint", "face_viewpoint", "nearest_viewpoint", "viewpoint_mask"]
