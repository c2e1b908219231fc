"""How well an episode followed (or found) its target: the numbers behind the paper's §III-B.

The paper's experiment (Kim et al., §III-B, Fig. 4 and Fig. 6) follows a target from the kitchen,
loses it on the way to the office, predicts where it went, looks there, searches by way-points
(Algorithm 1) and re-identifies it. These metrics say, for a recorded :class:`EpisodeLog`, how much
of the time the robot really followed the right person, how often it lost them, how it found them
again and how long that took. They compare what the robot believed (:class:`TickRecord`) with the
simulator's truth (:attr:`EpisodeLog.truths`); the follower itself never sees truth.

Definitions (``n`` ticks, truth ``truths[i]`` at tick ``i``; :class:`MetricParams` holds the
thresholds):

- **target person**: in each truth, the :class:`~pfctl.core.robot.PersonTruth` with ``is_target``
  or whose name is :attr:`EpisodeLog.target_name` (the first such person).
- **correct** tick: awareness in :data:`HAS_TARGET`, ``target_xy`` known, within ``match_radius``
  of the true target, and the true target is the person nearest to ``target_xy`` (ties count for
  the target).
- **wrong** tick: awareness in :data:`HAS_TARGET`, ``target_xy`` known, and some other person is
  within ``match_radius`` of it and nearer than the target. A tick can be neither (the estimate is
  far from everyone, e.g. a fresh track): such ticks are neutral.
- **tick period**: the median spacing of the ticks' ``t`` (0 with fewer than two ticks); the
  **duration** of a run of ticks ``i..j`` is ``t[j] - t[i] + period``.
- **first identification**: ``t`` of the first correct tick (``None`` if there is none).
- **following rate**: among the ticks from the first identification on, the share that are
  correct *and* whose true robot–target distance lies within ``band`` (closed interval) — the
  robot had the right person at a following distance. 0.0 if the target was never identified.
- **loss**: a maximal run of ticks after the first identification whose awareness is not in
  :data:`HAS_TARGET`, lasting at least ``min_loss_s`` (shorter gaps are flicker). Its ``t_lost``
  is the run's first tick's ``t``. It is **re-acquired** at the first correct tick after the run
  and before the next loss begins (ticks with the target in between that are wrong or neutral,
  and flicker gaps, do not end the search); ``t_found`` is that tick's ``t``. A loss with no
  such tick is not re-acquired (``losses - len(reacquisitions)`` of them).
- **how** a loss was re-acquired: the last search action among the ticks from ``t_lost`` up to
  (not including) ``t_found``: ``go_to_prediction`` or ``look_around`` → ``"prediction"``,
  ``waypoint_search`` → ``"waypoint_search"``, none of them → ``"other"``. The last one wins: a
  prediction that was looked at and then a way-point search is ``"waypoint_search"``.
- **identity switch**: a maximal run of wrong ticks (anywhere in the episode) lasting at least
  ``min_switch_s``; shorter wrong blips do not count.
- **collisions**: the last truth's ``collisions`` (0 without truths).
- **distance**: the path length of the true robot positions, or of the believed poses
  (``ticks[i].pose``) when there are no truths.
- **duration**: ``t`` of the last tick − ``t`` of the first + period (0 without ticks).

Search episodes (:func:`search_metrics`): **found** when a correct tick exists;
``time_to_find_s`` is its ``t`` minus the first tick's ``t``; ``distance_m`` and ``collisions``
count up to that tick (the cost of finding), over the whole episode when the target was never
found.

Room prediction (:func:`room_prediction_scores`): at each loss the follower logged which room the
belief over where she can be predicts for ``horizon_s`` later (:class:`RoomPredictionRecord`, the
last one made at or before ``t_lost``); its **top-1** / **top-2** hit when the room the true
target is in at ``t_lost + horizon_s`` is its first / among its first two. The baseline is
Algorithm 1's answer, "the room she was last seen heading to": l* (her own room when she
approached no door) for top-1, l* then her own room for top-2. Losses whose horizon runs past the
episode's end, or whose true position lies in no region, are not scored.

Without truths (a real robot) nothing can say whether the track was the right person, so the
robot's belief stands in: a tick is correct when its awareness is in :data:`HAS_TARGET`, no tick
is wrong (``identity_switches`` is 0), and the following rate uses the robot's own estimate of
the distance, from its believed pose to ``target_xy`` (a tick without ``target_xy`` is not
counted as within the band). The metrics then say ``ground_truth=False``. The believed path's
length includes the localisation's jitter, so it reads longer than the true one would.

Everything is vectorised with numpy: a 3000-tick episode takes a few milliseconds.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pfctl.core.episode import HAS_TARGET, EpisodeLog, tick_columns, truth_columns
from pfctl.core.mapping.regions import RegionMap
from pfctl.core.params import param

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]

#: Actions that count as "went to the predicted place and looked there".
PREDICTION_ACTIONS = ("go_to_prediction", "look_around")
#: The way-point search action (Algorithm 1).
WAYPOINT_ACTIONS = ("waypoint_search",)
#: The values of :attr:`Reacquisition.how`.
HOW = ("prediction", "waypoint_search", "other")

_EPS = 1e-9


@dataclass(frozen=True)
class MetricParams:
    """Thresholds of the metrics (see the module docstring)."""

    band: tuple[float, float] = param(
        (0.5, 2.5),
        "A tick counts as following when the target is identified and its true distance from the"
        " robot lies in this closed interval [low, high].",
        unit="m",
        ordered=True,
    )
    match_radius: float = 0.8
    """A track within this of a person is that person, m."""
    min_loss_s: float = 1.0
    """Shorter gaps without the target are flicker, not losses, s."""
    min_switch_s: float = 0.5
    """Shorter wrong-person runs are not identity switches, s."""


@dataclass(frozen=True)
class Reacquisition:
    """A loss and when (and by which behaviour) the target was correctly found again."""

    t_lost: float
    t_found: float
    how: str
    """One of :data:`HOW`: ``prediction``, ``waypoint_search`` or ``other``."""

    @property
    def time_to_refind(self) -> float:
        """Seconds from the loss to the re-identification."""
        return self.t_found - self.t_lost

    def to_json(self) -> dict[str, Any]:
        """``{"t_lost", "t_found", "how"}`` (plus ``time_to_refind_s``)."""
        return {
            "t_lost": float(self.t_lost),
            "t_found": float(self.t_found),
            "how": self.how,
            "time_to_refind_s": float(self.time_to_refind),
        }


@dataclass(frozen=True)
class FollowMetrics:
    """The metrics of a follow episode (§III-B, Fig. 4 and Fig. 6); see the module docstring."""

    following_rate: float
    first_identified_s: float | None
    losses: int
    reacquisitions: tuple[Reacquisition, ...]
    identity_switches: int
    collisions: int
    distance_m: float
    duration_s: float
    loss_times: tuple[float, ...] = ()
    """``t_lost`` of every loss, re-acquired or not (``len == losses``)."""
    switch_times: tuple[float, ...] = ()
    """The start ``t`` of every identity switch (``len == identity_switches``)."""
    ground_truth: bool = True
    """False when the log had no truths and the robot's belief stood in (module docstring)."""
    band: tuple[float, float] = MetricParams.band
    """The following band the rate was measured with (:attr:`MetricParams.band`), m."""

    @property
    def median_time_to_refind_s(self) -> float | None:
        """The median :attr:`Reacquisition.time_to_refind`, ``None`` without re-acquisitions."""
        if not self.reacquisitions:
            return None
        return float(np.median([r.time_to_refind for r in self.reacquisitions]))

    @property
    def unrecovered_losses(self) -> int:
        """Losses never re-acquired."""
        return self.losses - len(self.reacquisitions)

    def to_json(self) -> dict[str, Any]:
        """A JSON-serialisable dict of every metric (plain floats, ints, lists, ``None``)."""
        return {
            "following_rate": float(self.following_rate),
            "first_identified_s": _opt_float(self.first_identified_s),
            "losses": int(self.losses),
            "unrecovered_losses": int(self.unrecovered_losses),
            "loss_times": [float(t) for t in self.loss_times],
            "reacquisitions": [r.to_json() for r in self.reacquisitions],
            "median_time_to_refind_s": _opt_float(self.median_time_to_refind_s),
            "identity_switches": int(self.identity_switches),
            "switch_times": [float(t) for t in self.switch_times],
            "collisions": int(self.collisions),
            "distance_m": float(self.distance_m),
            "duration_s": float(self.duration_s),
            "ground_truth": bool(self.ground_truth),
            "band": [float(self.band[0]), float(self.band[1])],
        }


@dataclass(frozen=True)
class SearchMetrics:
    """The metrics of a search episode: was the target found, how fast, at what cost."""

    found: bool
    time_to_find_s: float | None
    distance_m: float
    """Path length up to the find (the whole episode if not found), m."""
    collisions: int
    """Collisions up to the find (the whole episode if not found)."""
    ground_truth: bool = True
    """False when the log had no truths and the robot's belief stood in."""

    def to_json(self) -> dict[str, Any]:
        """``{"found", "time_to_find_s", "distance_m", "collisions"}``, JSON-serialisable."""
        return {
            "found": bool(self.found),
            "time_to_find_s": _opt_float(self.time_to_find_s),
            "distance_m": float(self.distance_m),
            "collisions": int(self.collisions),
            "ground_truth": bool(self.ground_truth),
        }


def _opt_float(value: float | None) -> float | None:
    return None if value is None else float(value)


# -- the episode as arrays ----------------------------------------------------------------------


@dataclass(frozen=True)
class EpisodeArrays:
    """An :class:`EpisodeLog` as per-tick numpy arrays (what the metrics and figures need).

    ``robot_xy`` is the true robot position when there are truths, else the believed pose;
    ``target_true_xy`` is NaN where the truth has no target person (or without truths).
    """

    t: FloatArray
    has_target: BoolArray
    target_xy: FloatArray
    """``(n, 2)`` the follower's target estimate, NaN where it has none."""
    pose_xy: FloatArray
    """``(n, 2)`` the believed robot position."""
    robot_xy: FloatArray
    target_true_xy: FloatArray
    correct: BoolArray
    wrong: BoolArray
    true_distance: FloatArray
    """True robot–target distance (NaN where unknown or without truths)."""
    estimated_distance: FloatArray
    """Believed pose to ``target_xy`` (NaN without an estimate)."""
    period: float
    has_truth: bool

    @property
    def n(self) -> int:
        return len(self.t)


def _check_lengths(log: EpisodeLog) -> bool:
    if not log.truths:
        return False
    if len(log.truths) != len(log.ticks):
        raise ValueError(
            f"episode log has {len(log.truths)} truths for {len(log.ticks)} ticks; "
            "truths must be recorded one per tick"
        )
    return True


def _people_arrays(log: EpisodeLog) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Robot ``(n, 2)``, target ``(n, 2)`` and the other people ``(n, P, 2)`` (NaN-padded)."""
    columns = truth_columns(log.truths)
    n = len(columns.people)
    width = max(1, max((len(people) for people in columns.people), default=0))
    name = log.target_name
    nan2 = (math.nan, math.nan)
    target: list[tuple[float, float]] = []
    others: list[list[tuple[float, float]]] = []
    for people in columns.people:
        mine = nan2
        rest = []
        for who, x, y, is_target in people:
            if mine is nan2 and (is_target or (name is not None and who == name)):
                mine = (x, y)
            else:
                rest.append((x, y))
        target.append(mine)
        others.append(rest + [nan2] * (width - len(rest)))
    return (
        columns.robot_xy.reshape(n, 2),
        np.array(target, dtype=float).reshape(n, 2),
        np.array(others, dtype=float),
    )


def episode_arrays(log: EpisodeLog, params: MetricParams | None = None) -> EpisodeArrays:
    """The per-tick arrays of ``log`` with correct/wrong judged as the module docstring says.

    ValueError when truths are recorded but not one per tick.
    """
    params = params or MetricParams()
    ticks = tick_columns(log.ticks)
    n = len(ticks.t)
    t = ticks.t
    has = np.fromiter((a in HAS_TARGET for a in ticks.awareness), dtype=bool, count=n)
    target_xy = ticks.target_xy
    pose_xy = ticks.pose_xy
    period = float(np.median(np.diff(t))) if n >= 2 else 0.0
    estimated = np.hypot(*(target_xy - pose_xy).T) if n else np.zeros(0)
    has_truth = _check_lengths(log)
    if has_truth:
        robot_xy, target_true, others = _people_arrays(log)
        known = ~np.isnan(target_xy[:, 0])
        d_target = np.hypot(*(target_xy - target_true).T)
        d_others = np.hypot(
            target_xy[:, None, 0] - others[..., 0], target_xy[:, None, 1] - others[..., 1]
        )
        with np.errstate(invalid="ignore"):
            d_other = np.min(np.where(np.isnan(d_others), np.inf, d_others), axis=1)
            judged = has & known
            target_near = np.nan_to_num(d_target, nan=np.inf)
            correct = judged & (target_near <= params.match_radius) & (target_near <= d_other)
            wrong = judged & (d_other <= params.match_radius) & (d_other < target_near)
        true_distance = np.hypot(*(target_true - robot_xy).T)
    else:
        robot_xy = pose_xy
        target_true = np.full((n, 2), np.nan)
        correct = has.copy()
        wrong = np.zeros(n, dtype=bool)
        true_distance = np.full(n, np.nan)
    return EpisodeArrays(
        t=t,
        has_target=has,
        target_xy=target_xy,
        pose_xy=pose_xy,
        robot_xy=robot_xy,
        target_true_xy=target_true,
        correct=correct,
        wrong=wrong,
        true_distance=true_distance,
        estimated_distance=estimated,
        period=period,
        has_truth=has_truth,
    )


def runs(mask: BoolArray) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
    """The maximal runs of ``True`` in ``mask``: index arrays ``(starts, ends)``, ends inclusive."""
    m = np.asarray(mask, dtype=np.int8)
    edges = np.diff(np.concatenate(([0], m, [0])))
    starts = np.flatnonzero(edges == 1)
    ends = np.flatnonzero(edges == -1) - 1
    return starts, ends


def path_length(xy: FloatArray) -> float:
    """The length of the polyline ``(n, 2)``, m (NaN points skipped)."""
    xy = np.asarray(xy, dtype=float)
    xy = xy[~np.isnan(xy).any(axis=1)]
    if len(xy) < 2:
        return 0.0
    return float(np.hypot(*np.diff(xy, axis=0).T).sum())


def _search_codes(log: EpisodeLog) -> NDArray[np.int8]:
    """Per tick: 1 for a prediction action, 2 for way-point search, 0 otherwise."""
    codes = {a: 1 for a in PREDICTION_ACTIONS} | {a: 2 for a in WAYPOINT_ACTIONS}
    return np.fromiter(
        (codes.get(a, 0) if a else 0 for a in tick_columns(log.ticks).action),
        dtype=np.int8,
        count=len(log.ticks),
    )


def follow_metrics(log: EpisodeLog, params: MetricParams | None = None) -> FollowMetrics:
    """The metrics of a follow episode (module docstring: definitions, no-truth fallback)."""
    params = params or MetricParams()
    a = episode_arrays(log, params)
    n = a.n
    collisions = int(log.truths[-1].collisions) if log.truths else 0
    distance = path_length(a.robot_xy)
    duration = float(a.t[-1] - a.t[0] + a.period) if n else 0.0
    switch_starts, switch_ends = runs(a.wrong)
    keep = a.t[switch_ends] - a.t[switch_starts] + a.period >= params.min_switch_s - _EPS
    switch_times = tuple(float(x) for x in a.t[switch_starts[keep]])
    correct_idx = np.flatnonzero(a.correct)
    if len(correct_idx) == 0:
        return FollowMetrics(
            following_rate=0.0,
            first_identified_s=None,
            losses=0,
            reacquisitions=(),
            identity_switches=len(switch_times),
            collisions=collisions,
            distance_m=distance,
            duration_s=duration,
            switch_times=switch_times,
            ground_truth=a.has_truth,
            band=params.band,
        )
    first = int(correct_idx[0])
    distance_used = a.true_distance if a.has_truth else a.estimated_distance
    lo, hi = params.band
    with np.errstate(invalid="ignore"):
        in_band = (distance_used >= lo) & (distance_used <= hi)
    following = a.correct[first:] & in_band[first:]
    rate = float(following.mean())

    gap = ~a.has_target
    gap[:first] = False
    starts, ends = runs(gap)
    long = a.t[ends] - a.t[starts] + a.period >= params.min_loss_s - _EPS
    starts, ends = starts[long], ends[long]
    codes = _search_codes(log)
    reacq: list[Reacquisition] = []
    for k, (s, e) in enumerate(zip(starts, ends, strict=True)):
        limit = int(starts[k + 1]) if k + 1 < len(starts) else n
        j = int(np.searchsorted(correct_idx, e + 1))
        if j >= len(correct_idx) or correct_idx[j] >= limit:
            continue
        found = int(correct_idx[j])
        seen = codes[s:found]
        nz = np.flatnonzero(seen)
        how = "other" if len(nz) == 0 else ("prediction", "waypoint_search")[seen[nz[-1]] - 1]
        reacq.append(Reacquisition(float(a.t[s]), float(a.t[found]), how))
    return FollowMetrics(
        following_rate=rate,
        first_identified_s=float(a.t[first]),
        losses=len(starts),
        reacquisitions=tuple(reacq),
        identity_switches=len(switch_times),
        collisions=collisions,
        distance_m=distance,
        duration_s=duration,
        loss_times=tuple(float(x) for x in a.t[starts]),
        switch_times=switch_times,
        ground_truth=a.has_truth,
        band=params.band,
    )


def search_metrics(log: EpisodeLog, params: MetricParams | None = None) -> SearchMetrics:
    """The metrics of a search episode (module docstring): found, time to find, its cost."""
    params = params or MetricParams()
    a = episode_arrays(log, params)
    correct_idx = np.flatnonzero(a.correct)
    if len(correct_idx) == 0:
        return SearchMetrics(
            found=False,
            time_to_find_s=None,
            distance_m=path_length(a.robot_xy),
            collisions=int(log.truths[-1].collisions) if log.truths else 0,
            ground_truth=a.has_truth,
        )
    i = int(correct_idx[0])
    return SearchMetrics(
        found=True,
        time_to_find_s=float(a.t[i] - a.t[0]),
        distance_m=path_length(a.robot_xy[: i + 1]),
        collisions=int(log.truths[i].collisions) if log.truths else 0,
        ground_truth=a.has_truth,
    )


__all__ = [
    "HOW",
    "PREDICTION_ACTIONS",
    "WAYPOINT_ACTIONS",
    "EpisodeArrays",
    "FollowMetrics",
    "MetricParams",
    "Reacquisition",
    "RoomPredictionScores",
    "SearchMetrics",
    "episode_arrays",
    "follow_metrics",
    "path_length",
    "room_prediction_scores",
    "runs",
    "search_metrics",
]


@dataclass(frozen=True)
class RoomPredictionScores:
    """Room prediction at the moment of loss against the truth (module docstring): counts."""

    scored: int = 0
    top1: int = 0
    top2: int = 0
    heading_top1: int = 0
    """Hits of l* (Algorithm 1's heading region; her own room without one)."""
    heading_top2: int = 0
    """Hits of l* or her own room."""

    def to_json(self) -> dict[str, int]:
        return {
            "room_scored": self.scored,
            "room_top1": self.top1,
            "room_top2": self.top2,
            "room_heading_top1": self.heading_top1,
            "room_heading_top2": self.heading_top2,
        }


def room_prediction_scores(
    log: EpisodeLog, regions: RegionMap, params: MetricParams | None = None
) -> RoomPredictionScores:
    """Score the room predictions logged at the losses of :func:`follow_metrics` (module
    docstring); all zero without truths or room predictions."""
    if not log.truths or not log.room_predictions:
        return RoomPredictionScores()
    a = episode_arrays(log, params)
    counts = [0, 0, 0, 0, 0]
    records = sorted(log.room_predictions, key=lambda r: r.t)
    times = np.array([r.t for r in records])
    for t_lost in follow_metrics(log, params).loss_times:
        k = int(np.searchsorted(times, t_lost + _EPS, side="right")) - 1
        if k < 0:
            continue
        rec = records[k]
        at = rec.t + rec.horizon_s
        if len(a.t) == 0 or at > a.t[-1] + _EPS:
            continue
        i = min(int(np.searchsorted(a.t, at - _EPS)), len(a.t) - 1)
        xy = a.target_true_xy[i]
        if np.isnan(xy[0]):
            continue
        truth = regions.locate(xy)
        if truth is None:
            continue
        base = [r for r in (rec.heading, rec.current) if r is not None]
        counts[0] += 1
        counts[1] += rec.ranked[:1] == (truth,)
        counts[2] += truth in rec.ranked[:2]
        counts[3] += base[:1] == [truth]
        counts[4] += truth in base[:2]
    return RoomPredictionScores(*counts)
