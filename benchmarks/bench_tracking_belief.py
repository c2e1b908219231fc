"""Speed of the multi-person tracker and of the human belief grid (§II-E) on one CPU core.

Run ``python benchmarks/bench_tracking_belief.py [--ticks N]``.

*Tracker*: 1 or 10 people walk circles (radius 1.5–3.5 m, 0.5–1.5 m/s, paths crossing) in a
12 m × 9 m room; every 25 ms (40 Hz laser) the tracker gets their positions with 3 cm of noise
(each missed with 5 % probability), plus 0, 2 or 10 clutter detections uniform over the room
(10 per scan is a stress test far beyond a trained leg detector). After 2 s of warm-up it times
``N`` calls of ``MultiPersonTracker.update`` (predict + gated Hungarian association + Kalman
corrections + life cycle) and reports the confirmed tracks at the end. Goal: well under 1 ms with
10 tracks and 10–20 detections (leg detection and tracking together have 3 ms per scan).

*Belief*: the house of ``missions/house.yaml`` at its map resolution (0.05 m, the static map of
the simulator from ``rasterize_house``; blocked = occupied, walkable = free), the camera (58°,
0.4–8 m) at 12 poses around the house looking in 12 directions, one detected person in view.
It times ``HumanBelief.update`` (ray casting, Eq. 4, clipping) and ``visible_mask`` alone, for the
camera and for an all-around 8 m view. Goal: one update under 5 ms.

It prints figures; it asserts nothing about time.
"""

from __future__ import annotations

import os

# One core, one thread: set before numpy is imported.
for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"
if hasattr(os, "sched_setaffinity"):
    os.sched_setaffinity(0, {0})

import argparse  # noqa: E402
import math  # noqa: E402
import platform  # noqa: E402
import statistics  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import filterpy  # noqa: E402
import numpy as np  # noqa: E402
import scipy  # noqa: E402

from pfctl.core.mapping.grid import FREE, OCCUPIED  # noqa: E402
from pfctl.core.mapping.walls import rasterize_house  # noqa: E402
from pfctl.core.perception.belief import BeliefParams, HumanBelief, visible_mask  # noqa: E402
from pfctl.core.perception.tracking import (  # noqa: E402
    LASER,
    Detection,
    FieldOfView,
    MultiPersonTracker,
    TrackerParams,
)
from pfctl.core.robot import Pose2D  # noqa: E402
from pfctl.mission import load_mission  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
DT = 1.0 / 40.0
ROOM = (12.0, 9.0)
WARMUP_TICKS = 80


def crowd(n: int, ticks: int, seed: int = 0) -> list[np.ndarray]:
    """Positions ``(n, 2)`` of ``n`` people, one array per tick: each walks a circle of radius
    1.5–3.5 m somewhere in the room at 0.5–1.5 m/s, either way round (paths cross often)."""
    rng = np.random.default_rng(seed)
    centre = rng.uniform([2.0, 2.0], [ROOM[0] - 2.0, ROOM[1] - 2.0], (n, 2))
    radius = rng.uniform(1.5, 3.5, n)
    omega = rng.uniform(0.5, 1.5, n) / radius * rng.choice([-1.0, 1.0], n)
    phase = rng.uniform(-math.pi, math.pi, n)
    out = []
    for k in range(ticks):
        a = phase + omega * k * DT
        out.append(centre + radius[:, None] * np.column_stack((np.cos(a), np.sin(a))))
    return out


def time_tracker(people: int, clutter: int, ticks: int) -> tuple[list[float], int]:
    """Seconds per ``update`` after warm-up, and the confirmed tracks at the end."""
    rng = np.random.default_rng(1)
    truth = crowd(people, WARMUP_TICKS + ticks)
    fov = FieldOfView(Pose2D(ROOM[0] / 2, ROOM[1] / 2, 0.0), math.pi, 0.0, 20.0)
    tracker = MultiPersonTracker(TrackerParams())
    out = []
    for k, pos in enumerate(truth):
        seen = pos[rng.random(len(pos)) > 0.05]
        seen = seen + rng.normal(0.0, 0.03, seen.shape)
        fake = rng.uniform([0.0, 0.0], ROOM, (clutter, 2))
        dets = [Detection(float(x), float(y)) for x, y in np.vstack((seen, fake))]
        start = time.perf_counter()
        tracker.update(LASER, dets, fov, k * DT)
        if k >= WARMUP_TICKS:
            out.append(time.perf_counter() - start)
    return out, len(tracker.tracks(confirmed_only=True))


def camera_views(seed: int = 0) -> list[tuple[FieldOfView, tuple[float, float]]]:
    """12 camera poses × 12 headings in the house, each with a person 2 m ahead."""
    rng = np.random.default_rng(seed)
    spots = [
        (1.0, 3.3),
        (3.0, 1.5),
        (6.5, 2.0),
        (10.5, 2.5),
        (1.5, 5.0),
        (4.0, 5.0),
        (8.0, 5.0),
        (11.0, 5.0),
        (2.5, 7.5),
        (4.5, 7.0),
        (8.0, 7.5),
        (9.0, 8.0),
    ]
    out = []
    for x, y in spots:
        for k in range(12):
            yaw = k * math.pi / 6 + rng.uniform(-0.1, 0.1)
            fov = FieldOfView(Pose2D(x, y, yaw), math.radians(29.0), 0.4, 8.0)
            out.append((fov, (x + 2.0 * math.cos(yaw), y + 2.0 * math.sin(yaw))))
    return out


def time_belief(runs: int) -> dict[str, list[float]]:
    mission = load_mission(ROOT / "missions" / "house.yaml")
    grid = rasterize_house(mission.layout(), mission.map.resolution, mission.map.wall_thickness)
    states = grid.states()
    blocked, walkable = states == OCCUPIED, states == FREE
    belief = HumanBelief(grid.geometry, BeliefParams(), blocked, walkable)
    views = camera_views()
    times: dict[str, list[float]] = {"update": [], "visible_mask": [], "visible_mask 360°": []}
    for k in range(runs + 10):
        fov, person = views[k % len(views)]
        around = FieldOfView(fov.origin, math.pi, 0.4, 8.0)
        t0 = time.perf_counter()
        belief.update(fov, [person], t=0.1 * k)
        t1 = time.perf_counter()
        visible_mask(grid.geometry, fov, blocked)
        t2 = time.perf_counter()
        visible_mask(grid.geometry, around, blocked)
        t3 = time.perf_counter()
        if k >= 10:
            times["update"].append(t1 - t0)
            times["visible_mask"].append(t2 - t1)
            times["visible_mask 360°"].append(t3 - t2)
    print(
        f"belief grid {grid.geometry.width} x {grid.geometry.height} cells at "
        f"{grid.geometry.resolution:g} m ({grid.geometry.width * grid.geometry.height} cells), "
        f"{len(views)} camera views, {runs} runs"
    )
    return times


def row(label: str, seconds: list[float]) -> str:
    ms = sorted(1000 * s for s in seconds)
    p90 = ms[int(0.9 * (len(ms) - 1))]
    return f"{label:<34} {statistics.median(ms):>9.3f} {p90:>9.3f} {ms[0]:>9.3f} {ms[-1]:>9.3f}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--ticks", type=int, default=2000, help="timed tracker ticks per case")
    parser.add_argument("--runs", type=int, default=500, help="timed belief updates")
    args = parser.parse_args()
    cpu = platform.processor() or platform.machine()
    print(
        f"{platform.platform()} | {cpu} | Python {platform.python_version()} | "
        f"numpy {np.__version__} | scipy {scipy.__version__} | filterpy {filterpy.__version__} "
        f"| one core"
    )
    header = f"{'':<34} {'median ms':>9} {'p90 ms':>9} {'min ms':>9} {'max ms':>9}"
    print(f"tracker: 40 Hz, 3 cm noise, 5 % misses, {args.ticks} ticks after 2 s warm-up")
    print(header)
    for people, clutter in ((1, 0), (10, 0), (10, 2), (10, 10)):
        seconds, confirmed = time_tracker(people, clutter, args.ticks)
        label = f"{people} people + {clutter} clutter ({confirmed} conf.)"
        print(row(label, seconds))
    times = time_belief(args.runs)
    print(header)
    for label, seconds in times.items():
        print(row(label, seconds))


if __name__ == "__main__":
    main()
