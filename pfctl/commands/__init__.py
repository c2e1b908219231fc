"""One module per CLI command group: parse, load the mission, call core/backends, report.

What several commands share is here: the check of every ``--seed`` option."""

from __future__ import annotations

import typer

from pfctl.mission.types import SEED_MAX


def check_seed(value: int | None) -> int | None:
    """Typer callback of every ``--seed``: a seed is 0 to 2**32 - 1 (numpy's and scikit-learn's
    range), else a one-line option error before any work starts."""
    if value is not None and not 0 <= value <= SEED_MAX:
        raise typer.BadParameter(f"expected a seed from 0 to {SEED_MAX} (2**32 - 1), got {value}")
    return value
