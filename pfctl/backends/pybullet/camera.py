"""The RGB-D camera on the simulated HSR's head (Xtion PRO LIVE: 58° horizontal field of view).

:class:`SimCamera` renders the PyBullet world with ``getCameraImage`` (TinyRenderer, so it runs
headless) from the optical centre on the head: the pan/tilt pivot stands ``mount_height`` above
the base centre and the optical centre sits ``forward_offset`` ahead of it along the view
direction. It returns an :class:`~pfctl.core.robot.RgbdFrame`:

- ``rgb`` ``(h, w, 3) uint8``;
- ``depth`` ``(h, w) float32``, metric z-depth along the optical axis (what a ROS depth image
  holds), linearised from the OpenGL depth buffer as ``z = f n / (f − (f − n) b)``, with
  Gaussian noise of std ``depth_noise · z²`` and ``inf`` outside ``[range_min, range_max]``;
- ``mask`` ``(h, w) int32``, the PyBullet body id seen at each pixel (``-1`` for none);
- ``info``, pinhole intrinsics like ``sensor_msgs/CameraInfo``: square pixels,
  ``fx = fy = (w / 2) / tan(hfov / 2)``, ``cx = w / 2 − 0.5``, ``cy = h / 2 − 0.5`` (pixel
  centres at integer coordinates), consistent with the OpenGL projection used to render.

Head angles follow the HSR: pan about z (left positive), tilt about the pan-rotated y axis with
negative looking down.
"""

from __future__ import annotations

import math

import numpy as np
import pybullet as p

from pfctl.backends.pybullet.config import CameraConfig
from pfctl.core.robot import CameraInfo, HeadState, Pose2D, RgbdFrame

#: Clipping planes of the renderer, metres (the depth window is applied afterwards).
NEAR_PLANE = 0.05
FAR_PLANE = 20.0


def camera_pose(
    base: Pose2D, head: HeadState, mount_height: float, forward_offset: float
) -> tuple[np.ndarray, np.ndarray]:
    """The optical centre ``(3,)`` and rotation ``(3, 3)`` in the map frame; the rotation's
    columns are the camera's x (right), y (down) and z (forward) axes."""
    yaw = base.theta + head.pan
    cy, sy = math.cos(yaw), math.sin(yaw)
    ct, st = math.cos(head.tilt), math.sin(head.tilt)
    forward = np.array([ct * cy, ct * sy, st])
    right = np.array([sy, -cy, 0.0])
    down = np.cross(forward, right)
    position = np.array([base.x, base.y, mount_height]) + forward_offset * forward
    return position, np.column_stack((right, down, forward))


def intrinsics(cfg: CameraConfig) -> CameraInfo:
    """The pinhole model of a camera config (see the module docstring)."""
    f = (cfg.width / 2.0) / math.tan(math.radians(cfg.hfov_deg) / 2.0)
    cx, cy = cfg.width / 2.0 - 0.5, cfg.height / 2.0 - 0.5
    return CameraInfo(cfg.width, cfg.height, (f, 0.0, cx, 0.0, f, cy, 0.0, 0.0, 1.0))


class SimCamera:
    """Renders RGB, metric depth and the segmentation mask of the world ``client``."""

    def __init__(self, client: int, cfg: CameraConfig, seed: int = 0) -> None:
        self.client = client
        self.cfg = cfg
        self.info = intrinsics(cfg)
        self._rng = np.random.default_rng(seed)
        vfov = 2.0 * math.degrees(
            math.atan(math.tan(math.radians(cfg.hfov_deg) / 2.0) * cfg.height / cfg.width)
        )
        self._projection = p.computeProjectionMatrixFOV(
            vfov, cfg.width / cfg.height, NEAR_PLANE, FAR_PLANE, physicsClientId=client
        )

    def pose(self, base: Pose2D, head: HeadState) -> tuple[np.ndarray, np.ndarray]:
        """The optical centre and rotation for a base pose and head angles."""
        return camera_pose(base, head, self.cfg.mount_height, self.cfg.forward_offset)

    def render(self, base: Pose2D, head: HeadState, stamp: float) -> RgbdFrame:
        """One frame from the camera on a robot at ``base`` with its head at ``head``."""
        cfg = self.cfg
        position, rotation = self.pose(base, head)
        forward, up = rotation[:, 2], -rotation[:, 1]
        view = p.computeViewMatrix(
            position.tolist(),
            (position + forward).tolist(),
            up.tolist(),
            physicsClientId=self.client,
        )
        _, _, rgba, buffer, seg = p.getCameraImage(
            cfg.width,
            cfg.height,
            view,
            self._projection,
            renderer=p.ER_TINY_RENDERER,
            shadow=0,
            lightDirection=[0.3, 0.2, 1.0],
            physicsClientId=self.client,
        )
        shape = (cfg.height, cfg.width)
        rgb = np.asarray(rgba, dtype=np.uint8).reshape(*shape, 4)[:, :, :3].copy()
        b = np.asarray(buffer, dtype=np.float64).reshape(shape)
        z = FAR_PLANE * NEAR_PLANE / (FAR_PLANE - (FAR_PLANE - NEAR_PLANE) * b)
        if cfg.depth_noise > 0:
            z = z + self._rng.normal(0.0, 1.0, shape) * cfg.depth_noise * z * z
        z[(b >= 1.0) | (z < cfg.range_min) | (z > cfg.range_max)] = np.inf
        mask = np.asarray(seg, dtype=np.int32).reshape(shape)
        return RgbdFrame(
            stamp=stamp,
            rgb=rgb,
            depth=z.astype(np.float32),
            info=self.info,
            camera_position=(float(position[0]), float(position[1]), float(position[2])),
            camera_rotation=rotation,
            mask=mask,
        )


__all__ = ["SimCamera", "camera_pose", "intrinsics"]
