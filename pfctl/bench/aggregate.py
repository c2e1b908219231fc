"""Per-variant summary of a campaign: the mean and 95 % bootstrap interval of each metric.

The unit of resampling is the episode. Every metric is a ratio of sums over the episodes,
``Σ numerator / Σ denominator``, which covers plain means (denominator 1) and pooled rates alike:

follow — ``following_rate`` (mean of the episodes' rates), ``refind_success`` (re-acquired
losses / losses), ``time_to_refind_s`` (mean over all re-acquisitions), ``identity_switches``,
``collisions`` and ``path_length_m`` (means per episode), ``room_top1``/``room_top2`` (the room
predicted at a loss was where she was a few seconds later / among the first two, over the scored
losses) and ``room_heading_top1``/``room_heading_top2`` (the same for Algorithm 1's l*);

search — ``found_rate`` (episodes that found the target / episodes), ``time_to_find_s`` (mean
over the episodes that found the target), ``collisions``, ``path_length_m``.

The interval is scipy's percentile bootstrap (:func:`scipy.stats.bootstrap`, ``paired`` so an
episode's numerator and denominator are resampled together), seeded: the same records give the
same intervals. Resamples whose denominator is 0 (no loss among the episodes drawn) are left out
of the percentiles. Fewer than two contributing episodes give no interval.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy import stats

__all__ = [
    "FOLLOW_METRICS",
    "SEARCH_METRICS",
    "Estimate",
    "GroupSummary",
    "Metric",
    "bootstrap_ratio",
    "metrics_for",
    "summarize",
]

Record = dict[str, Any]


@dataclass(frozen=True)
class Metric:
    """One summarised quantity: how to read it from an episode's ``metrics``."""

    name: str
    label: str
    unit: str
    numerator: Callable[[dict[str, Any]], float]
    denominator: Callable[[dict[str, Any]], float]
    values: Callable[[dict[str, Any]], list[float]]
    """The episode's values for the box plots (none when it has nothing to say, e.g. the
    re-find success of an episode without a loss)."""
    percent: bool = False
    """A fraction shown as a percentage."""


def _one(_: dict[str, Any]) -> float:
    return 1.0


def _field(name: str) -> Callable[[dict[str, Any]], float]:
    return lambda m: float(m[name])


def _field_or_zero(name: str) -> Callable[[dict[str, Any]], float]:
    return lambda m: float(m.get(name, 0))


def _share(name: str) -> Callable[[dict[str, Any]], list[float]]:
    return lambda m: [m[name] / m["room_scored"]] if m.get("room_scored") else []


def _value(name: str) -> Callable[[dict[str, Any]], list[float]]:
    return lambda m: [float(m[name])]


FOLLOW_METRICS: tuple[Metric, ...] = (
    Metric(
        "following_rate",
        "following rate",
        "",
        _field("following_rate"),
        _one,
        _value("following_rate"),
        percent=True,
    ),
    Metric(
        "refind_success",
        "re-find success",
        "",
        _field("reacquired"),
        _field("losses"),
        lambda m: [m["reacquired"] / m["losses"]] if m["losses"] else [],
        percent=True,
    ),
    Metric(
        "time_to_refind_s",
        "time to re-find",
        "s",
        lambda m: float(sum(m["refind_times_s"])),
        lambda m: float(len(m["refind_times_s"])),
        lambda m: [float(t) for t in m["refind_times_s"]],
    ),
    Metric(
        "identity_switches",
        "identity switches",
        "",
        _field("identity_switches"),
        _one,
        _value("identity_switches"),
    ),
    Metric("collisions", "collisions", "", _field("collisions"), _one, _value("collisions")),
    Metric("path_length_m", "path length", "m", _field("distance_m"), _one, _value("distance_m")),
    *(
        Metric(
            f"room_{key}",
            label,
            "",
            _field_or_zero(f"room_{key}"),
            _field_or_zero("room_scored"),
            _share(f"room_{key}"),
            percent=True,
        )
        for key, label in (
            ("top1", "room top-1"),
            ("top2", "room top-2"),
            ("heading_top1", "room top-1 of l*"),
            ("heading_top2", "room top-2 of l*"),
        )
    ),
)

SEARCH_METRICS: tuple[Metric, ...] = (
    Metric(
        "found_rate",
        "found",
        "",
        lambda m: float(bool(m["found"])),
        _one,
        lambda m: [float(bool(m["found"]))],
        percent=True,
    ),
    Metric(
        "time_to_find_s",
        "time to find",
        "s",
        lambda m: float(m["time_to_find_s"]) if m["found"] else 0.0,
        lambda m: float(bool(m["found"])),
        lambda m: [float(m["time_to_find_s"])] if m["found"] else [],
    ),
    Metric("collisions", "collisions", "", _field("collisions"), _one, _value("collisions")),
    Metric("path_length_m", "path length", "m", _field("distance_m"), _one, _value("distance_m")),
)


def metrics_for(task: str) -> tuple[Metric, ...]:
    """The summarised metrics of a ``follow`` or ``search`` campaign."""
    return SEARCH_METRICS if task == "search" else FOLLOW_METRICS


@dataclass(frozen=True)
class Estimate:
    """A metric of one group: the point estimate and its bootstrap interval."""

    mean: float | None
    """``Σ numerator / Σ denominator``; None when the denominator is 0."""
    low: float | None
    high: float | None
    n: int
    """Episodes that contribute (denominator > 0)."""
    denominator: float
    """``Σ denominator`` (losses for re-find success, re-finds for their time)."""


@dataclass(frozen=True)
class GroupSummary:
    """One (mission, variant): episodes finished and errors, and each metric's estimate."""

    mission: str
    variant: str
    episodes: int
    """Episodes with status ``ok``."""
    failed: int
    """Episodes that ended in ``error`` or ``timeout``."""
    estimates: dict[str, Estimate]
    values: dict[str, list[float]]
    """Per metric, the episodes' values for the box plots."""


def bootstrap_ratio(
    numerator: Sequence[float],
    denominator: Sequence[float],
    *,
    confidence: float = 0.95,
    n_resamples: int = 9999,
    seed: int = 0,
) -> Estimate:
    """``Σ numerator / Σ denominator`` over episodes with its percentile bootstrap interval."""
    num = np.asarray(numerator, dtype=float)
    den = np.asarray(denominator, dtype=float)
    total = float(den.sum())
    n = int(np.count_nonzero(den > 0))
    mean = float(num.sum() / total) if total > 0 else None
    if mean is None or n < 2:
        return Estimate(mean, None, None, n, total)

    def ratio(a: np.ndarray, b: np.ndarray, axis: int = -1) -> np.ndarray:
        s = b.sum(axis=axis)
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(s > 0, a.sum(axis=axis) / np.where(s > 0, s, 1.0), np.nan)

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        result = stats.bootstrap(
            (num, den),
            ratio,
            paired=True,
            vectorized=True,
            confidence_level=confidence,
            n_resamples=n_resamples,
            method="percentile",
            rng=np.random.default_rng(seed),
        )
    low, high = float(result.confidence_interval.low), float(result.confidence_interval.high)
    if not (np.isfinite(low) and np.isfinite(high)):
        dist = np.asarray(result.bootstrap_distribution, dtype=float)
        dist = dist[np.isfinite(dist)]
        if len(dist) == 0:
            return Estimate(mean, None, None, n, total)
        alpha = (1.0 - confidence) / 2.0
        low, high = (float(v) for v in np.percentile(dist, [100 * alpha, 100 * (1 - alpha)]))
    return Estimate(mean, low, high, n, total)


def summarize(
    records: Iterable[Record],
    groups: Sequence[tuple[str, str]],
    metrics: Sequence[Metric],
    *,
    seed: int = 0,
) -> list[GroupSummary]:
    """One :class:`GroupSummary` per (mission label, variant name) of ``groups``, in order,
    from the episode ``records`` (the last record of each episode; others are ignored)."""
    by_group: dict[tuple[str, str], list[Record]] = {g: [] for g in groups}
    for record in records:
        key = (record["mission"], record["variant"])
        if key in by_group:
            by_group[key].append(record)
    out = []
    for mission, variant in groups:
        rows = by_group[(mission, variant)]
        ok = [r["metrics"] for r in rows if r["status"] == "ok"]
        estimates = {
            m.name: bootstrap_ratio(
                [m.numerator(x) for x in ok], [m.denominator(x) for x in ok], seed=seed
            )
            for m in metrics
        }
        values = {m.name: [v for x in ok for v in m.values(x)] for m in metrics}
        out.append(GroupSummary(mission, variant, len(ok), len(rows) - len(ok), estimates, values))
    return out
