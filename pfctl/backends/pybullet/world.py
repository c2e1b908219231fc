"""The simulated house in PyBullet: floors, walls extruded from the region boundaries, furniture.

- Each region's floor is a flat mesh of its polygon (rooms get slightly different tints), over an
  invisible ground plane that carries the collisions.
- Walls are the boxes of :func:`pfctl.core.mapping.walls.wall_boxes` extruded to the house's
  ``wall_height``, with gaps at the doors.
- Furniture (the layout's obstacles) is its polygon extruded to its height, as a visual mesh and
  a static triangle-mesh collision shape, so concave pieces are exact.

The same geometry is kept in 2-D for the fast laser and the base's collisions:
:class:`StaticScene` holds every body's outline as counter-clockwise segments.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pybullet as p
import shapely
from shapely.geometry.polygon import orient

from pfctl.backends.pybullet.config import HouseConfig
from pfctl.core.mapping.walls import wall_boxes

WALL_RGBA = (0.86, 0.85, 0.80, 1.0)
FURNITURE_RGBA = (0.55, 0.38, 0.24, 1.0)
FLOOR_TINTS = ((0.78, 0.70, 0.58), (0.70, 0.72, 0.74), (0.74, 0.66, 0.62), (0.68, 0.73, 0.64))


@dataclass
class StaticScene:
    """Outlines of walls and furniture as segments ``(m, 4)`` rows ``[x0, y0, x1, y1]``; each
    body's outline runs counter-clockwise (its inside on the left of every segment)."""

    segments: np.ndarray


@dataclass
class World:
    """Body ids of the static house and its 2-D scene."""

    ground: int
    floors: dict[str, int] = field(default_factory=dict)
    """Region name → the body of its floor."""
    walls: list[int] = field(default_factory=list)
    obstacles: list[int] = field(default_factory=list)
    scene: StaticScene = field(default_factory=lambda: StaticScene(np.empty((0, 4))))


def ccw_ring(polygon: shapely.Polygon) -> list[tuple[float, float]]:
    """The polygon's exterior, counter-clockwise, without the closing point."""
    return [(float(x), float(y)) for x, y in orient(polygon, 1.0).exterior.coords[:-1]]


def outline(ring: list[tuple[float, float]]) -> list[list[float]]:
    """The closed ring as segments ``[x0, y0, x1, y1]``."""
    return [[*ring[i], *ring[(i + 1) % len(ring)]] for i in range(len(ring))]


def _triangles(polygon: shapely.Polygon) -> list[list[tuple[float, float]]]:
    """A constrained Delaunay triangulation of a simple polygon, each triangle CCW."""
    tris = shapely.constrained_delaunay_triangles(polygon)
    return [ccw_ring(t) for t in shapely.get_parts(tris)]


def prism_mesh(
    polygon: shapely.Polygon, z0: float, z1: float, sides: bool = True
) -> tuple[list[list[float]], list[int], list[list[float]]]:
    """The polygon extruded from ``z0`` to ``z1``: vertices, triangle indices and normals (flat
    shading: every face has its own vertices). With ``sides=False`` only the top face."""
    vertices: list[list[float]] = []
    indices: list[int] = []
    normals: list[list[float]] = []

    def face(corners: list[tuple[float, float, float]], normal: tuple[float, float, float]) -> None:
        base = len(vertices)
        vertices.extend([list(c) for c in corners])
        normals.extend([list(normal)] * len(corners))
        for k in range(1, len(corners) - 1):
            indices.extend([base, base + k, base + k + 1])

    for tri in _triangles(polygon):
        face([(x, y, z1) for x, y in tri], (0.0, 0.0, 1.0))
        if sides:
            face([(x, y, z0) for x, y in reversed(tri)], (0.0, 0.0, -1.0))
    if sides:
        ring = ccw_ring(polygon)
        for (ax, ay), (bx, by) in zip(ring, ring[1:] + ring[:1], strict=True):
            n = np.array([by - ay, ax - bx])
            n = n / max(float(np.linalg.norm(n)), 1e-12)
            face([(ax, ay, z0), (bx, by, z0), (bx, by, z1), (ax, ay, z1)], (n[0], n[1], 0.0))
    return vertices, indices, normals


def _box(client: int, cx: float, cy: float, yaw: float, half: tuple[float, float, float]) -> int:
    col = p.createCollisionShape(p.GEOM_BOX, halfExtents=half, physicsClientId=client)
    vis = p.createVisualShape(
        p.GEOM_BOX, halfExtents=half, rgbaColor=WALL_RGBA, physicsClientId=client
    )
    orn = p.getQuaternionFromEuler([0.0, 0.0, yaw])
    return p.createMultiBody(0, col, vis, [cx, cy, half[2]], orn, physicsClientId=client)


def _mesh_body(
    client: int,
    mesh: tuple[list[list[float]], list[int], list[list[float]]],
    rgba: tuple[float, float, float, float],
    solid: bool,
) -> int:
    """A static body drawn as ``mesh``; with ``solid`` also a triangle-mesh collision shape (exact
    for concave shapes, as static bodies may have)."""
    vertices, indices, normals = mesh
    col = (
        p.createCollisionShape(
            p.GEOM_MESH, vertices=vertices, indices=indices, physicsClientId=client
        )
        if solid
        else -1
    )
    vis = p.createVisualShape(
        p.GEOM_MESH,
        vertices=vertices,
        indices=indices,
        normals=normals,
        rgbaColor=rgba,
        physicsClientId=client,
    )
    return p.createMultiBody(0, col, vis, physicsClientId=client)


def build_world(client: int, house: HouseConfig) -> World:
    """Ground, floors, walls (``wall_boxes`` extruded to ``wall_height``) and furniture."""
    ground_col = p.createCollisionShape(p.GEOM_PLANE, physicsClientId=client)
    ground_vis = p.createVisualShape(
        p.GEOM_BOX, halfExtents=[0.01, 0.01, 0.01], rgbaColor=[0, 0, 0, 0], physicsClientId=client
    )
    world = World(ground=p.createMultiBody(0, ground_col, ground_vis, physicsClientId=client))
    layout = house.layout
    for k, region in enumerate(layout.regions):
        rgba = (*FLOOR_TINTS[k % len(FLOOR_TINTS)], 1.0)
        top = prism_mesh(shapely.Polygon(region.polygon), 0.0, 0.0, sides=False)
        world.floors[region.name] = _mesh_body(client, top, rgba, solid=False)
    segs: list[list[float]] = []
    height = house.wall_height
    for box in wall_boxes(layout, house.wall_thickness):
        half = (box.length / 2.0, box.thickness / 2.0, height / 2.0)
        body = _box(client, box.center[0], box.center[1], box.yaw, half)
        world.walls.append(body)
        segs.extend(outline(ccw_ring(box.polygon())))
    for obstacle in layout.obstacles:
        poly = shapely.Polygon(obstacle.polygon)
        mesh = prism_mesh(poly, 0.0, obstacle.height)
        world.obstacles.append(_mesh_body(client, mesh, FURNITURE_RGBA, solid=True))
        segs.extend(outline(ccw_ring(poly)))
    world.scene = StaticScene(np.array(segs, dtype=float).reshape(-1, 4))
    return world


__all__ = ["StaticScene", "World", "build_world", "ccw_ring", "outline", "prism_mesh"]
