"""Leg model files (``perception.legs.model``, ``pfctl legs train --out``) and the model shipped
with pfctl: read and written here; the forest and its ``.npz`` bytes are core's
(:class:`~pfctl.core.perception.legs.model.LegModel`). A file that cannot be used is a one-line
:class:`LegModelError` naming it.
"""

from __future__ import annotations

import os
from importlib import resources
from pathlib import Path

from pfctl.core.perception.legs.features import FEATURE_NAMES
from pfctl.core.perception.legs.model import LegModel
from pfctl.errors import UserError
from pfctl.files import atomic_write


class LegModelError(UserError):
    """A leg model file that cannot be used (missing, corrupt, foreign, other features)."""


def shipped_model_path() -> Path:
    """The model shipped with pfctl (``pfctl/data/legs_model.npz``)."""
    return Path(str(resources.files("pfctl") / "data" / "legs_model.npz"))


def read_leg_model(path: Path, expected_features: tuple[str, ...] | None = None) -> LegModel:
    """The model in ``path`` (written by :func:`save_leg_model`).

    Raises :class:`LegModelError` (one line naming the file) for a missing, corrupt or foreign
    file, a newer format, or (with ``expected_features``) a model trained on other features.
    """
    path = Path(path)
    if not path.is_file():
        raise LegModelError(f"{path}: no such leg model file (write one with `pfctl legs train`)")
    try:
        with open(os.fspath(path), "rb") as handle:
            data = handle.read()
    except OSError as err:
        raise LegModelError(f"{path}: not a leg model (.npz without pickles): {err}") from None
    try:
        return LegModel.from_bytes(data, expected_features)
    except ValueError as err:
        raise LegModelError(f"{path}: {err}") from None


def load_leg_model(path: Path | None = None) -> LegModel:
    """A leg model for this pfctl's features (``None``: the shipped one); one-line
    :class:`LegModelError` if unusable."""
    return read_leg_model(shipped_model_path() if path is None else Path(path), FEATURE_NAMES)


def save_leg_model(model: LegModel, path: Path) -> Path:
    """Write ``model`` to ``path`` all or nothing; OSError if it cannot be written."""
    return atomic_write(path, model.to_bytes())


__all__ = [
    "LegModelError",
    "load_leg_model",
    "read_leg_model",
    "save_leg_model",
    "shipped_model_path",
]
