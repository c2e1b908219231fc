"""Speed of person detection + target identification (§II-E, Algorithm 2) on one CPU core.

Run ``python benchmarks/bench_identity.py [--frames N]``. Three people stand 2 m in front of the
simulated robot (the target, a look-alike in her clothes, a third person), facing it. For each
camera size (320x240, the house's; 640x480) it renders ``N`` frames (not timed; people turn a
little between frames), learns a profile from the target first, then times on each frame, after
3 warm-up frames:

- ``detect``: :class:`MaskPersonDetector` (the simulator's OpenPose stand-in), 3 people;
- ``clothes``: the upper/lower histograms of the 3 detections;
- ``identify, faces every frame``: :meth:`TargetIdentifier.observe` for the 3 tracks with a
  dlib face search and embedding in each head region on every frame (the worst case: new
  tracks);
- ``identify, settled tracks``: the same with the default budget (a track with 3 face samples
  is embedded again once a second), the steady state;
- ``total``: detect + identify, the cost per camera frame.

It prints the median, mean and minimum milliseconds per frame. It asserts nothing about time.
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
from dataclasses import replace  # noqa: E402

import cv2  # noqa: E402
import dlib  # noqa: E402
import numpy as np  # noqa: E402

from pfctl.app.sim import sim_config  # noqa: E402
from pfctl.backends.pybullet.simulation import SimRobot  # noqa: E402
from pfctl.core.perception.clothes import convert  # noqa: E402
from pfctl.core.perception.faces import FaceEncoder  # noqa: E402
from pfctl.core.perception.identity.identifier import TargetIdentifier  # noqa: E402
from pfctl.core.perception.identity.params import IdentityParams  # noqa: E402
from pfctl.core.perception.identity.profile import describe, learn_profile  # noqa: E402
from pfctl.core.perception.vision import MaskPersonDetector  # noqa: E402
from pfctl.core.robot import HeadTarget, RgbdFrame  # noqa: E402
from pfctl.mission import loads_mission  # noqa: E402

WARMUP = 3
STAGES = (
    "detect",
    "clothes",
    "identify, faces every frame",
    "identify, settled tracks",
    "total, faces every frame",
    "total, settled tracks",
)

SCENE = """
name: bench-identity
map:
  regions:
    - {{name: room, polygon: [[0, 0], [9, 0], [9, 6], [0, 6]]}}
robot: {{start: {{x: 1.0, y: 3.0, theta: 0.0}}}}
sensors:
  camera: {{width: {w}, height: {h}}}
scenario:
  seed: 5
  target: alice
  people:
    - {{name: alice, clothes: {{upper: [200, 30, 40], lower: [40, 40, 120]}}, route: [[3, 2.3]]}}
    - {{name: carol, clothes: {{upper: [200, 30, 40], lower: [40, 40, 120]}}, route: [[3, 3.0]]}}
    - {{name: bob, clothes: {{upper: [30, 120, 200], lower: [60, 60, 60]}}, route: [[3, 3.7]]}}
"""


def render(robot: SimRobot, frames: int) -> list[RgbdFrame]:
    """``frames`` frames of the three people facing the robot, turning by up to ±0.3 rad."""
    out = []
    robot.point_head(HeadTarget(0.0, math.atan2(0.35, 2.0)))
    for k in range(frames):
        for walker in robot.people:
            face = math.atan2(3.0 - walker.y, 1.0 - walker.x)
            walker.hold(walker.x, walker.y, face + 0.3 * math.sin(k))
        frame = None
        while frame is None:
            robot.step()
            frame = robot.observe().rgbd
        out.append(frame)
    return out


def run(w: int, h: int, frames: int) -> dict[str, list[float]]:
    mission = loads_mission(SCENE.format(w=w, h=h), source="bench.yaml")
    params = IdentityParams()
    encoder = FaceEncoder(params.face)
    with SimRobot(sim_config(mission)) as robot:
        detector = MaskPersonDetector(robot.person_instances(), robot.people_bodies.parts())
        shots = render(robot, frames + WARMUP)
    target = 0  # alice is instance 0
    looks = [
        describe(f.rgb, d, params, encoder)
        for f in shots[:5]
        for d in detector.detect(f)
        if d.instance == target
    ]
    profile = learn_profile(looks, params)
    always = TargetIdentifier(profile, replace(params, face_settled=10**9), encoder)
    settled = TargetIdentifier(profile, params, encoder)
    times: dict[str, list[float]] = {k: [] for k in STAGES}
    for k, frame in enumerate(shots):
        stamp = k / mission.sensors.camera.rate_hz
        t0 = time.perf_counter()
        seen = detector.detect(frame)
        t1 = time.perf_counter()
        converted = convert(frame.rgb, params.clothes.color_space)
        for d in seen:
            describe(frame.rgb, d, params, None, converted)
        t2 = time.perf_counter()
        for d in seen:
            assert d.instance is not None
            always.observe(d.instance, stamp, True, d, frame.rgb)
        t3 = time.perf_counter()
        for d in seen:
            assert d.instance is not None
            settled.observe(d.instance, stamp, True, d, frame.rgb)
        t4 = time.perf_counter()
        if k >= WARMUP:
            assert len(seen) == 3
            times["detect"].append(t1 - t0)
            times["clothes"].append(t2 - t1)
            times["identify, faces every frame"].append(t3 - t2)
            times["identify, settled tracks"].append(t4 - t3)
            times["total, faces every frame"].append((t1 - t0) + (t3 - t2))
            times["total, settled tracks"].append((t1 - t0) + (t4 - t3))
    assert always.target_track() == target and settled.target_track() == target
    return times


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=30, help="timed frames per camera size")
    args = parser.parse_args()
    cpu = platform.processor() or platform.machine()
    print(
        f"{platform.platform()} | {cpu} | Python {platform.python_version()} | "
        f"numpy {np.__version__} | OpenCV {cv2.__version__} | dlib {dlib.__version__} | one core"
    )
    print(f"3 people at 2 m, {args.frames} frames (10 Hz) per size; ms per frame")
    print(f"{'camera':>8}  {'stage':<28} {'median ms':>10} {'mean ms':>8} {'min ms':>8}")
    for w, h in ((320, 240), (640, 480)):
        for stage, runs in run(w, h, args.frames).items():
            print(
                f"{w:>4}x{h:<4} {stage:<28} {1000 * statistics.median(runs):>10.2f} "
                f"{1000 * statistics.fmean(runs):>8.2f} {1000 * min(runs):>8.2f}"
            )


if __name__ == "__main__":
    main()
