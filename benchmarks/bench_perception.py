"""Speed of the laser perception per scan on one CPU core: leg detection + tracking, 10 people.

Run ``python benchmarks/bench_perception.py [--runs N] [--static-after S]``. It feeds the
1081-beam crowd scan of ``bench_legs.py`` (10 people 1–5 m ahead) to
:meth:`pfctl.core.perception.pipeline.Perception.on_scan` at 40 Hz stamps — leg detection with the
shipped model, then the tracker's predict, Hungarian association and Kalman updates — and prints the
median, 90th and 99th percentiles in milliseconds after the ten tracks are confirmed. Goal (issue
5): under 3 ms a scan. ``--static-after S`` turns the static-scene filter on
(``perception.legs.static_after_s``). The belief update is timed by ``bench_tracking_belief.py``.
It asserts nothing about time.
"""

from __future__ import annotations

import os

# One core, one thread: set before numpy is imported.
for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"
if hasattr(os, "sched_setaffinity"):
    os.sched_setaffinity(0, {0})

import argparse  # noqa: E402
import time  # noqa: E402
from dataclasses import replace  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402
from bench_legs import crowd_scan  # noqa: E402

from pfctl.app.perception import build_perception  # noqa: E402
from pfctl.mission import load_mission  # noqa: E402

HOUSE = Path(__file__).resolve().parents[1] / "missions" / "house.yaml"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=1000, help="timed scans")
    parser.add_argument(
        "--static-after",
        type=float,
        default=0.0,
        help="perception.legs.static_after_s (the static-scene filter; 0: the mission's default)",
    )
    args = parser.parse_args()
    scan = crowd_scan(10)
    mission = load_mission(HOUSE)
    if args.static_after > 0:
        legs = mission.perception.legs.model_copy(update={"static_after_s": args.static_after})
        perception_cfg = mission.perception.model_copy(update={"legs": legs})
        mission = mission.model_copy(update={"perception": perception_cfg})
    perception = build_perception(mission)
    for k in range(40):  # one second to confirm the tracks
        perception.on_scan(replace(scan, stamp=k / 40))
    times = []
    for k in range(40, 40 + args.runs):
        s = replace(scan, stamp=k / 40)
        start = time.perf_counter()
        perception.on_scan(s)
        times.append(time.perf_counter() - start)
    ms = 1000 * np.array(times)
    tracks = perception.tracks()
    print(
        f"legs + tracking, {len(scan.ranges)} beams, 10 people in view, {len(tracks)} confirmed "
        f"tracks, {args.runs} scans: median {np.median(ms):.3f} ms, p90 "
        f"{np.percentile(ms, 90):.3f} ms, p99 {np.percentile(ms, 99):.3f} ms (goal < 3 ms median)"
    )


if __name__ == "__main__":
    main()
