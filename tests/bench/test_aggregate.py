"""pfctl bench's summary on known numbers: ratio-of-sums means, seeded percentile bootstrap
intervals, groups, and the CSV / Markdown / PNG it writes."""

from __future__ import annotations

import csv
import io
from typing import Any

import numpy as np
import pytest

from pfctl.bench.aggregate import (
    FOLLOW_METRICS,
    SEARCH_METRICS,
    bootstrap_ratio,
    summarize,
)
from pfctl.bench.plots import boxplots_png
from pfctl.bench.report import (
    episodes_csv,
    format_estimate,
    summary_csv,
    summary_markdown,
    summary_table,
)


def test_mean_and_interval_of_a_plain_mean() -> None:
    x = [1.0, 2.0, 3.0, 4.0, 5.0]
    e = bootstrap_ratio(x, [1.0] * 5)
    assert e.mean == 3.0 and e.n == 5 and e.denominator == 5
    assert e.low is not None and e.high is not None
    # the percentile interval of the mean of 1..5 (se ~0.63): about [1.8, 4.2]
    assert 1.4 < e.low < 2.4 and 3.6 < e.high < 4.6
    assert bootstrap_ratio(x, [1.0] * 5) == e  # seeded: the same interval every time
    y = np.random.default_rng(3).normal(10.0, 2.0, 30)
    a, b = bootstrap_ratio(y, np.ones(30)), bootstrap_ratio(y, np.ones(30), seed=1)
    assert a.mean == b.mean == pytest.approx(y.mean()) and a.low != b.low
    assert a.low == pytest.approx(y.mean() - 1.96 * y.std(ddof=1) / np.sqrt(30), abs=0.15)


def test_ratio_of_sums_resamples_episodes_together() -> None:
    # re-find success: episode i re-acquired num[i] of den[i] losses
    e = bootstrap_ratio([1, 0, 2, 1], [1, 0, 2, 2])
    assert e.mean == pytest.approx(4 / 5) and e.n == 3 and e.denominator == 5
    assert e.low is not None and e.high is not None
    assert 0.5 - 1e-9 <= e.low <= e.mean <= e.high <= 1.0 + 1e-9
    # every episode with a loss re-found all: the interval is the point (resamples with no
    # loss at all are left out)
    assert bootstrap_ratio([1, 0, 2], [1, 0, 2]) == type(e)(1.0, 1.0, 1.0, 2, 3.0)


def test_degenerate_groups() -> None:
    assert bootstrap_ratio([7.0] * 4, [1.0] * 4) == type(bootstrap_ratio([1], [1]))(
        7.0, 7.0, 7.0, 4, 4.0
    )
    one = bootstrap_ratio([0.4], [1.0])
    assert one.mean == 0.4 and one.low is None and one.high is None and one.n == 1
    none = bootstrap_ratio([0.0, 0.0], [0.0, 0.0])
    assert none.mean is None and none.low is None and none.n == 0
    empty = bootstrap_ratio([], [])
    assert empty.mean is None and empty.n == 0


def _follow(rate: float, losses: int, refinds: list[float], switches: int = 0) -> dict[str, Any]:
    return {
        "following_rate": rate,
        "losses": losses,
        "reacquired": len(refinds),
        "refind_times_s": refinds,
        "identity_switches": switches,
        "collisions": 0,
        "distance_m": 10.0 * rate,
    }


def _record(
    variant: str, seed: int, metrics: dict[str, Any] | None, status: str = "ok"
) -> dict[str, Any]:
    return {
        "mission": "house",
        "mission_file": "missions/house.yaml",
        "variant": variant,
        "index": seed - 1,
        "seed": seed,
        "task": "follow",
        "config": "c0ffee",
        "status": status,
        "error": None if status == "ok" else "boom",
        "metrics": metrics,
        "timing": {"wall_s": 30.0, "learn_wall_s": 5.0} if metrics else None,
        "run": {"id": f"run{variant}{seed}", "finished": "2026-01-01T00:00:00+00:00"},
    }


@pytest.fixture
def records() -> list[dict[str, Any]]:
    return [
        _record("base", 1, _follow(0.5, 2, [10.0, 20.0])),
        _record("base", 2, _follow(0.7, 1, [])),
        _record("base", 3, _follow(0.9, 0, [], switches=1)),
        _record("base", 4, None, status="error"),
        _record("search.alpha=2", 1, _follow(0.6, 1, [6.0])),
        _record("search.alpha=2", 2, _follow(0.8, 1, [8.0])),
        _record("other", 1, _follow(0.1, 0, [])),  # not a planned group: ignored
    ]


def test_summaries_per_group(records: list[dict[str, Any]]) -> None:
    groups = [("house", "base"), ("house", "search.alpha=2")]
    base, alpha = summarize(records, groups, FOLLOW_METRICS)
    assert (base.mission, base.variant, base.episodes, base.failed) == ("house", "base", 3, 1)
    e = base.estimates
    assert e["following_rate"].mean == pytest.approx(0.7)
    assert e["refind_success"].mean == pytest.approx(2 / 3) and e["refind_success"].n == 2
    assert e["time_to_refind_s"].mean == pytest.approx(15.0)
    assert e["time_to_refind_s"].low is None  # one episode re-found: no interval
    assert e["identity_switches"].mean == pytest.approx(1 / 3)
    assert e["path_length_m"].mean == pytest.approx(7.0)
    assert base.values["refind_success"] == [1.0, 0.0]
    assert base.values["time_to_refind_s"] == [10.0, 20.0]
    assert alpha.episodes == 2 and alpha.failed == 0
    assert alpha.estimates["time_to_refind_s"].mean == pytest.approx(7.0)
    low, high = alpha.estimates["time_to_refind_s"].low, alpha.estimates["time_to_refind_s"].high
    assert low == pytest.approx(6.0) and high == pytest.approx(8.0)


def test_search_metrics() -> None:
    def search(found: bool, t: float | None, d: float) -> dict[str, Any]:
        return {"found": found, "time_to_find_s": t, "distance_m": d, "collisions": 0}

    recs = [
        {**_record("base", s, m), "task": "search"}
        for s, m in [
            (1, search(True, 20.0, 5.0)),
            (2, search(False, None, 9.0)),
            (3, search(True, 40.0, 7.0)),
        ]
    ]
    (s,) = summarize(recs, [("house", "base")], SEARCH_METRICS)
    assert s.estimates["found_rate"].mean == pytest.approx(2 / 3)
    assert s.estimates["time_to_find_s"].mean == pytest.approx(30.0)
    assert s.estimates["time_to_find_s"].n == 2
    assert s.estimates["path_length_m"].mean == pytest.approx(7.0)


def test_tables_csv_markdown_and_plot(records: list[dict[str, Any]]) -> None:
    groups = [("house", "base"), ("house", "search.alpha=2")]
    summaries = summarize(records, groups, FOLLOW_METRICS)
    rows = list(csv.DictReader(io.StringIO(summary_csv(summaries, FOLLOW_METRICS))))
    assert len(rows) == 2 * len(FOLLOW_METRICS)
    rate = next(r for r in rows if r["variant"] == "base" and r["metric"] == "following_rate")
    assert float(rate["mean"]) == pytest.approx(0.7)
    assert float(rate["ci_low"]) <= 0.7 <= float(rate["ci_high"])
    assert (rate["n"], rate["episodes"], rate["failed"]) == ("3", "3", "1")
    md = summary_markdown(summaries, FOLLOW_METRICS, "t")
    assert "| search.alpha=2 | 2 |" in md and "| base | 3 (+1 failed) |" in md
    assert "70.0% [" in md
    rate_metric = FOLLOW_METRICS[0]
    assert format_estimate(rate_metric, summaries[0].estimates["following_rate"]).startswith(
        "70.0% ["
    )
    assert summary_table(summaries, FOLLOW_METRICS, "t").row_count == 2
    episodes = list(csv.DictReader(io.StringIO(episodes_csv(records[:4]))))
    assert [r["status"] for r in episodes] == ["ok", "ok", "ok", "error"]
    assert episodes[0]["refind_times_s"] == "[10.0, 20.0]" and episodes[3]["following_rate"] == ""
    png = boxplots_png(summaries, FOLLOW_METRICS, "t")
    assert png.startswith(b"\x89PNG") and len(png) > 20_000
    assert np.isfinite(summaries[1].estimates["following_rate"].mean or np.nan)


def test_episodes_csv_round_trips_floats() -> None:
    """A metric or wall time reads back from ``episodes.csv`` as the very float recorded."""
    record = _record("base", 1, _follow(0.123456789012, 2, [1234.56789012345]))
    record["timing"] = {"wall_s": 12345.678901234, "learn_wall_s": 0.1 + 0.2}
    (row,) = csv.DictReader(io.StringIO(episodes_csv([record])))
    assert float(row["following_rate"]) == 0.123456789012
    assert float(row["wall_s"]) == 12345.678901234
    assert float(row["learn_wall_s"]) == 0.1 + 0.2
