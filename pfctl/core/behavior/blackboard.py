"""The behavior tree's shared state: declared py_trees blackboard keys (§II-A).

The follower (:mod:`pfctl.core.follower`) writes the state keys once per tick, before the tree
is ticked; leaves (:mod:`pfctl.core.behavior.leaves`) declare which of them they read or write:
they read the state and the world model and write their intents (``intents``) — never a command
to the robot — and way-point search writes its latest decision (``waypoint``). One key is
privileged: ``true_target``, the simulator's truth of where the target is, which the app layer
fills only for a tree that names the oracle baseline's ``oracle_search``, the only leaf that
declares it (a leaf reads only the keys it declares). Each
follower has its own namespace (:func:`new_namespace`), so two followers in one process (tests,
campaigns) never share state; :func:`clear_namespace` drops one when its follower closes.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field

import numpy as np
import py_trees

from pfctl.core.robot import Pose2D

#: The declared keys and what they hold.
KEYS: dict[str, str] = {
    "t": "time of this tick, s (simulated or ROS time)",
    "pose": "Pose2D: the robot's believed pose in the map frame",
    "target": "TargetState | None: the identified target's track, if the tracker still has it",
    "last_seen": "Sighting | None: where and when the target was last detected, with its path",
    "prediction": "PredictionState | None: where the lost target is predicted to have gone",
    "world": "WorldModel: the robot's occupancy grid, the static map's planner, the regions and "
    "the people it tracks, for the leaves' control laws and Algorithm 1",
    "intents": "Intents: what the leaves want the base and the head to do this tick",
    "candidate": "TargetState | None: while she is not named, an ambiguous person (her clothes, "
    "no face seen yet, not known to be someone else) worth going to see the face of (see_face)",
    "head": "HeadState: the head's pan and tilt now (joint angles, rad)",
    "stranger": "TargetState | None: while she is not named, the nearest person in sight whom "
    "no camera frame has shown yet (the laser's legs alone), worth a glance (waypoint_search)",
    "waypoint": "WaypointDecision | None: Algorithm 1's latest way-point (waypoint_search)",
    "true_target": "PRIVILEGED (simulator's ground truth) tuple[float, float] | None: where the "
    "target really is; filled only for a tree naming oracle_search, the one leaf that reads it",
}

_counter = itertools.count(1)


def new_namespace() -> str:
    """A fresh namespace such as ``/follower_3`` for one follower's keys."""
    return f"/follower_{next(_counter)}"


def clear_namespace(namespace: str) -> None:
    """Remove every key under ``namespace`` from the (process-wide) blackboard."""
    prefix = namespace.rstrip("/") + "/"
    for key in list(py_trees.blackboard.Blackboard.storage):
        if key.startswith(prefix):
            py_trees.blackboard.Blackboard.unset(key)


@dataclass(frozen=True)
class TargetState:
    """The identified target's track this tick."""

    track_id: int
    x: float
    y: float
    vx: float
    vy: float
    last_detected: float
    """Stamp of the track's last associated detection (laser legs or camera), s."""

    @property
    def xy(self) -> tuple[float, float]:
        return (self.x, self.y)


@dataclass(frozen=True, eq=False)
class Sighting:
    """The target's last detection: when, where, and its detected path before (``(k, 3)`` rows
    ``t, x, y``) for prediction (§II-E) and Algorithm 1's heading region."""

    t: float
    xy: tuple[float, float]
    history: np.ndarray = field(repr=False)


@dataclass(eq=False)
class PredictionState:
    """A prediction made when the target was lost; leaves mark how far it has been used."""

    made_at: float
    last_seen: tuple[float, float]
    path: np.ndarray = field(repr=False)
    """``(k, 2)`` predicted positions (clipped to the map)."""
    goal: tuple[float, float]
    """Where to go and look: the clipped path's end, moved into free space for the robot."""
    region: str | None = None
    """The region the goal lies in."""
    reached: bool = False
    """The robot has arrived at the goal."""
    used: bool = False
    """The place has been looked at (or could not be reached): no longer available."""

    @property
    def available(self) -> bool:
        return not self.used


__all__ = [
    "KEYS",
    "Pose2D",
    "PredictionState",
    "Sighting",
    "TargetState",
    "clear_namespace",
    "new_namespace",
]
