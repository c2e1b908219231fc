"""CPU time of the follower's perception stages on a recorded crowd episode, replayed offline.

Run::

    .venv/bin/python benchmarks/replay_tick_stages.py --record /tmp/crowd.pkl   # ~70 s, once
    .venv/bin/python benchmarks/replay_tick_stages.py /tmp/crowd.pkl            # replay, ~1 min

``--record`` runs the crowd mission (``missions/house_crowd.yaml``, seed 7, 60 s, unpaced, faces
searched inline) and keeps every observation the follower perceived, the person detector and the
belief it started with and the target profile. The replay feeds the same scans and frames, in
order, to a fresh :class:`~pfctl.core.perception.pipeline.Perception` (the identifier without faces:
the live run's face results depend on timing) and an occupancy grid, then asks the belief for the
gaze's peaks, as the follower's tick does, ``--repeats`` times (default 5). Per stage and call
it keeps the smallest CPU time (``time.thread_time``) over the repeats — the replay is
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

#: (label, module, class, method) timed in the replay; indented labels run inside the one above.
STAGES: tuple[tuple[str, str, str, str], ...] = (
    ("on_scan", "pfctl.core.perception.pipeline", "Perception", "on_scan"),
    ("  leg detection", "pfctl.core.perception.legs.detector", "LegDetector", "detect"),
    ("    features", "pfctl.core.perception.legs.detector", "", "describe_segments"),
    ("    forest", "pfctl.core.perception.legs.model", "LegModel", "predict_proba"),
    ("    evidence", "pfctl.core.perception.legs.evidence", "LegEvidence", "update"),
    ("  tracking", "pfctl.core.perception.tracking", "MultiPersonTracker", "update"),
    ("on_frame", "pfctl.core.perception.pipeline", "Perception", "on_frame"),
    ("  person detection", "pfctl.core.perception.vision", "MaskPersonDetector", "detect"),
    (
        "  identification",
        "pfctl.core.perception.identity.identifier",
        "TargetIdentifier",
        "observe_frame",
    ),
    ("  belief update", "pfctl.core.perception.belief", "HumanBelief", "update"),
    ("grid update", "pfctl.core.mapping.grid", "OccupancyGrid", "update_scan"),
    ("belief most_likely", "pfctl.core.perception.belief", "HumanBelief", "most_likely"),
)


def record(path: Path, duration: float) -> None:
    """Run the crowd episode and pickle what the follower perceived."""
    from rich.console import Console

    from pfctl.app.episodes import run_sim_episode, target_profile
    from pfctl.app.sim import sim_robot
    from pfctl.core import follower as follower_mod
    from pfctl.mission import load_mission

    mission = load_mission(CROWD)
    profile = target_profile(mission, None, None, Console(stderr=True), str(CROWD))
    robot = sim_robot(mission, None, str(CROWD))
    kept: dict[str, Any] = {"observations": [], "profile": profile}
    original = follower_mod.Follower._perceive

    def perceive(self: Any, obs: Any) -> None:
        if not kept["observations"]:
            p = self.perception
            kept["detector"] = copy.deepcopy(p.detector)
            kept["belief"] = copy.deepcopy(p.belief)
            kept["grid"] = copy.deepcopy(self.grid)
        kept["observations"].append(dataclasses.replace(obs))
        original(self, obs)

    follower_mod.Follower._perceive = perceive  # type: ignore[method-assign]
    try:
        with robot:
            run_sim_episode(mission, robot, profile, duration, face_worker=False)
    finally:
        follower_mod.Follower._perceive = original  # type: ignore[method-assign]
    with open(path, "wb") as f:
        pickle.dump(kept, f, protocol=pickle.HIGHEST_PROTOCOL)
    print(f"{path}: {len(kept['observations'])} observations")


@contextmanager
def timed(times: dict[str, list[float]]) -> Iterator[None]:
    """Wrap the stages' methods to append each call's CPU time to ``times[label]``."""
    import importlib

    undo: list[Callable[[], None]] = []
    for label, module, cls, name in STAGES:
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
    from pfctl.app.perception import build_perception
    from pfctl.core.control import KNOWN_RADIUS
    from pfctl.core.follower import PEAK_CANDIDATES
    from pfctl.mission import load_mission

    mission = load_mission(CROWD)
    perception = build_perception(mission, detector=copy.deepcopy(kept["detector"]))
    from pfctl.app.perception import identity_params
    from pfctl.core.perception.identity.identifier import TargetIdentifier

    params = dataclasses.replace(identity_params(mission), faces=False)
    perception.identifier = TargetIdentifier(kept["profile"], params)
    perception.belief = copy.deepcopy(kept["belief"])
    grid = copy.deepcopy(kept["grid"])
    times: dict[str, list[float]] = {s[0]: [] for s in STAGES}
    totals: list[float] = []
    outputs: list[Any] = []
    with timed(times):
        for obs in kept["observations"]:
            t0 = time.thread_time()
            scan = obs.scan
            if scan is not None:
                legs = perception.on_scan(scan)
            if obs.rgbd is not None:
                perception.on_frame(obs.rgbd)
            if scan is not None:
                grid.update_scan(
                    (scan.pose.x, scan.pose.y, scan.pose.theta),
                    scan.ranges,
                    scan.angle_min,
                    scan.angle_increment,
                    scan.range_max,
                    scan.range_min,
                )
            peaks = perception.belief.most_likely(PEAK_CANDIDATES, min_separation=KNOWN_RADIUS)
            totals.append(time.thread_time() - t0)
            outputs.append(
                (
                    legs,
                    [(t.id, t.x, t.y) for t in perception.tracks()],
                    perception.identifier.target_track(),
                    peaks,
                )
            )
    outputs.append(grid.logodds.copy())
    outputs.append(perception.belief.p.copy())
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
    print(f"  {'perception+grid+peaks':24s} {_pcts(best_total)}")
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
