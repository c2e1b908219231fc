"""Speed of laser leg detection (§II-E) on one CPU core: a 1081-beam scan with 10 people.

Run ``python benchmarks/bench_legs.py [--runs N]``. It builds one scan of the HSR's laser (270°
at 0.25°, 1081 beams, 1 cm noise) in the living room of ``missions/house.yaml`` with 10 people
standing and walking 1–5 m in front, then times, after 20 warm-up calls, ``N`` calls of
``LegDetector.detect`` with the shipped model (segmentation, features, forest, pairing), and
each stage alone. It prints medians and minima in milliseconds. Goal: under ~1.5 ms a scan
(the tracker gets the rest of a 3 ms budget). It asserts nothing about time.
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
from collections.abc import Callable  # noqa: E402
from pathlib import Path  # noqa: E402
from typing import Any  # noqa: E402

import numpy as np  # noqa: E402

from pfctl.app.leg_models import load_leg_model  # noqa: E402
from pfctl.app.sim import house_config  # noqa: E402
from pfctl.backends.pybullet.laser import FastLaser, LaserSpec  # noqa: E402
from pfctl.backends.pybullet.leg_scans import LegScanGenerator  # noqa: E402
from pfctl.backends.pybullet.walkers import HIP_WIDTH, LEG_RADIUS  # noqa: E402
from pfctl.core.perception.legs.detector import (  # noqa: E402
    LegDetector,
    LegParams,
    describe_segments,
)
from pfctl.core.perception.legs.features import segment_features, segment_scan  # noqa: E402
from pfctl.core.robot import LaserScan, Pose2D  # noqa: E402
from pfctl.mission import load_mission  # noqa: E402

HOUSE = Path(__file__).resolve().parents[1] / "missions" / "house.yaml"


def crowd_scan(people: int = 10) -> LaserScan:
    """The living room seen from (5.6, 2, 0°) with ``people`` pairs of legs 1–5 m ahead."""
    gen = LegScanGenerator(house_config(load_mission(HOUSE)))
    laser = FastLaser(gen.segments, LaserSpec(noise_std=0.01), seed=0, one_sided=True)
    pose = Pose2D(5.6, 2.0, 0.0)
    rng = np.random.default_rng(0)
    legs = []
    for k in range(people):
        d, a = 1.0 + 4.0 * k / people, math.radians(-50 + 100 * k / people)
        cx, cy = pose.x + d * math.cos(a), pose.y + d * math.sin(a)
        heading = rng.uniform(-math.pi, math.pi)
        stride = rng.uniform(0.0, 0.3) * (k % 2)
        c, s = math.cos(heading), math.sin(heading)
        for side in (1, -1):
            fwd, lat = side * stride / 2, side * HIP_WIDTH / 2
            legs.append((cx + c * fwd - s * lat, cy + s * fwd + c * lat, LEG_RADIUS))
    return laser.scan(pose.compose(Pose2D(-0.167, 0.0)), np.array(legs), 0.0)


def timed(fn: Callable[[], Any], runs: int) -> list[float]:
    for _ in range(20):
        fn()
    out = []
    for _ in range(runs):
        start = time.perf_counter()
        fn()
        out.append(time.perf_counter() - start)
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=500, help="timed calls per stage")
    args = parser.parse_args()
    scan = crowd_scan()
    params = LegParams()
    model = load_leg_model(None)
    detector = LegDetector(model, params)
    found = detector.detect(scan)
    segs, feats, ok = describe_segments(scan, params)
    cpu = platform.processor() or platform.machine()
    print(
        f"{platform.platform()} | {cpu} | Python {platform.python_version()} | "
        f"numpy {np.__version__} | one core"
    )
    print(
        f"scan: {len(scan.ranges)} beams, {len(segs)} segments, {int(ok.sum())} classified; "
        f"model {model.n_trees} trees depth {model.depth}; found {len(found.legs)} legs, "
        f"{len(found.people)} people (10 in view); {args.runs} runs"
    )
    stages = {
        "segment": lambda: segment_scan(
            scan.ranges,
            scan.angle_min,
            scan.angle_increment,
            scan.range_min,
            scan.range_max,
            params.jump_distance,
        ),
        "features": lambda: segment_features(segs),
        "forest": lambda: model.predict_proba(feats[ok]),
        "detect (all)": lambda: detector.detect(scan),
    }
    print(f"{'stage':<14} {'median ms':>10} {'min ms':>8}")
    for name, fn in stages.items():
        runs = timed(fn, args.runs)
        print(f"{name:<14} {1000 * statistics.median(runs):>10.3f} {1000 * min(runs):>8.3f}")


if __name__ == "__main__":
    main()
