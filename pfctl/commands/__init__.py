"""One module per CLI command group: parse, load the mission, call core/backends, report.

What several commands share is here: the check of every ``--seed`` option, and of float
options for which NaN and infinity mean nothing."""

from __future__ import annotations

import math

import typer

from pfctl.mission.types import SEED_MAX


def check_seed(value: int | None) -> int | None:
    """Typer callback of every ``--seed``: a seed is 0 to 2**32 - 1 (numpy's and scikit-learn's
    range), else a one-line option error before any work starts."""
    if value is not None and not 0 <= value <= SEED_MAX:
        raise typer.BadParameter(f"expected a seed from 0 to {SEED_MAX} (2**32 - 1), got {value}")
    return value


def check_finite(value: float | None) -> float | None:
    """Typer callback of a float option for which NaN and ±inf mean nothing (a width, an area):
    a one-line option error before any work starts, instead of a failure deep in the work that
    does not name the option (NaN passes every ``<`` and ``>`` check)."""
    if value is not None and not math.isfinite(value):
        raise typer.BadParameter(f"expected a finite number, got {value}")
    return value
