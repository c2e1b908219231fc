"""CPU time of the follower's perceive stage on a recorded crowd episode, replayed offline.

Run::

    .venv/bin/python benchmarks/replay_tick_stages.py --record /tmp/crowd.pkl   # ~70 s, once
    .venv/bin/python benchmarks/replay_tick_stages.py /tmp/crowd.pkl            # replay, ~1 min

``--record`` runs the crowd mission (``missions/house_crowd.yaml``, seed 7, 60 s, unpaced, faces
searched inline) and keeps every observation the follower took (read through a thin proxy around
the robot), the person detector and the target profile. The replay builds a fresh follower for
the mission (its perception's identifier without faces: the live run's face results depend on
timing) and calls its stages on the same observations, in order: ``Follower.perceive`` (legs,
tracks, detections, identity, belief, occupancy grid) and the gaze rule
(``Follower.gaze_intent``, which asks the belief for its peaks), ``--repeats`` times (default
5); the work inside them is timed by wrapping the methods that do it. Per stage and call it
keeps the smallest CPU time (``time.thread_time``) over the repeats — the replay is
deterministic, so call i is the same work in every repeat and the minimum strips most of what a
busy machine adds — and prints median / p90 / p99 / max of those minima. A fixed workload to
compare code changes by; pinned to CPU 0 with one BLAS thread like the other benchmarks.
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"
if hasattr(os, "sched_setaffinity"):
    os.sched_setaffinity(0, {0})

import argparse  # noqa: E402
import copy  # noqa: E402
import dataclasses  # noqa: E402
import pickle  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from collections.abc import Callable, Iterator  # noqa: E402
from contextlib import contextmanager  # noqa: E402
from pathlib import Path  # noqa: E402
from typing import Any  # noqa: E402

import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
CROWD = ROOT / "missions" / "house_crowd.yaml"

#: The follower's stages the replay calls, timed by calling them.
PERCEIVE, GAZE = "perceive", "gaze rule"
#: (label, module, class, method): the stages (no module) and the work inside them, timed by
#: wrapping; indented labels run inside the one above.
STAGES: tuple[tuple[str, str, str, str], ...] = (
    (PERCEIVE, "", "", ""),
    ("  on_scan", "pfctl.core.perception.pipeline", "Perception", "on_scan"),
    ("    leg detection", "pfctl.core.perception.legs.detector", "LegDetector", "detect"),
    ("      features", "pfctl.core.perception.legs.detector", "", "describe_segments"),
    ("      forest", "pfctl.core.perception.legs.model", "LegModel", "predict_proba"),
    ("      evidence", "pfctl.core.perception.legs.evidence", "LegEvidence", "update"),
    ("    tracking", "pfctl.core.perception.tracking", "MultiPersonTracker", "update"),
    ("  on_frame", "pfctl.core.perception.pipeline", "Perception", "on_frame"),
    ("    person detection", "pfctl.core.perception.vision", "MaskPersonDetector", "detect"),
    (
        "    identification",
        "pfctl.core.perception.identity.identifier",
        "TargetIdentifier",
        "observe_frame",
    ),
    ("    belief update", "pfctl.core.perception.belief", "HumanBelief", "update"),
    ("  grid update", "pfctl.core.mapping.grid", "OccupancyGrid", "update_scan"),
    (GAZE, "", "", ""),
    ("  belief most_likely", "pfctl.core.perception.belief", "HumanBelief", "most_likely"),
)


class KeepingRobot:
    """The simulated robot, every observation the follower takes kept in ``observations``."""

    def __init__(self, robot: Any, observations: list[Any]) -> None:
        self._robot = robot
        self._observations = observations

    def observe(self) -> Any:
        observation = self._robot.observe()
        self._observations.append(dataclasses.replace(observation))
        return observation

    def __getattr__(self, name: str) -> Any:
        return getattr(self._robot, name)


class NoRobot:
    """The replay's robot: the stages replayed never command it (closing the follower stops
    the base)."""

    def command(self, *args: Any) -> None:
        pass


def record(path: Path, duration: float) -> None:
    """Run the crowd episode and pickle what the follower observed."""
    from rich.console import Console

    from pfctl.app.episodes import run_sim_episode, target_profile
    from pfctl.app.sim import sim_robot
    from pfctl.core.perception.vision import MaskPersonDetector
    from pfctl.mission import load_mission

    mission = load_mission(CROWD)
    profile = target_profile(mission, None, None, Console(stderr=True), str(CROWD))
    robot = sim_robot(mission, None, str(CROWD))
    observations: list[Any] = []
    kept: dict[str, Any] = {"observations": observations, "profile": profile}
    with robot:
        # the detector run_sim_episode makes for this robot
        kept["detector"] = MaskPersonDetector(
            robot.person_instances(),
            robot.people_bodies.parts(),
            min_pixels=mission.perception.vision.min_pixels,
        )
        port: Any = KeepingRobot(robot, observations)
        run_sim_episode(mission, port, profile, duration, face_worker=False)
    with open(path, "wb") as f:
        pickle.dump(kept, f, protocol=pickle.HIGHEST_PROTOCOL)
    print(f"{path}: {len(observations)} observations")


@contextmanager
def timed(times: dict[str, list[float]]) -> Iterator[None]:
    """Wrap the stages' methods to append each call's CPU time to ``times[label]``."""
    import importlib

    undo: list[Callable[[], None]] = []
    for label, module, cls, name in STAGES:
        if not module:
            continue  # a stage the replay calls
        owner: Any = importlib.import_module(module)
        if cls:
            owner = getattr(owner, cls)
        fn = getattr(owner, name)

        def wrapper(*a: Any, _fn: Any = fn, _label: str = label, **k: Any) -> Any:
            t0 = time.thread_time()
            try:
                return _fn(*a, **k)
            finally:
                times[_label].append(time.thread_time() - t0)

        setattr(owner, name, wrapper)
        undo.append(lambda o=owner, n=name, f=fn: setattr(o, n, f))
        if not cls:  # a module function imported by name elsewhere
            legs = importlib.import_module("pfctl.core.perception.legs.detector")
            if getattr(legs, name, None) is fn:
                setattr(legs, name, wrapper)
                undo.append(lambda m=legs, n=name, f=fn: setattr(m, n, f))
    try:
        yield
    finally:
        for u in reversed(undo):
            u()


def replay_once(kept: dict[str, Any]) -> tuple[dict[str, list[float]], list[float], Any]:
    """One replay: per-stage call times, per-observation total, and the outputs (for checks)."""
    from pfctl.app.follower import build_follower, static_map
    from pfctl.app.perception import build_perception, identity_params
    from pfctl.core.mapping.grid import FREE
    from pfctl.core.perception.identity.identifier import TargetIdentifier
    from pfctl.mission import load_mission

    mission = load_mission(CROWD)
    grid = static_map(mission)
    perception = build_perception(
        mission,
        detector=copy.deepcopy(kept["detector"]),
        belief_grid=(grid.geometry, grid.states() != FREE),
    )
    params = dataclasses.replace(identity_params(mission), faces=False)
    perception.identifier = TargetIdentifier(kept["profile"], params)
    follower = build_follower(mission, NoRobot(), perception)  # type: ignore[arg-type]
    times: dict[str, list[float]] = {s[0]: [] for s in STAGES}
    totals: list[float] = []
    outputs: list[Any] = []
    with timed(times):
        for obs in kept["observations"]:
            t0 = time.thread_time()
            target = follower.perceive(obs)
            t1 = time.thread_time()
            head = follower.gaze_intent(obs.pose, target)
            t2 = time.thread_time()
            times[PERCEIVE].append(t1 - t0)
            times[GAZE].append(t2 - t1)
            totals.append(t2 - t0)
            outputs.append(
                (
                    perception.last_legs,
                    [(t.id, t.x, t.y) for t in perception.tracks()],
                    target,
                    head,
                )
            )
    outputs.append(follower.grid.logodds.copy())
    assert perception.belief is not None
    outputs.append(perception.belief.p.copy())
    follower.close()
    return times, totals, outputs


def _pcts(ms: np.ndarray) -> str:
    if len(ms) == 0:
        return "no calls"
    p = np.percentile(ms, [50, 90, 99])
    return (
        f"median {p[0]:6.2f}  p90 {p[1]:6.2f}  p99 {p[2]:6.2f}  max {ms.max():6.2f} ms"
        f"  mean {ms.mean():5.2f}  (n={len(ms)})"
    )


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("pickle", type=Path, nargs="?", default=Path("/tmp/crowd.pkl"))
    parser.add_argument("--record", type=Path, default=None, help="record an episode to this file")
    parser.add_argument("--duration", type=float, default=60.0)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--save-outputs", type=Path, default=None)
    parser.add_argument("--compare-outputs", type=Path, default=None)
    parser.add_argument(
        "--retain", action="store_true", help="pfctl.app.memory.retain_freed_memory first"
    )
    args = parser.parse_args()
    if args.retain:
        from pfctl.app.memory import retain_freed_memory

        print(f"retain_freed_memory: {retain_freed_memory()}")
    if args.record is not None:
        record(args.record, args.duration)
        return 0
    with open(args.pickle, "rb") as f:
        kept = pickle.load(f)
    best: dict[str, np.ndarray] = {}
    best_total = None
    outputs = None
    for _ in range(args.repeats):
        times, totals, outputs = replay_once(kept)
        for k, v in times.items():
            a = np.array(v) * 1e3
            best[k] = a if k not in best else np.minimum(best[k], a)
        t = np.array(totals) * 1e3
        best_total = t if best_total is None else np.minimum(best_total, t)
    print(
        f"replay of {args.pickle}: {len(kept['observations'])} observations, min of "
        f"{args.repeats} repeats per call (CPU time)"
    )
    print(f"  {'perceive + gaze rule':24s} {_pcts(best_total)}")
    for label, *_ in STAGES:
        print(f"  {label:24s} {_pcts(best[label])}")
    if args.save_outputs is not None:
        with open(args.save_outputs, "wb") as f:
            pickle.dump(outputs, f)
    if args.compare_outputs is not None:
        with open(args.compare_outputs, "rb") as f:
            ref = pickle.load(f)
        same = _equal(ref, outputs)
        print(f"  outputs equal to {args.compare_outputs}: {same}")
    return 0


def _equal(a: Any, b: Any) -> bool:
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        return bool(np.array_equal(np.asarray(a), np.asarray(b)))
    if isinstance(a, (list, tuple)) and isinstance(b, (list, tuple)):
        return len(a) == len(b) and all(_equal(x, y) for x, y in zip(a, b, strict=True))
    return bool(a == b)


if __name__ == "__main__":
    sys.exit(main())
