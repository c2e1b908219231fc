"""PyBullet bodies of the simulated people, placed from the kinematic walkers every step.

Each person is four static (mass 0) bodies moved with ``resetBasePositionAndOrientation``: two leg
cylinders (:data:`~pfctl.backends.pybullet.walkers.LEG_RADIUS`) in the colour of
``clothes.lower``, a torso box textured with ``clothes.upper`` (a striped pattern, so look-alikes
in the same clothes look the same), and a head box whose front carries a real face, so dlib's
face detector and embeddings (Algorithm 2) work on rendered frames. The faces come from
scikit-image's subset of Labeled Faces in the Wild (``skimage.data.lfw_subset()``, 25x25 grey
crops; Huang et al. 2007): each person wears a distinct one of :data:`LFW_FACES`, in a seeded
order, tinted with a seeded skin tone (:func:`face_texture`); how well dlib finds and tells
them apart on renders is in ``benchmarks/README.md`` (``bench_identity.py``). Static bodies never
touch each other, so
people do not collide among themselves; they are solid for the robot, the laser
(``rayTestBatch``) and the camera (``getCameraImage`` and its segmentation mask).
"""

from __future__ import annotations

import functools
import struct
import tempfile
import zlib
from pathlib import Path

import numpy as np
import pybullet as p

from pfctl.backends.pybullet.walkers import LEG_RADIUS, Walker
from pfctl.core.tf_buffer import quaternion_from_yaw

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


#: Skin tones the LFW faces are tinted with (RGB).
SKIN_TONES = ((241, 194, 167), (224, 172, 105), (198, 134, 66), (141, 85, 36), (255, 219, 172))
#: Hair colours (RGB) of the band above the face.
HAIR_COLOURS = ((40, 25, 15), (90, 60, 30), (200, 170, 90), (20, 20, 20), (120, 40, 20))
#: Side of the head's face texture, pixels (the LFW crop is 25 px; the renderer magnifies).
FACE_TEXTURE_SIZE = 128
#: How much of the skin tone tints the (contrast-stretched) face; the rest stays grey, so dark
#: tones keep the contrast dlib needs under the renderer's dim light.
TINT_WEIGHT = 0.5
#: Indices into ``skimage.data.lfw_subset()`` of the faces people wear. Of the 91 of its 100
#: faces dlib's HOG detector finds after upscaling to 200x200, these were rendered on a head at
#: 1.2-2.5 m and ±20° (320x240), found in every view with their own embeddings within 0.42,
#: and chosen greedily (max-min) to be far apart in dlib's 128-D embedding space: every pair is
#: more than 0.6 apart across all views. A ninth person wears the first face again.
LFW_FACES: tuple[int, ...] = (20, 77, 64, 52, 92, 7, 50, 14)


@functools.cache
def _lfw_faces() -> np.ndarray:
    """The 100 face images of scikit-image's LFW subset, ``(100, 25, 25)`` floats in 0..1."""
    from skimage.data import lfw_subset  # scikit-image loads slowly: only when faces are drawn

    return np.asarray(lfw_subset()[:100], dtype=float)


def face_texture(
    rng: np.random.Generator, size: int = TEXTURE_SIZE, face: int | None = None
) -> np.ndarray:
    """The front of a head ``(size, size, 3) uint8``: a real face from LFW, tinted.

    The face is image ``face`` (default: one of :data:`LFW_FACES` drawn from ``rng``) of
    scikit-image's subset of *Labeled Faces in the Wild* (Huang et al. 2007,
    ``skimage.data.lfw_subset()``), upscaled and multiplied by a skin tone drawn from ``rng``,
    under a band of hair. The texture covers the head's whole front (:data:`HEAD_HALF`: 0.16 m
    wide, 0.22 m tall), so the face is drawn squashed to ``0.16 / 0.22`` of its height and
    appears square once mapped; the skin below it is the chin.
    """
    pool = LFW_FACES or tuple(range(100))
    index = int(pool[int(rng.integers(len(pool)))]) if face is None else int(face)
    skin = np.array(SKIN_TONES[int(rng.integers(len(SKIN_TONES)))], dtype=float)
    skin = np.clip(skin + rng.normal(0, 8, 3), 0, 255)
    hair = np.array(HAIR_COLOURS[int(rng.integers(len(HAIR_COLOURS)))], dtype=float)
    gray = _lfw_faces()[index]
    face_h = max(1, round(size * 2 * HEAD_HALF[1] / (2 * HEAD_HALF[2])))
    top = round(0.17 * size)
    top = min(top, size - face_h)
    import cv2  # OpenCV loads slowly: only when faces are drawn

    lo, hi = np.percentile(gray, (1, 99))
    g = cv2.resize(gray, (size, face_h), interpolation=cv2.INTER_CUBIC)
    g = np.clip((g - lo) / max(float(hi - lo), 1e-3), 0.0, 1.0)
    tint = TINT_WEIGHT * skin + (1.0 - TINT_WEIGHT) * 255.0
    img = np.empty((size, size, 3))
    img[:] = tint * 0.8
    img[:top] = hair
    img[top : top + face_h] = g[:, :, None] * tint
    return np.clip(img, 0, 255).astype(np.uint8)


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
            uvs += [[0.5, 0.03]] * 4  # below the face: skin
        indices += [base, base + 1, base + 2, base, base + 2, base + 3]
    return vertices, indices, uvs, normals


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
        pool = LFW_FACES or tuple(range(100))
        faces = [int(pool[i]) for i in np.random.default_rng([seed, 1000]).permutation(len(pool))]
        self.faces: dict[str, int] = {}
        """The LFW image index each person wears (distinct while there are enough faces)."""
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
            self.faces[walker.name] = faces[k % len(faces)]
            write_png(face_path, face_texture(rng, FACE_TEXTURE_SIZE, face=self.faces[walker.name]))
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

    def instances(self) -> dict[int, int]:
        """Body id → person instance (the walker's index): what the mask detector needs."""
        return {b: k for k, w in enumerate(self.walkers) for b in self.body_ids[w.name]}

    def parts(self) -> dict[int, str]:
        """Body id → ``leg``, ``torso`` or ``head``."""
        names = ("leg", "leg", "torso", "head")
        return {b: n for ids in self.body_ids.values() for b, n in zip(ids, names, strict=True)}

    def instance_names(self) -> dict[int, str]:
        """Person instance → name: GROUND TRUTH, for tests and labels only."""
        return {k: w.name for k, w in enumerate(self.walkers)}

    def sync(self) -> None:
        """Place every body from its walker's current state."""
        for walker in self.walkers:
            legs, torso, head = self._parts[walker.name]
            state = walker.state
            leg_len = LEG_FRACTION * state.height
            q = quaternion_from_yaw(state.theta)
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
