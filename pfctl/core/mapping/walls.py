"""The walls a :class:`~pfctl.core.mapping.house.HouseLayout` implies, and the house as an occupancy
grid.

This module is the **single source of truth** for the static geometry of a house described by
polygons: the rasteriser (``pfctl map export``, ``pfctl map annotate`` on a mission) and the
simulator (which extrudes the same wall boxes to ``map.wall_height``) both build their walls from
:func:`wall_segments` / :func:`wall_boxes`, so the map the robot is given and the world it drives
in cannot disagree.

The rules:

* Every edge of every region polygon is a wall; an edge shared by two regions is one wall, not two.
* A :class:`~pfctl.core.mapping.house.Door` segment lies on the shared boundary of its two
  regions; that part of the boundary is open (no wall).
* A wall of thickness ``t`` is the rectangle of its segment widened by ``t/2`` on each side and
  lengthened by ``t/2`` at each end — except at a door jamb, so that an opening is exactly as wide
  as its door segment. The lengthening closes the corners.
* Obstacles (furniture) are their polygons.

:func:`rasterize_house` turns this into the static map of the paper's convention (§II-B):
free ``p=0`` inside the regions, occupied ``p=1`` on walls and obstacles, unknown ``p=0.5``
outside the house.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np
import shapely
from numpy.typing import NDArray
from shapely.geometry import LineString, Polygon
from shapely.geometry.base import BaseGeometry
from shapely.ops import unary_union

from pfctl.core.mapping.grid import GridGeometry, OccupancyGrid
from pfctl.core.mapping.house import HouseLayout

Point = tuple[float, float]
Segment = tuple[Point, Point]

#: Distances below this (metres) are the same point; also the width of the door "cutter".
EPS = 1e-6


@dataclass(frozen=True)
class WallBox:
    """One straight piece of wall as a box footprint: centre, length along ``yaw``, thickness.

    The simulator extrudes each box to the mission's ``wall_height``; the rasteriser fills the
    union of their footprints (:func:`wall_footprint`).
    """

    center: Point
    length: float
    thickness: float
    yaw: float

    def polygon(self) -> Polygon:
        """The footprint rectangle in the map frame."""
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        hl, ht = self.length / 2.0, self.thickness / 2.0
        cx, cy = self.center
        corners = [(-hl, -ht), (hl, -ht), (hl, ht), (-hl, ht)]
        return Polygon([(cx + c * u - s * v, cy + s * u + c * v) for u, v in corners])


def _round_point(p: Iterable[float]) -> Point:
    x, y = p
    return (round(float(x), 9) + 0.0, round(float(y), 9) + 0.0)


def _lines(geom: BaseGeometry) -> list[LineString]:
    """The LineStrings of a (multi)line or collection, dropping points and empties."""
    if geom.is_empty:
        return []
    if isinstance(geom, LineString):
        return [geom]
    if hasattr(geom, "geoms"):
        out: list[LineString] = []
        for g in geom.geoms:
            out.extend(_lines(g))
        return out
    return []


def door_cutters(layout: HouseLayout, width: float = EPS) -> BaseGeometry:
    """The door openings as thin rectangles: each door segment widened by ``width`` on each side.

    Flat caps, so a cutter removes exactly the door segment from a wall line and nothing beyond
    its end points.
    """
    cutters = [
        LineString(d.segment).buffer(width, cap_style="flat")
        for d in layout.doors
        if LineString(d.segment).length > EPS
    ]
    return unary_union(cutters) if cutters else Polygon()


def wall_segments(layout: HouseLayout) -> list[Segment]:
    """The walls of a house as straight segments ``((x0, y0), (x1, y1))`` in metres.

    All region boundaries, merged so that an edge shared by two regions appears once, minus the
    door openings. Segments are maximal straight pieces between corners, junctions and door jambs,
    in a deterministic order (sorted by their end points).
    """
    if not layout.regions:
        return []
    boundaries = unary_union([Polygon(r.polygon).boundary for r in layout.regions])
    walls = boundaries.difference(door_cutters(layout)) if layout.doors else boundaries
    merged = shapely.line_merge(unary_union(walls)) if not walls.is_empty else walls
    segments: list[Segment] = []
    for line in _lines(merged):
        coords = list(line.simplify(0.0).coords)  # drop collinear intermediate vertices
        for a, b in itertools.pairwise(coords):
            pa, pb = _round_point(a), _round_point(b)
            if math.dist(pa, pb) <= EPS:
                continue
            segments.append((pa, pb) if pa <= pb else (pb, pa))
    return sorted(set(segments))


def wall_boxes(layout: HouseLayout, thickness: float = 0.1) -> list[WallBox]:
    """The walls as boxes of the given thickness (m), one per :func:`wall_segments` segment.

    Each box is lengthened by ``thickness/2`` at an end that is a corner or a junction (closing the
    corner) and not at an end that is a door jamb (keeping the opening as wide as the door).
    """
    jambs = [p for d in layout.doors for p in d.segment]
    boxes: list[WallBox] = []
    for a, b in wall_segments(layout):
        length = math.dist(a, b)
        ux, uy = (b[0] - a[0]) / length, (b[1] - a[1]) / length
        ext_a = 0.0 if any(math.dist(a, j) <= 1e-6 for j in jambs) else thickness / 2.0
        ext_b = 0.0 if any(math.dist(b, j) <= 1e-6 for j in jambs) else thickness / 2.0
        start = (a[0] - ux * ext_a, a[1] - uy * ext_a)
        end = (b[0] + ux * ext_b, b[1] + uy * ext_b)
        boxes.append(
            WallBox(
                center=((start[0] + end[0]) / 2.0, (start[1] + end[1]) / 2.0),
                length=length + ext_a + ext_b,
                thickness=thickness,
                yaw=math.atan2(uy, ux),
            )
        )
    return boxes


def wall_footprint(layout: HouseLayout, thickness: float = 0.1) -> BaseGeometry:
    """The union of the :func:`wall_boxes` footprints: where the walls stand, as a shapely area."""
    boxes = [b.polygon() for b in wall_boxes(layout, thickness)]
    return unary_union(boxes) if boxes else Polygon()


def house_bounds(layout: HouseLayout) -> tuple[float, float, float, float]:
    """(xmin, ymin, xmax, ymax) of all regions and obstacles, metres."""
    geoms = [Polygon(r.polygon) for r in layout.regions]
    geoms += [Polygon(o.polygon) for o in layout.obstacles]
    if not geoms:
        raise ValueError("a house needs at least one region")
    return tuple(float(v) for v in unary_union(geoms).bounds)  # type: ignore[return-value]


def house_geometry(layout: HouseLayout, resolution: float, margin: float = 0.5) -> GridGeometry:
    """The grid that covers the house plus ``margin`` metres, origin snapped to the resolution."""
    if resolution <= 0:
        raise ValueError(f"resolution must be > 0, got {resolution}")
    xmin, ymin, xmax, ymax = house_bounds(layout)
    ox = math.floor((xmin - margin) / resolution + 1e-9) * resolution
    oy = math.floor((ymin - margin) / resolution + 1e-9) * resolution
    width = math.ceil((xmax + margin - ox) / resolution - 1e-9)
    height = math.ceil((ymax + margin - oy) / resolution - 1e-9)
    return GridGeometry(
        resolution=resolution,
        width=int(width),
        height=int(height),
        origin=(round(ox, 9) + 0.0, round(oy, 9) + 0.0),
    )


def segment_distance(xy: np.ndarray, segs: np.ndarray) -> float:
    """Distance from the point ``xy`` to the nearest segment row ``[x0, y0, x1, y1]``."""
    if len(segs) == 0:
        return math.inf
    a, b = segs[:, :2], segs[:, 2:]
    e = b - a
    t = np.clip(np.sum((xy - a) * e, axis=1) / np.maximum(np.sum(e * e, axis=1), 1e-12), 0, 1)
    return float(np.min(np.hypot(*(a + t[:, None] * e - xy).T)))


def _mark_lines(mask: np.ndarray, geometry: GridGeometry, segments: Iterable[Segment]) -> None:
    """Mark every cell a segment passes through (its end points excluded), in place.

    Guarantees walls at least one cell thick at any resolution, so a coarse map never leaks
    through a wall thinner than a cell.
    """
    step = geometry.resolution / 4.0
    for a, b in segments:
        length = math.dist(a, b)
        n = max(2, math.ceil(length / step) + 1)
        t = np.linspace(0.0, 1.0, n)
        t = np.clip(t, 1e-6 / max(length, 1e-9), 1.0 - 1e-6 / max(length, 1e-9))
        xy = np.stack([a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])], axis=-1)
        rows, cols = geometry.world_to_cell(xy)
        ok = geometry.in_bounds(rows, cols)
        mask[rows[ok], cols[ok]] = True


def wall_mask(
    layout: HouseLayout, geometry: GridGeometry, thickness: float = 0.0
) -> NDArray[np.bool_]:
    """The cells of a grid with ``geometry`` that the house's walls cover.

    The footprint of the walls at ``thickness`` (none when 0), plus every cell a wall segment
    passes through, so the walls are closed at any resolution and door openings stay open.
    """
    mask = np.zeros(geometry.shape, dtype=bool)
    if thickness > 0:
        walls = wall_footprint(layout, thickness)
        if not walls.is_empty:
            shapely.prepare(walls)
            centres = geometry.cell_to_world(*np.indices(geometry.shape))
            mask |= shapely.intersects_xy(walls, centres[..., 0], centres[..., 1])
    _mark_lines(mask, geometry, wall_segments(layout))
    return mask


def house_probabilities(
    layout: HouseLayout,
    resolution: float,
    wall_thickness: float = 0.1,
    margin: float = 0.5,
    include_obstacles: bool = True,
) -> tuple[np.ndarray, GridGeometry]:
    """The probabilities ``p(m)`` of :func:`rasterize_house` and their grid, as plain arrays."""
    geometry = house_geometry(layout, resolution, margin)
    rows, cols = np.indices(geometry.shape)
    centres = geometry.cell_to_world(rows, cols)
    x, y = centres[..., 0], centres[..., 1]

    inside = unary_union([Polygon(r.polygon) for r in layout.regions])
    shapely.prepare(inside)
    free = shapely.intersects_xy(inside, x, y)

    occupied = wall_mask(layout, geometry, wall_thickness)
    if include_obstacles and layout.obstacles:
        obstacles = unary_union([Polygon(o.polygon) for o in layout.obstacles])
        shapely.prepare(obstacles)
        occupied |= shapely.intersects_xy(obstacles, x, y)

    p = np.full(geometry.shape, 0.5)
    p[free] = 0.0
    p[occupied] = 1.0
    return p, geometry


def rasterize_house(
    layout: HouseLayout,
    resolution: float,
    wall_thickness: float = 0.1,
    margin: float = 0.5,
    include_obstacles: bool = True,
) -> OccupancyGrid:
    """The static map of a house: free inside the regions, occupied walls/obstacles, else unknown.

    A cell is decided by its centre: inside any region (boundary included) → free (p=0); in the
    :func:`wall_footprint` of ``wall_thickness`` or inside an obstacle (if ``include_obstacles``)
    → occupied (p=1), and every cell a wall segment passes through is occupied too, so walls are
    closed at any resolution; elsewhere unknown (p=0.5). The grid covers the house's bounds plus
    ``margin`` metres, with its origin a multiple of ``resolution``.
    """
    p, geometry = house_probabilities(layout, resolution, wall_thickness, margin, include_obstacles)
    return OccupancyGrid.from_probabilities(p, resolution, origin=geometry.origin)


__all__ = [
    "WallBox",
    "door_cutters",
    "house_bounds",
    "house_geometry",
    "house_probabilities",
    "rasterize_house",
    "wall_boxes",
    "wall_footprint",
    "wall_segments",
]
