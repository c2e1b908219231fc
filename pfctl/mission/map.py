"""The ``map`` section: grid resolution, walls, the sensor model of Eq. 1, regions, doors and
obstacles (§II-B), with the checks of the house's geometry: polygons are simple, regions do not
overlap, and each door lies on the wall the two regions it joins share."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated

import shapely
from pydantic import Field, ValidationInfo, field_validator, model_validator

from pfctl.core.mapping.grid import InverseSensorModel
from pfctl.mission.errors import field_error, raise_first
from pfctl.mission.params import CoreSection, FromCore
from pfctl.mission.types import (
    TOLERANCE,
    MissionModel,
    Name,
    Point,
    Polygon,
    Positive,
    existing_file,
    fmt_point,
)


class SensorModel(CoreSection, core=InverseSensorModel):
    """Inverse sensor model of Eq. 1: p(occupied | what the beam did), and the clamping bounds."""

    p_hit: FromCore
    p_miss: FromCore
    p_min: FromCore
    p_max: FromCore

    @model_validator(mode="after")
    def _bounds_ordered(self) -> SensorModel:
        if self.p_min >= self.p_max:
            raise field_error(
                ("p_max",), f"expected p_max > p_min ({self.p_min:g}), got {self.p_max:g}"
            )
        return self


class RegionSpec(MissionModel):
    """A named polygon of the region map (§II-B)."""

    name: Name
    polygon: Polygon


class DoorSpec(MissionModel):
    """An opening in the wall two regions share: ``segment`` lies on their common boundary."""

    between: tuple[Name, Name]
    """The names of the two regions the door joins."""
    segment: tuple[Point, Point]
    """The opening: two [x, y] end points on the shared wall."""


class ObstacleSpec(MissionModel):
    """A static obstacle (furniture): a polygon and its height for the simulator, metres."""

    name: str = ""
    polygon: Polygon
    height: Positive = 0.8


class MapConfig(MissionModel):
    """The static house: grid resolution, walls, the sensor model, regions, doors, obstacles."""

    resolution: Positive = 0.05
    """Metres per cell of every grid (occupancy, belief)."""
    occupancy: Path | None = None
    """Optional ROS map_server YAML, relative to the mission file; else walls come from polygons."""
    wall_thickness: Positive = 0.1
    """Metres."""
    wall_height: Positive = 2.2
    """Metres, for the simulator."""
    sensor_model: SensorModel = SensorModel()
    regions: Annotated[tuple[RegionSpec, ...], Field(min_length=1)]
    """Rooms as polygons; they may share edges but not area."""
    doors: tuple[DoorSpec, ...] = ()
    """Openings, each on the wall shared by two regions."""
    obstacles: tuple[ObstacleSpec, ...] = ()
    """Furniture."""

    @field_validator("occupancy")
    @classmethod
    def _occupancy_exists(cls, value: Path | None, info: ValidationInfo) -> Path | None:
        """Resolve the map_server YAML relative to the mission file and check that it exists."""
        if value is None:
            return None
        return existing_file(value, info, "an existing map_server YAML file")

    @model_validator(mode="after")
    def _geometry(self) -> MapConfig:
        """Unique region names, no overlapping regions, doors on the walls of existing regions."""
        issues: list[tuple[tuple[str | int, ...], str]] = []
        polygons: dict[str, shapely.Polygon] = {}
        first_index: dict[str, int] = {}
        for i, region in enumerate(self.regions):
            if region.name in first_index:
                issues.append(
                    (
                        ("regions", i, "name"),
                        f"duplicate region name {region.name!r} "
                        f"(already used by regions[{first_index[region.name]}])",
                    )
                )
                continue
            first_index[region.name] = i
            polygon = shapely.Polygon(region.polygon)
            for other, other_polygon in polygons.items():
                common = polygon.intersection(other_polygon).area
                if common > TOLERANCE:
                    issues.append(
                        (
                            ("regions", i, "polygon"),
                            f"region {region.name!r} overlaps region {other!r} by {common:.3g} m²;"
                            " regions may share edges but not area",
                        )
                    )
            polygons[region.name] = polygon
        known = ", ".join(polygons)
        for i, door in enumerate(self.doors):
            a, b = door.between
            unknown = [n for n in (a, b) if n not in polygons]
            if unknown:
                issues.append(
                    (("doors", i, "between"), f"unknown region {unknown[0]!r} (regions: {known})")
                )
                continue
            if a == b:
                issues.append(
                    (
                        ("doors", i, "between"),
                        f"expected two different regions, got {a!r} twice",
                    )
                )
                continue
            issue = _door_issue(door, polygons[a], polygons[b])
            if issue:
                issues.append((("doors", i, "segment"), issue))
        raise_first(issues)
        return self


def _lines_of(geometry: shapely.Geometry) -> list[shapely.LineString]:
    """The line pieces of ``geometry`` (an intersection may mix points and lines), merged."""
    parts = getattr(geometry, "geoms", [geometry])
    lines = [g for g in parts if g.geom_type in ("LineString", "LinearRing") and not g.is_empty]
    if not lines:
        return []
    merged = shapely.line_merge(shapely.MultiLineString(lines))
    return [g for g in getattr(merged, "geoms", [merged]) if g.length > TOLERANCE]


def _door_issue(door: DoorSpec, a: shapely.Polygon, b: shapely.Polygon) -> str | None:
    """Why ``door`` is not an opening in the wall ``a`` and ``b`` share, or None if it is.

    The shared wall is the part of ``a``'s boundary within :data:`TOLERANCE` of ``b``'s, so
    edges that meet up to rounding still count; the door must lie on it within the tolerance.
    """
    p, q = door.segment
    if math.dist(p, q) <= TOLERANCE:
        return f"expected a door segment of positive length, got {fmt_point(p)} twice"
    walls = _lines_of(a.boundary.intersection(b.boundary.buffer(TOLERANCE)))
    name_a, name_b = door.between
    if sum(w.length for w in walls) <= 10 * TOLERANCE:
        return f"regions {name_a!r} and {name_b!r} share no wall, so no door can join them"
    segment = shapely.LineString([p, q])
    if shapely.MultiLineString(walls).buffer(2 * TOLERANCE).covers(segment):
        return None
    described = "; ".join(
        f"{fmt_point(w.coords[0])} to {fmt_point(w.coords[-1])}"
        for w in walls
        if w.length > 10 * TOLERANCE
    )
    return (
        f"expected the segment {fmt_point(p)} to {fmt_point(q)} to lie on the wall shared by "
        f"{name_a!r} and {name_b!r}: {described}"
    )
