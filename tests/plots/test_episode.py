"""The follow/search figures (paper Fig. 4 and Fig. 6) build from a synthetic episode and render."""

from __future__ import annotations

import numpy as np
import pytest

from pfctl.core.episode import (
    EpisodeLog,
    PredictionRecord,
    SpeechRecord,
    TickRecord,
    WaypointRecord,
)
from pfctl.core.mapping.house import HouseLayout
from pfctl.core.metrics import MetricParams, follow_metrics, search_metrics
from pfctl.core.robot import GroundTruth, PersonTruth, Pose2D
from pfctl.plots.episode import search_figure, timeline_figure, trajectory_figure
from pfctl.plots.prediction import png_bytes

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
DT = 0.1


def _walk(points: list[tuple[float, float]], speed: float) -> np.ndarray:
    """Positions every DT along the polyline at ``speed`` (the last point included)."""
    pts = np.asarray(points, dtype=float)
    seg = np.hypot(*np.diff(pts, axis=0).T)
    s = np.concatenate(([0.0], np.cumsum(seg)))
    n = max(1, round(s[-1] / (speed * DT)))
    q = np.linspace(0.0, s[-1], n + 1)[1:]
    return np.column_stack((np.interp(q, s, pts[:, 0]), np.interp(q, s, pts[:, 1])))


def _hold(xy: tuple[float, float], seconds: float) -> np.ndarray:
    return np.tile(np.asarray(xy, dtype=float), (round(seconds / DT), 1))


def _along(points: list[tuple[float, float]], speed: float, n: int) -> np.ndarray:
    """``n`` positions walking the polyline at ``speed`` and then standing at its end."""
    path = _walk(points, speed)
    if len(path) >= n:
        return path[:n]
    return np.vstack([path, np.tile(path[-1], (n - len(path), 1))])


def demo_log() -> EpisodeLog:
    """A synthetic follow episode in missions/house.yaml, like the paper's experiment (§III-B).

    The robot follows alice from the kitchen into the hall, loses her at the office door (1.5 s
    lost), goes to the predicted place and looks around, searches two way-points (Algorithm 1)
    and re-acquires her in the office. On the way: a 0.2 s flicker (not a loss) and a 0.3 s blip
    on bob (not an identity switch). Bob and carol walk about as distractors.
    """
    phases: list[tuple[np.ndarray, str, str | None]] = []

    def add(xy: np.ndarray, awareness: str, action: str | None) -> None:
        phases.append((xy, awareness, action))

    add(_hold((1.0, 3.3), 0.6), "lost", None)
    follow = _walk([(1.0, 3.3), (2.45, 3.5), (2.45, 4.7), (3.55, 5.2)], 0.4)
    add(follow[:30], "visible", "follow_target")
    add(follow[30:32], "lost", "follow_target")  # flicker: 0.2 s
    add(follow[32:-10], "visible", "follow_target")
    add(follow[-10:], "tracked", "follow_target")
    add(_hold((3.55, 5.2), 1.5), "lost", None)
    add(_walk([(3.55, 5.2), (3.95, 6.0), (3.9, 6.9)], 0.4), "predicted", "go_to_prediction")
    add(_hold((3.9, 6.9), 4.0), "predicted", "look_around")
    add(_walk([(3.9, 6.9), (5.0, 7.8)], 0.4), "searching", "waypoint_search")
    add(_hold((5.0, 7.8), 1.0), "searching", "waypoint_search")
    add(_walk([(5.0, 7.8), (3.0, 7.2)], 0.4), "searching", "waypoint_search")
    add(_walk([(3.0, 7.2), (2.4, 7.35)], 0.3), "visible", "follow_target")
    add(_hold((2.4, 7.35), 2.0), "visible", "follow_target")

    robot = np.vstack([p[0] for p in phases])
    awareness = [a for p in phases for a in [p[1]] * len(p[0])]
    actions = [c for p in phases for c in [p[2]] * len(p[0])]
    n = len(robot)
    t = np.arange(n) * DT
    alice = _along(
        [(3.3, 2.2), (2.45, 3.3), (2.45, 4.7), (3.95, 5.5), (3.95, 6.5), (2.8, 7.5), (1.3, 7.4)],
        0.55,
        n,
    )
    bob = _along([(10.5, 2.0), (8.95, 3.6), (8.95, 5.0), (3.0, 5.0), (1.0, 5.2)], 0.9, n)
    carol = _along([(9.0, 8.0), (9.45, 6.5), (9.45, 5.0), (11.0, 5.0), (9.0, 3.0)], 0.5, n)
    # the blip: 3 ticks on bob where he passes nearest to alice while she is visible
    gap = np.hypot(*(bob - alice).T)
    visible = np.array([a == "visible" for a in awareness])
    gap[~visible] = np.inf
    first_loss = awareness.index("predicted")
    gap[first_loss:] = np.inf
    mid = int(np.argmin(gap))
    blip = range(mid - 1, mid + 2)
    rng = np.random.default_rng(3)
    ticks: list[TickRecord] = []
    truths: list[GroundTruth] = []
    for i in range(n):
        has = awareness[i] in ("visible", "tracked")
        seen = bob[i] if i in blip else alice[i]
        target_xy = tuple(float(v) for v in seen + rng.normal(0, 0.05, 2)) if has else None
        ticks.append(
            TickRecord(
                t=float(t[i]),
                pose=Pose2D(*(robot[i] + rng.normal(0, 0.02, 2))),
                awareness=awareness[i],
                action=actions[i],
                target_id=7 if has else None,
                target_xy=target_xy,  # type: ignore[arg-type]
            )
        )
        people = (
            PersonTruth("alice", *alice[i], 0.0, 0.55, is_target=True),
            PersonTruth("bob", *bob[i], 0.0, 0.9),
            PersonTruth("carol", *carol[i], 0.0, 0.5),
        )
        truths.append(GroundTruth(float(t[i]), Pose2D(*robot[i]), people, collisions=0))
    lost_at = awareness.index("predicted")
    predictions = [
        PredictionRecord(
            t=float(t[lost_at]),
            last_seen=(3.95, 5.6),
            path=np.array([[3.95, 5.9], [3.95, 6.3], [3.92, 6.6], [3.9, 6.9]]),
            goal=(3.9, 6.9),
        )
    ]
    first_search = awareness.index("searching")
    waypoints = [
        WaypointRecord(float(t[first_search]), (5.0, 7.8), "frontier", "office"),
        WaypointRecord(float(t[first_search]) + 4.0, (3.0, 7.2), "frontier", "office"),
    ]
    speech = [SpeechRecord(float(t[first_search]) + 6.0, (3.0, 7.2), "Excuse me")]
    return EpisodeLog(ticks, truths, predictions, waypoints, target_name="alice", speech=speech)


def _no_truth(log: EpisodeLog) -> EpisodeLog:
    return EpisodeLog(log.ticks, [], log.predictions, log.waypoints, log.target_name)


def _legend_labels(fig: object) -> list[str]:
    labels: list[str] = []
    for ax in fig.axes:  # type: ignore[attr-defined]
        for legend in [ax.get_legend(), *(a for a in ax.artists if hasattr(a, "get_texts"))]:
            if legend is not None:
                labels += [t.get_text() for t in legend.get_texts()]
    return labels


def _assert_png(fig: object) -> None:
    data = png_bytes(fig)  # type: ignore[arg-type]
    assert data.startswith(PNG_SIGNATURE)
    assert len(data) > 20_000


def test_demo_log_has_the_story() -> None:
    m = follow_metrics(demo_log())
    assert m.losses == 1
    assert [r.how for r in m.reacquisitions] == ["waypoint_search"]
    assert m.identity_switches == 0
    assert 0.3 < m.following_rate < 1.0


def test_trajectory_figure(layout: HouseLayout) -> None:
    log = demo_log()
    fig = trajectory_figure(layout, log, follow_metrics(log), title="demo")
    labels = _legend_labels(fig)
    for expected in (
        "robot: visible",
        "robot: lost",
        "robot: searching",
        "other people",
        "target lost (robot there)",
        "re-acquired (target there)",
        "door",
    ):
        assert expected in labels
    assert any(lab.startswith("target (alice)") for lab in labels)
    assert any(lab.startswith("prediction") for lab in labels)
    assert any(lab.startswith("way-point") for lab in labels)
    assert "robot spoke (asked to see a face)" in labels
    texts = [t.get_text() for t in fig.axes[0].texts]
    assert "1" in texts and "2" in texts  # numbered way-points
    assert any(t.startswith("asked t=") for t in texts)
    assert any("following rate" in t for t in texts)
    _assert_png(fig)


def test_trajectory_figure_without_truth_or_metrics(layout: HouseLayout) -> None:
    fig = trajectory_figure(layout, _no_truth(demo_log()))
    labels = _legend_labels(fig)
    assert "robot: visible" in labels
    assert "other people" not in labels
    _assert_png(fig)


def test_timeline_figure() -> None:
    log = demo_log()
    fig = timeline_figure(log, follow_metrics(log))
    assert len(fig.axes) == 3
    labels = _legend_labels(fig)
    for expected in (
        "visible",
        "tracked",
        "lost",
        "predicted",
        "searching",
        "follow_target",
        "go_to_prediction",
        "look_around",
        "waypoint_search",
        "following band",
        "true distance",
        "target lost",
        "re-acquired",
    ):
        assert expected in labels
    assert fig.axes[-1].get_xlabel() == "time [s]"
    _assert_png(fig)


def test_timeline_band_follows_the_metrics() -> None:
    log = demo_log()
    fig = timeline_figure(log, follow_metrics(log, MetricParams(band=(0.8, 1.9))))
    (band,) = [p for p in fig.axes[2].patches if p.get_label() == "following band"]
    ys = band.get_patch_transform().transform(band.get_path().vertices)[:, 1]
    assert min(ys) == pytest.approx(0.8) and max(ys) == pytest.approx(1.9)


def test_timeline_figure_without_truth_or_target() -> None:
    log = _no_truth(demo_log())
    fig = timeline_figure(log)
    assert len(fig.axes) == 3  # the estimate still has a distance row
    assert "true distance" not in _legend_labels(fig)
    _assert_png(fig)
    bare = EpisodeLog([TickRecord(0.1 * i, Pose2D(0.1 * i, 0.0), "lost", None) for i in range(20)])
    fig = timeline_figure(bare)
    assert len(fig.axes) == 2
    assert png_bytes(fig).startswith(PNG_SIGNATURE)


@pytest.mark.parametrize("found", [True, False])
def test_search_figure(layout: HouseLayout, found: bool) -> None:
    log = demo_log()
    start = next(i for i, k in enumerate(log.ticks) if k.awareness == "predicted")
    stop = (
        len(log.ticks)
        if found
        else next(i for i, k in enumerate(log.ticks) if i > start and k.awareness == "visible")
    )
    log = EpisodeLog(
        log.ticks[start:stop], log.truths[start:stop], [], log.waypoints, log.target_name
    )
    metrics = search_metrics(log)
    assert metrics.found is found
    fig = search_figure(layout, log, metrics)
    labels = _legend_labels(fig)
    assert any(lab.startswith("way-point") for lab in labels)
    assert ("target where found" in labels) is found
    title = fig.axes[0].get_title()
    assert ("found after" in title) is found
    _assert_png(fig)


def test_empty_log_figures(layout: HouseLayout) -> None:
    log = EpisodeLog()
    for fig in (trajectory_figure(layout, log), timeline_figure(log), search_figure(layout, log)):
        assert png_bytes(fig).startswith(PNG_SIGNATURE)
