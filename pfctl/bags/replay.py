"""A recorded bag as the sensor stream the perception sees: scans and RGB-D frames in a fixed frame.

:func:`open_replay` looks at a ROS 1/2 bag (:mod:`pfctl.bags.reading`) and picks what to replay:

- the laser: ``--scan-topic``, or the bag's only ``sensor_msgs/LaserScan`` topic;
- the fixed frame: ``--frame``, else ``map`` or ``odom`` when the bag's ``/tf`` (and
  ``/tf_static``) has them, else the scan's own frame (a stationary laser);
- the camera, when the bag has an RGB ``sensor_msgs/Image`` topic, a depth image and a
  ``sensor_msgs/CameraInfo`` (the HSR's and the simulator's topic names, or any ``…rgb…image…`` /
  ``…depth…image…`` / ``…camera_info`` triple); images and depth pair up by stamp; a person-label
  image (``/pfctl/person_labels``, :mod:`pfctl.backends.hsr.person_labels`, as ``pfctl sim
  serve-hsr`` or a person detector on the robot publishes it) of the same stamp becomes the
  frame's ``mask``; without one, person keypoints (``/pfctl/person_keypoints``,
  ``sensor_msgs/PointCloud``, :mod:`pfctl.bags.person_keypoints`) of the same stamp
  become the frame's ``people``.

:meth:`Replay.stream` then yields :class:`~pfctl.core.robot.LaserScan` and
:class:`~pfctl.core.robot.RgbdFrame` values in bag order, posed in the fixed frame through the
recorded tf (a message whose transform is not available is skipped and counted).
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from pfctl.bags.person_keypoints import people_from_cloud
from pfctl.bags.reading import LASER_SCAN, Bag, BagError, laser_scan, open_bag, stamp_seconds
from pfctl.core.robot import CameraInfo, GivenPerson, LaserScan, Pose2D, RgbdFrame
from pfctl.core.tf_buffer import TransformBuffer, TransformLookupError
from pfctl.errors import UserError

IMAGE = "sensor_msgs/msg/Image"
CAMERA_INFO = "sensor_msgs/msg/CameraInfo"
POINT_CLOUD = "sensor_msgs/msg/PointCloud"
TF = "tf2_msgs/msg/TFMessage"
OCCUPANCY_GRID = "nav_msgs/msg/OccupancyGrid"
#: Camera topics tried first: the HSR's (Toyota's ROS 1 stack) and the simulator's recordings.
KNOWN_CAMERAS = (
    (
        "/hsrb/head_rgbd_sensor/rgb/image_rect_color",
        "/hsrb/head_rgbd_sensor/depth_registered/image_rect_raw",
        "/hsrb/head_rgbd_sensor/rgb/camera_info",
    ),
    (
        "/hsrb/head_rgbd_sensor/rgb/image_raw",
        "/hsrb/head_rgbd_sensor/depth/image_raw",
        "/hsrb/head_rgbd_sensor/rgb/camera_info",
    ),
)
#: An image and a depth image at most this far apart (s) are one RGB-D frame.
SYNC_SLOP = 0.02
#: Person labels (an instance/part image, :mod:`pfctl.backends.hsr.person_labels`) tried first.
KNOWN_LABELS = ("/pfctl/person_labels",)
#: Person keypoints (2-D keypoints/boxes, :mod:`pfctl.bags.person_keypoints`).
KNOWN_KEYPOINTS = ("/pfctl/person_keypoints",)


@dataclass(frozen=True)
class CameraTopics:
    """The three topics of an RGB-D camera."""

    rgb: str
    depth: str
    info: str
    labels: str | None = None
    """A 16UC1 person-label image of the same stamps (the frames' ``mask``), if the bag has one."""
    keypoints: str | None = None
    """Person keypoints of the same stamps (the frames' ``people``), if the bag has them and no
    labels."""

    def images(self) -> dict[str, str]:
        """The topics paired by stamp into one frame, by kind: ``rgb``, ``depth`` and, when
        known, ``labels`` or ``keypoints``."""
        kinds = {"rgb": self.rgb, "depth": self.depth}
        if self.labels is not None:
            kinds["labels"] = self.labels
        elif self.keypoints is not None:
            kinds["keypoints"] = self.keypoints
        return kinds


@dataclass
class Replay:
    """What will be replayed from an open bag (see the module docstring)."""

    bag: Bag
    scan_topic: str
    frame: str
    camera: CameraTopics | None
    tf: TransformBuffer
    grid: np.ndarray | None = None
    """The bag's last ``/map`` (``nav_msgs/OccupancyGrid``) values, ``(rows, cols)`` int8."""
    grid_origin: tuple[float, float] = (0.0, 0.0)
    grid_resolution: float = 0.0
    skipped: dict[str, int] = field(default_factory=dict)
    """Messages skipped per reason (no transform into the fixed frame, image without depth)."""

    def total(self) -> int:
        """How many messages :meth:`stream` reads (for a progress bar)."""
        topics = [self.scan_topic]
        if self.camera is not None:
            topics += [*self.camera.images().values(), self.camera.info]
        return sum(self.bag.count(t) for t in topics)

    def _skip(self, reason: str) -> None:
        self.skipped[reason] = self.skipped.get(reason, 0) + 1

    def stream(self) -> Iterator[LaserScan | RgbdFrame | None]:
        """Scans and RGB-D frames in bag order, posed in :attr:`frame`; ``None`` for each other
        message read (so a caller can advance a progress bar per message)."""
        topics = [self.scan_topic]
        cam = self.camera
        kinds: dict[str, str] = {}
        if cam is not None:
            kinds = {topic: kind for kind, topic in cam.images().items()}
            topics += [*kinds, cam.info]
        info: CameraInfo | None = None
        images: dict[str, tuple[float, Any]] = {}
        for m in self.bag.messages(topics):
            if m.topic == self.scan_topic:
                frame_id, scan = laser_scan(m.msg)
                pose = self._pose(frame_id, scan.stamp)
                yield None if pose is None else replace(scan, pose=pose)
                continue
            assert cam is not None
            if m.topic == cam.info:
                info = _camera_info(m.msg)
                yield None
                continue
            stamp = stamp_seconds(m.msg.header)
            images[kinds[m.topic]] = (stamp, m.msg)
            if len(images) < len(kinds) or any(
                abs(t - stamp) > SYNC_SLOP for t, _ in images.values()
            ):
                yield None
                continue
            msgs = {kind: msg for kind, (_, msg) in images.items()}
            images = {}
            if info is None:
                self._skip("frame before any camera_info")
                yield None
                continue
            frame = self._frame(msgs["rgb"], msgs["depth"], msgs.get("labels"), info)
            if frame is not None and "keypoints" in msgs:
                frame = replace(frame, people=self._people(msgs["keypoints"], frame))
            yield frame

    def _people(self, msg: Any, frame: RgbdFrame) -> tuple[GivenPerson, ...]:
        assert self.camera is not None and self.camera.keypoints is not None
        try:
            return people_from_cloud(msg, frame.depth.shape)
        except ValueError as err:
            raise UserError(f"{self.bag.path}: {self.camera.keypoints}: {err}") from None

    def _pose(self, frame_id: str, stamp: float) -> Pose2D | None:
        if frame_id.lstrip("/") == self.frame:
            return Pose2D(0.0, 0.0, 0.0)
        try:
            return self.tf.lookup_pose2d(self.frame, frame_id, stamp)
        except TransformLookupError:
            self._skip(f"no transform {self.frame} ← {frame_id}")
            return None

    def _frame(
        self, rgb_msg: Any, depth_msg: Any, labels_msg: Any | None, info: CameraInfo
    ) -> RgbdFrame | None:
        stamp = stamp_seconds(rgb_msg.header)
        frame_id = rgb_msg.header.frame_id
        try:
            m = self.tf.lookup(self.frame, frame_id, stamp)
        except TransformLookupError:
            self._skip(f"no transform {self.frame} ← {frame_id}")
            return None
        rgb = image_rgb(rgb_msg)
        depth = image_depth(depth_msg)
        if depth.shape != rgb.shape[:2]:
            self._skip("depth image of another size than the colour image")
            return None
        labels = None if labels_msg is None else image_labels(labels_msg)
        if labels is not None and labels.shape != rgb.shape[:2]:
            self._skip("person labels of another size than the colour image")
            return None
        x, y, z = (float(v) for v in m[:3, 3])
        return RgbdFrame(stamp, rgb, depth, info, (x, y, z), m[:3, :3].copy(), mask=labels)


def image_rgb(msg: Any) -> np.ndarray:
    """A ``sensor_msgs/Image`` in rgb8/bgr8/rgba8/bgra8/mono8 as ``(h, w, 3) uint8`` RGB."""
    enc = msg.encoding.lower()
    channels = {"rgb8": 3, "bgr8": 3, "rgba8": 4, "bgra8": 4, "mono8": 1}.get(enc)
    if channels is None:
        raise UserError(f"camera image encoding {msg.encoding!r} is not supported (rgb8, bgr8, …)")
    data = np.frombuffer(bytes(msg.data), dtype=np.uint8)
    rows = data.reshape(msg.height, msg.step)[:, : msg.width * channels]
    img = rows.reshape(msg.height, msg.width, channels)
    if channels == 1:
        return np.repeat(img, 3, axis=2)
    img = img[:, :, :3]
    return np.ascontiguousarray(img[:, :, ::-1] if enc.startswith("bgr") else img)


def image_depth(msg: Any) -> np.ndarray:
    """A depth ``sensor_msgs/Image`` (``32FC1`` metres or ``16UC1`` millimetres) as
    ``(h, w) float32`` metres, ``inf`` where there is no reading (0 or NaN)."""
    enc = msg.encoding.upper()
    if enc == "32FC1":
        dtype, scale = np.dtype(np.float32), 1.0
    elif enc in ("16UC1", "MONO16"):
        dtype, scale = np.dtype(np.uint16), 0.001
    else:
        raise UserError(f"depth image encoding {msg.encoding!r} is not supported (32FC1, 16UC1)")
    if msg.is_bigendian:
        dtype = dtype.newbyteorder(">")
    data = np.frombuffer(bytes(msg.data), dtype=np.uint8).reshape(msg.height, msg.step)
    row_bytes = msg.width * dtype.itemsize
    depth = data[:, :row_bytes].copy().view(dtype).reshape(msg.height, msg.width)
    out = depth.astype(np.float32) * np.float32(scale)
    out[~np.isfinite(out) | (out <= 0)] = np.inf
    return out


def image_labels(msg: Any) -> np.ndarray:
    """A ``16UC1``/``mono16`` person-label image as ``(h, w) int32``."""
    if msg.encoding.upper() not in ("16UC1", "MONO16"):
        raise UserError(f"person label encoding {msg.encoding!r} is not supported (16UC1)")
    dtype = np.dtype(">u2" if msg.is_bigendian else "<u2")
    data = np.frombuffer(bytes(msg.data), dtype=np.uint8).reshape(msg.height, msg.step)
    rows = data[:, : msg.width * 2].copy().view(dtype).reshape(msg.height, msg.width)
    return rows.astype(np.int32)


def _camera_info(msg: Any) -> CameraInfo:
    k = msg.K if hasattr(msg, "K") else msg.k  # ROS 1 spells it K, ROS 2 k
    a, b, c, d, e, f, g, h, i = (float(v) for v in k)
    return CameraInfo(
        int(msg.width), int(msg.height), (a, b, c, d, e, f, g, h, i), frame_id=msg.header.frame_id
    )


def _read_tf(bag: Bag) -> TransformBuffer:
    tf = TransformBuffer()
    topics = [t for t in ("/tf", "/tf_static") if bag.topics.get(t) == TF]
    if not topics:
        return tf
    for m in bag.messages(topics):
        for tr in m.msg.transforms:
            t, q = tr.transform.translation, tr.transform.rotation
            tf.add(
                tr.header.frame_id,
                tr.child_frame_id,
                stamp_seconds(tr.header),
                (t.x, t.y, t.z),
                (q.x, q.y, q.z, q.w),
                static=m.topic == "/tf_static",
            )
    return tf


def _find_camera(bag: Bag) -> CameraTopics | None:
    have = bag.topics
    labels = next((t for t in KNOWN_LABELS if have.get(t) == IMAGE), None)
    keypoints = None
    if labels is None:
        keypoints = next((t for t in KNOWN_KEYPOINTS if have.get(t) == POINT_CLOUD), None)
    for rgb, depth, info in KNOWN_CAMERAS:
        if have.get(rgb) == IMAGE and have.get(depth) == IMAGE and have.get(info) == CAMERA_INFO:
            return CameraTopics(rgb, depth, info, labels, keypoints)
    images = sorted(t for t, m in have.items() if m == IMAGE and t != labels)
    rgbs = [t for t in images if "rgb" in t or "color" in t]
    depths = [t for t in images if "depth" in t]
    infos = sorted(t for t, m in have.items() if m == CAMERA_INFO)
    if len(rgbs) == 1 and len(depths) == 1 and infos:
        ns = rgbs[0].rsplit("/", 1)[0]
        info = next((i for i in infos if i.startswith(ns)), infos[0])
        return CameraTopics(rgbs[0], depths[0], info, labels, keypoints)
    return None


def _read_grid(bag: Bag, replay: Replay) -> None:
    topic = "/map"
    if bag.topics.get(topic) != OCCUPANCY_GRID:
        return
    for m in bag.messages([topic]):
        info = m.msg.info
        values = np.asarray(m.msg.data, dtype=np.int8).reshape(info.height, info.width)
        replay.grid = values
        replay.grid_origin = (float(info.origin.position.x), float(info.origin.position.y))
        replay.grid_resolution = float(info.resolution)


def open_replay(
    path: Path, *, scan_topic: str | None = None, frame: str | None = None, camera: bool = True
) -> Replay:
    """Open ``path`` and decide what to replay; one-line :class:`UserError` when the bag has no
    such scan topic, several and none chosen, or no transform to the asked frame."""
    bag = open_bag(path)
    try:
        scans = sorted(t for t, m in bag.topics.items() if m == LASER_SCAN)
        if scan_topic is None:
            if len(scans) != 1:
                listed = ", ".join(scans) or "none"
                what = "several" if scans else "no"
                raise BagError(
                    f"{path}: {what} sensor_msgs/LaserScan topics ({listed}); "
                    "choose one with --scan-topic"
                )
            scan_topic = scans[0]
        bag.require(scan_topic, LASER_SCAN)
        tf = _read_tf(bag)
        scan_frame = _first_frame(bag, scan_topic)
        if frame is None:
            frame = next((f for f in ("map", "odom") if f in tf.frames), scan_frame)
        frame = frame.lstrip("/")
        if frame != scan_frame and frame not in tf.frames:
            known = ", ".join(sorted(tf.frames | {scan_frame}))
            raise BagError(f"{path}: --frame {frame}: the bag's tf has no such frame ({known})")
        replay = Replay(bag, scan_topic, frame, _find_camera(bag) if camera else None, tf)
        _read_grid(bag, replay)
        return replay
    except BaseException:
        bag.close()
        raise


def _first_frame(bag: Bag, topic: str) -> str:
    for m in bag.messages([topic]):
        return str(m.msg.header.frame_id).lstrip("/")
    raise BagError(f"{bag.path}: topic {topic} has no messages")


__all__ = [
    "CameraTopics",
    "Replay",
    "image_depth",
    "image_labels",
    "image_rgb",
    "open_replay",
]
