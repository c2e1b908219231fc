"""The sections of a mission file and the file itself (:class:`Mission`).

Each section is a small frozen model whose fields are SI values (``map``: :mod:`.map`,
``scenario``: :mod:`.scenario`, ``backend``: :mod:`.backend`, ``behavior.tree``: :mod:`.tree`;
the robot, its sensors, perception, tracking, belief, prediction, search, control and behavior
here). :meth:`Mission.layout` turns the ``map`` section into the
:class:`pfctl.core.mapping.house.HouseLayout` value types.

A key annotated ``FromCore`` is a core parameter: its type, default, bounds and meaning are
declared once, on the field of the dataclass the section names as ``core``
(:mod:`pfctl.mission.params`); the app builds that dataclass from the section by name.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Annotated, Literal

import shapely
from pydantic import Field, ValidationInfo, field_validator, model_validator

from pfctl.core.behavior.leaves import PRIVILEGED_LEAVES
from pfctl.core.control import ControlParams
from pfctl.core.follower import FollowerParams, PredictionParams
from pfctl.core.mapping.house import Door, HouseLayout, Obstacle, Region
from pfctl.core.mapping.regions import SearchParams
from pfctl.core.metrics import MetricParams
from pfctl.core.perception.belief import BeliefParams
from pfctl.core.perception.clothes import ClothesParams
from pfctl.core.perception.identity.params import IdentityParams
from pfctl.core.perception.legs.detector import LegParams
from pfctl.core.perception.tracking import TrackerParams
from pfctl.core.prediction.models import SvrState
from pfctl.mission.backend import BackendConfig
from pfctl.mission.errors import field_error, raise_first
from pfctl.mission.map import MapConfig, ObstacleSpec
from pfctl.mission.params import CoreSection, FromCore
from pfctl.mission.scenario import ScenarioConfig
from pfctl.mission.tree import TreeNode, paper_tree
from pfctl.mission.types import (
    NO_BOOL,
    TOLERANCE,
    Count,
    MissionModel,
    Name,
    NonNegative,
    Number,
    Positive,
    existing_file,
    fmt_point,
)


class Pose(MissionModel):
    """A pose in the map frame: metres and radians (REP-103)."""

    x: Number
    y: Number
    theta: Number = 0.0


class RobotConfig(
    CoreSection,
    core=ControlParams,
    core_names={
        "radius": "robot_radius",
        "head_pan_limits": "pan_limits",
        "head_tilt_limits": "tilt_limits",
    },
):
    """The robot's size and limits; the defaults are the Toyota HSR's (§III-A)."""

    radius: FromCore
    max_linear_speed: FromCore
    max_angular_speed: FromCore
    head_pan_limits: FromCore
    head_tilt_limits: FromCore
    head_max_speed: FromCore
    start: Pose | None = None
    """Where the robot starts; None: a point inside the first region."""


class LaserConfig(MissionModel):
    """The base laser (HSR: Hokuyo UST-20LX); the simulator renders it, the HSR reports its own."""

    rate_hz: Positive = 40.0
    """Scans per second; also the simulator's physics sub-step."""
    fov_deg: Annotated[float, Field(gt=0, le=360), NO_BOOL] = 270.0
    """Angular field of view, centred on the base's forward axis, degrees."""
    resolution_deg: Annotated[float, Field(gt=0, le=10), NO_BOOL] = 0.25
    """Angle between two beams, degrees (270° at 0.25° gives 1081 beams)."""
    range_min: Positive = 0.05
    range_max: Positive = 20.0
    noise_std: NonNegative = 0.01
    """Std of the Gaussian range noise, metres."""
    mount_x: Number = 0.167
    """Forward offset of the laser from the base centre, metres."""
    mount_height: Positive = 0.19
    """Height of the scan plane above the floor, metres."""

    @model_validator(mode="after")
    def _ranges_ordered(self) -> LaserConfig:
        if self.range_min >= self.range_max:
            raise field_error(
                ("range_max",),
                f"expected range_max > range_min ({self.range_min:g}), got {self.range_max:g}",
            )
        return self


class CameraConfig(CoreSection, core=ControlParams, core_names={"mount_height": "camera_height"}):
    """The RGB-D camera on the head (HSR: Xtion PRO LIVE)."""

    rate_hz: Positive = 10.0
    """Frames per second."""
    width: Annotated[int, Field(ge=16, le=1920), NO_BOOL] = 320
    height: Annotated[int, Field(ge=16, le=1080), NO_BOOL] = 240
    hfov_deg: Annotated[float, Field(gt=0, lt=180), NO_BOOL] = 58.0
    """Horizontal field of view, degrees."""
    mount_height: FromCore
    forward_offset: NonNegative = 0.1
    """Distance of the optical centre ahead of the pivot, metres."""
    range_min: Positive = 0.4
    """Nearest measurable depth, metres (closer: ``inf``)."""
    range_max: Positive = 8.0
    """Farthest measurable depth, metres (farther: ``inf``)."""
    depth_noise: NonNegative = 0.0
    """Depth noise grows with the square of the distance: std = depth_noise · z², metres."""

    @model_validator(mode="after")
    def _ranges_ordered(self) -> CameraConfig:
        if self.range_min >= self.range_max:
            raise field_error(
                ("range_max",),
                f"expected range_max > range_min ({self.range_min:g}), got {self.range_max:g}",
            )
        return self


class PoseNoise(MissionModel):
    """Noise of the robot's own pose estimates (simulator)."""

    localization_xy: NonNegative = 0.0
    """Std of the error of the map-frame position the robot reports, metres; the error wanders
    slowly (a Gauss-Markov process with a 2 s correlation time, like AMCL's)."""
    localization_theta: NonNegative = 0.0
    """Std of the map-frame heading the robot reports, radians."""
    odometry_linear: NonNegative = 0.0
    """Std of the odometry's translation error per metre travelled (it drifts)."""
    odometry_angular: NonNegative = 0.0
    """Std of the odometry's rotation error per radian turned (it drifts)."""


class SensorsConfig(MissionModel):
    """The robot's sensors: rates, fields of view, mounts and noise (the simulator uses them)."""

    laser: LaserConfig = LaserConfig()
    camera: CameraConfig = CameraConfig()
    pose: PoseNoise = PoseNoise()


class LegsConfig(CoreSection, core=LegParams):
    """Leg detection from the 2-D laser (§II-E; segment features of Arras et al. 2007)."""

    model: Path | None = None
    """A model written by ``pfctl legs train`` (relative to the mission file); default: the
    model shipped with pfctl."""
    probability: FromCore
    jump_distance: FromCore
    min_points: FromCore
    max_range: FromCore
    max_width: FromCore
    pair_distance: FromCore
    history_scans: FromCore
    static_after_s: FromCore
    weak_probability: FromCore

    @field_validator("model")
    @classmethod
    def _model_exists(cls, value: Path | None, info: ValidationInfo) -> Path | None:
        """Resolve the model file relative to the mission file and check that it exists."""
        if value is None:
            return None
        return existing_file(value, info, "a leg model file (pfctl legs train)")


class VisionConfig(MissionModel):
    """Person detection on the RGB-D camera (§II-E)."""

    detector: Literal["auto", "mask", "hog"] = "auto"
    """``mask``: the simulator's segmentation (stands in for OpenPose); ``hog``: OpenCV's HOG
    people detector for real cameras; ``auto``: ``mask`` when the frame has one, else ``hog``."""
    min_pixels: Count = 150
    """Fewer body pixels than this is no detection."""


class IdentityConfig(CoreSection, core=(IdentityParams, ClothesParams)):
    """Target identification (Algorithm 2): faces, then clothes histograms."""

    face_distance: FromCore
    clothes_similarity: FromCore
    color_space: FromCore
    bins: FromCore
    face_worker: bool = True
    """Search faces (dlib's detector and embedding) in a worker process off the control loop,
    not inline in the tick (``pfctl follow``/``search`` in the simulator)."""
    face_timing: FromCore
    face_latency_s: FromCore
    min_face_px: FromCore
    face_miss_limit: FromCore
    face_miss_backoff_s: FromCore
    face_to_rename: FromCore


class PerceptionConfig(MissionModel):
    """Leg detection, person detection and target identification (§II-E, Algorithm 2)."""

    legs: LegsConfig = LegsConfig()
    vision: VisionConfig = VisionConfig()
    identity: IdentityConfig = IdentityConfig()


class TrackingConfig(CoreSection, core=TrackerParams):
    """Noise of the constant-velocity Kalman filters and the association gate (§II-E)."""

    process_noise: FromCore
    laser_noise: FromCore
    camera_noise: FromCore
    gate: FromCore
    confirm_hits: FromCore
    confirm_s: FromCore
    tentative_timeout_s: FromCore
    max_coast_s: FromCore
    max_coast_unseen_s: FromCore
    new_id_beyond: FromCore


class BeliefConfig(CoreSection, core=BeliefParams):
    """The human belief grid of Eq. 4."""

    prior: FromCore
    p_o_given_h: FromCore
    p_o_given_not_h: FromCore
    decay_per_s: FromCore

    @model_validator(mode="after")
    def _informative(self) -> BeliefConfig:
        if self.p_o_given_h <= self.p_o_given_not_h:
            raise field_error(
                ("p_o_given_h",),
                f"expected p_o_given_h > p_o_given_not_h ({self.p_o_given_not_h:g}), "
                f"else a detection is no evidence; got {self.p_o_given_h:g}",
            )
        return self


class SvrParams(CoreSection, core=SvrState):
    """Hyper-parameters of the RBF support-vector regressor of ``prediction.model``.

    The defaults suit the default model ``svr`` (the paper's C and ε; γ = 0.01 s⁻² tuned on real
    pedestrian tracks, README "pfctl predict"). The paper used γ = 1 s⁻² with time as the input,
    which is ``svr-time``: set ``gamma: 1.0`` (and ``half_life_s: 1.0``) with that model.
    """

    C: FromCore
    epsilon: FromCore
    gamma: FromCore


class Weighting(CoreSection, core=SvrState, core_names={"kind": "weighting"}):
    """Sample weights of the trajectory fit: recent samples count more (§II-E)."""

    kind: FromCore
    half_life_s: FromCore


class PredictionConfig(CoreSection, core=PredictionParams):
    """Trajectory prediction of a lost target (§II-E, §III)."""

    model: FromCore
    history_s: FromCore
    horizon_s: FromCore
    svr: SvrParams = SvrParams()
    weighting: Weighting = Weighting()


class SearchConfig(CoreSection, core=SearchParams):
    """Frontier map (Eq. 2), utility (Eq. 3) and way-point search (Algorithm 1)."""

    alpha: FromCore
    beta: FromCore
    frontier_threshold: FromCore
    heading_window_s: FromCore
    min_frontier_cells: FromCore
    waypoint_choice: FromCore
    strategy: FromCore
    never_seen_strategy: FromCore
    prediction_goal: FromCore
    gaze: FromCore
    look_s: FromCore


class ControlConfig(
    CoreSection, core=(ControlParams, MetricParams), core_names={"following_band": "band"}
):
    """Gaze and base control while following (§II-E), and what counts as following."""

    following_distance: FromCore
    min_distance: FromCore
    turn_threshold: FromCore
    stale_after: FromCore
    following_band: FromCore

    @model_validator(mode="after")
    def _distances_ordered(self) -> ControlConfig:
        if self.min_distance > self.following_distance:
            raise field_error(
                ("min_distance",),
                f"expected min_distance <= following_distance ({self.following_distance:g}), "
                f"got {self.min_distance:g}",
            )
        return self


class BehaviorConfig(CoreSection, core=FollowerParams):
    """The behavior tree and its tick rate (§II-A); the default tree is the paper's Fig. 2."""

    tick_hz: FromCore
    tree: TreeNode = Field(default_factory=paper_tree)


def _furniture_at(obstacles: Sequence[ObstacleSpec], shape: shapely.Geometry) -> str | None:
    """``obstacle 'name'`` (or ``map.obstacles[i]``) of the first obstacle whose inside
    ``shape`` reaches (more than touching), or None."""
    for i, obstacle in enumerate(obstacles):
        polygon = shapely.Polygon(obstacle.polygon)
        if polygon.intersection(shape).area > TOLERANCE**2 or polygon.contains(shape):
            return f"obstacle {obstacle.name!r}" if obstacle.name else f"map.obstacles[{i}]"
    return None


class Mission(MissionModel):
    """A whole mission file. Only ``name`` and ``map.regions`` are required."""

    name: Name
    description: str | None = None
    map: MapConfig
    robot: RobotConfig = RobotConfig()
    sensors: SensorsConfig = SensorsConfig()
    perception: PerceptionConfig = PerceptionConfig()
    tracking: TrackingConfig = TrackingConfig()
    belief: BeliefConfig = BeliefConfig()
    prediction: PredictionConfig = PredictionConfig()
    search: SearchConfig = SearchConfig()
    control: ControlConfig = ControlConfig()
    behavior: BehaviorConfig = BehaviorConfig()
    scenario: ScenarioConfig = ScenarioConfig()
    backend: BackendConfig = BackendConfig()

    @model_validator(mode="after")
    def _places_exist(self) -> Mission:
        """The robot starts inside the house, clear of the furniture; routes name existing
        regions or points inside the house and outside the furniture."""
        issues: list[tuple[tuple[str | int, ...], str]] = []
        regions = [r.name for r in self.map.regions]
        house = shapely.union_all([shapely.Polygon(r.polygon) for r in self.map.regions])
        inside = house.buffer(TOLERANCE)
        start = self.robot.start
        if start is not None and not inside.covers(shapely.Point(start.x, start.y)):
            issues.append(
                (
                    ("robot", "start"),
                    f"expected a start inside the regions, got ({start.x:g}, {start.y:g})",
                )
            )
        elif start is not None:
            body = shapely.Point(start.x, start.y).buffer(self.robot.radius)
            hit = _furniture_at(self.map.obstacles, body)
            if hit is not None:
                issues.append(
                    (
                        ("robot", "start"),
                        f"expected a start clear of the furniture, got ({start.x:g}, "
                        f"{start.y:g}): the robot (radius {self.robot.radius:g} m) overlaps "
                        f"{hit}",
                    )
                )
        for i, person in enumerate(self.scenario.people):
            for j, stop in enumerate(person.route):
                loc = ("scenario", "people", i, "route", j)
                if isinstance(stop, str):
                    if stop not in regions:
                        issues.append(
                            (loc, f"unknown region {stop!r} (regions: {', '.join(regions)})")
                        )
                elif not inside.covers(shapely.Point(stop)):
                    issues.append(
                        (loc, f"expected a point inside the regions, got {fmt_point(stop)}")
                    )
                elif (hit := _furniture_at(self.map.obstacles, shapely.Point(stop))) is not None:
                    issues.append(
                        (loc, f"expected a point outside the furniture, got {fmt_point(stop)} "
                         f"inside {hit}")
                    )  # fmt: skip
        for i, region in enumerate(self.scenario.randomize.hide_in):
            if region not in regions:
                issues.append(
                    (
                        ("scenario", "randomize", "hide_in", i),
                        f"unknown region {region!r} (regions: {', '.join(regions)})",
                    )
                )
        raise_first(issues)
        return self

    @model_validator(mode="after")
    def _privileged_in_sim_only(self) -> Mission:
        """A mission set up for the real robot (``backend.hsr`` given) names no privileged leaf
        (the oracle baseline's ``oracle_search`` reads the simulator's ground truth)."""
        privileged = sorted(self.behavior.tree.leaf_names() & set(PRIVILEGED_LEAVES))
        if privileged and "hsr" in self.backend.model_fields_set:
            raise_first(
                [
                    (
                        ("behavior", "tree"),
                        f"{privileged[0]} reads the simulator's ground truth (privileged): "
                        "expected no such leaf in a mission for the real robot (backend.hsr)",
                    )
                ]
            )
        return self

    def layout(self) -> HouseLayout:
        """The ``map`` section as plain values (:class:`pfctl.core.mapping.house.HouseLayout`)."""
        return HouseLayout(
            regions=tuple(
                Region(name=r.name, polygon=tuple((float(x), float(y)) for x, y in r.polygon))
                for r in self.map.regions
            ),
            doors=tuple(
                Door(
                    between=(d.between[0], d.between[1]),
                    segment=(
                        (float(d.segment[0][0]), float(d.segment[0][1])),
                        (float(d.segment[1][0]), float(d.segment[1][1])),
                    ),
                )
                for d in self.map.doors
            ),
            obstacles=tuple(
                Obstacle(
                    polygon=tuple((float(x), float(y)) for x, y in o.polygon),
                    height=float(o.height),
                    name=o.name,
                )
                for o in self.map.obstacles
            ),
        )

    def start_pose(self) -> tuple[float, float, float]:
        """``robot.start`` as ``(x, y, theta)``, or a point inside the first region if unset."""
        start = self.robot.start
        if start is not None:
            return (start.x, start.y, start.theta)
        point = shapely.Polygon(self.map.regions[0].polygon).representative_point()
        return (float(point.x), float(point.y), 0.0)
