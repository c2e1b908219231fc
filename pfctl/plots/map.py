"""Figures a person would rather look at than read: the map with its regions, doors and graph.

Matplotlib with the non-interactive Agg backend; figures are written as PNG atomically (a
temporary file in the same folder, then ``os.replace``). Not part of ``core``: the algorithms
never draw.
"""

from __future__ import annotations

import io
import os
from collections.abc import Sequence
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import numpy as np
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch
from matplotlib.patches import Polygon as PolygonPatch
from shapely.geometry import Polygon

from pfctl.core.mapping.grid import FREE, OCCUPIED
from pfctl.core.mapping.house import HouseLayout
from pfctl.files import write_output

XY = tuple[float, float]
Route = tuple[str, Sequence[XY], bool]
"""A person's walk: name, points, whether they are the target."""

#: Cell colours: free white, occupied black, unknown grey.
FREE_RGB = (1.0, 1.0, 1.0)
OCCUPIED_RGB = (0.0, 0.0, 0.0)
UNKNOWN_RGB = (0.62, 0.62, 0.62)
DOOR_COLOR = "#ff7f0e"
GRAPH_COLOR = "#1f3b73"


def _region_colors(n: int) -> list[tuple[float, float, float, float]]:
    cmap = matplotlib.colormaps["tab10" if n <= 10 else "tab20"]
    return [cmap(i % cmap.N) for i in range(n)]


def region_anchor(polygon: Sequence[XY]) -> XY:
    """Where a region's name and graph node go: its centroid if inside, else a point inside."""
    shape = Polygon(polygon)
    c = shape.centroid
    p = c if shape.contains(c) else shape.representative_point()
    return (float(p.x), float(p.y))


def region_graph_edges(layout: HouseLayout) -> list[tuple[str, str, XY]]:
    """The region graph's edges: one per door, ``(region a, region b, door midpoint)``."""
    names = {r.name for r in layout.regions}
    edges = []
    for d in layout.doors:
        a, b = d.between
        if a in names and b in names:
            (x0, y0), (x1, y1) = d.segment
            edges.append((a, b, ((x0 + x1) / 2.0, (y0 + y1) / 2.0)))
    return edges


def grid_rgb(states: np.ndarray) -> np.ndarray:
    """An (H, W, 3) image of a trinary state array: free white, occupied black, unknown grey."""
    rgb = np.empty((*states.shape, 3))
    rgb[...] = UNKNOWN_RGB
    rgb[states == FREE] = FREE_RGB
    rgb[states == OCCUPIED] = OCCUPIED_RGB
    return rgb


ROUTE_COLOR = "#6a6a6a"
TARGET_COLOR = "#d62728"


def _draw_routes(ax: object, routes: Sequence[Route], handles: list[object]) -> None:
    """Each person's walk: a dashed line from a square (the start) to a circle (the end); the
    target's red and thicker, the others grey, each named at its start."""
    for name, path, is_target in routes:
        xy = np.asarray(path, dtype=float).reshape(-1, 2)
        color = TARGET_COLOR if is_target else ROUTE_COLOR
        ax.plot(  # type: ignore[attr-defined]
            xy[:, 0], xy[:, 1], color=color, linewidth=2.0 if is_target else 1.2,
            linestyle="--", zorder=7,
        )  # fmt: skip
        ax.scatter(xy[:1, 0], xy[:1, 1], marker="s", s=40, color=color, zorder=8)  # type: ignore[attr-defined]
        ax.scatter(xy[-1:, 0], xy[-1:, 1], marker="o", s=30, color=color, zorder=8)  # type: ignore[attr-defined]
        ax.annotate(  # type: ignore[attr-defined]
            name, (xy[0, 0], xy[0, 1]), xytext=(4, -10), textcoords="offset points",
            fontsize=8, color=color, zorder=8,
        )  # fmt: skip
    if any(is_target for _, _, is_target in routes):
        handles.append(Line2D([], [], color=TARGET_COLOR, linestyle="--", label="target's walk"))
    if any(not is_target for _, _, is_target in routes):
        handles.append(Line2D([], [], color=ROUTE_COLOR, linestyle="--", label="other people"))


def map_figure(
    grid: object,
    layout: HouseLayout | None = None,
    region_graph: bool = True,
    title: str | None = None,
    routes: Sequence[Route] = (),
) -> Figure:
    """The map figure (see :func:`plot_map`) as a matplotlib Figure, not yet written; ``routes``:
    people's walks ``(name, (n, 2) points, is_target)`` drawn over it."""
    geometry = grid.geometry  # type: ignore[attr-defined]
    states = grid.states()  # type: ignore[attr-defined]
    xmin, xmax, ymin, ymax = geometry.extent
    aspect = (ymax - ymin) / max(xmax - xmin, 1e-9)
    width_in = 9.0
    fig = Figure(figsize=(width_in, max(3.0, min(14.0, width_in * aspect + 1.2))), dpi=110)
    ax = fig.add_subplot(1, 1, 1)
    ax.imshow(
        grid_rgb(states),
        origin="lower",
        extent=geometry.extent,
        interpolation="nearest",
        zorder=0,
    )
    handles: list[object] = []
    if layout is not None:
        colors = _region_colors(len(layout.regions))
        anchors = {r.name: region_anchor(r.polygon) for r in layout.regions}
        for region, color in zip(layout.regions, colors, strict=True):
            ax.add_patch(
                PolygonPatch(
                    np.asarray(region.polygon),
                    closed=True,
                    facecolor=(*color[:3], 0.28),
                    edgecolor=(*color[:3], 0.95),
                    linewidth=1.5,
                    zorder=1,
                )
            )
        edges = region_graph_edges(layout)
        if region_graph:
            for a, b, mid in edges:
                xs = [anchors[a][0], mid[0], anchors[b][0]]
                ys = [anchors[a][1], mid[1], anchors[b][1]]
                ax.plot(xs, ys, color=GRAPH_COLOR, linewidth=1.3, linestyle="--", zorder=3)
            if anchors:
                pts = np.asarray(list(anchors.values()))
                ax.scatter(pts[:, 0], pts[:, 1], s=36, color=GRAPH_COLOR, zorder=4)
            handles.append(
                Line2D([], [], color=GRAPH_COLOR, linestyle="--", marker="o", label="region graph")
            )
        for door in layout.doors:
            (x0, y0), (x1, y1) = door.segment
            ax.plot(
                [x0, x1],
                [y0, y1],
                color=DOOR_COLOR,
                linewidth=5,
                solid_capstyle="butt",
                zorder=5,
            )
        if layout.doors:
            handles.append(Line2D([], [], color=DOOR_COLOR, linewidth=5, label="door"))
        for region in layout.regions:
            x, y = anchors[region.name]
            ax.annotate(
                region.name,
                (x, y),
                xytext=(0, 9),
                textcoords="offset points",
                ha="center",
                va="bottom",
                fontsize=9,
                zorder=6,
                bbox={"boxstyle": "round,pad=0.2", "fc": "white", "ec": "none", "alpha": 0.8},
            )
    _draw_routes(ax, routes, handles)
    handles.append(Patch(facecolor=OCCUPIED_RGB, label="occupied"))
    handles.append(Patch(facecolor=UNKNOWN_RGB, label="unknown"))
    ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8)
    ax.set_xlim(xmin, xmax)
    ax.set_ylim(ymin, ymax)
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    n_regions = len(layout.regions) if layout is not None else 0
    n_doors = len(layout.doors) if layout is not None else 0
    ax.set_title(
        title
        or (
            f"map {geometry.width}×{geometry.height} cells at {geometry.resolution:g} m"
            + (f" — {n_regions} regions, {n_doors} doors" if layout is not None else "")
        )
    )
    fig.tight_layout()
    return fig


def plot_map(
    grid: object,
    layout: HouseLayout | None = None,
    region_graph: bool = True,
    path: str | os.PathLike[str] = "map.png",
    title: str | None = None,
) -> Path:
    """Write a PNG of an occupancy grid with its regions, doors and region graph.

    The grid (any object with ``geometry`` and ``states()``, e.g.
    :class:`pfctl.core.mapping.grid.OccupancyGrid`) is drawn free white, occupied black, unknown
    grey, in metres (``imshow(origin='lower', extent=geometry.extent)``, equal aspect). With a
    ``layout``: each region a translucent coloured polygon with its name, each door a thick orange
    segment, and with ``region_graph`` the graph of §II-B — a node per region, an edge per door
    drawn through the door's midpoint. Returns the path written.
    """
    fig = map_figure(grid, layout, region_graph, title)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", bbox_inches="tight")
    return write_output(path, buf.getvalue())


__all__ = ["grid_rgb", "map_figure", "plot_map", "region_anchor", "region_graph_edges"]
