"""What a follower episode leaves behind: one record per tick, plus the truth beside it.

The follower (:mod:`pfctl.core.follower`) appends a :class:`TickRecord` per behavior-tree tick:
what the robot believed (its pose, the target's track, its awareness, the active action, the
navigation goal). A backend that knows the truth (the simulator) appends the
:class:`~pfctl.core.robot.GroundTruth` of the same instant to :attr:`EpisodeLog.truths`; metrics
(:mod:`pfctl.core.metrics`) compare the two, the follower's decisions never read truth.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from pfctl.core.robot import GroundTruth, Pose2D

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
class WaypointRecord:
    """A way-point Algorithm 1 chose."""

    t: float
    xy: tuple[float, float]
    reason: str
    """``WaypointDecision.reason`` (``frontier``, ``no_frontier_fallback``, ...)."""
    heading_region: str | None


@dataclass
class EpisodeLog:
    """Everything an episode recorded; ``truths`` is empty on a real robot."""

    ticks: list[TickRecord] = field(default_factory=list)
    truths: list[GroundTruth] = field(default_factory=list)
    """The truth at each tick's instant (same length as ``ticks`` when known)."""
    predictions: list[PredictionRecord] = field(default_factory=list)
    waypoints: list[WaypointRecord] = field(default_factory=list)
    target_name: str | None = None
    """The scenario's target (simulator), for the metrics."""
    tracks: list[TrackRow] = field(default_factory=list)
    """After each laser scan a tick fed to the perception (before its camera frame), one row per
    confirmed track seen then (coasting ones are left out), stamped with the scan: what
    ``pfctl replay`` writes after each scan of a bag
    (:func:`pfctl.core.perception.pipeline.track_rows`)."""


__all__ = [
    "AWARENESS",
    "HAS_TARGET",
    "EpisodeLog",
    "PredictionRecord",
    "TickRecord",
    "TrackRow",
    "WaypointRecord",
]
