"""``tracks.csv``: the people tracks a run saw, one row per track after each scan (``pfctl replay``
writes it for a bag, ``pfctl follow`` for an episode; the same columns, so the two compare)."""

from __future__ import annotations

import csv
import io

from pfctl.core.episode import TrackRow

#: The columns of ``tracks.csv``.
TRACK_COLUMNS = ("t", "track_id", "x", "y", "vx", "vy", "confidence", "is_target")


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


__all__ = ["TRACK_COLUMNS", "tracks_csv"]
