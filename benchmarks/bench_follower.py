"""Speed of one follower tick on one CPU core, in the crowd mission (or any mission).

Run::

    .venv/bin/python benchmarks/bench_follower.py                       # missions/house_crowd.yaml
    .venv/bin/python benchmarks/bench_follower.py missions/house.yaml --duration 60
    .venv/bin/python benchmarks/bench_follower.py --sync                # faces inline (the old way)
    .venv/bin/python benchmarks/bench_follower.py --profile             # + cProfile of the ticks

It learns the target in the simulator (not timed), then runs the follower
(:func:`pfctl.app.episodes.run_sim_episode`) for ``--duration`` simulated seconds (default
60) **the way a robot runs it**: the face searches of Algorithm 2 (dlib's HOG detector and ResNet
embedding, ~75–90 ms per face) go to a :class:`~pfctl.core.perception.face_worker.FaceWorker`
process with ``realtime`` timing (results are folded in when they are back, the tick never waits),
and the loop is paced in wall time at the mission's tick rate: after the tick and the simulator's
step it sleeps until the next period, so the worker — pinned to the same CPU 0 and running at the
lowest priority (nice 19, ``SCHED_IDLE``) — gets the idle time of the one core and the control loop
preempts it whenever it wakes. ``--sync`` searches faces inline in the tick instead (as before
the worker); ``--timing deterministic`` uses the simulator's reproducible timing (the tick waits
for a result that is due); ``--no-pace`` runs as fast as it can.

It reports the median, 90th and 99th percentile and maximum wall time of one follower tick
(:attr:`EpisodeResult.tick_seconds`: observe → perceive → predict → decide → act → log; the
simulator's step, camera rendering and MOVE_BASE's path planning included, is not in it: a real
robot renders nothing and its move_base plans in its own process). Goal: p99 within the
laser's period, 25 ms at 40 Hz (issues 23 and 24; 20 ms before every scan was used). It
also reports each tick's CPU time in the loop's thread (``time.thread_time``): the tick's own
work, without the time the OS gave other processes (other jobs on a shared machine, the face
worker) meanwhile — the figure to compare code changes by when the machine is busy. The
ticks are also split by what the observation carried (an RGB-D frame or not, read by a thin proxy
around the robot's ``observe``; with the camera at the tick rate, as in the shipped missions,
every tick has one) and by whether the tick did face work (inline: a face was embedded; with the
worker: a head crop was submitted), and each tick's time is broken into the tick's stages —
timed by calling them one after the other, as ``Follower.tick`` does (:func:`staged_tick`) — and
the work inside them, timed by wrapping a few methods in this process only (leg classification
of the tick's scans, laser perception, leg detection, camera perception, person detection,
Algorithm 2 identification, face detection
and embedding with dlib when inline, the worker's submit and poll, tracking, belief update,
occupancy grid update, behavior tree, Algorithm 1, the gaze rule, calls into the robot, Python's
garbage collector): per stage how many ticks ran it, its median and p99 when it ran, and its
mean share of the slowest 1 % of ticks. The ten slowest ticks are listed with their CPU time,
the people in the frame, the clothing histograms measured and what they did. With the worker
it also prints its jobs (submitted, completed, refused because two were out, results folded in
or discarded because the track was gone, searches backed off on the back of a head) and the
child's wall and CPU time per job, and the simulator's step time and how often the loop overran
its period.

``--profile`` then runs the same episode again (same seed) with :mod:`cProfile` enabled only
inside ``Follower.tick`` and prints the ``--top`` (default 25) functions by cumulative time;
the profiler slows every call down, so the percentiles above come from the un-profiled run.

Like ``bench_perception.py`` it pins itself to CPU 0 and sets one BLAS/OpenMP thread before
numpy is imported, and prints the machine. It prints figures; it asserts nothing about time.
"""

from __future__ import annotations

import os

# One core, one thread: set before numpy is imported.
for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"
if hasattr(os, "sched_setaffinity"):
    os.sched_setaffinity(0, {0})

import argparse  # noqa: E402
import cProfile  # noqa: E402
import functools  # noqa: E402
import gc  # noqa: E402
import importlib  # noqa: E402
import io  # noqa: E402
import platform  # noqa: E402
import pstats  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from collections.abc import Callable, Iterator  # noqa: E402
from contextlib import contextmanager  # noqa: E402
from dataclasses import dataclass  # noqa: E402
from pathlib import Path  # noqa: E402
from typing import TYPE_CHECKING, Any, cast  # noqa: E402

import numpy as np  # noqa: E402

if TYPE_CHECKING:
    from pfctl.app.follower import EpisodeResult
    from pfctl.backends.pybullet.simulation import SimRobot
    from pfctl.core.episode import TickRecord
    from pfctl.core.follower import Follower
    from pfctl.core.perception.face_worker import FaceWorker
    from pfctl.core.robot import Observation
    from pfctl.mission import Mission

ROOT = Path(__file__).resolve().parents[1]
CROWD = ROOT / "missions" / "house_crowd.yaml"
GOAL_MS = 25.0
"""The tick's p99 goal, ms: the period of a 40 Hz laser, so that every scan is used in time."""

#: The tick's stages (DESIGN.md "One tick of the follower"), timed by calling them in order as
#: :meth:`pfctl.core.follower.Follower.tick` does (:func:`staged_tick`); they do not overlap.
TICK_STAGES = ("observe", "perceive", "predict", "decide", "act", "log")

#: Work inside the stages, timed by wrapping the methods that do it: (label, module, class or
#: None for a module function, attribute). The indentation says which stage (or inner work) a
#: label runs in.
INNER: tuple[tuple[str, str, str | None, str], ...] = (
    (
        "  leg classification (a tick's scans)",
        "pfctl.core.perception.legs.detector",
        "LegDetector",
        "classify",
    ),
    ("  laser perception (on_scan)", "pfctl.core.perception.pipeline", "Perception", "on_scan"),
    ("    leg detection", "pfctl.core.perception.legs.detector", "LegDetector", "detect"),
    ("  camera perception (on_frame)", "pfctl.core.perception.pipeline", "Perception", "on_frame"),
    ("    person detection (mask)", "pfctl.core.perception.vision", "MaskPersonDetector", "detect"),
    (
        "    identification (Alg. 2)",
        "pfctl.core.perception.identity.identifier",
        "TargetIdentifier",
        "observe_frame",
    ),
    (
        "      faces inline: dlib detect+embed",
        "pfctl.core.perception.faces",
        "FaceEncoder",
        "detect",
    ),
    ("      face worker: submit crop", "pfctl.core.perception.face_worker", "FaceWorker", "submit"),
    ("      face worker: poll", "pfctl.core.perception.face_worker", "FaceWorker", "poll"),
    (
        "      face worker: wait (deterministic)",
        "pfctl.core.perception.face_worker",
        "FaceWorker",
        "wait",
    ),
    ("    belief update (Eq. 4)", "pfctl.core.perception.belief", "HumanBelief", "update"),
    (
        "    tracking (in on_scan/on_frame)",
        "pfctl.core.perception.tracking",
        "MultiPersonTracker",
        "update",
    ),
    ("  occupancy grid (Eq. 1)", "pfctl.core.mapping.grid", "OccupancyGrid", "update_scan"),
    ("  behavior tree (tick_once)", "py_trees.behaviour", "Behaviour", "tick_once"),
    (
        "    Algorithm 1 (next_waypoint)",
        "pfctl.core.behavior.world",
        "WorldModel",
        "next_waypoint",
    ),
    ("    grid planner (plan)", "pfctl.core.mapping.planning", "GridPlanner", "plan"),
    ("  gaze rule (no leaf pointed the head)", "pfctl.core.follower", "Follower", "gaze_intent"),
    ("  robot calls (navigate, command, …)", "", None, ""),
)
#: The robot's calls from observe (its navigation status) and act (the intents sent); the
#: simulator plans a path in its next step, as a real robot's move_base plans on its own.
ROBOT_STAGE = "  robot calls (navigate, command, …)"
GC_STAGE = "garbage collector (within the above)"
OTHER_STAGE = "other (between the stages)"


class TickClock:
    """Per-tick stage times: wrappers add into :attr:`current` while a tick runs."""

    def __init__(self) -> None:
        self.in_tick = False
        self.current: dict[str, float] = {}
        self.ticks: list[dict[str, float]] = []
        self.frames: list[bool] = []
        """Per tick: did the observation carry an RGB-D frame."""
        self.scans: list[int] = []
        """Per tick: how many laser scans the observation carried (every scan since the last)."""
        self.embedded = 0
        """Face work in the running tick: faces embedded inline, or crops submitted."""
        self.embeddings: list[int] = []
        self.cpu: list[float] = []
        """CPU time of each tick in this thread (``time.thread_time``), s: the tick's own work,
        without the time the OS gave other processes meanwhile."""
        self.people: list[int] = []
        """People the camera detected in each tick's frame."""
        self.clothes: list[int] = []
        """Clothing histogram pairs Algorithm 2 measured in each tick."""
        self.cpu_start = 0.0
        self.clothes_before = 0
        self.tick_start = 0.0
        self.tick_end = 0.0
        self.steps: list[float] = []
        """Wall time from the end of each tick to the end of the simulator's step, s."""
        self.overruns = 0
        """Periods whose tick + step took longer than the period (paced runs)."""
        self.identifiers: list[Any] = []
        self._gc_start: float | None = None
        self.missing: list[str] = []

    def add(self, stage: str, seconds: float) -> None:
        if self.in_tick:
            self.current[stage] = self.current.get(stage, 0.0) + seconds

    def gc_callback(self, phase: str, info: dict[str, Any]) -> None:
        """``gc.callbacks`` hook: time the collections that happen inside a tick."""
        if phase == "start":
            self._gc_start = time.perf_counter()
        elif self._gc_start is not None:
            self.add(GC_STAGE, time.perf_counter() - self._gc_start)
            self._gc_start = None


def _timed(clock: TickClock, stage: str, fn: Callable[..., Any]) -> Callable[..., Any]:
    """``fn`` adding its wall time to ``stage`` (re-entrant calls counted once)."""
    depth = 0

    @functools.wraps(fn)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        nonlocal depth
        if depth:
            return fn(*args, **kwargs)
        depth += 1
        t0 = time.perf_counter()
        try:
            return fn(*args, **kwargs)
        finally:
            depth -= 1
            clock.add(stage, time.perf_counter() - t0)

    return wrapper


def staged_tick(follower: Follower, clock: TickClock) -> TickRecord:
    """One tick of ``follower``, its stages called in order (as ``Follower.tick`` calls them),
    each one's wall time added to ``clock``."""

    def stage(name: str, fn: Callable[..., Any], *args: Any) -> Any:
        t0 = time.perf_counter()
        try:
            return fn(*args)
        finally:
            clock.add(name, time.perf_counter() - t0)

    obs = stage("observe", follower.observe)
    target = stage("perceive", follower.perceive, obs)
    stage("predict", follower.predict, obs.stamp, target)
    stage("decide", follower.decide, obs, target)
    stage("act", follower.act, obs)
    record: TickRecord = stage("log", follower.log_tick, obs, target)
    return record


@contextmanager
def instrumented(clock: TickClock | None, profiler: cProfile.Profile | None) -> Iterator[None]:
    """Run ``Follower.tick`` with ``clock`` as :func:`staged_tick` (each stage timed), the
    :data:`INNER` work timed by wrappers, and ``profiler`` enabled; undo after.

    Nothing on disk changes: the wrappers replace class attributes of the imported modules."""
    from pfctl.core.follower import Follower

    undo: list[tuple[Any, str, Any]] = []

    def patch(owner: Any, name: str, value: Any) -> None:
        undo.append((owner, name, owner.__dict__[name]))
        setattr(owner, name, value)

    tick = Follower.__dict__["tick"]

    @functools.wraps(tick)
    def timed_tick(self: Any) -> Any:
        if clock is not None:
            clock.current = {}
            clock.embedded = 0
            clock.in_tick = True
            clock.clothes_before = _clothes_measured(self)
            clock.cpu_start = time.thread_time()
            clock.tick_start = time.perf_counter()
        if profiler is not None:
            profiler.enable()
        try:
            return staged_tick(self, clock) if clock is not None else tick(self)
        finally:
            if profiler is not None:
                profiler.disable()
            if clock is not None:
                clock.in_tick = False
                clock.tick_end = time.perf_counter()
                clock.cpu.append(time.thread_time() - clock.cpu_start)
                clock.ticks.append(clock.current)
                clock.embeddings.append(clock.embedded)
                clock.people.append(len(self.perception.last_sightings))
                clock.clothes.append(_clothes_measured(self) - clock.clothes_before)

    patch(Follower, "tick", timed_tick)
    if clock is not None:
        for label, module, cls, attr in INNER:
            if not module:
                continue
            try:
                owner = importlib.import_module(module)
                owner = getattr(owner, cls) if cls else owner
                fn = owner.__dict__[attr]
            except (ImportError, AttributeError, KeyError):
                clock.missing.append(label.strip())
                continue
            patch(owner, attr, _timed(clock, label, fn))
        _count_embeddings(clock, patch)
        gc.callbacks.append(clock.gc_callback)
    try:
        yield
    finally:
        if clock is not None:
            gc.callbacks.remove(clock.gc_callback)
        for owner, name, value in reversed(undo):
            setattr(owner, name, value)


def _clothes_measured(follower: Any) -> int:
    """Clothing histogram pairs the follower's identifier has measured so far."""
    identifier = follower.perception.identifier
    stats = getattr(identifier, "face_stats", None)
    return int(getattr(stats, "clothes_measured", 0))


def _count_embeddings(clock: TickClock, patch: Callable[[Any, str, Any], None]) -> None:
    """Count the face work of a tick: the faces ``FaceEncoder.detect`` returns (each one was
    embedded inline) and the crops ``FaceWorker.submit`` accepts; note every identifier made."""
    from pfctl.core.perception.face_worker import FaceWorker
    from pfctl.core.perception.faces import FaceEncoder
    from pfctl.core.perception.identity.identifier import TargetIdentifier

    detect = FaceEncoder.__dict__["detect"]
    submit = FaceWorker.__dict__["submit"]
    init = TargetIdentifier.__dict__["__init__"]

    @functools.wraps(detect)
    def counted(self: Any, *args: Any, **kwargs: Any) -> Any:
        faces = detect(self, *args, **kwargs)
        if clock.in_tick:
            clock.embedded += len(faces)
        return faces

    @functools.wraps(submit)
    def submitted(self: Any, *args: Any, **kwargs: Any) -> Any:
        ok = submit(self, *args, **kwargs)
        if clock.in_tick:
            clock.embedded += int(ok)
        return ok

    @functools.wraps(init)
    def noted(self: Any, *args: Any, **kwargs: Any) -> None:
        init(self, *args, **kwargs)
        clock.identifiers.append(self)

    patch(FaceEncoder, "detect", counted)
    patch(FaceWorker, "submit", submitted)
    patch(TargetIdentifier, "__init__", noted)


class Pacer:
    """``on_tick`` hook: after the tick and the step, sleep until one period after the tick
    started (no catching up after an overrun), as a robot's control loop does."""

    def __init__(self, clock: TickClock | None, period: float) -> None:
        self.clock = clock
        self.period = period
        self.start: float | None = None
        self.periods = 0
        self.overruns = 0

    def __call__(self, sim_time: float) -> None:
        now = time.perf_counter()
        if self.clock is not None:
            self.clock.steps.append(now - self.clock.tick_end)
            start = self.clock.tick_start
        else:
            start = self.start if self.start is not None else now
        wake = start + self.period
        self.periods += 1
        if now >= wake:
            self.overruns += 1
        else:
            time.sleep(wake - now)
        self.start = time.perf_counter()


class ProbedRobot:
    """The simulated robot seen by the follower: notes what each observation carries and times
    the calls the follower makes into the robot (they are the simulator's cost, not the
    follower's); everything else goes straight to the robot."""

    _TIMED = ("command", "navigate", "nav_status", "cancel", "point_head")

    def __init__(self, robot: SimRobot, clock: TickClock | None) -> None:
        self._robot = robot
        self._clock = clock

    def observe(self) -> Observation:
        observation = self._robot.observe()
        if self._clock is not None:
            self._clock.frames.append(observation.rgbd is not None)
            self._clock.scans.append(len(observation.scans))
        return observation

    def __getattr__(self, name: str) -> Any:
        value = getattr(self._robot, name)
        if self._clock is None or name not in self._TIMED:
            return value
        return _timed(self._clock, ROBOT_STAGE, value)


@dataclass(frozen=True)
class Mode:
    """How the episode is run: faces inline or in a worker, its timing, paced or not."""

    sync: bool = False
    timing: str = "realtime"
    pace: bool = True

    def describe(self) -> str:
        faces = "faces inline (sync)" if self.sync else f"face worker, {self.timing} timing"
        return f"{faces}, {'paced at the tick rate' if self.pace else 'unpaced'}"


def run_once(
    mission: Mission,
    source: str,
    seed: int | None,
    duration: float,
    clock: TickClock | None,
    profiler: cProfile.Profile | None,
    mode: Mode,
) -> tuple[EpisodeResult, int, FaceWorker | None, Pacer | None]:
    """Learn the target, then one instrumented episode; the result, the seed used, the face
    worker (closed; its stats kept) and the pacer."""
    from rich.console import Console

    from pfctl.app.episodes import run_sim_episode, target_profile
    from pfctl.app.perception import identity_params
    from pfctl.app.sim import sim_robot
    from pfctl.core.perception.face_worker import FaceWorker

    profile = target_profile(mission, None, seed, Console(stderr=True), source)
    robot = sim_robot(mission, seed, source)
    worker = None
    if not mode.sync and len(profile.faces):
        # the loop is pinned to CPU 0: the worker too, at the lowest priority
        worker = FaceWorker(identity_params(mission).face, cpus=[0], nice=19, idle=True)
    pacer = Pacer(clock, 1.0 / mission.behavior.tick_hz) if mode.pace else None
    try:
        with robot, instrumented(clock, profiler):
            port = cast("SimRobot", ProbedRobot(robot, clock))
            result = run_sim_episode(
                mission,
                port,
                profile,
                duration,
                on_tick=pacer,
                face_worker=worker if worker is not None else False,
                face_timing=mode.timing,  # type: ignore[arg-type]
            )
    finally:
        if worker is not None:
            worker.close()
    return result, robot.seed, worker, pacer


def _pcts(ms: np.ndarray) -> str:
    if len(ms) == 0:
        return "no ticks"
    return (
        f"median {np.median(ms):6.2f}  p90 {np.percentile(ms, 90):6.2f}  "
        f"p99 {np.percentile(ms, 99):6.2f}  max {ms.max():7.2f} ms  (n={len(ms)})"
    )


def cpu_name() -> str:
    """The CPU's model name (from /proc/cpuinfo when there is one)."""
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown"


def _versions() -> str:
    """Python and the versions of the libraries the tick leans on."""
    from importlib.metadata import PackageNotFoundError, version

    parts = [f"python {platform.python_version()}"]
    for dist in ("numpy", "scipy", "scikit-learn", "pybullet", "dlib", "py_trees"):
        try:
            parts.append(f"{dist} {version(dist)}")
        except PackageNotFoundError:
            continue
    try:
        import dlib

        parts.append(f"(dlib BLAS {dlib.DLIB_USE_BLAS}, AVX {dlib.USE_AVX_INSTRUCTIONS})")
    except ImportError:
        pass
    return ", ".join(parts)


def report(
    result: EpisodeResult,
    clock: TickClock,
    mission: Mission,
    seed: int,
    mode: Mode,
    worker: FaceWorker | None,
    pacer: Pacer | None,
) -> None:
    """Print the percentiles, the split by camera frame and face work, the stages, the slowest
    ticks, the face worker's jobs and the simulator's step."""
    ms = 1000.0 * np.asarray(result.tick_seconds, dtype=float)
    n = len(ms)
    frames = np.array(clock.frames[:n], dtype=bool)
    per_tick = np.array(clock.scans[:n], dtype=int)
    scans = per_tick > 0
    ok = len(frames) == n and len(clock.ticks) == n and len(clock.embeddings) == n
    p99 = float(np.percentile(ms, 99)) if n else float("nan")
    verdict = "meets" if p99 <= GOAL_MS else "misses"
    print(
        f"\nfollower tick, {mission.name}, seed {seed}: {result.sim_time:.1f} s simulated at "
        f"{mission.behavior.tick_hz:g} Hz in {result.wall_time:.1f} s wall; {mode.describe()}"
    )
    print(f"  all ticks        {_pcts(ms)}   → p99 {verdict} the goal ≤ {GOAL_MS:g} ms")
    if len(per_tick) == n and n:
        print(f"  laser scans per tick: mean {per_tick.mean():.2f}, max {per_tick.max()}")
    if len(clock.cpu) == n:
        print(f"  CPU of the tick  {_pcts(1000.0 * np.asarray(clock.cpu))}   (thread time)")
    if not ok:
        print("  (the per-tick probes do not line up with the ticks; no breakdown)")
        return
    print(f"  with RGB-D frame {_pcts(ms[frames])}")
    print(f"  without frame    {_pcts(ms[~frames])}")
    print(f"  no scan either   {_pcts(ms[~frames & ~scans])}")
    embedded = np.array(clock.embeddings) > 0
    work = "a face embedding" if worker is None else "a face crop submitted"
    print(f"  with {work:25s} {_pcts(ms[embedded])}")
    print(f"  without {work:22s} {_pcts(ms[~embedded])}")
    if len(clock.cpu) == n:
        cpu = 1000.0 * np.asarray(clock.cpu)
        print(f"    CPU with    {_pcts(cpu[embedded])}")
        print(f"    CPU without {_pcts(cpu[~embedded])}")
    print(
        f"  first tick {ms[0]:.1f} ms; p99 without the first second "
        f"{_first_second_p99(ms, mission)}"
    )

    stage_ms = {
        label: 1000.0 * np.array([t.get(label, np.nan) for t in clock.ticks])
        for label in [*TICK_STAGES, *(s[0] for s in INNER), GC_STAGE]
    }
    top = np.sum([np.nan_to_num(stage_ms[k]) for k in TICK_STAGES], axis=0)
    stage_ms[OTHER_STAGE] = ms - top
    slow = ms >= np.percentile(ms, 99)
    rest = ms[~embedded]
    slow_rest = ~embedded & (ms >= np.percentile(rest, 99)) if len(rest) else slow & False
    print(
        f"\n  stages (ms; 'ran' = ticks that called it; 'tail' = mean over the {slow.sum()} "
        f"slowest ticks (≥ p99), whose mean is {ms[slow].mean():.1f} ms; 'tail w/o emb.' = the "
        f"same over the {slow_rest.sum()} slowest ticks without {work}"
        + (f", mean {ms[slow_rest].mean():.1f} ms)" if slow_rest.any() else ")")
    )
    print(
        f"  {'stage':36s} {'ran':>5s} {'median':>8s} {'p99':>8s} {'max':>8s} {'tail':>8s} "
        f"{'tail w/o emb.':>14s}"
    )
    for label, values in stage_ms.items():
        ran = ~np.isnan(values)
        if not ran.any():
            print(f"  {label:36s} {0:5d}")
            continue
        v = values[ran]
        tail = float(np.nan_to_num(values[slow]).mean())
        tail_rest = float(np.nan_to_num(values[slow_rest]).mean()) if slow_rest.any() else 0.0
        print(
            f"  {label:36s} {ran.sum():5d} {np.median(v):8.2f} {np.percentile(v, 99):8.2f} "
            f"{v.max():8.2f} {tail:8.2f} {tail_rest:14.2f}"
        )
    if clock.missing:
        print(f"  (not timed, not found in this code: {', '.join(clock.missing)})")

    print("\n  the 10 slowest ticks (Np: people in the frame, Nc: clothes measured)")
    records = result.log.ticks
    for i in np.argsort(ms)[::-1][:10]:
        parts = sorted(((v, k.strip()) for k, v in clock.ticks[i].items()), reverse=True)[:3]
        rec = records[i] if i < len(records) else None
        what = f"{rec.awareness}/{rec.action}" if rec is not None else "?"
        who = (
            f"{clock.people[i]}p {clock.clothes[i]}c"
            if len(clock.people) == n and len(clock.clothes) == n
            else ""
        )
        cpu = f"cpu {1000 * clock.cpu[i]:5.1f}" if len(clock.cpu) == n else ""
        print(
            f"  t={rec.t if rec else float('nan'):6.1f} s {ms[i]:7.1f} ms {cpu} "
            f"{'frame' if frames[i] else '     '} {who:6s} {what:34s} "
            + ", ".join(f"{k} {1000 * v:.1f}" for v, k in parts)
        )
    _report_faces(clock, worker)
    _report_steps(clock, pacer)


def _report_faces(clock: TickClock, worker: FaceWorker | None) -> None:
    """The identifier's face searches and the worker's jobs."""
    if clock.identifiers:
        f = clock.identifiers[-1].face_stats
        print(
            f"\n  face searches (identifier): inline {f.inline}, submitted {f.submitted}, "
            f"refused by a busy worker {f.refused}, deferred {f.deferred}, folded in {f.folded}, "
            f"discarded (track gone) {f.discarded}, backed off (no face lately) {f.backed_off}, "
            f"waited for the worker {1000 * f.waited_s:.0f} ms"
        )
    if worker is None:
        return
    w = worker.stats
    print(
        f"  face worker (pid {worker.pid}, CPU 0, nice 19/SCHED_IDLE): models loaded in "
        f"{w.load_seconds or float('nan'):.2f} s; jobs submitted {w.submitted}, completed "
        f"{w.completed}, dropped (submit refused: {worker.max_in_flight} out) {w.refused}, "
        f"faces embedded {w.faces}"
    )
    if w.job_seconds:
        wall = 1000.0 * np.asarray(w.job_seconds)
        cpu = 1000.0 * np.asarray(w.job_cpu_seconds)
        print(f"    per job, wall in the child {_pcts(wall)}")
        print(f"    per job, CPU of the child  {_pcts(cpu)}")


def _report_steps(clock: TickClock, pacer: Pacer | None) -> None:
    """The simulator's step (not in the tick) and the pacing."""
    if clock.steps:
        steps = 1000.0 * np.array(clock.steps)
        print(f"\n  simulator step + bookkeeping (not in the tick) {_pcts(steps)}")
    if pacer is not None:
        print(
            f"  paced at {1000 * pacer.period:.0f} ms: {pacer.overruns} of {pacer.periods} "
            "periods overran (tick + step longer than the period; no sleep then)"
        )


def _first_second_p99(ms: np.ndarray, mission: Mission) -> str:
    skip = round(mission.behavior.tick_hz)
    return f"{np.percentile(ms[skip:], 99):.2f} ms" if len(ms) > skip else "—"


def print_profile(profiler: cProfile.Profile, result: EpisodeResult, top: int) -> None:
    """The ``top`` functions by cumulative time inside ``Follower.tick``."""
    out = io.StringIO()
    stats = pstats.Stats(profiler, stream=out)
    total = sum(result.tick_seconds)
    print(
        f"\ncProfile inside Follower.tick ({len(result.tick_seconds)} ticks, {total:.1f} s of "
        f"profiled tick time, profiler overhead included), top {top} by cumulative time:"
    )
    stats.strip_dirs().sort_stats("cumulative").print_stats(top)
    text = out.getvalue()
    start = text.find("   ncalls")
    print(text[start:] if start >= 0 else text)


def main() -> int:
    """Parse the arguments, run, print; the exit status."""
    parser = argparse.ArgumentParser(
        description=__doc__.splitlines()[0], formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument(
        "mission", nargs="?", type=Path, default=CROWD, help="mission YAML (default: house_crowd)"
    )
    parser.add_argument("--duration", type=float, default=60.0, help="simulated seconds")
    parser.add_argument("--seed", type=int, default=None, help="seed (default: the scenario's)")
    parser.add_argument("--profile", action="store_true", help="also cProfile the ticks")
    parser.add_argument("--top", type=int, default=25, help="functions shown by --profile")
    parser.add_argument(
        "--sync", action="store_true", help="search faces inline in the tick (no worker)"
    )
    parser.add_argument(
        "--timing",
        choices=("realtime", "deterministic"),
        default="realtime",
        help="the face worker's timing (default: realtime, as on a robot)",
    )
    parser.add_argument(
        "--no-pace", action="store_true", help="do not sleep to the tick rate between ticks"
    )
    args = parser.parse_args()

    if not args.mission.is_file():
        hint = (
            " (the crowd mission is not written yet; pass another, e.g. missions/house.yaml)"
            if args.mission == CROWD
            else ""
        )
        print(f"{args.mission}: no such mission file{hint}", file=sys.stderr)
        return 2
    from pfctl.errors import UserError
    from pfctl.mission import load_mission

    try:
        mission = load_mission(args.mission)
    except UserError as err:
        print(err, file=sys.stderr)
        return 2

    affinity = sorted(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else "?"
    print("pfctl follower-tick benchmark")
    print(f"  machine : {platform.platform()} | {cpu_name()} | cpu affinity {affinity}")
    print(f"  {_versions()}")
    print(
        f"  mission : {args.mission} ({len(mission.scenario.people)} people"
        f" + {getattr(mission.scenario, 'random_people', 0)} random), "
        f"{args.duration:g} s simulated, tick {mission.behavior.tick_hz:g} Hz"
    )

    mode = Mode(sync=args.sync, timing=args.timing, pace=not args.no_pace)
    print(f"  mode    : {mode.describe()}")
    from pfctl.app.memory import retain_freed_memory

    kept = retain_freed_memory()  # as run_follower does for every episode
    print(f"  memory  : freed blocks kept in the heap (retain_freed_memory: {kept})")
    clock = TickClock()
    try:
        result, seed, worker, pacer = run_once(
            mission, str(args.mission), args.seed, args.duration, clock, None, mode
        )
    except UserError as err:
        print(err, file=sys.stderr)
        return 2
    report(result, clock, mission, seed, mode, worker, pacer)

    if args.profile:
        profiler = cProfile.Profile()
        result, *_ = run_once(mission, str(args.mission), seed, args.duration, None, profiler, mode)
        print_profile(profiler, result, args.top)
    return 0


if __name__ == "__main__":
    sys.exit(main())
