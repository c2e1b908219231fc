"""Floor plans of generated homes: rooms as polygons, doors and wide openings on shared walls.

A plan is one of :data:`LAYOUTS`, drawn from a random generator:

- ``corridor``: a corridor across the home, rooms south and north of it, each with a door into it;
  two neighbouring rooms may be joined by a wide opening (living room and kitchen);
- ``open_plan``: a living room and a kitchen joined by a wide opening along the south side (the
  living room L-shaped around the kitchen when the home is deep enough), the other rooms north of
  them, each with a door into the living room or the kitchen;
- ``hall``: a hall in the middle, rooms all around it (west, east, south, north), each with a door;
- ``l_shaped``: the ``corridor`` layout on an L-shaped outline (a corner of the rectangle cut
  away).

Every coordinate is a multiple of :data:`GRID` metres, so a door lies exactly on the wall its two
regions share; rooms are at least :data:`MIN_ROOM` metres wide both ways. The region graph (a node
per region, an edge per door) is connected by construction.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np
import shapely

from pfctl.core.mapping.house import Door, Point, Region

__all__ = [
    "CIRCULATION",
    "DOOR_WIDTH",
    "GRID",
    "LAYOUTS",
    "MIN_ROOM",
    "OPENING_WIDTH",
    "FloorPlan",
    "max_rooms",
    "min_rooms",
    "plan_home",
]

#: The layout kinds, in the order the seed picks from.
LAYOUTS = ("corridor", "open_plan", "hall", "l_shaped")
#: Coordinates are multiples of this, metres.
GRID = 0.05
#: The narrowest a room may be, metres (either way).
MIN_ROOM = 2.2
#: The narrowest a room is drawn, metres: :data:`MIN_ROOM` plus the rounding to :data:`GRID`.
_ROOM = MIN_ROOM + 0.1
#: Width of a door, metres (lowest, highest).
DOOR_WIDTH = (0.8, 1.4)
#: Width of a wide opening between two open-plan regions, metres.
OPENING_WIDTH = (1.8, 3.0)
#: Corridor width, metres.
_CORRIDOR = (1.2, 1.6)
#: Hall width and depth, metres.
_HALL = (2.0, 3.0)
#: Distance kept between a door and the corner of its wall, metres.
_DOOR_MARGIN = 0.25
#: Names of the regions people pass through rather than stay in (not counted as rooms).
CIRCULATION = ("corridor", "hall")
#: Room names after the living room and the kitchen, in the order they are given.
_ROOM_NAMES = (
    "bedroom",
    "study",
    "bedroom_2",
    "laundry",
    "office",
    "guest_room",
    "dining_room",
    "storage",
    "playroom",
    "bedroom_3",
)


@dataclass(frozen=True)
class FloorPlan:
    """Regions and doors of a generated home, and how it was laid out."""

    kind: str
    """One of :data:`LAYOUTS`."""
    width: float
    height: float
    regions: tuple[Region, ...]
    doors: tuple[Door, ...]

    @property
    def rooms(self) -> tuple[Region, ...]:
        """The regions that are rooms (not a corridor or hall)."""
        return tuple(r for r in self.regions if r.name not in CIRCULATION)

    def describe(self) -> str:
        """``corridor layout, 14.2 × 10.3 m: 6 rooms (kitchen, ...) off a corridor, 7 doors``."""
        wide = sum(1 for d in self.doors if _length(d) > DOOR_WIDTH[1] + 1e-6)
        names = ", ".join(r.name for r in self.rooms)
        others = [r.name for r in self.regions if r.name in CIRCULATION]
        via = f" and a {others[0]}" if others else ""
        return (
            f"{self.kind} layout, {self.width:g} x {self.height:g} m: {len(self.rooms)} rooms "
            f"({names}){via}; {len(self.doors) - wide} doors, {wide} wide openings"
        )


def _length(door: Door) -> float:
    return math.dist(*door.segment)


def _q(value: float) -> float:
    """``value`` on the :data:`GRID`, as a clean decimal."""
    return round(round(value / GRID) * GRID, 2) + 0.0


def _rect(x0: float, y0: float, x1: float, y1: float) -> tuple[Point, ...]:
    return ((x0, y0), (x1, y0), (x1, y1), (x0, y1))


def _fit(length: float) -> int:
    """How many rooms fit side by side along ``length`` metres."""
    return max(int(length / _ROOM + 1e-9), 0)


def _split(start: float, end: float, n: int, rng: np.random.Generator) -> list[float]:
    """``n + 1`` cut positions from ``start`` to ``end``, each part at least :data:`_ROOM` wide
    (the rest shared at random)."""
    spare = end - start - n * _ROOM
    if n < 1 or spare < -1e-9:
        raise ValueError(f"{n} rooms do not fit in {end - start:g} m")
    shares = rng.dirichlet(np.full(n, 2.0)) * max(spare, 0.0)
    cuts = [start]
    for share in shares[:-1]:
        cuts.append(cuts[-1] + _ROOM + float(share))
    cuts = [_q(c) for c in cuts] + [end]
    for a, b in itertools.pairwise(cuts):
        if b - a < MIN_ROOM - 1e-9:
            raise ValueError("rounding made a room too narrow")
    return cuts


def _between(low: float, high: float, rng: np.random.Generator) -> float:
    return _q(float(rng.uniform(low, high))) if high > low else _q(low)


# ---------------------------------------------------------------------------------------------
# capacities


def min_rooms(kind: str) -> int:
    """The fewest rooms of a ``kind`` of plan whose target can walk through two doors."""
    return 3 if kind == "open_plan" else 2


def max_rooms(kind: str, width: float, height: float) -> int:
    """The most rooms a ``kind`` of plan fits in ``width`` × ``height`` metres (0: none)."""
    if kind in ("corridor", "l_shaped"):
        two_sides = height >= 2 * _ROOM + _CORRIDOR[0]
        if kind == "l_shaped":
            if not two_sides or width < 2 * _ROOM:
                return 0
            ne = height >= 2 * _ROOM + _CORRIDOR[0] + 1.0
            return _fit(width) + _fit(width - _ROOM) + int(ne)
        if height < _ROOM + _CORRIDOR[0]:
            return 0
        return _fit(width) * (2 if two_sides else 1)
    if kind == "open_plan":
        if height < 2 * _ROOM + 1.2 or width < 2 * _ROOM:
            return 0
        return 2 + _fit(width)
    if kind == "hall":
        if width < 2 * _ROOM + _HALL[0] or height < _HALL[0]:
            return 0
        columns = 2 * (2 if height >= 2 * _ROOM and height >= 2 * 1.3 else 1)
        rows = 2 if height >= 2 * _ROOM + _HALL[0] else (1 if height >= _ROOM + _HALL[0] else 0)
        return columns + rows * _fit(width - 2 * _ROOM)
    raise ValueError(f"unknown layout {kind!r}; expected one of {', '.join(LAYOUTS)}")


# ---------------------------------------------------------------------------------------------
# layouts: each returns the region polygons (rooms unnamed, as "r<i>") and the pairs to join


_Joins = list[tuple[str, str, str]]
"""(region, region, "door" | "opening")."""


def _corridor(
    width: float, height: float, rooms: int, rng: np.random.Generator, cut: bool
) -> tuple[dict[str, tuple[Point, ...]], _Joins]:
    """Rooms south and north of a corridor across the home; with ``cut``, the north-east corner
    of the rectangle is cut away (an L-shaped outline), a room or none left below the cut."""
    two_sides = height >= 2 * _ROOM + _CORRIDOR[0]
    cw = _between(_CORRIDOR[0], min(_CORRIDOR[1], height - 2 * _ROOM), rng) if two_sides else 1.2
    if cut and not two_sides:
        raise ValueError("an L-shaped home needs rooms on both sides of its corridor")
    south_depth = _between(_ROOM, height - cw - _ROOM, rng) if two_sides else _q(height - cw)
    y0, y1 = south_depth, _q(south_depth + cw)
    depth = height - y1
    ne_possible = cut and depth >= _ROOM + 1.0
    north_cap = 0
    if two_sides:
        north_cap = _fit(width - _ROOM) + int(ne_possible) if cut else _fit(width)
    low = max(1, rooms - north_cap)
    high = min(_fit(width), rooms - 1 if cut else rooms)
    if low > high:
        raise ValueError("the rooms do not fit both sides of the corridor")
    n_south = int(rng.integers(low, high + 1))
    n_north = rooms - n_south
    polygons: dict[str, tuple[Point, ...]] = {}
    south = _split(0.0, width, n_south, rng)
    for i in range(n_south):
        polygons[f"s{i}"] = _rect(south[i], 0.0, south[i + 1], y0)
    north_width = width
    n_nw = n_north
    if cut:
        ne = ne_possible and (
            n_north > _fit(width - _ROOM) or (n_north >= 2 and rng.random() < 0.5)
        )
        n_nw = n_north - int(ne)
        widest = width - max(n_nw * _ROOM, _ROOM)
        a = _between(min(max(_ROOM, 0.3 * width), widest), min(0.5 * width, widest), rng)
        north_width = _q(width - a)
        if ne:
            b = _between(1.0, min(depth - _ROOM, 0.5 * height), rng)
            polygons["ne"] = _rect(north_width, y1, width, _q(height - b))
    if n_nw:
        north = _split(0.0, north_width, n_nw, rng)
        for i in range(n_nw):
            polygons[f"n{i}"] = _rect(north[i], y1, north[i + 1], height)
    polygons["corridor"] = _rect(0.0, y0, width, y1)
    joins: _Joins = [(name, "corridor", "door") for name in polygons if name != "corridor"]
    if n_south >= 2 and rng.random() < 0.7:
        k = int(rng.integers(n_south - 1))
        joins.append((f"s{k}", f"s{k + 1}", "opening"))
    return polygons, joins


def _open_plan(
    width: float, height: float, rooms: int, rng: np.random.Generator
) -> tuple[dict[str, tuple[Point, ...]], _Joins]:
    """A living room and a kitchen joined by a wide opening, the other rooms north of them."""
    n_north = rooms - 2
    if n_north < 1 or n_north > _fit(width):
        raise ValueError("the rooms do not fit north of the living room")
    ds = _between(max(_ROOM + 1.2, 0.45 * height), min(height - _ROOM, 0.6 * height), rng)
    xk = _between(max(_ROOM, 0.45 * width), width - _ROOM, rng)
    polygons: dict[str, tuple[Point, ...]] = {}
    if ds - _ROOM >= 1.2 and rng.random() < 0.6:  # the living room wraps around the kitchen
        yk = _between(_ROOM, ds - 1.2, rng)
        polygons["living"] = ((0.0, 0.0), (xk, 0.0), (xk, yk), (width, yk), (width, ds), (0.0, ds))
        polygons["kitchen"] = _rect(xk, 0.0, width, yk)
    else:
        polygons["living"] = _rect(0.0, 0.0, xk, ds)
        polygons["kitchen"] = _rect(xk, 0.0, width, ds)
    joins: _Joins = [("living", "kitchen", "opening")]
    north = _split(0.0, width, n_north, rng)
    south_polys = {k: shapely.Polygon(v) for k, v in polygons.items()}
    for i in range(n_north):
        name = f"n{i}"
        polygons[name] = _rect(north[i], ds, north[i + 1], height)
        room = shapely.Polygon(polygons[name])
        shared = {k: room.boundary.intersection(p.boundary).length for k, p in south_polys.items()}
        joins.append((name, max(shared, key=lambda k: (shared[k], k == "living")), "door"))
    if n_north >= 2 and rng.random() < 0.4:  # an en-suite door between two north rooms
        k = int(rng.integers(n_north - 1))
        joins.append((f"n{k}", f"n{k + 1}", "door"))
    return polygons, joins


def _hall(
    width: float, height: float, rooms: int, rng: np.random.Generator
) -> tuple[dict[str, tuple[Point, ...]], _Joins]:
    """A hall in the middle, rooms west and east of it (one or two each) and rows south and
    north of it."""
    for _ in range(200):
        hw = _between(_HALL[0], min(_HALL[1] + 2.0, width - 2 * _ROOM), rng)
        xa = _between(_ROOM, width - _ROOM - hw, rng)
        xb = _q(xa + hw)
        rows_room = height - _HALL[0]
        ya = _between(_ROOM, rows_room - _ROOM, rng) if rows_room >= 2 * _ROOM else 0.0
        if rows_room >= _ROOM and ya == 0.0 and rng.random() < 0.5:
            ya = _between(_ROOM, rows_room, rng)
        yb = height
        if height - ya - _HALL[0] >= _ROOM:
            yb = _between(ya + _HALL[0], height - _ROOM, rng)
        stack = height >= 2 * _ROOM and (yb - ya) >= 2.6
        fit_row = _fit(xb - xa)
        n_south_cap = fit_row if ya > 0 else 0
        n_north_cap = fit_row if yb < height else 0
        caps = [2 if stack else 1, 2 if stack else 1, n_south_cap, n_north_cap]
        if sum(caps) < rooms:
            continue
        counts = [1, 1, 0, 0] if rooms >= 2 else [1, 0, 0, 0]
        while sum(counts) < rooms:
            options = [i for i in range(4) if counts[i] < caps[i]]
            counts[int(rng.choice(options))] += 1
        polygons: dict[str, tuple[Point, ...]] = {"hall": _rect(xa, ya, xb, yb)}
        for side, (x0, x1) in enumerate(((0.0, xa), (xb, width))):
            n = counts[side]
            if n == 0:
                continue
            cuts = [0.0, height]
            if n == 2:
                lo, hi = max(_ROOM, ya + 1.3), min(height - _ROOM, yb - 1.3)
                if lo > hi:
                    break
                cuts = [0.0, _between(lo, hi, rng), height]
            for i in range(n):
                polygons[f"c{side}{i}"] = _rect(x0, cuts[i], x1, cuts[i + 1])
        else:
            for row, (y0, y1) in ((2, (0.0, ya)), (3, (yb, height))):
                if counts[row]:
                    cuts = _split(xa, xb, counts[row], rng)
                    for i in range(counts[row]):
                        polygons[f"r{row}{i}"] = _rect(cuts[i], y0, cuts[i + 1], y1)
            joins: _Joins = [(name, "hall", "door") for name in polygons if name != "hall"]
            return polygons, joins
    raise ValueError("the rooms do not fit around a hall")


# ---------------------------------------------------------------------------------------------
# doors and names


def _shared_wall(a: shapely.Polygon, b: shapely.Polygon) -> shapely.LineString | None:
    """The longest straight piece of the wall ``a`` and ``b`` share, or None."""
    common = a.boundary.intersection(b.boundary)
    parts = [g for g in getattr(common, "geoms", [common]) if g.geom_type == "LineString"]
    merged = shapely.line_merge(shapely.MultiLineString(parts)) if parts else None
    pieces = [g for g in getattr(merged, "geoms", [merged])] if merged is not None else []
    straight: list[shapely.LineString] = []
    for piece in pieces:
        coords = list(piece.coords)
        straight += [shapely.LineString(s) for s in itertools.pairwise(coords)]
    return max(straight, key=lambda s: s.length, default=None)


def _door(
    a: shapely.Polygon, b: shapely.Polygon, kind: str, rng: np.random.Generator
) -> tuple[Point, Point]:
    wall = _shared_wall(a, b)
    if wall is None:
        raise ValueError("two regions to join share no wall")
    usable = wall.length - 2 * _DOOR_MARGIN
    low, high = OPENING_WIDTH if kind == "opening" else DOOR_WIDTH
    if usable < low:
        if kind == "opening" and usable >= DOOR_WIDTH[0]:
            low, high = DOOR_WIDTH
        else:
            raise ValueError("a shared wall is too short for a door")
    w = _q(float(rng.uniform(low, min(high, usable))))
    w = min(max(w, low), usable)
    start = _q(_DOOR_MARGIN + float(rng.uniform(0.0, usable - w)))
    (x0, y0), (x1, y1) = wall.coords
    if (x1, y1) < (x0, y0):
        (x0, y0), (x1, y1) = (x1, y1), (x0, y0)
    ux, uy = (x1 - x0) / wall.length, (y1 - y0) / wall.length
    p = (_q(x0 + ux * start), _q(y0 + uy * start))
    q = (_q(x0 + ux * (start + w)), _q(y0 + uy * (start + w)))
    return p, q


def _names(polygons: dict[str, tuple[Point, ...]], joins: _Joins, kind: str) -> dict[str, str]:
    """Room names by size and role: the living room the largest (or the open plan's), the kitchen
    the one it opens onto (else the next largest), the bathroom the smallest, then bedrooms..."""
    area = {k: shapely.Polygon(v).area for k, v in polygons.items() if k not in CIRCULATION}
    order = sorted(area, key=lambda k: (-area[k], k))
    names: dict[str, str] = {k: k for k in polygons if k in CIRCULATION}
    if kind == "open_plan":
        names["living"], names["kitchen"] = "living_room", "kitchen"
    else:
        living = order[0]
        names[living] = "living_room"
        opens = [
            b if a == living else a for a, b, how in joins if how == "opening" and living in (a, b)
        ]
        kitchen = opens[0] if opens else (order[1] if len(order) > 1 else None)
        if kitchen is not None:
            names[kitchen] = "kitchen"
    rest = [k for k in order if k not in names]
    if len(area) >= 4 and rest:
        names[rest.pop()] = "bathroom"
    for i, k in enumerate(rest):
        names[k] = _ROOM_NAMES[i] if i < len(_ROOM_NAMES) else f"room_{i + 1}"
    return names


def plan_home(
    kind: str, width: float, height: float, rooms: int, rng: np.random.Generator
) -> FloorPlan:
    """A random plan of ``kind`` with ``rooms`` rooms in ``width`` × ``height`` metres.

    Raises:
        ValueError: the rooms do not fit (see :func:`max_rooms`), or this draw failed (callers
            draw again).
    """
    if not min_rooms(kind) <= rooms <= max_rooms(kind, width, height):
        raise ValueError(
            f"a {kind} plan of {width:g} x {height:g} m holds {min_rooms(kind)} to "
            f"{max_rooms(kind, width, height)} rooms, not {rooms}"
        )
    width, height = _q(width), _q(height)
    if kind == "corridor":
        polygons, joins = _corridor(width, height, rooms, rng, cut=False)
    elif kind == "l_shaped":
        polygons, joins = _corridor(width, height, rooms, rng, cut=True)
    elif kind == "open_plan":
        polygons, joins = _open_plan(width, height, rooms, rng)
    else:
        polygons, joins = _hall(width, height, rooms, rng)
    flip_x, flip_y = bool(rng.random() < 0.5), bool(rng.random() < 0.5)

    def place(p: Point) -> Point:
        x, y = p
        return (_q(width - x) if flip_x else x, _q(height - y) if flip_y else y)

    def oriented(poly: tuple[Point, ...]) -> tuple[Point, ...]:
        pts = tuple(place(p) for p in poly)
        return pts[::-1] if flip_x != flip_y else pts  # counter-clockwise, as drawn

    polygons = {k: oriented(v) for k, v in polygons.items()}
    names = _names(polygons, joins, kind)
    shapes = {k: shapely.Polygon(v) for k, v in polygons.items()}
    doors = tuple(
        Door(between=(names[a], names[b]), segment=_door(shapes[a], shapes[b], how, rng))
        for a, b, how in joins
    )
    regions = sorted(polygons, key=lambda k: (names[k] in CIRCULATION, _room_rank(names[k])))
    return FloorPlan(
        kind=kind,
        width=width,
        height=height,
        regions=tuple(Region(names[k], polygons[k]) for k in regions),
        doors=doors,
    )


def _room_rank(name: str) -> tuple[int, str]:
    fixed = ("living_room", "kitchen", *_ROOM_NAMES, "bathroom")
    return (fixed.index(name), name) if name in fixed else (len(fixed), name)
