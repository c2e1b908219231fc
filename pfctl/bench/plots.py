"""``boxplots.png``: one panel per metric, one box per mission and variant.

Each box is the episodes' values (for re-find success, the episodes that lost the target; for
the time to re-find, every re-acquisition; for the time to find, the episodes that found the
target), the dots the values themselves, and the black diamond with its bar the mean and 95 %
bootstrap interval of :mod:`pfctl.bench.aggregate`. Matplotlib's Agg backend (no display);
figures are returned as PNG bytes for the caller to write atomically.
"""

from __future__ import annotations

import io
import math
from collections.abc import Sequence

import matplotlib

matplotlib.use("Agg")

import numpy as np
from matplotlib.figure import Figure

from pfctl.bench.aggregate import GroupSummary, Metric

__all__ = ["boxplots_figure", "boxplots_png"]


def _label(summary: GroupSummary, with_mission: bool) -> str:
    # one line per KEY=VALUE, broken after the "=" (long values are the common case)
    variant = "\n".join(part.replace("=", "=\n", 1) for part in summary.variant.split(" "))
    if not with_mission:
        return variant
    return summary.mission if summary.variant == "base" else f"{summary.mission}\n{variant}"


def boxplots_figure(
    summaries: Sequence[GroupSummary], metrics: Sequence[Metric], title: str
) -> Figure:
    """The box plots (module docstring) as a matplotlib figure."""
    with_mission = len({s.mission for s in summaries}) > 1 or all(
        s.variant == "base" for s in summaries
    )
    labels = [_label(s, with_mission) for s in summaries]
    cols = min(3, len(metrics))
    rows = math.ceil(len(metrics) / cols)
    longest = max(len(line) for label in labels for line in label.splitlines())
    width = max(4.0, len(summaries) * max(0.9, 0.075 * longest) + 1.2)
    fig = Figure(figsize=(cols * width, rows * 3.6 + 0.6), layout="constrained")
    axes = fig.subplots(rows, cols, squeeze=False).ravel()
    rng = np.random.default_rng(0)  # the dots' horizontal jitter
    x = np.arange(len(summaries))
    for ax, metric in zip(axes, metrics, strict=False):
        scale = 100.0 if metric.percent else 1.0
        data = [np.asarray(s.values[metric.name], dtype=float) * scale for s in summaries]
        if any(len(d) for d in data):
            ax.boxplot(
                [d if len(d) else [math.nan] for d in data],
                positions=x,
                widths=0.5,
                showfliers=False,
                medianprops={"color": "tab:blue"},
            )
            for i, d in enumerate(data):
                ax.scatter(
                    i + rng.uniform(-0.12, 0.12, len(d)), d, s=9, color="0.35", alpha=0.6, zorder=3
                )
        else:
            ax.text(0.5, 0.5, "no values", ha="center", va="center", transform=ax.transAxes)
        for i, s in enumerate(summaries):
            e = s.estimates[metric.name]
            if e.mean is None:
                continue
            if e.low is not None and e.high is not None:
                err = [[(e.mean - e.low) * scale], [(e.high - e.mean) * scale]]
                ax.errorbar(i + 0.3, e.mean * scale, yerr=err, color="k", capsize=3, zorder=4)
            ax.plot(i + 0.3, e.mean * scale, marker="D", color="k", markersize=4, zorder=5)
        unit = "%" if metric.percent else metric.unit
        ax.set_title(metric.label + (f" ({unit})" if unit else ""), fontsize=10)
        ax.set_xticks(x, labels, fontsize=8)
        ax.set_xlim(-0.6, len(summaries) - 0.4)
        if metric.percent:
            ax.set_ylim(-5, 105)
        ax.grid(axis="y", alpha=0.3)
    for ax in axes[len(metrics) :]:
        ax.set_visible(False)
    fig.suptitle(f"{title}  (box: episodes; ◆ and bar: mean and 95% bootstrap interval)")
    return fig


def boxplots_png(summaries: Sequence[GroupSummary], metrics: Sequence[Metric], title: str) -> bytes:
    """:func:`boxplots_figure` as PNG bytes."""
    fig = boxplots_figure(summaries, metrics, title)
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=110)
    return buffer.getvalue()
