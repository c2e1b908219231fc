"""Trajectory files: a person's track as time-stamped 2-D positions, read with clear errors.

Two formats (the inputs of ``pfctl predict``, §II-E):

* **CSV** ``t,x,y``: one track per file, a header line naming the columns is required (extra
  columns are ignored, column order is free), ``t`` in seconds, ``x``/``y`` in metres; time must
  strictly increase.
* **Frames** ``frame ped_id x y``: the whitespace-separated format of the ETH/UCY pedestrian
  datasets, many people per file. Frame ids are converted to seconds with a frame rate given by
  the caller: ``fps`` is the number of *annotated steps per second*, and one step is the frame-id
  increment of the file (``frame_step``; when not given it is the greatest common divisor of the
  differences between the file's distinct frame ids — 10 in ETH/UCY). So
  ``t = (frame − first frame) / frame_step / fps``; ``fps=2.5`` gives the 0.4 s steps of the
  hotel and univ scenes. A person's annotations are split into separate tracks wherever a step is
  missing, so every track is evenly sampled.

Every problem a user can cause raises :class:`TrajectoryFileError`, whose message is one line
naming the file (and line and field where there is one). It is a ``ValueError``: core does not
know about the CLI, the commands turn it into a user error (exit status 2).
"""

from __future__ import annotations

import csv
import io
import math
import os
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

__all__ = [
    "CSV_COLUMNS",
    "Track",
    "TrajectoryFileError",
    "frame_step_of",
    "read_csv_track",
    "read_frames",
    "read_tracks",
    "track_to_csv",
]

FloatArray = NDArray[np.float64]

#: The columns a CSV track must have.
CSV_COLUMNS = ("t", "x", "y")


class TrajectoryFileError(ValueError):
    """A trajectory file that cannot be used; the message names the file (and line/field)."""


@dataclass(frozen=True, eq=False)
class Track:
    """One person's track: times ``t`` (n,) in seconds, strictly increasing, and ``xy`` (n, 2) m.

    ``name`` says where it came from (``file``, or ``file#ped_id`` and ``.k`` for the k-th piece of
    a person split at a missing step), ``source`` the file, ``person`` who walked it (the pieces
    of one person share it, so a train/test split by person keeps them together).
    """

    t: FloatArray
    xy: FloatArray
    name: str = ""
    source: str = ""
    person: str = ""

    def __len__(self) -> int:
        return len(self.t)

    @property
    def duration(self) -> float:
        """Time from the first to the last sample, s."""
        return float(self.t[-1] - self.t[0]) if len(self.t) else 0.0

    def last(self, seconds: float) -> Track:
        """The samples of the last ``seconds`` of the track (at least the final two)."""
        keep = self.t >= self.t[-1] - seconds - 1e-9
        keep[-2:] = True
        return Track(self.t[keep], self.xy[keep], self.name, self.source, self.person)


def _read_text(path: Path) -> str:
    if not path.exists():
        raise TrajectoryFileError(f"{path}: no such file")
    if path.is_dir():
        raise TrajectoryFileError(f"{path}: is a directory, expected a trajectory file")
    try:
        return path.read_text(encoding="utf-8")
    except UnicodeDecodeError:
        raise TrajectoryFileError(f"{path}: not a text file (not UTF-8)") from None
    except OSError as err:
        raise TrajectoryFileError(f"{path}: cannot read: {err.strerror or err}") from None


def _number(text: str, where: str, field: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise TrajectoryFileError(f"{where}: {field}: expected a number, got {text!r}") from None
    if not math.isfinite(value):
        raise TrajectoryFileError(f"{where}: {field}: expected a finite number, got {text!r}")
    return value


def read_csv_track(path: str | os.PathLike[str], min_points: int = 2) -> Track:
    """Read a ``t,x,y`` CSV track (header required); :class:`TrajectoryFileError` if unusable.

    Checks, each reported with the file, line and field: the header has ``t``, ``x`` and ``y``;
    every row has a value for each of them; values are finite numbers; ``t`` strictly increases;
    there are at least ``min_points`` rows. Blank lines are skipped.
    """
    path = Path(path)
    text = _read_text(path)
    rows = list(csv.reader(io.StringIO(text)))
    numbered = [(i + 1, row) for i, row in enumerate(rows) if any(cell.strip() for cell in row)]
    if not numbered:
        raise TrajectoryFileError(f"{path}: empty file, expected a header line 't,x,y'")
    header_line, header = numbered[0]
    names = [cell.strip().lower() for cell in header]
    missing = [c for c in CSV_COLUMNS if c not in names]
    if missing:
        if all(_is_number(cell) for cell in header):
            raise TrajectoryFileError(
                f"{path}:{header_line}: no header line; the first line must name the columns t,x,y"
            )
        raise TrajectoryFileError(
            f"{path}:{header_line}: header has no column {', '.join(missing)} "
            f"(found {', '.join(names) or 'nothing'}; expected t,x,y)"
        )
    index = {c: names.index(c) for c in CSV_COLUMNS}
    values = np.empty((len(numbered) - 1, 3))
    previous_t = -math.inf
    for k, (line, row) in enumerate(numbered[1:]):
        where = f"{path}:{line}"
        for j, column in enumerate(CSV_COLUMNS):
            i = index[column]
            if i >= len(row) or not row[i].strip():
                raise TrajectoryFileError(f"{where}: {column}: missing value")
            values[k, j] = _number(row[i].strip(), where, column)
        if values[k, 0] <= previous_t:
            raise TrajectoryFileError(
                f"{where}: t: time must increase, got {values[k, 0]:g} after {previous_t:g}"
            )
        previous_t = values[k, 0]
    if len(values) < min_points:
        raise TrajectoryFileError(
            f"{path}: {len(values)} point(s), need at least {min_points} rows of t,x,y"
        )
    return Track(
        values[:, 0].copy(), values[:, 1:].copy(), str(path), source=str(path), person=str(path)
    )


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def frame_step_of(frames: Iterable[float]) -> float:
    """The frame-id increment of a file: the gcd of the differences of its distinct frame ids."""
    distinct = np.unique(np.asarray(list(frames), dtype=float))
    if len(distinct) < 2:
        return 1.0
    diffs = np.diff(distinct)
    if np.all(np.isclose(diffs, np.round(diffs))):
        return float(np.gcd.reduce(np.round(diffs).astype(np.int64)))
    return float(diffs.min())


def read_frames(
    path: str | os.PathLike[str],
    fps: float,
    frame_step: float | None = None,
    min_points: int = 2,
) -> list[Track]:
    """Read a ``frame ped_id x y`` file into tracks (see the module docstring for ``fps``).

    A person's rows are sorted by frame and split wherever a step is missing; tracks shorter than
    ``min_points`` are dropped. Errors (one line, file:line: field): a row without 4 fields,
    a non-numeric or non-finite value, a frame id not on the ``frame_step`` lattice, the same
    person twice in one frame, no usable track at all.
    """
    path = Path(path)
    if not (math.isfinite(fps) and fps > 0):
        raise TrajectoryFileError(f"{path}: fps must be a positive number, got {fps}")
    if frame_step is not None and not (math.isfinite(frame_step) and frame_step > 0):
        raise TrajectoryFileError(f"{path}: frame step must be positive, got {frame_step}")
    text = _read_text(path)
    rows: list[tuple[float, float, float, float]] = []
    lines: list[int] = []
    fields = ("frame", "ped_id", "x", "y")
    for number, raw in enumerate(text.splitlines(), start=1):
        parts = raw.split()
        if not parts or parts[0].startswith("#"):
            continue
        where = f"{path}:{number}"
        if len(parts) != 4:
            raise TrajectoryFileError(
                f"{where}: expected 4 whitespace-separated fields 'frame ped_id x y', "
                f"got {len(parts)}"
            )
        f, p, x, y = (_number(v, where, name) for v, name in zip(parts, fields, strict=True))
        rows.append((f, p, x, y))
        lines.append(number)
    if not rows:
        raise TrajectoryFileError(f"{path}: no data lines, expected 'frame ped_id x y' rows")
    data = np.asarray(rows)
    line_of = np.asarray(lines)
    step = frame_step if frame_step is not None else frame_step_of(data[:, 0])
    steps = (data[:, 0] - data[:, 0].min()) / step
    off = np.abs(steps - np.round(steps)) > 1e-6
    if np.any(off):
        i = int(np.argmax(off))
        raise TrajectoryFileError(
            f"{path}:{line_of[i]}: frame: {data[i, 0]:g} is not a multiple of the frame step "
            f"{step:g} from the first frame"
        )
    k = np.round(steps).astype(np.int64)
    tracks: list[Track] = []
    for ped in np.unique(data[:, 1]):
        mine = np.flatnonzero(data[:, 1] == ped)
        mine = mine[np.argsort(k[mine], kind="stable")]
        kk = k[mine]
        dup = np.flatnonzero(np.diff(kk) == 0)
        if len(dup):
            i = mine[dup[0] + 1]
            raise TrajectoryFileError(
                f"{path}:{line_of[i]}: frame: person {ped:g} appears twice in frame {data[i, 0]:g}"
            )
        cuts = np.flatnonzero(np.diff(kk) != 1) + 1
        for part, seg in enumerate(np.split(mine, cuts)):
            if len(seg) < min_points:
                continue
            suffix = f".{part}" if len(cuts) else ""
            tracks.append(
                Track(
                    k[seg] / fps,
                    data[seg][:, 2:4].copy(),
                    name=f"{path}#{ped:g}{suffix}",
                    source=str(path),
                    person=f"{path}#{ped:g}",
                )
            )
    if not tracks:
        raise TrajectoryFileError(
            f"{path}: no track has {min_points} consecutive steps (frame step {step:g})"
        )
    return tracks


def read_tracks(
    path: str | os.PathLike[str],
    fmt: str,
    fps: float | None = None,
    frame_step: float | None = None,
    min_points: int = 2,
) -> list[Track]:
    """All tracks of a file or a folder (recursively: ``*.csv`` for csv, ``*.txt`` for frames).

    ``fmt`` is ``"csv"`` or ``"frames"``; frames need ``fps``. In a folder, a CSV with fewer than
    ``min_points`` rows is an error like any other bad file.
    """
    path = Path(path)
    if fmt not in ("csv", "frames"):
        raise TrajectoryFileError(f"{path}: unknown format {fmt!r}, expected csv or frames")
    if fmt == "frames" and fps is None:
        raise TrajectoryFileError(f"{path}: the frames format needs a frame rate (fps)")
    if not path.exists():
        raise TrajectoryFileError(f"{path}: no such file or folder")
    if path.is_dir():
        pattern = "*.csv" if fmt == "csv" else "*.txt"
        files = sorted(p for p in path.rglob(pattern) if p.is_file())
        if not files:
            raise TrajectoryFileError(f"{path}: folder has no {pattern} files")
    else:
        files = [path]
    tracks: list[Track] = []
    for f in files:
        if fmt == "csv":
            tracks.append(read_csv_track(f, min_points))
        else:
            assert fps is not None
            tracks.extend(read_frames(f, fps, frame_step, min_points))
    return tracks


def track_to_csv(t: FloatArray, xy: FloatArray, extra: dict[str, list[str]] | None = None) -> str:
    """``t,x,y[,extra...]`` CSV text (header first) of time-stamped points."""
    extra = extra or {}
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(["t", "x", "y", *extra])
    for i, (ti, (x, y)) in enumerate(zip(t, xy, strict=True)):
        writer.writerow([f"{ti:.6g}", f"{x:.4f}", f"{y:.4f}", *(v[i] for v in extra.values())])
    return out.getvalue()
