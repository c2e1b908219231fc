"""`pfctl mission validate|schema|generate`: check mission files, print the mission JSON Schema,
or generate a random home as a mission."""

from __future__ import annotations

import json
import re
import sys
import time
from pathlib import Path
from typing import Annotated

import typer

from pfctl.app.homes import HOUSE_MISSION, make_home
from pfctl.commands import check_seed
from pfctl.core.homes import LAYOUTS, HomeOptions
from pfctl.errors import MissionError, UserError
from pfctl.files import check_output_file, write_output
from pfctl.mission import Mission, dump_json_schema, load_mission

app = typer.Typer(
    help="Check a mission file, print its JSON Schema, or generate a random home.",
    no_args_is_help=True,
)
#: The most people besides the target that ``generate`` adds of each kind.
MAX_PEOPLE = 10
_SIZE = re.compile(r"^\s*(\d+(?:\.\d*)?)\s*[xX×]\s*(\d+(?:\.\d*)?)\s*$")


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


def _size(text: str | None) -> tuple[float, float] | None:
    """``--size WxH`` in metres, or None."""
    if text is None:
        return None
    match = _SIZE.match(text)
    if match is None:
        raise UserError(f"--size {text}: expected WIDTHxHEIGHT in metres, e.g. 14x10")
    return (float(match[1]), float(match[2]))


@app.command()
def generate(
    out: Annotated[Path, typer.Option("--out", "-o", help="The mission YAML to write.")],
    seed: Annotated[
        int, typer.Option("--seed", callback=check_seed, help="Seed of every random choice.")
    ] = 1,
    rooms: Annotated[
        int | None,
        typer.Option("--rooms", help="Rooms besides a corridor or hall (default: by the size)."),
    ] = None,
    size: Annotated[
        str | None,
        typer.Option("--size", help="WIDTHxHEIGHT in metres (default: drawn, 10x8 to 16x12)."),
    ] = None,
    layout: Annotated[
        str | None,
        typer.Option("--layout", help=f"One of {', '.join(LAYOUTS)} (default: drawn)."),
    ] = None,
    crowd: Annotated[
        int, typer.Option("--crowd", help="Other people, in other clothes, on their own routes.")
    ] = 0,
    look_alikes: Annotated[
        int, typer.Option("--look-alikes", help="Other people in the target's clothes.")
    ] = 0,
    base: Annotated[
        Path,
        typer.Option("--base", help="Mission whose sections besides map and scenario are copied."),
    ] = HOUSE_MISSION,
) -> None:
    """Write a random home as a self-contained mission: rooms, doors, furniture, the target's
    walk through doors, other people; the same seed and options give the same file."""
    check_output_file(out, "--out")
    dimensions = _size(size)
    if layout is not None and layout not in LAYOUTS:
        raise UserError(f"--layout {layout}: expected one of {', '.join(LAYOUTS)}")
    for option, count in (("--crowd", crowd), ("--look-alikes", look_alikes)):
        if not 0 <= count <= MAX_PEOPLE:
            raise UserError(f"{option} {count}: expected 0 to {MAX_PEOPLE} people")
    if rooms is not None and rooms < 1:
        raise UserError(f"--rooms {rooms}: expected at least 1")
    started = time.perf_counter()
    options = HomeOptions(
        seed=seed, rooms=rooms, size=dimensions, layout=layout, crowd=crowd, look_alikes=look_alikes
    )
    made = make_home(options, base)
    out.parent.mkdir(parents=True, exist_ok=True)
    write_output(out, made.text)
    typer.echo(
        f"wrote {out}: {made.home.plan.describe()}; {summary(made.mission)} "
        f"({time.perf_counter() - started:.1f} s)"
    )
