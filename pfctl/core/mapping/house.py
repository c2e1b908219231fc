"""The house as plain values: named region polygons, doors between them, furniture obstacles.

These are what the mission's ``map`` section becomes once validated; core code receives them and
never reads YAML (DESIGN.md). Coordinates are metres in the map frame.
"""

from __future__ import annotations

from dataclasses import dataclass, field

Point = tuple[float, float]


@dataclass(frozen=True)
class Region:
    """A named polygon of the region map (§II-B): a room, a hall, a corridor."""

    name: str
    polygon: tuple[Point, ...]


@dataclass(frozen=True)
class Door:
    """An opening in the wall shared by two regions: the segment of the boundary that is open."""

    between: tuple[str, str]
    segment: tuple[Point, Point]


@dataclass(frozen=True)
class Obstacle:
    """A piece of furniture or other static obstacle: a polygon, with its height in metres."""

    polygon: tuple[Point, ...]
    height: float = 0.8
    name: str = ""


@dataclass(frozen=True)
class HouseLayout:
    """Everything static in the map: regions, doors, obstacles."""

    regions: tuple[Region, ...]
    doors: tuple[Door, ...] = ()
    obstacles: tuple[Obstacle, ...] = field(default=())

    def region(self, name: str) -> Region:
        """The region called ``name``; KeyError if there is none."""
        for r in self.regions:
            if r.name == name:
                return r
        raise KeyError(name)
