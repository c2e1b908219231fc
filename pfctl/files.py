"""Writing the files a command produces: atomically, and with a one-line error for the user."""

from __future__ import annotations

import os
from pathlib import Path

from pfctl.core.atomic_files import atomic_write
from pfctl.errors import UserError


def write_output(path: str | os.PathLike[str], data: str | bytes) -> Path:
    """Write ``data`` to ``path`` all or nothing; an OSError becomes a :class:`UserError` naming
    the file (exit 2, nothing partial left behind)."""
    try:
        return atomic_write(path, data)
    except OSError as err:
        raise UserError(f"{path}: cannot write: {err.strerror or err}") from None
