"""Figures of trajectory prediction (§II-E, §III-B): a track with every model's prediction on the
map, and the door experiment's three panels (truth vs SVR vs cubic polynomial, as in the paper).

Matplotlib with the Agg backend; the functions return figures or PNG bytes, the commands write
them atomically (:func:`pfctl.files.write_output`). Not part of ``core``: the algorithms never draw.
"""

from __future__ import annotations

import io
from collections.abc import Mapping

import matplotlib

matplotlib.use("Agg")

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from numpy.typing import NDArray

from pfctl.core.mapping.grid import OccupancyGrid
from pfctl.core.mapping.house import HouseLayout
from pfctl.core.prediction.door_experiment import CASES, DOOR_WIDTH, DoorExperiment
from pfctl.plots.map import map_figure

__all__ = ["MODEL_STYLE", "door_figure", "png_bytes", "prediction_figure"]

FloatArray = NDArray[np.float64]

#: Colour and line style of each model in every figure.
MODEL_STYLE: dict[str, dict[str, object]] = {
    "svr": {"color": "#d62728", "linestyle": "-", "linewidth": 2.2},
    "svr-time": {"color": "#9467bd", "linestyle": "-.", "linewidth": 1.5},
    "poly3": {"color": "#2ca02c", "linestyle": "--", "linewidth": 2.0},
    "cv": {"color": "#7f7f7f", "linestyle": ":", "linewidth": 1.6},
}
HISTORY_COLOR = "#1f77b4"
TRUTH_COLOR = "black"


def png_bytes(fig: Figure) -> bytes:
    """The figure as PNG bytes (written by the caller, atomically)."""
    buf = io.BytesIO()
    fig.savefig(buf, format="png", bbox_inches="tight")
    return buf.getvalue()


def _style(name: str) -> dict[str, object]:
    return MODEL_STYLE.get(name, {"linewidth": 1.5})


def _draw_path(ax: Axes, start: FloatArray, path: FloatArray, label: str, **style: object) -> None:
    xy = np.vstack([start[None, :], path])
    ax.plot(xy[:, 0], xy[:, 1], label=label, zorder=7, **style)  # type: ignore[arg-type]
    ax.plot(*path[-1], marker="o", markersize=5, color=style.get("color"), zorder=8)


def prediction_figure(
    history: FloatArray,
    predictions: Mapping[str, FloatArray],
    clipped: Mapping[str, FloatArray] | None = None,
    grid: OccupancyGrid | None = None,
    layout: HouseLayout | None = None,
    title: str = "",
    region: str | None = None,
) -> Figure:
    """The observed ``history`` (n, 2), every model's predicted path and, with a map, the map and
    its regions. ``clipped`` paths (same keys) are drawn solid over the raw predictions, which
    are then drawn faint: the part of a raw prediction beyond the clipped one went through a wall.
    """
    if grid is not None:
        fig = map_figure(grid, layout, region_graph=False, title=title or None)
        ax = fig.axes[0]
    else:
        fig = Figure(figsize=(8.0, 6.0), dpi=110)
        ax = fig.add_subplot(1, 1, 1)
        ax.set_aspect("equal")
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        ax.grid(True, alpha=0.3)
        if title:
            ax.set_title(title)
    start = history[-1]
    ax.plot(
        history[:, 0],
        history[:, 1],
        color=HISTORY_COLOR,
        marker=".",
        linewidth=1.5,
        label="history",
        zorder=6,
    )
    ax.plot(*start, marker="s", color=HISTORY_COLOR, markersize=7, zorder=9, label="last seen")
    for name, path in predictions.items():
        style = dict(_style(name))
        if clipped is not None and name in clipped:
            faint = {**style, "alpha": 0.35, "linewidth": 1.0}
            xy = np.vstack([start[None, :], path])
            ax.plot(xy[:, 0], xy[:, 1], zorder=6, **faint)  # type: ignore[arg-type]
            _draw_path(ax, start, clipped[name], f"{name} (clipped)", **style)
        else:
            _draw_path(ax, start, path, name, **style)
    if region is not None:
        ax.annotate(
            f"predicted region: {region}",
            xy=(0.01, 0.01),
            xycoords="axes fraction",
            fontsize=9,
            bbox={"boxstyle": "round,pad=0.3", "fc": "white", "ec": "0.5", "alpha": 0.9},
        )
    if grid is None:
        ax.legend(loc="best", fontsize=8)
    else:
        handles, labels = ax.get_legend_handles_labels()
        old = ax.get_legend()
        old_handles = list(old.legend_handles) if old is not None else []
        old_labels = [t.get_text() for t in old.get_texts()] if old is not None else []
        ax.legend(
            handles=[*handles, *old_handles],
            labels=[*labels, *old_labels],
            loc="upper left",
            bbox_to_anchor=(1.01, 1.0),
            fontsize=8,
        )
        fig.tight_layout()
    return fig


def door_figure(result: DoorExperiment, models: tuple[str, ...] = ("svr", "poly3")) -> Figure:
    """Three panels (left, straight, right) like the paper's door figure: the wall and door,
    the observed history up to the loss, the true hidden path, and each model's prediction."""
    fig = Figure(figsize=(13.5, 5.0), dpi=110)
    axes = fig.subplots(1, len(CASES), sharey=True)
    errors = result.mean_errors()
    for ax, case in zip(axes, CASES, strict=True):
        walk = result.examples[case]
        seen = walk.t <= walk.t_loss + 1e-9
        hidden = (walk.t >= walk.t_loss - 1e-9) & (walk.t <= walk.t_loss + max(result.horizons))
        half = DOOR_WIDTH / 2.0
        ax.plot([0, 0], [-6, -half], color="black", linewidth=4, solid_capstyle="butt")
        ax.plot([0, 0], [half, 6], color="black", linewidth=4, solid_capstyle="butt")
        ax.plot([0, 0], [-half, half], color="#ff7f0e", linewidth=4, alpha=0.6, label="door")
        _, hist_xy = walk.history(result.history_s)
        ax.plot(
            walk.observed[seen, 0],
            walk.observed[seen, 1],
            color=HISTORY_COLOR,
            alpha=0.35,
            linewidth=1,
        )
        ax.plot(hist_xy[:, 0], hist_xy[:, 1], ".", color=HISTORY_COLOR, markersize=4, label="seen")
        ax.plot(
            walk.xy[hidden, 0],
            walk.xy[hidden, 1],
            color=TRUTH_COLOR,
            linewidth=2,
            label="truth (hidden)",
        )
        start = hist_xy[-1]
        for name in models:
            if name in result.paths[case]:
                _draw_path(ax, start, result.paths[case][name], name, **_style(name))
        for h in result.horizons:
            p = walk.truth_at(np.array([walk.t_loss + h]))[0]
            ax.plot(*p, marker="x", color=TRUTH_COLOR, markersize=7)
        lines = [
            f"{name}: " + ", ".join(f"{e:.2f}" for e in errors[case][name])
            for name in models
            if name in errors[case]
        ]
        hs = "/".join(f"{h:g}" for h in result.horizons)
        ax.set_title(f"{case}\nmean error at {hs} s ({result.walks} walks):\n" + "\n".join(lines))
        ax.set_aspect("equal")
        ax.set_xlim(-3.5, 4.5)
        ax.set_ylim(-4.5, 4.5)
        ax.grid(True, alpha=0.3)
        ax.set_xlabel("x [m]")
    axes[0].set_ylabel("y [m]")
    axes[0].legend(loc="lower left", fontsize=8)
    fig.suptitle(
        f"door experiment: target lost at the door, seed {result.seed}; "
        f"models fitted on the last {result.history_s:g} s"
    )
    fig.tight_layout()
    return fig
