"""Running the simulated house for a while: step, drive, record, keep the truth (``pfctl sim run``).

:func:`run_simulation` steps a :class:`SimRobot` for ``duration`` simulated seconds. Each control
period it asks the driver (a script, the keyboard, or none: the robot stands still) for a
command, steps the simulator, hands the observation and the ground truth to the recorder, and
keeps the truth for the picture. Inside :func:`pfctl.interrupts.graceful_interrupts`, Ctrl-C or
SIGTERM ends the run between two periods: the result says ``interrupted`` and what was recorded
so far is a complete episode. The base is stopped at the end whatever happens.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Protocol

from pfctl.backends.pybullet.drivers import KeyboardDriver, ScriptStep
from pfctl.backends.pybullet.simulation import SimRobot
from pfctl.bags.recording import EpisodeRecorder
from pfctl.core.episode import GroundTruthCodec
from pfctl.core.packed_records import PackedRecords, packed_factory
from pfctl.core.robot import STOP, GroundTruth


class Driver(Protocol):
    """Gives the command in force at a time; ``quit`` ends the run."""

    quit: bool

    def command(self, t: float) -> ScriptStep | None: ...


@dataclass
class RunResult:
    """What a run did: the truth at every control period (packed, so that hours of it stay
    small: :class:`~pfctl.core.episode.GroundTruthCodec`) and a few counts."""

    truths: PackedRecords[GroundTruth] = field(default_factory=packed_factory(GroundTruthCodec))
    sim_time: float = 0.0
    wall_time: float = 0.0
    scans: int = 0
    frames: int = 0
    interrupted: bool = False
    """Ended early by Ctrl-C or the quit key."""

    @property
    def real_time_factor(self) -> float:
        return self.sim_time / self.wall_time if self.wall_time > 0 else float("inf")


def run_simulation(
    robot: SimRobot,
    duration: float,
    driver: Driver | None = None,
    recorder: EpisodeRecorder | None = None,
    keys: Callable[[], str] | None = None,
    on_tick: Callable[[float], None] | None = None,
    stop: Callable[[], bool] | None = None,
) -> RunResult:
    """Step ``robot`` for ``duration`` simulated seconds (see the module docstring).

    ``keys`` returns the keys pressed since its last call; they go to ``driver`` when it is a
    :class:`KeyboardDriver`. ``on_tick`` gets the simulated time after every period (progress).
    ``stop`` (e.g. the flag of :func:`pfctl.interrupts.graceful_interrupts`) ends the run when it
    returns True.
    """
    result = RunResult()
    start = time.perf_counter()
    last: ScriptStep | None = None
    try:
        while robot.time < duration - 1e-9:
            if keys is not None and isinstance(driver, KeyboardDriver):
                driver.press(keys())
            if (stop is not None and stop()) or (driver is not None and driver.quit):
                result.interrupted = True
                break
            if driver is not None:
                step = driver.command(robot.time)
                if step is not None and step != last:
                    robot.command(step.base, step.head)
                    last = step
            robot.step()
            observation = robot.observe()
            truth = robot.ground_truth()
            result.scans += observation.scan is not None
            result.frames += observation.rgbd is not None
            result.truths.append(truth)
            if recorder is not None:
                recorder.add(observation, truth)
            if on_tick is not None:
                on_tick(robot.time)
    except KeyboardInterrupt:
        result.interrupted = True
    finally:
        robot.command(STOP)
    result.sim_time = robot.time
    result.wall_time = time.perf_counter() - start
    return result


__all__ = ["Driver", "RunResult", "run_simulation"]
