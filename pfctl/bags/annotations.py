"""Annotated person tracks in a bag (``leg_tracker/Person``: ``pose`` + ``id``), as ground truth.

Leigh et al.'s annotated tracking bags (angusleigh/leg_tracker_benchmarks) publish one
``leg_tracker/Person`` per annotated person, in the laser's frame at the scan it annotates. The
message has no header: the bag time stamps it, and the people of one scan share one bag time.
An annotation follows its scan in the bag: it belongs to the last scan recorded before it, whose
header stamp is about one scan period earlier than the annotation's bag time (the next scan's
stamp is the nearer one, but its people have walked on). :func:`read_annotations` groups them
into :class:`AnnotatedPeople`, one per annotated scan, with that scan's header stamp.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from pfctl.bags.reading import LASER_SCAN, PERSON, Bag, BagError, stamp_seconds

#: Messages whose bag times are closer than this (s) annotate the same scan.
SAME_SCAN_S = 1e-3


@dataclass(frozen=True)
class AnnotatedPeople:
    """The people annotated on one scan: bag time (s), ids, positions ``(n, 2)`` (the laser's
    frame) and the header stamp of the scan they annotate (None: no scan before them)."""

    time: float
    ids: tuple[int, ...]
    xy: np.ndarray
    scan_stamp: float | None = None


def read_annotations(bag: Bag, topic: str, scan_topic: str) -> list[AnnotatedPeople]:
    """The annotated people of ``topic`` (``leg_tracker/Person``), grouped by bag time, each
    group with the stamp of the last ``scan_topic`` scan before it in the bag;
    :class:`~pfctl.bags.reading.BagError` (one line) if the bag has no such topic, the topic
    is of another type or has no messages."""
    bag.require(topic)
    if bag.topics[topic] != PERSON:
        raise BagError(
            f"{bag.path}: topic {topic} is {bag.topics[topic]}, expected leg_tracker/Person "
            "(geometry_msgs/Pose pose, uint32 id)"
        )
    bag.require(scan_topic, LASER_SCAN)
    groups: list[tuple[float, float | None, list[int], list[tuple[float, float]]]] = []
    scan_stamp: float | None = None
    for m in bag.messages([topic, scan_topic]):
        if m.topic == scan_topic:
            scan_stamp = stamp_seconds(m.msg.header)
            continue
        p = m.msg.pose.position
        if not groups or m.time - groups[-1][0] > SAME_SCAN_S:
            groups.append((m.time, scan_stamp, [], []))
        groups[-1][2].append(int(m.msg.id))
        groups[-1][3].append((float(p.x), float(p.y)))
    if not groups:
        raise BagError(f"{bag.path}: topic {topic} has no messages")
    return [
        AnnotatedPeople(t, tuple(ids), np.array(xy, dtype=float).reshape(-1, 2), stamp)
        for t, stamp, ids, xy in groups
    ]


def nearest_scan(stamps: Sequence[float], time: float, tolerance: float) -> int | None:
    """Index of the scan stamp nearest ``time`` (``stamps`` increasing), None when none is
    within ``tolerance`` seconds."""
    if not len(stamps):
        return None
    s = np.asarray(stamps, dtype=float)
    i = int(np.searchsorted(s, time))
    best = min((j for j in (i - 1, i) if 0 <= j < len(s)), key=lambda j: abs(s[j] - time))
    return best if abs(s[best] - time) <= tolerance else None


__all__ = ["SAME_SCAN_S", "AnnotatedPeople", "nearest_scan", "read_annotations"]
