"""Do the reference episodes come out the same? Record them with this checkout, compare two records.

A restructuring must not change what the robot does. This script runs the reference set — ``pfctl
follow missions/house.yaml`` for seeds 1-3, ``missions/house_crowd.yaml`` seed 1 (60 s each),
``pfctl search missions/house_hide.yaml --seed 2``, ``pfctl bench missions/house.yaml --episodes 4
--seed 1``, ``pfctl predict evaluate`` on the hotel tracks — plus the mission JSON Schema, ``pfctl
bt leaves`` and every command's ``--help``, and compares two such records field by field:

* ``metrics.json``, ``tracks.csv`` and the campaign's ``results.jsonl`` (with ``campaign.json``,
  ``summary.csv``, ``episodes.csv``) must be identical except the wall-clock fields
  (``wall_time_s``, ``tick_ms_*``, the campaign's ``timing`` and ``run`` blocks);
* the prediction table must be identical except its ``ms/call`` column;
* the JSON Schema must be identical except ``description`` texts (docstrings);
* ``bt leaves`` and the help texts are compared as text (a difference is reported, not fatal:
  a reworded docstring changes them).

Usage::

    python benchmarks/same_episodes.py record OUT [--jobs 2]   # with this checkout's pfctl
    python benchmarks/same_episodes.py compare BEFORE AFTER     # exit 1 when an episode differs

A record takes about 6 minutes on 2 cores (``--jobs 2``).
"""

from __future__ import annotations

import argparse
import csv
import difflib
import io
import json
import os
import re
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
HOTEL = ROOT.parent / "shared" / "data" / "pedestrians" / "hotel"

#: Fields (and ``episodes.csv`` columns) that measure the machine or the run, not the episode.
WALL_CLOCK = {"wall_time_s", "tick_ms_median", "tick_ms_p99", "timing", "run"}
WALL_CLOCK_COLUMNS = WALL_CLOCK | {"wall_s", "learn_wall_s", "episode_wall_s", "run_id", "finished"}

_SIM = ["--backend", "sim"]
_MINUTE = ["--duration", "60"]
EPISODES: dict[str, list[str]] = {
    **{
        f"follow-house-{s}": ["follow", "missions/house.yaml", *_SIM, "--seed", str(s), *_MINUTE]
        for s in (1, 2, 3)
    },
    "follow-crowd-1": ["follow", "missions/house_crowd.yaml", *_SIM, "--seed", "1", *_MINUTE],
    "search-hide-2": ["search", "missions/house_hide.yaml", *_SIM, "--seed", "2"],
    "bench-house": ["bench", "missions/house.yaml", "--episodes", "4", "--seed", "1"],
}
COMMANDS = (
    "",
    "mission",
    "mission validate",
    "mission schema",
    "map",
    "map export",
    "map render",
    "map annotate",
    "predict",
    "predict track",
    "predict evaluate",
    "predict search",
    "predict experiment",
    "sim",
    "sim run",
    "sim serve-hsr",
    "sim export-map",
    "learn-target",
    "legs",
    "legs train",
    "legs evaluate",
    "follow",
    "search",
    "bench",
    "bt",
    "bt show",
    "bt leaves",
    "replay",
)


def _pfctl(args: list[str], out: Path, name: str) -> None:
    """Run ``pfctl ARGS`` with this interpreter; stdout/stderr to ``out/name.*``."""
    env = dict(os.environ, COLUMNS="200")
    with open(out / f"{name}.stdout", "w") as so, open(out / f"{name}.stderr", "w") as se:
        code = subprocess.run(
            [sys.executable, "-m", "pfctl", *args], cwd=ROOT, stdout=so, stderr=se, env=env
        ).returncode
    (out / f"{name}.rc").write_text(f"{code}\n")


def record(out: Path, jobs: int, hotel: Path) -> None:
    """Run the reference set with this checkout's pfctl into ``out``."""
    out.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()

    def episode(item: tuple[str, list[str]]) -> None:
        name, args = item
        t0 = time.perf_counter()
        _pfctl([*args, "--out", str(out / name)], out, name)
        print(f"{name}: {time.perf_counter() - t0:.0f} s", flush=True)

    with ThreadPoolExecutor(jobs) as pool:
        list(pool.map(episode, EPISODES.items()))
    if hotel.exists():
        _pfctl(
            ["predict", "evaluate", str(hotel), "--format", "frames", "--fps", "2.5"],
            out,
            "predict-hotel",
        )
    _pfctl(["mission", "schema"], out, "mission-schema")
    _pfctl(["bt", "leaves"], out, "bt-leaves")
    with open(out / "help.txt", "w") as help_file:
        for command in COMMANDS:
            result = subprocess.run(
                [sys.executable, "-m", "pfctl", *command.split(), "--help"],
                cwd=ROOT,
                capture_output=True,
                text=True,
                env=dict(os.environ, COLUMNS="200"),
            )
            help_file.write(f"### pfctl {command}\n{result.stdout}{result.stderr}")
    print(f"recorded in {out} ({time.perf_counter() - start:.0f} s)")


def _strip(value: Any, drop: set[str]) -> Any:
    if isinstance(value, dict):
        return {k: _strip(v, drop) for k, v in value.items() if k not in drop}
    if isinstance(value, list):
        return [_strip(v, drop) for v in value]
    return value


def _diff_json(a: Any, b: Any, path: str = "") -> list[str]:
    """Where two JSON values differ (paths and both values)."""
    if isinstance(a, dict) and isinstance(b, dict):
        out = []
        for key in sorted(set(a) | set(b)):
            if key not in a or key not in b:
                out.append(f"{path}.{key}: only in {'after' if key in b else 'before'}")
            else:
                out += _diff_json(a[key], b[key], f"{path}.{key}")
        return out
    if isinstance(a, list) and isinstance(b, list) and len(a) == len(b):
        return [
            d
            for i, (x, y) in enumerate(zip(a, b, strict=True))
            for d in _diff_json(x, y, f"{path}[{i}]")
        ]
    return [] if a == b else [f"{path}: {a!r} != {b!r}"]


def _csv_rows(path: Path) -> list[list[str]]:
    """A CSV file's rows without its wall-clock columns."""
    rows = list(csv.reader(io.StringIO(path.read_text())))
    if not rows:
        return rows
    keep = [i for i, name in enumerate(rows[0]) if name not in WALL_CLOCK_COLUMNS]
    return [[row[i] for i in keep if i < len(row)] for row in rows]


def _diff_rows(a: list[list[str]], b: list[list[str]]) -> list[str]:
    """Where two CSV tables differ: the first differing row."""
    if a == b:
        return []
    first = next((i for i, (x, y) in enumerate(zip(a, b, strict=False)) if x != y), None)
    where = first if first is not None else min(len(a), len(b))
    return [f": {len(a)} rows before, {len(b)} after; first difference at row {where}"]


def _jsonl(path: Path) -> list[Any]:
    rows = [json.loads(line) for line in path.read_text().splitlines() if line.strip()]
    return sorted(rows, key=lambda r: (r.get("mission"), r.get("variant"), r.get("index")))


def _table_without_timing(text: str) -> str:
    """The prediction table with its last (ms/call) column blanked."""
    return "\n".join(re.sub(r"│[^│]*│$", "│", line) for line in text.splitlines())


def _schema_without_docs(text: str) -> Any:
    return _strip(json.loads(text), {"description"})


def compare(before: Path, after: Path) -> int:
    """Print what differs; 1 when an episode, the table or the schema differs."""
    failures: list[str] = []
    notes: list[str] = []
    for name in EPISODES:
        a, b = before / name, after / name
        rc_a = (
            (before / f"{name}.rc").read_text().strip() if (before / f"{name}.rc").exists() else "?"
        )
        rc_b = (after / f"{name}.rc").read_text().strip()
        if rc_a not in ("?", rc_b):
            failures.append(f"{name}: exit status {rc_a} != {rc_b}")
        for f in sorted(p.name for p in a.iterdir()):
            fa, fb = a / f, b / f
            if not fb.exists():
                failures.append(f"{name}/{f}: missing after")
                continue
            if f.endswith(".json"):
                diff = _diff_json(
                    _strip(json.loads(fa.read_text()), WALL_CLOCK),
                    _strip(json.loads(fb.read_text()), WALL_CLOCK),
                )
            elif f.endswith(".jsonl"):
                diff = _diff_json(_strip(_jsonl(fa), WALL_CLOCK), _strip(_jsonl(fb), WALL_CLOCK))
            elif f.endswith(".csv"):
                ra, rb = _csv_rows(fa), _csv_rows(fb)
                diff = _diff_rows(ra, rb)
            else:
                continue  # figures
            status = "same" if not diff else f"{len(diff)} differences"
            print(f"{name}/{f}: {status}")
            failures += [f"{name}/{f}{d}" for d in diff[:10]]
    pa, pb = before / "predict-hotel.stdout", after / "predict-hotel.stdout"
    if pa.exists() and pb.exists():
        same = _table_without_timing(pa.read_text()) == _table_without_timing(pb.read_text())
        print(f"predict evaluate hotel: {'same table' if same else 'different table'}")
        if not same:
            failures.append("predict evaluate hotel: the table differs")
    sa, sb = before / "mission-schema.stdout", after / "mission-schema.stdout"
    schema = _diff_json(_schema_without_docs(sa.read_text()), _schema_without_docs(sb.read_text()))
    docs = sa.read_text() != sb.read_text()
    print(
        f"mission schema: {'same' if not schema else 'different'} except descriptions"
        f"{' (descriptions reworded)' if docs and not schema else ''}"
    )
    failures += [f"schema{d}" for d in schema[:20]]
    for name in ("bt-leaves.stdout", "help.txt"):
        ta, tb = (before / name).read_text(), (after / name).read_text()
        if ta != tb:
            lines = list(difflib.unified_diff(ta.splitlines(), tb.splitlines(), lineterm="", n=0))
            notes.append(
                f"{name}: {sum(1 for x in lines if x.startswith(('+', '-')))} lines differ"
            )
            notes += ["  " + x for x in lines[:40]]
        else:
            print(f"{name}: same")
    for n in notes:
        print(n)
    if failures:
        print(f"\nDIFFERENT ({len(failures)}):")
        for f in failures:
            print("  " + f)
        return 1
    print("\nthe same: every episode, the prediction table and the schema (descriptions aside)")
    return 0


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = parser.add_subparsers(dest="what", required=True)
    rec = sub.add_parser("record", help="run the reference set into OUT")
    rec.add_argument("out", type=Path)
    rec.add_argument("--jobs", type=int, default=2)
    rec.add_argument("--hotel", type=Path, default=HOTEL, help="the hotel tracks (ETH/UCY frames)")
    cmp_ = sub.add_parser("compare", help="compare two records")
    cmp_.add_argument("before", type=Path)
    cmp_.add_argument("after", type=Path)
    args = parser.parse_args()
    if args.what == "record":
        record(args.out.resolve(), args.jobs, args.hotel)
        return 0
    return compare(args.before, args.after)


if __name__ == "__main__":
    sys.exit(main())
