"""PyBullet bodies of the simulated people, placed from the kinematic walkers every step.

Each person is four static (mass 0) bodies moved with ``resetBasePositionAndOrientation``: two leg
cylinders (:data:`~pfctl.backends.pybullet.walkers.LEG_RADIUS`) in the colour of
``clothes.lower``, a torso box textured with ``clothes.upper`` (a striped pattern, so look-alikes
in the same clothes look the same), and a head box whose front carries a procedurally generated
face (skin tone, eyes, brows, mouth; seeded per person). Static bodies never touch each other, so
people do not collide among themselves; they are solid for the robot, the laser
(``rayTestBatch``) and the camera (``getCameraImage`` and its segmentation mask).
"""

from __future__ import annotations

import math
import struct
import tempfile
import zlib
from pathlib import Path

import numpy as np
import pybullet as p

from pfctl.backends.pybullet.walkers import LEG_RADIUS, Walker

#: Leg length as a fraction of body height (hip height).
LEG_FRACTION = 0.47
#: Torso box half extents (depth, width) in metres; its height spans hip to shoulder.
TORSO_HALF = (0.11, 0.19)
#: Head box half extents (depth, width, height), metres.
HEAD_HALF = (0.09, 0.08, 0.11)
TEXTURE_SIZE = 64


def write_png(path: Path, rgb: np.ndarray) -> None:
    """Write an ``(h, w, 3) uint8`` image as a PNG (zlib only, no imaging library needed)."""
    img = np.ascontiguousarray(rgb, dtype=np.uint8)
    h, w, _ = img.shape
    raw = b"".join(b"\x00" + img[r].tobytes() for r in range(h))

    def chunk(kind: bytes, data: bytes) -> bytes:
        return (
            struct.pack(">I", len(data))
            + kind
            + data
            + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)
        )

    header = struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0)
    path.write_bytes(
        b"\x89PNG\r\n\x1a\n"
        + chunk(b"IHDR", header)
        + chunk(b"IDAT", zlib.compress(raw, 6))
        + chunk(b"IEND", b"")
    )


def face_texture(rng: np.random.Generator, size: int = TEXTURE_SIZE) -> np.ndarray:
    """A cartoon face ``(size, size, 3) uint8``: skin, hair, eyes, brows and a mouth."""
    skin = np.array(
        [(241, 194, 167), (224, 172, 105), (198, 134, 66), (141, 85, 36), (255, 219, 172)][
            int(rng.integers(5))
        ],
        dtype=float,
    )
    skin = np.clip(skin + rng.normal(0, 8, 3), 0, 255)
    hair = np.array(
        [(40, 25, 15), (90, 60, 30), (200, 170, 90), (20, 20, 20), (120, 40, 20)][
            int(rng.integers(5))
        ]
    )
    img = np.empty((size, size, 3))
    img[:] = skin
    yy, xx = np.mgrid[0:size, 0:size] / size
    hairline = 0.18 + 0.08 * rng.random()
    img[yy < hairline] = hair
    eye_y = 0.40 + 0.05 * rng.random()
    eye_dx = 0.16 + 0.05 * rng.random()
    eye_r = 0.05 + 0.02 * rng.random()
    iris = np.array([(60, 40, 20), (40, 90, 140), (50, 110, 60)][int(rng.integers(3))])
    for side in (-1, 1):
        cx = 0.5 + side * eye_dx
        white = (xx - cx) ** 2 + ((yy - eye_y) * 1.6) ** 2 < eye_r**2
        img[white] = (250, 250, 250)
        img[(xx - cx) ** 2 + (yy - eye_y) ** 2 < (eye_r * 0.5) ** 2] = iris
        brow = (np.abs(yy - (eye_y - 0.09)) < 0.018) & (np.abs(xx - cx) < eye_r * 1.3)
        img[brow] = hair
    nose = (np.abs(xx - 0.5) < 0.03) & (yy > eye_y + 0.05) & (yy < eye_y + 0.2)
    img[nose] = skin * 0.85
    mouth_y = 0.72 + 0.04 * rng.random()
    width = 0.12 + 0.06 * rng.random()
    mouth = (np.abs(yy - mouth_y - 2.0 * (xx - 0.5) ** 2) < 0.02) & (np.abs(xx - 0.5) < width)
    img[mouth] = (150, 40, 50)
    return img.astype(np.uint8)


def clothes_texture(rgb: tuple[int, int, int], size: int = TEXTURE_SIZE) -> np.ndarray:
    """The upper clothes: the colour with darker horizontal stripes (the same for look-alikes)."""
    base = np.array(rgb, dtype=float)
    img = np.empty((size, size, 3))
    img[:] = base
    stripes = (np.arange(size) // 8) % 4 == 0
    img[stripes] = base * 0.7
    return img.astype(np.uint8)


def box_mesh(
    half: tuple[float, float, float], face_only_front: bool
) -> tuple[list[list[float]], list[int], list[list[float]], list[list[float]]]:
    """A box as a textured mesh: vertices, triangle indices, uvs and normals per face.

    Every face shows the whole texture, unless ``face_only_front``: then only the front (+x)
    face does and the others sample a spot of skin (sides, back) or hair (top) of a
    :func:`face_texture`.
    """
    hx, hy, hz = half
    faces = {  # normal: four corners, counter-clockwise seen from outside (u right, v up)
        (1, 0, 0): [(hx, -hy, -hz), (hx, hy, -hz), (hx, hy, hz), (hx, -hy, hz)],
        (-1, 0, 0): [(-hx, hy, -hz), (-hx, -hy, -hz), (-hx, -hy, hz), (-hx, hy, hz)],
        (0, 1, 0): [(hx, hy, -hz), (-hx, hy, -hz), (-hx, hy, hz), (hx, hy, hz)],
        (0, -1, 0): [(-hx, -hy, -hz), (hx, -hy, -hz), (hx, -hy, hz), (-hx, -hy, hz)],
        (0, 0, 1): [(hx, -hy, hz), (hx, hy, hz), (-hx, hy, hz), (-hx, -hy, hz)],
        (0, 0, -1): [(-hx, -hy, -hz), (-hx, hy, -hz), (hx, hy, -hz), (hx, -hy, -hz)],
    }
    full = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]
    vertices: list[list[float]] = []
    indices: list[int] = []
    uvs: list[list[float]] = []
    normals: list[list[float]] = []
    for normal, corners in faces.items():
        base = len(vertices)
        vertices += [list(c) for c in corners]
        normals += [list(map(float, normal))] * 4
        if not face_only_front or normal == (1, 0, 0):
            uvs += full
        elif normal == (0, 0, 1):
            uvs += [[0.5, 0.97]] * 4  # hair
        else:
            uvs += [[0.06, 0.4]] * 4  # cheek: skin
        indices += [base, base + 1, base + 2, base, base + 2, base + 3]
    return vertices, indices, uvs, normals


def _yaw(theta: float) -> tuple[float, float, float, float]:
    return (0.0, 0.0, math.sin(theta / 2.0), math.cos(theta / 2.0))


class PeopleBodies:
    """The bodies of ``walkers`` in the PyBullet world ``client``; :meth:`sync` moves them."""

    def __init__(self, client: int, walkers: list[Walker], seed: int = 0) -> None:
        self.client = client
        self.walkers = walkers
        self.body_ids: dict[str, list[int]] = {}
        self._parts: dict[str, tuple[list[int], int, int]] = {}
        self._texdir = tempfile.TemporaryDirectory(prefix="pfctl-people-")
        texdir = Path(self._texdir.name)
        textures: dict[tuple[int, int, int], int] = {}
        for k, walker in enumerate(walkers):
            h = walker.height
            leg_len = LEG_FRACTION * h
            torso_top = h - 2 * HEAD_HALF[2] - 0.03
            torso_half_h = (torso_top - leg_len) / 2.0
            legs = []
            for _ in range(2):
                vis = p.createVisualShape(
                    p.GEOM_CYLINDER,
                    radius=LEG_RADIUS,
                    length=leg_len,
                    rgbaColor=[*(c / 255.0 for c in walker.clothes.lower), 1.0],
                    physicsClientId=client,
                )
                col = p.createCollisionShape(
                    p.GEOM_CYLINDER, radius=LEG_RADIUS, height=leg_len, physicsClientId=client
                )
                legs.append(self._body(col, vis, (walker.x, walker.y, leg_len / 2)))
            half = (*TORSO_HALF, torso_half_h)
            torso = self._body(
                p.createCollisionShape(p.GEOM_BOX, halfExtents=half, physicsClientId=client),
                self._mesh(half, face_only_front=False),
                (walker.x, walker.y, leg_len + torso_half_h),
            )
            upper = walker.clothes.upper
            if upper not in textures:
                path = texdir / f"clothes_{len(textures)}.png"
                write_png(path, clothes_texture(upper))
                textures[upper] = p.loadTexture(str(path), physicsClientId=client)
            p.changeVisualShape(torso, -1, textureUniqueId=textures[upper], physicsClientId=client)
            head = self._body(
                p.createCollisionShape(p.GEOM_BOX, halfExtents=HEAD_HALF, physicsClientId=client),
                self._mesh(HEAD_HALF, face_only_front=True),
                (walker.x, walker.y, h - HEAD_HALF[2]),
            )
            face_path = texdir / f"face_{k}.png"
            rng = np.random.default_rng([seed, k])
            write_png(face_path, face_texture(rng))
            face = p.loadTexture(str(face_path), physicsClientId=client)
            p.changeVisualShape(head, -1, textureUniqueId=face, physicsClientId=client)
            self._parts[walker.name] = (legs, torso, head)
            self.body_ids[walker.name] = [*legs, torso, head]
        self.sync()

    def _mesh(self, half: tuple[float, float, float], face_only_front: bool) -> int:
        vertices, indices, uvs, normals = box_mesh(half, face_only_front)
        return p.createVisualShape(
            p.GEOM_MESH,
            vertices=vertices,
            indices=indices,
            uvs=uvs,
            normals=normals,
            rgbaColor=[1, 1, 1, 1],
            physicsClientId=self.client,
        )

    def _body(self, col: int, vis: int, pos: tuple[float, float, float]) -> int:
        return p.createMultiBody(
            baseMass=0.0,
            baseCollisionShapeIndex=col,
            baseVisualShapeIndex=vis,
            basePosition=pos,
            physicsClientId=self.client,
        )

    def owner(self, body_id: int) -> str | None:
        """The name of the person a body belongs to, or None."""
        for name, ids in self.body_ids.items():
            if body_id in ids:
                return name
        return None

    def sync(self) -> None:
        """Place every body from its walker's current state."""
        for walker in self.walkers:
            legs, torso, head = self._parts[walker.name]
            state = walker.state
            leg_len = LEG_FRACTION * state.height
            q = _yaw(state.theta)
            for body, (x, y, _r) in zip(legs, state.legs, strict=True):
                p.resetBasePositionAndOrientation(
                    body, (float(x), float(y), leg_len / 2), q, physicsClientId=self.client
                )
            torso_top = state.height - 2 * HEAD_HALF[2] - 0.03
            p.resetBasePositionAndOrientation(
                torso,
                (state.x, state.y, (leg_len + torso_top) / 2),
                q,
                physicsClientId=self.client,
            )
            p.resetBasePositionAndOrientation(
                head,
                (state.x, state.y, state.height - HEAD_HALF[2]),
                q,
                physicsClientId=self.client,
            )

    def close(self) -> None:
        """Remove the texture files (the bodies go with the PyBullet client)."""
        self._texdir.cleanup()


__all__ = ["PeopleBodies", "box_mesh", "clothes_texture", "face_texture", "write_png"]
