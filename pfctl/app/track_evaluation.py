"""``pfctl track evaluate``: the replay's perception on every scan of a bag, scored by CLEAR-MOT
against the bag's annotated people.

The bag is replayed as ``pfctl replay`` does (:func:`~pfctl.bags.replay.open_replay`: scans
posed in a fixed frame through the bag's tf; leg detection and tracking of the mission's
perception). After each scan the tracks the replay reports (confirmed and seen now: the rows of
``tracks.csv``) are brought into the laser's frame at that scan's stamp — where the annotations
are (:mod:`pfctl.bags.annotations`) — and each annotated scan (the last scan recorded before the
annotation) is scored by :class:`~pfctl.core.perception.clear_mot.ClearMot`.

For rate checks the scans can be thinned (``decimate``: every n-th scan) and each kept scan
repeated ``spread`` times with its stamps spread evenly up to the next kept scan (the same
motion seen at ``spread`` times the rate); a scan is scored at its first copy, and only the
annotations of kept scans count.

An annotator may have marked only the people within part of the laser's view: ``bearings``
(min, max, radians in the laser's frame) then scores only the annotations and the tracks at
bearings in that interval, as the benchmark's own CLEAR-MOT script does
(angusleigh/leg_tracker_benchmarks, ``clear_mot.py``'s ``constrain_to_specific_angle``; −80° to
12° for ``general_tracking_moving``): a person walking beside the robot outside it is tracked
rightly, and is no false positive.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator, Sequence
from contextlib import AbstractContextManager, nullcontext
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TypeVar

import numpy as np

from pfctl.app.perception import build_perception
from pfctl.bags.annotations import AnnotatedPeople, nearest_scan, read_annotations
from pfctl.bags.replay import open_replay
from pfctl.core.perception.clear_mot import ClearMot, ClearMotResult, FrameScore
from pfctl.core.perception.pipeline import Perception
from pfctl.core.robot import LaserScan
from pfctl.errors import UserError
from pfctl.mission import Mission, load_mission

#: Stamps closer than this (s) are the same scan's.
SAME_STAMP_S = 1e-6

Progress = Callable[[int], AbstractContextManager[Callable[[int], None]]]
"""A progress bar up to a total, yielding ``advance(k)``."""


@dataclass(frozen=True)
class ScanTracks:
    """The tracks reported after one scan, in the laser's frame at its stamp."""

    stamp: float
    ids: tuple[int, ...]
    xy: np.ndarray


@dataclass(frozen=True)
class TrackEvaluation:
    """What :func:`evaluate_tracks` measured."""

    result: ClearMotResult
    frames: tuple[FrameScore, ...]
    """One per annotated scan, in time order."""
    truth: tuple[AnnotatedPeople, ...]
    """The annotations scored, each stamped with its scan's stamp."""
    tracks: tuple[ScanTracks, ...]
    """The tracks after every scan (laser frame)."""
    frame: str
    """The fixed frame the tracker ran in."""
    scan_topic: str
    unpaired: int
    """Annotated scans that were not replayed (not posed, or thinned out): not scored."""
    skipped: dict[str, int]


def thinned(
    scans: Iterable[LaserScan], decimate: int, spread: int
) -> Iterator[tuple[LaserScan, bool]]:
    """Every ``decimate``-th scan, each followed by ``spread − 1`` copies stamped evenly up to
    the next one; ``(scan, is_first_copy)``."""
    if decimate < 1 or spread < 1:
        raise ValueError(f"decimate and spread must be ≥ 1, got {decimate} and {spread}")
    kept = (s for k, s in enumerate(scans) if k % decimate == 0)
    previous: LaserScan | None = None
    for scan in kept:
        if previous is not None:
            yield previous, True
            step = (scan.stamp - previous.stamp) / spread
            for k in range(1, spread):
                yield replace(previous, stamp=previous.stamp + k * step), False
        previous = scan
    if previous is not None:
        yield previous, True


_Found = TypeVar("_Found", AnnotatedPeople, ScanTracks)


def _seen_tracks(perception: Perception, scan: LaserScan) -> ScanTracks:
    rows = perception.seen_track_rows(scan.stamp)
    xy = np.array([(r[2], r[3]) for r in rows], dtype=float).reshape(-1, 2)
    local = scan.pose.inverse().transform(xy) if len(xy) else xy
    return ScanTracks(scan.stamp, tuple(r[1] for r in rows), local)


def evaluation_mission(path: Path | None) -> Mission:
    """The mission whose perception parameters to use; without one, every default (a
    placeholder map: the evaluation does not use it)."""
    if path is None:
        placeholder = {"name": "all", "polygon": [[0, 0], [1, 0], [1, 1], [0, 1]]}
        return Mission.model_validate({"name": "track", "map": {"regions": [placeholder]}})
    if not path.is_file():
        raise UserError(f"--mission {path}: no such mission file")
    return load_mission(path)


def evaluate_tracks(
    bag_path: Path,
    ground_truth: str,
    mission: Mission,
    *,
    scan_topic: str | None = None,
    frame: str | None = None,
    radius: float = 0.75,
    decimate: int = 1,
    spread: int = 1,
    bearings: tuple[float, float] | None = None,
    progress: Progress | None = None,
) -> TrackEvaluation:
    """Replay ``bag_path``'s scans through the mission's perception and score the tracks by
    CLEAR-MOT at the scans annotated on ``ground_truth`` (module docstring). One-line
    :class:`~pfctl.errors.UserError` for a bag without the topics or frames asked."""
    if not radius > 0:
        raise UserError(f"--radius: expected a distance > 0 m, got {radius:g}")
    source = open_replay(bag_path, scan_topic=scan_topic, frame=frame, camera=False)
    with source.bag:
        annotations = read_annotations(source.bag, ground_truth, source.scan_topic)
        perception = build_perception(mission)
        bar = nullcontext(None) if progress is None else progress(source.total())
        with bar as advance:
            scans = (
                s for s in (_count(item, advance) for item in source.stream()) if s is not None
            )
            scored = score_scans(
                scans,
                annotations,
                perception,
                radius=radius,
                decimate=decimate,
                spread=spread,
                bearings=bearings,
            )
    if not scored.tracks:
        raise UserError(f"{bag_path}: no scan of {source.scan_topic} could be posed")
    return replace(
        scored, frame=source.frame, scan_topic=source.scan_topic, skipped=dict(source.skipped)
    )


def score_scans(
    scans: Iterable[LaserScan],
    annotations: Sequence[AnnotatedPeople],
    perception: Perception,
    *,
    radius: float = 0.75,
    decimate: int = 1,
    spread: int = 1,
    bearings: tuple[float, float] | None = None,
) -> TrackEvaluation:
    """Run ``perception`` on ``scans`` (posed in a fixed frame, in time order), thinned and
    spread as asked, and score its tracks at the annotated scans (module docstring), only
    within ``bearings`` (min, max, radians in the laser's frame) when given."""
    seen: list[ScanTracks] = []
    for scan, first in thinned(scans, decimate, spread):
        perception.on_scan(scan)
        if first:
            seen.append(_seen_tracks(perception, scan))
    stamps = [s.stamp for s in seen]
    mot = ClearMot(radius)
    truth: list[AnnotatedPeople] = []
    unpaired = 0
    for people in annotations:
        i = (
            None
            if people.scan_stamp is None
            else nearest_scan(stamps, people.scan_stamp, SAME_STAMP_S)
        )
        if i is None:
            unpaired += 1
            continue
        tracks = seen[i]
        if bearings is not None:
            people, tracks = _within(people, bearings), _within(tracks, bearings)
        mot.add(tracks.stamp, people.ids, people.xy, tracks.ids, tracks.xy)
        truth.append(replace(people, time=tracks.stamp))
    return TrackEvaluation(
        mot.result(), tuple(mot.frames), tuple(truth), tuple(seen), "", "", unpaired, {}
    )


def _within(found: _Found, bearings: tuple[float, float]) -> _Found:
    """``found`` with only the people (or tracks) at bearings within ``bearings``."""
    bearing = np.arctan2(found.xy[:, 1], found.xy[:, 0])
    keep = (bearing >= bearings[0]) & (bearing <= bearings[1])
    ids = tuple(i for i, k in zip(found.ids, keep, strict=True) if k)
    return replace(found, ids=ids, xy=found.xy[keep])


def _count(item: object, advance: Callable[[int], None] | None) -> LaserScan | None:
    """``item`` if it is a scan, else None; one step of the progress bar either way."""
    if advance is not None:
        advance(1)
    return item if isinstance(item, LaserScan) else None


__all__ = [
    "Progress",
    "ScanTracks",
    "TrackEvaluation",
    "evaluate_tracks",
    "evaluation_mission",
    "score_scans",
    "thinned",
]
