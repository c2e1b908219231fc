"""The Robot port (DESIGN.md): what the follower needs from any robot, simulated or real.

Every backend (``backends/pybullet``, ``backends/hsr``) implements :class:`Robot`; a robot that
can speak also implements :class:`Speaker`, which the follower uses when it is there. The follower
only ever sees :class:`Observation`; ground truth (:class:`GroundTruth`) travels beside it for
metrics and recording and must never be read by the follower's decisions.

Conventions (REP-103/105): metres, radians, seconds; map frame x forward, y left, angles CCW.
Values are small frozen dataclasses or numpy arrays.
"""

from __future__ import annotations

import enum
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Protocol, runtime_checkable

import numpy as np


@dataclass(frozen=True)
class Pose2D:
    """A planar pose in the map frame: position (m) and heading (rad, CCW from +x)."""

    x: float
    y: float
    theta: float = 0.0

    def transform(self, local_xy: np.ndarray) -> np.ndarray:
        """Map points ``(n, 2)`` given in this pose's frame into the parent frame."""
        c, s = math.cos(self.theta), math.sin(self.theta)
        pts = np.asarray(local_xy, dtype=float).reshape(-1, 2)
        return np.column_stack(
            (self.x + c * pts[:, 0] - s * pts[:, 1], self.y + s * pts[:, 0] + c * pts[:, 1])
        )

    def distance_to(self, other: Pose2D) -> float:
        """Euclidean distance between the two positions (m)."""
        return math.hypot(other.x - self.x, other.y - self.y)

    def compose(self, other: Pose2D) -> Pose2D:
        """``other``, given in this pose's frame, in the parent frame (``self ⊕ other``)."""
        c, s = math.cos(self.theta), math.sin(self.theta)
        return Pose2D(
            self.x + c * other.x - s * other.y,
            self.y + s * other.x + c * other.y,
            wrap_angle(self.theta + other.theta),
        )

    def inverse(self) -> Pose2D:
        """The parent frame's origin seen from this pose (``self ⊕ self.inverse()`` = 0)."""
        c, s = math.cos(self.theta), math.sin(self.theta)
        return Pose2D(-c * self.x - s * self.y, s * self.x - c * self.y, wrap_angle(-self.theta))

    def relative(self, other: Pose2D) -> Pose2D:
        """``other`` (a pose in the parent frame) seen from this pose (``self⁻¹ ⊕ other``)."""
        return self.inverse().compose(other)


def wrap_angle(angle: float) -> float:
    """The angle in (−π, π]."""
    return math.atan2(math.sin(angle), math.cos(angle))


@dataclass(frozen=True)
class Twist2D:
    """A base velocity command in the robot's own frame: vx, vy (m/s), wz (rad/s)."""

    vx: float = 0.0
    vy: float = 0.0
    wz: float = 0.0


STOP = Twist2D()
"""The zero command: the base stands still."""


@dataclass(frozen=True)
class HeadState:
    """Head joint angles (rad): pan about z (left positive), tilt about y (down negative)."""

    pan: float = 0.0
    tilt: float = 0.0


@dataclass(frozen=True)
class HeadTarget:
    """Desired head joint angles (rad); the backend moves toward them within its limits."""

    pan: float = 0.0
    tilt: float = 0.0


@dataclass(frozen=True)
class RobotLimits:
    """The robot's size and the limits every backend clamps its commands to (the mission's
    ``robot`` section declares their defaults, units and meanings)."""

    radius: float
    max_linear_speed: float
    max_angular_speed: float
    head_pan_limits: tuple[float, float]
    head_tilt_limits: tuple[float, float]
    head_max_speed: float


@dataclass(frozen=True)
class LaserScan:
    """A planar scan like ``sensor_msgs/LaserScan`` (REP-117: ``inf`` = no return in range).

    ``pose`` is the laser's own pose in the map frame at the time of the scan, so that beam ``i``
    at ``angle_min + i * angle_increment`` (laser frame) ends at ``pose.transform([r cos, r sin])``.
    """

    stamp: float
    angle_min: float
    angle_increment: float
    range_min: float
    range_max: float
    ranges: np.ndarray
    pose: Pose2D

    @property
    def angles(self) -> np.ndarray:
        """The angle of each beam in the laser frame (rad)."""
        return self.angle_min + self.angle_increment * np.arange(len(self.ranges))

    def points(self) -> np.ndarray:
        """The finite returns as map-frame points ``(n, 2)``."""
        r = np.asarray(self.ranges, dtype=float)
        ok = np.isfinite(r)
        a = self.angles[ok]
        local = np.column_stack((r[ok] * np.cos(a), r[ok] * np.sin(a)))
        return self.pose.transform(local)


@dataclass(frozen=True)
class CameraInfo:
    """Pinhole intrinsics like ``sensor_msgs/CameraInfo``: image size and the 3x3 matrix K."""

    width: int
    height: int
    K: tuple[float, ...]
    """Row-major 3x3 camera matrix (fx, 0, cx, 0, fy, cy, 0, 0, 1)."""
    frame_id: str = "head_rgbd_sensor"

    @property
    def fx(self) -> float:
        return self.K[0]

    @property
    def fy(self) -> float:
        return self.K[4]

    @property
    def cx(self) -> float:
        return self.K[2]

    @property
    def cy(self) -> float:
        return self.K[5]

    @property
    def horizontal_fov(self) -> float:
        """Horizontal field of view (rad)."""
        return 2.0 * math.atan2(self.width / 2.0, self.fx)


@dataclass(frozen=True)
class GivenPerson:
    """A person an external detector found in a frame's colour image, in 2-D only (§II-E: the
    paper's OpenPose ran beside the robot; the follower places its people in 3-D with the
    depth, :class:`pfctl.core.perception.vision.GivenPersonDetector`)."""

    box: tuple[int, int, int, int]
    """Image box ``(x0, y0, x1, y1)`` of the whole body, pixels (``x1``, ``y1`` exclusive)."""
    keypoints: Mapping[str, tuple[float, float]] | None = None
    """2-D keypoints ``name -> (u, v)`` (:data:`pfctl.core.perception.vision.Keypoints`), when
    known."""
    score: float = 1.0
    """The detector's confidence (OpenPose: the mean confidence of the keypoints)."""
    head_box: tuple[int, int, int, int] | None = None
    """Where the head is, when the detector knows (Algorithm 2 searches faces there)."""


@dataclass(frozen=True)
class RgbdFrame:
    """One RGB-D image: colour ``(h, w, 3) uint8``, metric depth ``(h, w) float32`` (m, ``inf``
    where nothing is seen), an optional segmentation mask ``(h, w) int32`` (backend body ids; the
    simulator's only, for tests and labels), the people an external detector found in it
    (``people``, when the backend has such a source), the intrinsics, and the camera's pose.

    ``camera_position`` / ``camera_rotation`` give the optical frame in the map frame: the
    rotation's columns are the camera's x (right), y (down), z (forward) axes in map coordinates.
    """

    stamp: float
    rgb: np.ndarray
    depth: np.ndarray
    info: CameraInfo
    camera_position: tuple[float, float, float]
    camera_rotation: np.ndarray
    mask: np.ndarray | None = None
    people: tuple[GivenPerson, ...] | None = None
    """The people an external 2-D detector found in this image (e.g. OpenPose keypoints over
    ROS, stamped like the image); None: the frame comes with no such detections (an empty tuple
    means the detector ran and found no one)."""


@dataclass(frozen=True)
class Observation:
    """What the follower may read on one tick."""

    stamp: float
    pose: Pose2D
    """The robot base's pose in the map frame (as localisation reports it; may be noisy)."""
    head: HeadState
    scans: tuple[LaserScan, ...] = ()
    """Every laser scan since the previous observation, oldest first, stamps increasing (the
    laser's rate, not the tick's: at 40 Hz and a 10 Hz tick, four), so that leg detection and
    tracking run on each scan at its own stamp and pose; empty if none has arrived."""
    rgbd: RgbdFrame | None = None
    """The newest RGB-D frame, or None if none has arrived since the previous observation."""
    collisions: int = 0
    """How many collisions the base has had so far (a robot can report bumper hits)."""
    odometry: Pose2D | None = None
    """The base's pose in the odom frame from wheel odometry (smooth, but it drifts), if any."""

    def __post_init__(self) -> None:
        if not isinstance(self.scans, tuple):  # e.g. one scan, given where the newest was once
            raise TypeError(
                f"Observation.scans must be a tuple of LaserScan, got {type(self.scans).__name__}"
            )

    @property
    def scan(self) -> LaserScan | None:
        """The newest of :attr:`scans`, or None if no scan has arrived since the previous
        observation."""
        return self.scans[-1] if self.scans else None


@dataclass(frozen=True)
class PersonTruth:
    """Ground truth of one simulated person: who, where, heading, speed."""

    name: str
    x: float
    y: float
    theta: float
    speed: float
    is_target: bool = False


@dataclass(frozen=True)
class GroundTruth:
    """The simulator's truth at one instant, kept apart from the observation (metrics only)."""

    stamp: float
    robot: Pose2D
    people: tuple[PersonTruth, ...] = ()
    command: Twist2D = STOP
    collisions: int = 0
    extra: dict[str, float] = field(default_factory=dict)


class NavStatus(enum.Enum):
    """The state of a MOVE_BASE-style goal (``actionlib_msgs/GoalStatus`` subset)."""

    PENDING = "pending"
    ACTIVE = "active"
    SUCCEEDED = "succeeded"
    ABORTED = "aborted"
    PREEMPTED = "preempted"
    """Cancelled by :meth:`Robot.cancel` or replaced by a new goal."""
    IDLE = "idle"
    """No goal has been given yet."""


class RobotLostError(RuntimeError):
    """The robot stopped answering mid-run (its sensors went stale, its ROS master or simulator
    went away). The backend has already stopped the base; the message says what was lost."""


@runtime_checkable
class Robot(Protocol):
    """The port every backend implements (DESIGN.md, "The Robot port")."""

    def observe(self) -> Observation:
        """The sensor bundle since the previous call: every scan since then, the newest RGB-D
        frame, the pose and head now; never ground truth."""
        ...

    def command(self, base: Twist2D, head: HeadTarget | None = None) -> None:
        """Set the base velocity (clamped to the robot's limits) and, optionally, a head target.

        A direct command cancels an active :meth:`navigate` goal (it becomes PREEMPTED).
        """
        ...

    def point_head(self, head: HeadTarget) -> None:
        """Move the head toward ``head`` only; the base and any navigation goal carry on."""
        ...

    def navigate(self, goal: Pose2D) -> None:
        """Start MOVE_BASE-style navigation to ``goal``; progress through :meth:`nav_status`."""
        ...

    def nav_status(self) -> NavStatus:
        """The state of the newest navigation goal."""
        ...

    def cancel(self) -> None:
        """Cancel the navigation goal (if any) and stop the base."""
        ...

    def step(self) -> None:
        """Advance one control period (the simulator steps physics; a real robot waits)."""
        ...

    def close(self) -> None:
        """Stop the base and release resources; safe to call twice, also after errors."""
        ...


@runtime_checkable
class Speaker(Protocol):
    """A robot with a voice (text-to-speech): optional beside :class:`Robot`, which stays what
    DESIGN.md names. A person who shows the robot only their back hears it ask to see their
    face (:class:`~pfctl.core.behavior.leaves.WaypointSearch`); a robot without a voice goes
    round to their front instead."""

    @property
    def speaks(self) -> bool:
        """Whether :meth:`say` is heard (False: the robot was given no voice to speak with)."""
        ...

    def say(self, text: str) -> None:
        """Say ``text`` aloud; returns at once, the speech goes on meanwhile."""
        ...
