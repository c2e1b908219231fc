"""The ``map`` section: grid resolution, walls, the sensor model of Eq. 1, regions, doors and
obstacles (§II-B), with the checks of the house's geometry: polygons are simple, regions do not
overlap, and each door lies on the wall the two regions it joins share; the occupancy map
(``map.occupancy``) must be readable; and the grids made from the map must fit
:data:`GRID_MEMORY_LIMIT` (:func:`grid_memory_issue`)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated

import shapely
from pydantic import Field, ValidationInfo, field_validator, model_validator

from pfctl.core.mapping.grid import InverseSensorModel
from pfctl.core.mapping.house import HouseLayout, Obstacle, Region
from pfctl.core.mapping.walls import house_geometry
from pfctl.mission.errors import field_error, raise_first
from pfctl.mission.map_server import GridFileError, map_server_size
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

#: Memory the grids made from one map may take together, bytes. A command builds several grids of
#: the map's cells (occupancy, free space and clearance for planning, region masks, distance
#: transforms, belief, frontiers); :data:`GRID_BYTES_PER_CELL` is their measured peak per cell.
#: 2 GiB holds a 110 × 110 m map at 0.05 m; a large real home (40 × 40 m) needs an eighth of it.
GRID_MEMORY_LIMIT = 2 * 1024**3
#: Peak bytes per map cell of the heaviest command (``pfctl follow``), rounded up
#: (benchmarks/README.md).
GRID_BYTES_PER_CELL = 400


def grid_memory_issue(width: int, height: int, resolution: float) -> str | None:
    """Why a ``width`` × ``height`` grid of ``resolution`` metres is too big for
    :data:`GRID_MEMORY_LIMIT`, or None if it fits."""
    need = width * height * GRID_BYTES_PER_CELL
    if need <= GRID_MEMORY_LIMIT:
        return None
    return (
        f"the grids of a {width * resolution:.4g} × {height * resolution:.4g} m map at "
        f"{resolution:g} m ({width} × {height} cells) need about {_gib(need)}, over the limit of "
        f"{_gib(GRID_MEMORY_LIMIT)}; use a coarser resolution or a smaller map"
    )


def house_grid_issue(layout: HouseLayout, resolution: float) -> str | None:
    """:func:`grid_memory_issue` of the house's polygons rasterised at ``resolution`` (the grid
    of :func:`~pfctl.core.mapping.walls.rasterize_house`), or None if it fits."""
    geometry = house_geometry(layout, resolution)
    return grid_memory_issue(geometry.width, geometry.height, resolution)


def _gib(n: float) -> str:
    return f"{n / 1024**3:.3g} GiB"


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

    @model_validator(mode="after")
    def _grids_fit(self) -> MapConfig:
        """The occupancy map is readable, and the grids of the map fit the memory limit: the
        polygons rasterised at ``resolution`` (the simulator, map export) and the occupancy
        image (the robot's map)."""
        layout = HouseLayout(
            regions=tuple(Region(r.name, tuple(r.polygon)) for r in self.regions),
            obstacles=tuple(Obstacle(tuple(o.polygon), o.height, o.name) for o in self.obstacles),
        )
        issue = house_grid_issue(layout, self.resolution)
        if issue:
            raise field_error(("resolution",), issue)
        if self.occupancy is not None:
            try:
                width, height, resolution = map_server_size(self.occupancy)
            except GridFileError as err:
                raise field_error(("occupancy",), f"unreadable map: {err}") from None
            issue = grid_memory_issue(width, height, resolution)
            if issue:
                raise field_error(("occupancy",), f"{self.occupancy}: {issue}")
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
