"""What a follower episode leaves behind: one record per tick, plus the truth beside it.

The follower (:mod:`pfctl.core.follower`) appends a :class:`TickRecord` per behavior-tree tick:
what the robot believed (its pose, the target's track, its awareness, the active action, the
navigation goal). A backend that knows the truth (the simulator) appends the
:class:`~pfctl.core.robot.GroundTruth` of the same instant to :attr:`EpisodeLog.truths`; metrics
(:mod:`pfctl.core.metrics`) compare the two, the follower's decisions never read truth.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from pfctl.core.packed_records import (
    NONE_INDEX,
    PackedRecords,
    RecordCodec,
    StringTable,
    packed_factory,
)
from pfctl.core.robot import GroundTruth, PersonTruth, Pose2D, Twist2D

#: The robot's awareness of the target, as the paper's Fig. 6 shows it over time.
AWARENESS = ("visible", "tracked", "lost", "predicted", "searching")
"""``visible``: the identified target was detected within the last tick or so; ``tracked``: the
tracker still holds the target's track but it is coasting; ``lost``: no target track;
``predicted``: lost, going to or looking at the predicted place; ``searching``: lost, way-point
search (Algorithm 1)."""

#: Awareness values in which the robot has the target.
HAS_TARGET = ("visible", "tracked")


@dataclass(frozen=True)
class TickRecord:
    """One behavior-tree tick as the robot saw it (never ground truth)."""

    t: float
    pose: Pose2D
    """The robot's believed pose in the map frame."""
    awareness: str
    """One of :data:`AWARENESS`."""
    action: str | None
    """The action leaf that ran (running or just finished) on this tick, e.g. ``follow_target``."""
    target_id: int | None = None
    """The track Algorithm 2 names the target, if any."""
    target_xy: tuple[float, float] | None = None
    """That track's position estimate."""
    goal: tuple[float, float] | None = None
    """The navigation goal being driven to, if any."""
    base_mode: str = "stop"
    """How the base moved: ``turn``, ``go_straight``, ``move_base``, ``hold`` or ``stop``."""
    gaze: str = "none"
    """What the head looked at: ``target``, ``belief``, ``legs``, ``sweep`` or ``none``."""


TrackRow = tuple[float, int, float, float, float, float, float, bool]
"""``(t, track_id, x, y, vx, vy, confidence, is_target)``."""


@dataclass(frozen=True, eq=False)
class PredictionRecord:
    """A prediction made when the target was lost: where from and where to (map frame)."""

    t: float
    last_seen: tuple[float, float]
    path: np.ndarray
    """``(k, 2)`` predicted positions, the last one the goal."""
    goal: tuple[float, float]
    """Where the robot went to look (the path's end, moved into free space)."""


@dataclass(frozen=True)
class SpeechRecord:
    """What the robot said (:class:`~pfctl.core.robot.Speaker`), when, and where it stood."""

    t: float
    xy: tuple[float, float]
    text: str


@dataclass(frozen=True)
class RoomPredictionRecord:
    """Which room the lost target is in ``horizon_s`` after the loss at ``t``, as the belief over
    where she can be predicts it (``ranked``, most likely first), beside Algorithm 1's answer:
    ``heading`` (l*, the room she was last seen heading to) and ``current`` (her room then)."""

    t: float
    ranked: tuple[str, ...]
    heading: str | None
    current: str | None
    horizon_s: float


@dataclass(frozen=True)
class WaypointRecord:
    """A way-point Algorithm 1 chose."""

    t: float
    xy: tuple[float, float]
    reason: str
    """``WaypointDecision.reason`` (``frontier``, ``no_frontier_fallback``, ...)."""
    heading_region: str | None


class TickCodec(RecordCodec[TickRecord]):
    """A :class:`TickRecord` as one row (:mod:`pfctl.core.packed_records`)."""

    dtype = np.dtype(
        [
            ("t", "f8"),
            ("x", "f8"),
            ("y", "f8"),
            ("theta", "f8"),
            ("awareness", "i2"),
            ("action", "i2"),
            ("base_mode", "i2"),
            ("gaze", "i2"),
            ("has_target", "?"),
            ("target_id", "i8"),
            ("has_target_xy", "?"),
            ("target_x", "f8"),
            ("target_y", "f8"),
            ("has_goal", "?"),
            ("goal_x", "f8"),
            ("goal_y", "f8"),
        ]
    )

    def __init__(self) -> None:
        self.strings = StringTable()

    def encode(self, record: TickRecord) -> tuple[Any, ...]:
        s = self.strings.encode
        target_xy, goal = record.target_xy or (0.0, 0.0), record.goal or (0.0, 0.0)
        return (
            record.t,
            record.pose.x,
            record.pose.y,
            record.pose.theta,
            s(record.awareness),
            s(record.action),
            s(record.base_mode),
            s(record.gaze),
            record.target_id is not None,
            0 if record.target_id is None else record.target_id,
            record.target_xy is not None,
            *target_xy,
            record.goal is not None,
            *goal,
        )

    def decode(self, row: tuple[Any, ...]) -> TickRecord:
        t, x, y, theta, awareness, action, base_mode, gaze = row[:8]
        has_target, target_id, has_xy, tx, ty, has_goal, gx, gy = row[8:]
        s = self.strings.decode
        return TickRecord(
            t=t,
            pose=Pose2D(x, y, theta),
            awareness=s(awareness),  # type: ignore[arg-type]
            action=s(action),
            target_id=target_id if has_target else None,
            target_xy=(tx, ty) if has_xy else None,
            goal=(gx, gy) if has_goal else None,
            base_mode=s(base_mode),  # type: ignore[arg-type]
            gaze=s(gaze),  # type: ignore[arg-type]
        )


class PersonTruthCodec(RecordCodec[PersonTruth]):
    """A :class:`~pfctl.core.robot.PersonTruth` as one row, its name in ``strings``."""

    dtype = np.dtype(
        [
            ("name", "i4"),
            ("x", "f8"),
            ("y", "f8"),
            ("theta", "f8"),
            ("speed", "f8"),
            ("is_target", "?"),
        ]
    )

    def __init__(self, strings: StringTable) -> None:
        self.strings = strings

    def encode(self, record: PersonTruth) -> tuple[Any, ...]:
        return (
            self.strings.encode(record.name),
            record.x,
            record.y,
            record.theta,
            record.speed,
            record.is_target,
        )

    def decode(self, row: tuple[Any, ...]) -> PersonTruth:
        name, x, y, theta, speed, is_target = row
        return PersonTruth(self.strings.decode(name), x, y, theta, speed, is_target)  # type: ignore[arg-type]


class GroundTruthCodec(RecordCodec[GroundTruth]):
    """A :class:`~pfctl.core.robot.GroundTruth` as one row; its people are rows of a nested
    store (the row holds where they start and how many), a non-empty ``extra`` an entry of a
    list."""

    dtype = np.dtype(
        [
            ("stamp", "f8"),
            ("x", "f8"),
            ("y", "f8"),
            ("theta", "f8"),
            ("vx", "f8"),
            ("vy", "f8"),
            ("wz", "f8"),
            ("collisions", "i8"),
            ("first_person", "i8"),
            ("people", "i4"),
            ("extra", "i8"),
        ]
    )

    def __init__(self) -> None:
        self.people: PackedRecords[PersonTruth] = PackedRecords(PersonTruthCodec(StringTable()))
        self.extras: list[dict[str, float]] = []

    def encode(self, record: GroundTruth) -> tuple[Any, ...]:
        first = len(self.people)
        self.people.extend(record.people)
        extra = NONE_INDEX
        if record.extra:
            extra = len(self.extras)
            self.extras.append(dict(record.extra))
        robot, command = record.robot, record.command
        return (
            record.stamp,
            robot.x,
            robot.y,
            robot.theta,
            command.vx,
            command.vy,
            command.wz,
            record.collisions,
            first,
            len(record.people),
            extra,
        )

    def decode(self, row: tuple[Any, ...]) -> GroundTruth:
        stamp, x, y, theta, vx, vy, wz, collisions, first, count, extra = row
        return GroundTruth(
            stamp=stamp,
            robot=Pose2D(x, y, theta),
            people=tuple(self.people[first + k] for k in range(count)),
            command=Twist2D(vx, vy, wz),
            collisions=collisions,
            extra={} if extra == NONE_INDEX else dict(self.extras[extra]),
        )


class TrackRowCodec(RecordCodec[TrackRow]):
    """A :data:`TrackRow` as one row (the tuple's order)."""

    dtype = np.dtype(
        [
            ("t", "f8"),
            ("track_id", "i8"),
            ("x", "f8"),
            ("y", "f8"),
            ("vx", "f8"),
            ("vy", "f8"),
            ("confidence", "f8"),
            ("is_target", "?"),
        ]
    )

    def encode(self, record: TrackRow) -> tuple[Any, ...]:
        return tuple(record)

    def decode(self, row: tuple[Any, ...]) -> TrackRow:
        return row  # type: ignore[return-value]


def packed_ticks(records: Iterable[TickRecord] = ()) -> PackedRecords[TickRecord]:
    """A packed sequence of ticks."""
    return PackedRecords(TickCodec(), records)


def packed_truths(records: Iterable[GroundTruth] = ()) -> PackedRecords[GroundTruth]:
    """A packed sequence of truths."""
    return PackedRecords(GroundTruthCodec(), records)


def packed_track_rows(records: Iterable[TrackRow] = ()) -> PackedRecords[TrackRow]:
    """A packed sequence of track rows."""
    return PackedRecords(TrackRowCodec(), records)


@dataclass(frozen=True)
class TickColumns:
    """The ticks of a log as arrays, one entry per tick (what metrics and plots read)."""

    t: np.ndarray
    pose_xy: np.ndarray
    """``(n, 2)`` believed robot positions."""
    awareness: list[str]
    action: list[str | None]
    target_xy: np.ndarray
    """``(n, 2)`` the target track's position, NaN where there is none."""


@dataclass(frozen=True)
class TruthColumns:
    """The truths of a log as arrays and plain lists, one entry per truth."""

    robot_xy: np.ndarray
    """``(n, 2)`` true robot positions."""
    people: list[list[tuple[str, float, float, bool]]]
    """Per truth, its people as ``(name, x, y, is_target)`` in their order."""


def tick_columns(ticks: PackedRecords[TickRecord]) -> TickColumns:
    """``ticks`` as :class:`TickColumns`, read from the packed rows without making records."""
    strings = ticks.codec.strings  # type: ignore[attr-defined]
    target_xy = np.stack([ticks.column("target_x"), ticks.column("target_y")], axis=1)
    target_xy[~ticks.column("has_target_xy")] = np.nan
    return TickColumns(
        t=ticks.column("t"),
        pose_xy=np.stack([ticks.column("x"), ticks.column("y")], axis=1),
        awareness=strings.decode_all(ticks.column("awareness")),
        action=strings.decode_all(ticks.column("action")),
        target_xy=target_xy,
    )


def truth_columns(truths: PackedRecords[GroundTruth]) -> TruthColumns:
    """``truths`` as :class:`TruthColumns`, read from the packed rows without making records."""
    people_store = truths.codec.people  # type: ignore[attr-defined]
    everyone = list(
        zip(
            people_store.codec.strings.decode_all(people_store.column("name")),
            people_store.column("x").tolist(),
            people_store.column("y").tolist(),
            people_store.column("is_target").tolist(),
            strict=True,
        )
    )
    spans = zip(
        truths.column("first_person").tolist(), truths.column("people").tolist(), strict=True
    )
    return TruthColumns(
        robot_xy=np.stack([truths.column("x"), truths.column("y")], axis=1),
        people=[everyone[first : first + count] for first, count in spans],
    )


@dataclass
class EpisodeLog:
    """Everything an episode recorded; ``truths`` is empty on a real robot.

    The per-tick records (``ticks``, ``truths``, ``tracks``) are kept packed
    (:class:`~pfctl.core.packed_records.PackedRecords`, a few hundred bytes a tick rather than
    kilobytes) so that an episode of hours stays small; lists given here are packed."""

    ticks: PackedRecords[TickRecord] = field(default_factory=packed_factory(TickCodec))
    truths: PackedRecords[GroundTruth] = field(default_factory=packed_factory(GroundTruthCodec))
    """The truth at each tick's instant (same length as ``ticks`` when known)."""
    predictions: list[PredictionRecord] = field(default_factory=list)
    waypoints: list[WaypointRecord] = field(default_factory=list)
    room_predictions: list[RoomPredictionRecord] = field(default_factory=list)
    target_name: str | None = None
    """The scenario's target (simulator), for the metrics."""
    tracks: PackedRecords[TrackRow] = field(default_factory=packed_factory(TrackRowCodec))
    """After each laser scan a tick fed to the perception (before its camera frame), one row per
    confirmed track seen then (coasting ones are left out), stamped with the scan: what
    ``pfctl replay`` writes after each scan of a bag
    (:func:`pfctl.core.perception.pipeline.track_rows`)."""
    speech: list[SpeechRecord] = field(default_factory=list)
    """What the robot said aloud, in order."""

    def __post_init__(self) -> None:
        if not isinstance(self.ticks, PackedRecords):
            self.ticks = packed_ticks(self.ticks)
        if not isinstance(self.truths, PackedRecords):
            self.truths = packed_truths(self.truths)
        if not isinstance(self.tracks, PackedRecords):
            self.tracks = packed_track_rows(self.tracks)


__all__ = [
    "AWARENESS",
    "HAS_TARGET",
    "EpisodeLog",
    "GroundTruthCodec",
    "PredictionRecord",
    "RoomPredictionRecord",
    "SpeechRecord",
    "TickCodec",
    "TickColumns",
    "TickRecord",
    "TrackRow",
    "TrackRowCodec",
    "TruthColumns",
    "WaypointRecord",
    "packed_ticks",
    "packed_track_rows",
    "packed_truths",
]
