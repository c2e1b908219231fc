"""Where a robot or a person can go in a home: the project's own planner grid, checked.

The grid is the static map the simulator and the follower use
(:func:`~pfctl.core.mapping.walls.rasterize_house`), planned on by
:class:`~pfctl.core.mapping.planning.GridPlanner` for a disc of the robot's (or a person's) radius.
A home is *open* for a radius when the free cells of that disc form one connected piece
(8-connected, as the planner's graph) that reaches every region: nothing can be hidden in, or sent
to, a pocket no one can drive or walk into.
"""

from __future__ import annotations

import numpy as np
import shapely
from numpy.typing import NDArray
from scipy import ndimage

from pfctl.core.mapping.grid import GridGeometry
from pfctl.core.mapping.house import Door, HouseLayout
from pfctl.core.mapping.planning import GridPlanner
from pfctl.core.mapping.walls import rasterize_house

__all__ = ["doors_crossed", "home_planner", "open_issue", "reachable_regions", "region_masks"]

_EIGHT = np.ones((3, 3), dtype=bool)
#: The least free area (m²) of a region that counts as reaching it.
MIN_REACH_AREA = 0.5


def home_planner(
    layout: HouseLayout, resolution: float, wall_thickness: float, radius: float
) -> GridPlanner:
    """The planner of ``layout``'s static map (walls, doors, furniture) for a disc of ``radius``."""
    return GridPlanner(rasterize_house(layout, resolution, wall_thickness), radius)


def _components(free: NDArray[np.bool_]) -> tuple[NDArray[np.int32], int]:
    labels, count = ndimage.label(free, structure=_EIGHT)
    return labels, int(count)


def region_masks(layout: HouseLayout, geometry: GridGeometry) -> dict[str, NDArray[np.bool_]]:
    """Per region, the cells of ``geometry`` whose centres lie inside it."""
    centres = geometry.cell_to_world(*np.indices(geometry.shape))
    return {
        r.name: shapely.contains_xy(shapely.Polygon(r.polygon), centres[..., 0], centres[..., 1])
        for r in layout.regions
    }


def reachable_regions(
    layout: HouseLayout,
    planner: GridPlanner,
    start: tuple[float, float],
    masks: dict[str, NDArray[np.bool_]] | None = None,
) -> dict[str, float]:
    """Per region, the free area (m²) of it a disc starting at ``start`` can reach; ``masks``:
    :func:`region_masks` of the planner's grid, if already made."""
    labels, _ = _components(planner.free)
    rows, cols = planner.geometry.world_to_cell(np.asarray(start, dtype=float))
    label = int(labels[int(rows), int(cols)]) if planner.geometry.in_bounds(rows, cols) else 0
    reach = (labels == label) if label else np.zeros(labels.shape, dtype=bool)
    masks = region_masks(layout, planner.geometry) if masks is None else masks
    cell = planner.geometry.resolution**2
    return {name: float((mask & reach).sum() * cell) for name, mask in masks.items()}


def open_issue(
    layout: HouseLayout,
    planner: GridPlanner,
    masks: dict[str, NDArray[np.bool_]] | None = None,
) -> str | None:
    """Why ``layout`` is not open for the planner's disc (see the module docstring), or None."""
    labels, count = _components(planner.free)
    if count == 0:
        return "no free cell"
    if count > 1:
        sizes = np.bincount(labels.ravel())[1:]
        small = int(np.argsort(sizes)[0]) + 1
        where = planner.geometry.cell_to_world(*(int(v[0]) for v in np.nonzero(labels == small)))
        return (
            f"{count} separate free areas for radius {planner.robot_radius:g} m "
            f"(one near ({where[0]:.2f}, {where[1]:.2f}))"
        )
    rows, cols = np.nonzero(labels == 1)
    point = planner.geometry.cell_to_world(rows[0], cols[0])
    start = (float(point[0]), float(point[1]))
    for name, area in reachable_regions(layout, planner, start, masks).items():
        if area < MIN_REACH_AREA:
            return f"region {name!r} has {area:.2f} m² free for radius {planner.robot_radius:g} m"
    return None


def doors_crossed(path: NDArray[np.float64], doors: tuple[Door, ...]) -> list[int]:
    """Indices of the ``doors`` a polyline ``(n, 2)`` passes through, in the order it does."""
    if len(path) < 2:
        return []
    line = shapely.LineString(path)
    hits: list[tuple[float, int]] = []
    for i, door in enumerate(doors):
        common = line.intersection(shapely.LineString(door.segment))
        if common.is_empty:
            continue
        pieces = [g for g in getattr(common, "geoms", [common])]
        for piece in pieces:
            hits.append((line.project(piece.representative_point()), i))
    hits.sort()
    out: list[int] = []
    for _, i in hits:
        if not out or out[-1] != i:
            out.append(i)
    return out
