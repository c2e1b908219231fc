"""Speed of the simulator's planning, navigation and people on one CPU core.

Run ``python benchmarks/bench_nav.py [--runs N]``. On ``missions/house.yaml`` (0.05 m cells) it
reports the median (and minimum) time, after warm-up, of building a :class:`GridPlanner`, of one
plan kitchen → office (two doors), of re-planning around a blocker (``with_obstacles`` + plan), of
one :meth:`Navigator.update` while driving, of stepping 4 walkers by one 25 ms physics period, and
of :meth:`PeopleBodies.sync` for 4 people in PyBullet DIRECT. It prints figures; it asserts nothing.
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"
if hasattr(os, "sched_setaffinity"):
    os.sched_setaffinity(0, {0})

import argparse  # noqa: E402
import platform  # noqa: E402
import statistics  # noqa: E402
import time  # noqa: E402
from collections.abc import Callable  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402
import pybullet as p  # noqa: E402

from pfctl.app.sim import sim_config  # noqa: E402
from pfctl.backends.pybullet.navigation import Navigator  # noqa: E402
from pfctl.backends.pybullet.people_bodies import PeopleBodies  # noqa: E402
from pfctl.backends.pybullet.walkers import make_walkers  # noqa: E402
from pfctl.core.mapping.planning import GridPlanner  # noqa: E402
from pfctl.core.mapping.walls import rasterize_house  # noqa: E402
from pfctl.core.robot import Pose2D  # noqa: E402
from pfctl.mission import ScenarioConfig, load_mission  # noqa: E402

HOUSE = Path(__file__).resolve().parents[1] / "missions" / "house.yaml"


def timed(fn: Callable[[], object], runs: int, warmup: int = 3) -> tuple[float, float]:
    """Median and minimum wall time (ms) of ``fn`` over ``runs`` calls after ``warmup``."""
    for _ in range(warmup):
        fn()
    times = []
    for _ in range(runs):
        t0 = time.perf_counter()
        fn()
        times.append((time.perf_counter() - t0) * 1e3)
    return statistics.median(times), min(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=30)
    args = parser.parse_args()
    mission = load_mission(HOUSE)
    scenario = {**mission.scenario.model_dump(), "random_people": 1}  # 4 people
    mission = mission.model_copy(update={"scenario": ScenarioConfig.model_validate(scenario)})
    grid = rasterize_house(mission.layout(), mission.map.resolution, mission.map.wall_thickness)
    planner = GridPlanner(grid, mission.robot.radius)
    start, goal = (1.0, 3.3), (3.0, 7.5)

    def fresh_plan() -> None:
        GridPlanner(grid, mission.robot.radius).plan(start, goal)

    blocker = np.array([[2.45, 5.0]])
    nav = Navigator(planner, mission.robot.max_linear_speed, mission.robot.max_angular_speed)
    pose = Pose2D(*start)
    nav.start(Pose2D(*goal), pose)
    scan_pts = np.column_stack((np.linspace(0, 12, 1081), np.full(1081, 4.0)))
    walkers = make_walkers(sim_config(mission).scenario, mission.layout(), planner, seed=7)
    client = p.connect(p.DIRECT)
    bodies = PeopleBodies(client, walkers, seed=7)

    def step_walkers() -> None:
        for w in walkers:
            w.step(0.025)

    rows = [
        ("GridPlanner(...) build", lambda: GridPlanner(grid, mission.robot.radius)),
        ("build + first plan (graph)", fresh_plan),
        ("plan kitchen -> office", lambda: planner.plan(start, goal)),
        ("with_obstacles + plan", lambda: planner.with_obstacles(blocker, 0.1).plan(start, goal)),
        ("Navigator.update (1081 pts)", lambda: nav.update(pose, 0.1, scan_pts)),
        ("4 walkers .step(25 ms)", step_walkers),
        ("PeopleBodies.sync (4)", bodies.sync),
    ]
    print(f"{platform.platform()} | {platform.processor() or platform.machine()}")
    print(f"Python {platform.python_version()}, numpy {np.__version__}; runs={args.runs}")
    print(f"{'step':32s} {'median ms':>10s} {'min ms':>8s}")
    for name, fn in rows:
        med, lo = timed(fn, args.runs)
        print(f"{name:32s} {med:10.3f} {lo:8.3f}")
    bodies.close()
    p.disconnect(client)


if __name__ == "__main__":
    main()
