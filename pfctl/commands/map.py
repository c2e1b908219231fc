"""`pfctl map annotate|render|export`: regions and doors of a map — propose, write, draw, export.

- ``annotate SOURCE``: take a ROS map_server map or a mission, propose rooms and doors
  automatically (``--auto``, :mod:`pfctl.core.mapping.rooms`) and/or take them from a file or flags,
  write them into a mission (``--out``, comments and the rest of the file kept) and draw them
  (``--png``).
- ``render MISSION``: draw a mission's map with its regions, doors and region graph.
- ``export MISSION``: write the house a mission's polygons imply
  (:mod:`pfctl.core.mapping.walls`) as a ROS map_server map (YAML + PGM).

Every bad input is a :class:`pfctl.errors.UserError` (one line, exit 2) raised before anything is
written; every file is written atomically.
"""

from __future__ import annotations

import io
import math
import re
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Any

import typer
import yaml
from rich.console import Console
from rich.table import Table
from shapely.geometry import Polygon

from pfctl.commands import check_finite
from pfctl.core.mapping.grid import GridGeometry, OccupancyGrid
from pfctl.core.mapping.house import Door, HouseLayout, Region
from pfctl.core.mapping.rooms import RoomParams, name_after, segment_free_space
from pfctl.core.mapping.walls import rasterize_house
from pfctl.errors import MissionError, UserError
from pfctl.files import check_output_file, write_output
from pfctl.mission import Mission, load_mission, loads_mission
from pfctl.mission.edit import render_regions
from pfctl.mission.map import grid_memory_issue, house_grid_issue
from pfctl.mission.map_server import (
    GridFileError,
    load_map_server,
    map_server_size,
    save_map_server,
)

app = typer.Typer(help="Maps: annotate regions and doors, render them.", no_args_is_help=True)

_NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
_POINT = re.compile(rf"^\s*({_NUMBER})\s*,\s*({_NUMBER})\s*$")


# --------------------------------------------------------------------------------------------
# reading the source


@dataclass
class Source:
    """What ``SOURCE`` gave: the grid, and for a mission its layout and occupancy map file."""

    path: Path
    grid: OccupancyGrid
    mission: Mission | None = None
    occupancy: Path | None = None  # the map_server YAML the grid came from, if any

    @property
    def layout(self) -> HouseLayout | None:
        return self.mission.layout() if self.mission is not None else None


def _read_yaml_mapping(path: Path, what: str) -> dict[str, Any]:
    if not path.exists():
        raise UserError(f"{path}: no such file (expected {what})")
    if path.is_dir():
        raise UserError(f"{path}: is a directory (expected {what})")
    try:
        data = yaml.safe_load(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError) as err:
        raise UserError(f"{path}: cannot read: {err}") from None
    except yaml.YAMLError as err:
        mark = getattr(err, "problem_mark", None)
        line = f":{mark.line + 1}" if mark is not None else ""
        problem = getattr(err, "problem", None) or "syntax error"
        raise UserError(f"{path}{line}: invalid YAML: {problem}") from None
    if not isinstance(data, dict):
        raise UserError(f"{path}: expected {what}, got {type(data).__name__}")
    return data


def _load_map_server(path: Path) -> OccupancyGrid:
    try:
        issue = grid_memory_issue(*map_server_size(path))
        if issue:
            raise UserError(f"{path}: {issue}")
        return load_map_server(path)
    except GridFileError as err:
        raise UserError(str(err)) from None


def _check_resolution(layout: HouseLayout, resolution: float | None) -> None:
    """An explicit ``--resolution`` must keep the house's grids within the memory limit."""
    issue = house_grid_issue(layout, resolution) if resolution is not None else None
    if issue:
        raise UserError(f"--resolution {resolution:g}: {issue}")


def load_source(path: Path, resolution: float | None = None) -> Source:
    """Read ``SOURCE``: a map_server YAML (has ``image``) or a mission (has ``name``/``map``).

    A mission's grid is its ``map.occupancy`` map if it has one, else its polygons rasterised at
    ``resolution`` (default ``map.resolution``) with ``map.wall_thickness``.
    """
    what = "a mission YAML (keys name, map) or a ROS map_server map YAML (key image)"
    data = _read_yaml_mapping(path, what)
    if "image" in data:
        grid = _load_map_server(path)
        if resolution is not None and not math.isclose(resolution, grid.resolution):
            raise UserError(
                f"--resolution {resolution:g}: {path} is a map_server map at "
                f"{grid.resolution:g} m; --resolution only applies when rasterising a mission"
            )
        return Source(path=path, grid=grid, occupancy=path)
    if "map" in data or "name" in data:
        mission = load_mission(path)
        if mission.map.occupancy is not None and resolution is None:
            occupancy = Path(mission.map.occupancy)
            return Source(path, _load_map_server(occupancy), mission, occupancy)
        _check_resolution(mission.layout(), resolution)
        grid = rasterize_house(
            mission.layout(),
            resolution if resolution is not None else mission.map.resolution,
            wall_thickness=mission.map.wall_thickness,
        )
        return Source(path=path, grid=grid, mission=mission)
    raise UserError(f"{path}: expected {what}; found keys {', '.join(map(str, data)) or 'none'}")


# --------------------------------------------------------------------------------------------
# regions and doors from flags and files


def _points(text: str, where: str, expected: str) -> list[tuple[float, float]]:
    points = []
    for part in text.split(";"):
        m = _POINT.match(part)
        if not m:
            raise UserError(f"{where}: expected {expected}, got the point {part.strip()!r}")
        x, y = float(m.group(1)), float(m.group(2))
        if not (math.isfinite(x) and math.isfinite(y)):
            raise UserError(f"{where}: expected finite coordinates, got {part.strip()!r}")
        points.append((x, y))
    return points


def parse_region_spec(spec: str) -> Region:
    """``NAME=x0,y0;x1,y1;x2,y2[;...]`` → Region (at least 3 points)."""
    expected = "NAME=x0,y0;x1,y1;x2,y2;... (a name and at least 3 points)"
    where = f"--region {spec!r}"
    name, sep, rest = spec.partition("=")
    if not sep or not name.strip() or not rest.strip():
        raise UserError(f"{where}: expected {expected}")
    points = _points(rest, where, expected)
    if len(points) < 3:
        raise UserError(f"{where}: expected {expected}, got {len(points)} point(s)")
    return Region(name=name.strip(), polygon=tuple(points))


def parse_door_spec(spec: str) -> Door:
    """``A,B=x0,y0;x1,y1`` → Door between regions A and B."""
    expected = "A,B=x0,y0;x1,y1 (two region names and the 2 end points of the opening)"
    where = f"--door {spec!r}"
    names, sep, rest = spec.partition("=")
    parts = [n.strip() for n in names.split(",")]
    if not sep or len(parts) != 2 or not all(parts) or not rest.strip():
        raise UserError(f"{where}: expected {expected}")
    points = _points(rest, where, expected)
    if len(points) != 2:
        raise UserError(f"{where}: expected {expected}, got {len(points)} point(s)")
    return Door(between=(parts[0], parts[1]), segment=(points[0], points[1]))


def _point_of(value: Any, where: str) -> tuple[float, float]:
    if (
        isinstance(value, list | tuple)
        and len(value) == 2
        and all(isinstance(v, int | float) and not isinstance(v, bool) for v in value)
        and all(math.isfinite(v) for v in value)
    ):
        return (float(value[0]), float(value[1]))
    raise UserError(f"{where}: expected an [x, y] point of two numbers, got {value!r}")


def load_regions_file(path: Path) -> tuple[list[Region], list[Door]]:
    """Regions and doors from a YAML file with ``regions:``/``doors:`` lists (mission format).

    A whole mission is accepted too (its ``map.regions`` / ``map.doors``).
    """
    data = _read_yaml_mapping(path, "a YAML mapping with 'regions' (and 'doors') lists")
    prefix = ""
    if "regions" not in data and isinstance(data.get("map"), dict):
        data, prefix = data["map"], "map."
    raw_regions = data.get("regions")
    raw_doors = data.get("doors") or []
    if not isinstance(raw_regions, list) or not raw_regions:
        raise UserError(f"{path}: {prefix}regions: expected a non-empty list of regions")
    if not isinstance(raw_doors, list):
        raise UserError(f"{path}: {prefix}doors: expected a list of doors")
    regions = []
    for i, item in enumerate(raw_regions):
        where = f"{path}: {prefix}regions[{i}]"
        if not isinstance(item, dict) or not isinstance(item.get("name"), str) or not item["name"]:
            raise UserError(f"{where}: expected {{name: NAME, polygon: [[x, y], ...]}}")
        poly = item.get("polygon")
        if not isinstance(poly, list) or len(poly) < 3:
            raise UserError(f"{where}.polygon: expected a list of at least 3 [x, y] points")
        pts = tuple(_point_of(p, f"{where}.polygon[{j}]") for j, p in enumerate(poly))
        regions.append(Region(name=item["name"], polygon=pts))
    doors = []
    for i, item in enumerate(raw_doors):
        where = f"{path}: {prefix}doors[{i}]"
        between = item.get("between") if isinstance(item, dict) else None
        segment = item.get("segment") if isinstance(item, dict) else None
        if (
            not isinstance(between, list)
            or len(between) != 2
            or not all(isinstance(n, str) for n in between)
        ):
            raise UserError(f"{where}.between: expected two region names [A, B]")
        if not isinstance(segment, list) or len(segment) != 2:
            raise UserError(f"{where}.segment: expected two [x, y] end points")
        a, b = (_point_of(p, f"{where}.segment[{j}]") for j, p in enumerate(segment))
        doors.append(Door(between=(between[0], between[1]), segment=(a, b)))
    return regions, doors


def _merge(
    layers: Sequence[tuple[Sequence[Region], Sequence[Door]]],
) -> tuple[list[Region], list[Door]]:
    """Regions by name (a later layer replaces a same-named region), doors deduplicated."""
    by_name: dict[str, Region] = {}
    doors: list[Door] = []
    for regions, layer_doors in layers:
        for r in regions:
            by_name[r.name] = r
        for d in layer_doors:
            if d not in doors:
                doors.append(d)
    return list(by_name.values()), doors


def check_layout(regions: Sequence[Region], doors: Sequence[Door], resolution: float) -> None:
    """Validate regions and doors with the mission's own rules; UserError on the first problem."""
    text = render_regions(
        Path("/nonexistent-pfctl-check/annotation.yaml"), regions, doors, resolution=resolution
    )
    try:
        loads_mission(text, source="annotation")
    except MissionError as err:
        message = re.sub(r"^annotation(:\d+)?: ", "", str(err))
        raise UserError(f"regions/doors to annotate: {message}") from None


def auto_layout(
    states: Any,
    geometry: GridGeometry,
    params: RoomParams,
    reference: HouseLayout | None = None,
) -> tuple[HouseLayout, list[str]]:
    """The rooms and doors ``--auto`` proposes for a trinary map, and the warnings to print.

    Rooms take the names of ``reference``'s regions they match. UserError if no room is found.
    """
    try:
        seg = segment_free_space(states, geometry, params)
    except ValueError as err:
        raise UserError(str(err)) from None
    if reference is not None:
        seg = name_after(seg, reference)
    layout = seg.layout()
    try:
        check_layout(layout.regions, layout.doors, geometry.resolution)
        return layout, [f"--auto: {w}" for w in seg.warnings]
    except UserError:
        pass
    # a proposed door the mission rules reject is dropped, not the whole proposal
    check_layout(layout.regions, (), geometry.resolution)
    kept: list[Door] = []
    dropped: list[str] = []
    for d in layout.doors:
        try:
            check_layout(layout.regions, (d,), geometry.resolution)
            kept.append(d)
        except UserError:
            dropped.append(f"{d.between[0]}|{d.between[1]}")
    warnings = [f"--auto: {w}" for w in seg.warnings] + [
        f"--auto: dropped {len(dropped)} proposed door(s) not on the wall their rooms share: "
        + ", ".join(dropped)
    ]
    return HouseLayout(regions=layout.regions, doors=tuple(kept)), warnings


# --------------------------------------------------------------------------------------------
# output


def _neighbours(layout: HouseLayout) -> dict[str, list[str]]:
    out: dict[str, list[str]] = {r.name: [] for r in layout.regions}
    for d in layout.doors:
        a, b = d.between
        if a in out and b not in out[a]:
            out[a].append(b)
        if b in out and a not in out[b]:
            out[b].append(a)
    return out


def summary_table(layout: HouseLayout, title: str = "regions") -> Table:
    """A rich table: name, area (m²), neighbours through doors."""
    table = Table(title=title)
    table.add_column("region")
    table.add_column("area m²", justify="right")
    table.add_column("neighbours")
    neighbours = _neighbours(layout)
    for r in layout.regions:
        table.add_row(r.name, f"{Polygon(r.polygon).area:.2f}", ", ".join(neighbours[r.name]))
    return table


def _prepare_parent(path: Path, option: str) -> None:
    """Create the folder of an output file; UserError if that is impossible."""
    if path.is_dir():
        raise UserError(f"{option} {path}: is a directory, expected a file path")
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
    except OSError as err:
        raise UserError(f"{option} {path}: cannot create its folder: {err.strerror}") from None


def _png_bytes(
    grid: OccupancyGrid,
    layout: HouseLayout | None,
    graph: bool,
    title: str,
    routes: list[tuple[str, Any, bool]] | None = None,
) -> bytes:
    from pfctl.plots.map import map_figure

    fig = map_figure(grid, layout, region_graph=graph, title=title, routes=routes or ())
    buf = io.BytesIO()
    fig.savefig(buf, format="png", bbox_inches="tight")
    return buf.getvalue()


def _console() -> Console:
    return Console(width=100, soft_wrap=True)


# --------------------------------------------------------------------------------------------
# commands


@app.command()
def annotate(
    source: Annotated[
        Path,
        typer.Argument(help="A ROS map_server map YAML, or a mission YAML.", show_default=False),
    ],
    auto: Annotated[
        bool, typer.Option("--auto", help="Propose rooms and doors by segmenting the free space.")
    ] = False,
    regions_file: Annotated[
        Path | None,
        typer.Option("--regions", help="YAML with regions:/doors: lists (mission format)."),
    ] = None,
    region: Annotated[
        list[str] | None,
        typer.Option("--region", help="A region: NAME=x0,y0;x1,y1;x2,y2;... (repeatable)."),
    ] = None,
    door: Annotated[
        list[str] | None,
        typer.Option("--door", help="A door: A,B=x0,y0;x1,y1 on the wall A and B share."),
    ] = None,
    out: Annotated[
        Path | None,
        typer.Option("--out", help="Mission YAML to write regions/doors into (new or existing)."),
    ] = None,
    png: Annotated[
        Path | None, typer.Option("--png", help="Draw the map, regions, doors and graph here.")
    ] = None,
    resolution: Annotated[
        float | None,
        typer.Option("--resolution", help="Cell size (m) when rasterising a mission's polygons."),
    ] = None,
    name: Annotated[
        str | None, typer.Option("--name", help="Mission name (new --out file; default its stem).")
    ] = None,
    reference: Annotated[
        Path | None,
        typer.Option("--reference", help="Mission whose region names --auto rooms take (IoU≥0.5)."),
    ] = None,
    door_width: Annotated[
        float,
        typer.Option(
            "--door-width", callback=check_finite, help="--auto: widest door or opening, m."
        ),
    ] = RoomParams().door_width,
    min_room_area: Annotated[
        float,
        typer.Option("--min-room-area", callback=check_finite, help="--auto: smallest room, m²."),
    ] = 2.0,
) -> None:
    """Propose (--auto) or take regions and doors for a map; write them (--out), draw (--png).

    Sources stack: --auto, then --regions FILE, then --region/--door flags.
    A later region with the same name replaces an earlier one.
    With none of them and a mission SOURCE, the mission's own regions are used.
    --auto names rooms room_1, room_2, ... (south to north, west to east),
    or after the regions of --reference (default: SOURCE or --out, if a mission).
    """
    if door_width <= 0:
        raise UserError(f"--door-width: expected a positive width in metres, got {door_width:g}")
    if min_room_area < 0:
        raise UserError(f"--min-room-area: expected an area ≥ 0 m², got {min_room_area:g}")
    if resolution is not None and not (math.isfinite(resolution) and resolution > 0):
        raise UserError(f"--resolution: expected a positive cell size in metres, got {resolution}")
    # parse everything cheap first, so a typo fails before the segmentation runs
    flag_regions = [parse_region_spec(s) for s in region or []]
    flag_doors = [parse_door_spec(s) for s in door or []]
    file_layer = load_regions_file(regions_file) if regions_file is not None else ([], [])
    check_output_file(out, "--out")
    check_output_file(png, "--png")
    src = load_source(source, resolution)
    grid = src.grid

    layers: list[tuple[Sequence[Region], Sequence[Door]]] = []
    if auto:
        params = RoomParams(door_width=door_width, min_room_area=min_room_area)
        ref_layout = _reference_layout(reference, src, out)
        try:
            proposal, warnings = auto_layout(grid.states(), grid.geometry, params, ref_layout)
        except UserError as err:
            raise UserError(f"{source}: --auto: {err}") from None
        for warning in warnings:
            sys.stderr.write(f"pfctl: warning: {source}: {warning}\n")
        layers.append((proposal.regions, proposal.doors))
    if regions_file is not None:
        layers.append(file_layer)
    if flag_regions or flag_doors:
        layers.append((flag_regions, flag_doors))
    if not layers:
        if src.layout is None:
            raise UserError(
                f"{source}: nothing to annotate: give --auto, --regions FILE or --region NAME=..."
            )
        layers.append((src.layout.regions, src.layout.doors))
    regions, doors = _merge(layers)
    if not regions:
        raise UserError("nothing to annotate: no regions were given or found")
    check_layout(regions, doors, grid.resolution)
    layout = HouseLayout(regions=tuple(regions), doors=tuple(doors))

    # render everything in memory, then write (mission first, then the picture)
    mission_text = None
    if out is not None:
        _prepare_parent(out, "--out")
        occupancy = src.occupancy
        mission_text = render_regions(
            out,
            regions,
            doors,
            name=name,
            resolution=grid.resolution,
            occupancy=occupancy,
        )
        loads_mission(mission_text, source=str(out), base_dir=out.parent)
    png_data = None
    if png is not None:
        _prepare_parent(png, "--png")
        png_data = _png_bytes(grid, layout, True, f"{source.name}: {len(regions)} regions")

    console = _console()
    console.print(summary_table(layout, title=f"{source}: {len(regions)} regions"))
    if mission_text is not None and out is not None:
        write_output(out, mission_text)
        console.print(f"wrote {out}")
    if png_data is not None and png is not None:
        write_output(png, png_data)
        console.print(f"wrote {png}")


def _reference_layout(reference: Path | None, src: Source, out: Path | None) -> HouseLayout | None:
    """Whose region names --auto rooms take: --reference, else a mission SOURCE, else --out."""
    if reference is not None:
        return load_mission(reference).layout()
    if src.layout is not None:
        return src.layout
    if out is not None and out.is_file():
        try:
            return load_mission(out).layout()
        except MissionError:
            return None  # the write will report what is wrong with it
    return None


@app.command()
def render(
    mission: Annotated[
        Path, typer.Argument(help="A mission YAML (or a map_server map YAML).", show_default=False)
    ],
    png: Annotated[Path, typer.Option("--png", help="The PNG to write.")],
    resolution: Annotated[
        float | None,
        typer.Option("--resolution", help="Cell size (m) when rasterising the polygons."),
    ] = None,
    graph: Annotated[
        bool, typer.Option("--graph/--no-graph", help="Draw the region graph.")
    ] = True,
    routes: Annotated[
        bool,
        typer.Option(
            "--routes", help="Draw the scenario's people walking their routes (as planned)."
        ),
    ] = False,
) -> None:
    """Draw a mission's map with its regions, doors and region graph to a PNG."""
    if resolution is not None and not (math.isfinite(resolution) and resolution > 0):
        raise UserError(f"--resolution: expected a positive cell size in metres, got {resolution}")
    check_output_file(png, "--png")
    src = load_source(mission, resolution)
    _prepare_parent(png, "--png")
    layout = src.layout
    title = src.mission.name if src.mission is not None else mission.name
    walks = None
    if routes and src.mission is not None:
        from pfctl.app.homes import planned_walks

        walks = planned_walks(src.mission)
    write_output(png, _png_bytes(src.grid, layout, graph, title, walks))
    console = _console()
    if layout is not None:
        console.print(summary_table(layout, title=f"{mission}: {len(layout.regions)} regions"))
    console.print(f"wrote {png}")


@app.command()
def export(
    mission: Annotated[Path, typer.Argument(help="A mission YAML.", show_default=False)],
    out: Annotated[
        Path, typer.Option("--out", help="The map_server YAML to write (a .pgm goes beside it).")
    ],
    resolution: Annotated[
        float | None,
        typer.Option("--resolution", help="Cell size in metres (default: map.resolution)."),
    ] = None,
    margin: Annotated[
        float, typer.Option("--margin", help="Unknown border around the house, metres.")
    ] = 0.5,
    obstacles: Annotated[
        bool, typer.Option("--obstacles/--no-obstacles", help="Draw the furniture.")
    ] = True,
) -> None:
    """Write the house a mission's polygons imply (walls, doors, furniture) as a ROS map."""
    if resolution is not None and not (math.isfinite(resolution) and resolution > 0):
        raise UserError(f"--resolution: expected a positive cell size in metres, got {resolution}")
    if not (math.isfinite(margin) and margin >= 0):
        raise UserError(f"--margin: expected a distance ≥ 0 in metres, got {margin}")
    if out.suffix.lower() not in (".yaml", ".yml"):
        raise UserError(f"--out {out}: expected a map_server YAML path ending in .yaml")
    check_output_file(out, "--out")
    loaded = load_mission(mission)
    _check_resolution(loaded.layout(), resolution)
    grid = rasterize_house(
        loaded.layout(),
        resolution if resolution is not None else loaded.map.resolution,
        wall_thickness=loaded.map.wall_thickness,
        margin=margin,
        include_obstacles=obstacles,
    )
    _prepare_parent(out, "--out")
    try:
        yaml_path, pgm_path = save_map_server(grid, out)
    except GridFileError as err:
        raise UserError(str(err)) from None
    g = grid.geometry
    _console().print(
        f"wrote {yaml_path} and {pgm_path.name}: {g.width}×{g.height} cells at "
        f"{g.resolution:g} m, origin ({g.origin[0]:g}, {g.origin[1]:g})"
    )
