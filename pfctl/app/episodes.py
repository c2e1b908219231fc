"""Running one episode of the follower: on the simulated house or on any robot of the Robot port.

What ``pfctl follow`` / ``pfctl search`` and ``pfctl bench`` share, apart from the command line:
the target's profile (read, or learned in the simulator first: :func:`target_profile`), hiding
the target in the simulated house for a search (:func:`hide_target`), and the
episode itself (:func:`run_sim_episode` on the simulator, :func:`run_episode` on any robot): the
follower of §II (perception, Algorithm 2, the belief of Eq. 4, the behavior tree of Fig. 2) ticked
until the duration runs out, measured by :mod:`pfctl.core.metrics`.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
from rich.console import Console
from rich.progress import BarColumn, Progress, TextColumn

from pfctl.app.follower import EpisodeResult, build_follower, run_follower, static_map
from pfctl.app.oracle import privileged_leaves, refuse_on_real_robot, true_target_reader
from pfctl.app.perception import build_perception, identity_params
from pfctl.app.profiles import check_target_profile, load_target_profile
from pfctl.app.spill import spill_log
from pfctl.core.episode import EpisodeLog, TickRecord
from pfctl.core.mapping.grid import FREE, OCCUPIED
from pfctl.core.metrics import MetricParams, search_metrics
from pfctl.core.perception.face_worker import FaceWorker
from pfctl.core.perception.identity.params import FaceTiming
from pfctl.core.perception.identity.profile import TargetProfile, learn_profile
from pfctl.core.perception.vision import PersonDetector
from pfctl.core.robot import GroundTruth, Observation, Robot
from pfctl.errors import UserError
from pfctl.mission import Mission

if TYPE_CHECKING:
    from pfctl.backends.pybullet.simulation import SimRobot
    from pfctl.bags.recording import EpisodeRecorder

#: Simulated seconds the robot watches the target posing when it learns them first.
LEARN_SECONDS = 6.0


def target_profile(
    mission: Mission, path: Path | None, seed: int | None, console: Console, source: str
) -> TargetProfile:
    """The target's profile: read from ``path``, else learned in the simulator first."""
    params = identity_params(mission)
    if path is not None:
        try:
            profile = load_target_profile(path)
            check_target_profile(profile, params, str(path))
        except (OSError, ValueError) as err:
            raise UserError(f"--target {path}: {err}") from None
        return profile
    from pfctl.app.learn_target import learn_in_sim

    with Progress(
        TextColumn("learning the target"),
        BarColumn(),
        console=console,
        transient=True,
        disable=not console.is_terminal,
    ) as progress:
        learned = learn_in_sim(mission, LEARN_SECONDS, seed, params, progress, source)
    try:
        return learn_profile(learned.appearances, params)
    except ValueError:
        raise UserError(f"{source}: the simulated target was never seen whole") from None


class RecordingRobot:
    """The simulated robot, every observation the follower takes recorded with the truth."""

    def __init__(self, robot: SimRobot, recorder: EpisodeRecorder) -> None:
        self._robot = robot
        self._recorder = recorder

    def observe(self) -> Observation:
        observation = self._robot.observe()
        self._recorder.add(observation, self._robot.ground_truth())
        return observation

    def __getattr__(self, name: str) -> Any:
        return getattr(self._robot, name)


def run_sim_episode(
    mission: Mission,
    robot: SimRobot,
    profile: TargetProfile,
    duration: float,
    *,
    on_tick: Callable[[float], None] | None = None,
    stop: Callable[[], bool] | None = None,
    until_found: bool = False,
    recorder: EpisodeRecorder | None = None,
    face_worker: bool | FaceWorker | None = None,
    face_timing: FaceTiming | None = None,
) -> EpisodeResult:
    """The follower on the simulated robot for ``duration`` s, the truth recorded beside each
    tick; ``until_found`` ends the run when the target is identified (``pfctl search``);
    ``recorder`` also writes every observation to an episode bag.

    Faces are searched in a worker process when ``face_worker`` (None: the mission's
    ``perception.identity.face_worker``; or a :class:`FaceWorker` to use), with ``face_timing``
    (None: the mission's, ``auto`` being deterministic here). The worker is started and has
    loaded its models before the first tick, and is stopped when the episode ends, however it
    ends."""
    from pfctl.core.perception.vision import MaskPersonDetector

    detector = MaskPersonDetector(
        robot.person_instances(),
        robot.people_bodies.parts(),
        min_pixels=mission.perception.vision.min_pixels,
    )
    port: Robot = robot if recorder is None else RecordingRobot(robot, recorder)  # type: ignore[assignment]
    return run_episode(
        mission,
        port,
        profile,
        duration,
        detector=detector,
        now=lambda: robot.time,
        truth=robot.ground_truth,
        kind="sim",
        on_tick=on_tick,
        stop=stop,
        until_found=until_found,
        face_worker=face_worker,
        face_timing=face_timing,
    )


def run_episode(
    mission: Mission,
    robot: Robot,
    profile: TargetProfile,
    duration: float,
    *,
    detector: PersonDetector | None,
    now: Callable[[], float],
    truth: Callable[[], GroundTruth] | None,
    kind: Literal["sim", "real"],
    on_tick: Callable[[float], None] | None = None,
    stop: Callable[[], bool] | None = None,
    until_found: bool = False,
    face_worker: bool | FaceWorker | None = None,
    face_timing: FaceTiming | None = None,
) -> EpisodeResult:
    """The mission's follower on any ``robot`` (the Robot port) for ``duration`` s of ``now()``:
    perception with the camera ``detector`` and the human belief over the mission's static map,
    the target ``profile`` identified by Algorithm 2 (faces in a worker process as
    :func:`run_sim_episode` says; ``kind`` picks the mission's face timing for a simulated or a
    real robot), ``truth`` (a simulator's) recorded beside each tick for the metrics; the
    target's true position is given to the follower only for a tree with the oracle baseline
    (:mod:`pfctl.app.oracle`), and only with ``kind`` sim."""
    true_target = None
    if privileged_leaves(mission):
        if kind != "sim" or truth is None:
            refuse_on_real_robot(mission, mission.name)
        else:
            true_target = true_target_reader(truth)
    grid = static_map(mission)
    use_worker = mission.perception.identity.face_worker if face_worker is None else face_worker
    perception = build_perception(
        mission,
        detector=detector,
        profile=profile,
        belief_grid=(grid.geometry, grid.states() != FREE),
        occupied=(grid.geometry, grid.states() == OCCUPIED),
        face_worker=use_worker,
        face_timing=face_timing,
        robot=kind,
        handoff=not until_found,
    )
    try:
        identifier = perception.identifier
        if identifier is not None and identifier.worker is not None:
            identifier.worker.wait_ready()
        log = EpisodeLog(target_name=mission.scenario.target)
        spill_log(log)  # an episode of hours keeps its log in a file, not in memory
        follower = build_follower(mission, robot, perception, log, true_target)
        params = metric_params(mission)

        def found(record: TickRecord) -> bool:
            return record.target_id is not None and search_metrics(log, params).found

        return run_follower(
            follower,
            robot,
            duration,
            now=now,
            truth=truth,
            on_tick=on_tick,
            stop=stop,
            until=found if until_found else None,
        )
    finally:
        perception.close()


def metric_params(mission: Mission) -> MetricParams:
    """The metrics' parameters of ``mission`` (its following distance band)."""
    lo, hi = mission.control.following_band
    return MetricParams(band=(lo, hi))


def hide_target(mission: Mission, robot: SimRobot, region: str | None) -> str:
    """Put the scenario's target at a free spot of ``region`` (None: one of the mission's
    ``scenario.randomize.hide_in``, else a region other than the robot's and its neighbours,
    chosen by the seed), standing still, out of the robot's view; the region used. ``robot``
    simulates ``mission``."""
    from pfctl.backends.pybullet.walkers import PERSON_RADIUS
    from pfctl.core.mapping.regions import RegionMap

    target = next((w for w in robot.people if w.is_target), None)
    if target is None:
        raise UserError("scenario.target: the mission names no target to search for")
    regions = RegionMap(mission.layout())
    rng = np.random.default_rng([robot.seed, 99])
    here = regions.locate((robot.pose.x, robot.pose.y))
    choices = [n for n in regions.names if n != here and n not in regions.neighbours(here or "")]
    hide_in = list(mission.scenario.randomize.hide_in)
    if hide_in:
        choices = [n for n in hide_in if n != here] or hide_in
    if region is None:
        choices = choices or [n for n in regions.names if n != here]
        region = choices[int(rng.integers(len(choices)))]
    planner = robot.planner.with_radius(PERSON_RADIUS + 0.2)
    rows, cols = np.nonzero(planner.free)
    cells = planner.geometry.cell_to_world(rows, cols)
    inside = np.array([regions.locate(c) == region for c in cells[:: max(1, len(cells) // 4000)]])
    cells = cells[:: max(1, len(cells) // 4000)][inside]
    if len(cells) == 0:
        raise UserError(f"--region {region}: no free spot for the target")
    x, y = cells[int(rng.integers(len(cells)))]
    target.hold(float(x), float(y), float(rng.uniform(-math.pi, math.pi)))
    robot.resense()  # the first observation must not show the target where she stood
    return region


__all__ = [
    "LEARN_SECONDS",
    "RecordingRobot",
    "hide_target",
    "metric_params",
    "run_episode",
    "run_sim_episode",
    "target_profile",
]
