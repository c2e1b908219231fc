"""`pfctl mission validate|schema` (filled by the mission work)."""

from __future__ import annotations

import typer

app = typer.Typer(help="Check a mission file, or print its JSON Schema.", no_args_is_help=True)
