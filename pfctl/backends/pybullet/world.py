"""The simulated house in PyBullet: floor, walls extruded from the region boundaries, furniture.

The same geometry is kept as 2-D outline segments (:class:`StaticScene`) for the fast laser.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pybullet as p

from pfctl.core.walls import wall_boxes
from pfctl.mission import Mission


@dataclass
class StaticScene:
    """Outlines of walls and furniture as segments ``(m, 4)`` rows ``[x0, y0, x1, y1]``."""

    segments: np.ndarray


@dataclass
class World:
    """Body ids of the static house and its 2-D scene."""

    floor: int
    walls: list[int] = field(default_factory=list)
    obstacles: list[int] = field(default_factory=list)
    scene: StaticScene = field(default_factory=lambda: StaticScene(np.empty((0, 4))))


def _outline(poly: list[tuple[float, float]]) -> list[list[float]]:
    pts = list(poly)
    return [[*pts[i], *pts[(i + 1) % len(pts)]] for i in range(len(pts))]


def _box(client: int, cx: float, cy: float, yaw: float, half: tuple[float, float, float]) -> int:
    col = p.createCollisionShape(p.GEOM_BOX, halfExtents=half, physicsClientId=client)
    vis = p.createVisualShape(
        p.GEOM_BOX, halfExtents=half, rgbaColor=[0.85, 0.85, 0.8, 1], physicsClientId=client
    )
    orn = p.getQuaternionFromEuler([0.0, 0.0, yaw])
    return p.createMultiBody(0, col, vis, [cx, cy, half[2]], orn, physicsClientId=client)


def build_world(client: int, mission: Mission) -> World:
    """Floor, walls (``wall_boxes`` extruded to ``wall_height``) and furniture boxes."""
    floor_col = p.createCollisionShape(p.GEOM_PLANE, physicsClientId=client)
    floor = p.createMultiBody(0, floor_col, physicsClientId=client)
    world = World(floor=floor)
    segs: list[list[float]] = []
    height = mission.map.wall_height
    for box in wall_boxes(mission.layout(), mission.map.wall_thickness):
        half = (box.length / 2.0, box.thickness / 2.0, height / 2.0)
        world.walls.append(_box(client, box.center[0], box.center[1], box.yaw, half))
        segs.extend(_outline([tuple(map(float, q)) for q in box.polygon().exterior.coords[:-1]]))
    for obs in mission.map.obstacles:
        pts = np.array([[float(x), float(y)] for x, y in obs.polygon])
        lo, hi = pts.min(axis=0), pts.max(axis=0)
        half = ((hi[0] - lo[0]) / 2.0, (hi[1] - lo[1]) / 2.0, float(obs.height) / 2.0)
        c = (lo + hi) / 2.0
        world.obstacles.append(_box(client, float(c[0]), float(c[1]), 0.0, half))
        corners = [(lo[0], lo[1]), (hi[0], lo[1]), (hi[0], hi[1]), (lo[0], hi[1])]
        segs.extend(_outline([(float(a), float(b)) for a, b in corners]))
    world.scene = StaticScene(np.array(segs, dtype=float).reshape(-1, 4))
    return world
