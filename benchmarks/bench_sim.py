"""Real-time factor of the simulated house on one CPU core.

Run ``python benchmarks/bench_sim.py [--duration S]``. On ``missions/house.yaml`` with 4 people
(the scenario's 3 plus one random distractor) the robot tours the house with MOVE_BASE (kitchen →
office → bedroom → living room → kitchen ...) while the people walk; the script reports the
real-time factor (simulated seconds per wall-clock second) of

- the laser only (the fast 2-D model at 40 Hz);
- the laser and the RGB-D camera (10 Hz, 320x240, TinyRenderer);
- the laser through PyBullet's ``rayTestBatch`` (for comparison);

and, for each, the median time of one laser scan and one camera frame. It prints figures; it
asserts nothing.
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
from typing import Any  # noqa: E402

from pfctl.app.sim import sim_config  # noqa: E402
from pfctl.backends.pybullet import simulation  # noqa: E402
from pfctl.backends.pybullet.simulation import SimOptions, SimRobot  # noqa: E402
from pfctl.core.mapping.regions import RegionMap  # noqa: E402
from pfctl.core.robot import NavStatus, Pose2D  # noqa: E402
from pfctl.mission import Mission, ScenarioConfig, load_mission  # noqa: E402

HOUSE = Path(__file__).resolve().parents[1] / "missions" / "house.yaml"
TOUR = ("office", "bedroom", "living_room", "kitchen")


def _timed(fn: Callable[..., Any], sink: list[float]) -> Callable[..., Any]:
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        t0 = time.perf_counter()
        out = fn(*args, **kwargs)
        sink.append((time.perf_counter() - t0) * 1e3)
        return out

    return wrapper


def run(mission: Mission, options: SimOptions, duration: float) -> dict[str, float]:
    """Tour the house for ``duration`` simulated seconds; the real-time factor and timings."""
    regions = RegionMap(mission.layout())
    goals = [Pose2D(*regions.region_point(name)) for name in TOUR]
    scans: list[float] = []
    frames: list[float] = []
    with SimRobot(sim_config(mission), options) as robot:
        robot.laser.scan = _timed(robot.laser.scan, scans)  # type: ignore[method-assign]
        if robot.camera is not None:
            robot.camera.render = _timed(robot.camera.render, frames)  # type: ignore[method-assign]
        k = 0
        robot.navigate(goals[k])
        t0 = time.perf_counter()
        while robot.time < duration:
            robot.step()
            robot.observe()
            if robot.nav_status() is not NavStatus.ACTIVE:
                k = (k + 1) % len(goals)
                robot.navigate(goals[k])
        wall = time.perf_counter() - t0
        sim = robot.time
        collisions = robot.collisions
    return {
        "rtf": sim / wall,
        "scan_ms": statistics.median(scans) if scans else float("nan"),
        "frame_ms": statistics.median(frames) if frames else float("nan"),
        "scans": len(scans),
        "frames": len(frames),
        "collisions": collisions,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--duration", type=float, default=60.0, help="simulated seconds per run")
    args = parser.parse_args()
    mission = load_mission(HOUSE)
    scenario = {**mission.scenario.model_dump(), "random_people": 1}  # 4 people
    mission = mission.model_copy(update={"scenario": ScenarioConfig.model_validate(scenario)})
    cam = mission.sensors.camera
    print(
        f"{platform.platform()} | {platform.processor() or platform.machine()} | "
        f"Python {platform.python_version()} | "
        f"pybullet API {simulation.p.getAPIVersion()} | one core"
    )
    print(
        f"missions/house.yaml, 4 people, {args.duration:g} s simulated per run, "
        f"laser {mission.sensors.laser.rate_hz:g} Hz, camera {cam.rate_hz:g} Hz "
        f"{cam.width}x{cam.height}\n"
    )
    print(f"{'configuration':<34}{'real-time factor':>18}{'scan ms':>10}{'frame ms':>10}")
    for label, options in (
        ("laser only (fast)", SimOptions(camera=False)),
        ("laser + RGB-D camera", SimOptions(camera=True)),
        ("laser only (rayTestBatch)", SimOptions(camera=False, laser_model="bullet")),
    ):
        r = run(mission, options, args.duration)
        print(
            f"{label:<34}{r['rtf']:>17.1f}x{r['scan_ms']:>10.2f}{r['frame_ms']:>10.1f}"
            f"   ({r['scans']:.0f} scans, {r['frames']:.0f} frames)"
        )


if __name__ == "__main__":
    main()
