"""Trajectories: a person's walk as time-stamped 2-D positions, and the text of the two
trajectory formats parsed with clear errors (the files are read by :mod:`pfctl.app.track_files`).

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

Every problem in the text raises :class:`TrajectoryFormatError`, whose message is one line
naming the source (the file, and line and field where there is one). It is a ``ValueError``:
core does not know about the CLI, the app turns it into a user error (exit status 2).
"""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

__all__ = [
    "CSV_COLUMNS",
    "Trajectory",
    "TrajectoryFormatError",
    "frame_step_of",
    "parse_csv_trajectory",
    "parse_frames",
    "trajectory_to_csv",
]

FloatArray = NDArray[np.float64]

#: The columns a CSV track must have.
CSV_COLUMNS = ("t", "x", "y")


class TrajectoryFormatError(ValueError):
    """Trajectory text that cannot be used; the message names its source (and line/field)."""


@dataclass(frozen=True, eq=False)
class Trajectory:
    """One person's recorded walk: times ``t`` (n,) in seconds, strictly increasing, and ``xy``
    (n, 2) m.

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

    def last(self, seconds: float) -> Trajectory:
        """The samples of the last ``seconds`` of the trajectory (at least the final two)."""
        keep = self.t >= self.t[-1] - seconds - 1e-9
        keep[-2:] = True
        return Trajectory(self.t[keep], self.xy[keep], self.name, self.source, self.person)


def _number(text: str, where: str, field: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise TrajectoryFormatError(f"{where}: {field}: expected a number, got {text!r}") from None
    if not math.isfinite(value):
        raise TrajectoryFormatError(f"{where}: {field}: expected a finite number, got {text!r}")
    return value


def parse_csv_trajectory(text: str, source: str, min_points: int = 2) -> Trajectory:
    """The trajectory in ``t,x,y`` CSV ``text`` (header required) read from ``source`` (a file
    name, for the messages and the trajectory's names); :class:`TrajectoryFormatError` if
    unusable.

    Checks, each reported with the source, line and field: the header has ``t``, ``x`` and ``y``;
    every row has a value for each of them; values are finite numbers; ``t`` strictly increases;
    there are at least ``min_points`` rows. Blank lines are skipped.
    """
    rows = list(csv.reader(io.StringIO(text)))
    numbered = [(i + 1, row) for i, row in enumerate(rows) if any(cell.strip() for cell in row)]
    if not numbered:
        raise TrajectoryFormatError(f"{source}: empty file, expected a header line 't,x,y'")
    header_line, header = numbered[0]
    names = [cell.strip().lower() for cell in header]
    missing = [c for c in CSV_COLUMNS if c not in names]
    if missing:
        if all(_is_number(cell) for cell in header):
            raise TrajectoryFormatError(
                f"{source}:{header_line}: no header line; "
                "the first line must name the columns t,x,y"
            )
        raise TrajectoryFormatError(
            f"{source}:{header_line}: header has no column {', '.join(missing)} "
            f"(found {', '.join(names) or 'nothing'}; expected t,x,y)"
        )
    index = {c: names.index(c) for c in CSV_COLUMNS}
    values = np.empty((len(numbered) - 1, 3))
    previous_t = -math.inf
    for k, (line, row) in enumerate(numbered[1:]):
        where = f"{source}:{line}"
        for j, column in enumerate(CSV_COLUMNS):
            i = index[column]
            if i >= len(row) or not row[i].strip():
                raise TrajectoryFormatError(f"{where}: {column}: missing value")
            values[k, j] = _number(row[i].strip(), where, column)
        if values[k, 0] <= previous_t:
            raise TrajectoryFormatError(
                f"{where}: t: time must increase, got {values[k, 0]:g} after {previous_t:g}"
            )
        previous_t = values[k, 0]
    if len(values) < min_points:
        raise TrajectoryFormatError(
            f"{source}: {len(values)} point(s), need at least {min_points} rows of t,x,y"
        )
    return Trajectory(
        values[:, 0].copy(), values[:, 1:].copy(), source, source=source, person=source
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


def parse_frames(
    text: str,
    source: str,
    fps: float,
    frame_step: float | None = None,
    min_points: int = 2,
) -> list[Trajectory]:
    """The trajectories in ``frame ped_id x y`` ``text`` read from ``source`` (a file name, for
    the messages and the trajectories' names); see the module docstring for ``fps``.

    A person's rows are sorted by frame and split wherever a step is missing; pieces shorter than
    ``min_points`` are dropped. Errors (:class:`TrajectoryFormatError`, one line, source:line:
    field): a bad ``fps`` or ``frame_step``, a row without 4 fields, a non-numeric or non-finite
    value, a frame id not on the ``frame_step`` lattice, the same person twice in one frame, no
    usable trajectory at all.
    """
    if not (math.isfinite(fps) and fps > 0):
        raise TrajectoryFormatError(f"{source}: fps must be a positive number, got {fps}")
    if frame_step is not None and not (math.isfinite(frame_step) and frame_step > 0):
        raise TrajectoryFormatError(f"{source}: frame step must be positive, got {frame_step}")
    rows: list[tuple[float, float, float, float]] = []
    lines: list[int] = []
    fields = ("frame", "ped_id", "x", "y")
    for number, raw in enumerate(text.splitlines(), start=1):
        parts = raw.split()
        if not parts or parts[0].startswith("#"):
            continue
        where = f"{source}:{number}"
        if len(parts) != 4:
            raise TrajectoryFormatError(
                f"{where}: expected 4 whitespace-separated fields 'frame ped_id x y', "
                f"got {len(parts)}"
            )
        f, p, x, y = (_number(v, where, name) for v, name in zip(parts, fields, strict=True))
        rows.append((f, p, x, y))
        lines.append(number)
    if not rows:
        raise TrajectoryFormatError(f"{source}: no data lines, expected 'frame ped_id x y' rows")
    data = np.asarray(rows)
    line_of = np.asarray(lines)
    step = frame_step if frame_step is not None else frame_step_of(data[:, 0])
    steps = (data[:, 0] - data[:, 0].min()) / step
    off = np.abs(steps - np.round(steps)) > 1e-6
    if np.any(off):
        i = int(np.argmax(off))
        raise TrajectoryFormatError(
            f"{source}:{line_of[i]}: frame: {data[i, 0]:g} is not a multiple of the frame step "
            f"{step:g} from the first frame"
        )
    k = np.round(steps).astype(np.int64)
    tracks: list[Trajectory] = []
    for ped in np.unique(data[:, 1]):
        mine = np.flatnonzero(data[:, 1] == ped)
        mine = mine[np.argsort(k[mine], kind="stable")]
        kk = k[mine]
        dup = np.flatnonzero(np.diff(kk) == 0)
        if len(dup):
            i = mine[dup[0] + 1]
            raise TrajectoryFormatError(
                f"{source}:{line_of[i]}: frame: person {ped:g} appears twice "
                f"in frame {data[i, 0]:g}"
            )
        cuts = np.flatnonzero(np.diff(kk) != 1) + 1
        for part, seg in enumerate(np.split(mine, cuts)):
            if len(seg) < min_points:
                continue
            suffix = f".{part}" if len(cuts) else ""
            tracks.append(
                Trajectory(
                    k[seg] / fps,
                    data[seg][:, 2:4].copy(),
                    name=f"{source}#{ped:g}{suffix}",
                    source=source,
                    person=f"{source}#{ped:g}",
                )
            )
    if not tracks:
        raise TrajectoryFormatError(
            f"{source}: no track has {min_points} consecutive steps (frame step {step:g})"
        )
    return tracks


def trajectory_to_csv(
    t: FloatArray, xy: FloatArray, extra: dict[str, list[str]] | None = None
) -> str:
    """``t,x,y[,extra...]`` CSV text (header first) of time-stamped points; each number is
    written as ``repr(float)``, so it reads back to the same float."""
    extra = extra or {}
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(["t", "x", "y", *extra])
    for i, (ti, (x, y)) in enumerate(zip(t, xy, strict=True)):
        writer.writerow([*(repr(float(v)) for v in (ti, x, y)), *(v[i] for v in extra.values())])
    return out.getvalue()
