"""Reading recorded ROS 1 and ROS 2 bags without ROS (``rosbags``), as core value types.

:func:`open_bag` opens a ROS 1 ``.bag`` file (message types from the ROS1_NOETIC typestore) or a
ROS 2 bag (a directory, or its ``.mcap``/``.db3`` file; types from the bag, else ROS2_HUMBLE)
with rosbags' ``AnyReader``. The :class:`Bag` lists its topics and iterates:

- :meth:`Bag.scans`: ``sensor_msgs/LaserScan`` as ``(frame_id, LaserScan)``; the scan's pose is
  ``Pose2D(0, 0, 0)``, i.e. the points are in the scan's own frame (a caller with ``/tf`` puts
  it in the map). Ranges without a valid return (NaN, ±inf, 0, outside the range window) become
  ``inf`` (REP-117 as the core reads it).
- :meth:`Bag.pose_arrays`: ``geometry_msgs/PoseArray`` as :class:`PoseArrayMessage`.
- :meth:`Bag.messages`: any topics, deserialised, in bag order (for callers that interleave
  topics, e.g. labels that precede their scan).

Every problem with the file is a :class:`~pfctl.errors.UserError` of one line naming the bag:
missing file, a file that is not a bag or is damaged, a missing topic (with the topics the bag
does have) or a topic of another message type.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path
from types import TracebackType
from typing import Any

import numpy as np

from pfctl.core.robot import LaserScan, Pose2D
from pfctl.core.tf_buffer import yaw_from_quaternion
from pfctl.errors import UserError

LASER_SCAN = "sensor_msgs/msg/LaserScan"
POSE_ARRAY = "geometry_msgs/msg/PoseArray"
PERSON = "leg_tracker/msg/Person"
#: ``leg_tracker/Person`` (Leigh et al.'s annotated tracks): not in the standard type stores, so
#: registered from its definition (a bag that carries the definition gives the same type).
PERSON_DEFINITION = "geometry_msgs/Pose pose\nuint32 id\n"


class BagError(UserError):
    """A bag that cannot be read as asked (one line naming the bag)."""


@dataclass(frozen=True)
class BagMessage:
    """One deserialised message: topic, type, bag time (s) and the rosbags message object."""

    topic: str
    msgtype: str
    time: float
    msg: Any


@dataclass(frozen=True)
class PoseArrayMessage:
    """A ``geometry_msgs/PoseArray``: header stamp (s), frame and poses ``(n, 3)`` x, y, yaw."""

    stamp: float
    frame_id: str
    poses: np.ndarray


def _one_line(err: BaseException) -> str:
    text = " ".join(str(err).split())
    return text or type(err).__name__


def stamp_seconds(header: Any) -> float:
    """A ``std_msgs/Header`` stamp in seconds."""
    return float(header.stamp.sec) + float(header.stamp.nanosec) * 1e-9


def laser_scan(msg: Any) -> tuple[str, LaserScan]:
    """A deserialised ``sensor_msgs/LaserScan`` as ``(frame_id, LaserScan)`` in its own frame."""
    r = np.array(msg.ranges, dtype=float)
    lo, hi = float(msg.range_min), float(msg.range_max)
    with np.errstate(invalid="ignore"):
        bad = ~np.isfinite(r) | (r < max(lo, 1e-6)) | (r > hi)
    r[bad] = np.inf
    scan = LaserScan(
        stamp=stamp_seconds(msg.header),
        angle_min=float(msg.angle_min),
        angle_increment=float(msg.angle_increment),
        range_min=lo,
        range_max=hi,
        ranges=r,
        pose=Pose2D(0.0, 0.0, 0.0),
    )
    return str(msg.header.frame_id), scan


def pose_array(msg: Any) -> PoseArrayMessage:
    """A deserialised ``geometry_msgs/PoseArray`` as :class:`PoseArrayMessage`."""
    rows = []
    for p in msg.poses:
        q = p.orientation
        rows.append((p.position.x, p.position.y, yaw_from_quaternion(q.x, q.y, q.z, q.w)))
    poses = np.array(rows, dtype=float).reshape(-1, 3)
    return PoseArrayMessage(stamp_seconds(msg.header), str(msg.header.frame_id), poses)


class Bag:
    """An open bag; use as a context manager (``with open_bag(path) as bag``)."""

    def __init__(self, path: Path) -> None:
        from rosbags.highlevel import AnyReader
        from rosbags.typesys import Stores, get_types_from_msg, get_typestore

        self.path = Path(path)
        if not self.path.exists():
            raise BagError(f"{self.path}: no such bag file")
        if self.path.is_dir() and not (self.path / "metadata.yaml").is_file():
            raise BagError(_not_a_bag_folder(self.path))
        ros1 = self.path.is_file() and self.path.suffix == ".bag"
        store = get_typestore(Stores.ROS1_NOETIC if ros1 else Stores.ROS2_HUMBLE)
        store.register(get_types_from_msg(PERSON_DEFINITION, PERSON))
        try:
            self._reader = AnyReader([self.path], default_typestore=store)
            self._reader.open()
        except Exception as err:  # rosbags raises its own errors for a damaged bag
            raise BagError(f"{self.path}: cannot read the bag: {_one_line(err)}") from None
        self.topics: dict[str, str] = {c.topic: c.msgtype for c in self._reader.connections}
        """Topic → message type (``pkg/msg/Type``)."""

    def __enter__(self) -> Bag:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        self.close()

    def close(self) -> None:
        """Release the file."""
        self._reader.close()

    def require(self, topic: str, msgtype: str | None = None) -> None:
        """Raise :class:`BagError` unless the bag has ``topic`` (of ``msgtype``, if given)."""
        if topic not in self.topics:
            have = ", ".join(f"{t} ({m})" for t, m in sorted(self.topics.items())) or "none"
            raise BagError(f"{self.path}: no topic {topic}; the bag has: {have}")
        if msgtype is not None and self.topics[topic] != msgtype:
            raise BagError(
                f"{self.path}: topic {topic} is {self.topics[topic]}, expected {msgtype}"
            )

    def count(self, topic: str) -> int:
        """How many messages ``topic`` has."""
        return sum(c.msgcount for c in self._reader.connections if c.topic == topic)

    def messages(self, topics: Iterable[str]) -> Iterator[BagMessage]:
        """The messages of ``topics`` (each must exist), deserialised, in bag time order."""
        wanted = list(topics)
        for t in wanted:
            self.require(t)
        conns = [c for c in self._reader.connections if c.topic in wanted]
        try:
            for conn, ts, raw in self._reader.messages(connections=conns):
                msg = self._reader.deserialize(raw, conn.msgtype)
                yield BagMessage(conn.topic, conn.msgtype, ts * 1e-9, msg)
        except BagError:
            raise
        except Exception as err:
            raise BagError(f"{self.path}: cannot read the bag: {_one_line(err)}") from None

    def scans(self, topic: str) -> Iterator[tuple[str, LaserScan]]:
        """The ``sensor_msgs/LaserScan`` messages of ``topic`` as ``(frame_id, LaserScan)``."""
        self.require(topic, LASER_SCAN)
        for m in self.messages([topic]):
            yield laser_scan(m.msg)

    def pose_arrays(self, topic: str) -> Iterator[PoseArrayMessage]:
        """The ``geometry_msgs/PoseArray`` messages of ``topic``."""
        self.require(topic, POSE_ARRAY)
        for m in self.messages([topic]):
            yield pose_array(m.msg)


def _not_a_bag_folder(path: Path) -> str:
    """What a folder without a ROS 2 bag's ``metadata.yaml`` was expected to be."""
    message = (
        f"{path}: a folder but not a ROS 2 bag (no metadata.yaml); expected a ROS 1 .bag file, "
        "a ROS 2 bag folder or its .mcap/.db3 file"
    )
    episode_bag = path / "episode.bag"
    if episode_bag.is_file():
        message += f" (this looks like a pfctl recording: give {episode_bag})"
    return message


def open_bag(path: Path) -> Bag:
    """Open a ROS 1 or ROS 2 bag for reading; :class:`BagError` (one line) if it cannot be."""
    return Bag(Path(path))


def read_scans(path: Path, topic: str) -> list[tuple[str, LaserScan]]:
    """All scans of ``topic`` in the bag at ``path``."""
    with open_bag(path) as bag:
        return list(bag.scans(topic))


__all__ = [
    "LASER_SCAN",
    "PERSON",
    "PERSON_DEFINITION",
    "POSE_ARRAY",
    "Bag",
    "BagError",
    "BagMessage",
    "PoseArrayMessage",
    "laser_scan",
    "open_bag",
    "pose_array",
    "read_scans",
    "stamp_seconds",
]
