"""The sections of a mission file and the file itself (:class:`Mission`).

Each section is a small frozen model whose fields are SI values (``map``: :mod:`.map`,
``scenario``: :mod:`.scenario`, ``backend``: :mod:`.backend`, ``behavior.tree``: :mod:`.tree`;
the robot, its sensors, perception, tracking, belief, prediction, search, control and behavior
here). :meth:`Mission.layout` turns the ``map`` section into the
:class:`pfctl.core.mapping.house.HouseLayout` value types.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Literal

import shapely
from pydantic import Field, ValidationInfo, field_validator, model_validator

from pfctl.core.mapping.house import Door, HouseLayout, Obstacle, Region
from pfctl.mission.backend import BackendConfig
from pfctl.mission.errors import field_error, raise_first
from pfctl.mission.map import MapConfig
from pfctl.mission.scenario import ScenarioConfig
from pfctl.mission.tree import TreeNode, paper_tree
from pfctl.mission.types import (
    NO_BOOL,
    TOLERANCE,
    Count,
    Limits,
    MissionModel,
    Name,
    NonNegative,
    Number,
    Positive,
    Probability,
    UnitInterval,
    existing_file,
    fmt_point,
)


class Pose(MissionModel):
    """A pose in the map frame: metres and radians (REP-103)."""

    x: Number
    y: Number
    theta: Number = 0.0


class RobotConfig(MissionModel):
    """The robot's size and limits; the defaults are the Toyota HSR's (§III-A)."""

    radius: Positive = 0.215
    max_linear_speed: Positive = 0.22
    """m/s (omnidirectional base)."""
    max_angular_speed: Positive = 0.8
    """rad/s."""
    head_pan_limits: Limits = (-3.84, 1.75)
    head_tilt_limits: Limits = (-1.57, 0.52)
    head_max_speed: Positive = 1.0
    """rad/s."""
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


class CameraConfig(MissionModel):
    """The RGB-D camera on the head (HSR: Xtion PRO LIVE)."""

    rate_hz: Positive = 10.0
    """Frames per second."""
    width: Annotated[int, Field(ge=16, le=1920), NO_BOOL] = 320
    height: Annotated[int, Field(ge=16, le=1080), NO_BOOL] = 240
    hfov_deg: Annotated[float, Field(gt=0, lt=180), NO_BOOL] = 58.0
    """Horizontal field of view, degrees."""
    mount_height: Positive = 1.05
    """Height of the head's pan/tilt pivot above the floor, metres."""
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


class LegsConfig(MissionModel):
    """Leg detection from the 2-D laser (§II-E; segment features of Arras et al. 2007)."""

    model: Path | None = None
    """A model written by ``pfctl legs train`` (relative to the mission file); default: the
    model shipped with pfctl."""
    probability: Probability = 0.5
    """Random-forest score above which a laser segment is a leg."""
    jump_distance: Positive = 0.13
    """A segment ends where two neighbouring returns are farther apart than this, metres."""
    min_points: Annotated[int, Field(ge=2), NO_BOOL] = 3
    """Segments with fewer returns are not classified."""
    max_range: Positive = 6.0
    """Segments farther from the laser than this are not classified, metres."""
    pair_distance: Positive = 0.45
    """Two legs closer than this form one person candidate, metres. Walking legs are up to
    ~0.4 m apart at shin height; 0.6 paired the legs of two people passing each other (see
    tests/app/test_perception.py)."""
    history_scans: Annotated[int, Field(ge=1, le=100), NO_BOOL] = 10
    """P(leg) of a segment is averaged over this many scans of its track (1: each scan alone).
    On the real bags, 10 raised leave-one-bag-out precision from 0.57 to 0.78 and recall from
    0.51 to 0.54 (``pfctl legs evaluate --history``), and cut the demo replay's track ids from
    114 to 36 (fewer tracks started by clutter)."""

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


class IdentityConfig(MissionModel):
    """Target identification (Algorithm 2): faces, then clothes histograms."""

    face_distance: Positive = 0.6
    """Face-embedding distance below which two faces match."""
    clothes_similarity: UnitInterval = 0.6
    """Histogram intersection S above which clothes match."""
    color_space: Literal["hsv", "rgb", "lab"] = "hsv"
    """Colour space of the clothing histograms."""
    bins: tuple[Count, Count, Count] = (16, 4, 4)
    """Histogram bins per channel of ``color_space``."""
    face_worker: bool = True
    """Search faces (dlib's detector and embedding, ~90 ms per face) in a worker process off the
    control loop, not inline in the tick (``pfctl follow``/``search`` in the simulator)."""
    face_timing: Literal["auto", "deterministic", "realtime"] = "auto"
    """When the worker's results count: ``deterministic`` (a search of the frame at t counts
    from t + ``face_latency_s``, waiting for the worker if needed: reproducible episodes),
    ``realtime`` (whatever has come back, never wait), ``auto``: deterministic in the simulator,
    realtime on a robot."""
    face_latency_s: NonNegative = 0.1
    """Deterministic timing: the latency of a face search, seconds (about one embedding)."""
    face_miss_limit: Count = 3
    """After this many face searches of a track in a row found no face (the back of the head),
    its face is searched only every ``face_miss_backoff_s``."""
    face_miss_backoff_s: NonNegative = 0.5
    """How often a track whose face searches keep missing is searched again, seconds."""


class PerceptionConfig(MissionModel):
    """Leg detection, person detection and target identification (§II-E, Algorithm 2)."""

    legs: LegsConfig = LegsConfig()
    vision: VisionConfig = VisionConfig()
    identity: IdentityConfig = IdentityConfig()


class TrackingConfig(MissionModel):
    """Noise of the constant-velocity Kalman filters and the association gate (§II-E)."""

    process_noise: Positive = 0.5
    """Continuous white-noise acceleration of the constant-velocity model: √(spectral density),
    i.e. the std of the velocity change over one second (m/s per √s), whatever the sensor rate."""
    laser_noise: Positive = 0.05
    """Std of a leg-pair position, m."""
    camera_noise: Positive = 0.15
    """Std of a camera position, m."""
    gate: Positive = 9.21
    """Squared Mahalanobis gate (chi², 2 dof, 99 %)."""
    confirm_hits: Count = 3
    """A tentative track is confirmed after this many associated detections."""
    tentative_timeout_s: Positive = 0.5
    """A tentative track unseen for this long is deleted."""
    max_coast_s: Positive = 1.5
    """A confirmed track unseen for this long while inside a sensor's field of view is deleted."""
    max_coast_unseen_s: Positive = 5.0
    """A confirmed track outside every sensor's field of view coasts this long before deletion."""


class BeliefConfig(MissionModel):
    """The human belief grid of Eq. 4."""

    prior: Probability = 0.05
    p_o_given_h: Annotated[float, Field(gt=0, le=1), NO_BOOL] = 0.9
    """p(person detected | person in the cell)."""
    p_o_given_not_h: Annotated[float, Field(ge=0, lt=1), NO_BOOL] = 0.05
    """p(person detected | no person in the cell)."""
    decay_per_s: NonNegative = 0.0

    @model_validator(mode="after")
    def _informative(self) -> BeliefConfig:
        if self.p_o_given_h <= self.p_o_given_not_h:
            raise field_error(
                ("p_o_given_h",),
                f"expected p_o_given_h > p_o_given_not_h ({self.p_o_given_not_h:g}), "
                f"else a detection is no evidence; got {self.p_o_given_h:g}",
            )
        return self


class SvrParams(MissionModel):
    """Hyper-parameters of the RBF support-vector regressor of ``prediction.model``.

    The defaults suit the default model ``svr`` (the paper's C and ε; γ = 0.01 s⁻² tuned on real
    pedestrian tracks, README "pfctl predict"). The paper used γ = 1 s⁻² with time as the input,
    which is ``svr-time``: set ``gamma: 1.0`` (and ``half_life_s: 1.0``) with that model.
    """

    C: Positive = 1000.0
    epsilon: Positive = 0.01
    """Half-width of the ε-insensitive tube, metres."""
    gamma: Positive = 0.01
    """RBF width parameter, s⁻² (time is in seconds since the last sample)."""


class Weighting(MissionModel):
    """Sample weights of the trajectory fit: recent samples count more (§II-E)."""

    kind: Literal["none", "linear", "exponential"] = "exponential"
    half_life_s: Positive = 0.5
    """Age at which an exponential weight has halved, seconds."""


class PredictionConfig(MissionModel):
    """Trajectory prediction of a lost target (§II-E, §III)."""

    model: Literal["svr", "svr-time", "poly3", "cv"] = "svr"
    history_s: Positive = 3.0
    horizon_s: Positive = 3.0
    svr: SvrParams = SvrParams()
    weighting: Weighting = Weighting()


class SearchConfig(MissionModel):
    """Frontier map (Eq. 2), utility (Eq. 3) and way-point search (Algorithm 1)."""

    alpha: NonNegative = 0.05
    """Utility per unknown cell a frontier borders (Eq. 3)."""
    beta: NonNegative = 1.0
    """Weight of obstacle boundaries in the frontier map (Eq. 2)."""
    frontier_threshold: Positive = 0.1
    """F above which a cell is a frontier cell."""
    heading_window_s: Positive = 3.0
    """T: the pose history Algorithm 1 looks back over, s."""
    min_frontier_cells: Count = 5
    """Smaller frontier clusters are dropped."""
    waypoint_choice: Literal["utility", "nearest"] = "utility"
    """How Algorithm 1 picks the frontier to search: ``utility`` (Eq. 3, the paper) or
    ``nearest`` (the reachable frontier nearest the robot by path length, whatever its size or
    l*: the nearest-frontier baseline, ``missions/baselines/``)."""


class ControlConfig(MissionModel):
    """Gaze and base control while following (§II-E), and what counts as following."""

    following_distance: Annotated[float, Field(ge=0.3), NO_BOOL] = 1.0
    """Keep this far from the target, metres."""
    min_distance: Annotated[float, Field(ge=0.3), NO_BOOL] = 0.7
    """Never drive closer than this to a person (base centre to person centre), metres."""
    turn_threshold: Annotated[float, Field(gt=0, le=3.2), NO_BOOL] = 0.5
    """Above this bearing to the target the base turns in place before going straight, rad."""
    stale_after: Positive = 0.5
    """The base stops when the laser or the pose is older than this, seconds."""
    following_band: Limits = (0.5, 2.5)
    """A tick counts as following when the target is identified and this far away, metres."""

    @model_validator(mode="after")
    def _distances_ordered(self) -> ControlConfig:
        if self.min_distance > self.following_distance:
            raise field_error(
                ("min_distance",),
                f"expected min_distance <= following_distance ({self.following_distance:g}), "
                f"got {self.min_distance:g}",
            )
        return self


class BehaviorConfig(MissionModel):
    """The behavior tree and its tick rate (§II-A); the default tree is the paper's Fig. 2."""

    tick_hz: Positive = 10.0
    tree: TreeNode = Field(default_factory=paper_tree)


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
        """The robot starts inside the house; routes name existing regions or inside points."""
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
