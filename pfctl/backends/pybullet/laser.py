"""The base laser of the simulated HSR (Hokuyo: 270° at 0.25°, 1081 beams, 20 m, 40 Hz).

Two models behind one interface, ``scan(pose, legs, stamp) -> LaserScan``:

- :class:`FastLaser` (the default) casts the beams in 2-D with numpy: the walls and furniture do
  not move, so each beam is intersected with their outline segments in one matrix product, and
  with every leg circle ``[x, y, radius]`` analytically. Outlines of solid boxes are one-sided
  (a beam from outside meets a box's front faces first, so its back faces are dropped before the
  product), and the static ranges are reused while the laser does not move (``bench_sim.py``
  compares it with ``rayTestBatch``).
- :class:`BulletLaser` casts the same beams with PyBullet's ``rayTestBatch`` at the laser's mount
  height against every body in the world (walls, furniture, the people's leg cylinders). It is the
  reference the fast model is tested against, and the model to use when bodies other than legs
  (a table's legs, a box on the floor) should be seen.

Both add Gaussian range noise (``noise_std``) and follow REP-117: ``inf`` for no return within
``[range_min, range_max]``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pybullet as p

from pfctl.backends.pybullet.config import LaserConfig
from pfctl.core.robot import LaserScan, Pose2D


@dataclass(frozen=True)
class LaserSpec:
    """Beam geometry, mount and noise of the base laser (HSR Hokuyo defaults)."""

    angle_min: float = -np.deg2rad(135.0)
    angle_increment: float = np.deg2rad(0.25)
    beams: int = 1081
    range_min: float = 0.05
    range_max: float = 20.0
    noise_std: float = 0.0
    mount_x: float = 0.167
    mount_height: float = 0.19

    @classmethod
    def from_config(cls, cfg: LaserConfig) -> LaserSpec:
        """The spec of the simulated laser (field of view centred ahead)."""
        beams = math.floor(cfg.fov_deg / cfg.resolution_deg + 1e-9) + 1
        if cfg.fov_deg >= 360.0:
            beams -= 1  # a full circle: the last beam would repeat the first
        return cls(
            angle_min=-math.radians(cfg.fov_deg) / 2.0,
            angle_increment=math.radians(cfg.resolution_deg),
            beams=beams,
            range_min=cfg.range_min,
            range_max=cfg.range_max,
            noise_std=cfg.noise_std,
            mount_x=cfg.mount_x,
            mount_height=cfg.mount_height,
        )

    def laser_pose(self, pose: Pose2D) -> Pose2D:
        """The laser's map-frame pose for a base pose (mounted ``mount_x`` ahead of the centre)."""
        return pose.compose(Pose2D(self.mount_x, 0.0, 0.0))

    def directions(self, laser: Pose2D) -> np.ndarray:
        """Unit map-frame directions ``(beams, 2)`` of the beams from ``laser``."""
        ang = laser.theta + self.angle_min + self.angle_increment * np.arange(self.beams)
        return np.column_stack((np.cos(ang), np.sin(ang)))


class _Noisy:
    """Range noise, the REP-117 range window and the message, shared by both models."""

    def __init__(self, spec: LaserSpec, seed: int) -> None:
        self.spec = spec
        self._rng = np.random.default_rng(seed)

    def laser_pose(self, pose: Pose2D) -> Pose2D:
        return self.spec.laser_pose(pose)

    def _finish(self, ranges: np.ndarray, laser: Pose2D, stamp: float) -> LaserScan:
        sp = self.spec
        if sp.noise_std > 0:
            ranges = ranges + self._rng.normal(0.0, sp.noise_std, sp.beams)
        ranges[(ranges > sp.range_max) | (ranges < sp.range_min)] = np.inf
        return LaserScan(
            stamp=stamp,
            angle_min=sp.angle_min,
            angle_increment=sp.angle_increment,
            range_min=sp.range_min,
            range_max=sp.range_max,
            ranges=ranges,
            pose=laser,
        )


def ray_circle_ranges(origin: np.ndarray, d: np.ndarray, circles: np.ndarray) -> np.ndarray:
    """Distance along each unit ray ``d`` ``(n, 2)`` from ``origin`` to the nearest circle
    ``[x, y, radius]`` it enters (``inf`` if none)."""
    circles = np.asarray(circles, dtype=float).reshape(-1, 3)
    if len(circles) == 0:
        return np.full(len(d), np.inf)
    f = origin - circles[:, :2]  # (k, 2)
    b = d @ f.T  # (n, k)
    c = np.sum(f * f, axis=1) - circles[:, 2] ** 2  # (k,)
    disc = b * b - c[None, :]
    with np.errstate(invalid="ignore"):
        t = -b - np.sqrt(disc)
    return np.where((disc >= 0) & (t > 0), t, np.inf).min(axis=1)


class FastLaser(_Noisy):
    """Vectorised 2-D laser over ``segments`` ``(m, 4)`` rows ``[x0, y0, x1, y1]`` (map frame).

    With ``one_sided``, every segment belongs to the counter-clockwise outline of a solid body,
    so a beam can only enter it from its right-hand side; segments seen from behind are skipped.
    """

    def __init__(
        self,
        segments: np.ndarray,
        spec: LaserSpec | None = None,
        seed: int = 0,
        one_sided: bool = False,
    ) -> None:
        super().__init__(spec or LaserSpec(), seed)
        self.segments = np.asarray(segments, dtype=float).reshape(-1, 4)
        self.one_sided = one_sided
        self._cache: tuple[Pose2D, np.ndarray, np.ndarray] | None = None

    def static_ranges(self, laser: Pose2D) -> tuple[np.ndarray, np.ndarray]:
        """Beam directions ``(n, 2)`` and ranges to the static segments from the laser pose.

        Beam ``i`` with unit direction ``d`` meets segment ``p0 + u e`` at ``o + t d`` where
        ``t = (w × e) / (d × e)`` and ``u = (w × d) / (d × e)``, ``w = p0 − o``; both crosses
        with ``d`` come from one product of the beams with a ``(2, 2m)`` matrix.
        """
        if self._cache is not None and self._cache[0] == laser:
            return self._cache[1], self._cache[2]
        d = self.spec.directions(laser)
        o = np.array([laser.x, laser.y])
        best = np.full(len(d), np.inf)
        segs = self.segments
        if self.one_sided and len(segs):
            e = segs[:, 2:] - segs[:, :2]
            rel = o - segs[:, :2]
            segs = segs[e[:, 0] * rel[:, 1] - e[:, 1] * rel[:, 0] < 0]
        if len(segs):
            p0 = segs[:, :2]
            e = segs[:, 2:] - p0
            w = p0 - o
            m = len(segs)
            cross_we = w[:, 0] * e[:, 1] - w[:, 1] * e[:, 0]  # (m,)
            mat = np.empty((2, 2 * m))
            mat[0, :m], mat[1, :m] = e[:, 1], -e[:, 0]  # d × e
            mat[0, m:], mat[1, m:] = -w[:, 1], w[:, 0]  # w × d
            prod = d @ mat
            with np.errstate(divide="ignore", invalid="ignore"):
                inv = 1.0 / prod[:, :m]
                t = cross_we * inv
                u = prod[:, m:] * inv
            ok = (t > 0) & (u >= 0) & (u <= 1)
            best = np.where(ok, t, np.inf).min(axis=1)
        self._cache = (laser, d, best)
        return d, best

    def scan(self, pose: Pose2D, legs: np.ndarray, stamp: float) -> LaserScan:
        """One scan from base ``pose``; ``legs`` ``(k, 3)`` rows ``[x, y, radius]``."""
        laser = self.laser_pose(pose)
        d, static = self.static_ranges(laser)
        ranges = np.minimum(static, ray_circle_ranges(np.array([laser.x, laser.y]), d, legs))
        return self._finish(ranges, laser, stamp)


class BulletLaser(_Noisy):
    """The same laser by PyBullet's ``rayTestBatch`` against every body of ``client``.

    The bodies must be where they should be when :meth:`scan` is called (the people synced);
    ``legs`` is ignored, the leg cylinders are bodies in the world.
    """

    def __init__(self, client: int, spec: LaserSpec | None = None, seed: int = 0) -> None:
        super().__init__(spec or LaserSpec(), seed)
        self.client = client

    def scan(self, pose: Pose2D, legs: np.ndarray, stamp: float) -> LaserScan:
        sp = self.spec
        laser = self.laser_pose(pose)
        d = sp.directions(laser)
        z = sp.mount_height
        start = np.column_stack((np.full(sp.beams, laser.x), np.full(sp.beams, laser.y)))
        end = start + sp.range_max * d
        froms = np.column_stack((start, np.full(sp.beams, z)))
        tos = np.column_stack((end, np.full(sp.beams, z)))
        hits = p.rayTestBatch(froms.tolist(), tos.tolist(), physicsClientId=self.client)
        frac = np.array([h[2] if h[0] >= 0 else np.inf for h in hits])
        return self._finish(frac * sp.range_max, laser, stamp)


__all__ = ["BulletLaser", "FastLaser", "LaserSpec", "ray_circle_ranges"]
