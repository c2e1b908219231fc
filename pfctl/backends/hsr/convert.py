"""Pure conversions between ROS 1 messages and the Robot port's types (``pfctl.core.robot``).

No node, no master: each function maps one message to a core value or back. Conventions follow
the core port and the ROS REPs:

* LaserScan (REP-117): core keeps ``inf`` for every range that is not a valid return, because
  :meth:`pfctl.core.robot.LaserScan.points` uses only finite values. So NaN (invalid), ``-inf``
  (too close), ``+inf`` (no return) and finite values outside ``[range_min, range_max]`` all
  become ``inf`` on the way in (as :func:`pfctl.bags.reading.laser_scan` does for ROS 2 bags); on
  the way out ``inf`` is sent as ``+inf`` ("no return"), which REP-117 consumers understand.
* Depth (REP-118): core depth is ``float32`` metres with ``inf`` where nothing is seen.
  ``16UC1`` is millimetres with 0 = no return; ``32FC1`` is metres with NaN (or non-positive /
  infinite) = no return. Colour is always ``(h, w, 3) uint8`` RGB in core.
* Head joints by name: ``head_pan_joint``, ``head_tilt_joint`` (HSR's ``/hsrb/joint_states``).
* Time: ROS ``Time``/``Duration`` (``secs``, ``nsecs``) ⇄ float seconds.

Message classes are imported lazily through :mod:`pfctl.backends.hsr.ros_import`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from pfctl.backends.hsr.ros_import import import_ros_module
from pfctl.core.robot import (
    CameraInfo,
    HeadState,
    HeadTarget,
    LaserScan,
    NavStatus,
    Pose2D,
    Twist2D,
)

HEAD_PAN_JOINT = "head_pan_joint"
HEAD_TILT_JOINT = "head_tilt_joint"
HEAD_JOINTS = (HEAD_PAN_JOINT, HEAD_TILT_JOINT)

# actionlib_msgs/GoalStatus constants (fixed by the message definition).
_GOAL_STATUS = {
    0: NavStatus.PENDING,  # PENDING
    1: NavStatus.ACTIVE,  # ACTIVE
    2: NavStatus.PREEMPTED,  # PREEMPTED
    3: NavStatus.SUCCEEDED,  # SUCCEEDED
    4: NavStatus.ABORTED,  # ABORTED
    5: NavStatus.ABORTED,  # REJECTED: the server refused the goal
    6: NavStatus.PREEMPTED,  # PREEMPTING: cancel requested while active
    7: NavStatus.PREEMPTED,  # RECALLING: cancel requested while pending
    8: NavStatus.PREEMPTED,  # RECALLED: cancelled before it started
    9: NavStatus.ABORTED,  # LOST: the server no longer knows the goal
}


def _msg(module: str, name: str) -> Any:
    return getattr(import_ros_module(module), name)


# ---------------------------------------------------------------------------------------- time


def time_to_sec(t: Any) -> float:
    """A ROS ``Time`` or ``Duration`` (anything with ``secs``/``nsecs``) in float seconds."""
    return float(t.secs) + float(t.nsecs) * 1e-9


def sec_to_time(seconds: float) -> Any:
    """Float seconds (>= 0) as a ``rospy.Time``."""
    return _msg("rospy", "Time").from_sec(float(seconds))


def sec_to_duration(seconds: float) -> Any:
    """Float seconds as a ``rospy.Duration``."""
    return _msg("rospy", "Duration").from_sec(float(seconds))


def _header(stamp: float | None, frame_id: str) -> Any:
    header = _msg("std_msgs.msg", "Header")()
    if stamp is not None:
        header.stamp = sec_to_time(stamp)
    header.frame_id = frame_id
    return header


# ---------------------------------------------------------------------------------- geometry


def yaw_from_quaternion(q: Any) -> float:
    """The yaw (rad, about z, ZYX convention) of a quaternion with fields ``x, y, z, w``; the
    form ``w² + x² - y² - z²`` (not ``1 - 2(y² + z²)``) keeps it right for non-unit quaternions."""
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), q.w * q.w + q.x * q.x - q.y * q.y - q.z * q.z)


def quaternion_from_yaw(yaw: float) -> Any:
    """A ``geometry_msgs/Quaternion`` rotating by ``yaw`` about z."""
    return _msg("geometry_msgs.msg", "Quaternion")(
        x=0.0, y=0.0, z=math.sin(yaw / 2.0), w=math.cos(yaw / 2.0)
    )


def pose2d_from_pose(pose: Any) -> Pose2D:
    """A ``geometry_msgs/Pose`` projected to the plane: ``x``, ``y`` and the yaw."""
    return Pose2D(
        float(pose.position.x), float(pose.position.y), yaw_from_quaternion(pose.orientation)
    )


def pose2d_to_pose(pose: Pose2D, z: float = 0.0) -> Any:
    """A ``geometry_msgs/Pose`` at ``(x, y, z)`` with yaw ``theta``."""
    point = _msg("geometry_msgs.msg", "Point")(x=pose.x, y=pose.y, z=z)
    return _msg("geometry_msgs.msg", "Pose")(
        position=point, orientation=quaternion_from_yaw(pose.theta)
    )


def pose2d_from_transform(transform: Any) -> Pose2D:
    """A ``geometry_msgs/Transform`` projected to the plane: translation ``x``, ``y`` and yaw."""
    t = transform.translation
    return Pose2D(float(t.x), float(t.y), yaw_from_quaternion(transform.rotation))


def pose2d_to_transform(pose: Pose2D, z: float = 0.0) -> Any:
    """A ``geometry_msgs/Transform`` translating by ``(x, y, z)`` and rotating by ``theta``."""
    v = _msg("geometry_msgs.msg", "Vector3")(x=pose.x, y=pose.y, z=z)
    return _msg("geometry_msgs.msg", "Transform")(
        translation=v, rotation=quaternion_from_yaw(pose.theta)
    )


def pose2d_from_odometry(msg: Any) -> Pose2D:
    """The base pose of a ``nav_msgs/Odometry`` (in its ``header.frame_id``, usually odom)."""
    return pose2d_from_pose(msg.pose.pose)


def twist_to_msg(twist: Twist2D) -> Any:
    """A ``geometry_msgs/Twist`` for a base command (``linear.x/y``, ``angular.z``)."""
    msg = _msg("geometry_msgs.msg", "Twist")()
    msg.linear.x, msg.linear.y, msg.angular.z = float(twist.vx), float(twist.vy), float(twist.wz)
    return msg


def twist_from_msg(msg: Any) -> Twist2D:
    """The planar part of a ``geometry_msgs/Twist``."""
    return Twist2D(float(msg.linear.x), float(msg.linear.y), float(msg.angular.z))


# ------------------------------------------------------------------------------------- laser


def laser_scan_from_msg(msg: Any, pose: Pose2D | None = None) -> LaserScan:
    """A ``sensor_msgs/LaserScan`` as a core :class:`LaserScan`.

    ``pose`` is the laser's pose in the map frame at the scan's time (the caller looks it up in
    tf); the default is the laser's own frame. Every range that is not a finite value in
    ``[range_min, range_max]`` becomes ``inf`` (see the module docstring). ``angle_min``,
    ``angle_increment`` and the number of beams come from the message (``angle_max`` is not used).
    """
    r = np.array(msg.ranges, dtype=float)
    lo, hi = float(msg.range_min), float(msg.range_max)
    with np.errstate(invalid="ignore"):
        bad = ~np.isfinite(r) | (r < max(lo, 1e-6)) | (r > hi)
    r[bad] = np.inf
    return LaserScan(
        stamp=time_to_sec(msg.header.stamp),
        angle_min=float(msg.angle_min),
        angle_increment=float(msg.angle_increment),
        range_min=lo,
        range_max=hi,
        ranges=r,
        pose=pose if pose is not None else Pose2D(0.0, 0.0, 0.0),
    )


def laser_scan_to_msg(scan: LaserScan, frame_id: str = "base_range_sensor_link") -> Any:
    """A core :class:`LaserScan` as a ``sensor_msgs/LaserScan`` in ``frame_id`` (its ``pose`` is
    not part of the message: publish it on tf). Non-returns are sent as ``+inf``."""
    r = np.asarray(scan.ranges, dtype=float)
    out = np.where(np.isfinite(r), r, np.inf)
    n = len(out)
    return _msg("sensor_msgs.msg", "LaserScan")(
        header=_header(scan.stamp, frame_id),
        angle_min=float(scan.angle_min),
        angle_max=float(scan.angle_min + scan.angle_increment * max(n - 1, 0)),
        angle_increment=float(scan.angle_increment),
        time_increment=0.0,
        scan_time=0.0,
        range_min=float(scan.range_min),
        range_max=float(scan.range_max),
        ranges=[float(v) for v in out],
        intensities=[],
    )


# ------------------------------------------------------------------------------------ images

_COLOUR = {"rgb8": 3, "bgr8": 3, "rgba8": 4, "bgra8": 4}


def _pixels(msg: Any, dtype: np.dtype, channels: int) -> np.ndarray:
    """The pixels as ``(h, w, channels)`` of ``dtype``, honouring ``step`` and endianness."""
    dt = np.dtype(dtype).newbyteorder(">" if msg.is_bigendian else "<")
    h, w, step = int(msg.height), int(msg.width), int(msg.step)
    raw = np.frombuffer(bytes(msg.data), dtype=np.uint8)
    if raw.size < h * step:
        raise ValueError(
            f"image data has {raw.size} bytes, expected {h * step} ({h} rows of {step})"
        )
    row_bytes = w * channels * dt.itemsize
    rows = raw[: h * step].reshape(h, step)[:, :row_bytes]
    return np.ascontiguousarray(rows).view(dt).reshape(h, w, channels).astype(dt.newbyteorder("="))


def rgb_from_image(msg: Any) -> np.ndarray:
    """A colour ``sensor_msgs/Image`` (``rgb8``, ``bgr8``, ``rgba8``, ``bgra8``) as core's
    ``(h, w, 3) uint8`` RGB."""
    enc = msg.encoding
    if enc not in _COLOUR:
        raise ValueError(f"unsupported colour encoding {enc!r} (expected one of {sorted(_COLOUR)})")
    px = _pixels(msg, np.uint8, _COLOUR[enc])[:, :, :3]
    if enc.startswith("bgr"):
        px = px[:, :, ::-1]
    return np.ascontiguousarray(px)


def rgb_to_image(
    rgb: np.ndarray, stamp: float | None = None, frame_id: str = "", encoding: str = "rgb8"
) -> Any:
    """A core ``(h, w, 3) uint8`` RGB array as a ``sensor_msgs/Image`` in ``rgb8`` or ``bgr8``."""
    if encoding not in ("rgb8", "bgr8"):
        raise ValueError(f"unsupported colour encoding {encoding!r} (expected rgb8 or bgr8)")
    px = np.asarray(rgb, dtype=np.uint8)
    if px.ndim != 3 or px.shape[2] != 3:
        raise ValueError(f"expected an (h, w, 3) array, got shape {px.shape}")
    if encoding == "bgr8":
        px = px[:, :, ::-1]
    h, w = px.shape[:2]
    return _msg("sensor_msgs.msg", "Image")(
        header=_header(stamp, frame_id),
        height=h,
        width=w,
        encoding=encoding,
        is_bigendian=0,
        step=w * 3,
        data=np.ascontiguousarray(px).tobytes(),
    )


def depth_from_image(msg: Any) -> np.ndarray:
    """A depth ``sensor_msgs/Image`` as core's ``(h, w) float32`` metres, ``inf`` = no return.

    ``16UC1`` (also ``mono16``) is millimetres with 0 = no return; ``32FC1`` is metres with NaN,
    non-positive or infinite values = no return.
    """
    enc = msg.encoding
    if enc in ("16UC1", "mono16"):
        mm = _pixels(msg, np.uint16, 1)[:, :, 0]
        depth = mm.astype(np.float32) / np.float32(1000.0)
        depth[mm == 0] = np.inf
        return depth
    if enc == "32FC1":
        depth = _pixels(msg, np.float32, 1)[:, :, 0].astype(np.float32)
        with np.errstate(invalid="ignore"):
            depth[~np.isfinite(depth) | (depth <= 0)] = np.inf
        return depth
    raise ValueError(f"unsupported depth encoding {enc!r} (expected 16UC1 or 32FC1)")


def depth_to_image(
    depth: np.ndarray, stamp: float | None = None, frame_id: str = "", encoding: str = "32FC1"
) -> Any:
    """Core depth (``float32`` metres, ``inf`` = no return) as a ``sensor_msgs/Image``:
    ``32FC1`` metres with NaN for no return, or ``16UC1`` millimetres (rounded) with 0 for no
    return (and for depths beyond 65.535 m, which 16 bits cannot hold)."""
    z = np.asarray(depth, dtype=np.float64)
    if z.ndim != 2:
        raise ValueError(f"expected an (h, w) depth array, got shape {z.shape}")
    none = ~np.isfinite(z) | (z <= 0)
    if encoding == "32FC1":
        data = np.where(none, np.nan, z).astype("<f4")
        itemsize = 4
    elif encoding == "16UC1":
        mm = np.rint(np.where(none, 0.0, z) * 1000.0)
        mm[mm > 65535] = 0
        data = mm.astype("<u2")
        itemsize = 2
    else:
        raise ValueError(f"unsupported depth encoding {encoding!r} (expected 16UC1 or 32FC1)")
    h, w = z.shape
    return _msg("sensor_msgs.msg", "Image")(
        header=_header(stamp, frame_id),
        height=h,
        width=w,
        encoding=encoding,
        is_bigendian=0,
        step=w * itemsize,
        data=np.ascontiguousarray(data).tobytes(),
    )


def camera_info_from_msg(msg: Any) -> CameraInfo:
    """A ``sensor_msgs/CameraInfo`` as core :class:`CameraInfo` (size, ``K``, frame)."""
    k = tuple(float(v) for v in msg.K)
    if len(k) != 9:
        raise ValueError(f"CameraInfo.K has {len(k)} values, expected 9")
    return CameraInfo(
        width=int(msg.width), height=int(msg.height), K=k, frame_id=msg.header.frame_id
    )


def camera_info_to_msg(info: CameraInfo, stamp: float | None = None) -> Any:
    """Core :class:`CameraInfo` as a distortion-free ``sensor_msgs/CameraInfo`` (``K``, identity
    ``R``, ``P = [K | 0]``)."""
    k = [float(v) for v in info.K]
    p = [k[0], k[1], k[2], 0.0, k[3], k[4], k[5], 0.0, k[6], k[7], k[8], 0.0]
    return _msg("sensor_msgs.msg", "CameraInfo")(
        header=_header(stamp, info.frame_id),
        height=int(info.height),
        width=int(info.width),
        distortion_model="plumb_bob",
        D=[0.0] * 5,
        K=k,
        R=[1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
        P=p,
    )


# -------------------------------------------------------------------------------------- head


def joint_positions(msg: Any, names: Sequence[str]) -> tuple[float, ...] | None:
    """The positions of ``names`` (in that order) in a ``sensor_msgs/JointState`` that may list
    other joints in any order; None if one of them is missing (a partial JointState)."""
    index = {name: i for i, name in enumerate(msg.name)}
    if any(n not in index or index[n] >= len(msg.position) for n in names):
        return None
    return tuple(float(msg.position[index[n]]) for n in names)


def head_state_from_joint_state(msg: Any) -> HeadState | None:
    """The head's pan/tilt from a ``sensor_msgs/JointState`` (``head_pan_joint``,
    ``head_tilt_joint``), or None if the message does not carry both."""
    pos = joint_positions(msg, HEAD_JOINTS)
    return None if pos is None else HeadState(pan=pos[0], tilt=pos[1])


def joint_state_msg(
    positions: dict[str, float], stamp: float | None = None, frame_id: str = ""
) -> Any:
    """A ``sensor_msgs/JointState`` with the given joint positions (no velocities/efforts)."""
    return _msg("sensor_msgs.msg", "JointState")(
        header=_header(stamp, frame_id),
        name=list(positions),
        position=[float(v) for v in positions.values()],
        velocity=[],
        effort=[],
    )


def head_target_to_trajectory(
    target: HeadTarget, duration: float = 0.5, stamp: float | None = None
) -> Any:
    """A ``trajectory_msgs/JointTrajectory`` moving ``head_pan_joint``/``head_tilt_joint`` to the
    target in ``duration`` seconds (for ``/hsrb/head_trajectory_controller/command``). With no
    ``stamp`` the header stamp is zero, which controllers read as "start now"."""
    point = _msg("trajectory_msgs.msg", "JointTrajectoryPoint")(
        positions=[float(target.pan), float(target.tilt)],
        velocities=[0.0, 0.0],
        time_from_start=sec_to_duration(duration),
    )
    return _msg("trajectory_msgs.msg", "JointTrajectory")(
        header=_header(stamp, ""), joint_names=list(HEAD_JOINTS), points=[point]
    )


def head_target_from_trajectory(msg: Any) -> HeadTarget | None:
    """The last point's head pan/tilt of a ``trajectory_msgs/JointTrajectory``; None if it has no
    point or lacks a head joint (the bridge's side of :func:`head_target_to_trajectory`)."""
    if not msg.points:
        return None
    index = {name: i for i, name in enumerate(msg.joint_names)}
    last = msg.points[-1].positions
    if any(n not in index or index[n] >= len(last) for n in HEAD_JOINTS):
        return None
    return HeadTarget(
        pan=float(last[index[HEAD_PAN_JOINT]]), tilt=float(last[index[HEAD_TILT_JOINT]])
    )


# ---------------------------------------------------------------------------------- navigation


def nav_status_from_goal_status(status: int | None) -> NavStatus:
    """An ``actionlib_msgs/GoalStatus.status`` (or actionlib's ``get_state()``) as
    :class:`NavStatus`; None (no goal yet) is IDLE.

    REJECTED and LOST count as ABORTED; PREEMPTING, RECALLING and RECALLED (a cancel under way
    or done) as PREEMPTED.
    """
    if status is None:
        return NavStatus.IDLE
    try:
        return _GOAL_STATUS[int(status)]
    except KeyError:
        raise ValueError(f"unknown actionlib GoalStatus {status!r}") from None


def nav_status_to_goal_status(status: NavStatus) -> int | None:
    """:class:`NavStatus` as the ``actionlib_msgs/GoalStatus`` value a server reports (None for
    IDLE: there is no goal)."""
    return {
        NavStatus.PENDING: 0,
        NavStatus.ACTIVE: 1,
        NavStatus.PREEMPTED: 2,
        NavStatus.SUCCEEDED: 3,
        NavStatus.ABORTED: 4,
        NavStatus.IDLE: None,
    }[status]
