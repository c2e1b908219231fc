"""`pfctl sim`: the simulated house.

- ``run MISSION``: run the house with the scenario's people for a while, the robot standing
  still, replaying a velocity script (``--script``) or driven from the keyboard (``--teleop``);
  optionally record the episode (``--record DIR``, a ROS 1 bag and sidecars); draw everyone's
  paths on a top-down PNG and print what happened.
- ``export-map MISSION --out map.yaml``: the static occupancy grid the simulator's walls and
  furniture imply (:func:`pfctl.core.mapping.walls.rasterize_house`), as a ROS map_server map.
- ``serve-hsr MISSION``: the house as a Toyota HSR on the ROS 1 master of ``ROS_MASTER_URI``
  (:mod:`pfctl.backends.hsr.sim_bridge`: the topics, tf, move_base and services of the mission's
  ``backend.hsr``, on a ``/clock`` of simulated time) until ``--duration`` or Ctrl-C / SIGTERM.

Every bad input is a :class:`pfctl.errors.UserError` (one line, exit 2); files are written
atomically.
"""

from __future__ import annotations

import itertools
import math
import os
import sys
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer
from rich.console import Console
from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn

from pfctl.commands import check_seed
from pfctl.core.mapping.walls import rasterize_house
from pfctl.errors import UserError
from pfctl.files import check_episode_dir, check_output_dir, check_output_file
from pfctl.interrupts import StopFlag, graceful_interrupts
from pfctl.mission import Mission, load_mission
from pfctl.mission.map import house_grid_issue
from pfctl.mission.map_server import GridFileError, save_map_server

if TYPE_CHECKING:  # the simulator is imported when a command needs it: pybullet loads slowly
    from pfctl.backends.hsr.sim_bridge import BridgeStats
    from pfctl.backends.pybullet.runner import RunResult
    from pfctl.backends.pybullet.simulation import SimRobot

app = typer.Typer(help="The simulated house: run it, export its map.", no_args_is_help=True)


@app.command("run")
def run(
    mission: Annotated[Path, typer.Argument(help="A mission YAML.", show_default=False)],
    duration: Annotated[float, typer.Option("--duration", help="Simulated seconds to run.")] = 60.0,
    seed: Annotated[
        int | None,
        typer.Option(
            "--seed", callback=check_seed, help="Seed (default: the mission's scenario.seed)."
        ),
    ] = None,
    record: Annotated[
        Path | None,
        typer.Option("--record", help="Write the episode here: a ROS 1 bag and sidecars."),
    ] = None,
    record_images: Annotated[
        bool, typer.Option("--record-images", help="Also record the RGB-D images (large).")
    ] = False,
    png: Annotated[
        Path | None,
        typer.Option(
            "--png", help="Top-down picture of the paths [default: DIR/paths.png or sim_run.png]."
        ),
    ] = None,
    script: Annotated[
        Path | None,
        typer.Option("--script", help="Drive by a velocity script: CSV t,vx,vy,wz[,pan,tilt]."),
    ] = None,
    teleop: Annotated[
        bool, typer.Option("--teleop", help="Drive from the keyboard (paces to the clock).")
    ] = False,
    gui: Annotated[bool, typer.Option("--gui", help="Open PyBullet's window to watch.")] = False,
    realtime: Annotated[
        bool, typer.Option("--realtime", help="Pace the simulation to the wall clock.")
    ] = False,
    camera: Annotated[
        bool, typer.Option("--camera/--no-camera", help="Render the head's RGB-D camera.")
    ] = True,
    laser: Annotated[
        str, typer.Option("--laser", help="Laser model: fast (2-D, default) or bullet.")
    ] = "fast",
) -> None:
    """Run the simulated house: people walk their routes; the robot stands, replays a script or
    is driven from the keyboard. Writes a top-down PNG of everyone's paths."""
    from pfctl.app.sim import sim_robot
    from pfctl.backends.pybullet import drivers
    from pfctl.backends.pybullet.runner import run_simulation
    from pfctl.backends.pybullet.simulation import SimOptions
    from pfctl.bags.recording import Episode, EpisodeRecorder, RecordingError
    from pfctl.plots.sim_run import plot_paths

    if not (math.isfinite(duration) and duration > 0):
        raise UserError(f"--duration: expected a positive number of seconds, got {duration}")
    if laser not in ("fast", "bullet"):
        raise UserError(f"--laser: expected fast or bullet, got {laser!r}")
    if script is not None and teleop:
        raise UserError("--script and --teleop: expected one way to drive the robot, got both")
    if gui and sys.platform.startswith("linux") and not os.environ.get("DISPLAY"):
        raise UserError("--gui: no display (DISPLAY is not set); run without --gui for headless")
    if teleop and not gui and not sys.stdin.isatty():
        raise UserError("--teleop: stdin is not a terminal; run it in a terminal or with --gui")
    if record is not None:
        check_episode_dir(record)
    if png is None:
        png = record / "paths.png" if record is not None else Path("sim_run.png")
    if png.suffix.lower() != ".png":
        raise UserError(f"--png {png}: expected a path ending in .png")
    if record is not None:
        check_output_dir(record, "--record")
    check_output_file(png, "--png")
    loaded = load_mission(mission)
    steps = None
    if script is not None:
        try:
            steps = drivers.read_velocity_script(script)
        except drivers.ScriptError as err:
            raise UserError(str(err)) from None
    options = SimOptions(
        gui=gui,
        realtime=realtime or teleop,
        camera=camera,
        laser_model="bullet" if laser == "bullet" else "fast",
    )
    robot = sim_robot(loaded, seed, str(mission), options)
    console = Console(stderr=True)
    with robot:
        driver: drivers.ScriptedDriver | drivers.KeyboardDriver | None = None
        if steps is not None:
            driver = drivers.ScriptedDriver(steps)
        elif teleop:
            driver = drivers.KeyboardDriver(
                loaded.robot.max_linear_speed, loaded.robot.max_angular_speed
            )
            console.print(drivers.HELP)
        try:
            recorder = (
                EpisodeRecorder(record, loaded.name, images=record_images and camera)
                if record is not None
                else None
            )
        except RecordingError as err:
            raise UserError(str(err)) from None
        try:
            with graceful_interrupts() as stop, _Progress(console, duration) as tick:
                if teleop and not gui:
                    with drivers.TerminalKeys() as terminal:
                        result = run_simulation(
                            robot, duration, driver, recorder, terminal.read, tick, stop
                        )
                else:
                    keys = (lambda: drivers.window_keys(robot.client)) if teleop else None
                    result = run_simulation(robot, duration, driver, recorder, keys, tick, stop)
            if recorder is not None:
                recorder.close()
        except BaseException:
            if recorder is not None:
                recorder.abort()
            raise
        episode = Episode(mission_name=loaded.name, truths=result.truths)
        try:
            png.parent.mkdir(parents=True, exist_ok=True)
        except OSError as err:
            raise UserError(f"--png {png}: cannot create its folder: {err.strerror}") from None
        title = f"{loaded.name}: {result.sim_time:.1f} s simulated, seed {robot.seed}"
        picture = plot_paths(
            robot.static_map,
            loaded.layout(),
            episode.robot_path(),
            episode.people_paths(),
            episode.target,
            png,
            title=title,
        )
    _report(loaded, result, robot.collisions, picture, record)
    wrote = f"the episode to {record}/ and {picture}" if record is not None else str(picture)
    stop.exit_if_set(f"after {result.sim_time:.1f} s simulated; wrote {wrote}")
    if result.interrupted:  # the quit key
        raise typer.Exit(130)


class _Progress:
    """A progress bar of simulated time on stderr (hidden when stderr is not a terminal)."""

    def __init__(self, console: Console, duration: float) -> None:
        self.duration = duration
        self.bar = Progress(
            TextColumn("simulating"),
            BarColumn(),
            TextColumn("{task.completed:.1f}/{task.total:.0f} s"),
            TimeRemainingColumn(),
            console=console,
            transient=True,
            disable=not console.is_terminal,
        )

    def __enter__(self) -> Callable[[float], None]:
        self.bar.__enter__()
        task = self.bar.add_task("sim", total=self.duration)
        return lambda t: self.bar.update(task, completed=min(t, self.duration))

    def __exit__(self, *exc: object) -> None:
        self.bar.__exit__(None, None, None)


def _report(
    mission: Mission, result: RunResult, collisions: int, picture: Path, record: Path | None
) -> None:
    out = Console(width=100, soft_wrap=True)
    status = "interrupted after" if result.interrupted else "ran"
    out.print(
        f"{status} {result.sim_time:.1f} s simulated in {result.wall_time:.1f} s "
        f"({result.real_time_factor:.1f}x real time): {result.scans} scans, "
        f"{result.frames} camera frames, {collisions} collisions"
    )
    truths = result.truths
    if len(truths) > 1:
        robot = [(g.robot.x, g.robot.y) for g in truths]
        out.print(f"  robot: {_length(robot):.2f} m driven")
        for k, person in enumerate(truths[0].people):
            path = [(g.people[k].x, g.people[k].y) for g in truths]
            role = "target" if person.is_target else "distractor"
            out.print(f"  {person.name} ({role}): {_length(path):.2f} m walked")
    if record is not None:
        out.print(f"wrote the episode to {record}/ (episode.bag, truth.csv, episode.json)")
    out.print(f"wrote {picture}")


def _length(points: list[tuple[float, float]]) -> float:
    return sum(math.dist(a, b) for a, b in itertools.pairwise(points))


@app.command("export-map")
def export_map(
    mission: Annotated[Path, typer.Argument(help="A mission YAML.", show_default=False)],
    out: Annotated[
        Path, typer.Option("--out", help="The map_server YAML to write (a .pgm goes beside it).")
    ],
    resolution: Annotated[
        float | None,
        typer.Option("--resolution", help="Cell size in metres (default: map.resolution)."),
    ] = None,
) -> None:
    """Write the simulator's static map (walls, doors, furniture) as a ROS map_server map."""
    if resolution is not None and not (math.isfinite(resolution) and resolution > 0):
        raise UserError(f"--resolution: expected a positive cell size in metres, got {resolution}")
    if out.suffix.lower() not in (".yaml", ".yml"):
        raise UserError(f"--out {out}: expected a map_server YAML path ending in .yaml")
    check_output_file(out, "--out")
    loaded = load_mission(mission)
    issue = house_grid_issue(loaded.layout(), resolution) if resolution is not None else None
    if issue:
        raise UserError(f"--resolution {resolution:g}: {issue}")
    grid = rasterize_house(
        loaded.layout(),
        resolution if resolution is not None else loaded.map.resolution,
        wall_thickness=loaded.map.wall_thickness,
        include_obstacles=True,
    )
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
        yaml_path, pgm_path = save_map_server(grid, out)
    except OSError as err:
        raise UserError(f"--out {out}: cannot create its folder: {err.strerror}") from None
    except GridFileError as err:
        raise UserError(str(err)) from None
    g = grid.geometry
    Console(width=100, soft_wrap=True).print(
        f"wrote {yaml_path} and {pgm_path.name}: {g.width}×{g.height} cells at {g.resolution:g} m"
    )


@app.command("serve-hsr")
def serve_hsr(
    mission: Annotated[Path, typer.Argument(help="A mission YAML.", show_default=False)],
    seed: Annotated[
        int | None,
        typer.Option(
            "--seed", callback=check_seed, help="Seed (default: the mission's scenario.seed)."
        ),
    ] = None,
    duration: Annotated[
        float | None,
        typer.Option(
            "--duration",
            help="Simulated seconds to serve (default: until Ctrl-C or SIGTERM).",
            show_default=False,
        ),
    ] = None,
    rate: Annotated[
        float,
        typer.Option("--rate", help="Simulated seconds per wall second; 0: as fast as possible."),
    ] = 1.0,
    depth_encoding: Annotated[
        str,
        typer.Option(
            "--depth-encoding", help="Depth image: 16UC1 (mm, like the Xtion) or 32FC1 (m)."
        ),
    ] = "16UC1",
    hide: Annotated[
        str | None,
        typer.Option(
            "--hide",
            help="Put the target standing still in this region, out of view (for pfctl search).",
            show_default=False,
        ),
    ] = None,
    pose_target: Annotated[
        bool,
        typer.Option(
            "--pose-target",
            help="The target stands 1.4 m in front of the robot, facing it "
            "(for pfctl learn-target --backend hsr).",
        ),
    ] = False,
    wait_for_command: Annotated[
        bool,
        typer.Option(
            "--wait-for-command",
            help="Hold the episode (the clock runs, nobody moves) until the robot is first "
            "commanded: a follower started later sees the episode from its start.",
        ),
    ] = False,
) -> None:
    """Serve the simulated house as a Toyota HSR on the ROS 1 master of ROS_MASTER_URI: the
    laser, RGB-D camera, person labels, odometry, tf, head and base commands, move_base and the
    ground truth of the mission's backend.hsr, on /clock (use_sim_time; ROS time = simulated
    time + 100 s)."""
    from pfctl.backends.hsr.sim_bridge import DEPTH_ENCODINGS

    if duration is not None and not (math.isfinite(duration) and duration > 0):
        raise UserError(f"--duration: expected a positive number of seconds, got {duration:g}")
    if not (math.isfinite(rate) and rate >= 0):
        raise UserError(f"--rate: expected a number >= 0 (0: as fast as possible), got {rate:g}")
    if depth_encoding not in DEPTH_ENCODINGS:
        raise UserError(
            f"--depth-encoding {depth_encoding}: expected one of {', '.join(DEPTH_ENCODINGS)}"
        )
    if hide is not None and pose_target:
        raise UserError("--hide and --pose-target: expected at most one of them, got both")
    loaded = load_mission(mission)
    regions = [r.name for r in loaded.map.regions]
    if hide is not None and hide not in regions:
        raise UserError(f"--hide {hide}: unknown region (regions: {', '.join(regions)})")
    console = Console(stderr=True)
    stats, stop = _serve(
        loaded,
        mission,
        seed,
        duration,
        rate,
        depth_encoding,
        hide,
        pose_target,
        wait_for_command,
        console,
    )
    _serve_report(stats)
    if stats.lost is not None:
        sys.stderr.write(f"pfctl: error: {stats.lost}\n")
        raise typer.Exit(1)
    stop.exit_if_set(f"after serving {stats.sim_time:.1f} s simulated")


def _serve(
    mission: Mission,
    path: Path,
    seed: int | None,
    duration: float | None,
    rate: float,
    depth_encoding: str,
    hide: str | None,
    pose_target: bool,
    wait_for_command: bool,
    console: Console,
) -> tuple[BridgeStats, StopFlag]:
    """Serve until ``duration``, Ctrl-C or SIGTERM; the run (:func:`graceful_interrupts`) opens
    once the bridge is up: a signal while loading or reaching the master ends the command."""
    from pfctl.backends.hsr.ros_import import import_rospy
    from pfctl.backends.hsr.sim_bridge import (
        CLOCK_OFFSET,
        SimHsrBridge,
        claim_sim_time,
        master_uri,
        reach_master,
    )

    import_rospy()  # ROS 1 missing: one line naming the apt packages
    uri = master_uri()
    reach_master(uri)
    claim_sim_time(uri)  # before the simulator loads: a node reads /use_sim_time as it starts
    from pfctl.app.hsr import hsr_config
    from pfctl.app.sim import sim_robot

    robot = sim_robot(mission, seed, str(path))
    with robot:
        scene = None
        if hide is not None:
            from pfctl.app.episodes import hide_target

            hide_target(mission, robot, hide)
        elif pose_target:
            scene = _posing(robot, str(path))
        bridge = SimHsrBridge(
            robot,
            hsr_config(mission),
            uri,
            rate=rate,
            depth_encoding=depth_encoding,
            wait_for_command=wait_for_command,
        )
        pace = f"rate {rate:.1f}×" if rate > 0 else "as fast as possible"

        def ready() -> None:
            console.print(
                f"serving {path} as an HSR on {uri.rstrip('/')}, seed {robot.seed}, {pace} "
                f"(ROS time = simulated time + {CLOCK_OFFSET:g} s"
                + (", held until the first command)" if wait_for_command else ")"),
                highlight=False,
                soft_wrap=True,
            )

        def released(held: float) -> None:
            console.print(
                f"the first command came after {held:.2f} s: the episode starts "
                f"(ROS time = simulated time + {CLOCK_OFFSET + held:.3f} s)",
                highlight=False,
                soft_wrap=True,
            )

        stop = StopFlag()
        try:
            bridge.start()
            with graceful_interrupts() as stop, _ServeProgress(console, duration) as tick:
                stats = bridge.run(
                    duration,
                    stop,
                    on_period=tick,
                    scene=scene,
                    on_ready=ready,
                    on_release=released,
                )
            return stats, stop
        finally:
            bridge.shutdown("interrupted" if stop() else "done")


def _posing(robot: SimRobot, source: str) -> Callable[[float], None]:
    """Hold the target in front of the robot (as ``pfctl learn-target`` does in the simulator),
    turning a little from side to side; the scene callback that keeps them there."""
    from pfctl.app.learn_target import SWAY, stand_in_front

    x, y, _ = stand_in_front(robot, source=source)
    target = next(w for w in robot.people if w.is_target)
    facing = target.theta
    robot.resense()

    def scene(t: float) -> None:
        target.hold(x, y, facing + SWAY * math.sin(2 * math.pi * t / 3.0))

    return scene


class _ServeProgress:
    """Simulated time served, on stderr when it is a terminal (a bar with ``--duration``)."""

    def __init__(self, console: Console, duration: float | None) -> None:
        self.duration = duration
        self.bar = Progress(
            TextColumn("serving"),
            BarColumn(),
            TextColumn("{task.completed:.1f} s simulated"),
            console=console,
            transient=True,
            disable=not console.is_terminal,
        )

    def __enter__(self) -> Callable[[float], None]:
        self.bar.__enter__()
        task = self.bar.add_task("serve", total=self.duration)
        return lambda t: self.bar.update(task, completed=t)

    def __exit__(self, *exc: object) -> None:
        self.bar.__exit__(None, None, None)


def _serve_report(stats: BridgeStats) -> None:
    status = "interrupted after" if stats.interrupted else "served"
    held = f" (after holding for {stats.held:.1f} s)" if stats.held > 0 else ""
    Console(width=100, soft_wrap=True).print(
        f"{status} {stats.sim_time:.1f} s simulated{held} in {stats.wall_time:.1f} s "
        f"({stats.real_time_factor:.2f}× real time): {stats.scans} scans, {stats.frames} camera "
        f"frames; received {stats.velocity_commands} velocity commands, {stats.head_commands} "
        f"head commands, {stats.goals} move_base goals, {stats.viewpoint_stops} viewpoint stops, "
        f"{stats.said} sentences to say; "
        f"{stats.collisions} collisions",
        highlight=False,
    )
