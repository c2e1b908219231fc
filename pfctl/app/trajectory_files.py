"""Trajectory files, the inputs of ``pfctl predict``: a ``t,x,y`` CSV of one person, or the
``frame ped_id x y`` files of the ETH/UCY data sets, one file or a folder of them.

The files are read here; their text is parsed by core
(:mod:`pfctl.core.prediction.trajectories`, where the formats are described). Every problem is a
one-line :class:`~pfctl.errors.UserError` naming the file (and line and field where there is
one).
"""

from __future__ import annotations

import os
from pathlib import Path

from pfctl.core.prediction.trajectories import (
    Trajectory,
    TrajectoryFormatError,
    parse_csv_trajectory,
    parse_frames,
)
from pfctl.errors import UserError


def _read_text(path: Path) -> str:
    if not path.exists():
        raise UserError(f"{path}: no such file")
    if path.is_dir():
        raise UserError(f"{path}: is a directory, expected a trajectory file")
    try:
        return path.read_text(encoding="utf-8")
    except UnicodeDecodeError:
        raise UserError(f"{path}: not a text file (not UTF-8)") from None
    except OSError as err:
        raise UserError(f"{path}: cannot read: {err.strerror or err}") from None


def read_csv_trajectory(path: str | os.PathLike[str], min_points: int = 2) -> Trajectory:
    """The trajectory in a ``t,x,y`` CSV file (header required; at least ``min_points`` rows)."""
    path = Path(path)
    text = _read_text(path)
    try:
        return parse_csv_trajectory(text, str(path), min_points)
    except TrajectoryFormatError as err:
        raise UserError(str(err)) from None


def read_frames(
    path: str | os.PathLike[str],
    fps: float,
    frame_step: float | None = None,
    min_points: int = 2,
) -> list[Trajectory]:
    """The trajectories in a ``frame ped_id x y`` file, ``fps`` annotated steps per second
    (pieces with fewer than ``min_points`` steps dropped)."""
    path = Path(path)
    text = _read_text(path)
    try:
        return parse_frames(text, str(path), fps, frame_step, min_points)
    except TrajectoryFormatError as err:
        raise UserError(str(err)) from None


def read_trajectories(
    path: str | os.PathLike[str],
    fmt: str,
    fps: float | None = None,
    frame_step: float | None = None,
    min_points: int = 2,
) -> list[Trajectory]:
    """All trajectories of a file or a folder (recursively: ``*.csv`` for csv, ``*.txt`` for
    frames).

    ``fmt`` is ``"csv"`` or ``"frames"``; frames need ``fps``. In a folder, a CSV with fewer than
    ``min_points`` rows is an error like any other bad file.
    """
    path = Path(path)
    if fmt not in ("csv", "frames"):
        raise UserError(f"{path}: unknown format {fmt!r}, expected csv or frames")
    if fmt == "frames" and fps is None:
        raise UserError(f"{path}: the frames format needs a frame rate (fps)")
    if not path.exists():
        raise UserError(f"{path}: no such file or folder")
    if path.is_dir():
        pattern = "*.csv" if fmt == "csv" else "*.txt"
        files = sorted(p for p in path.rglob(pattern) if p.is_file())
        if not files:
            raise UserError(f"{path}: folder has no {pattern} files")
    else:
        files = [path]
    trajectories: list[Trajectory] = []
    for f in files:
        if fmt == "csv":
            trajectories.append(read_csv_trajectory(f, min_points))
        else:
            assert fps is not None
            trajectories.extend(read_frames(f, fps, frame_step, min_points))
    return trajectories


__all__ = ["read_csv_trajectory", "read_frames", "read_trajectories"]
