"""Follow campaign: many seeds of one or more missions, their follow metrics side by side.

Run::

    .venv/bin/python benchmarks/follow_campaign.py                      # 3 missions × seeds 1..20
    .venv/bin/python benchmarks/follow_campaign.py missions/house.yaml --seeds 2 --duration 60
    .venv/bin/python benchmarks/follow_campaign.py A.yaml B.yaml --seeds 10 --first-seed 101 \\
        --duration 120 --jobs 4 --out out/campaign-ab

For every mission (default: ``missions/house.yaml``, ``missions/house_no_prediction.yaml``
and ``missions/house_no_waypoint_search.yaml``: the paper's episode and its two ablations) and
every seed (``--seeds N`` seeds from ``--first-seed``, default 20 seeds 1..20), one episode of
``pfctl bench`` runs (:func:`pfctl.app.campaign.run_campaign_episode`): learn the target's
profile in the simulator *with that seed* (the faces depend on the seed), run the follower for
``--duration`` simulated seconds (default 120) and return the episode's
:func:`~pfctl.core.metrics.follow_metrics`. ``--jobs`` workers (default: the number of
CPUs) run at once (:func:`pfctl.bench.runner.run_in_processes`): a fresh process per episode,
started with the ``spawn`` context (PyBullet connections must not be forked), one BLAS/OpenMP
thread. An episode that raises becomes a row whose ``status`` is ``error`` (with the message), one
that runs past ``--timeout`` wall seconds is ended with status ``timeout``; the other episodes go
on. Ctrl-C stops the workers and still writes what finished. ``pfctl bench`` runs the same
episodes with resuming, ``--vary``, Ray and bootstrap intervals; this script keeps the view by
re-acquisition method.

It prints one line per finished episode and at the end, per mission: episodes (and errors), the
mean following rate with its standard deviation and range, losses, re-acquisition success
(re-acquired losses / losses, and how many by prediction / way-point search / other), the median
time to re-find (over all re-acquisitions), identity switches, collisions and the median distance
driven. It writes into ``--out`` (default ``out/campaign/``):

- ``episodes.csv``: one row per episode (mission, seed, status, every metric, wall times);
- ``summary.json``: the configuration, the machine and the per-mission summary;
- ``campaign.png``: following rate (mean ± sd, one dot per episode), re-acquisition success
  (stacked by how), and a box plot of the time to re-find, one bar/box per mission.

One episode of 120 simulated seconds costs 45–70 s of wall time on one core (camera rendering,
perception and 5–10 s of learning): the default campaign (60 episodes) took 29 min with
``--jobs 2`` on a 2-CPU machine. ``summary.json`` records ``git describe --always --dirty`` and
the missions' SHA-1 at the start (the workers import the code as it is when each episode starts).
It prints figures; it asserts nothing.
"""

from __future__ import annotations

import os

# One BLAS/OpenMP thread per process: set before numpy is imported (the spawned workers import
# this module first, so they inherit it too).
for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"

import argparse  # noqa: E402
import csv  # noqa: E402
import json  # noqa: E402
import math  # noqa: E402
import platform  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402
from typing import Any  # noqa: E402

import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
DEFAULT_MISSIONS = (
    "missions/house.yaml",
    "missions/house_no_prediction.yaml",
    "missions/house_no_waypoint_search.yaml",
)
HOW = ("prediction", "waypoint_search", "other")
#: The columns of ``episodes.csv``, in order.
FIELDS = (
    "mission",
    "seed",
    "status",
    "error",
    "following_rate",
    "first_identified_s",
    "losses",
    "reacquired",
    "unrecovered_losses",
    "by_prediction",
    "by_waypoint_search",
    "by_other",
    "median_time_to_refind_s",
    "refind_times_s",
    "identity_switches",
    "collisions",
    "distance_m",
    "duration_s",
    "sim_time_s",
    "wall_time_s",
    "learn_wall_s",
    "tick_ms_median",
    "tick_ms_p99",
)


# -- episode rows ---------------------------------------------------------------------------------


def record_row(record: dict[str, Any]) -> dict[str, Any]:
    """A ``pfctl bench`` episode record as a row of ``episodes.csv`` (:data:`FIELDS`)."""
    row: dict[str, Any] = dict.fromkeys(FIELDS)
    row.update(mission=record["mission"], seed=record["seed"], status=record["status"])
    row["error"] = record["error"] or ""
    row.update(record["metrics"] or {})
    timing = record["timing"] or {}
    row.update(
        wall_time_s=timing.get("episode_wall_s"),
        learn_wall_s=timing.get("learn_wall_s"),
        tick_ms_median=timing.get("tick_ms_median"),
        tick_ms_p99=timing.get("tick_ms_p99"),
    )
    return {k: row[k] for k in FIELDS}


# -- summary --------------------------------------------------------------------------------------


def _median(values: list[float]) -> float | None:
    return float(np.median(values)) if values else None


def summarize(rows: list[dict[str, Any]]) -> dict[str, Any]:
    """Per-mission aggregate of the episode rows (errors counted, not averaged)."""
    ok = [r for r in rows if r["status"] == "ok"]
    rates = np.array([r["following_rate"] for r in ok], dtype=float)
    losses = sum(r["losses"] for r in ok)
    reacquired = sum(r["reacquired"] for r in ok)
    refinds = [t for r in ok for t in r["refind_times_s"]]
    return {
        "episodes": len(rows),
        "ok": len(ok),
        "errors": len(rows) - len(ok),
        "following_rate_mean": float(rates.mean()) if len(rates) else None,
        "following_rate_sd": float(rates.std(ddof=1)) if len(rates) > 1 else None,
        "following_rate_min": float(rates.min()) if len(rates) else None,
        "following_rate_max": float(rates.max()) if len(rates) else None,
        "never_identified": sum(r["first_identified_s"] is None for r in ok),
        "losses": losses,
        "reacquired": reacquired,
        "reacquisition_success": reacquired / losses if losses else None,
        "reacquired_by": {how: sum(r[f"by_{how}"] for r in ok) for how in HOW},
        "median_time_to_refind_s": _median(refinds),
        "time_to_refind_s": refinds,
        "identity_switches": sum(r["identity_switches"] for r in ok),
        "collisions": sum(r["collisions"] for r in ok),
        "median_distance_m": _median([r["distance_m"] for r in ok]),
        "median_episode_wall_s": _median([r["wall_time_s"] + r["learn_wall_s"] for r in ok]),
    }


def _pct(x: float | None) -> str:
    return "—" if x is None else f"{100 * x:.1f}%"


def _num(x: float | None, unit: str = "", fmt: str = ".1f") -> str:
    return "—" if x is None else f"{x:{fmt}}{unit}"


def print_table(summary: dict[str, dict[str, Any]]) -> None:
    """The per-mission comparison as a rich table (metrics as rows, one column per mission)."""
    from rich.console import Console
    from rich.table import Table

    table = Table(title="follow campaign")
    table.add_column("metric")
    for label in summary:
        table.add_column(label, justify="right")

    def row(name: str, fn: Any) -> None:
        table.add_row(name, *(fn(s) for s in summary.values()))

    row("episodes (errors)", lambda s: f"{s['ok']} ({s['errors']})")
    row(
        "following rate mean ± sd",
        lambda s: f"{_pct(s['following_rate_mean'])} ± {_pct(s['following_rate_sd'])}",
    )
    row(
        "  range",
        lambda s: f"{_pct(s['following_rate_min'])} – {_pct(s['following_rate_max'])}",
    )
    row("never identified", lambda s: str(s["never_identified"]))
    row("losses", lambda s: str(s["losses"]))
    row(
        "re-acquired / losses",
        lambda s: f"{s['reacquired']}/{s['losses']} ({_pct(s['reacquisition_success'])})",
    )
    for how in HOW:
        row(f"  by {how.replace('_', ' ')}", lambda s, h=how: str(s["reacquired_by"][h]))
    row("median time to re-find", lambda s: _num(s["median_time_to_refind_s"], " s"))
    row("identity switches", lambda s: str(s["identity_switches"]))
    row("collisions", lambda s: str(s["collisions"]))
    row("median distance", lambda s: _num(s["median_distance_m"], " m"))
    row("median wall / episode", lambda s: _num(s["median_episode_wall_s"], " s", ".0f"))
    Console(width=max(100, 30 + 22 * len(summary))).print(table)


def figure_png(summary: dict[str, dict[str, Any]], rows: list[dict[str, Any]], path: Path) -> None:
    """Bar chart of the following rate and of re-acquisition success, box plot of re-find time."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    labels = list(summary)
    x = np.arange(len(labels))
    fig, axes = plt.subplots(1, 3, figsize=(5 + 3.2 * len(labels), 4.6), layout="constrained")
    rng = np.random.default_rng(0)

    ax = axes[0]
    means = [summary[k]["following_rate_mean"] or 0.0 for k in labels]
    sds = [summary[k]["following_rate_sd"] or 0.0 for k in labels]
    ax.bar(x, means, yerr=sds, capsize=4, color="tab:blue", alpha=0.6)
    for i, k in enumerate(labels):
        vals = [r["following_rate"] for r in rows if r["mission"] == k and r["status"] == "ok"]
        ax.scatter(i + rng.uniform(-0.15, 0.15, len(vals)), vals, s=12, color="k", zorder=3)
    ax.set_ylim(0, 1)
    ax.set_title("following rate\n(bar: mean ± sd; dots: episodes)", fontsize=10)

    ax = axes[1]
    bottom = np.zeros(len(labels))
    colors = {"prediction": "tab:green", "waypoint_search": "tab:orange", "other": "tab:gray"}
    for how in HOW:
        share = np.array(
            [
                summary[k]["reacquired_by"][how] / summary[k]["losses"]
                if summary[k]["losses"]
                else 0
                for k in labels
            ]
        )
        ax.bar(x, share, bottom=bottom, color=colors[how], label=f"by {how.replace('_', ' ')}")
        bottom += share
    for i, k in enumerate(labels):
        ax.text(
            i,
            bottom[i] + 0.02,
            f"{summary[k]['reacquired']}/{summary[k]['losses']}",
            ha="center",
            fontsize=9,
        )
    ax.set_ylim(0, 1.3)
    ax.set_yticks(np.linspace(0, 1, 6))
    ax.legend(loc="upper center", fontsize=8, ncol=3, handlelength=1)
    ax.set_title("re-acquisition success\n(re-acquired / losses, by how)", fontsize=10)

    ax = axes[2]
    data = [summary[k]["time_to_refind_s"] for k in labels]
    if any(data):
        ax.boxplot(
            [d if d else [math.nan] for d in data], positions=x, widths=0.5, showfliers=False
        )
        for i, d in enumerate(data):
            ax.scatter(i + rng.uniform(-0.12, 0.12, len(d)), d, s=10, color="k", alpha=0.6)
    else:
        ax.text(0.5, 0.5, "no re-acquisitions", ha="center", transform=ax.transAxes)
    ax.set_ylabel("s")
    ax.set_ylim(bottom=0)
    ax.set_title("time to re-find\n(over re-acquisitions)", fontsize=10)

    for ax in axes:
        ax.set_xticks(x, labels, rotation=15, ha="right", fontsize=9)
    fig.savefig(path, dpi=120)
    plt.close(fig)


# -- main -----------------------------------------------------------------------------------------


def _csv_value(value: Any) -> Any:
    if value is None:
        return ""
    if isinstance(value, list):
        return ";".join(f"{v:.2f}" for v in value)
    if isinstance(value, float):
        return f"{value:.4f}"
    return value


def _progress_line(done: int, total: int, row: dict[str, Any]) -> str:
    head = f"[{done}/{total}] {row['mission']} seed {row['seed']}: "
    if row["status"] != "ok":
        return head + f"ERROR {row['error']}"
    first = row["first_identified_s"]
    return head + (
        f"following {100 * row['following_rate']:.1f}%, "
        f"first id {'never' if first is None else f'{first:.1f} s'}, "
        f"losses {row['losses']} (re-acquired {row['reacquired']}: "
        f"{row['by_prediction']} pred, {row['by_waypoint_search']} wp, {row['by_other']} other), "
        f"switches {row['identity_switches']}, collisions {row['collisions']}, "
        f"{row['distance_m']:.1f} m, wall {row['learn_wall_s'] + row['wall_time_s']:.0f} s"
    )


def _git_state() -> str | None:
    """``git describe --always --dirty`` of the repository (the code the workers ran)."""
    import subprocess

    try:
        out = subprocess.run(
            ["git", "describe", "--always", "--dirty"],
            cwd=ROOT,
            capture_output=True,
            text=True,
            timeout=10,
            check=True,
        )
    except (OSError, subprocess.SubprocessError):
        return None
    return out.stdout.strip() or None


def _sha1(path: str) -> str:
    """The SHA-1 of a mission file, to tell which version a campaign ran."""
    import hashlib

    return hashlib.sha1(Path(path).read_bytes()).hexdigest()


def main(argv: list[str] | None = None) -> int:
    """Parse the arguments, run the campaign, print and write the results; the exit status."""
    parser = argparse.ArgumentParser(
        description=__doc__.splitlines()[0], formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("missions", nargs="*", help="mission YAMLs (default: the three houses)")
    parser.add_argument("--seeds", type=int, default=20, help="number of seeds (default 20)")
    parser.add_argument("--first-seed", type=int, default=1, help="first seed (default 1)")
    parser.add_argument("--duration", type=float, default=120.0, help="simulated s per episode")
    parser.add_argument("--jobs", type=int, default=os.cpu_count() or 1, help="worker processes")
    parser.add_argument(
        "--timeout",
        type=float,
        default=None,
        help="wall seconds before an episode is killed (default max(600, 10 × duration); 0: none)",
    )
    parser.add_argument("--out", type=Path, default=Path("out/campaign"), help="output folder")
    args = parser.parse_args(argv)

    paths = args.missions or [str(ROOT / p) for p in DEFAULT_MISSIONS]
    if args.seeds < 1 or args.jobs < 1 or not (math.isfinite(args.duration) and args.duration > 0):
        print("--seeds, --jobs and --duration must be positive", file=sys.stderr)
        return 2
    from pfctl.errors import UserError
    from pfctl.mission import load_mission

    for p in paths:  # fail early, in one line, on a missing or bad mission
        try:
            load_mission(p)
        except UserError as err:
            print(err, file=sys.stderr)
            return 2
    try:
        args.out.mkdir(parents=True, exist_ok=True)
    except OSError as err:
        print(f"--out {args.out}: cannot create it: {err.strerror or err}", file=sys.stderr)
        return 2
    timeout = max(600.0, 10 * args.duration) if args.timeout is None else args.timeout

    from pfctl.app.campaign import run_campaign_episode
    from pfctl.bench.runner import run_in_processes
    from pfctl.commands.bench import build_campaign

    seeds = list(range(args.first_seed, args.first_seed + args.seeds))
    try:
        campaign = build_campaign(
            [Path(p) for p in paths],
            "follow",
            args.seeds,
            args.first_seed,
            args.duration,
            [],
            timeout,
        )
    except UserError as err:
        print(err, file=sys.stderr)
        return 2
    labels = [g.label for g in campaign.groups]  # one group per mission: no variants
    paths = [g.path for g in campaign.groups]
    specs = campaign.specs()  # seed-major: a campaign cut short compares missions on the same seeds
    jobs = min(args.jobs, len(specs))
    print(
        f"follow campaign: {len(paths)} mission(s) × {len(seeds)} seeds "
        f"({seeds[0]}..{seeds[-1]}), {args.duration:g} s simulated each, {jobs} workers; "
        f"{platform.node()} | {platform.platform()} | {os.cpu_count()} CPUs | "
        f"python {platform.python_version()}",
        flush=True,
    )

    git = _git_state()  # the code the workers will import
    digests = {label: _sha1(path) for label, path in zip(labels, paths, strict=True)}
    csv_path = args.out / "episodes.csv"
    started = time.perf_counter()
    rows: list[dict[str, Any]] = []
    with csv_path.open("w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=FIELDS)
        writer.writeheader()

        def on_record(record: dict[str, Any]) -> None:
            row = record_row(record)
            rows.append(row)
            writer.writerow({k: _csv_value(row.get(k)) for k in FIELDS})
            f.flush()
            print(_progress_line(len(rows), len(specs), row), flush=True)

        try:
            run_in_processes(specs, jobs, on_record, run_campaign_episode)
        except KeyboardInterrupt:
            print(f"interrupted: {len(specs) - len(rows)} episodes not run", file=sys.stderr)
    wall = time.perf_counter() - started

    order = {(t.mission_label, t.seed): i for i, t in enumerate(specs)}
    rows.sort(key=lambda r: order[(r["mission"], r["seed"])])
    with csv_path.open("w", newline="") as f:  # again, in task order
        writer = csv.DictWriter(f, fieldnames=FIELDS)
        writer.writeheader()
        writer.writerows({k: _csv_value(r.get(k)) for k in FIELDS} for r in rows)
    summary = {label: summarize([r for r in rows if r["mission"] == label]) for label in labels}
    print(f"\n{len(rows)}/{len(specs)} episodes in {wall:.0f} s wall")
    print_table(summary)
    report = {
        "config": {
            "missions": dict(zip(labels, paths, strict=True)),
            "seeds": seeds,
            "duration_s": args.duration,
            "jobs": jobs,
            "timeout_s": timeout,
            "wall_s": wall,
            "finished": len(rows),
            "planned": len(specs),
            "git": git,
            "mission_sha1": digests,
        },
        "machine": {
            "platform": platform.platform(),
            "cpus": os.cpu_count(),
            "python": platform.python_version(),
            "numpy": np.__version__,
        },
        "missions": summary,
    }
    (args.out / "summary.json").write_text(json.dumps(report, indent=2) + "\n")
    figure_png(summary, rows, args.out / "campaign.png")
    print(f"wrote {csv_path}, {args.out / 'summary.json'}, {args.out / 'campaign.png'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
