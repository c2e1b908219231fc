"""CPU time of one call of Algorithm 1 (``WorldModel.next_waypoint``) on the calls of episodes.

Run::

    .venv/bin/python benchmarks/bench_alg1.py --record /tmp/alg1.pkl   # crowd, seeds 7-10, 120 s
    .venv/bin/python benchmarks/bench_alg1.py --replay /tmp/alg1.pkl   # the same calls again
    .venv/bin/python benchmarks/bench_alg1.py missions/house.yaml --seeds 1 2 --record /tmp/h.pkl

``--record`` runs the follower in the simulator (faces inline, not timed) for ``--duration``
simulated seconds per seed and keeps every call of ``WorldModel.next_waypoint`` the behaviour
tree makes: the occupancy grid, the target's history, the robot's position, the search settings
and the decision. Then it calls ``next_waypoint`` again on each, ``--reps`` times, and prints the
median, p90, p99 and maximum over the calls of one call's CPU time (``time.thread_time``: each
call's best of the reps, and every rep), and whether each decision is the recorded one. The file
holds arrays, numbers and the mission's path, so a recording made on one commit replays on
another (a worktree at the old commit): the same calls before and after a change.

Like the other benchmarks it sets one BLAS thread and pins itself to one CPU (``--cpu``, default
0). It prints figures; it asserts nothing about time.
"""

from __future__ import annotations

import os

# One thread: set before numpy is imported.
for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"

import argparse  # noqa: E402
import dataclasses  # noqa: E402
import pickle  # noqa: E402
import platform  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402
from typing import Any  # noqa: E402

import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
CROWD = ROOT / "missions" / "house_crowd.yaml"


def _summary(decision: Any) -> str:
    """What Algorithm 1 decided, to compare a replayed call with the recorded one."""
    d = decision
    fields = (d.waypoint, d.heading_region, d.target_region, d.target_point, d.reason)
    return repr((*fields, d.goals, d.utilities, d.best, [c.n_unknown for c in d.clusters]))


def record(mission_path: Path, seeds: list[int], duration: float) -> list[dict[str, Any]]:
    """Run the follower for each seed; every next_waypoint call's inputs and decision."""
    from rich.console import Console

    from pfctl.app.episodes import run_sim_episode, target_profile
    from pfctl.app.sim import sim_robot
    from pfctl.core.behavior.world import WorldModel
    from pfctl.mission import load_mission

    mission = load_mission(mission_path)
    calls: list[dict[str, Any]] = []
    original = WorldModel.next_waypoint

    def recorded(self: WorldModel, history: Any, here: tuple[float, float]) -> Any:
        call = {
            "logodds": self.grid.logodds.copy(),
            "geometry": dataclasses.astuple(self.grid.geometry),
            "history": np.array(history, dtype=float, copy=True),
            "here": (float(here[0]), float(here[1])),
            "search": dataclasses.asdict(self.search),
        }
        decision = original(self, history, here)
        calls.append({**call, "decision": _summary(decision)})
        return decision

    WorldModel.next_waypoint = recorded  # type: ignore[method-assign]
    try:
        for seed in seeds:
            start = len(calls)
            profile = target_profile(mission, None, seed, Console(stderr=True), str(mission_path))
            with sim_robot(mission, seed, str(mission_path)) as robot:
                run_sim_episode(mission, robot, profile, duration, face_worker=False)
            print(f"  recorded seed {seed}: {len(calls) - start} calls", file=sys.stderr)
    finally:
        WorldModel.next_waypoint = original  # type: ignore[method-assign]
    return calls


def replay(mission_path: str, calls: list[dict[str, Any]], reps: int) -> None:
    """Time next_waypoint on each recorded call and print the figures."""
    from pfctl.core.behavior.world import WorldModel
    from pfctl.core.mapping.grid import GridGeometry, OccupancyGrid
    from pfctl.core.mapping.regions import RegionMap, SearchParams
    from pfctl.mission import load_mission

    regions = RegionMap(load_mission(mission_path).layout())
    best, every, same = [], [], 0
    for call in calls:
        resolution, width, height, origin = call["geometry"]
        grid = OccupancyGrid(
            GridGeometry(resolution, width, height, tuple(origin)), call["logodds"]
        )
        world = WorldModel(grid, None, regions, SearchParams(**call["search"]))  # type: ignore[arg-type]
        times = []
        for _ in range(reps):
            t0 = time.thread_time()
            decision = world.next_waypoint(call["history"], call["here"])
            times.append(time.thread_time() - t0)
        best.append(min(times))
        every.extend(times)
        same += _summary(decision) == call["decision"]
    for label, values in (("best of the reps", best), ("every rep", every)):
        ms = 1e3 * np.array(values)
        print(
            f"  {label:16s}: median {np.median(ms):5.2f}  p90 {np.percentile(ms, 90):5.2f}  "
            f"p99 {np.percentile(ms, 99):5.2f}  max {ms.max():5.2f} ms  (n={len(ms)})"
        )
    print(f"  decisions as recorded: {same} of {len(calls)}")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("mission", nargs="?", type=Path, default=CROWD, help="mission YAML")
    parser.add_argument("--seeds", type=int, nargs="+", default=[7, 8, 9, 10])
    parser.add_argument("--duration", type=float, default=120.0, help="simulated s per seed")
    parser.add_argument("--record", type=Path, help="run the episodes, save the calls here")
    parser.add_argument("--replay", type=Path, help="time the calls saved here")
    parser.add_argument("--reps", type=int, default=5, help="timed calls per recorded call")
    parser.add_argument("--cpu", type=int, default=0, help="the CPU to pin to")
    args = parser.parse_args()
    if (args.record is None) == (args.replay is None):
        parser.error("give one of --record FILE and --replay FILE")
    if hasattr(os, "sched_setaffinity"):
        os.sched_setaffinity(0, {args.cpu})
    if args.record is not None:
        calls = record(args.mission, args.seeds, args.duration)
        with open(args.record, "wb") as f:
            pickle.dump({"mission": str(args.mission), "calls": calls}, f)
        mission = str(args.mission)
    else:
        with open(args.replay, "rb") as f:
            saved = pickle.load(f)
        mission, calls = saved["mission"], saved["calls"]
    import pfctl

    print("Algorithm 1 (WorldModel.next_waypoint) per call, CPU time")
    print(
        f"  machine : {platform.platform()} | cpu {args.cpu} | python {platform.python_version()}"
    )
    print(f"  pfctl   : {Path(pfctl.__file__).parent}")
    print(f"  calls   : {len(calls)} from {mission}, {args.reps} reps each")
    replay(mission, calls, args.reps)
    return 0


if __name__ == "__main__":
    sys.exit(main())
