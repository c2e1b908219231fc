"""`pfctl mission validate|schema`: check mission files, or print the mission JSON Schema."""

from __future__ import annotations

import json
import os
import sys
import tempfile
from pathlib import Path
from typing import Annotated

import typer

from pfctl.errors import MissionError, UserError
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
    text = json.dumps(dump_json_schema(), indent=2) + "\n"
    if out is None:
        typer.echo(text, nl=False)
        return
    write_atomically(out, text)
    typer.echo(f"wrote {out}")


def write_atomically(path: Path, text: str) -> None:
    """Write ``text`` to ``path`` through a temporary file and a rename: all of it or nothing.

    Raises:
        UserError: if the file cannot be written (no such directory, no permission, ...).
    """
    directory = path.parent if str(path.parent) else Path(".")
    tmp: str | None = None
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=directory)
        with os.fdopen(fd, "w", encoding="utf-8") as handle:
            handle.write(text)
            handle.flush()
            os.fsync(handle.fileno())
        os.replace(tmp, path)
        tmp = None
    except OSError as err:
        raise UserError(f"{path}: cannot write: {err.strerror or err}") from None
    finally:
        if tmp is not None:
            Path(tmp).unlink(missing_ok=True)
