"""Furniture of generated homes: shelves, wardrobes, sofas, beds, tables — placed so that it
occludes but never blocks.

Each room gets the pieces of its kind (:data:`CATALOG`): against a wall (long side along it),
end-on to a wall (a bed, a bookshelf standing out into the room as the shipped house's does), or
free-standing (a table). A candidate place is kept only if the piece stays inside its room, clear
of every door's approach (:data:`DOOR_CLEARANCE`), :data:`GAP` from the other pieces, and if the
home stays *open* (:func:`pfctl.core.homes.reach.open_issue`) for the robot's and a person's
radius on the planner grid of the static map — so every room stays reachable and no one is sent
into a pocket.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np
import shapely

from pfctl.core.homes.reach import open_issue, region_masks
from pfctl.core.mapping.grid import OccupancyGrid
from pfctl.core.mapping.house import HouseLayout, Obstacle, Point, Region
from pfctl.core.mapping.planning import GridPlanner
from pfctl.core.mapping.walls import house_probabilities

__all__ = ["CATALOG", "DOOR_CLEARANCE", "GAP", "Piece", "furnish"]

#: No furniture within this distance (m) of a door's segment (on either side).
DOOR_CLEARANCE = 0.8
#: Distance (m) kept between two pieces, so a person or the robot can pass between them.
GAP = 0.65
#: Distance (m) of a piece from the wall it stands against (the wall is centred on the boundary).
_WALL_GAP = 0.08
#: Candidate places tried per piece.
_TRIES = 25


@dataclass(frozen=True)
class Piece:
    """A kind of furniture: name, size ranges (m), height range (m), how it stands."""

    name: str
    length: tuple[float, float]
    """Along the wall (``wall``), out from the wall (``end_on``), or the longer side (``free``)."""
    depth: tuple[float, float]
    height: tuple[float, float]
    placement: str
    """``wall``, ``end_on`` or ``free``."""
    chance: float = 1.0
    """Probability the room gets this piece."""


_SHELF = Piece("bookshelf", (1.0, 1.8), (0.35, 0.45), (1.6, 2.0), "wall", 0.7)
_DIVIDER = Piece("bookshelf", (1.2, 1.8), (0.3, 0.4), (1.7, 2.0), "end_on", 0.6)
_WARDROBE = Piece("wardrobe", (1.0, 2.0), (0.55, 0.65), (1.8, 2.0), "wall")
_TABLE = Piece("table", (1.2, 1.8), (0.8, 1.0), (0.72, 0.76), "free", 0.7)

#: The pieces of each kind of room (a name's first word), in the order they are placed.
CATALOG: dict[str, tuple[Piece, ...]] = {
    "living": (
        Piece("sofa", (1.8, 2.4), (0.8, 0.95), (0.75, 0.85), "wall"),
        _SHELF,
        _DIVIDER,
        _TABLE,
    ),
    "kitchen": (
        Piece("counter", (1.8, 3.0), (0.6, 0.65), (0.9, 0.92), "wall"),
        Piece("cupboard", (0.6, 1.2), (0.6, 0.65), (1.9, 2.1), "wall", 0.7),
        Piece("table", (1.0, 1.4), (0.8, 0.9), (0.72, 0.76), "free", 0.6),
    ),
    "bedroom": (
        Piece("bed", (2.0, 2.1), (1.4, 1.8), (0.45, 0.55), "end_on"),
        _WARDROBE,
        _SHELF,
    ),
    "guest": (Piece("bed", (2.0, 2.1), (0.9, 1.4), (0.45, 0.55), "end_on"), _WARDROBE),
    "study": (Piece("desk", (1.2, 1.6), (0.65, 0.75), (0.74, 0.76), "wall"), _DIVIDER, _SHELF),
    "office": (Piece("desk", (1.2, 1.6), (0.65, 0.75), (0.74, 0.76), "wall"), _DIVIDER, _SHELF),
    "bathroom": (
        Piece("bathtub", (1.6, 1.7), (0.7, 0.75), (0.55, 0.6), "wall", 0.7),
        Piece("cabinet", (0.6, 1.0), (0.4, 0.45), (1.6, 1.9), "wall"),
    ),
    "laundry": (
        Piece("washer", (0.6, 0.65), (0.6, 0.65), (0.85, 0.9), "wall"),
        Piece("shelf", (0.8, 1.4), (0.4, 0.5), (1.7, 2.0), "wall"),
    ),
    "dining": (_TABLE, Piece("sideboard", (1.2, 1.8), (0.45, 0.5), (0.85, 0.9), "wall"), _SHELF),
    "storage": (Piece("shelf", (1.0, 2.0), (0.4, 0.6), (1.8, 2.0), "wall"), _SHELF),
    "playroom": (Piece("toy_shelf", (1.0, 1.6), (0.35, 0.45), (1.2, 1.6), "wall"), _TABLE),
    "hall": (Piece("shoe_cabinet", (0.8, 1.4), (0.35, 0.4), (1.1, 1.8), "wall", 0.6),),
    "room": (_SHELF, _TABLE),
}


def _kind(name: str) -> str:
    head = name.split("_")[0]
    return head if head in CATALOG else ("room" if head != "corridor" else "")


class _Grid:
    """The static map's probabilities with furniture painted in; planners for the two radii."""

    def __init__(
        self,
        layout: HouseLayout,
        resolution: float,
        wall_thickness: float,
        radii: tuple[float, ...],
    ) -> None:
        self.layout = layout
        self.p, self.geometry = house_probabilities(
            layout, resolution, wall_thickness, include_obstacles=False
        )
        self.resolution = resolution
        self.radii = radii
        self.centres = self.geometry.cell_to_world(*np.indices(self.geometry.shape))
        self.masks = region_masks(layout, self.geometry)

    def painted(self, polygon: shapely.Polygon) -> np.ndarray:
        """``p`` with the cells whose centres ``polygon`` covers occupied (as rasterised)."""
        p = self.p.copy()
        x0, y0, x1, y1 = polygon.bounds
        (r0, r1), (c0, c1) = (
            sorted(int(v) for v in a)
            for a in self.geometry.world_to_cell(np.array([[x0, y0], [x1, y1]]))
        )
        rs = slice(max(r0 - 1, 0), r1 + 2)
        cs = slice(max(c0 - 1, 0), c1 + 2)
        window = self.centres[rs, cs]
        hit = shapely.intersects_xy(polygon, window[..., 0], window[..., 1])
        p[rs, cs][hit] = 1.0
        return p

    def open_with(self, polygon: shapely.Polygon, layout: HouseLayout) -> np.ndarray | None:
        """The painted probabilities if the home stays open with ``polygon`` added, else None."""
        p = self.painted(polygon)
        grid = OccupancyGrid.from_probabilities(p, self.resolution, origin=self.geometry.origin)
        for radius in self.radii:
            if open_issue(layout, GridPlanner(grid, radius), self.masks) is not None:
                return None
        return p


def _wall_place(
    room: shapely.Polygon, along: float, out: float, rng: np.random.Generator
) -> shapely.Polygon | None:
    """A rectangle ``along`` × ``out`` against a random edge of ``room`` (inside it)."""
    coords = list(shapely.geometry.polygon.orient(room, 1.0).exterior.coords)
    edges = [(a, b) for a, b in itertools.pairwise(coords)]
    edges = [(a, b) for a, b in edges if math.dist(a, b) >= along + 2 * _WALL_GAP]
    if not edges:
        return None
    (ax, ay), (bx, by) = edges[int(rng.integers(len(edges)))]
    length = math.dist((ax, ay), (bx, by))
    ux, uy = (bx - ax) / length, (by - ay) / length
    nx, ny = -uy, ux  # inward: the room is left of a counter-clockwise edge
    s = float(rng.uniform(_WALL_GAP, length - along - _WALL_GAP))
    x0, y0 = ax + ux * s + nx * _WALL_GAP, ay + uy * s + ny * _WALL_GAP
    return shapely.Polygon(
        [
            (x0, y0),
            (x0 + ux * along, y0 + uy * along),
            (x0 + ux * along + nx * out, y0 + uy * along + ny * out),
            (x0 + nx * out, y0 + ny * out),
        ]
    )


def _free_place(
    room: shapely.Polygon, length: float, depth: float, rng: np.random.Generator
) -> shapely.Polygon | None:
    x0, y0, x1, y1 = room.bounds
    w, h = (length, depth) if rng.random() < 0.5 else (depth, length)
    margin = GAP + _WALL_GAP
    if x1 - x0 < w + 2 * margin or y1 - y0 < h + 2 * margin:
        return None
    cx = float(rng.uniform(x0 + margin + w / 2, x1 - margin - w / 2))
    cy = float(rng.uniform(y0 + margin + h / 2, y1 - margin - h / 2))
    return shapely.box(cx - w / 2, cy - h / 2, cx + w / 2, cy + h / 2)


def _rounded(polygon: shapely.Polygon) -> tuple[Point, ...]:
    return tuple((round(x, 2) + 0.0, round(y, 2) + 0.0) for x, y in polygon.exterior.coords[:-1])


def furnish(
    layout: HouseLayout,
    rng: np.random.Generator,
    *,
    resolution: float,
    wall_thickness: float,
    radii: tuple[float, ...],
) -> tuple[Obstacle, ...]:
    """Furniture for every room of ``layout`` (see the module docstring); ``radii``: the discs
    (robot, person) that must still reach everywhere."""
    grid = _Grid(layout, resolution, wall_thickness, radii)
    keep_out = shapely.union_all(
        [shapely.LineString(d.segment).buffer(DOOR_CLEARANCE) for d in layout.doors]
    )
    placed: list[Obstacle] = []
    shapes: list[shapely.Polygon] = []
    counts: dict[str, int] = {}
    for region in layout.regions:
        room = shapely.Polygon(region.polygon)
        inner = room.buffer(-_WALL_GAP / 2)
        for piece in CATALOG.get(_kind(region.name), ()):
            if rng.random() >= piece.chance:
                continue
            polygon = _place(piece, region, room, inner, keep_out, shapes, grid, layout, rng)
            if polygon is None:
                continue
            shapes.append(polygon)
            counts[piece.name] = counts.get(piece.name, 0) + 1
            height = round(float(rng.uniform(*piece.height)), 2)
            name = f"{region.name}_{piece.name}"
            if any(o.name == name for o in placed):
                name = f"{name}_{counts[piece.name]}"
            placed.append(Obstacle(polygon=_rounded(polygon), height=height, name=name))
    return tuple(placed)


def _place(
    piece: Piece,
    region: Region,
    room: shapely.Polygon,
    inner: shapely.Polygon,
    keep_out: shapely.Geometry,
    shapes: list[shapely.Polygon],
    grid: _Grid,
    layout: HouseLayout,
    rng: np.random.Generator,
) -> shapely.Polygon | None:
    """A place for ``piece`` in ``region`` that passes every check, or None after the tries."""
    del region
    for _ in range(_TRIES):
        length = round(float(rng.uniform(*piece.length)), 2)
        depth = round(float(rng.uniform(*piece.depth)), 2)
        if piece.placement == "free":
            polygon = _free_place(room, length, depth, rng)
        elif piece.placement == "end_on":
            polygon = _wall_place(room, depth, length, rng)
        else:
            polygon = _wall_place(room, length, depth, rng)
        if polygon is None:
            continue
        polygon = shapely.Polygon(_rounded(polygon))
        if not inner.contains(polygon) or polygon.intersects(keep_out):
            continue
        if any(polygon.distance(other) < GAP for other in shapes):
            continue
        p = grid.open_with(polygon, layout)
        if p is None:
            continue
        grid.p = p
        return polygon
    return None
