"""Issue 22's bars over a search campaign: re-find within 90 s, time against the oracle, collisions.

``pfctl bench`` summarises each metric per variant (means and bootstrap intervals); the issue
asks for figures it does not print: the share of losses re-found within ``--within`` seconds of
the loss, the median time to re-find against the oracle's, the share of episodes without a
collision, and the room prediction at the loss against Algorithm 1's heading region l*. This
script reads one or more ``results.jsonl`` (campaigns over the same homes, e.g. one per
``search.strategy``) and prints them per variant, plus a per-home table of the losses not
re-found (to trace)::

    python benchmarks/search_campaign.py OUT/trees/results.jsonl OUT/belief/results.jsonl \
        --oracle oracle [--within 90] [--markdown]

A variant is named after its campaign folder and ``pfctl bench``'s variant label
(``trees/behavior.tree=oracle``, ``belief/search.strategy=belief``); ``--oracle`` picks the
reference by a substring of that name. Only the last record of each episode counts
(:func:`pfctl.bench.results.latest`); episodes that ended in ``error`` or ``timeout`` are counted
and left out of the figures. A loss not re-found counts as not re-found within the bound, even
when the episode ended less than ``--within`` seconds after it (conservative: the loss times are
not in the records).
"""

from __future__ import annotations

import argparse
import statistics
from collections import defaultdict
from pathlib import Path
from typing import Any

from pfctl.bench.results import latest, read_records


def load(paths: list[Path]) -> dict[str, list[dict[str, Any]]]:
    """Records that finished ``ok``, by variant name ``FOLDER/VARIANT``; the others counted under
    the key ``"!failed FOLDER/VARIANT"``."""
    by_variant: dict[str, list[dict[str, Any]]] = defaultdict(list)
    for path in paths:
        records, _ = read_records(path)
        for record in latest(records).values():
            name = f"{path.parent.name}/{record['variant']}"
            if record.get("status") != "ok" or record.get("metrics") is None:
                by_variant[f"!failed {name}"].append(record)
            else:
                by_variant[name].append(record)
    return dict(by_variant)


def figures(records: list[dict[str, Any]], within: float) -> dict[str, Any]:
    """The issue's figures for one variant's episodes."""
    m = [r["metrics"] for r in records]
    losses = sum(x["losses"] for x in m)
    times = [t for x in m for t in x["refind_times_s"]]
    scored = sum(x.get("room_scored", 0) for x in m)
    return {
        "episodes": len(m),
        "losses": losses,
        "refound": len(times),
        "within": sum(t <= within for t in times),
        "median": statistics.median(times) if times else None,
        "mean": statistics.fmean(times) if times else None,
        "no_collision": sum(x["collisions"] == 0 for x in m),
        "following": statistics.fmean(x["following_rate"] for x in m) if m else 0.0,
        "switches": sum(x["identity_switches"] for x in m),
        "room_scored": scored,
        "top1": sum(x.get("room_top1", 0) for x in m),
        "top2": sum(x.get("room_top2", 0) for x in m),
        "lstar_top1": sum(x.get("room_heading_top1", 0) for x in m),
        "lstar_top2": sum(x.get("room_heading_top2", 0) for x in m),
    }


def _pct(k: int, n: int) -> str:
    return f"{100.0 * k / n:.1f} % ({k}/{n})" if n else "–"


def _s(value: float | None) -> str:
    return "–" if value is None else f"{value:.1f} s"


def table(by_variant: dict[str, list[dict[str, Any]]], oracle: str | None, within: float) -> str:
    """The per-variant table (markdown)."""
    ok = {k: v for k, v in by_variant.items() if not k.startswith("!failed")}
    figs = {k: figures(v, within) for k, v in sorted(ok.items())}
    ref = next((f for k, f in figs.items() if oracle and oracle in k), None)
    head = (
        "| variant | episodes | losses re-found within "
        f"{within:.0f} s | re-found at all | median / mean time to re-find | × oracle's median "
        "| episodes without collision | following | identity switches | room top-1 / top-2 "
        "(belief) | l* top-1 / l* or own room top-2 |"
    )
    lines = [head, "|" + "---|" * 11]
    for name, f in figs.items():
        ratio = (
            f"{f['median'] / ref['median']:.2f}"
            if ref is not None and ref["median"] and f["median"] is not None
            else "–"
        )
        lines.append(
            f"| {name} | {f['episodes']} | {_pct(f['within'], f['losses'])} "
            f"| {_pct(f['refound'], f['losses'])} | {_s(f['median'])} / {_s(f['mean'])} "
            f"| {ratio} | {_pct(f['no_collision'], f['episodes'])} "
            f"| {100 * f['following']:.1f} % | {f['switches']} "
            f"| {f['top1']} / {f['top2']} of {f['room_scored']} "
            f"| {f['lstar_top1']} / {f['lstar_top2']} of {f['room_scored']} |"
        )
    failed = {k: len(v) for k, v in by_variant.items() if k.startswith("!failed")}
    for name, n in sorted(failed.items()):
        lines.append(f"\n{n} episode(s) of {name.removeprefix('!failed ')} ended in error/timeout")
    return "\n".join(lines)


def misses(by_variant: dict[str, list[dict[str, Any]]]) -> str:
    """Per home, which variants left a loss unrecovered (to trace)."""
    rows: dict[str, dict[str, str]] = defaultdict(dict)
    names = sorted(k for k in by_variant if not k.startswith("!failed"))
    for name in names:
        for r in by_variant[name]:
            m = r["metrics"]
            home = Path(r["mission_file"]).stem
            rows[home][name] = f"{m['reacquired']}/{m['losses']}"
    lines = ["| home | " + " | ".join(names) + " |", "|" + "---|" * (len(names) + 1)]
    for home in sorted(rows):
        cells = [rows[home].get(n, "") for n in names]
        if any(c and c.split("/")[0] != c.split("/")[1] for c in cells):
            lines.append(f"| {home} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("results", nargs="+", type=Path, help="results.jsonl of pfctl bench")
    parser.add_argument("--oracle", default="oracle", help="substring naming the oracle variant")
    parser.add_argument("--within", type=float, default=90.0, help="re-find bound after a loss, s")
    args = parser.parse_args()
    for path in args.results:
        if not path.is_file():
            parser.error(f"{path}: no such results file")
    by_variant = load(args.results)
    print(table(by_variant, args.oracle, args.within))
    print("\nHomes where a loss was not re-found (re-found/losses per variant):\n")
    print(misses(by_variant))


if __name__ == "__main__":
    main()
