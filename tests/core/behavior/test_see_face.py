"""The go-and-see-the-face leaf (issue 23, item 3) on a constructed map: where it drives, where
the head aims, when it decides and when it gives up."""

from __future__ import annotations

import math
from types import SimpleNamespace
from typing import Any

import numpy as np
import py_trees
from py_trees.common import Access, Status

from pfctl.core.behavior.blackboard import KEYS, TargetState, new_namespace
from pfctl.core.behavior.leaves import Leaf, SeeFace
from pfctl.core.control import ControlParams
from pfctl.core.mapping.grid import OccupancyGrid
from pfctl.core.mapping.planning import GridPlanner
from pfctl.core.robot import Pose2D

RES = 0.05


def _room() -> GridPlanner:
    """8 m × 6 m, walled round, empty."""
    p = np.zeros((round(6 / RES), round(8 / RES)))
    p[:2, :] = p[-2:, :] = p[:, :2] = p[:, -2:] = 1.0
    return GridPlanner(OccupancyGrid.from_probabilities(p, RES), 0.2)


class Intents:
    """Records what the leaf asks for."""

    def __init__(self) -> None:
        self.goals: list[tuple[float, float]] = []
        self.stops = 0
        self.looks: list[tuple[tuple[float, float], str, float | None]] = []
        self.turns: list[float] = []
        self.nav = "running"
        self.control = ControlParams()
        self.can_speak = False
        self.said: list[str] = []

    def claim(self, action: str) -> None:
        pass

    def release(self) -> None:
        pass

    def stop(self) -> None:
        self.stops += 1

    def go_to(self, xy: tuple[float, float], tolerance: float, face: float | None = None) -> str:
        self.goals.append(xy)
        return self.nav

    def turn(self, wz: float) -> None:
        self.turns.append(wz)

    def say(self, text: str) -> bool:
        if self.can_speak:
            self.said.append(text)
        return self.can_speak

    def look_at(
        self, xy: tuple[float, float], source: str = "target", height: float | None = None
    ) -> None:
        self.looks.append((xy, source, height))


class Rig:
    """A leaf (``leaf_class``, with its defaults and ``params``) on its own blackboard, in the
    empty room, its intents recorded."""

    def __init__(self, leaf_class: type[Leaf] = SeeFace, **params: Any) -> None:
        spec = {p.name: p.default for p in leaf_class.spec.params}
        spec.update(params)
        ns = new_namespace()
        self.leaf = leaf_class(leaf_class.spec.name, ns, spec)
        self.leaf.setup()
        self.bb = py_trees.blackboard.Client(name="rig", namespace=ns)
        for key in KEYS:
            self.bb.register_key(key, access=Access.WRITE)
        self.intents = Intents()
        self.bb.world = SimpleNamespace(planner=_room())
        self.bb.intents, self.bb.target, self.bb.last_seen, self.bb.prediction = (
            self.intents,
            None,
            None,
            None,
        )
        self.bb.stranger, self.bb.head = None, None

    def tick(self, t: float, candidate: TargetState | None, pose: Pose2D) -> Status:
        self.bb.t, self.bb.pose, self.bb.candidate = t, pose, candidate
        self.leaf.tick_once()
        return self.leaf.status


def _bearing(frm: tuple[float, float], to: tuple[float, float]) -> float:
    return math.atan2(to[1] - frm[1], to[0] - frm[0])


def _off(a: float, b: float) -> float:
    return abs((a - b + math.pi) % (2 * math.pi) - math.pi)


def test_a_standing_person_is_seen_from_in_front_on_the_robots_side_head_at_face_height() -> None:
    rig = Rig()
    her = TargetState(7, 6.0, 3.0, 0.0, 0.0, 0.0)
    robot = Pose2D(1.0, 1.0)
    assert rig.tick(0.0, None, robot) is Status.FAILURE  # no one to look at
    assert rig.tick(0.1, her, robot) is Status.RUNNING
    goal = rig.intents.goals[-1]
    assert 1.5 - RES <= math.dist(goal, her.xy) <= 2.5 + RES
    toward_robot = _bearing(her.xy, (robot.x, robot.y))
    assert _off(_bearing(her.xy, goal), toward_robot) <= math.radians(60) + 0.05
    assert rig.intents.looks[-1] == (her.xy, "see_face", 1.55)
    # the face decided (she is named, or he is no longer a candidate): success
    assert rig.tick(0.2, None, robot) is Status.SUCCESS


def test_a_walker_is_met_ahead_of_them_but_not_in_their_way() -> None:
    rig = Rig()
    walker = TargetState(8, 2.0, 3.0, 0.8, 0.0, 0.0)  # walking east
    assert rig.tick(0.0, walker, Pose2D(7.0, 1.0)) is Status.RUNNING
    goal = rig.intents.goals[-1]
    ahead = (2.8, 3.0)  # where they will be in a second
    off = _off(_bearing(ahead, goal), 0.0)
    assert math.radians(20) - 0.05 <= off <= math.radians(60) + 0.05
    assert 1.5 - RES <= math.dist(goal, ahead) <= 2.5 + RES


def test_it_gives_up_after_timeout_and_does_not_try_the_same_person_again_soon() -> None:
    rig = Rig(timeout=5.0, retry_s=30.0)
    him = TargetState(9, 6.0, 3.0, 0.0, 0.0, 0.0)
    robot = Pose2D(1.0, 3.0)
    statuses = [rig.tick(0.1 * k, him, robot) for k in range(60)]
    assert statuses[:50] == [Status.RUNNING] * 50 and statuses[50] is Status.FAILURE
    assert rig.tick(20.0, him, robot) is Status.FAILURE  # within retry_s: not again
    other = TargetState(10, 6.0, 1.0, 0.0, 0.0, 20.0)
    assert rig.tick(20.1, other, robot) is Status.RUNNING  # someone else: yes
    assert rig.tick(40.0, him, robot) is Status.SUCCESS  # the candidate changed: decided
