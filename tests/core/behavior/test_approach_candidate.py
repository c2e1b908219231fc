"""way-point search goes up to a standing person in her clothes whose face has not decided
(generated home 50: seen through a door 5 m off, S ≈ 0.65, her face too small to count): to
``APPROACH_TO`` m, head on the face, for at most ``APPROACH_S`` per person; walkers are not
chased, and a person it cannot reach is left."""

from __future__ import annotations

import math
from types import SimpleNamespace

import py_trees
import pytest
from py_trees.common import Access, Status

from pfctl.core.behavior.blackboard import KEYS, TargetState, new_namespace
from pfctl.core.behavior.leaves import WaypointSearch
from pfctl.core.robot import Pose2D
from tests.core.behavior.test_see_face import Intents, _room


class Rig:
    def __init__(self) -> None:
        ns = new_namespace()
        self.leaf = WaypointSearch("waypoint_search", ns, {"tolerance": 0.4})
        self.leaf.setup()
        self.bb = py_trees.blackboard.Client(name="rig", namespace=ns)
        for key in KEYS:
            self.bb.register_key(key, access=Access.WRITE)
        self.intents = Intents()
        self.stops = 0
        self.intents.stop = self._stop  # type: ignore[method-assign]
        self.bb.world = SimpleNamespace(planner=_room())
        self.bb.intents, self.bb.target, self.bb.last_seen, self.bb.prediction = (
            self.intents,
            None,
            None,
            None,
        )
        self.bb.t, self.bb.pose, self.bb.candidate = 0.0, Pose2D(1.0, 3.0), None
        self.leaf.initialise()

    def _stop(self) -> None:
        self.stops += 1

    def approach(self, t: float, candidate: TargetState | None, pose: Pose2D) -> bool:
        self.bb.t, self.bb.pose, self.bb.candidate = t, pose, candidate
        return self.leaf._approach_candidate()


def test_a_standing_candidate_is_gone_up_to_head_on_the_face_then_left_after_a_while() -> None:
    rig = Rig()
    her = TargetState(4, 6.0, 3.0, 0.05, 0.0, 0.0)  # standing, 5 m east of the robot
    robot = Pose2D(1.0, 3.0)
    assert rig.approach(0.0, her, robot)
    goal = rig.intents.goals[-1]
    assert math.dist(goal, her.xy) == pytest.approx(WaypointSearch.APPROACH_TO)
    assert goal[0] < her.x  # on the robot's side of her
    assert rig.intents.looks[-1] == (her.xy, "candidate", WaypointSearch.FACE_HEIGHT)
    # close enough: the base stops, the head stays on her
    near = Pose2D(6.0 - WaypointSearch.APPROACH_TO + 0.1, 3.0)
    assert rig.approach(5.0, her, near) and rig.stops == 1
    # her face never turned to the robot: after APPROACH_S the search goes on past her
    assert not rig.approach(WaypointSearch.APPROACH_S + 0.1, her, near)
    someone_else = TargetState(5, 6.0, 1.0, 0.0, 0.0, 0.0)
    assert rig.approach(WaypointSearch.APPROACH_S + 0.2, someone_else, near)


def test_no_candidate_or_a_walker_is_not_gone_after() -> None:
    rig = Rig()
    assert not rig.approach(0.0, None, Pose2D(1.0, 3.0))
    walker = TargetState(6, 6.0, 3.0, 0.7, 0.0, 0.0)
    assert not rig.approach(0.1, walker, Pose2D(1.0, 3.0))
    assert rig.intents.goals == [] and rig.intents.looks == []


def test_a_candidate_it_cannot_drive_to_is_left_at_once() -> None:
    rig = Rig()
    rig.intents.nav = "failed"
    her = TargetState(7, 6.0, 3.0, 0.0, 0.0, 0.0)
    assert not rig.approach(0.0, her, Pose2D(1.0, 3.0))
    rig.intents.nav = "running"
    assert not rig.approach(0.1, her, Pose2D(1.0, 3.0))  # not tried again


def test_the_leaf_runs_the_approach_before_its_search() -> None:
    rig = Rig()
    her = TargetState(8, 6.0, 3.0, 0.0, 0.0, 0.0)
    rig.bb.t, rig.bb.candidate = 0.1, her
    rig.leaf.tick_once()
    assert rig.leaf.status is Status.RUNNING
    assert rig.intents.looks[-1][1] == "candidate"
