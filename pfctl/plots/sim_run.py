"""The top-down picture of an episode: the house map with the robot's and everyone's paths."""

from __future__ import annotations

import io
import os
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from pfctl.core.mapping.grid import OccupancyGrid
from pfctl.core.mapping.house import HouseLayout
from pfctl.files import write_output
from pfctl.plots.map import map_figure


def plot_paths(
    grid: OccupancyGrid,
    layout: HouseLayout | None,
    robot: np.ndarray,
    people: Mapping[str, np.ndarray],
    target: str | None,
    path: str | os.PathLike[str],
    title: str | None = None,
) -> Path:
    """Write a PNG of the house (:func:`pfctl.plots.map.map_figure`) with the true paths of the
    ``robot`` (black, ``(k, 2)``), the ``target`` (red) and the other ``people`` (name →
    ``(k, 2)``); a dot marks where each one ended."""
    fig = map_figure(grid, layout, region_graph=False, title=title)
    ax = fig.axes[0]
    if len(robot):
        ax.plot(robot[:, 0], robot[:, 1], color="black", linewidth=2.0, label="robot", zorder=7)
        ax.scatter(*robot[-1], color="black", s=30, zorder=8)
    others = iter(["#1f77b4", "#2ca02c", "#9467bd", "#8c564b", "#e377c2", "#17becf"] * 5)
    for name, xy in people.items():
        color = "#d62728" if name == target else next(others)
        label = f"{name} (target)" if name == target else name
        ax.plot(xy[:, 0], xy[:, 1], color=color, linewidth=1.4, label=label, zorder=6)
        ax.scatter(*np.asarray(xy[-1]), color=color, s=24, zorder=8)
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", bbox_inches="tight")
    return write_output(path, buf.getvalue())
