"""A mission's follower: core parameters from its YAML sections, and an episode loop.

``core`` never reads the mission; this module turns ``control``, ``search``, ``prediction``,
``robot`` and ``behavior`` into the follower's values (:func:`follower_params`), builds the
:class:`~pfctl.core.follower.Follower` for a robot (:func:`build_follower`) and runs it
(:func:`run_follower`): each control period one follower tick, then one robot step. The base is
stopped at the end whatever happens.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

from pfctl.app.memory import retain_freed_memory
from pfctl.core.control import ControlParams
from pfctl.core.episode import EpisodeLog, TickRecord
from pfctl.core.follower import Follower, FollowerParams, PredictionParams
from pfctl.core.mapping.grid import InverseSensorModel, OccupancyGrid
from pfctl.core.mapping.regions import RegionMap, SearchParams
from pfctl.core.mapping.walls import rasterize_house
from pfctl.core.perception.pipeline import Perception
from pfctl.core.prediction.models import SvrState
from pfctl.core.robot import STOP, GroundTruth, Robot, RobotLostError
from pfctl.mission import Mission
from pfctl.mission.map_server import load_map_server
from pfctl.mission.params import core_params, core_values


def control_params(mission: Mission) -> ControlParams:
    """Gaze and base control (``control``, ``robot``, ``sensors.camera``)."""
    return core_params(ControlParams, mission.control, mission.robot, mission.sensors.camera)


def prediction_params(mission: Mission) -> PredictionParams:
    """The predictor of a lost target (``prediction``); its hyperparameters by their names in
    the model (``svr`` and ``weighting``, declared by the default model :class:`SvrState`)."""
    p = mission.prediction
    return core_params(PredictionParams, p, params=core_values(SvrState, p.svr, p.weighting))


def follower_params(mission: Mission) -> FollowerParams:
    """The follower's parameters from the mission."""
    return core_params(
        FollowerParams,
        mission.behavior,
        control=control_params(mission),
        search=core_params(SearchParams, mission.search),
        prediction=prediction_params(mission),
    )


def static_map(mission: Mission) -> OccupancyGrid:
    """The house's walls and furniture as the robot's navigation map."""
    if mission.map.occupancy is not None:
        return load_map_server(mission.map.occupancy)
    return rasterize_house(mission.layout(), mission.map.resolution, mission.map.wall_thickness)


def build_follower(
    mission: Mission,
    robot: Robot,
    perception: Perception,
    log: EpisodeLog | None = None,
    true_target: Callable[[], tuple[float, float] | None] | None = None,
) -> Follower:
    """The mission's follower on ``robot`` with ``perception``; ``true_target`` (privileged,
    the simulator's, :mod:`pfctl.app.oracle`) only for a tree with the oracle baseline."""
    grid = static_map(mission)
    regions = RegionMap(mission.layout())
    # cached per geometry: made here, not in the tick of the first prediction or Algorithm 1
    # (both block the region map's walls on this map's grid)
    regions.blocked_mask(grid.geometry)
    return Follower(
        robot,
        perception,
        mission.behavior.tree.model_dump(exclude_none=True),
        follower_params(mission),
        static_map=grid,
        regions=regions,
        sensor_model=core_params(InverseSensorModel, mission.map.sensor_model),
        robot_radius=mission.robot.radius,
        leaf_defaults={"oracle_search": {"range": mission.sensors.camera.range_max}},
        log=log,
        true_target=true_target,
    )


@dataclass
class EpisodeResult:
    """How a run ended."""

    log: EpisodeLog
    sim_time: float = 0.0
    wall_time: float = 0.0
    interrupted: bool = False
    stopped_early: bool = False
    """``until`` ended the run before ``duration``."""
    tick_seconds: list[float] = field(default_factory=list)
    """Wall time of each follower tick (not the robot's step), seconds."""
    clock_origin: float = 0.0
    """The robot's clock at the episode's t = 0 (ROS time on the HSR; 0 in the simulator)."""
    lost: str | None = None
    """Why the run ended early because the robot stopped answering (:class:`RobotLostError`)."""


def run_follower(
    follower: Follower,
    robot: Robot,
    duration: float,
    *,
    now: Callable[[], float],
    truth: Callable[[], GroundTruth] | None = None,
    on_tick: Callable[[float], None] | None = None,
    stop: Callable[[], bool] | None = None,
    until: Callable[[TickRecord], bool] | None = None,
) -> EpisodeResult:
    """Tick ``follower`` and step ``robot`` until ``now()`` reaches ``duration`` (or ``until``
    says so after a tick, or ``stop`` asks to end). ``truth`` (simulator) is recorded beside each
    tick for the metrics. A robot that stops answering (:class:`RobotLostError`) ends the run
    with :attr:`EpisodeResult.lost` set, keeping what was measured. The follower is closed (base
    stopped) at the end."""
    import time

    retain_freed_memory()  # the next tick reuses this tick's pages (no page faults per tick)
    result = EpisodeResult(follower.log)
    start = time.perf_counter()
    try:
        while now() < duration - 1e-9:
            if stop is not None and stop():
                result.interrupted = True
                break
            t0 = time.perf_counter()
            record = follower.tick()
            result.tick_seconds.append(time.perf_counter() - t0)
            if truth is not None:
                follower.log.truths.append(truth())
            if until is not None and until(record):
                result.stopped_early = True
                break
            robot.step()
            if on_tick is not None:
                on_tick(now())
    except KeyboardInterrupt:
        result.interrupted = True
    except RobotLostError as err:
        result.lost = str(err)
    finally:
        follower.close()
        robot.command(STOP)
    result.sim_time = now()
    result.wall_time = time.perf_counter() - start
    return result


__all__ = [
    "EpisodeResult",
    "build_follower",
    "control_params",
    "follower_params",
    "prediction_params",
    "run_follower",
    "static_map",
]
