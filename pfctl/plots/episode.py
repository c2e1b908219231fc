"""Figures of a follow or search episode, like the paper's Fig. 4 (trajectories on the house map)
and Fig. 6 (awareness, actions and distance over time), Kim et al. §III-B.

- :func:`trajectory_figure`: the annotated house (regions, doors, furniture), the robot's path
  coloured by its awareness of the target, the target's and the other people's true paths, where
  the target was lost, the predictions and way-points the robot used to find it again, and where
  it was re-acquired.
- :func:`timeline_figure`: awareness and the active action as coloured spans over time, and the
  robot–target distance (true and estimated) with the following band.
- :func:`search_figure`: a search episode's path, way-points, the target and where it was found.

Matplotlib with the Agg backend; every function returns a :class:`~matplotlib.figure.Figure`
built without pyplot (nothing to close: it is freed with its last reference). Callers write it
with :func:`pfctl.plots.prediction.png_bytes` and an atomic write. Not part of ``core``: the
algorithms never draw.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence

import matplotlib

matplotlib.use("Agg")

import numpy as np
from matplotlib.axes import Axes
from matplotlib.collections import LineCollection
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch
from matplotlib.patches import Polygon as PolygonPatch

from pfctl.core.episode import AWARENESS, EpisodeLog
from pfctl.core.mapping.grid import OccupancyGrid
from pfctl.core.mapping.house import HouseLayout
from pfctl.core.mapping.walls import rasterize_house
from pfctl.core.metrics import (
    EpisodeArrays,
    FollowMetrics,
    MetricParams,
    SearchMetrics,
    episode_arrays,
    follow_metrics,
    runs,
    search_metrics,
)
from pfctl.plots.map import map_figure, region_anchor

__all__ = [
    "ACTION_COLORS",
    "AWARENESS_COLORS",
    "search_figure",
    "summary_lines",
    "timeline_figure",
    "trajectory_figure",
]

#: One colour per awareness value (Fig. 6's top row): green while the robot has the target,
#: red when lost, orange while looking at the prediction, purple while searching.
AWARENESS_COLORS: dict[str, str] = {
    "visible": "#2ca02c",
    "tracked": "#98df8a",
    "lost": "#d62728",
    "predicted": "#ff7f0e",
    "searching": "#9467bd",
}
#: Colours of the known action leaves (Fig. 2); other actions get the next free colour.
ACTION_COLORS: dict[str, str] = {
    "follow_target": "#2ca02c",
    "gaze_at_target": "#bcbd22",
    "go_to_prediction": "#ff7f0e",
    "look_around": "#e6b422",
    "waypoint_search": "#9467bd",
    "go_to_last_seen": "#17becf",
    "stop": "#7f7f7f",
}
_SPARE_COLORS = ("#8c564b", "#e377c2", "#1f77b4", "#aec7e8", "#c49c94", "#f7b6d2", "#c7c7c7")
UNKNOWN_COLOR = "#7f7f7f"
TARGET_COLOR = "#d62728"
OTHER_COLOR = "#9a9a9a"
ROBOT_COLOR = "black"
PREDICTION_COLOR = "#01665e"
WAYPOINT_COLOR = "#6a3d9a"
REACQUIRED_COLOR = "#1a9850"
LOSS_COLOR = "#b2182b"
SPEECH_COLOR = "#1f78b4"
FURNITURE_FACE = "#c8a47e"
FURNITURE_EDGE = "#7a5230"
HOW_LABEL = {"prediction": "prediction", "waypoint_search": "way-point search", "other": "other"}


# -- shared helpers -----------------------------------------------------------------------------


def summary_lines(metrics: FollowMetrics) -> list[str]:
    """Short human lines for a figure: following rate, losses, each re-acquisition."""
    lines = [f"following rate {100.0 * metrics.following_rate:.0f} %"]
    if metrics.first_identified_s is not None:
        lines[0] += f" (identified at {metrics.first_identified_s:.1f} s)"
    else:
        lines[0] += " (target never identified)"
    found_at = {r.t_lost: r for r in metrics.reacquisitions}
    n = metrics.losses
    lines.append(f"{n} loss{'es' if n != 1 else ''}, {len(metrics.reacquisitions)} re-acquired")
    for t in metrics.loss_times:
        r = found_at.get(t)
        if r is None:
            lines.append(f"  lost {t:.1f} s → not re-acquired")
        else:
            lines.append(
                f"  lost {t:.1f} s → found {r.t_found:.1f} s "
                f"({r.time_to_refind:.1f} s, {HOW_LABEL.get(r.how, r.how)})"
            )
    extra = []
    if metrics.identity_switches:
        extra.append(f"{metrics.identity_switches} identity switch(es)")
    if metrics.collisions:
        extra.append(f"{metrics.collisions} collision(s)")
    extra.append(f"{metrics.distance_m:.1f} m in {metrics.duration_s:.1f} s")
    lines.append(", ".join(extra))
    if not metrics.ground_truth:
        lines.append("no ground truth: judged by the robot's own belief")
    return lines


def _house_map(
    layout: HouseLayout, grid: OccupancyGrid | None, title: str | None
) -> tuple[Figure, Axes]:
    """:func:`pfctl.plots.map.map_figure` of the house, plus the furniture with its names."""
    if grid is None:
        grid = rasterize_house(layout, 0.05)
    fig = map_figure(grid, layout, region_graph=False, title=title)
    width, height = fig.get_size_inches()
    fig.set_size_inches(width + 3.2, height)  # room for the legend and the summary on the right
    ax = fig.axes[0]
    for obstacle in layout.obstacles:
        ax.add_patch(
            PolygonPatch(
                np.asarray(obstacle.polygon),
                closed=True,
                facecolor=FURNITURE_FACE,
                edgecolor=FURNITURE_EDGE,
                linewidth=0.8,
                zorder=2,
            )
        )
        if obstacle.name:
            x, y = region_anchor(obstacle.polygon)
            ax.text(
                x,
                y,
                obstacle.name.replace("_", "\n"),
                ha="center",
                va="center",
                fontsize=6.5,
                style="italic",
                color="#3d2914",
                zorder=3,
            )
    return fig, ax


def _finish_legend(ax: Axes, handles: Sequence[object], note: Sequence[str] = ()) -> None:
    """Our handles first, then :func:`map_figure`'s (door, occupied, unknown), outside right;
    ``note`` lines in a box under the legend."""
    old = ax.get_legend()
    old_handles = list(old.legend_handles) if old is not None else []
    old_labels = [t.get_text() for t in old.get_texts()] if old is not None else []
    keep = [
        (h, lab)
        for h, lab in zip(old_handles, old_labels, strict=True)
        if lab not in ("occupied", "unknown")
    ]
    all_handles = [*handles, *(h for h, _ in keep)]
    labels = [h.get_label() for h in handles] + [lab for _, lab in keep]  # type: ignore[attr-defined]
    legend = ax.legend(
        handles=all_handles,
        labels=labels,
        loc="upper left",
        bbox_to_anchor=(1.01, 1.0),
        fontsize=8,
        framealpha=0.95,
    )
    legend.set_zorder(20)
    if note:
        ax.annotate(
            "\n".join(note),
            xy=(1.01, 0.0),
            xycoords="axes fraction",
            ha="left",
            va="bottom",
            fontsize=8,
            family="monospace",
            bbox={"boxstyle": "round,pad=0.4", "fc": "white", "ec": "0.6"},
        )


def _awareness_color(value: str) -> str:
    return AWARENESS_COLORS.get(value, UNKNOWN_COLOR)


def _action_colors(actions: Iterable[str]) -> dict[str, str]:
    colors: dict[str, str] = {}
    spare = iter(_SPARE_COLORS * 4)
    for name in actions:
        colors[name] = ACTION_COLORS.get(name) or next(spare, UNKNOWN_COLOR)
    return colors


def _present(values: Iterable[str], order: Sequence[str]) -> list[str]:
    """The distinct ``values``, known ones in ``order`` first, the rest as they come."""
    seen = list(dict.fromkeys(values))
    return [v for v in order if v in seen] + [v for v in seen if v not in order]


def _draw_awareness_path(ax: Axes, xy: np.ndarray, awareness: Sequence[str]) -> list[Line2D]:
    """The path ``(n, 2)`` as segments coloured by the awareness at each segment's start tick;
    legend handles for the awareness values present."""
    if len(xy) >= 2:
        seg = np.stack([xy[:-1], xy[1:]], axis=1)
        ok = ~np.isnan(seg).any(axis=(1, 2))
        colors = [_awareness_color(a) for a in awareness[:-1]]
        ax.add_collection(
            LineCollection(
                seg[ok],
                colors=[c for c, k in zip(colors, ok, strict=True) if k],
                linewidths=2.8,
                capstyle="round",
                joinstyle="round",
                zorder=7,
            )
        )
    return [
        Line2D([], [], color=_awareness_color(a), linewidth=2.8, label=f"robot: {a}")
        for a in _present(awareness, AWARENESS)
    ]


def _people_paths(log: EpisodeLog, a: EpisodeArrays) -> dict[str, np.ndarray]:
    """True paths of the people other than the target, by name (NaN where absent)."""
    names: dict[str, np.ndarray] = {}
    if not a.has_truth:
        return names
    target_name = log.target_name
    for i, g in enumerate(log.truths):
        for p in g.people:
            if p.is_target or p.name == target_name:
                continue
            if p.name not in names:
                names[p.name] = np.full((a.n, 2), np.nan)
            names[p.name][i] = (p.x, p.y)
    return names


def _index_at(t: np.ndarray, when: float) -> int:
    """The index of the tick at (or just before) ``when``."""
    return int(np.clip(np.searchsorted(t, when + 1e-9) - 1, 0, len(t) - 1))


def _draw_people(ax: Axes, log: EpisodeLog, a: EpisodeArrays) -> list[object]:
    handles: list[object] = []
    others = _people_paths(log, a)
    for xy in others.values():
        ax.plot(xy[:, 0], xy[:, 1], color=OTHER_COLOR, linewidth=1.0, alpha=0.55, zorder=5)
    if others:
        handles.append(
            Line2D([], [], color=OTHER_COLOR, linewidth=1.0, alpha=0.7, label="other people")
        )
    target = a.target_true_xy
    if a.has_truth and not np.isnan(target).all():
        ax.plot(
            target[:, 0],
            target[:, 1],
            color=TARGET_COLOR,
            linewidth=1.6,
            linestyle=(0, (5, 3)),
            zorder=6,
        )
        first = int(np.flatnonzero(~np.isnan(target[:, 0]))[0])
        ax.plot(*target[first], marker="s", markersize=8, color=TARGET_COLOR, mec="white", zorder=9)
        name = log.target_name or "target"
        handles.append(
            Line2D(
                [],
                [],
                color=TARGET_COLOR,
                linewidth=1.6,
                linestyle=(0, (5, 3)),
                label=f"target ({name}), start ■",
            )
        )
    return handles


def _draw_waypoints(ax: Axes, log: EpisodeLog) -> list[object]:
    for k, w in enumerate(log.waypoints, start=1):
        ax.plot(*w.xy, marker="^", markersize=11, color=WAYPOINT_COLOR, mec="white", zorder=10)
        ax.annotate(
            str(k),
            w.xy,
            xytext=(6, 5),
            textcoords="offset points",
            fontsize=8,
            fontweight="bold",
            color=WAYPOINT_COLOR,
            zorder=11,
            bbox={"boxstyle": "round,pad=0.1", "fc": "white", "ec": "none", "alpha": 0.8},
        )
    if not log.waypoints:
        return []
    return [
        Line2D(
            [],
            [],
            linestyle="none",
            marker="^",
            markersize=9,
            color=WAYPOINT_COLOR,
            label="way-point (Alg. 1), in order",
        )
    ]


def _draw_speech(ax: Axes, log: EpisodeLog) -> list[object]:
    """Where the robot spoke (asked someone to look at it), with the time."""
    for said in log.speech:
        ax.plot(*said.xy, marker="D", markersize=8, color=SPEECH_COLOR, mec="white", zorder=12)
        ax.annotate(
            f"asked t={said.t:.0f} s",
            said.xy,
            xytext=(7, -11),
            textcoords="offset points",
            fontsize=7.5,
            color=SPEECH_COLOR,
            zorder=13,
            bbox={"boxstyle": "round,pad=0.1", "fc": "white", "ec": "none", "alpha": 0.8},
        )
    if not log.speech:
        return []
    return [
        Line2D(
            [],
            [],
            linestyle="none",
            marker="D",
            markersize=7,
            color=SPEECH_COLOR,
            label="robot spoke (asked to see a face)",
        )
    ]


def _draw_robot_start(ax: Axes, xy: np.ndarray) -> list[object]:
    ok = np.flatnonzero(~np.isnan(xy[:, 0]))
    if len(ok) == 0:
        return []
    ax.plot(*xy[ok[0]], marker="s", markersize=9, color=ROBOT_COLOR, mec="white", zorder=12)
    ax.plot(*xy[ok[-1]], marker="o", markersize=6, color=ROBOT_COLOR, mec="white", zorder=12)
    return [
        Line2D(
            [],
            [],
            linestyle="none",
            marker="s",
            color=ROBOT_COLOR,
            label="robot start (■), end (●)",
        )
    ]


# -- Fig. 4: trajectories on the map ------------------------------------------------------------


def trajectory_figure(
    layout: HouseLayout,
    log: EpisodeLog,
    metrics: FollowMetrics | None = None,
    title: str | None = None,
    grid: OccupancyGrid | None = None,
    params: MetricParams | None = None,
) -> Figure:
    """The episode on the house map, like the paper's Fig. 4.

    The house (regions with names, doors, furniture) from ``layout`` over ``grid`` (the layout
    rasterised at 5 cm when none is given); the robot's true path (believed without truth)
    coloured by its awareness at each tick; the target's true path dashed red, the other people's
    faint grey; start markers; × where the robot was at each loss; every prediction (line from
    where the target was last seen, star at the goal); the way-points in order (numbered
    triangles); a circle at the target where it was re-acquired. ``metrics`` (computed from the
    log with ``params`` when not given) are summarised in a box under the legend.
    """
    metrics = metrics or follow_metrics(log, params)
    a = episode_arrays(log, params)
    fig, ax = _house_map(layout, grid, title or "follow episode")
    handles: list[object] = []
    awareness = [k.awareness for k in log.ticks]
    handles += _draw_awareness_path(ax, a.robot_xy, awareness)
    handles += _draw_robot_start(ax, a.robot_xy)
    handles += _draw_people(ax, log, a)

    for p in log.predictions:
        path = np.vstack([np.asarray(p.last_seen, dtype=float)[None, :], np.asarray(p.path)])
        ax.plot(
            path[:, 0],
            path[:, 1],
            color=PREDICTION_COLOR,
            linewidth=2.0,
            linestyle="-",
            marker=".",
            markersize=4,
            zorder=9,
        )
        ax.plot(*p.last_seen, marker="o", markersize=5, color=PREDICTION_COLOR, zorder=10)
        ax.plot(*p.goal, marker="*", markersize=16, color=PREDICTION_COLOR, mec="black", zorder=10)
    if log.predictions:
        handles.append(
            Line2D(
                [],
                [],
                color=PREDICTION_COLOR,
                linewidth=2.0,
                marker="*",
                markersize=12,
                mec="black",
                label="prediction: path, goal ★",
            )
        )
    handles += _draw_waypoints(ax, log)
    handles += _draw_speech(ax, log)

    if a.n and metrics.loss_times:
        idx = [_index_at(a.t, t) for t in metrics.loss_times]
        xy = a.robot_xy[idx]
        ax.scatter(
            xy[:, 0], xy[:, 1], marker="X", s=150, color=LOSS_COLOR, ec="white", lw=1.0, zorder=13
        )
        for t, (x, y) in zip(metrics.loss_times, xy, strict=True):
            ax.annotate(
                f"lost t={t:.0f} s",
                (x, y),
                xytext=(8, -12),
                textcoords="offset points",
                fontsize=7.5,
                color=LOSS_COLOR,
                zorder=13,
                bbox={"boxstyle": "round,pad=0.1", "fc": "white", "ec": "none", "alpha": 0.8},
            )
        handles.append(
            Line2D(
                [],
                [],
                linestyle="none",
                marker="X",
                markersize=10,
                color=LOSS_COLOR,
                mec="white",
                label="target lost (robot there)",
            )
        )
    if a.n and metrics.reacquisitions:
        where = a.target_true_xy if a.has_truth else a.target_xy
        for r in metrics.reacquisitions:
            i = _index_at(a.t, r.t_found)
            x, y = where[i] if not np.isnan(where[i]).any() else a.target_xy[i]
            ax.plot(
                x,
                y,
                marker="o",
                markersize=17,
                mfc="none",
                mec=REACQUIRED_COLOR,
                mew=2.5,
                zorder=13,
            )
            ax.annotate(
                f"found t={r.t_found:.0f} s",
                (x, y),
                xytext=(10, 8),
                textcoords="offset points",
                fontsize=7.5,
                color=REACQUIRED_COLOR,
                zorder=13,
                bbox={"boxstyle": "round,pad=0.1", "fc": "white", "ec": "none", "alpha": 0.8},
            )
        handles.append(
            Line2D(
                [],
                [],
                linestyle="none",
                marker="o",
                markersize=11,
                mfc="none",
                mec=REACQUIRED_COLOR,
                mew=2.0,
                label="re-acquired (target there)",
            )
        )
    _finish_legend(ax, handles, summary_lines(metrics))
    fig.tight_layout()
    return fig


# -- Fig. 6: the timeline -----------------------------------------------------------------------


def _spans(
    ax: Axes,
    t: np.ndarray,
    period: float,
    values: Sequence[str | None],
    colors: dict[str, str],
) -> None:
    """Each maximal run of equal non-None ``values`` as a span [t_start, t_end + period)."""
    labels = np.asarray([v if v is not None else "" for v in values], dtype=object)
    for name, color in colors.items():
        starts, ends = runs(labels == name)
        if len(starts):
            width = t[ends] - t[starts] + period
            ax.broken_barh(
                list(zip(t[starts], width, strict=True)),
                (0.0, 1.0),
                facecolors=color,
                edgecolors="none",
            )


def _row_legend(ax: Axes, colors: dict[str, str]) -> None:
    ax.legend(
        handles=[Patch(facecolor=c, label=n) for n, c in colors.items()],
        loc="upper left",
        bbox_to_anchor=(1.005, 1.0),
        fontsize=8,
        frameon=False,
        borderaxespad=0.0,
    )


def _event_lines(axes: Sequence[Axes], metrics: FollowMetrics) -> list[object]:
    handles: list[object] = []
    for ax in axes:
        for t in metrics.loss_times:
            ax.axvline(t, color=LOSS_COLOR, linestyle="--", linewidth=1.3, zorder=5)
        for r in metrics.reacquisitions:
            ax.axvline(r.t_found, color=REACQUIRED_COLOR, linestyle="-", linewidth=1.6, zorder=5)
    if metrics.loss_times:
        handles.append(Line2D([], [], color=LOSS_COLOR, linestyle="--", label="target lost"))
    if metrics.reacquisitions:
        handles.append(Line2D([], [], color=REACQUIRED_COLOR, label="re-acquired"))
    return handles


def timeline_figure(
    log: EpisodeLog,
    metrics: FollowMetrics | None = None,
    params: MetricParams | None = None,
) -> Figure:
    """The episode over time, like the paper's Fig. 6.

    Row 1: the robot's awareness of the target as coloured spans (:data:`AWARENESS_COLORS`);
    row 2: the action leaf that ran (:data:`ACTION_COLORS`; ticks without an action are blank);
    row 3, when there is a distance to show (truths, or any target estimate): the true
    robot–target distance (black), the follower's own estimate from its pose and ``target_xy``
    (blue) and the following band shaded green (``params.band``, else the band ``metrics`` were
    measured with). Dashed red lines mark each loss,
    green lines each re-acquisition. The title summarises ``metrics`` (computed when not given).
    """
    if params is None:
        params = MetricParams(band=metrics.band) if metrics is not None else MetricParams()
    metrics = metrics or follow_metrics(log, params)
    a = episode_arrays(log, params)
    show_distance = a.has_truth or bool(np.isfinite(a.estimated_distance).any())
    nrows = 3 if show_distance else 2
    ratios = [0.7, 0.7, 2.6][:nrows]
    fig = Figure(figsize=(11.0, 2.2 + 1.25 * sum(ratios)), dpi=110)
    axes = list(fig.subplots(nrows, 1, sharex=True, gridspec_kw={"height_ratios": ratios}))
    t = a.t
    t0 = float(t[0]) if a.n else 0.0
    t1 = float(t[-1] + a.period) if a.n else 1.0

    awareness = [k.awareness for k in log.ticks]
    aw_colors = {v: _awareness_color(v) for v in _present(awareness, AWARENESS)}
    _spans(axes[0], t, a.period, awareness, aw_colors)
    _row_legend(axes[0], aw_colors)
    axes[0].set_ylabel("awareness", rotation=0, ha="right", va="center")

    actions = [k.action for k in log.ticks]
    act_colors = _action_colors(_present((x for x in actions if x), tuple(ACTION_COLORS)))
    _spans(axes[1], t, a.period, actions, act_colors)
    _row_legend(axes[1], act_colors)
    axes[1].set_ylabel("action", rotation=0, ha="right", va="center")
    for ax in axes[:2]:
        ax.set_yticks([])
        ax.set_ylim(0.0, 1.0)
        for side in ("top", "right", "left"):
            ax.spines[side].set_visible(False)

    event_handles = _event_lines(axes, metrics)
    if show_distance:
        ax = axes[2]
        lo, hi = params.band
        band = ax.axhspan(lo, hi, color="#2ca02c", alpha=0.13, lw=0, label="following band")
        handles: list[object] = [band]
        if a.has_truth:
            (true_line,) = ax.plot(
                t, a.true_distance, color="black", linewidth=1.6, label="true distance"
            )
            handles.append(true_line)
        (est_line,) = ax.plot(
            t,
            a.estimated_distance,
            color="#1f77b4",
            linewidth=1.2,
            alpha=0.9,
            label="estimated (pose → target track)",
        )
        handles.append(est_line)
        if a.has_truth and a.wrong.any():
            starts, ends = runs(a.wrong)
            for s, e in zip(starts, ends, strict=True):
                ax.axvspan(t[s], t[e] + a.period, color="#e377c2", alpha=0.25, lw=0)
            handles.append(Patch(facecolor="#e377c2", alpha=0.4, label="wrong person tracked"))
        ax.set_ylabel("robot–target\ndistance [m]")
        top = np.nanmax(np.concatenate([a.true_distance, a.estimated_distance, [hi]]))
        ax.set_ylim(0.0, float(top) * 1.08 + 0.1)
        ax.grid(True, alpha=0.3)
        ax.legend(
            handles=[*handles, *event_handles],
            loc="upper left",
            bbox_to_anchor=(1.005, 1.0),
            fontsize=8,
            frameon=False,
            borderaxespad=0.0,
        )
    elif event_handles:
        axes[1].legend(
            handles=[*event_handles],
            loc="lower left",
            bbox_to_anchor=(1.005, -0.6),
            fontsize=8,
            frameon=False,
        )
    axes[-1].set_xlim(t0, t1)
    axes[-1].set_xlabel("time [s]")
    lines = summary_lines(metrics)
    fig.suptitle("follow episode — " + "; ".join([lines[0], lines[1]]), fontsize=11)
    fig.tight_layout()
    return fig


# -- a search episode ---------------------------------------------------------------------------


def search_figure(
    layout: HouseLayout,
    log: EpisodeLog,
    metrics: SearchMetrics | None = None,
    title: str | None = None,
    grid: OccupancyGrid | None = None,
    params: MetricParams | None = None,
) -> Figure:
    """A search episode on the house map: the robot's path coloured by awareness, the way-points
    in order, the target's true path (or position), and a circle where the target was found,
    with the robot's position at that moment; the title says whether, when and at what cost."""
    metrics = metrics or search_metrics(log, params)
    a = episode_arrays(log, params)
    if metrics.found and metrics.time_to_find_s is not None:
        summary = (
            f"found after {metrics.time_to_find_s:.1f} s, {metrics.distance_m:.1f} m driven"
            + (f", {metrics.collisions} collision(s)" if metrics.collisions else "")
        )
    else:
        duration = float(a.t[-1] - a.t[0]) if a.n else 0.0
        summary = f"not found in {duration:.1f} s ({metrics.distance_m:.1f} m driven)"
    fig, ax = _house_map(layout, grid, (title or "search episode") + " — " + summary)
    handles: list[object] = []
    handles += _draw_awareness_path(ax, a.robot_xy, [k.awareness for k in log.ticks])
    handles += _draw_robot_start(ax, a.robot_xy)
    handles += _draw_people(ax, log, a)
    handles += _draw_waypoints(ax, log)
    handles += _draw_speech(ax, log)
    correct = np.flatnonzero(a.correct)
    if metrics.found and len(correct):
        i = int(correct[0])
        where = a.target_true_xy[i] if a.has_truth else a.target_xy[i]
        if np.isnan(where).any():
            where = a.target_xy[i]
        ax.plot(
            *where, marker="o", markersize=17, mfc="none", mec=REACQUIRED_COLOR, mew=2.5, zorder=13
        )
        ax.plot(
            *a.robot_xy[i], marker="D", markersize=8, color=REACQUIRED_COLOR, mec="white", zorder=13
        )
        ax.annotate(
            f"found t={a.t[i]:.0f} s",
            tuple(where),
            xytext=(10, 8),
            textcoords="offset points",
            fontsize=8,
            color=REACQUIRED_COLOR,
            zorder=13,
            bbox={"boxstyle": "round,pad=0.1", "fc": "white", "ec": "none", "alpha": 0.8},
        )
        handles.append(
            Line2D(
                [],
                [],
                linestyle="none",
                marker="o",
                markersize=11,
                mfc="none",
                mec=REACQUIRED_COLOR,
                mew=2.0,
                label="target where found",
            )
        )
        handles.append(
            Line2D(
                [],
                [],
                linestyle="none",
                marker="D",
                markersize=7,
                color=REACQUIRED_COLOR,
                label="robot when found",
            )
        )
    elif a.has_truth and not np.isnan(a.target_true_xy[-1]).any():
        ax.plot(*a.target_true_xy[-1], marker="*", markersize=14, color=TARGET_COLOR, zorder=12)
    _finish_legend(ax, handles)
    fig.tight_layout()
    return fig
