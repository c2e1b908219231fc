"""A small tf buffer: recorded transforms between named frames, looked up at a time.

It answers what ``tf2_ros.Buffer.lookup_transform(target, source, t)`` answers for a recorded
bag, without ROS: every ``/tf`` edge ``parent → child`` is kept as a time series of rigid
transforms (``/tf_static`` edges hold for all times), a lookup walks the frame tree from the
source up to the common ancestor and down to the target, and each edge is interpolated at ``t``
(translation linearly, rotation by spherical interpolation). Like tf, it refuses to extrapolate
beyond an edge's first or last sample by more than ``tolerance`` seconds.

Transforms are 4x4 homogeneous matrices ``T_parent_child``: a point in ``child`` coordinates maps
to ``parent`` coordinates as ``T @ [x, y, z, 1]``.
"""

from __future__ import annotations

import bisect
import math
from dataclasses import dataclass, field

import numpy as np

from pfctl.core.robot import Pose2D


class TransformLookupError(LookupError):
    """No transform between two frames at the asked time (the message says why)."""


def quaternion_matrix(x: float, y: float, z: float, w: float) -> np.ndarray:
    """The 3x3 rotation matrix of a quaternion (normalised first)."""
    n = math.sqrt(x * x + y * y + z * z + w * w) or 1.0
    x, y, z, w = x / n, y / n, z / n, w / n
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def yaw_from_quaternion(x: float, y: float, z: float, w: float) -> float:
    """The yaw (rad, about z; ZYX convention) of a unit quaternion ``(x, y, z, w)``:
    ``atan2(2(wz + xy), 1 − 2(y² + z²))``."""
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def quaternion_from_yaw(yaw: float) -> tuple[float, float, float, float]:
    """The unit quaternion ``(x, y, z, w)`` of a rotation by ``yaw`` (rad) about z."""
    return (0.0, 0.0, math.sin(yaw / 2.0), math.cos(yaw / 2.0))


def _slerp(q0: np.ndarray, q1: np.ndarray, s: float) -> np.ndarray:
    dot = float(np.dot(q0, q1))
    if dot < 0.0:  # the shorter way round
        q1, dot = -q1, -dot
    if dot > 0.9995:
        q = q0 + s * (q1 - q0)
    else:
        theta = math.acos(dot)
        q = (math.sin((1 - s) * theta) * q0 + math.sin(s * theta) * q1) / math.sin(theta)
    return q / np.linalg.norm(q)


def _matrix(translation: np.ndarray, quaternion: np.ndarray) -> np.ndarray:
    m = np.eye(4)
    m[:3, :3] = quaternion_matrix(*quaternion)
    m[:3, 3] = translation
    return m


@dataclass
class _Edge:
    stamps: list[float] = field(default_factory=list)
    translations: list[np.ndarray] = field(default_factory=list)
    quaternions: list[np.ndarray] = field(default_factory=list)
    static: bool = False

    def add(self, stamp: float, translation: np.ndarray, quaternion: np.ndarray) -> None:
        if self.static:
            self.stamps, self.translations, self.quaternions = [stamp], [translation], [quaternion]
            return
        i = bisect.bisect_right(self.stamps, stamp)
        if i > 0 and self.stamps[i - 1] == stamp:  # a repeated stamp replaces the sample
            self.translations[i - 1], self.quaternions[i - 1] = translation, quaternion
            return
        self.stamps.insert(i, stamp)
        self.translations.insert(i, translation)
        self.quaternions.insert(i, quaternion)

    def at(self, t: float, tolerance: float, name: str) -> np.ndarray:
        if self.static or (len(self.stamps) == 1 and abs(t - self.stamps[0]) <= tolerance):
            return _matrix(self.translations[0], self.quaternions[0])
        first, last = self.stamps[0], self.stamps[-1]
        if t < first - tolerance or t > last + tolerance:
            raise TransformLookupError(
                f"no transform {name} at t={t:.3f} (recorded from {first:.3f} to {last:.3f})"
            )
        i = bisect.bisect_left(self.stamps, t)
        if i <= 0:
            return _matrix(self.translations[0], self.quaternions[0])
        if i >= len(self.stamps):
            return _matrix(self.translations[-1], self.quaternions[-1])
        t0, t1 = self.stamps[i - 1], self.stamps[i]
        s = (t - t0) / (t1 - t0)
        translation = (1 - s) * self.translations[i - 1] + s * self.translations[i]
        return _matrix(translation, _slerp(self.quaternions[i - 1], self.quaternions[i], s))


class TransformBuffer:
    """Recorded transforms between frames (a tree, as in tf), looked up at a time."""

    def __init__(self, tolerance: float = 0.2) -> None:
        """``tolerance``: how far (s) a lookup may reach beyond an edge's recorded samples."""
        self.tolerance = tolerance
        self._parent: dict[str, str] = {}
        self._edges: dict[str, _Edge] = {}

    @property
    def frames(self) -> set[str]:
        """Every frame seen, as parent or child."""
        return set(self._parent) | set(self._parent.values())

    def add(
        self,
        parent: str,
        child: str,
        stamp: float,
        translation: tuple[float, float, float],
        quaternion: tuple[float, float, float, float],
        *,
        static: bool = False,
    ) -> None:
        """Record ``T_parent_child`` at ``stamp`` (a child's latest parent wins, as in tf)."""
        parent, child = parent.lstrip("/"), child.lstrip("/")
        if self._parent.get(child) != parent:
            self._parent[child] = parent
            self._edges[child] = _Edge(static=static)
        self._edges[child].add(
            float(stamp), np.asarray(translation, float), np.asarray(quaternion, float)
        )

    def _chain(self, frame: str) -> list[str]:
        chain = [frame]
        while chain[-1] in self._parent and len(chain) <= len(self._parent) + 1:
            chain.append(self._parent[chain[-1]])
        return chain

    def lookup(self, target: str, source: str, t: float) -> np.ndarray:
        """``T_target_source`` at time ``t`` (4x4): maps ``source`` coordinates into ``target``."""
        target, source = target.lstrip("/"), source.lstrip("/")
        if target == source:
            return np.eye(4)
        up, down = self._chain(source), self._chain(target)
        common = next((f for f in up if f in down), None)
        if common is None:
            known = ", ".join(sorted(self.frames)) or "none"
            raise TransformLookupError(
                f"frames {target!r} and {source!r} are not connected by tf (frames: {known})"
            )
        t_common_source = np.eye(4)
        for child in up[: up.index(common)]:
            edge = self._edges[child].at(t, self.tolerance, f"{self._parent[child]}→{child}")
            t_common_source = edge @ t_common_source
        t_common_target = np.eye(4)
        for child in down[: down.index(common)]:
            edge = self._edges[child].at(t, self.tolerance, f"{self._parent[child]}→{child}")
            t_common_target = edge @ t_common_target
        return np.linalg.inv(t_common_target) @ t_common_source

    def lookup_pose2d(self, target: str, source: str, t: float) -> Pose2D:
        """The planar pose of ``source`` in ``target`` at ``t`` (x, y and the yaw of its x-axis)."""
        m = self.lookup(target, source, t)
        return Pose2D(float(m[0, 3]), float(m[1, 3]), math.atan2(m[1, 0], m[0, 0]))


__all__ = [
    "TransformBuffer",
    "TransformLookupError",
    "quaternion_from_yaw",
    "quaternion_matrix",
    "yaw_from_quaternion",
]
