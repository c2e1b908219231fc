"""`pfctl follow` and `pfctl search`: the whole architecture on a robot (§III-B).

``pfctl follow MISSION --backend sim``: learn the target (unless ``--target PROFILE``), then run
the follower (:mod:`pfctl.core.follower`) in the simulated house for ``--duration`` simulated
seconds: it follows the target, loses them, predicts, goes and looks, searches by Algorithm 1,
re-identifies them and follows again, as the mission's behavior tree decides. Prints a summary
(following rate, losses, each re-acquisition and how, identity switches, collisions, distance)
and writes ``trajectory.png`` (Fig. 4), ``timeline.png`` (Fig. 6), ``metrics.json`` and
``tracks.csv`` (the people tracks after each tick with a scan, as ``pfctl replay`` writes them
for a bag) into ``--out``.

``pfctl search MISSION --backend sim``: the target stands somewhere in the house out of view
(``--region``, else a region away from the robot chosen by the seed); the robot searches until
it identifies them or ``--duration`` runs out; prints the time to find and the path length,
writes ``search.png`` and ``metrics.json``.

``--backend hsr`` runs the same follower on a Toyota HSR over ROS 1
(:mod:`pfctl.backends.hsr.robot`, topics from the mission's ``backend.hsr``) — or on the simulated
house served as one by ``pfctl sim serve-hsr`` — for ``--duration`` seconds of ROS time, with a
target profile learned before (``--target``). When the simulator's truth is on the master the
metrics use it; on a real robot identity switches and collisions cannot be known and the
distances are the robot's own beliefs (:mod:`pfctl.core.metrics`). A robot that stops
answering (stale laser or pose, lost master) has its base stopped and ends the run: the outputs of
what was measured are written and the command exits 1 with one line saying what was lost.

Both stop the base on every exit; the first Ctrl-C or SIGTERM ends the episode, what was measured
is written, and the command exits 130 or 143 with one line (:mod:`pfctl.interrupts`).
"""

from __future__ import annotations

import json
import math
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import numpy as np
import typer
from rich.console import Console
from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn
from rich.table import Table

from pfctl.app.episodes import (
    hide_target,
    metric_params,
    run_episode,
    run_sim_episode,
    target_profile,
)
from pfctl.app.follower import EpisodeResult
from pfctl.app.oracle import refuse_on_real_robot
from pfctl.app.tracks_file import tracks_csv
from pfctl.commands import check_seed
from pfctl.core.metrics import (
    FollowMetrics,
    SearchMetrics,
    follow_metrics,
    search_metrics,
)
from pfctl.core.perception.face_worker import FaceWorkerError
from pfctl.core.perception.identity.profile import TargetProfile
from pfctl.errors import UserError
from pfctl.files import atomic_write_all, check_episode_dir, check_output_dir
from pfctl.interrupts import StopFlag, graceful_interrupts
from pfctl.mission import Mission, load_mission

if TYPE_CHECKING:
    from pfctl.backends.pybullet.simulation import SimRobot
    from pfctl.bags.recording import EpisodeRecorder

BACKENDS = ("sim", "hsr")


def _check_common(
    backend: str,
    duration: float,
    out: Path,
    target: Path | None,
    record: Path | None,
    gui: bool,
) -> None:
    if backend not in BACKENDS:
        raise UserError(f"--backend {backend}: expected one of {', '.join(BACKENDS)}")
    if not (math.isfinite(duration) and duration > 0):
        raise UserError(f"--duration: expected a positive number of seconds, got {duration:g}")
    check_output_dir(out, "--out")
    if record is not None:
        check_episode_dir(record)
        check_output_dir(record, "--record")
    if backend == "hsr":
        if target is None:
            raise UserError(
                "--target: with --backend hsr, give the profile learned on the robot first "
                "(pfctl learn-target MISSION --backend hsr --out target.npz)"
            )
        if record is not None:
            raise UserError(
                "--record: only with --backend sim (on ROS, record the topics with rosbag record)"
            )
        if gui:
            raise UserError("--gui: only with --backend sim")


@contextmanager
def _worker_errors() -> Iterator[None]:
    """A face worker that died ends the command with one line on stderr and exit status 1."""
    try:
        yield
    except FaceWorkerError as err:
        sys.stderr.write(f"pfctl: error: {err}\n")
        raise typer.Exit(1) from None


def _progress(console: Console, duration: float, unit: str = "s simulated") -> Progress:
    return Progress(
        TextColumn("{task.description}"),
        BarColumn(),
        TextColumn("{task.completed:.1f}/{task.total:.0f} " + unit),
        TimeRemainingColumn(),
        console=console,
        transient=True,
        disable=not console.is_terminal,
    )


def _write(out: Path, files: list[tuple[str, bytes | str]]) -> list[Path]:
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as err:
        raise UserError(f"--out {out}: cannot create it: {err.strerror or err}") from None
    paths = [(out / name, data) for name, data in files]
    try:
        atomic_write_all(paths)
    except OSError as err:
        raise UserError(f"--out {out}: cannot write: {err.strerror or err}") from None
    return [p for p, _ in paths]


def follow(
    mission: Annotated[Path, typer.Argument(help="A mission YAML.", show_default=False)],
    backend: Annotated[
        str, typer.Option("--backend", help="Where to run: sim (PyBullet) or hsr (ROS 1).")
    ] = "sim",
    target: Annotated[
        Path | None,
        typer.Option(
            "--target", help="A target profile (pfctl learn-target); default (sim): learn."
        ),
    ] = None,
    seed: Annotated[
        int | None,
        typer.Option(
            "--seed", callback=check_seed, help="Simulator seed (default: scenario.seed)."
        ),
    ] = None,
    duration: Annotated[
        float, typer.Option("--duration", help="Seconds (simulated, or ROS time on hsr).")
    ] = 120.0,
    out: Annotated[
        Path,
        typer.Option(
            "--out", help="Folder for trajectory.png, timeline.png, metrics.json, tracks.csv."
        ),
    ] = Path("out/follow"),
    record: Annotated[
        Path | None,
        typer.Option("--record", help="Also record the episode (ROS 1 bag + truth) into DIR."),
    ] = None,
    gui: Annotated[bool, typer.Option("--gui", help="Open PyBullet's window (real time).")] = False,
) -> None:
    """Follow the mission's target; lose, predict, search, re-identify and follow again."""
    from pfctl.plots.episode import timeline_figure, trajectory_figure
    from pfctl.plots.prediction import png_bytes

    _check_common(backend, duration, out, target, record, gui)
    loaded = load_mission(mission)
    if backend == "hsr":
        refuse_on_real_robot(loaded, str(mission))
    console = Console(stderr=True)
    profile = target_profile(loaded, target, seed, console, str(mission))
    if backend == "hsr":
        (result, stop), seed_used = _run_hsr(loaded, profile, duration, console, "following"), None
    else:
        robot = _sim_robot(loaded, seed, gui, str(mission))
        seed_used = robot.seed
        with robot, _worker_errors():
            recorder = _recorder(record, loaded)
            try:
                with graceful_interrupts() as stop, _progress(console, duration) as bar:
                    task = bar.add_task("following", total=duration)
                    result = run_sim_episode(
                        loaded,
                        robot,
                        profile,
                        duration,
                        on_tick=lambda t: bar.update(task, completed=min(t, duration)),
                        stop=stop,
                        recorder=recorder,
                    )
                if recorder is not None:
                    recorder.close()
            except BaseException:
                if recorder is not None:
                    recorder.abort()
                raise
    metrics = follow_metrics(result.log, metric_params(loaded))
    title = loaded.name if seed_used is None else f"{loaded.name}, seed {seed_used}"
    layout = loaded.layout()
    files = [
        ("metrics.json", json.dumps(_follow_json(metrics, result, seed_used), indent=2) + "\n"),
        ("trajectory.png", png_bytes(trajectory_figure(layout, result.log, metrics, title))),
        ("timeline.png", png_bytes(timeline_figure(result.log, metrics))),
        ("tracks.csv", tracks_csv(result.log.tracks)),
    ]
    written = _write(out, files)
    _follow_report(metrics, result, written)
    _end(result, stop, out)


def _sim_robot(mission: Mission, seed: int | None, gui: bool, source: str) -> SimRobot:
    """The simulated house; with ``gui`` in PyBullet's window, paced to the clock."""
    from pfctl.app.sim import sim_robot
    from pfctl.backends.pybullet.simulation import SimOptions

    return sim_robot(mission, seed, source, SimOptions(gui=gui, realtime=gui))


def _run_hsr(
    mission: Mission,
    profile: TargetProfile,
    duration: float,
    console: Console,
    what: str,
    *,
    until_found: bool = False,
) -> tuple[EpisodeResult, StopFlag]:
    """The follower on the HSR over ROS 1 (``backend.hsr``) for ``duration`` s of ROS time; the
    simulator's truth is recorded for the metrics when ``pfctl sim serve-hsr`` publishes it.
    Connecting is not part of the run: a signal while waiting for the robot ends the command."""
    from pfctl.app.hsr import hsr_config
    from pfctl.backends.hsr.robot import HsrRobot

    robot = HsrRobot(hsr_config(mission))
    with robot, _worker_errors():
        truth = robot.ground_truth if robot.ground_truth() is not None else None
        with graceful_interrupts() as stop, _progress(console, duration, "s") as bar:
            task = bar.add_task(what, total=duration)
            result = run_episode(
                mission,
                robot,
                profile,
                duration,
                detector=robot.person_detector(),
                now=lambda: robot.time,
                truth=truth,  # type: ignore[arg-type]
                kind="real",
                on_tick=lambda t: bar.update(task, completed=min(t, duration)),
                stop=stop,
                until_found=until_found,
            )
    result.clock_origin = robot.clock_origin
    return result, stop


def _end(result: EpisodeResult, stop: StopFlag, out: Path) -> None:
    """Exit 1 with one line when the robot was lost, 130 (SIGINT) or 143 (SIGTERM) with one line
    when interrupted (the outputs of what was measured are written first)."""
    if result.lost is not None:
        sys.stderr.write(f"pfctl: error: {result.lost}; the base was stopped\n")
        raise typer.Exit(1)
    stop.exit_if_set(f"after {result.sim_time:.1f} s of the episode; wrote {out}")
    if result.interrupted:
        raise typer.Exit(130)


def _recorder(record: Path | None, mission: Mission) -> EpisodeRecorder | None:
    """An episode recorder into ``record`` (as ``pfctl sim run --record``), or None."""
    if record is None:
        return None
    from pfctl.bags.recording import EpisodeRecorder, RecordingError

    check_episode_dir(record)
    try:
        return EpisodeRecorder(record, mission.name, images=False)
    except RecordingError as err:
        raise UserError(str(err)) from None


def _follow_json(
    metrics: FollowMetrics, result: EpisodeResult, seed: int | None
) -> dict[str, object]:
    data = metrics.to_json()
    ticks = np.asarray(result.tick_seconds) * 1000.0
    data.update(
        seed=seed,
        sim_time_s=round(result.sim_time, 3),
        wall_time_s=round(result.wall_time, 3),
        interrupted=result.interrupted,
        lost=result.lost,
        clock_origin_s=result.clock_origin,
        tick_ms_median=round(float(np.median(ticks)), 3) if len(ticks) else None,
        tick_ms_p99=round(float(np.percentile(ticks, 99)), 3) if len(ticks) else None,
    )
    return data


def _follow_report(metrics: FollowMetrics, result: EpisodeResult, written: list[Path]) -> None:
    out = Console(width=100, soft_wrap=True)
    status = "interrupted after" if result.interrupted else "ran"
    out.print(
        f"{status} {result.sim_time:.1f} s simulated in {result.wall_time:.1f} s; "
        f"first identified at "
        + (
            f"{metrics.first_identified_s:.1f} s"
            if metrics.first_identified_s is not None
            else "never"
        )
    )
    table = Table(show_header=False, box=None)
    table.add_row("following rate", f"{metrics.following_rate:.1%}")
    table.add_row("losses", str(metrics.losses))
    for r in metrics.reacquisitions:
        table.add_row(
            "  re-acquired",
            f"lost at {r.t_lost:.1f} s, found at {r.t_found:.1f} s "
            f"({r.t_found - r.t_lost:.1f} s) by {r.how}",
        )
    table.add_row("identity switches", str(metrics.identity_switches))
    table.add_row("collisions", str(metrics.collisions))
    table.add_row("distance driven", f"{metrics.distance_m:.1f} m")
    out.print(table)
    out.print("wrote " + ", ".join(str(p) for p in written))


def search(
    mission: Annotated[Path, typer.Argument(help="A mission YAML.", show_default=False)],
    backend: Annotated[
        str, typer.Option("--backend", help="Where to run: sim (PyBullet) or hsr (ROS 1).")
    ] = "sim",
    target: Annotated[
        Path | None,
        typer.Option(
            "--target", help="A target profile (pfctl learn-target); default (sim): learn."
        ),
    ] = None,
    region: Annotated[
        str | None,
        typer.Option("--region", help="Sim: where the target hides (default: chosen by the seed)."),
    ] = None,
    seed: Annotated[
        int | None,
        typer.Option(
            "--seed", callback=check_seed, help="Simulator seed (default: scenario.seed)."
        ),
    ] = None,
    duration: Annotated[float, typer.Option("--duration", help="Give up after (s).")] = 180.0,
    out: Annotated[
        Path, typer.Option("--out", help="Folder for search.png and metrics.json.")
    ] = Path("out/search"),
    gui: Annotated[bool, typer.Option("--gui", help="Open PyBullet's window (real time).")] = False,
) -> None:
    """Find the mission's target somewhere in the house: belief, Algorithm 1 and frontiers."""
    from pfctl.plots.episode import search_figure
    from pfctl.plots.prediction import png_bytes

    _check_common(backend, duration, out, target, None, gui)
    if region is not None and backend == "hsr":
        raise UserError(
            "--region: only with --backend sim (the person hides themselves; with serve-hsr: "
            "pfctl sim serve-hsr --hide REGION)"
        )
    loaded = load_mission(mission)
    if backend == "hsr":
        refuse_on_real_robot(loaded, str(mission))
    names = [r.name for r in loaded.map.regions]
    if region is not None and region not in names:
        raise UserError(f"--region {region}: unknown region (regions: {', '.join(names)})")
    console = Console(stderr=True)
    profile = target_profile(loaded, target, seed, console, str(mission))
    hidden_in: str | None = None
    seed_used: int | None = None
    if backend == "hsr":
        result, stop = _run_hsr(loaded, profile, duration, console, "searching", until_found=True)
    else:
        robot = _sim_robot(loaded, seed, gui, str(mission))
        seed_used = robot.seed
        with robot, _worker_errors():
            hidden_in = hide_target(loaded, robot, region)
            with graceful_interrupts() as stop, _progress(console, duration) as bar:
                task = bar.add_task("searching", total=duration)
                result = run_sim_episode(
                    loaded,
                    robot,
                    profile,
                    duration,
                    on_tick=lambda t: bar.update(task, completed=min(t, duration)),
                    stop=stop,
                    until_found=True,
                )
    metrics = search_metrics(result.log, metric_params(loaded))
    data = metrics.to_json()
    data.update(seed=seed_used, region=hidden_in, sim_time_s=round(result.sim_time, 3))
    files = [
        ("metrics.json", json.dumps(data, indent=2) + "\n"),
        ("search.png", png_bytes(search_figure(loaded.layout(), result.log, metrics))),
    ]
    written = _write(out, files)
    _search_report(metrics, result, written)
    _end(result, stop, out)


def _search_report(metrics: SearchMetrics, result: EpisodeResult, written: list[Path]) -> None:
    out = Console(width=100, soft_wrap=True)
    if metrics.found and metrics.time_to_find_s is not None:
        out.print(f"found the target after {metrics.time_to_find_s:.1f} s")
    else:
        out.print(f"did not find the target in {result.sim_time:.1f} s")
    out.print(f"  path length {metrics.distance_m:.1f} m, {metrics.collisions} collisions")
    out.print("wrote " + ", ".join(str(p) for p in written))


__all__ = ["follow", "search"]
