"""`pfctl sim`: the simulated house.

- ``export-map MISSION --out map.yaml``: the static occupancy grid the simulator's walls and
  furniture imply (:func:`pfctl.core.walls.rasterize_house`), as a ROS map_server map.

Every bad input is a :class:`pfctl.errors.UserError` (one line, exit 2); files are written
atomically.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated

import typer
from rich.console import Console

from pfctl.core.grid import GridFileError
from pfctl.core.walls import rasterize_house
from pfctl.errors import UserError
from pfctl.mission import load_mission

app = typer.Typer(help="The simulated house: export its map.", no_args_is_help=True)


@app.command("export-map")
def export_map(
    mission: Annotated[Path, typer.Argument(help="A mission YAML.", show_default=False)],
    out: Annotated[
        Path, typer.Option("--out", help="The map_server YAML to write (a .pgm goes beside it).")
    ],
    resolution: Annotated[
        float | None,
        typer.Option("--resolution", help="Cell size in metres (default: map.resolution)."),
    ] = None,
) -> None:
    """Write the simulator's static map (walls, doors, furniture) as a ROS map_server map."""
    if resolution is not None and not (math.isfinite(resolution) and resolution > 0):
        raise UserError(f"--resolution: expected a positive cell size in metres, got {resolution}")
    if out.suffix.lower() not in (".yaml", ".yml"):
        raise UserError(f"--out {out}: expected a map_server YAML path ending in .yaml")
    if out.is_dir():
        raise UserError(f"--out {out}: is a directory, expected a file path")
    loaded = load_mission(mission)
    grid = rasterize_house(
        loaded.layout(),
        resolution if resolution is not None else loaded.map.resolution,
        wall_thickness=loaded.map.wall_thickness,
        include_obstacles=True,
    )
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
        yaml_path, pgm_path = grid.save_map_server(out)
    except OSError as err:
        raise UserError(f"--out {out}: cannot create its folder: {err.strerror}") from None
    except GridFileError as err:
        raise UserError(str(err)) from None
    g = grid.geometry
    Console(width=100, soft_wrap=True).print(
        f"wrote {yaml_path} and {pgm_path.name}: {g.width}×{g.height} cells at {g.resolution:g} m"
    )
