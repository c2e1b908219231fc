"""`pfctl bench`: a campaign of seeded episodes, missions and variants side by side.

``pfctl bench MISSION... [--homes N --home-seed S] [--task follow|search] [--episodes N]
[--seed S] [--duration D] [--vary KEY=V1,V2,...]... [--workers K | --ray ADDRESS] [--out DIR]
[--resume]`` runs episode
``i`` (seed ``S + i``) of every mission under every variant (the cross product of the
``--vary``s, :mod:`pfctl.bench.variants`) headless in the simulated house — learn the target,
then follow them (``pfctl follow``) or find them hidden somewhere (``pfctl search``) — in
``--workers`` spawned processes, or as Ray tasks on a cluster (``--ray``). Each finished episode
is appended to ``OUT/results.jsonl`` at once; ``--resume`` continues a campaign from it and skips
the episodes already done (:mod:`pfctl.bench.results`). At the end (also after Ctrl-C, with what
finished) it prints per mission and variant the mean and 95 % bootstrap interval of each metric
(:mod:`pfctl.bench.aggregate`) and writes ``summary.csv``, ``summary.md``, ``boxplots.png`` and
``episodes.csv`` into ``--out``.

Generated homes: ``--homes N --home-seed S`` writes the homes of seeds ``S..S+N-1`` (``pfctl
mission generate --seed K``) into ``OUT/homes/`` and runs each of them (default one episode per
home); a folder given as a MISSION stands for the missions in it. The homes of ``--homes`` (and
those of one folder) are summarised together, per variant, under one label (``homes``, or the
folder's name); ``episodes.csv`` keeps each episode's file.

Bad options, missions or ``--vary`` values end in one line and exit status 2 before anything is
written. A worker process that dies (``kill -9``) has its episode run again on a new one, once;
after a second death the episode is recorded as an error. A campaign with episodes in error
(in this run or an earlier one of it) writes its summary and exits 1, with one line saying how
many and where their errors are (``results.jsonl``, ``episodes.csv``); ``--resume`` runs them
again. Ctrl-C or SIGTERM (the first one; later ones are ignored while it stops,
:mod:`pfctl.bench.stop_signals`) stops the workers, keeps the results file, writes the summary of
what finished and exits 130 (SIGINT) or 143 (SIGTERM) with one line saying how to continue.
"""

from __future__ import annotations

import math
import os
import time
from pathlib import Path
from typing import Annotated, Any

import typer
from rich.console import Console

from pfctl.app.campaign import run_campaign_episode
from pfctl.app.homes import write_homes
from pfctl.bench.aggregate import metrics_for, summarize
from pfctl.bench.episode import BLAS_THREAD_VARIABLES
from pfctl.bench.plan import (
    TASKS,
    Campaign,
    EpisodeSpec,
    MissionVariant,
    load_variant,
    mission_digest,
)
from pfctl.bench.plan import mission_labels as _labels
from pfctl.bench.results import RESULTS_FILE, episode_key, latest, open_results
from pfctl.bench.runner import (
    RAY_INSTALL,
    connect_ray,
    disconnect_ray,
    ray_address_issue,
    ray_available,
    run_in_processes,
    run_on_ray,
)
from pfctl.bench.stop_signals import StopSignals
from pfctl.bench.variants import parse_vary, variants
from pfctl.commands import check_seed
from pfctl.errors import UserError
from pfctl.files import check_output_dir, write_output
from pfctl.mission.types import SEED_MAX
from pfctl.progress import progress_bar

#: The folder of ``--out`` the ``--homes`` are generated into, and their label in the summary.
HOMES_FOLDER = "homes"
#: Default simulated seconds of an episode per task.
DEFAULT_DURATION = {"follow": 120.0, "search": 180.0}


def _check_options(
    task: str, episodes: int, workers: int, duration: float, timeout: float | None
) -> None:
    if task not in TASKS:
        raise UserError(f"--task {task}: expected one of {', '.join(TASKS)}")
    if episodes < 1:
        raise UserError(f"--episodes: expected at least 1, got {episodes}")
    if workers < 1:
        raise UserError(f"--workers: expected at least 1, got {workers}")
    if not (math.isfinite(duration) and duration > 0):
        raise UserError(f"--duration: expected a positive number of seconds, got {duration:g}")
    if timeout is not None and not (math.isfinite(timeout) and timeout >= 0):
        raise UserError(f"--timeout: expected seconds >= 0 (0: none), got {timeout:g}")


def build_campaign(
    missions: list[Path],
    task: str,
    episodes: int,
    seed: int,
    duration: float,
    vary: list[str],
    timeout: float,
    labels: list[str | None] | None = None,
) -> Campaign:
    """The campaign of the command's arguments: every mission under every variant, loaded and
    validated (one-line :class:`UserError` for the first bad one). ``labels``: per mission, the
    label it is summarised under (the missions of a folder or of ``--homes`` share one), or None
    for its own (the file's stem)."""
    combos = variants([parse_vary(v) for v in vary])
    paths = [os.path.normpath(p) for p in missions]
    if len(set(paths)) != len(paths):
        raise UserError("MISSION: the same mission file is given twice")
    own = _labels(paths)
    given = labels if labels is not None else [None] * len(paths)
    groups = []
    for label, path in zip(
        [g if g is not None else o for g, o in zip(given, own, strict=True)], paths, strict=True
    ):
        for variant in combos:
            mission = load_variant(path, variant)
            if task == "search" and mission.scenario.target is None:
                raise UserError(f"{path}: scenario.target: --task search needs a target to find")
            groups.append(MissionVariant(label, path, variant, mission, mission_digest(mission)))
    return Campaign(task, tuple(groups), episodes, seed, duration, timeout)  # type: ignore[arg-type]


def _episode_line(record: dict[str, Any], done: int, total: int) -> str:
    mission = record["mission"]
    stem = Path(record["mission_file"]).stem
    if stem != mission and record["mission_file"] != mission:  # a home of a shared label
        mission = f"{mission}/{stem}"
    head = f"[{done}/{total}] {mission} · {record['variant']} · seed {record['seed']}: "
    if record["status"] == "error":
        return head + f"[red]error[/red] {record['error']}"
    m, timing = record["metrics"], record["timing"] or {}
    wall = f", {timing['wall_s']:.0f} s wall" if timing.get("wall_s") is not None else ""
    late = " [yellow](timed out)[/yellow]" if record["status"] == "timeout" else ""
    if record["task"] == "search":
        found = f"found in {m['time_to_find_s']:.1f} s" if m["found"] else "not found"
        return head + f"{found} ({m['region']}), {m['distance_m']:.1f} m{wall}{late}"
    return head + (
        f"following {100 * m['following_rate']:.1f}%, losses {m['losses']} "
        f"(re-found {m['reacquired']}), switches {m['identity_switches']}, "
        f"collisions {m['collisions']}, {m['distance_m']:.1f} m{wall}{late}"
    )


def _write_summary(
    campaign: Campaign, records: list[dict[str, Any]], out: Path, console: Console
) -> list[Path]:
    """Print the per-variant table and write the summary files; the files written."""
    from pfctl.bench.plots import boxplots_png
    from pfctl.bench.report import episodes_csv, summary_csv, summary_markdown, summary_table

    planned = {s.key for s in campaign.specs()}
    kept = [r for r in latest(records).values() if episode_key(r) in planned]
    order = {s.key: i for i, s in enumerate(campaign.specs())}
    kept.sort(key=lambda r: order[episode_key(r)])
    metrics = metrics_for(campaign.task)
    groups = list(dict.fromkeys((g.label, g.variant.name) for g in campaign.groups))
    summaries = summarize(kept, groups, metrics)
    last = campaign.seed + campaign.episodes - 1
    title = (
        f"pfctl bench: {campaign.task}, {len(kept)}/{len(planned)} episodes, "
        f"{campaign.duration:g} s simulated, seeds {campaign.seed}..{last}"
    )
    Console(width=max(100, 40 + 24 * len(metrics))).print(summary_table(summaries, metrics, title))
    files = [
        (out / "summary.csv", summary_csv(summaries, metrics)),
        (out / "summary.md", summary_markdown(summaries, metrics, title)),
        (out / "episodes.csv", episodes_csv(kept)),
        (out / "boxplots.png", boxplots_png(summaries, metrics, title)),
    ]
    return [write_output(path, data) for path, data in files]


def _expand_folders(missions: list[Path]) -> tuple[list[Path], list[str | None]]:
    """Mission files, a folder standing for the missions in it (``*.yaml``, sorted, summarised
    together under the folder's name); each file's shared label or None."""
    files: list[Path] = []
    labels: list[str | None] = []
    for path in missions:
        if not path.is_dir():
            files.append(path)
            labels.append(None)
            continue
        inside = sorted(p for p in path.iterdir() if p.suffix in (".yaml", ".yml") and p.is_file())
        if not inside:
            raise UserError(f"{path}: a folder without mission files (*.yaml)")
        files += inside
        labels += [path.resolve().name or str(path)] * len(inside)
    return files, labels


def bench(
    missions: Annotated[
        list[Path] | None,
        typer.Argument(
            help="Mission YAMLs to run, or folders of them (e.g. generated homes).",
            show_default=False,
        ),
    ] = None,
    task: Annotated[
        str, typer.Option("--task", help="follow (pfctl follow) or search (pfctl search).")
    ] = "follow",
    episodes: Annotated[
        int | None,
        typer.Option(
            "--episodes", help="Episodes per mission and variant (default 10; with --homes 1)."
        ),
    ] = None,
    seed: Annotated[
        int,
        typer.Option("--seed", callback=check_seed, help="Seed of episode 0; episode i: seed + i."),
    ] = 1,
    duration: Annotated[
        float | None,
        typer.Option(
            "--duration", help="Simulated s per episode (default follow 120, search 180)."
        ),
    ] = None,
    vary: Annotated[
        list[str] | None,
        typer.Option(
            "--vary",
            help="KEY=V1,V2,...: a mission key's values (YAML; @FILE reads one); repeatable.",
        ),
    ] = None,
    workers: Annotated[
        int | None,
        typer.Option(
            "--workers", help="Worker processes (default: the CPUs); with --ray local, its CPUs."
        ),
    ] = None,
    ray: Annotated[
        str | None,
        typer.Option("--ray", help="Run as Ray tasks: auto, ray://HOST:PORT, or local."),
    ] = None,
    out: Annotated[
        Path, typer.Option("--out", help="Folder for results.jsonl and the summary.")
    ] = Path("out/bench"),
    resume: Annotated[
        bool,
        typer.Option("--resume", help="Continue the campaign in --out; skip finished episodes."),
    ] = False,
    timeout: Annotated[
        float | None,
        typer.Option(
            "--timeout",
            help="Wall s before an episode is ended (default max(600, 10 x duration); 0: none).",
        ),
    ] = None,
    homes: Annotated[
        int | None,
        typer.Option(
            "--homes", help="Also run N generated homes (pfctl mission generate), in OUT/homes/."
        ),
    ] = None,
    home_seed: Annotated[
        int,
        typer.Option("--home-seed", callback=check_seed, help="Seed of the first generated home."),
    ] = 1,
) -> None:
    """Run seeded episodes of missions and variants; summarise each metric per variant."""
    seconds = DEFAULT_DURATION.get(task, 120.0) if duration is None else duration
    jobs = (os.cpu_count() or 1) if workers is None else workers
    if episodes is None:
        episodes = 1 if homes is not None else 10
    if homes is not None and homes < 1:
        raise UserError(f"--homes: expected at least 1, got {homes}")
    if homes is not None and home_seed + homes - 1 > SEED_MAX:
        raise UserError(
            f"--home-seed {home_seed} --homes {homes}: the last home's seed is above {SEED_MAX}"
        )
    if not missions and homes is None:
        raise UserError("MISSION: expected mission files, a folder of missions, or --homes N")
    _check_options(task, episodes, jobs, seconds, timeout)
    if seed + episodes - 1 > SEED_MAX:
        raise UserError(
            f"--seed {seed} --episodes {episodes}: the last episode's seed "
            f"{seed + episodes - 1} is above {SEED_MAX} (2**32 - 1)"
        )
    issue = ray_address_issue(ray) if ray is not None else None
    if issue is not None:
        raise UserError(f"--ray {ray}: {issue}")
    if ray is not None and not ray_available():
        raise UserError(f"--ray {ray}: Ray is not installed; {RAY_INSTALL}")
    check_output_dir(out, "--out")
    limit = max(600.0, 10 * seconds) if timeout is None else timeout
    files, labels = _expand_folders(missions or [])
    for v in vary or []:  # a bad --vary is one line before the homes are written
        parse_vary(v)
    if homes is not None:
        seeds = list(range(home_seed, home_seed + homes))
        Console(stderr=True).print(
            f"pfctl bench: generating {homes} homes (seeds {seeds[0]}..{seeds[-1]}) into "
            f"{out / HOMES_FOLDER}",
            highlight=False,
            soft_wrap=True,
        )
        files += write_homes(out / HOMES_FOLDER, seeds)
        labels += [HOMES_FOLDER] * homes
    campaign = build_campaign(files, task, episodes, seed, seconds, vary or [], limit, labels)
    console = Console(stderr=True)
    # Ray is started or reached before anything is written: an unreachable cluster is one line
    ray_owned = connect_ray(ray, jobs) if ray is not None else False
    try:
        records, writer = open_results(
            out, campaign, resume, lambda line: console.print(line, highlight=False, soft_wrap=True)
        )
    except BaseException:
        if ray_owned:
            disconnect_ray()
        raise
    finished = {k for k, r in latest(records).items() if r["status"] == "ok"}
    todo = [s for s in campaign.specs() if s.key not in finished]
    total = len(campaign.specs())
    where = (
        f"Ray at {ray}" if ray is not None else f"{min(jobs, max(1, len(todo)))} worker processes"
    )
    console.print(
        f"pfctl bench: {len(campaign.groups)} mission variant(s) × {episodes} episodes, "
        f"{campaign.task} {seconds:g} s simulated; {total - len(todo)} done, {len(todo)} to run "
        f"on {where}; results in {out / RESULTS_FILE}"
    )
    for name in BLAS_THREAD_VARIABLES:  # read by numpy in the workers spawned from here on
        os.environ[name] = "1"
    done = total - len(todo)
    interrupted = False
    started = time.perf_counter()
    stop = StopSignals()
    with stop:  # until the summary is written: a second signal cannot cut it short
        try:
            with progress_bar(console, "episodes", len(todo)) as advance:

                def on_record(record: dict[str, Any]) -> None:
                    nonlocal done
                    with stop.holding():  # a record received is kept and shown whole
                        writer.append(record)
                        records.append(record)
                        done += 1
                        advance(1)
                        console.print(_episode_line(record, done, total), highlight=False)

                def on_retry(spec: EpisodeSpec, how: str) -> None:
                    console.print(
                        f"{spec.mission_label} · {spec.variant} · seed {spec.seed}: the worker "
                        f"process died ({how}); running the episode again on a new one",
                        highlight=False,
                        soft_wrap=True,
                    )

                if ray is not None:
                    run_on_ray(todo, ray, jobs, on_record, run_campaign_episode, owned=ray_owned)
                else:
                    run_in_processes(todo, jobs, on_record, run_campaign_episode, on_retry)
        except KeyboardInterrupt:
            interrupted = True
        finally:
            writer.close()
        wall = time.perf_counter() - started
        last = latest(records)
        planned = {s.key for s in campaign.specs()}
        ok = {k for k, r in last.items() if r["status"] == "ok"}
        failed = sum(1 for k, r in last.items() if k in planned and r["status"] == "error")
        left = len(planned - ok)
        console.print(
            f"{len(todo)} episode(s) planned this run, {wall:.0f} s wall; {left} not done"
        )
        written = _write_summary(campaign, records, out, console)
        results = [out / RESULTS_FILE] if (out / RESULTS_FILE).exists() else []
        console.print("wrote " + ", ".join(str(p) for p in [*results, *written]))
    if interrupted:
        how = stop.received.name if stop.received is not None else "SIGINT"
        console.print(
            f"pfctl: interrupted ({how}); continue with: pfctl bench ... --out {out} --resume",
            highlight=False,
            soft_wrap=True,
        )
        raise typer.Exit(stop.exit_code)
    if failed:
        console.print(
            f"pfctl: error: {failed} of {total} episodes failed; their errors are in "
            f"{out / RESULTS_FILE} and {out / 'episodes.csv'} (--resume runs them again)",
            highlight=False,
            soft_wrap=True,
        )
        raise typer.Exit(1)


__all__ = ["bench", "build_campaign"]
