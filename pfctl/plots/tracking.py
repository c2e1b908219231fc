"""The picture of ``pfctl track evaluate``: tracks against annotated people over time.

Two panels share the time axis: x and y in the laser's frame (where the annotations are). Each
annotated person is a row of wide pale discs in their id's colour, each track a thin line of
small dots in its own; a third strip marks, per annotated scan, the misses (red ×), the false
positives (orange ▲) and the ID switches (black |), so where the tracker failed reads at a glance.
"""

from __future__ import annotations

import io
from collections.abc import Sequence

import numpy as np

from pfctl.core.perception.clear_mot import ClearMotResult, FrameScore

#: Tracks are drawn this long (s) before the first and after the last annotation.
MARGIN_S = 2.0
#: A track unseen for longer than this (s) is drawn with a gap.
GAP_S = 0.5

People = Sequence[tuple[float, Sequence[int], np.ndarray]]
"""Per scan: stamp, ids and positions ``(n, 2)``."""


def _by_id(people: People, t0: float, t1: float) -> dict[int, np.ndarray]:
    """id → rows ``(t, x, y)`` within ``[t0, t1]``."""
    out: dict[int, list[tuple[float, float, float]]] = {}
    for stamp, ids, xy in people:
        if t0 <= stamp <= t1:
            for i, (x, y) in zip(ids, np.asarray(xy).reshape(-1, 2), strict=True):
                out.setdefault(int(i), []).append((stamp, float(x), float(y)))
    return {i: np.array(rows) for i, rows in out.items()}


def tracking_figure(
    truth: People,
    tracks: People,
    frames: Sequence[FrameScore],
    result: ClearMotResult,
    title: str,
    origin: float = 0.0,
) -> bytes:
    """The PNG of tracks against annotations (module docstring); times are drawn from
    ``origin`` (s, e.g. the first scan's stamp)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    truth = [(t - origin, ids, xy) for t, ids, xy in truth]
    tracks = [(t - origin, ids, xy) for t, ids, xy in tracks]
    stamps = [t for t, _, _ in truth] or [t for t, _, _ in tracks] or [0.0]
    t0, t1 = min(stamps) - MARGIN_S, max(stamps) + MARGIN_S
    fig, axes = plt.subplots(
        3, 1, figsize=(12, 8), sharex=True, gridspec_kw={"height_ratios": [3, 3, 1]}
    )
    truth_cmap, track_cmap = plt.get_cmap("Set2"), plt.get_cmap("tab20")
    for k, (pid, rows) in enumerate(sorted(_by_id(truth, t0, t1).items())):
        for axis, col in ((axes[0], 1), (axes[1], 2)):
            axis.scatter(rows[:, 0], rows[:, col], s=110, color=truth_cmap(k % 8), alpha=0.45,
                         linewidths=0, label=f"person {pid}" if col == 1 else None)  # fmt: skip
    for k, (tid, rows) in enumerate(sorted(_by_id(tracks, t0, t1).items())):
        color = track_cmap(k % 20)
        cuts = np.flatnonzero(np.diff(rows[:, 0]) > GAP_S) + 1
        for piece in np.split(np.arange(len(rows)), cuts):
            for axis, col in ((axes[0], 1), (axes[1], 2)):
                axis.plot(rows[piece, 0], rows[piece, col], ".-", color=color, ms=3, lw=0.8)
        axes[0].annotate(str(tid), (rows[0, 0], rows[0, 1]), fontsize=7, color=color)
    for name, level, marker, color in (
        ("misses", 2, "x", "red"),
        ("false_positives", 1, "^", "orange"),
        ("switches", 0, "|", "black"),
    ):
        ts = [f.stamp - origin for f in frames for _ in getattr(f, name)]
        axes[2].scatter(ts, [level] * len(ts), marker=marker, color=color, s=30)
    axes[2].set_yticks([0, 1, 2], ["ID switch", "false pos.", "miss"])
    axes[2].set_ylim(-0.7, 2.7)
    axes[0].set_ylabel("x in the laser frame (m)")
    axes[1].set_ylabel("y in the laser frame (m)")
    axes[2].set_xlabel("time from the first scan (s)")
    axes[0].legend(loc="upper right", fontsize=7, ncol=4)
    axes[0].set_title(
        f"{title}: MOTA {100 * result.mota:.1f} %, MOTP {result.motp:.3f} m, "
        f"{result.misses} misses, {result.false_positives} FP, {result.id_switches} ID switches "
        f"of {result.ground_truth} (people: pale discs; tracks: dots, id at the start)",
        fontsize=9,
    )
    axes[2].set_xlim(t0, t1)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=100, bbox_inches="tight")
    plt.close(fig)
    return buf.getvalue()


__all__ = ["tracking_figure"]
