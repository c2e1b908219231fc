"""`pfctl mission validate|schema`: check mission files, or print the mission JSON Schema."""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Annotated

import typer

from pfctl.errors import MissionError
from pfctl.files import check_output_file, write_output
from pfctl.mission import Mission, dump_json_schema, load_mission

app = typer.Typer(help="Check a mission file, or print its JSON Schema.", no_args_is_help=True)


def _plural(count: int, noun: str) -> str:
    return f"{count} {noun}" if count == 1 else f"{count} {noun}s"


def summary(mission: Mission) -> str:
    """``N regions, M doors, K obstacles, tree of T nodes``: what a mission holds, in one line."""
    return ", ".join(
        (
            _plural(len(mission.map.regions), "region"),
            _plural(len(mission.map.doors), "door"),
            _plural(len(mission.map.obstacles), "obstacle"),
            f"tree of {_plural(mission.behavior.tree.size(), 'node')}",
        )
    )


@app.command()
def validate(
    files: Annotated[list[Path], typer.Argument(help="Mission YAML files to check.")],
) -> None:
    """Check each mission FILE: print `OK <file>: ...` or one error line; exit 2 if any fail."""
    failed = 0
    for file in files:
        try:
            mission = load_mission(file)
        except MissionError as err:
            failed += 1
            sys.stderr.write(f"pfctl: error: {err}\n")
            continue
        typer.echo(f"OK {file}: {summary(mission)}")
    if failed:
        raise typer.Exit(code=MissionError.exit_code)


@app.command()
def schema(
    out: Annotated[
        Path | None,
        typer.Option("--out", "-o", help="Write the schema to this file (atomically)."),
    ] = None,
) -> None:
    """Print the JSON Schema of a mission file, or write it to --out."""
    check_output_file(out, "--out", make_folder=False)
    text = json.dumps(dump_json_schema(), indent=2) + "\n"
    if out is None:
        typer.echo(text, nl=False)
        return
    write_output(out, text)
    typer.echo(f"wrote {out}")
