"""The campaign's summary as a person reads it: a terminal table, CSV and Markdown, and the
episodes as CSV.

``summary.csv`` is long (one row per mission, variant and metric: ``mean``, ``ci_low``,
``ci_high``, ``n`` contributing episodes, ``denominator``, ``episodes``, ``failed``);
``summary.md`` and the printed table have a row per mission and variant and a column per metric,
each cell ``mean [low, high]``. ``episodes.csv`` has one row per episode: identity, status,
every metric, wall times, run id.
"""

from __future__ import annotations

import csv
import io
import json
from collections.abc import Sequence
from typing import Any

from rich.table import Table

from pfctl.bench.aggregate import Estimate, GroupSummary, Metric

__all__ = ["episodes_csv", "format_estimate", "summary_csv", "summary_markdown", "summary_table"]


def _number(metric: Metric, value: float) -> str:
    if metric.percent:
        return f"{100 * value:.1f}"
    return f"{value:.2f}" if abs(value) < 10 else f"{value:.1f}"


def format_estimate(metric: Metric, estimate: Estimate) -> str:
    """``mean [low, high]`` with the metric's unit (``62.5% [48.0, 77.1]``, ``14.2 s [...]``)."""
    if estimate.mean is None:
        return "—"
    unit = "%" if metric.percent else (f" {metric.unit}" if metric.unit else "")
    text = _number(metric, estimate.mean) + unit
    if estimate.low is not None and estimate.high is not None:
        text += f" [{_number(metric, estimate.low)}, {_number(metric, estimate.high)}]"
    return text


def _show_mission(summaries: Sequence[GroupSummary]) -> bool:
    return len({s.mission for s in summaries}) > 1 or all(s.variant == "base" for s in summaries)


def _group_label(summary: GroupSummary, with_mission: bool, sep: str = " · ") -> str:
    if with_mission and summary.variant != "base":
        return f"{summary.mission}{sep}{summary.variant}"
    return summary.mission if with_mission else summary.variant


def summary_table(
    summaries: Sequence[GroupSummary], metrics: Sequence[Metric], title: str
) -> Table:
    """A rich table: a row per mission and variant, a column per metric."""
    table = Table(title=title, title_justify="left")
    table.add_column("mission · variant" if _show_mission(summaries) else "variant")
    table.add_column("episodes", justify="right")
    for metric in metrics:
        table.add_column(metric.label, justify="right")
    with_mission = _show_mission(summaries)
    for s in summaries:
        failed = f" (+{s.failed} failed)" if s.failed else ""
        table.add_row(
            _group_label(s, with_mission),
            f"{s.episodes}{failed}",
            *(format_estimate(m, s.estimates[m.name]) for m in metrics),
        )
    table.caption = "mean [95% bootstrap interval]"
    return table


def summary_markdown(
    summaries: Sequence[GroupSummary], metrics: Sequence[Metric], title: str
) -> str:
    """The table of :func:`summary_table` as Markdown, with a heading and a note."""
    with_mission = _show_mission(summaries)
    head = ["mission · variant" if with_mission else "variant", "episodes"]
    head += [m.label for m in metrics]
    lines = [f"# {title}", "", "| " + " | ".join(head) + " |"]
    lines.append("|" + "|".join(["---"] + ["---:"] * (len(head) - 1)) + "|")
    for s in summaries:
        failed = f" (+{s.failed} failed)" if s.failed else ""
        cells = [_group_label(s, with_mission).replace("|", "\\|"), f"{s.episodes}{failed}"]
        cells += [format_estimate(m, s.estimates[m.name]) for m in metrics]
        lines.append("| " + " | ".join(cells) + " |")
    lines += [
        "",
        "Mean [95 % percentile-bootstrap interval over episodes]; rates in percent. Re-find "
        "success is re-acquired losses / losses, time to re-find the mean over re-acquisitions, "
        "time to find the mean over the episodes that found the target.",
        "",
    ]
    return "\n".join(lines)


def summary_csv(summaries: Sequence[GroupSummary], metrics: Sequence[Metric]) -> str:
    """One row per mission, variant and metric (module docstring)."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(
        [
            "mission",
            "variant",
            "metric",
            "mean",
            "ci_low",
            "ci_high",
            "n",
            "denominator",
            "episodes",
            "failed",
        ]
    )
    for s in summaries:
        for m in metrics:
            e = s.estimates[m.name]
            writer.writerow(
                [
                    s.mission,
                    s.variant,
                    m.name,
                    *("" if v is None else f"{v:.6g}" for v in (e.mean, e.low, e.high)),
                    e.n,
                    f"{e.denominator:g}",
                    s.episodes,
                    s.failed,
                ]
            )
    return buffer.getvalue()


def episodes_csv(records: Sequence[dict[str, Any]]) -> str:
    """One row per episode record: identity, status, every metric, wall times, run id."""
    metric_names: list[str] = []
    for r in records:
        for name in r.get("metrics") or {}:
            if name not in metric_names:
                metric_names.append(name)
    head = ["mission", "mission_file", "variant", "index", "seed", "status", "error"]
    tail = ["wall_s", "learn_wall_s", "tick_ms_median", "tick_ms_p99", "run_id", "finished"]
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(head + metric_names + tail)
    for r in records:
        metrics = r.get("metrics") or {}
        timing = r.get("timing") or {}
        writer.writerow(
            [r.get(k, "") if r.get(k) is not None else "" for k in head]
            + [_cell(metrics.get(k)) for k in metric_names]
            + [_cell(timing.get(k)) for k in tail[:4]]
            + [r["run"].get("id", ""), r["run"].get("finished", "")]
        )
    return buffer.getvalue()


def _cell(value: Any) -> str:
    if value is None:
        return ""
    if isinstance(value, bool):
        return str(value).lower()
    if isinstance(value, float):
        return repr(value)
    if isinstance(value, list):
        return json.dumps(value)
    return str(value)
