"""Writing the files a command produces: atomically, and with a one-line error for the user."""

from __future__ import annotations

import csv
import io
import os
from pathlib import Path

from pfctl.core.atomic_files import atomic_write
from pfctl.core.episode import TrackRow
from pfctl.errors import UserError

#: The columns of ``tracks.csv`` (``pfctl replay``, ``pfctl follow``).
TRACK_COLUMNS = ("t", "track_id", "x", "y", "vx", "vy", "confidence", "is_target")


def write_output(path: str | os.PathLike[str], data: str | bytes) -> Path:
    """Write ``data`` to ``path`` all or nothing; an OSError becomes a :class:`UserError` naming
    the file (exit 2, nothing partial left behind)."""
    try:
        return atomic_write(path, data)
    except OSError as err:
        raise UserError(f"{path}: cannot write: {err.strerror or err}") from None


def check_episode_dir(path: Path) -> None:
    """Refuse to write an episode (``--record``) over a file or over a folder that holds
    something else."""
    if path.exists() and not path.is_dir():
        raise UserError(f"--record {path}: exists and is not a directory")
    if path.is_dir() and any(path.iterdir()) and not (path / "episode.json").is_file():
        raise UserError(
            f"--record {path}: a folder that is neither empty nor an episode; choose another"
        )


def tracks_csv(rows: list[TrackRow]) -> str:
    """The people tracks as ``tracks.csv`` (:data:`TRACK_COLUMNS`; mm and mm/s resolution)."""
    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(TRACK_COLUMNS)
    for t, tid, x, y, vx, vy, conf, is_target in rows:
        writer.writerow(
            [f"{t:.3f}", tid, f"{x:.3f}", f"{y:.3f}", f"{vx:.3f}", f"{vy:.3f}", f"{conf:.3f}",
             int(is_target)]
        )  # fmt: skip
    return buf.getvalue()
