"""Labelled simulated laser scans for training and testing the leg detector (§II-E).

Each scan puts the laser at a random free spot of a random room of the house (walls
and furniture from :func:`~pfctl.backends.pybullet.world.build_world`), adds random furniture
around it (boxes, bins, and tables and chairs whose thin legs are the classic false positives
of a leg detector), places a crowd of 0–8 people 0.5–6 m from the laser (standing, legs side by
side or shifting weight, or walking with the legs apart and scissoring at any phase, facing
anywhere), and casts the beams with the simulator's :class:`~pfctl.backends.pybullet.laser.
FastLaser` with range noise and a few dropped returns, for one of several laser models
(:data:`LASERS`: the HSR's 0.25° Hokuyo, a 1/3° Hokuyo like the real data set's, a coarser 0.5°
one).

People's legs are :class:`~pfctl.backends.pybullet.walkers.Walker` legs (``Walker.legs()``),
:data:`~pfctl.backends.pybullet.walkers.LEG_RADIUS` scaled per person by 0.8–1.35 (thin legs to
wide trousers; the 2-D laser has no height, so the different mount heights of the lasers show
only as these different leg widths). The labels are the true leg circles ``[x, y, radius]`` in
the map frame: a segment is a leg when most of its returns lie on one
(:func:`pfctl.core.perception.legs.training.label_by_circles`).

Everything is seeded: the same seed gives the same scans.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any, cast

import numpy as np
import pybullet as p
import shapely
from shapely.geometry.polygon import orient

from pfctl.backends.pybullet.config import Clothes, HouseConfig
from pfctl.backends.pybullet.laser import FastLaser, LaserSpec
from pfctl.backends.pybullet.walkers import LEG_RADIUS, Walker
from pfctl.backends.pybullet.world import build_world, ccw_ring, outline
from pfctl.core.robot import LaserScan, Pose2D


@dataclass(frozen=True)
class LaserModel:
    """A laser to simulate: beam geometry, range noise and the share of dropped returns."""

    name: str
    spec: LaserSpec
    dropout: float = 0.003


def _spec(fov_deg: float, res_deg: float, height: float, range_max: float) -> LaserSpec:
    beams = math.floor(fov_deg / res_deg + 1e-9) + 1
    return LaserSpec(
        angle_min=-math.radians(fov_deg) / 2.0,
        angle_increment=math.radians(res_deg),
        beams=beams,
        range_min=0.05,
        range_max=range_max,
        mount_x=0.0,
        mount_height=height,
    )


#: The simulated lasers, drawn in turn: the HSR's, the real data set's, a coarse one.
LASERS: tuple[LaserModel, ...] = (
    LaserModel("hsr_0.25deg", _spec(270.0, 0.25, 0.19, 20.0)),
    LaserModel("hokuyo_1/3deg", _spec(270.0, 360.0 / 1024.0, 0.30, 11.0)),
    LaserModel("coarse_0.5deg", _spec(240.0, 0.5, 0.25, 8.0)),
)


@dataclass(frozen=True)
class LabelledScan:
    """One simulated scan (``pose``: the laser's map pose) and the true leg circles ``(k, 3)``
    ``[x, y, radius]`` in the map frame (every leg in the world, seen or not)."""

    scan: LaserScan
    legs: np.ndarray
    laser: str
    people: int


def _box(cx: float, cy: float, w: float, d: float, yaw: float) -> shapely.Polygon:
    c, s = math.cos(yaw), math.sin(yaw)
    corners = [(-w / 2, -d / 2), (w / 2, -d / 2), (w / 2, d / 2), (-w / 2, d / 2)]
    return shapely.Polygon([(cx + c * x - s * y, cy + s * x + c * y) for x, y in corners])


class LegScanGenerator:
    """Draws labelled scans in ``house``; :meth:`draw` takes a seeded rng."""

    def __init__(self, house: HouseConfig) -> None:
        client = p.connect(p.DIRECT)
        try:
            world = build_world(client, house)
        finally:
            p.disconnect(client)
        self.segments = world.scene.segments
        layout = house.layout
        rooms = [shapely.Polygon(r.polygon) for r in layout.regions]
        furniture = shapely.union_all([shapely.Polygon(o.polygon) for o in layout.obstacles])
        walls = shapely.union_all([shapely.LineString([s[:2], s[2:]]) for s in self.segments])
        self.rooms = rooms
        self.blocked = shapely.union_all([furniture, walls.buffer(0.01)])
        self.free = shapely.difference(shapely.union_all(rooms), self.blocked)
        self._areas = np.array([r.area for r in rooms])

    def _free_point(
        self, rng: np.random.Generator, room: shapely.Polygon, clearance: float
    ) -> np.ndarray | None:
        minx, miny, maxx, maxy = room.bounds
        for _ in range(50):
            pt = np.array([rng.uniform(minx, maxx), rng.uniform(miny, maxy)])
            if room.contains(shapely.Point(pt)) and self._clear(pt, clearance, ()):
                return pt
        return None

    def _clear(self, pt: np.ndarray, clearance: float, extra: tuple[shapely.Geometry, ...]) -> bool:
        point = shapely.Point(pt)
        if not self.free.contains(point) or self.blocked.distance(point) < clearance:
            return False
        return all(g.distance(point) >= clearance for g in extra)

    def draw(self, rng: np.random.Generator, laser: LaserModel | None = None) -> LabelledScan:
        """One labelled scan (a random laser of :data:`LASERS` unless given)."""
        laser = laser or LASERS[int(rng.integers(len(LASERS)))]
        room = self.rooms[int(rng.choice(len(self.rooms), p=self._areas / self._areas.sum()))]
        origin = None
        while origin is None:
            origin = self._free_point(rng, room, 0.35)
        pose = Pose2D(float(origin[0]), float(origin[1]), float(rng.uniform(-math.pi, math.pi)))
        boxes, poles = self._furniture(rng, pose)
        taken: list[shapely.Geometry] = [shapely.Point(origin).buffer(0.3), *boxes]
        taken += [shapely.Point(x, y).buffer(r) for x, y, r in poles]
        legs = self._people(rng, pose, laser.spec, taken)
        segs = [self.segments]
        for b in boxes:
            segs.append(np.array(outline(ccw_ring(orient(b, 1.0))), dtype=float))
        spec = _with_noise(laser.spec, float(rng.uniform(0.005, 0.025)))
        fast = FastLaser(np.vstack(segs), spec, seed=int(rng.integers(2**31)), one_sided=True)
        circles = np.vstack([legs.reshape(-1, 3), np.asarray(poles, dtype=float).reshape(-1, 3)])
        scan = _scan(fast, pose, circles, rng, laser.dropout)
        return LabelledScan(scan, legs, laser.name, len(legs) // 2)

    def _furniture(
        self, rng: np.random.Generator, pose: Pose2D
    ) -> tuple[list[shapely.Polygon], list[tuple[float, float, float]]]:
        """Random boxes (cupboards, boxes), bins, and tables/chairs as four thin legs, within
        6 m of the laser, clear of it."""
        boxes: list[shapely.Polygon] = []
        poles: list[tuple[float, float, float]] = []
        for _ in range(int(rng.integers(0, 7))):
            r = rng.uniform(0.6, 6.0)
            a = pose.theta + rng.uniform(-2.4, 2.4)
            cx, cy = pose.x + r * math.cos(a), pose.y + r * math.sin(a)
            if not self._clear(np.array([cx, cy]), 0.05, ()):
                continue
            kind = rng.random()
            if kind < 0.35:
                boxes.append(
                    _box(
                        cx, cy, rng.uniform(0.15, 1.2), rng.uniform(0.15, 0.8), rng.uniform(0, 3.2)
                    )
                )
            elif kind < 0.5:
                poles.append((cx, cy, float(rng.uniform(0.13, 0.3))))  # bin, pot, round stool
            else:  # table or chair: four legs at the corners of a rectangle
                w, d = rng.uniform(0.35, 1.4), rng.uniform(0.35, 0.9)
                yaw = rng.uniform(0, math.pi)
                c, s = math.cos(yaw), math.sin(yaw)
                radius = float(rng.uniform(0.01, 0.03))
                for sx, sy in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
                    x, y = sx * w / 2, sy * d / 2
                    poles.append((cx + c * x - s * y, cy + s * x + c * y, radius))
        return boxes, poles

    def _people(
        self,
        rng: np.random.Generator,
        pose: Pose2D,
        spec: LaserSpec,
        taken: list[shapely.Geometry],
    ) -> np.ndarray:
        """Legs ``(2k, 3)`` of 0–8 people 0.5–6 m from the laser, most in its field of view."""
        out = []
        half_fov = -spec.angle_min
        for k in range(int(rng.integers(0, 9))):
            for _ in range(30):
                r = rng.uniform(0.5, 6.0)
                a = pose.theta + rng.uniform(-half_fov, half_fov)
                pt = np.array([pose.x + r * math.cos(a), pose.y + r * math.sin(a)])
                if self._clear(pt, 0.2, tuple(taken)):
                    break
            else:
                continue
            walker = Walker(
                f"person_{k}",
                [pt],
                cast(Any, None),  # one stop: no route to plan
                speed=1.0,
                clothes=Clothes((0, 0, 0), (0, 0, 0)),
            )
            walker.theta = float(rng.uniform(-math.pi, math.pi))
            if rng.random() < 0.45:  # standing: legs together, or weight shifted
                walker.speed = 0.0
                walker.phase = float(rng.choice([0.0, math.pi]) + rng.normal(0.0, 0.4))
            else:  # walking, at any point of the gait cycle
                walker.speed = float(rng.uniform(0.3, 1.4))
                walker.phase = float(rng.uniform(0.0, 2 * math.pi))
            legs = walker.legs()
            legs[:, 2] = LEG_RADIUS * rng.uniform(0.8, 1.35)
            out.append(legs)
            taken.append(shapely.Point(pt).buffer(0.3))
        return np.vstack(out) if out else np.empty((0, 3))


def _with_noise(spec: LaserSpec, noise_std: float) -> LaserSpec:
    return LaserSpec(
        angle_min=spec.angle_min,
        angle_increment=spec.angle_increment,
        beams=spec.beams,
        range_min=spec.range_min,
        range_max=spec.range_max,
        noise_std=noise_std,
        mount_x=spec.mount_x,
        mount_height=spec.mount_height,
    )


def _scan(
    fast: FastLaser, pose: Pose2D, circles: np.ndarray, rng: np.random.Generator, dropout: float
) -> LaserScan:
    scan = fast.scan(pose, circles, 0.0)
    ranges = scan.ranges.copy()
    ranges[rng.random(len(ranges)) < dropout] = np.inf
    return LaserScan(
        scan.stamp,
        scan.angle_min,
        scan.angle_increment,
        scan.range_min,
        scan.range_max,
        ranges,
        scan.pose,
    )


def simulate_leg_scans(house: HouseConfig, count: int, seed: int) -> Iterator[LabelledScan]:
    """``count`` labelled scans in ``house``, deterministic for ``seed``."""
    generator = LegScanGenerator(house)
    rng = np.random.default_rng(seed)
    for _ in range(count):
        yield generator.draw(rng)


__all__ = ["LASERS", "LabelledScan", "LaserModel", "LegScanGenerator", "simulate_leg_scans"]
