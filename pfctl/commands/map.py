"""`pfctl map annotate` (filled by the map-annotation work)."""

from __future__ import annotations

import typer

app = typer.Typer(help="Maps: annotate regions and doors, render them.", no_args_is_help=True)
