"""Follow campaign: many seeds of one or more missions, their follow metrics side by side.

Run::

    .venv/bin/python benchmarks/follow_campaign.py                      # 3 missions × seeds 1..20
    .venv/bin/python benchmarks/follow_campaign.py missions/house.yaml --seeds 2 --duration 60
    .venv/bin/python benchmarks/follow_campaign.py A.yaml B.yaml --seeds 10 --first-seed 101 \\
        --duration 120 --jobs 4 --out out/campaign-ab

For every mission (default: ``missions/house.yaml``, ``missions/house_no_prediction.yaml``
and ``missions/house_no_waypoint_search.yaml``: the paper's episode and its two ablations) and
every seed (``--seeds N`` seeds from ``--first-seed``, default 20 seeds 1..20), one worker process
loads the mission, learns the target's profile in the simulator *with that seed* (the faces
depend on the seed), runs the follower for ``--duration`` simulated seconds (default 120) with
:func:`pfctl.commands.follow.run_sim_episode` and returns the episode's
:func:`~pfctl.core.episode_metrics.follow_metrics`. ``--jobs`` workers (default: the number of
CPUs) run at once; each is a fresh process started with the ``spawn`` context (PyBullet
connections must not be forked) with one BLAS/OpenMP thread. An episode that raises, dies or
exceeds ``--timeout`` wall seconds becomes a row whose ``status`` is ``error`` (with the message);
the other episodes go on. Ctrl-C stops the workers and still writes what finished.

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
import multiprocessing as mp  # noqa: E402
import platform  # noqa: E402
import signal  # noqa: E402
import sys  # noqa: E402
import threading  # noqa: E402
import time  # noqa: E402
import traceback  # noqa: E402
from collections import deque  # noqa: E402
from dataclasses import dataclass  # noqa: E402
from multiprocessing.connection import Connection, wait  # noqa: E402
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


@dataclass(frozen=True)
class Task:
    """One episode to run: a mission file (and its label in the tables) and a seed."""

    label: str
    path: str
    seed: int
    duration: float


# -- the worker (a spawned process) ---------------------------------------------------------------


def run_episode(task: Task) -> dict[str, Any]:
    """Learn the target with ``task.seed``, run one follow episode, return its metric row."""
    from rich.console import Console

    from pfctl.commands.follow import _profile, _sim_robot, run_sim_episode
    from pfctl.core.episode_metrics import MetricParams, follow_metrics
    from pfctl.mission import load_mission

    mission = load_mission(task.path)
    console = Console(stderr=True, quiet=True)
    start = time.perf_counter()
    profile = _profile(mission, None, task.seed, console, task.path)
    learn_s = time.perf_counter() - start
    robot = _sim_robot(mission, task.seed, False, task.path)
    with robot:
        result = run_sim_episode(mission, robot, profile, task.duration)
    lo, hi = mission.control.following_band
    metrics = follow_metrics(result.log, MetricParams(band=(lo, hi)))
    refinds = [r.time_to_refind for r in metrics.reacquisitions]
    ticks = 1000.0 * np.asarray(result.tick_seconds, dtype=float)
    row: dict[str, Any] = {
        "mission": task.label,
        "seed": task.seed,
        "status": "ok",
        "error": "",
        "following_rate": metrics.following_rate,
        "first_identified_s": metrics.first_identified_s,
        "losses": metrics.losses,
        "reacquired": len(metrics.reacquisitions),
        "unrecovered_losses": metrics.unrecovered_losses,
        "median_time_to_refind_s": metrics.median_time_to_refind_s,
        "refind_times_s": refinds,
        "identity_switches": metrics.identity_switches,
        "collisions": metrics.collisions,
        "distance_m": metrics.distance_m,
        "duration_s": metrics.duration_s,
        "sim_time_s": result.sim_time,
        "wall_time_s": result.wall_time,
        "learn_wall_s": learn_s,
        "tick_ms_median": float(np.median(ticks)) if len(ticks) else None,
        "tick_ms_p99": float(np.percentile(ticks, 99)) if len(ticks) else None,
    }
    for how in HOW:
        row[f"by_{how}"] = sum(r.how == how for r in metrics.reacquisitions)
    return row


def error_row(task: Task, message: str) -> dict[str, Any]:
    """The row of an episode that did not finish."""
    row: dict[str, Any] = dict.fromkeys(FIELDS)
    row.update(mission=task.label, seed=task.seed, status="error", error=message)
    return row


def _exit_with_parent(parent: int) -> None:
    """End this worker at once if the campaign process that started it goes away."""

    def watch() -> None:
        while True:
            time.sleep(2.0)
            if os.getppid() != parent:
                os._exit(3)

    threading.Thread(target=watch, name="parent-watch", daemon=True).start()


def _worker(task: Task, conn: Connection, parent: int) -> None:
    """Process entry point: run ``task`` and send its row (an error row if it raised)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # the parent handles Ctrl-C
    _exit_with_parent(parent)
    try:
        row = run_episode(task)
    except BaseException as err:  # any failure becomes an error row
        last = traceback.extract_tb(err.__traceback__)[-1:] if err.__traceback__ else []
        where = f" ({Path(last[0].filename).name}:{last[0].lineno})" if last else ""
        row = error_row(task, f"{type(err).__name__}: {err}{where}".replace("\n", " "))
    try:
        conn.send(row)
        conn.close()
    except OSError:  # the campaign is gone: nobody to tell
        pass


# -- the scheduler --------------------------------------------------------------------------------


@dataclass
class _Running:
    task: Task
    proc: Any  # multiprocessing.context.SpawnProcess
    conn: Connection
    started: float


def run_campaign(
    tasks: list[Task], jobs: int, timeout: float, on_row: Any, start_method: str = "spawn"
) -> list[dict[str, Any]]:
    """Run ``tasks`` in at most ``jobs`` fresh processes at once; ``on_row(row)`` as each ends.

    Each episode gets its own process (no state, memory or PyBullet connection carried over);
    a process that dies without answering or runs longer than ``timeout`` wall seconds (0: no
    limit) yields an error row. Ctrl-C kills the running workers and returns what finished.
    """
    ctx = mp.get_context(start_method)
    pending = deque(tasks)
    running: list[_Running] = []
    rows: list[dict[str, Any]] = []

    def finish(job: _Running, row: dict[str, Any]) -> None:
        running.remove(job)
        job.conn.close()
        job.proc.join(timeout=10)
        if job.proc.is_alive():
            job.proc.kill()
            job.proc.join()
        rows.append(row)
        on_row(row)

    try:
        while pending or running:
            while pending and len(running) < jobs:
                task = pending.popleft()
                recv, send = ctx.Pipe(duplex=False)
                # not daemonic: an episode starts its own face worker process (daemonic
                # processes may not have children); _exit_with_parent and the kills below end it
                proc = ctx.Process(target=_worker, args=(task, send, os.getpid()), daemon=False)
                proc.start()
                send.close()  # the child holds the only write end: EOF when it dies
                running.append(_Running(task, proc, recv, time.monotonic()))
            ready = wait([job.conn for job in running], timeout=1.0)
            for job in [j for j in running if j.conn in ready]:
                try:
                    row = job.conn.recv()
                except (EOFError, OSError):
                    job.proc.join(timeout=10)
                    code = job.proc.exitcode
                    row = error_row(job.task, f"worker died (exit code {code})")
                finish(job, row)
            if timeout > 0:
                now = time.monotonic()
                for job in [j for j in running if now - j.started > timeout]:
                    job.proc.kill()
                    finish(job, error_row(job.task, f"timed out after {timeout:g} s wall"))
    except KeyboardInterrupt:
        for job in running:
            job.proc.kill()
        for job in running:
            job.proc.join()
            job.conn.close()
        print(
            f"interrupted: {len(running)} running and {len(pending)} pending episodes dropped",
            file=sys.stderr,
        )
    return rows


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


def _labels(paths: list[str]) -> list[str]:
    """File stems, or the paths themselves when two stems collide."""
    stems = [Path(p).stem for p in paths]
    return stems if len(set(stems)) == len(stems) else list(paths)


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

    labels = _labels(paths)
    seeds = list(range(args.first_seed, args.first_seed + args.seeds))
    # Seed-major order: a campaign cut short still compares the missions on the same seeds.
    tasks = [
        Task(label, path, seed, args.duration)
        for seed in seeds
        for label, path in zip(labels, paths, strict=True)
    ]
    jobs = min(args.jobs, len(tasks))
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
    with csv_path.open("w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=FIELDS)
        writer.writeheader()
        done = 0

        def on_row(row: dict[str, Any]) -> None:
            nonlocal done
            done += 1
            writer.writerow({k: _csv_value(row.get(k)) for k in FIELDS})
            f.flush()
            print(_progress_line(done, len(tasks), row), flush=True)

        rows = run_campaign(tasks, jobs, timeout, on_row)
    wall = time.perf_counter() - started

    order = {(t.label, t.seed): i for i, t in enumerate(tasks)}
    rows.sort(key=lambda r: order[(r["mission"], r["seed"])])
    with csv_path.open("w", newline="") as f:  # again, in task order
        writer = csv.DictWriter(f, fieldnames=FIELDS)
        writer.writeheader()
        writer.writerows({k: _csv_value(r.get(k)) for k in FIELDS} for r in rows)
    summary = {label: summarize([r for r in rows if r["mission"] == label]) for label in labels}
    print(f"\n{len(rows)}/{len(tasks)} episodes in {wall:.0f} s wall")
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
            "planned": len(tasks),
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
