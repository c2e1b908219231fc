"""The mission YAML: pydantic models of every section, and ``load_mission()`` with one-line errors.

This module is the only place that knows the mission file format (DESIGN.md). Everything below
it receives plain typed objects: :meth:`Mission.layout` turns the ``map`` section into the
:class:`pfctl.core.mapping.house.HouseLayout` value types, and the other sections are small frozen
models whose fields are SI values.

A mission is checked in three layers, and every failure becomes a :class:`pfctl.errors.MissionError`
whose message is one line, ``<file>:<line>: <key.path[2].sub>: <what was expected>``:

1. reading: missing file, a directory, not UTF-8, empty, YAML syntax, duplicate keys; the
   mission it ``extends`` (read first, this file merged over it: :func:`merge_mission_data`)
   and a tree file it includes (``behavior.tree: {include: PATH}``), missing or in a cycle;
2. shape: unknown keys, wrong types, ranges (pydantic, ``extra="forbid"`` everywhere);
3. meaning: polygons are simple with >= 3 distinct points, regions do not overlap, doors lie on
   the wall two existing regions share, the scenario's target and routes name existing things.

The line is found by composing the YAML node graph and walking it along the error's key path to
the deepest node that exists. A mission merged with the one it extends has one node graph merged
the same way, each node marked with the file it came from, so the error names that file.

Example::

    mission = load_mission("missions/house.yaml")
    layout = mission.layout()          # HouseLayout: regions, doors, obstacles
    mission.behavior.tree.size()       # number of behavior-tree nodes
"""

from __future__ import annotations

import functools
import math
import os
import re
from collections.abc import Iterator, Mapping, Sequence
from pathlib import Path
from typing import Annotated, Any, Literal, Union, get_args, get_origin

import shapely
import yaml
from pydantic import (
    AfterValidator,
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Discriminator,
    Field,
    Tag,
    ValidationError,
    ValidationInfo,
    field_validator,
    model_validator,
)
from pydantic_core import PydanticCustomError
from shapely.validation import explain_validity

from pfctl.core.behavior.registry import leaf_spec
from pfctl.core.mapping.house import Door, HouseLayout, Obstacle, Region
from pfctl.errors import MissionError

__all__ = [
    "BackendConfig",
    "BehaviorConfig",
    "BeliefConfig",
    "CameraConfig",
    "Clothes",
    "Composite",
    "ControlConfig",
    "Decorator",
    "DoorSpec",
    "HsrConfig",
    "LaserConfig",
    "MapConfig",
    "Mission",
    "ObstacleSpec",
    "Parallel",
    "PerceptionConfig",
    "Person",
    "Pose",
    "PoseNoise",
    "PredictionConfig",
    "RegionSpec",
    "Repeat",
    "Retry",
    "RobotConfig",
    "ScenarioConfig",
    "ScenarioRandomization",
    "SearchConfig",
    "SensorModel",
    "SensorsConfig",
    "SvrParams",
    "Timeout",
    "TrackingConfig",
    "TreeNode",
    "Weighting",
    "dump_json_schema",
    "load_mission",
    "loads_mission",
    "merge_mission_data",
]

#: Geometric tolerance of the semantic checks, metres (and m² for areas).
TOLERANCE = 1e-6

# --------------------------------------------------------------------------------------------
# Scalar types
# --------------------------------------------------------------------------------------------


def _error(kind: str, message: str) -> PydanticCustomError:
    """A validation error whose message is ``message`` verbatim (no template expansion)."""
    return PydanticCustomError(kind, "{detail}", {"detail": message})


def _reject_bool(value: Any) -> Any:
    """YAML's ``yes``/``true`` must not silently become 1: numbers reject booleans."""
    if isinstance(value, bool):
        raise _error("bool_not_number", f"expected a number, got the boolean {str(value).lower()}")
    return value


def _snake_case(value: str) -> str:
    """Behavior-tree leaf names are snake_case identifiers (``target_visible``)."""
    if not re.fullmatch(r"[a-z][a-z0-9_]*", value):
        raise _error(
            "snake_case", f"expected a snake_case name such as 'target_visible', got {value!r}"
        )
    return value


_NO_BOOL = BeforeValidator(_reject_bool)
# Constraints come before the validator so that pydantic folds them into the number schema
# (and the JSON Schema says exclusiveMinimum, not an unknown "gt").
Number = Annotated[float, Field(allow_inf_nan=False), _NO_BOOL]
"""A finite float; booleans are rejected."""
Positive = Annotated[float, Field(gt=0, allow_inf_nan=False), _NO_BOOL]
NonNegative = Annotated[float, Field(ge=0, allow_inf_nan=False), _NO_BOOL]
Probability = Annotated[float, Field(gt=0, lt=1), _NO_BOOL]
"""A probability in the open interval (0, 1)."""
UnitInterval = Annotated[float, Field(ge=0, le=1), _NO_BOOL]
Integer = Annotated[int, _NO_BOOL]
Count = Annotated[int, Field(ge=1), _NO_BOOL]
Name = Annotated[str, Field(min_length=1)]
Identifier = Annotated[
    str, AfterValidator(_snake_case), Field(json_schema_extra={"pattern": "^[a-z][a-z0-9_]*$"})
]
Point = tuple[Number, Number]
"""An ``[x, y]`` point in the map frame, metres."""
Channel = Annotated[int, Field(ge=0, le=255), _NO_BOOL]
RGB = tuple[Channel, Channel, Channel]


def _fmt_point(p: Sequence[float]) -> str:
    return f"({p[0]:g}, {p[1]:g})"


def _check_polygon(points: tuple[Point, ...]) -> tuple[Point, ...]:
    """A simple polygon of >= 3 distinct points; a repeated closing point is dropped."""
    pts = list(points)
    if len(pts) >= 2 and pts[0] == pts[-1]:
        pts.pop()
    distinct = len(set(pts))
    if distinct < 3:
        raise _error(
            "polygon_points",
            f"expected a polygon of at least 3 distinct [x, y] points, got {distinct}",
        )
    if shapely.LineString(pts).convex_hull.area <= TOLERANCE**2:
        raise _error(
            "polygon_area", "expected a polygon with an area, but its points are collinear"
        )
    polygon = shapely.Polygon(pts)
    if not polygon.is_valid:
        reason = explain_validity(polygon)
        match = re.fullmatch(r"(.*?)\[\s*(\S+)\s+(\S+)\s*\]", reason)
        if match:
            where = _fmt_point((float(match.group(2)), float(match.group(3))))
            reason = f"{match.group(1).lower()} at {where}"
        raise _error(
            "polygon_invalid", f"expected a simple polygon (edges that do not cross), got {reason}"
        )
    return tuple(pts)


Polygon = Annotated[tuple[Point, ...], AfterValidator(_check_polygon)]
"""A simple polygon: >= 3 distinct points, not self-intersecting; closing point optional."""


def _fail(loc: tuple[str | int, ...], message: str, more: int = 0) -> PydanticCustomError:
    """A semantic error at ``loc`` *relative to* the model that raises it.

    Pydantic gives model validators no way to point deeper than the model, so the relative key
    path travels in the error's context and :func:`_format_error` appends it. ``more`` counts
    further semantic errors found in the same pass.
    """
    return PydanticCustomError("mission", "{detail}", {"detail": message, "loc": loc, "more": more})


def _raise_first(issues: list[tuple[tuple[str | int, ...], str]]) -> None:
    """Raise the first of ``issues`` (relative key path, message), counting the rest."""
    if issues:
        loc, message = issues[0]
        raise _fail(loc, message, more=len(issues) - 1)


class _Model(BaseModel):
    """Base of every mission model: unknown keys are errors, values are immutable."""

    model_config = ConfigDict(extra="forbid", frozen=True, use_attribute_docstrings=True)


# --------------------------------------------------------------------------------------------
# map
# --------------------------------------------------------------------------------------------


class SensorModel(_Model):
    """Inverse sensor model of Eq. 1: p(occupied | what the beam did), and the clamping bounds."""

    p_hit: Annotated[float, Field(gt=0.5, lt=1), _NO_BOOL] = 0.7
    """p(occupied | the beam ended in the cell)."""
    p_miss: Annotated[float, Field(gt=0, lt=0.5), _NO_BOOL] = 0.4
    """p(occupied | the beam passed through the cell)."""
    p_min: Probability = 0.02
    """Lower clamp of p(m), so the map can still change its mind."""
    p_max: Probability = 0.98
    """Upper clamp of p(m); greater than p_min."""

    @model_validator(mode="after")
    def _bounds_ordered(self) -> SensorModel:
        if self.p_min >= self.p_max:
            raise _fail(("p_max",), f"expected p_max > p_min ({self.p_min:g}), got {self.p_max:g}")
        return self


def _existing_file(value: Path, info: ValidationInfo, what: str) -> Path:
    """``value`` resolved against the mission file's folder; an error when it is no file."""
    context = info.context if isinstance(info.context, Mapping) else {}
    base = Path(context.get("base_dir", "."))
    path = value if value.is_absolute() else base / value
    if not path.is_file():
        raise _error("file_missing", f"expected {what}, but {path} does not exist")
    return path.resolve()


class RegionSpec(_Model):
    """A named polygon of the region map (§II-B)."""

    name: Name
    polygon: Polygon


class DoorSpec(_Model):
    """An opening in the wall two regions share: ``segment`` lies on their common boundary."""

    between: tuple[Name, Name]
    """The names of the two regions the door joins."""
    segment: tuple[Point, Point]
    """The opening: two [x, y] end points on the shared wall."""


class ObstacleSpec(_Model):
    """A static obstacle (furniture): a polygon and its height for the simulator, metres."""

    name: str = ""
    polygon: Polygon
    height: Positive = 0.8


class MapConfig(_Model):
    """The static house: grid resolution, walls, the sensor model, regions, doors, obstacles."""

    resolution: Positive = 0.05
    """Metres per cell of every grid (occupancy, belief)."""
    occupancy: Path | None = None
    """Optional ROS map_server YAML, relative to the mission file; else walls come from polygons."""
    wall_thickness: Positive = 0.1
    """Metres."""
    wall_height: Positive = 2.2
    """Metres, for the simulator."""
    sensor_model: SensorModel = SensorModel()
    regions: Annotated[tuple[RegionSpec, ...], Field(min_length=1)]
    """Rooms as polygons; they may share edges but not area."""
    doors: tuple[DoorSpec, ...] = ()
    """Openings, each on the wall shared by two regions."""
    obstacles: tuple[ObstacleSpec, ...] = ()
    """Furniture."""

    @field_validator("occupancy")
    @classmethod
    def _occupancy_exists(cls, value: Path | None, info: ValidationInfo) -> Path | None:
        """Resolve the map_server YAML relative to the mission file and check that it exists."""
        if value is None:
            return None
        return _existing_file(value, info, "an existing map_server YAML file")

    @model_validator(mode="after")
    def _geometry(self) -> MapConfig:
        """Unique region names, no overlapping regions, doors on the walls of existing regions."""
        issues: list[tuple[tuple[str | int, ...], str]] = []
        polygons: dict[str, shapely.Polygon] = {}
        first_index: dict[str, int] = {}
        for i, region in enumerate(self.regions):
            if region.name in first_index:
                issues.append(
                    (
                        ("regions", i, "name"),
                        f"duplicate region name {region.name!r} "
                        f"(already used by regions[{first_index[region.name]}])",
                    )
                )
                continue
            first_index[region.name] = i
            polygon = shapely.Polygon(region.polygon)
            for other, other_polygon in polygons.items():
                common = polygon.intersection(other_polygon).area
                if common > TOLERANCE:
                    issues.append(
                        (
                            ("regions", i, "polygon"),
                            f"region {region.name!r} overlaps region {other!r} by {common:.3g} m²;"
                            " regions may share edges but not area",
                        )
                    )
            polygons[region.name] = polygon
        known = ", ".join(polygons)
        for i, door in enumerate(self.doors):
            a, b = door.between
            unknown = [n for n in (a, b) if n not in polygons]
            if unknown:
                issues.append(
                    (("doors", i, "between"), f"unknown region {unknown[0]!r} (regions: {known})")
                )
                continue
            if a == b:
                issues.append(
                    (
                        ("doors", i, "between"),
                        f"expected two different regions, got {a!r} twice",
                    )
                )
                continue
            issue = _door_issue(door, polygons[a], polygons[b])
            if issue:
                issues.append((("doors", i, "segment"), issue))
        _raise_first(issues)
        return self


def _lines_of(geometry: shapely.Geometry) -> list[shapely.LineString]:
    """The line pieces of ``geometry`` (an intersection may mix points and lines), merged."""
    parts = getattr(geometry, "geoms", [geometry])
    lines = [g for g in parts if g.geom_type in ("LineString", "LinearRing") and not g.is_empty]
    if not lines:
        return []
    merged = shapely.line_merge(shapely.MultiLineString(lines))
    return [g for g in getattr(merged, "geoms", [merged]) if g.length > TOLERANCE]


def _door_issue(door: DoorSpec, a: shapely.Polygon, b: shapely.Polygon) -> str | None:
    """Why ``door`` is not an opening in the wall ``a`` and ``b`` share, or None if it is.

    The shared wall is the part of ``a``'s boundary within :data:`TOLERANCE` of ``b``'s, so
    edges that meet up to rounding still count; the door must lie on it within the tolerance.
    """
    p, q = door.segment
    if math.dist(p, q) <= TOLERANCE:
        return f"expected a door segment of positive length, got {_fmt_point(p)} twice"
    walls = _lines_of(a.boundary.intersection(b.boundary.buffer(TOLERANCE)))
    name_a, name_b = door.between
    if sum(w.length for w in walls) <= 10 * TOLERANCE:
        return f"regions {name_a!r} and {name_b!r} share no wall, so no door can join them"
    segment = shapely.LineString([p, q])
    if shapely.MultiLineString(walls).buffer(2 * TOLERANCE).covers(segment):
        return None
    described = "; ".join(
        f"{_fmt_point(w.coords[0])} to {_fmt_point(w.coords[-1])}"
        for w in walls
        if w.length > 10 * TOLERANCE
    )
    return (
        f"expected the segment {_fmt_point(p)} to {_fmt_point(q)} to lie on the wall shared by "
        f"{name_a!r} and {name_b!r}: {described}"
    )


# --------------------------------------------------------------------------------------------
# robot, perception, tracking, belief, prediction, search
# --------------------------------------------------------------------------------------------


class Pose(_Model):
    """A pose in the map frame: metres and radians (REP-103)."""

    x: Number
    y: Number
    theta: Number = 0.0


def _check_limits(value: tuple[float, float]) -> tuple[float, float]:
    """A ``[low, high]`` pair must have ``low < high``."""
    if value[0] >= value[1]:
        raise _error(
            "limits_order",
            f"expected [low, high] with low < high, got [{value[0]:g}, {value[1]:g}]",
        )
    return value


Limits = Annotated[tuple[Number, Number], AfterValidator(_check_limits)]
"""A ``[low, high]`` joint-limit pair in radians, ``low < high``."""


class RobotConfig(_Model):
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


class LaserConfig(_Model):
    """The base laser (HSR: Hokuyo UST-20LX); the simulator renders it, the HSR reports its own."""

    rate_hz: Positive = 40.0
    """Scans per second; also the simulator's physics sub-step."""
    fov_deg: Annotated[float, Field(gt=0, le=360), _NO_BOOL] = 270.0
    """Angular field of view, centred on the base's forward axis, degrees."""
    resolution_deg: Annotated[float, Field(gt=0, le=10), _NO_BOOL] = 0.25
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
            raise _fail(
                ("range_max",),
                f"expected range_max > range_min ({self.range_min:g}), got {self.range_max:g}",
            )
        return self


class CameraConfig(_Model):
    """The RGB-D camera on the head (HSR: Xtion PRO LIVE)."""

    rate_hz: Positive = 10.0
    """Frames per second."""
    width: Annotated[int, Field(ge=16, le=1920), _NO_BOOL] = 320
    height: Annotated[int, Field(ge=16, le=1080), _NO_BOOL] = 240
    hfov_deg: Annotated[float, Field(gt=0, lt=180), _NO_BOOL] = 58.0
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
            raise _fail(
                ("range_max",),
                f"expected range_max > range_min ({self.range_min:g}), got {self.range_max:g}",
            )
        return self


class PoseNoise(_Model):
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


class SensorsConfig(_Model):
    """The robot's sensors: rates, fields of view, mounts and noise (the simulator uses them)."""

    laser: LaserConfig = LaserConfig()
    camera: CameraConfig = CameraConfig()
    pose: PoseNoise = PoseNoise()


class LegsConfig(_Model):
    """Leg detection from the 2-D laser (§II-E; segment features of Arras et al. 2007)."""

    model: Path | None = None
    """A model written by ``pfctl legs train`` (relative to the mission file); default: the
    model shipped with pfctl."""
    probability: Probability = 0.5
    """Random-forest score above which a laser segment is a leg."""
    jump_distance: Positive = 0.13
    """A segment ends where two neighbouring returns are farther apart than this, metres."""
    min_points: Annotated[int, Field(ge=2), _NO_BOOL] = 3
    """Segments with fewer returns are not classified."""
    max_range: Positive = 6.0
    """Segments farther from the laser than this are not classified, metres."""
    pair_distance: Positive = 0.45
    """Two legs closer than this form one person candidate, metres. Walking legs are up to
    ~0.4 m apart at shin height; 0.6 paired the legs of two people passing each other (see
    tests/app/test_perception.py)."""
    history_scans: Annotated[int, Field(ge=1, le=100), _NO_BOOL] = 10
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
        return _existing_file(value, info, "a leg model file (pfctl legs train)")


class VisionConfig(_Model):
    """Person detection on the RGB-D camera (§II-E)."""

    detector: Literal["auto", "mask", "hog"] = "auto"
    """``mask``: the simulator's segmentation (stands in for OpenPose); ``hog``: OpenCV's HOG
    people detector for real cameras; ``auto``: ``mask`` when the frame has one, else ``hog``."""
    min_pixels: Count = 150
    """Fewer body pixels than this is no detection."""


class IdentityConfig(_Model):
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


class PerceptionConfig(_Model):
    """Leg detection, person detection and target identification (§II-E, Algorithm 2)."""

    legs: LegsConfig = LegsConfig()
    vision: VisionConfig = VisionConfig()
    identity: IdentityConfig = IdentityConfig()


class TrackingConfig(_Model):
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


class BeliefConfig(_Model):
    """The human belief grid of Eq. 4."""

    prior: Probability = 0.05
    p_o_given_h: Annotated[float, Field(gt=0, le=1), _NO_BOOL] = 0.9
    """p(person detected | person in the cell)."""
    p_o_given_not_h: Annotated[float, Field(ge=0, lt=1), _NO_BOOL] = 0.05
    """p(person detected | no person in the cell)."""
    decay_per_s: NonNegative = 0.0

    @model_validator(mode="after")
    def _informative(self) -> BeliefConfig:
        if self.p_o_given_h <= self.p_o_given_not_h:
            raise _fail(
                ("p_o_given_h",),
                f"expected p_o_given_h > p_o_given_not_h ({self.p_o_given_not_h:g}), "
                f"else a detection is no evidence; got {self.p_o_given_h:g}",
            )
        return self


class SvrParams(_Model):
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


class Weighting(_Model):
    """Sample weights of the trajectory fit: recent samples count more (§II-E)."""

    kind: Literal["none", "linear", "exponential"] = "exponential"
    half_life_s: Positive = 0.5
    """Age at which an exponential weight has halved, seconds."""


class PredictionConfig(_Model):
    """Trajectory prediction of a lost target (§II-E, §III)."""

    model: Literal["svr", "svr-time", "poly3", "cv"] = "svr"
    history_s: Positive = 3.0
    horizon_s: Positive = 3.0
    svr: SvrParams = SvrParams()
    weighting: Weighting = Weighting()


class SearchConfig(_Model):
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


# --------------------------------------------------------------------------------------------
# behavior tree
# --------------------------------------------------------------------------------------------

COMPOSITES = ("sequence", "fallback", "parallel")
DECORATORS = ("inverter", "retry", "timeout", "repeat", "force_success", "force_failure")
LEAVES = ("condition", "action")
NODE_KINDS = COMPOSITES + DECORATORS + LEAVES


class Composite(_Model):
    """A sequence or fallback: an optional name and a non-empty list of children."""

    name: str | None = None
    children: Annotated[tuple[TreeNode, ...], Field(min_length=1)]
    memory: bool = False
    """False (reactive): every tick starts again at the first child, so a condition is checked
    again while a later action runs; True: a tick resumes at the child that was running."""


class Parallel(Composite):
    """Ticks every child each tick; succeeds when all (or one) succeed."""

    policy: Literal["success_on_all", "success_on_one"] = "success_on_all"


class Decorator(_Model):
    """A decorator (inverter, force_success, force_failure): one child."""

    name: str | None = None
    child: TreeNode


class Retry(Decorator):
    """Re-run the child after a failure, up to ``attempts`` times in all."""

    attempts: Count


class Timeout(Decorator):
    """Fail the child if it is still running after ``seconds``."""

    seconds: Positive


class Repeat(Decorator):
    """Run the child ``count`` times while it succeeds."""

    count: Count


class TreeNode(_Model):
    """One behavior-tree node (Fig. 2): exactly one of the keys below, plus ``params`` on leaves.

    Composites ``sequence`` / ``fallback`` / ``parallel`` hold ``{name?, children: [...]}``;
    decorators ``inverter`` / ``retry`` / ``timeout`` / ``repeat`` / ``force_success`` /
    ``force_failure`` hold ``{name?, child, ...}``; leaves are ``{condition: NAME, params?}`` or
    ``{action: NAME, params?}`` with NAME a snake_case identifier.
    """

    sequence: Composite | None = None
    fallback: Composite | None = None
    parallel: Parallel | None = None
    inverter: Decorator | None = None
    retry: Retry | None = None
    timeout: Timeout | None = None
    repeat: Repeat | None = None
    force_success: Decorator | None = None
    force_failure: Decorator | None = None
    condition: Identifier | None = None
    action: Identifier | None = None
    params: dict[str, Any] = Field(default_factory=dict)

    @model_validator(mode="before")
    @classmethod
    def _exactly_one_kind(cls, data: Any) -> Any:
        """A node is a mapping with exactly one kind key; ``params`` only on leaves."""
        kinds_text = ", ".join(NODE_KINDS)
        if not isinstance(data, Mapping):
            got = repr(data) if isinstance(data, (str, int, float)) else type(data).__name__
            raise _error(
                "tree_node", f"expected a tree node, a mapping with one of {kinds_text}, got {got}"
            )
        if any(key not in NODE_KINDS and key != "params" for key in data):
            return data  # pydantic reports the unknown key, with the allowed ones
        kinds = [key for key in data if key in NODE_KINDS]
        if len(kinds) != 1:
            got = " and ".join(repr(k) for k in kinds) if kinds else "none"
            raise _error(
                "tree_node", f"expected exactly one of {kinds_text} in a tree node, got {got}"
            )
        if "params" in data and kinds[0] not in LEAVES:
            raise _fail(("params",), f"params belong to a condition or action leaf, not {kinds[0]}")
        return data

    @model_validator(mode="after")
    def _known_leaf(self) -> TreeNode:
        """A leaf names a registered condition or action, with valid parameters."""
        if self.condition is None and self.action is None:
            return self
        kind = "condition" if self.condition is not None else "action"
        try:
            spec = leaf_spec(kind, str(self.body))
        except ValueError as err:
            raise _fail((kind,), str(err)) from None
        try:
            spec.resolve(self.params)
        except ValueError as err:
            key, _, reason = str(err).partition(": ")
            raise _fail(("params", key), reason) from None
        return self

    @property
    def kind(self) -> str:
        """Which node this is: one of :data:`NODE_KINDS`."""
        for kind in NODE_KINDS:
            if getattr(self, kind) is not None:
                return kind
        raise AssertionError("a validated TreeNode always has a kind")  # pragma: no cover

    @property
    def body(self) -> Composite | Decorator | str:
        """The value under the kind key: the composite/decorator model, or the leaf's name."""
        return getattr(self, self.kind)  # type: ignore[no-any-return]

    @property
    def is_leaf(self) -> bool:
        """True for condition and action leaves."""
        return self.kind in LEAVES

    @property
    def label(self) -> str:
        """A short human name: the leaf's name, else the node's ``name``, else its kind."""
        body = self.body
        if isinstance(body, str):
            return body
        return body.name or self.kind

    @property
    def children(self) -> tuple[TreeNode, ...]:
        """The child nodes: a composite's children, a decorator's child, none for a leaf."""
        body = self.body
        if isinstance(body, Composite):
            return body.children
        if isinstance(body, Decorator):
            return (body.child,)
        return ()

    def walk(self) -> Iterator[TreeNode]:
        """This node and all below it, depth first, in order."""
        yield self
        for child in self.children:
            yield from child.walk()

    def size(self) -> int:
        """The number of nodes in this subtree, this one included."""
        return sum(1 for _ in self.walk())


Composite.model_rebuild()
Parallel.model_rebuild()
Decorator.model_rebuild()
Retry.model_rebuild()
Timeout.model_rebuild()
Repeat.model_rebuild()
TreeNode.model_rebuild()


def _paper_tree() -> TreeNode:
    """Fig. 2 of the paper: follow while visible, else predict and look, else way-point search."""
    return TreeNode.model_validate(
        {
            "fallback": {
                "name": "root",
                "children": [
                    {
                        "sequence": {
                            "name": "follow",
                            "children": [
                                {"condition": "target_visible"},
                                {"action": "follow_target"},
                            ],
                        }
                    },
                    {
                        "fallback": {
                            "name": "find",
                            "children": [
                                {
                                    "sequence": {
                                        "name": "predict_and_look",
                                        "children": [
                                            {"condition": "prediction_available"},
                                            {"action": "go_to_prediction"},
                                            {"action": "look_around"},
                                        ],
                                    }
                                },
                                {"action": "waypoint_search"},
                            ],
                        }
                    },
                ],
            }
        }
    )


class ControlConfig(_Model):
    """Gaze and base control while following (§II-E), and what counts as following."""

    following_distance: Annotated[float, Field(ge=0.3), _NO_BOOL] = 1.0
    """Keep this far from the target, metres."""
    min_distance: Annotated[float, Field(ge=0.3), _NO_BOOL] = 0.7
    """Never drive closer than this to a person (base centre to person centre), metres."""
    turn_threshold: Annotated[float, Field(gt=0, le=3.2), _NO_BOOL] = 0.5
    """Above this bearing to the target the base turns in place before going straight, rad."""
    stale_after: Positive = 0.5
    """The base stops when the laser or the pose is older than this, seconds."""
    following_band: Limits = (0.5, 2.5)
    """A tick counts as following when the target is identified and this far away, metres."""

    @model_validator(mode="after")
    def _distances_ordered(self) -> ControlConfig:
        if self.min_distance > self.following_distance:
            raise _fail(
                ("min_distance",),
                f"expected min_distance <= following_distance ({self.following_distance:g}), "
                f"got {self.min_distance:g}",
            )
        return self


class BehaviorConfig(_Model):
    """The behavior tree and its tick rate (§II-A); the default tree is the paper's Fig. 2."""

    tick_hz: Positive = 10.0
    tree: TreeNode = Field(default_factory=_paper_tree)


# --------------------------------------------------------------------------------------------
# scenario
# --------------------------------------------------------------------------------------------


def _route_stop_kind(value: Any) -> str | None:
    if isinstance(value, str):
        return "region"
    if isinstance(value, (list, tuple)):
        return "point"
    return None


RouteStop = Annotated[
    Union[Annotated[Name, Tag("region")], Annotated[Point, Tag("point")]],  # noqa: UP007
    Discriminator(
        _route_stop_kind,
        custom_error_type="route_stop",
        custom_error_message="expected a region name or an [x, y] point",
    ),
]
"""A stop of a person's route: the name of a region (its centre) or an ``[x, y]`` point."""


class Clothes(_Model):
    """Colours of a simulated person's clothes, RGB 0..255 (Algorithm 2 compares histograms)."""

    upper: RGB
    lower: RGB


class Person(_Model):
    """A simulated person: name, clothes, walking speed (m/s) and route."""

    name: Name
    clothes: Clothes
    speed: Annotated[float, Field(ge=0.3, le=1.4), _NO_BOOL] = 0.8
    route: Annotated[tuple[RouteStop, ...], Field(min_length=1)]
    """Region names or [x, y] points, walked in order; the person starts at the first."""
    height: Annotated[float, Field(ge=1.2, le=2.1), _NO_BOOL] = 1.7
    """Body height, metres (simulator)."""
    pause_s: NonNegative = 2.0
    """Mean pause at each intermediate stop of the route, seconds."""
    loop: bool = False
    """Walk the route again and again (back to the first stop); else stay at the last stop."""


PeopleCount = Annotated[int, Field(ge=0, le=20), _NO_BOOL]


def _check_range(value: tuple[Any, Any]) -> tuple[Any, Any]:
    """A ``[low, high]`` range must have ``low <= high`` (equal: a fixed value)."""
    if value[0] > value[1]:
        raise _error(
            "range_order", f"expected [low, high] with low <= high, got [{value[0]}, {value[1]}]"
        )
    return value


CountRange = Annotated[tuple[PeopleCount, PeopleCount], AfterValidator(_check_range)]
"""An inclusive ``[low, high]`` range of a number of people, each drawn uniformly."""
ScaleRange = Annotated[
    tuple[
        Annotated[float, Field(ge=0.25, le=4.0), _NO_BOOL],
        Annotated[float, Field(ge=0.25, le=4.0), _NO_BOOL],
    ],
    AfterValidator(_check_range),
]
"""A ``[low, high]`` range of a factor, drawn uniformly."""


class ScenarioRandomization(_Model):
    """What else the seed varies from episode to episode (``pfctl bench`` campaigns).

    Everything is off by default, so a mission without this section runs exactly as before. The
    draws come from their own random streams of the seed: turning one on leaves everything the
    seed already varied (region stops, pauses, ``random_people``, faces, sensor noise) as it was.
    """

    speed_scale: ScaleRange = (1.0, 1.0)
    """Each of ``people`` walks at their ``speed`` times a factor drawn from this range (the
    result kept within a person's 0.3-1.4 m/s)."""
    route_jitter: NonNegative = 0.0
    """Each ``[x, y]`` stop of the ``people``'s routes moves by up to this many metres, to a
    free spot of the same region (region stops are already a random free point of the region)."""
    extra_people: CountRange = (0, 0)
    """Distractors added to ``random_people``: their number drawn from this range."""
    look_alikes: CountRange = (0, 0)
    """Distractors dressed like the target (each colour channel within ``look_alike_jitter``),
    walking random looping routes: their number drawn from this range."""
    look_alike_jitter: Annotated[int, Field(ge=0, le=128), _NO_BOOL] = 12
    """How far a look-alike's clothes may stray from the target's, per RGB channel (0..255)."""
    hide_in: tuple[Name, ...] = ()
    """``pfctl search``/``bench --task search``: the target hides in one of these regions, chosen
    by the seed (empty: any region that is not the robot's or next to it)."""


class ScenarioConfig(_Model):
    """The simulator's episode: seed, the people, and which of them is the target."""

    seed: Integer = 0
    target: str | None = None
    """The name of the person to follow: one of ``people``."""
    people: tuple[Person, ...] = ()
    random_people: PeopleCount = 0
    """Extra distractors with random clothes, speeds and looping routes drawn from ``seed``."""
    randomize: ScenarioRandomization = ScenarioRandomization()
    """Further per-seed variation for benchmark campaigns; all off by default."""

    @model_validator(mode="after")
    def _names(self) -> ScenarioConfig:
        issues: list[tuple[tuple[str | int, ...], str]] = []
        seen: dict[str, int] = {}
        for i, person in enumerate(self.people):
            if person.name in seen:
                issues.append(
                    (
                        ("people", i, "name"),
                        f"duplicate person name {person.name!r} "
                        f"(already used by people[{seen[person.name]}])",
                    )
                )
            seen.setdefault(person.name, i)
        if self.target is not None and self.target not in seen:
            names = ", ".join(seen) or "none"
            issues.append(
                (
                    ("target",),
                    f"expected the name of one of the people ({names}), got {self.target!r}",
                )
            )
        if self.target is None and self.randomize.look_alikes[1] > 0:
            issues.append(
                (
                    ("randomize", "look_alikes"),
                    "look-alikes copy the target's clothes: name a scenario.target first",
                )
            )
        _raise_first(issues)
        return self


# --------------------------------------------------------------------------------------------
# the mission
# --------------------------------------------------------------------------------------------


# --------------------------------------------------------------------------------------------
# backend
# --------------------------------------------------------------------------------------------

Topic = Annotated[str, Field(pattern=r"^/[A-Za-z0-9_/]*[A-Za-z0-9_]$")]
"""A global ROS 1 graph name (``/hsrb/base_scan``)."""
Frame = Annotated[str, Field(pattern=r"^[A-Za-z0-9_][A-Za-z0-9_/]*$")]
"""A tf frame id without a leading slash (``base_footprint``)."""


class HsrConfig(_Model):
    """The Toyota HSR over ROS 1 (``--backend hsr``): the topics, frames and safety timeouts.

    The defaults are the names of Toyota's ROS 1 stack; ``pfctl sim serve-hsr`` serves exactly
    these, so the same mission drives the robot and the simulated house. Person detections come
    from one of two sources (§II-E: the paper's OpenPose ran beside the robot):

    * ``person_labels`` (the default): an instance-segmentation image published by a person
      detector (e.g. an OpenPose node on another machine, or the simulator):
      ``sensor_msgs/Image``, encoding ``16UC1`` (``mono16``), the RGB image's size and stamp;
      pixel value 0 is no person, value ``v > 0`` is person ``(v - 1) // 4`` (an index that only
      has to be stable within one image) and body part ``(v - 1) % 4`` (0 unknown, 1 head,
      2 torso, 3 leg).
    * ``person_keypoints`` (when set; then ``person_labels`` is not subscribed and must be left
      out or null): 2-D keypoints and boxes as a ``sensor_msgs/PointCloud``
      (:mod:`pfctl.backends.hsr.person_keypoints`): ``header.stamp`` = the stamp of the RGB image
      the detector ran on (paired with RGB, depth and camera_info like the labels),
      ``header.frame_id`` = the RGB optical frame; one point per keypoint, ``x`` = pixel column,
      ``y`` = pixel row, ``z`` = confidence (≤ 0: not found); channels ``person`` (an index
      stable within the message) and ``part`` (OpenPose BODY_25 index 0-24; 25 = the box's
      top-left corner, 26 = its bottom-right corner, for detectors that give boxes), one value
      per point. The follower places each person in 3-D from the depth around its torso.
    """

    laser: Topic = "/hsrb/base_scan"
    """sensor_msgs/LaserScan of the base laser (REP-117 ranges)."""
    rgb: Topic = "/hsrb/head_rgbd_sensor/rgb/image_rect_color"
    """sensor_msgs/Image, rgb8 or bgr8."""
    depth: Topic = "/hsrb/head_rgbd_sensor/depth_registered/image_rect_raw"
    """sensor_msgs/Image registered to the RGB image: 16UC1 (mm) or 32FC1 (m)."""
    camera_info: Topic = "/hsrb/head_rgbd_sensor/rgb/camera_info"
    """sensor_msgs/CameraInfo of the RGB image."""
    person_labels: Topic | None = "/pfctl/person_labels"
    """sensor_msgs/Image 16UC1 person/part labels (see above); null: no camera detections
    (unless ``person_keypoints`` is set)."""
    person_keypoints: Topic | None = None
    """sensor_msgs/PointCloud of 2-D keypoints/boxes (see above), e.g. ``/pfctl/person_keypoints``
    from a relay of an OpenPose node; null: the person labels are the source."""
    joint_states: Topic = "/hsrb/joint_states"
    """sensor_msgs/JointState with head_pan_joint and head_tilt_joint."""
    odom: Topic = "/hsrb/odom"
    """nav_msgs/Odometry of the base."""
    pose: Topic | None = None
    """geometry_msgs/PoseStamped of the base in the map (e.g. ``/global_pose``); null: tf."""
    command_velocity: Topic = "/hsrb/command_velocity"
    """geometry_msgs/Twist to the omnidirectional base."""
    head_command: Topic = "/hsrb/head_trajectory_controller/command"
    """trajectory_msgs/JointTrajectory to the head."""
    move_base: Topic = "/move_base/move"
    """The move_base_msgs/MoveBaseAction server."""
    viewpoint_stop: Topic | None = "/viewpoint_controller/stop"
    """std_srvs/Empty called (when it exists) before the head is commanded; null: never."""
    ground_truth: Topic | None = "/ground_truth"
    """Namespace of the simulator's truth (``robot``, ``people``, ``collisions``) used for the
    metrics only, never by the follower; absent on a real robot."""
    map_frame: Frame = "map"
    odom_frame: Frame = "odom"
    base_frame: Frame = "base_footprint"
    stale_timeout: Positive = 0.5
    """Zero velocity is published when the laser or the pose is older than this (wall) time, s."""
    connect_timeout: Positive = 20.0
    """How long to wait at start for the first laser scan, pose and clock, s."""

    @model_validator(mode="before")
    @classmethod
    def _one_person_source(cls, data: Any) -> Any:
        """With ``person_keypoints`` the keypoints are the person source: ``person_labels`` is
        then null (not subscribed); naming a labels topic as well is an error."""
        if not isinstance(data, Mapping) or data.get("person_keypoints") is None:
            return data
        labels = data.get("person_labels")
        if labels is not None:
            raise _fail(
                ("person_keypoints",),
                f"expected one person source, got person_labels ({labels}) as well: leave "
                "person_labels out (or null) to take the people from the keypoints",
            )
        return {**data, "person_labels": None}


class BackendConfig(_Model):
    """Backend-specific settings."""

    hsr: HsrConfig = HsrConfig()


class Mission(_Model):
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
                        (loc, f"expected a point inside the regions, got {_fmt_point(stop)}")
                    )
        for i, region in enumerate(self.scenario.randomize.hide_in):
            if region not in regions:
                issues.append(
                    (
                        ("scenario", "randomize", "hide_in", i),
                        f"unknown region {region!r} (regions: {', '.join(regions)})",
                    )
                )
        _raise_first(issues)
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


def dump_json_schema() -> dict[str, Any]:
    """The JSON Schema of a mission file (what ``pfctl mission schema`` prints)."""
    return Mission.model_json_schema()


# --------------------------------------------------------------------------------------------
# loading, and turning every failure into one line
# --------------------------------------------------------------------------------------------


def load_mission(path: str | os.PathLike[str]) -> Mission:
    """Read and validate the mission at ``path``.

    A mission may start from another: a top-level ``extends: PATH`` (relative to the file)
    loads that mission's YAML first — recursively, a cycle is an error — and merges this file
    over it (:func:`merge_mission_data`). ``behavior.tree: {include: PATH}`` reads the tree from
    a file holding exactly what ``behavior.tree`` would (``missions/trees/``). Relative paths in
    a file (``map.occupancy``, ``perception.legs.model``) stay relative to the file that has
    them, and errors name the file and line the failing value came from.

    Raises:
        MissionError: for anything wrong with the file, with a one-line message
            ``<file>:<line>: <key.path>: <what was expected>``.
    """
    source = os.fspath(path)
    file = Path(source)
    text = _read_text(file, source, "a mission YAML file")
    return _loads(text, source, file.parent, ((file.resolve(), source),))


def loads_mission(
    text: str, *, source: str = "<string>", base_dir: str | os.PathLike[str] | None = None
) -> Mission:
    """Validate the mission YAML in ``text``; ``source`` names it in errors.

    ``base_dir`` is where relative paths in the mission (``map.occupancy``, ``extends``,
    ``behavior.tree.include``) are resolved; the current directory if None.

    Raises:
        MissionError: as :func:`load_mission`.
    """
    return _loads(text, source, Path(base_dir) if base_dir is not None else Path("."), ())


def merge_mission_data(base: Any, child: Any, path: tuple[str, ...] = ()) -> Any:
    """``child`` deep-merged over ``base`` (the semantics of ``extends``).

    Mappings merge key by key (a key of ``child`` wins; keys only in ``base`` stay); lists and
    scalars replace. ``behavior.tree`` replaces as a whole: a tree node is one of several kinds,
    and merging two trees would mix them. ``path`` is the key path of ``base`` and ``child``.
    """
    if isinstance(base, dict) and isinstance(child, dict) and path != _TREE_PATH:
        merged = dict(base)
        for key, value in child.items():
            sub = (*path, str(key))
            merged[key] = merge_mission_data(base[key], value, sub) if key in base else value
        return merged
    return child


#: The top-level key naming the mission a file extends.
EXTENDS_KEY = "extends"
#: ``behavior.tree: {include: PATH}``: the tree is read from PATH.
INCLUDE_KEY = "include"
_TREE_PATH = ("behavior", "tree")
_Chain = tuple[tuple[Path, str], ...]
"""The files being extended, outermost first: (resolved path, name in messages)."""


def _read_text(file: Path, source: str, what: str) -> str:
    """The UTF-8 text of ``file``; one-line errors naming ``source``."""
    if file.is_dir():
        raise MissionError(f"{source}: is a directory, expected {what}")
    try:
        raw = file.read_bytes()
    except FileNotFoundError:
        raise MissionError(f"{source}: no such file") from None
    except OSError as err:
        raise MissionError(f"{source}: cannot read: {err.strerror or err}") from None
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError as err:
        line = raw[: err.start].count(b"\n") + 1
        raise MissionError(
            f"{source}:{line}: not UTF-8 text (byte 0x{raw[err.start]:02x}); "
            "save the mission as UTF-8"
        ) from None


def _loads(text: str, source: str, base_dir: Path, chain: _Chain) -> Mission:
    """Read ``text`` with what it extends and includes, then validate the merged mission."""
    root, data, sources = _read_layers(text, source, base_dir, chain)
    context = {"base_dir": base_dir}
    try:
        return Mission.model_validate(data, context=context)
    except ValidationError as err:
        raise MissionError(_format_validation_error(err, root, sources)) from None
    except RecursionError:
        raise MissionError(f"{source}: the mission is nested too deeply") from None


def _read_layers(
    text: str, source: str, base_dir: Path, chain: _Chain
) -> tuple[yaml.MappingNode, dict[str, Any], list[str]]:
    """The mission in ``text`` merged over the one it extends: the YAML node graph (every node
    keeps the name of its file in its marks, for error lines), the data, and the files read,
    this one first."""
    root, data = _parse_yaml(text, source)
    if root is None or data is None:
        raise MissionError(
            f"{source}: the file is empty; expected a mission with at least 'name' and 'map'"
        )
    if not isinstance(data, dict) or not isinstance(root, yaml.MappingNode):
        raise MissionError(
            f"{source}:{root.start_mark.line + 1}: expected a mapping of mission sections "
            f"(name, map, ...) at the top level, got {_yaml_kind(data)}"
        )
    _check_duplicate_keys(root, source)
    sources = [source, *_include_tree(root, data, source, base_dir)]
    key = _key_node(root, EXTENDS_KEY)
    if key is None:
        return root, data, sources
    line = key.start_mark.line + 1
    where = f"{source}:{line}: {EXTENDS_KEY}"
    value = data.pop(EXTENDS_KEY)
    root = yaml.MappingNode(
        root.tag,
        [(k, v) for k, v in root.value if k is not key],
        root.start_mark,
        root.end_mark,
        root.flow_style,
    )
    base_file = _referenced_file(
        value, base_dir, where, "the path of the mission this one extends", "mission file"
    )
    resolved = base_file.resolve()
    names = [name for _, name in chain] or [source]
    if any(resolved == seen for seen, _ in chain):
        cycle = " -> ".join([*names, os.path.normpath(base_file)])
        raise MissionError(f"{where}: a mission cannot extend itself: {cycle}")
    base_name = os.path.normpath(base_file)  # for messages; the file is read as written
    base_text = _read_text(base_file, base_name, "a mission YAML file")
    base_chain = (*(chain or ((Path(source), source),)), (resolved, base_name))
    base_root, base_data, base_sources = _read_layers(
        base_text, base_name, base_file.parent, base_chain
    )
    _rebase_files(base_data, base_file.parent, base_dir)
    merged_root = _merge_nodes(base_root, root, ())
    assert isinstance(merged_root, yaml.MappingNode)
    return merged_root, merge_mission_data(base_data, data), [*sources, *base_sources]


def _referenced_file(value: object, base_dir: Path, where: str, expected: str, kind: str) -> Path:
    """The existing file a mission names at ``where`` (``extends``, a tree ``include``): an
    absolute path, or one relative to the naming file's folder ``base_dir``; else one line."""
    if not isinstance(value, str) or not value.strip():
        raise MissionError(
            f"{where}: expected {expected} (relative to this file), got {_got(value)}"
        )
    file = Path(value) if Path(value).is_absolute() else base_dir / value
    if not file.is_file():
        raise MissionError(
            f"{where}: expected an existing {kind}, but {os.path.normpath(file)} "
            + ("is a directory" if file.is_dir() else "does not exist")
        )
    return file


def _key_node(node: yaml.Node, key: str) -> yaml.ScalarNode | None:
    """The key node ``key`` of mapping ``node`` (the last, as PyYAML keeps), else None."""
    if not isinstance(node, yaml.MappingNode):
        return None
    for k, _ in reversed(node.value):
        if isinstance(k, yaml.ScalarNode) and k.value == key:
            return k
    return None


def _include_tree(
    root: yaml.MappingNode, data: dict[str, Any], source: str, base_dir: Path
) -> list[str]:
    """Replace ``behavior.tree: {include: PATH}`` by the tree read from PATH (relative to the
    mission file), in the data and in the node graph; the file read, if any."""
    behavior, tree = data.get("behavior"), None
    if isinstance(behavior, dict):
        tree = behavior.get("tree")
    if not isinstance(tree, dict) or INCLUDE_KEY not in tree:
        return []
    behavior_value = next(v for k, v in root.value if k is _key_node(root, "behavior"))
    tree_key = _key_node(behavior_value, "tree")
    assert tree_key is not None and isinstance(behavior_value, yaml.MappingNode)
    tree_value = next(v for k, v in behavior_value.value if k is tree_key)
    include_key = _key_node(tree_value, INCLUDE_KEY)
    assert include_key is not None
    where = f"{source}:{include_key.start_mark.line + 1}: behavior.tree.{INCLUDE_KEY}"
    others = [str(k) for k in tree if k != INCLUDE_KEY]
    if others:
        raise MissionError(
            f"{where}: a tree read from a file takes no other keys, got {others[0]!r} beside it"
        )
    value = tree[INCLUDE_KEY]
    file = _referenced_file(value, base_dir, where, "the path of a tree file", "tree file")
    name = os.path.normpath(file)
    tree_root, tree_data = _parse_yaml(_read_text(file, name, "a behavior-tree YAML file"), name)
    if tree_root is None or tree_data is None:
        raise MissionError(
            f"{name}: the file is empty; expected a behavior tree (what behavior.tree holds)"
        )
    _check_duplicate_keys(tree_root, name, _TREE_PATH)
    behavior["tree"] = tree_data
    behavior_value.value = [(k, tree_root if k is tree_key else v) for k, v in behavior_value.value]
    return [name]


def _merge_nodes(base: yaml.Node, child: yaml.Node, path: tuple[str, ...]) -> yaml.Node:
    """:func:`merge_mission_data` on the YAML node graphs: a merged mapping takes the child's
    marks; every other node stays the one (and the file) its value came from."""
    if not (
        isinstance(base, yaml.MappingNode)
        and isinstance(child, yaml.MappingNode)
        and path != _TREE_PATH
    ):
        return child
    children = {k.value: (k, v) for k, v in child.value if isinstance(k, yaml.ScalarNode)}
    merged: list[tuple[yaml.Node, yaml.Node]] = []
    for k, v in base.value:
        name = k.value if isinstance(k, yaml.ScalarNode) else None
        if name in children:
            ck, cv = children.pop(name)
            merged.append((ck, _merge_nodes(v, cv, (*path, name))))
        else:
            merged.append((k, v))
    merged += [
        (k, v) for k, v in child.value if not isinstance(k, yaml.ScalarNode) or k.value in children
    ]
    return yaml.MappingNode(child.tag, merged, child.start_mark, child.end_mark, child.flow_style)


@functools.cache
def _file_fields() -> tuple[tuple[str, ...], ...]:
    """Key paths of the mission's file-valued fields (``map.occupancy``,
    ``perception.legs.model``): the ``Path`` fields of the models, through nested models."""

    def walk(model: type[BaseModel], seen: frozenset[type[BaseModel]]) -> list[tuple[str, ...]]:
        out: list[tuple[str, ...]] = []
        for name, info in model.model_fields.items():
            if Path in (info.annotation, *get_args(info.annotation)):
                out.append((name,))
            for sub in _models_in(info.annotation):
                if sub not in seen:
                    out += [(name, *rest) for rest in walk(sub, seen | {sub})]
        return out

    return tuple(walk(Mission, frozenset({Mission})))


def _rebase_files(data: dict[str, Any], file_dir: Path, base_dir: Path) -> None:
    """Relative file paths of a base mission in ``file_dir``, made absolute so that they still
    name the same files when the extending mission in ``base_dir`` is validated."""
    if file_dir.resolve() == base_dir.resolve():
        return
    for keys in _file_fields():
        parent: Any = data
        for key in keys[:-1]:
            parent = parent.get(key) if isinstance(parent, dict) else None
        value = parent.get(keys[-1]) if isinstance(parent, dict) else None
        if isinstance(value, str) and value and not Path(value).is_absolute():
            parent[keys[-1]] = str((file_dir / value).absolute())


def _yaml_kind(value: Any) -> str:
    if isinstance(value, list):
        return "a list"
    if isinstance(value, str):
        return f"the string {_short(value)}"
    return f"{type(value).__name__} {_short(value)}"


def _one_line(text: str) -> str:
    return " ".join(str(text).split())


def _short(value: Any, limit: int = 40) -> str:
    text = _one_line(repr(value))
    return text if len(text) <= limit else text[: limit - 3] + "..."


def _parse_yaml(text: str, source: str) -> tuple[yaml.Node | None, Any]:
    """Compose the node graph (for line numbers) and construct the data from it, in one parse."""
    loader = yaml.SafeLoader(text)
    loader.name = source  # every node's marks name its file (errors of merged missions)
    try:
        root = loader.get_single_node()
        data = loader.construct_document(root) if root is not None else None
    except yaml.MarkedYAMLError as err:
        mark = err.problem_mark or err.context_mark
        where = f"{source}:{mark.line + 1}" if mark is not None else source
        parts = [p for p in (err.context, err.problem) if p]
        cmark, pmark = err.context_mark, err.problem_mark
        if cmark is not None and pmark is not None and err.context and cmark.line != pmark.line:
            parts[0] = f"{err.context} (line {cmark.line + 1})"
        detail = _one_line(": ".join(parts) or "invalid YAML")
        label = (
            "YAML error"
            if isinstance(err, yaml.constructor.ConstructorError)
            else "YAML syntax error"
        )
        raise MissionError(f"{where}: {label}: {detail}") from None
    except yaml.YAMLError as err:
        raise MissionError(f"{source}: YAML syntax error: {_one_line(str(err))}") from None
    except RecursionError:
        raise MissionError(f"{source}: the YAML is nested too deeply") from None
    finally:
        loader.dispose()
    return root, data


def _format_loc(loc: Sequence[str | int]) -> str:
    """``("map", "doors", 1, "between")`` -> ``map.doors[1].between``."""
    out = ""
    for part in loc:
        if isinstance(part, int):
            out += f"[{part}]"
        else:
            out += f".{part}" if out else str(part)
    return out


def _check_duplicate_keys(root: yaml.Node, source: str, prefix: tuple[str | int, ...] = ()) -> None:
    """PyYAML keeps the last of two equal keys silently; a mission must not repeat a key.
    ``prefix`` is the key path of ``root`` in the mission (a tree file's ``behavior.tree``)."""
    seen: set[int] = set()
    stack: list[tuple[yaml.Node, tuple[str | int, ...]]] = [(root, prefix)]
    while stack:
        node, loc = stack.pop()
        if id(node) in seen:
            continue
        seen.add(id(node))
        if isinstance(node, yaml.MappingNode):
            keys: dict[str, int] = {}
            for key, value in node.value:
                if isinstance(key, yaml.ScalarNode) and key.value != "<<":
                    if key.value in keys:
                        path = _format_loc((*loc, key.value))
                        raise MissionError(
                            f"{source}:{key.start_mark.line + 1}: {path}: duplicate key "
                            f"(first on line {keys[key.value]})"
                        )
                    keys[key.value] = key.start_mark.line + 1
                    stack.append((value, (*loc, key.value)))
        elif isinstance(node, yaml.SequenceNode):
            stack.extend((item, (*loc, i)) for i, item in enumerate(node.value))


def _locate(root: yaml.Node, loc: Sequence[str | int]) -> tuple[tuple[str | int, ...], yaml.Mark]:
    """Walk the node graph along ``loc``; the cleaned key path and the mark of the deepest node.

    Union tags that pydantic inserts into the path (``route[0].point``) are dropped: a string
    step into a scalar or a list cannot be a key. Once a key is missing, the rest of the path is
    kept as is. The mark is the key's when the last step was into a mapping; its ``name`` is the
    file the node was read from (a mission merged with the one it extends has nodes of both).
    """
    node: yaml.Node | None = root
    mark = root.start_mark
    path: list[str | int] = []
    for part in loc:
        if node is None:
            path.append(str(part) if isinstance(part, str) else part)
        elif isinstance(node, yaml.MappingNode):
            match = next(
                (
                    (k, v)
                    for k, v in reversed(node.value)
                    if isinstance(k, yaml.ScalarNode) and k.value == str(part)
                ),
                None,
            )
            path.append(str(part))
            if match is None:
                node = None
            else:
                mark = match[0].start_mark
                node = match[1]
        elif isinstance(part, str):
            continue  # a union tag, not a key
        elif isinstance(node, yaml.SequenceNode) and 0 <= part < len(node.value):
            path.append(part)
            node = node.value[part]
            mark = node.start_mark
        else:
            path.append(part)
            node = None
    return tuple(path), mark


def _allowed_keys(loc: Sequence[str | int]) -> list[str] | None:
    """The keys the model at ``loc`` accepts, found by walking the model types along the path."""
    candidates: list[Any] = [Mission]
    for part in loc:
        following: list[Any] = []
        for tp in candidates:
            following.extend(_step_type(tp, part))
        candidates = following
    for tp in candidates:
        for model in _models_in(tp):
            return [f.alias or name for name, f in model.model_fields.items()]
    return None


def _models_in(tp: Any) -> Iterator[type[BaseModel]]:
    """The pydantic models ``tp`` may be (through Annotated, Optional and unions)."""
    if isinstance(tp, type) and issubclass(tp, BaseModel):
        yield tp
        return
    origin = get_origin(tp)
    if origin is Annotated:
        yield from _models_in(get_args(tp)[0])
    elif origin is Union or type(tp).__name__ == "UnionType":
        for arg in get_args(tp):
            yield from _models_in(arg)


def _step_type(tp: Any, part: str | int) -> list[Any]:
    """The types one key-path step below ``tp``."""
    origin = get_origin(tp)
    if origin is Annotated:
        return _step_type(get_args(tp)[0], part)
    if origin is Union or type(tp).__name__ == "UnionType":
        return [t for arg in get_args(tp) for t in _step_type(arg, part)]
    if isinstance(tp, type) and issubclass(tp, BaseModel):
        field = tp.model_fields.get(str(part))
        return [field.annotation] if field is not None else []
    if origin in (tuple, list) and isinstance(part, int):
        args = get_args(tp)
        if len(args) == 2 and args[1] is Ellipsis:
            return [args[0]]
        return [args[part]] if part < len(args) else []
    return []


_MODEL_TYPE = re.compile(r"a valid dictionary or instance of \w+")
_COUNT = re.compile(r"^\w+ should have at (least|most) (\d+) items? after validation, not (\d+)$")
_BOUND = re.compile(r"^expected (greater|less) than( or equal to)? (\S+)$")
_OPERATORS = {
    ("greater", False): ">",
    ("greater", True): ">=",
    ("less", False): "<",
    ("less", True): "<=",
}


def _got(value: Any) -> str:
    """How an input reads in ``(got ...)``: short values verbatim, containers by their kind."""
    if isinstance(value, (list, tuple)):
        return f"a list of {len(value)}"
    if isinstance(value, Mapping):
        return "a mapping"
    if value is None or isinstance(value, bool):
        return {None: "null", True: "true", False: "false"}[value]
    return _short(value)


def _format_error(error: Mapping[str, Any], root: yaml.Node) -> tuple[yaml.Mark, str, int]:
    """One pydantic error as ``(mark, "key.path: message", further errors it stands for)``."""
    loc = tuple(error["loc"])
    ctx = error.get("ctx") or {}
    kind = error["type"]
    message = _one_line(error["msg"])
    if kind == "mission":
        loc = (*loc, *ctx.get("loc", ()))
    path, mark = _locate(root, loc)
    more = int(ctx.get("more", 0)) if kind == "mission" else 0
    if kind == "missing":
        message = "required key is missing"
    elif kind == "extra_forbidden":
        allowed = _allowed_keys(loc[:-1])
        message = "unknown key"
        if allowed:
            message += f" (expected one of: {', '.join(allowed)})"
    elif kind == "invalid_key":
        message = f"expected a string key, got {_short(error.get('input'))}"
    else:
        message = re.sub(r"^(Value error|Assertion failed), ", "", message)
        message = _MODEL_TYPE.sub("a mapping", message)
        message = message.replace("a valid tuple", "a list").replace(
            "a valid dictionary", "a mapping"
        )
        if message.startswith("Input should be "):
            message = "expected " + message[len("Input should be ") :]
        count = _COUNT.match(message)
        if count:
            unit = "item" if count.group(2) == "1" else "items"
            message = f"expected at {count.group(1)} {count.group(2)} {unit}, got {count.group(3)}"
        bound = _BOUND.match(message)
        if bound:
            operator = _OPERATORS[(bound.group(1), bool(bound.group(2)))]
            message = f"expected a value {operator} {bound.group(3)}"
        if "detail" not in ctx and kind != "route_stop" and not count:
            message += f" (got {_got(error.get('input'))})"
    where = _format_loc(path)
    return mark, f"{where}: {message}" if where else message, more


def _format_validation_error(err: ValidationError, root: yaml.Node, sources: list[str]) -> str:
    """The first error in file order — the files in ``sources`` order (the mission, then what it
    includes and extends), then by line — as one line naming its file, with ``(+N more)`` when
    there are others."""
    errors = err.errors()
    # A list with a bad item is also "too short after validation": that one is noise.
    errors = [
        e
        for e in errors
        if e["type"] not in ("too_short", "too_long")
        or not any(
            len(o["loc"]) > len(e["loc"]) and o["loc"][: len(e["loc"])] == e["loc"] for o in errors
        )
    ]
    formatted = [_format_error(e, root) for e in errors]
    order = {name: i for i, name in reversed(list(enumerate(sources)))}

    def position(item: tuple[yaml.Mark, str, int]) -> tuple[int, int]:
        return (order.get(item[0].name, len(sources)), item[0].line)

    formatted.sort(key=position)  # stable: equal lines keep pydantic's order
    mark, message, _ = formatted[0]
    more = len(formatted) - 1 + sum(m for _, _, m in formatted)
    suffix = f" (+{more} more)" if more else ""
    return f"{mark.name}:{mark.line + 1}: {message}{suffix}"
