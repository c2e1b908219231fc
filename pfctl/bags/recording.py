"""Recording a simulated episode as a ROS 1 bag (``rosbags``) and reading it back.

An episode directory holds

- ``episode.bag``: a ROS 1 bag (format 2.0, uncompressed) that ``rosbag info``, ``rqt_bag``,
  Foxglove Studio and ``rosbags`` open. Topics (frame ``map`` unless noted):

  ============================================  ==============================  =================
  topic                                         type                            from
  ============================================  ==============================  =================
  ``/hsrb/base_scan``                           sensor_msgs/LaserScan           observation
  ``/global_pose``                              geometry_msgs/PoseStamped       observation pose
  ``/hsrb/odom``                                nav_msgs/Odometry (``odom``)    odometry
  ``/hsrb/joint_states``                        sensor_msgs/JointState          head pan/tilt
  ``/tf``                                       tf2_msgs/TFMessage              map→odom
                                                                                →base_footprint
                                                                                →base_range_sensor
                                                                                (→head_rgbd_sensor
                                                                                _rgb_frame, 3-D,
                                                                                with images)
  ``/hsrb/head_rgbd_sensor/rgb/image_raw``      sensor_msgs/Image (rgb8)        ``images=True``
  ``/hsrb/head_rgbd_sensor/depth/image_raw``    sensor_msgs/Image (32FC1, m)    ``images=True``
  ``/hsrb/head_rgbd_sensor/rgb/camera_info``    sensor_msgs/CameraInfo          ``images=True``
  ``/cmd_vel``                                  geometry_msgs/Twist             truth.command
  ``/ground_truth/robot``                       geometry_msgs/PoseStamped       truth.robot
  ``/ground_truth/people``                      visualization_msgs/MarkerArray  truth.people
  ``/ground_truth/collisions``                  std_msgs/UInt32                 truth.collisions
  ============================================  ==============================  =================

  In ``/ground_truth/people`` each person is a CYLINDER marker whose ``ns`` is the person's name,
  whose colour is red for the target and blue for a distractor, and whose ``text`` reads
  ``"target speed=0.800"`` or ``"distractor speed=0.800"``.
- ``truth.csv``: the same ground truth as a flat table for fast plotting (one row per record and
  body: ``stamp,name,x,y,theta,speed,is_target,vx,vy,wz,collisions``; the robot's rows are named
  ``robot`` and carry the command and the collision count).
- ``episode.json``: mission name, duration, message counts per topic, the target's name.

The directory is assembled in a temporary sibling and moved into place by :meth:`close`, so an
error leaves nothing half-written (:meth:`abort` drops it).
"""

from __future__ import annotations

import contextlib
import csv
import io
import json
import math
import os
import re
import shutil
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from types import TracebackType
from typing import Any

import numpy as np
from rosbags.rosbag1 import Reader, Writer
from rosbags.typesys import Stores, get_types_from_msg, get_typestore
from scipy.spatial.transform import Rotation

from pfctl.core.robot import (
    GroundTruth,
    HeadState,
    LaserScan,
    Observation,
    PersonTruth,
    Pose2D,
    RgbdFrame,
    Twist2D,
)
from pfctl.core.tf_buffer import quaternion_from_yaw, yaw_from_quaternion

BAG_NAME = "episode.bag"
TRUTH_NAME = "truth.csv"
META_NAME = "episode.json"
MAP_FRAME = "map"
ODOM_FRAME = "odom"
BASE_FRAME = "base_footprint"
LASER_FRAME = "base_range_sensor_link"
CAMERA_FRAME = "head_rgbd_sensor_rgb_frame"

TOPICS: dict[str, str] = {
    "/hsrb/base_scan": "sensor_msgs/msg/LaserScan",
    "/global_pose": "geometry_msgs/msg/PoseStamped",
    "/hsrb/odom": "nav_msgs/msg/Odometry",
    "/hsrb/joint_states": "sensor_msgs/msg/JointState",
    "/tf": "tf2_msgs/msg/TFMessage",
    "/hsrb/head_rgbd_sensor/rgb/image_raw": "sensor_msgs/msg/Image",
    "/hsrb/head_rgbd_sensor/depth/image_raw": "sensor_msgs/msg/Image",
    "/hsrb/head_rgbd_sensor/rgb/camera_info": "sensor_msgs/msg/CameraInfo",
    "/cmd_vel": "geometry_msgs/msg/Twist",
    "/ground_truth/robot": "geometry_msgs/msg/PoseStamped",
    "/ground_truth/people": "visualization_msgs/msg/MarkerArray",
    "/ground_truth/collisions": "std_msgs/msg/UInt32",
}
IMAGE_TOPICS = (
    "/hsrb/head_rgbd_sensor/rgb/image_raw",
    "/hsrb/head_rgbd_sensor/depth/image_raw",
    "/hsrb/head_rgbd_sensor/rgb/camera_info",
)
_TF_MSG = "geometry_msgs/TransformStamped[] transforms\n"
_PERSON_TEXT = re.compile(r"^(target|distractor) speed=([-+0-9.eE]+)$")


# --------------------------------------------------------------------------------------------
# the encoding shared with ``pfctl sim serve-hsr`` (pure: no message library)


@dataclass(frozen=True)
class PersonMarker:
    """The fields of one person's ``visualization_msgs/Marker`` in ``/ground_truth/people``."""

    ns: str
    """The person's name."""
    id: int
    pose: Pose2D
    """Position and heading in the map frame."""
    z: float
    scale: tuple[float, float, float]
    color: tuple[float, float, float, float]
    """Red for the target, blue for a distractor (r, g, b, a)."""
    text: str
    """``"target speed=0.800"`` or ``"distractor speed=0.800"``."""
    lifetime: float
    """Seconds."""
    type: int = 3  # CYLINDER
    action: int = 0  # ADD


def person_marker(person: PersonTruth, index: int) -> PersonMarker:
    """The marker of ``person``, the ``index``-th of the truth's people (see the module doc)."""
    color = (0.85, 0.1, 0.1, 0.8) if person.is_target else (0.15, 0.35, 0.85, 0.8)
    return PersonMarker(
        ns=person.name,
        id=index,
        pose=Pose2D(person.x, person.y, person.theta),
        z=0.85,
        scale=(0.5, 0.5, 1.7),
        color=color,
        text=f"{'target' if person.is_target else 'distractor'} speed={person.speed:.3f}",
        lifetime=0.2,
    )


def person_from_marker(ns: str, pose: Pose2D, text: str) -> PersonTruth:
    """The person a marker of :func:`person_marker` encodes (its ``ns``, pose and ``text``)."""
    match = _PERSON_TEXT.match(text)
    return PersonTruth(
        name=ns,
        x=pose.x,
        y=pose.y,
        theta=pose.theta,
        speed=float(match.group(2)) if match else 0.0,
        is_target=bool(match and match.group(1) == "target"),
    )


def camera_in_base(
    frame: RgbdFrame, base: Pose2D
) -> tuple[tuple[float, float, float], tuple[float, float, float, float]]:
    """The optical frame of ``frame`` seen from the base at ``base`` (both in the map frame):
    the translation ``(x, y, z)`` and the rotation as a quaternion ``(x, y, z, w)`` of the
    ``base_footprint → head_rgbd_sensor_rgb_frame`` transform (z forward, x right, y down)."""
    map_base = np.eye(4)
    map_base[:2, :2] = [
        [math.cos(base.theta), -math.sin(base.theta)],
        [math.sin(base.theta), math.cos(base.theta)],
    ]
    map_base[:2, 3] = (base.x, base.y)
    map_camera = np.eye(4)
    map_camera[:3, :3] = frame.camera_rotation
    map_camera[:3, 3] = frame.camera_position
    base_camera = np.linalg.solve(map_base, map_camera)
    qx, qy, qz, qw = (float(v) for v in Rotation.from_matrix(base_camera[:3, :3]).as_quat())
    x, y, z = (float(v) for v in base_camera[:3, 3])
    return (x, y, z), (qx, qy, qz, qw)


class RecordingError(ValueError):
    """An episode directory that cannot be written or read (the message names the path)."""


def _typestore() -> Any:
    store = get_typestore(Stores.ROS1_NOETIC)
    store.register(get_types_from_msg(_TF_MSG, "tf2_msgs/msg/TFMessage"))
    return store


def _ns(stamp: float) -> int:
    return max(0, round(stamp * 1e9))


# --------------------------------------------------------------------------------------------
# writing


class EpisodeRecorder:
    """Write observations and ground truth of one episode into ``directory`` (see module doc).

    ``add`` takes one control tick; a scan or RGB-D frame is written only when the observation
    carries a new one. Use as a context manager or call :meth:`close` (or :meth:`abort`).
    """

    def __init__(self, directory: Path, mission_name: str, images: bool = False) -> None:
        self.directory = Path(directory)
        self.mission_name = mission_name
        self.images = images
        if self.directory.exists() and not self.directory.is_dir():
            raise RecordingError(f"{self.directory}: exists and is not a directory")
        parent = self.directory.absolute().parent
        try:
            parent.mkdir(parents=True, exist_ok=True)
            self._tmp = Path(tempfile.mkdtemp(prefix=f".{self.directory.name}.", dir=parent))
        except OSError as err:
            raise RecordingError(f"{self.directory}: cannot create: {err.strerror}") from None
        self._store = _typestore()
        self._writer = Writer(self._tmp / BAG_NAME)
        self._writer.open()
        self._conns = {
            topic: self._writer.add_connection(topic, msgtype, typestore=self._store)
            for topic, msgtype in TOPICS.items()
            if images or topic not in IMAGE_TOPICS
        }
        self._counts: dict[str, int] = dict.fromkeys(self._conns, 0)
        self._csv = io.StringIO()
        self._rows = csv.writer(self._csv, lineterminator="\n")
        self._rows.writerow(
            [
                "stamp",
                "name",
                "x",
                "y",
                "theta",
                "speed",
                "is_target",
                "vx",
                "vy",
                "wz",
                "collisions",
            ]
        )
        self._seq = 0
        self._first: float | None = None
        self._last = 0.0
        self._target: str | None = None
        self._open = True

    # -- message builders ------------------------------------------------------------------

    def _types(self) -> Any:
        return self._store.types

    def _header(self, stamp: float, frame: str) -> Any:
        t = self._types()
        ns = _ns(stamp)
        return t["std_msgs/msg/Header"](
            seq=self._seq,
            stamp=t["builtin_interfaces/msg/Time"](sec=ns // 10**9, nanosec=ns % 10**9),
            frame_id=frame,
        )

    def _pose(self, p: Pose2D, z: float = 0.0) -> Any:
        t = self._types()
        qx, qy, qz, qw = quaternion_from_yaw(p.theta)
        return t["geometry_msgs/msg/Pose"](
            position=t["geometry_msgs/msg/Point"](x=float(p.x), y=float(p.y), z=z),
            orientation=t["geometry_msgs/msg/Quaternion"](x=qx, y=qy, z=qz, w=qw),
        )

    def _transform(self, stamp: float, parent: str, child: str, p: Pose2D, z: float) -> Any:
        t = self._types()
        qx, qy, qz, qw = quaternion_from_yaw(p.theta)
        return t["geometry_msgs/msg/TransformStamped"](
            header=self._header(stamp, parent),
            child_frame_id=child,
            transform=t["geometry_msgs/msg/Transform"](
                translation=t["geometry_msgs/msg/Vector3"](x=float(p.x), y=float(p.y), z=z),
                rotation=t["geometry_msgs/msg/Quaternion"](x=qx, y=qy, z=qz, w=qw),
            ),
        )

    def _camera_transform(self, frame: RgbdFrame, base: Pose2D) -> Any:
        """``base_footprint → head_rgbd_sensor_rgb_frame`` (3-D: the optical frame, z forward)."""
        t = self._types()
        (x, y, z), (qx, qy, qz, qw) = camera_in_base(frame, base)
        return t["geometry_msgs/msg/TransformStamped"](
            header=self._header(frame.stamp, BASE_FRAME),
            child_frame_id=CAMERA_FRAME,
            transform=t["geometry_msgs/msg/Transform"](
                translation=t["geometry_msgs/msg/Vector3"](x=x, y=y, z=z),
                rotation=t["geometry_msgs/msg/Quaternion"](x=qx, y=qy, z=qz, w=qw),
            ),
        )

    def _write(self, topic: str, stamp: float, msg: Any) -> None:
        conn = self._conns[topic]
        data = self._store.serialize_ros1(msg, conn.msgtype)
        self._writer.write(conn, _ns(stamp), data)
        self._counts[topic] += 1

    # -- public API --------------------------------------------------------------------------

    def add(self, observation: Observation, truth: GroundTruth) -> None:
        """Record one tick: the observation's pose, head, new scan/frame and the ground truth."""
        if not self._open:
            raise RecordingError(f"{self.directory}: recorder already closed")
        t = self._types()
        stamp = float(truth.stamp)
        self._seq += 1
        self._first = stamp if self._first is None else self._first
        self._last = max(self._last, stamp, float(observation.stamp))
        obs = observation
        zero3 = t["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=0.0)
        cov = np.zeros(36, dtype=np.float64)
        self._write(
            "/global_pose",
            obs.stamp,
            t["geometry_msgs/msg/PoseStamped"](
                header=self._header(obs.stamp, MAP_FRAME), pose=self._pose(obs.pose)
            ),
        )
        if obs.odometry is not None:
            odom = t["nav_msgs/msg/Odometry"](
                header=self._header(obs.stamp, ODOM_FRAME),
                child_frame_id=BASE_FRAME,
                pose=t["geometry_msgs/msg/PoseWithCovariance"](
                    pose=self._pose(obs.odometry), covariance=cov
                ),
                twist=t["geometry_msgs/msg/TwistWithCovariance"](
                    twist=t["geometry_msgs/msg/Twist"](linear=zero3, angular=zero3),
                    covariance=cov,
                ),
            )
            self._write("/hsrb/odom", obs.stamp, odom)
        self._write(
            "/hsrb/joint_states",
            obs.stamp,
            t["sensor_msgs/msg/JointState"](
                header=self._header(obs.stamp, ""),
                name=["head_pan_joint", "head_tilt_joint"],
                position=np.array([obs.head.pan, obs.head.tilt], dtype=np.float64),
                velocity=np.zeros(0, dtype=np.float64),
                effort=np.zeros(0, dtype=np.float64),
            ),
        )
        if obs.odometry is not None:  # map → odom → base, as a localised ROS robot has it
            map_to_odom = obs.pose.compose(obs.odometry.inverse())
            transforms = [
                self._transform(obs.stamp, MAP_FRAME, ODOM_FRAME, map_to_odom, 0.0),
                self._transform(obs.stamp, ODOM_FRAME, BASE_FRAME, obs.odometry, 0.0),
            ]
        else:
            transforms = [self._transform(obs.stamp, MAP_FRAME, BASE_FRAME, obs.pose, 0.0)]
        if obs.scan is not None:
            self._add_scan(obs.scan, obs.pose)
            transforms.append(
                self._transform(
                    obs.scan.stamp, BASE_FRAME, LASER_FRAME, obs.pose.relative(obs.scan.pose), 0.0
                )
            )
        if obs.rgbd is not None and self.images:
            self._add_rgbd(obs.rgbd)
            transforms.append(self._camera_transform(obs.rgbd, obs.pose))
        self._write("/tf", obs.stamp, t["tf2_msgs/msg/TFMessage"](transforms=transforms))
        self._add_truth(truth)

    def _add_scan(self, scan: LaserScan, base: Pose2D) -> None:
        t = self._types()
        ranges = np.asarray(scan.ranges, dtype=np.float32)
        msg = t["sensor_msgs/msg/LaserScan"](
            header=self._header(scan.stamp, LASER_FRAME),
            angle_min=float(scan.angle_min),
            angle_max=float(scan.angle_min + scan.angle_increment * (len(ranges) - 1)),
            angle_increment=float(scan.angle_increment),
            time_increment=0.0,
            scan_time=0.0,
            range_min=float(scan.range_min),
            range_max=float(scan.range_max),
            ranges=ranges,
            intensities=np.zeros(0, dtype=np.float32),
        )
        self._write("/hsrb/base_scan", scan.stamp, msg)

    def _add_rgbd(self, frame: RgbdFrame) -> None:
        t = self._types()
        h, w = frame.rgb.shape[:2]
        rgb = np.ascontiguousarray(frame.rgb, dtype=np.uint8)
        depth = np.ascontiguousarray(frame.depth, dtype=np.float32)
        image = t["sensor_msgs/msg/Image"]
        self._write(
            IMAGE_TOPICS[0],
            frame.stamp,
            image(
                header=self._header(frame.stamp, CAMERA_FRAME),
                height=h,
                width=w,
                encoding="rgb8",
                is_bigendian=0,
                step=3 * w,
                data=rgb.reshape(-1),
            ),
        )
        self._write(
            IMAGE_TOPICS[1],
            frame.stamp,
            image(
                header=self._header(frame.stamp, CAMERA_FRAME),
                height=h,
                width=w,
                encoding="32FC1",
                is_bigendian=0,
                step=4 * w,
                data=depth.reshape(-1).view(np.uint8),
            ),
        )
        k = np.asarray(frame.info.K, dtype=np.float64)
        p = np.array([k[0], 0, k[2], 0, 0, k[4], k[5], 0, 0, 0, 1, 0], dtype=np.float64)
        self._write(
            IMAGE_TOPICS[2],
            frame.stamp,
            t["sensor_msgs/msg/CameraInfo"](
                header=self._header(frame.stamp, CAMERA_FRAME),
                height=frame.info.height,
                width=frame.info.width,
                distortion_model="plumb_bob",
                D=np.zeros(5, dtype=np.float64),
                K=k,
                R=np.eye(3, dtype=np.float64).reshape(-1),
                P=p,
                binning_x=0,
                binning_y=0,
                roi=t["sensor_msgs/msg/RegionOfInterest"](
                    x_offset=0, y_offset=0, height=0, width=0, do_rectify=False
                ),
            ),
        )

    def _add_truth(self, truth: GroundTruth) -> None:
        t = self._types()
        s = float(truth.stamp)
        cmd = truth.command
        self._write(
            "/ground_truth/robot",
            s,
            t["geometry_msgs/msg/PoseStamped"](
                header=self._header(s, MAP_FRAME), pose=self._pose(truth.robot)
            ),
        )
        vec = t["geometry_msgs/msg/Vector3"]
        self._write(
            "/cmd_vel",
            s,
            t["geometry_msgs/msg/Twist"](
                linear=vec(x=float(cmd.vx), y=float(cmd.vy), z=0.0),
                angular=vec(x=0.0, y=0.0, z=float(cmd.wz)),
            ),
        )
        self._write(
            "/ground_truth/collisions", s, t["std_msgs/msg/UInt32"](data=int(truth.collisions))
        )
        markers = []
        for i, person in enumerate(truth.people):
            if person.is_target:
                self._target = person.name
            m = person_marker(person, i)
            lifetime = _ns(m.lifetime)
            markers.append(
                t["visualization_msgs/msg/Marker"](
                    header=self._header(s, MAP_FRAME),
                    ns=m.ns,
                    id=m.id,
                    type=m.type,
                    action=m.action,
                    pose=self._pose(m.pose, z=m.z),
                    scale=vec(x=m.scale[0], y=m.scale[1], z=m.scale[2]),
                    color=t["std_msgs/msg/ColorRGBA"](
                        r=m.color[0], g=m.color[1], b=m.color[2], a=m.color[3]
                    ),
                    lifetime=t["builtin_interfaces/msg/Duration"](
                        sec=lifetime // 10**9, nanosec=lifetime % 10**9
                    ),
                    frame_locked=False,
                    points=[],
                    colors=[],
                    text=m.text,
                    mesh_resource="",
                    mesh_use_embedded_materials=False,
                )
            )
        self._write(
            "/ground_truth/people", s, t["visualization_msgs/msg/MarkerArray"](markers=markers)
        )
        r = truth.robot
        self._rows.writerow(
            [f"{s:.6f}", "robot", f"{r.x:.6f}", f"{r.y:.6f}", f"{r.theta:.6f}", "", ""]
            + [f"{v:.6f}" for v in (cmd.vx, cmd.vy, cmd.wz)]
            + [str(truth.collisions)]
        )
        for p in truth.people:
            self._rows.writerow(
                [f"{s:.6f}", p.name, *(f"{v:.6f}" for v in (p.x, p.y, p.theta, p.speed))]
                + [str(int(p.is_target))]
                + [""] * 4
            )

    def close(self) -> Path:
        """Finish the bag and the sidecars and move the episode into place; return the dir."""
        if not self._open:
            return self.directory
        try:
            self._writer.close()
            meta = {
                "format": "pfctl-episode-1",
                "mission": self.mission_name,
                "bag": BAG_NAME,
                "truth": TRUTH_NAME,
                "start": self._first if self._first is not None else 0.0,
                "end": self._last,
                "target": self._target,
                "messages": self._counts,
            }
            (self._tmp / TRUTH_NAME).write_text(self._csv.getvalue(), encoding="utf-8")
            (self._tmp / META_NAME).write_text(json.dumps(meta, indent=2) + "\n", encoding="utf-8")
            self._install()
        except BaseException:
            self.abort()
            raise
        self._open = False
        return self.directory

    def _install(self) -> None:
        target = self.directory
        try:
            if target.is_dir() and not any(target.iterdir()):
                target.rmdir()
            if not target.exists():
                os.replace(self._tmp, target)
                return
            for name in (BAG_NAME, TRUTH_NAME, META_NAME):
                os.replace(self._tmp / name, target / name)
            shutil.rmtree(self._tmp, ignore_errors=True)
        except OSError as err:
            raise RecordingError(f"{target}: cannot write the episode: {err.strerror}") from None

    def abort(self) -> None:
        """Drop everything written so far; the target directory is left as it was."""
        if self._open:
            self._open = False
            with contextlib.suppress(Exception):
                self._writer.close()
            shutil.rmtree(self._tmp, ignore_errors=True)

    def __enter__(self) -> EpisodeRecorder:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        if exc_type is None:
            self.close()
        else:
            self.abort()


# --------------------------------------------------------------------------------------------
# reading


@dataclass
class Episode:
    """An episode read back from its bag: observations (pose, head, scans) and ground truth."""

    mission_name: str
    truths: list[GroundTruth] = field(default_factory=list)
    poses: list[tuple[float, Pose2D]] = field(default_factory=list)
    """The map-frame poses the robot reported (``/global_pose``)."""
    odometry: list[tuple[float, Pose2D]] = field(default_factory=list)
    """The odom-frame poses of the wheel odometry (``/hsrb/odom``)."""
    heads: list[tuple[float, HeadState]] = field(default_factory=list)
    scans: list[LaserScan] = field(default_factory=list)
    images: int = 0
    """How many RGB frames the bag holds (they are not decoded here)."""

    @property
    def stamps(self) -> np.ndarray:
        return np.array([g.stamp for g in self.truths])

    @property
    def duration(self) -> float:
        return float(self.truths[-1].stamp - self.truths[0].stamp) if self.truths else 0.0

    @property
    def target(self) -> str | None:
        for g in self.truths:
            for p in g.people:
                if p.is_target:
                    return p.name
        return None

    def robot_path(self) -> np.ndarray:
        """The true robot positions ``(n, 2)``."""
        return np.array([(g.robot.x, g.robot.y) for g in self.truths]).reshape(-1, 2)

    def people_paths(self) -> dict[str, np.ndarray]:
        """Each person's true positions ``(n, 2)``, in order of first appearance."""
        out: dict[str, list[tuple[float, float]]] = {}
        for g in self.truths:
            for p in g.people:
                out.setdefault(p.name, []).append((p.x, p.y))
        return {k: np.array(v).reshape(-1, 2) for k, v in out.items()}


def _pose2d(pose: Any) -> Pose2D:
    q = pose.orientation
    return Pose2D(
        float(pose.position.x), float(pose.position.y), yaw_from_quaternion(q.x, q.y, q.z, q.w)
    )


def _tf_pose(tr: Any) -> Pose2D:
    t = tr.transform
    q = t.rotation
    return Pose2D(
        float(t.translation.x), float(t.translation.y), yaw_from_quaternion(q.x, q.y, q.z, q.w)
    )


def _stamp(header: Any) -> float:
    return header.stamp.sec + header.stamp.nanosec * 1e-9


def read_episode(directory: Path) -> Episode:
    """Read an episode directory written by :class:`EpisodeRecorder` back from its bag."""
    directory = Path(directory)
    bag = directory / BAG_NAME
    if not bag.is_file():
        raise RecordingError(f"{directory}: no {BAG_NAME} (expected an episode directory)")
    mission_name = ""
    meta_path = directory / META_NAME
    if meta_path.is_file():
        with contextlib.suppress(ValueError, OSError):
            mission_name = str(json.loads(meta_path.read_text(encoding="utf-8")).get("mission"))
    store = _typestore()
    by_time: dict[str, dict[int, Any]] = {}
    odom: list[tuple[float, Pose2D]] = []
    poses: list[tuple[float, Pose2D]] = []
    heads: list[tuple[float, HeadState]] = []
    laser_at: dict[float, Pose2D] = {}
    scans: list[Any] = []
    images = 0
    try:
        with Reader(bag) as reader:
            for conn, ts, raw in reader.messages():
                msg = store.deserialize_ros1(raw, conn.msgtype)
                topic = conn.topic
                if topic == "/hsrb/odom":
                    odom.append((_stamp(msg.header), _pose2d(msg.pose.pose)))
                elif topic == "/global_pose":
                    poses.append((_stamp(msg.header), _pose2d(msg.pose)))
                elif topic == "/hsrb/joint_states":
                    pos = dict(zip(msg.name, msg.position, strict=True))
                    heads.append(
                        (
                            _stamp(msg.header),
                            HeadState(
                                float(pos.get("head_pan_joint", 0.0)),
                                float(pos.get("head_tilt_joint", 0.0)),
                            ),
                        )
                    )
                elif topic == "/tf":
                    frames = {tr.child_frame_id: tr for tr in msg.transforms}
                    if LASER_FRAME in frames and BASE_FRAME in frames:
                        base = _tf_pose(frames[BASE_FRAME])
                        if ODOM_FRAME in frames:  # map → odom → base
                            base = _tf_pose(frames[ODOM_FRAME]).compose(base)
                        rel = _tf_pose(frames[LASER_FRAME])
                        laser_at[round(_stamp(frames[LASER_FRAME].header), 9)] = base.compose(rel)
                elif topic == "/hsrb/base_scan":
                    scans.append(msg)
                elif topic == IMAGE_TOPICS[0]:
                    images += 1
                else:
                    by_time.setdefault(topic, {})[ts] = msg
    except Exception as err:  # rosbags raises its own errors for a damaged bag
        raise RecordingError(f"{bag}: cannot read the bag: {err}") from None
    episode = Episode(
        mission_name=mission_name, poses=poses, odometry=odom, heads=heads, images=images
    )
    for msg in scans:
        s = _stamp(msg.header)
        episode.scans.append(
            LaserScan(
                stamp=s,
                angle_min=float(msg.angle_min),
                angle_increment=float(msg.angle_increment),
                range_min=float(msg.range_min),
                range_max=float(msg.range_max),
                ranges=np.asarray(msg.ranges, dtype=float),
                pose=laser_at.get(round(s, 9), Pose2D(0.0, 0.0, 0.0)),
            )
        )
    robots = by_time.get("/ground_truth/robot", {})
    for ts in sorted(robots):
        people = []
        markers = by_time.get("/ground_truth/people", {}).get(ts)
        for m in markers.markers if markers is not None else []:
            people.append(person_from_marker(m.ns, _pose2d(m.pose), m.text))
        cmd = by_time.get("/cmd_vel", {}).get(ts)
        col = by_time.get("/ground_truth/collisions", {}).get(ts)
        episode.truths.append(
            GroundTruth(
                stamp=_stamp(robots[ts].header),
                robot=_pose2d(robots[ts].pose),
                people=tuple(people),
                command=Twist2D(float(cmd.linear.x), float(cmd.linear.y), float(cmd.angular.z))
                if cmd is not None
                else Twist2D(),
                collisions=int(col.data) if col is not None else 0,
            )
        )
    return episode


__all__ = [
    "BAG_NAME",
    "META_NAME",
    "TOPICS",
    "TRUTH_NAME",
    "Episode",
    "EpisodeRecorder",
    "PersonMarker",
    "RecordingError",
    "camera_in_base",
    "person_from_marker",
    "person_marker",
    "read_episode",
]
