"""Person keypoints: 2-D keypoints and boxes an external pose detector publishes for the follower.

The paper ran OpenPose on a machine beside the HSR and placed each person it found in 3-D with
the depth image (§II-E). The HSR backend takes such detections, when the mission sets
``backend.hsr.person_keypoints``, from a ``sensor_msgs/PointCloud`` topic — a standard message,
so that no custom message has to be built on the robot or here. The format lives with the bags
because two sides read it: the HSR backend on the wire, :mod:`pfctl.bags.replay` in a recorded
bag. A message holds:

``header.stamp``
    The stamp of the RGB image the detector ran on (the backend pairs it with the RGB, depth
    and camera_info messages of that stamp, as it pairs the person labels); ``header.frame_id``
    the RGB optical frame.
``points``
    One ``geometry_msgs/Point32`` per keypoint: ``x`` = pixel column ``u``, ``y`` = pixel row
    ``v`` (of the RGB image), ``z`` = confidence; ``z ≤ 0`` means "not found" (OpenPose writes
    0, 0, 0 for a part it did not find) and the point is ignored.
``channels``
    Two ``sensor_msgs/ChannelFloat32`` with one value per point: ``person`` (a whole number
    ≥ 0, an index that only has to be stable within one message) and ``part``: the OpenPose
    BODY_25 index 0–24 (:data:`BODY_25`), or 25 = the box's top-left corner ``(x0, y0)`` and
    26 = its bottom-right corner ``(x1, y1)``, exclusive, for detectors that give boxes.
    Other channels are ignored.

A message with no points says the detector ran and found nobody. A relay from an OpenPose ROS
wrapper (e.g. ``openpose_ros``' ``OpenPoseHumanList``: ``body_key_points_with_prob[i].x, .y,
.prob`` per human) to this topic is a few lines of Python: one point per key point, the human's
index in ``person``, ``i`` in ``part``, the image's header.

:func:`read_cloud` checks a message (a missing channel, channels of another length than the
points, a part outside 0–26, a person index that is not a whole number ≥ 0, a non-finite value,
a part given twice: :class:`ValueError` saying what was expected) and returns each person's
parts; :func:`given_person` turns them into the :class:`~pfctl.core.robot.GivenPerson` core
places in 3-D (:class:`~pfctl.core.perception.vision.GivenPersonDetector`);
:func:`people_from_cloud` does both. ``pfctl sim serve-hsr`` stands in for OpenPose with the
simulator's mask detections (:func:`detection_parts`); :func:`cloud_fields` gives the points and
channels of a message.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from pfctl.core.perception.vision import PersonDetection
from pfctl.core.robot import GivenPerson

BODY_25 = (
    "nose",
    "neck",
    "right_shoulder",
    "right_elbow",
    "right_wrist",
    "left_shoulder",
    "left_elbow",
    "left_wrist",
    "mid_hip",
    "right_hip",
    "right_knee",
    "right_ankle",
    "left_hip",
    "left_knee",
    "left_ankle",
    "right_eye",
    "left_eye",
    "right_ear",
    "left_ear",
    "left_big_toe",
    "left_small_toe",
    "left_heel",
    "right_big_toe",
    "right_small_toe",
    "right_heel",
)
"""OpenPose's BODY_25 parts by index."""
BOX_TOP_LEFT = 25
"""Part index of the box's top-left corner ``(x0, y0)``."""
BOX_BOTTOM_RIGHT = 26
"""Part index of the box's bottom-right corner ``(x1, y1)`` (exclusive)."""
PARTS = BOX_BOTTOM_RIGHT + 1
PERSON_CHANNEL = "person"
PART_CHANNEL = "part"
HEAD_PARTS = (0, 15, 16, 17, 18)
"""Nose, eyes and ears: the head keypoint is their mean, the head box is around them."""
#: Core keypoint names taken directly from one BODY_25 part.
DIRECT = {"neck": 1, "right_shoulder": 2, "left_shoulder": 5, "right_hip": 9, "left_hip": 12}
MIN_KEYPOINTS = 3
"""A person with fewer confident keypoints than this and no box is dropped (a guess of a box)."""
BODY_PAD = 0.1
"""A box made from keypoints is padded by this fraction of their height on every side (the
keypoints are joints; the body reaches beyond them)."""

Parts = Mapping[int, tuple[float, float, float]]
"""One person's parts: BODY_25 index (or a box corner) → ``(u, v, confidence)``."""


# ------------------------------------------------------------------------------------- reading


def _channel(msg: Any, name: str, n: int) -> np.ndarray:
    found = [c for c in msg.channels if c.name == name]
    if not found:
        names = ", ".join(repr(c.name) for c in msg.channels) or "none"
        raise ValueError(
            f"expected channels 'person' and 'part' (one value per point), no {name!r} "
            f"among the channels ({names})"
        )
    values = np.asarray(found[0].values, dtype=float).ravel()
    if len(values) != n:
        raise ValueError(
            f"expected one {name!r} value per point ({n} points), got {len(values)} values"
        )
    return values


def read_cloud(msg: Any) -> dict[int, dict[int, tuple[float, float, float]]]:
    """Each person's parts in a ``sensor_msgs/PointCloud`` of this module's semantics (ROS 1 or
    a bag's message: anything with ``points`` and ``channels``), person index → part →
    ``(u, v, confidence)``, every point kept (also those not found). :class:`ValueError` naming
    what was expected when the message breaks the semantics (module docstring)."""
    n = len(msg.points)
    xyz = np.array([(p.x, p.y, p.z) for p in msg.points], dtype=float).reshape(n, 3)
    person = _channel(msg, PERSON_CHANNEL, n)
    part = _channel(msg, PART_CHANNEL, n)
    bad = ~np.isfinite(xyz).all(axis=1)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise ValueError(
            f"expected finite x (u), y (v) and z (confidence), got point {i} = "
            f"({xyz[i, 0]:g}, {xyz[i, 1]:g}, {xyz[i, 2]:g})"
        )
    for name, values, top in ((PERSON_CHANNEL, person, None), (PART_CHANNEL, part, PARTS - 1)):
        wrong = ~np.isfinite(values) | (values < 0) | (values != np.round(values))
        if top is not None:
            wrong |= values > top
        if wrong.any():
            i = int(np.flatnonzero(wrong)[0])
            allowed = "a whole number >= 0" if top is None else f"a whole number in 0..{top}"
            raise ValueError(f"expected {name} values {allowed}, got {values[i]:g} at point {i}")
    people: dict[int, dict[int, tuple[float, float, float]]] = {}
    for (u, v, c), k, j in zip(xyz.tolist(), person.astype(int), part.astype(int), strict=True):
        parts = people.setdefault(int(k), {})
        if int(j) in parts:
            raise ValueError(
                f"expected each part once per person, got part {j} of person {k} twice"
            )
        parts[int(j)] = (u, v, c)
    return people


# ------------------------------------------------------------------------------------ decoding


def _mean(points: Sequence[tuple[float, float]]) -> tuple[float, float]:
    return sum(u for u, _ in points) / len(points), sum(v for _, v in points) / len(points)


def _clip(
    box: tuple[float, float, float, float], shape: tuple[int, int]
) -> tuple[int, int, int, int] | None:
    """The box with whole-pixel edges (outwards) inside an image of ``shape``; None when no
    pixel of it is inside."""
    h, w = shape
    x0, y0, x1, y1 = box
    u0, v0 = min(max(math.floor(x0), 0), w), min(max(math.floor(y0), 0), h)
    u1, v1 = min(max(math.ceil(x1), 0), w), min(max(math.ceil(y1), 0), h)
    return (u0, v0, u1, v1) if u0 < u1 and v0 < v1 else None


def _head(
    found: Mapping[int, tuple[float, float]],
) -> tuple[tuple[float, float], tuple[float, float, float, float]] | None:
    """The head's centre and box from the nose, eyes and ears: centred on their mean, with a
    half-width of 0.6 × their horizontal spread (the ears span about the head's width) or
    0.35 × the distance to the neck (nose to neck is about a head), whichever is larger (at
    least 2 px), and a half-height 1.2 times that; None without head keypoints."""
    head = [found[j] for j in HEAD_PARTS if j in found]
    if not head:
        return None
    cu, cv = _mean(head)
    us = [u for u, _ in head]
    half = 0.6 * (max(us) - min(us))
    if 1 in found:
        half = max(half, 0.35 * math.dist((cu, cv), found[1]))
    half = max(half, 2.0)
    return (cu, cv), (cu - half, cv - 1.2 * half, cu + half, cv + 1.2 * half)


def given_person(parts: Parts, shape: tuple[int, int]) -> GivenPerson | None:
    """One person's parts as core sees them in an image of ``shape`` ``(h, w)``:

    - ``box``: the given corners (parts 25 and 26) when both were found; else the bounding box
      of the confident keypoints padded by :data:`BODY_PAD` of their height on each side and
      grown to hold the head box (the head's top is above the nose); clipped to the image;
    - ``keypoints``: ``head`` (the mean of nose, eyes and ears), ``neck`` (1), ``mid_hip`` (8,
      else the mid-point of the hips 9 and 12), ``ankles`` (the mid-point of 11 and 14, or
      whichever was found), and the shoulders (2, 5) and hips (9, 12) that were found, whose
      depth places the person (:class:`~pfctl.core.perception.vision.GivenPersonDetector`);
    - ``head_box``: around the head keypoints (see :func:`_head`), clipped, when there are some;
    - ``score``: the mean confidence of the points found (corners included).

    None for a person with fewer than :data:`MIN_KEYPOINTS` keypoints found and no box, or whose
    box has no pixel inside the image."""
    found = {j: (u, v) for j, (u, v, c) in parts.items() if c > 0}
    if not found:
        return None
    keypoints_found = {j: p for j, p in found.items() if j < len(BODY_25)}
    has_box = BOX_TOP_LEFT in found and BOX_BOTTOM_RIGHT in found
    if not has_box and len(keypoints_found) < MIN_KEYPOINTS:
        return None
    head = _head(keypoints_found)
    if has_box:
        (x0, y0), (x1, y1) = found[BOX_TOP_LEFT], found[BOX_BOTTOM_RIGHT]
        raw: tuple[float, float, float, float] = (x0, y0, x1, y1)
    else:
        us = [u for u, _ in keypoints_found.values()]
        vs = [v for _, v in keypoints_found.values()]
        pad = BODY_PAD * (max(vs) - min(vs))
        raw = (min(us) - pad, min(vs) - pad, max(us) + 1 + pad, max(vs) + 1 + pad)
        if head is not None:
            hb = head[1]
            raw = (min(raw[0], hb[0]), min(raw[1], hb[1]), max(raw[2], hb[2]), max(raw[3], hb[3]))
    box = _clip(raw, shape)
    if box is None:
        return None
    keypoints: dict[str, tuple[float, float]] = {}
    head_box = None
    if head is not None:
        keypoints["head"] = head[0]
        head_box = _clip(head[1], shape)
    for name, j in DIRECT.items():
        if j in found:
            keypoints[name] = found[j]
    if 8 in found:
        keypoints["mid_hip"] = found[8]
    elif 9 in found and 12 in found:
        keypoints["mid_hip"] = _mean([found[9], found[12]])
    ankles = [found[j] for j in (11, 14) if j in found]
    if ankles:
        keypoints["ankles"] = _mean(ankles)
    score = sum(c for _, _, c in parts.values() if c > 0) / len(found)
    return GivenPerson(box, keypoints or None, float(score), head_box)


def people_from_cloud(msg: Any, shape: tuple[int, int]) -> tuple[GivenPerson, ...]:
    """The people of a keypoint message (:func:`read_cloud`, then :func:`given_person`) in an
    image of ``shape``, by person index; :class:`ValueError` for a malformed message."""
    people = (given_person(parts, shape) for _, parts in sorted(read_cloud(msg).items()))
    return tuple(p for p in people if p is not None)


# ------------------------------------------------------------------------------------ encoding


def detection_parts(detection: PersonDetection) -> dict[int, tuple[float, float, float]]:
    """A detection of the simulator's mask detector as the parts a pose detector would send
    (confidence 1): its box as the corners 25 and 26; ``head`` as the nose (0) and, with a head
    box, the ears (17, 18) at the head box's left and right edges on the head's row; ``neck``
    (1), ``mid_hip`` (8); ``ankles`` as both ankles (11, 14)."""
    x0, y0, x1, y1 = detection.box
    parts: dict[int, tuple[float, float, float]] = {
        BOX_TOP_LEFT: (float(x0), float(y0), 1.0),
        BOX_BOTTOM_RIGHT: (float(x1), float(y1), 1.0),
    }
    kp = detection.keypoints or {}
    if "head" in kp:
        u, v = kp["head"]
        parts[0] = (float(u), float(v), 1.0)
        if detection.head_box is not None:
            hx0, _, hx1, _ = detection.head_box
            parts[17] = (float(hx0), float(v), 1.0)
            parts[18] = (float(hx1 - 1), float(v), 1.0)
    for name, j in (("neck", 1), ("mid_hip", 8)):
        if name in kp:
            parts[j] = (float(kp[name][0]), float(kp[name][1]), 1.0)
    if "ankles" in kp:
        u, v = kp["ankles"]
        parts[11] = parts[14] = (float(u), float(v), 1.0)
    return parts


def cloud_fields(
    people: Mapping[int, Parts],
) -> tuple[list[tuple[float, float, float]], list[float], list[float]]:
    """``(points, person channel, part channel)`` of a message carrying ``people`` (person
    index → parts), persons and parts in increasing order."""
    points: list[tuple[float, float, float]] = []
    person: list[float] = []
    part: list[float] = []
    for k in sorted(people):
        for j in sorted(people[k]):
            u, v, c = people[k][j]
            points.append((float(u), float(v), float(c)))
            person.append(float(k))
            part.append(float(j))
    return points, person, part


def cloud_message(sensor: Any, geometry: Any, header: Any, people: Mapping[int, Parts]) -> Any:
    """A ``sensor_msgs/PointCloud`` of ``people`` built with the modules ``sensor``
    (``sensor_msgs.msg``) and ``geometry`` (``geometry_msgs.msg``) of ROS 1."""
    points, person, part = cloud_fields(people)
    return sensor.PointCloud(
        header=header,
        points=[geometry.Point32(u, v, c) for u, v, c in points],
        channels=[
            sensor.ChannelFloat32(name=PERSON_CHANNEL, values=person),
            sensor.ChannelFloat32(name=PART_CHANNEL, values=part),
        ],
    )


__all__ = [
    "BODY_25",
    "BOX_BOTTOM_RIGHT",
    "BOX_TOP_LEFT",
    "MIN_KEYPOINTS",
    "PART_CHANNEL",
    "PERSON_CHANNEL",
    "Parts",
    "cloud_fields",
    "cloud_message",
    "detection_parts",
    "given_person",
    "people_from_cloud",
    "read_cloud",
]
