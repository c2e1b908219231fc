"""Person labels: the instance-segmentation image a person detector publishes for the follower.

The HSR backend takes its camera detections (§II-E: OpenPose on the paper's robot) from a
``sensor_msgs/Image`` topic (``backend.hsr.person_labels``) with the RGB image's size and stamp,
encoding ``16UC1`` (``mono16``): pixel value 0 is no person; a value ``v > 0`` is person
``(v - 1) // 4`` — an index that only has to be stable within one image — and body part
``(v - 1) % 4``: 0 unknown, 1 head, 2 torso, 3 leg. A detector that only knows whole bodies
writes part 0; one that knows heads lets Algorithm 2 search faces there.

``pfctl sim serve-hsr`` makes this image from the simulator's segmentation mask
(:func:`encode_labels`); the backend and ``pfctl replay`` read it with :func:`label_detector`,
the same :class:`~pfctl.core.perception.vision.MaskPersonDetector` the simulated follower uses on
the mask.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from pfctl.core.perception.vision import MaskPersonDetector

PARTS = ("", "head", "torso", "leg")
"""Part names by code ``(v - 1) % 4``; ``""`` is a body pixel of no known part."""
MAX_PEOPLE = 16383
"""The most people one 16-bit image can label (``4 * 16383 + 4 > 65535``)."""
DEFAULT_MAX_PEOPLE = 64
"""People a :func:`label_detector` tells apart by default (index 0 … 63)."""
ENCODING = "16UC1"


def label_value(person: int, part: str = "") -> int:
    """The pixel value of ``part`` of person ``person``."""
    if not 0 <= person < MAX_PEOPLE:
        raise ValueError(f"person index {person} outside 0..{MAX_PEOPLE - 1}")
    return 1 + 4 * int(person) + PARTS.index(part)


def encode_labels(
    mask: np.ndarray, instances: Mapping[int, int], parts: Mapping[int, str]
) -> np.ndarray:
    """The ``uint16`` label image of a body-id mask (the simulator's segmentation): each pixel
    of body ``b`` with ``instances[b] = k`` and ``parts[b] = name`` becomes
    :func:`label_value` ``(k, name)``; every other pixel (walls, the robot, -1 = nothing) is 0."""
    top = max(instances, default=-1) + 1
    table = np.zeros(top + 1, dtype=np.uint16)
    for body, person in instances.items():
        table[body] = label_value(person, parts.get(body, ""))
    ids = np.asarray(mask).astype(np.int64, copy=False)
    ids = np.where((ids >= 0) & (ids < top), ids, top)
    return table[ids]


def label_detector(
    min_pixels: int = 150, max_people: int = DEFAULT_MAX_PEOPLE
) -> MaskPersonDetector:
    """A person detector over frames whose ``mask`` is a label image (one detection per person
    index with at least ``min_pixels`` pixels, its head box and keypoints from the parts)."""
    if not 0 < max_people <= MAX_PEOPLE:
        raise ValueError(f"max_people must be in 1..{MAX_PEOPLE}, got {max_people}")
    instances = {label_value(k, part): k for k in range(max_people) for part in PARTS}
    parts = {label_value(k, part): part for k in range(max_people) for part in PARTS if part}
    return MaskPersonDetector(instances, parts, min_pixels=min_pixels)


__all__ = [
    "DEFAULT_MAX_PEOPLE",
    "ENCODING",
    "MAX_PEOPLE",
    "PARTS",
    "encode_labels",
    "label_detector",
    "label_value",
]
