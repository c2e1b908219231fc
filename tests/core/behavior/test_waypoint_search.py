"""The way-point search leaf on constructed maps. It goes up to a standing person in her clothes
whose face has not decided (generated home 50: seen through a door 5 m off, S ≈ 0.65, her face
too small to count): to ``APPROACH_TO`` m, head on them, round to their front when they show
no face, for at most ``approach_s`` per person once near; walkers are not chased, and a person
it cannot reach is left. It leaves the frontiers
round which the camera has looked, and with none worth a visit it looks where the belief says."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest
from py_trees.common import Status

from pfctl.core.behavior.blackboard import TargetState
from pfctl.core.behavior.leaves import WaypointSearch
from pfctl.core.mapping.frontiers import FrontierCluster
from pfctl.core.mapping.grid import OccupancyGrid
from pfctl.core.mapping.planning import GridPlanner
from pfctl.core.mapping.regions import RegionMap, SearchParams, WaypointDecision
from pfctl.core.perception.viewpoints import face_viewpoint
from pfctl.core.robot import HeadState, Pose2D
from pfctl.core.search.next_look import STEP_IN
from pfctl.core.search.whereabouts import Whereabouts
from tests.core.behavior.test_see_face import Rig as LeafRig
from tests.core.behavior.test_see_face import _room
from tests.core.search.test_whereabouts import GEOMETRY, HOME, PARAMS

APPROACH_S = next(p.default for p in WaypointSearch.spec.params if p.name == "approach_s")
"""The leaf's default ``approach_s``, s."""


class Rig(LeafRig):
    def __init__(self) -> None:
        super().__init__(WaypointSearch)
        self.bb.t, self.bb.pose, self.bb.candidate = 0.0, Pose2D(1.0, 3.0), None
        self.leaf.initialise()

    @property
    def stops(self) -> int:
        return self.intents.stops

    def approach(self, t: float, candidate: TargetState | None, pose: Pose2D) -> bool:
        self.bb.t, self.bb.pose, self.bb.candidate = t, pose, candidate
        return self.leaf._approach_candidate()


def test_a_standing_candidate_is_gone_up_to_head_on_them_then_left_after_a_while() -> None:
    rig = Rig()
    her = TargetState(4, 6.0, 3.0, 0.05, 0.0, 0.0)  # standing, 5 m east of the robot
    robot = Pose2D(1.0, 3.0)
    assert rig.approach(0.0, her, robot)
    goal = rig.intents.goals[-1]
    # the nearest place within APPROACH_TO of her: on the robot's side, about that far
    assert WaypointSearch.APPROACH_TO - 0.1 <= math.dist(goal, her.xy) <= WaypointSearch.APPROACH_TO
    assert goal[0] < her.x
    # the head on her torso (the control's look height): her whole body and face in the frame
    assert rig.intents.looks[-1] == (her.xy, "candidate", None)
    # there: the base stops, the head stays on her
    rig.intents.nav = "arrived"
    assert rig.approach(5.0, her, Pose2D(*goal)) and rig.stops == 1
    assert rig.intents.looks[-1][1] == "candidate"
    # its MOVE_BASE stopped a few centimetres short: the place chosen again is not driven to
    rig.intents.nav = "running"
    sent = len(rig.intents.goals)
    short = Pose2D(goal[0] - 0.12, goal[1])
    assert rig.approach(5.0 + WaypointSearch.APPROACH_REPLAN_S, her, short) and rig.stops == 2
    assert len(rig.intents.goals) == sent
    # no face: APPROACH_LOOK_S after it got there, the robot goes round to her front; it
    # gets there 5 s later, and her face never turns to it
    round_from = 5.0 + WaypointSearch.APPROACH_LOOK_S
    assert rig.approach(round_from, her, Pose2D(*goal))
    front = rig.intents.goals[-1]
    assert front[0] > her.x
    rig.intents.nav = "arrived"
    assert rig.approach(round_from + 5.0, her, Pose2D(*front))
    # approach_s after it came near, less the way round, the search goes on
    near = 5.0  # APPROACH_NEAR was first reached at the place (the robot was 5 m off at 0 s)
    assert rig.approach(near + APPROACH_S + 5.0 - 0.1, her, Pose2D(*front))
    assert not rig.approach(near + APPROACH_S + 5.0 + 0.1, her, Pose2D(*front))
    someone_else = TargetState(5, 6.0, 1.0, 0.0, 0.0, 0.0)
    rig.intents.nav = "running"
    assert rig.approach(near + APPROACH_S + 5.2, someone_else, Pose2D(*front))


def test_a_candidate_who_shows_no_face_is_seen_from_in_front() -> None:
    """Generated home 28 (``pfctl search``): she stood with her back to the laundry's door;
    the robot went to the nearest place to see her from, looked at her back until it gave up
    and searched on. At the place ``APPROACH_LOOK_S`` without a face deciding, it goes round
    to a place in front of her: beyond her as seen from where it stood, as far."""
    rig = Rig()
    her = TargetState(4, 5.0, 3.0, 0.0, 0.0, 0.0)
    assert rig.approach(0.0, her, Pose2D(1.0, 3.0))
    first = rig.intents.goals[-1]
    assert first[0] < her.x
    rig.intents.nav = "arrived"
    assert rig.approach(4.0, her, Pose2D(*first))
    rig.intents.nav = "running"
    sent = len(rig.intents.goals)
    assert rig.approach(4.0 + WaypointSearch.APPROACH_LOOK_S - 0.1, her, Pose2D(*first))
    assert len(rig.intents.goals) == sent  # still looking from there
    assert rig.approach(4.0 + WaypointSearch.APPROACH_LOOK_S, her, Pose2D(*first))
    front = rig.intents.goals[-1]
    assert front[0] > her.x  # the far side: she faces away from where the robot stood
    assert abs(math.atan2(front[1] - her.y, front[0] - her.x)) <= math.radians(60) + 1e-6
    dist = math.dist(front, her.xy)
    assert WaypointSearch.APPROACH_MIN <= dist <= WaypointSearch.APPROACH_TO + 1e-9
    assert rig.intents.looks[-1][:2] == (her.xy, "candidate")


def test_a_robot_that_speaks_asks_her_once_on_its_way_and_waits_before_going_round() -> None:
    """The crowd, seeds 7, 10, 29 and 41: she stood facing the office's west wall 0.9 m off;
    no place in front of her could be reached, and the robot looked at her back until it gave
    up. The shipped house with ``face_to_rename``, seed 4: asked only ``APPROACH_LOOK_S``
    after it reached its place, her face came 4.2 s after her back was in view. A robot that
    speaks asks her, once, when the camera has been on her back ``ASK_LOOK_S`` within
    ``APPROACH_NEAR``, drives on to its place while she turns, and stands there, head on her,
    until ``ask_s`` has passed since it asked; then, no face decided, it goes round as one
    without a voice does. Farther off, or the camera elsewhere, it does not ask."""
    rig = Rig()
    rig.intents.can_speak = True
    wait = next(p.default for p in WaypointSearch.spec.params if p.name == "ask_s")
    look = WaypointSearch.ASK_LOOK_S
    her = TargetState(4, 5.0, 3.0, 0.0, 0.0, 0.0)
    assert rig.approach(0.0, her, Pose2D(1.0, 3.0))  # 4 m off: too far for her face
    first = rig.intents.goals[-1]
    assert rig.approach(look + 0.5, her, Pose2D(1.9, 3.0))  # 3.1 m off
    rig.bb.head = HeadState(pan=math.pi / 2, tilt=0.0)  # the camera elsewhere
    assert rig.approach(2.0, her, Pose2D(2.1, 3.0))  # 2.9 m off
    assert rig.approach(2.0 + look + 0.5, her, Pose2D(2.1, 3.0))
    rig.bb.head = HeadState(pan=0.0, tilt=0.0)  # on her from now
    on = 2.0 + look + 0.5
    assert rig.approach(on, her, Pose2D(2.2, 3.0))
    assert rig.approach(on + look - 0.1, her, Pose2D(2.3, 3.0))
    assert rig.intents.said == []  # not yet: she may be turning anyway
    sent, stops = len(rig.intents.goals), rig.intents.stops
    asked = on + look
    assert rig.approach(asked, her, Pose2D(2.4, 3.0))
    assert rig.intents.said == [WaypointSearch.ASK]
    assert len(rig.intents.goals) == sent + 1 and rig.intents.stops == stops  # drives on
    assert rig.intents.goals[-1] == first
    rig.intents.nav = "arrived"
    assert rig.approach(asked + 0.5, her, Pose2D(*first))
    sent = len(rig.intents.goals)
    for t in np.arange(asked + 0.5, asked + wait - 0.05, 0.5):  # past APPROACH_LOOK_S there
        assert rig.approach(float(t), her, Pose2D(*first))
    assert asked + wait - 0.5 - WaypointSearch.APPROACH_LOOK_S > asked + 0.5
    assert len(rig.intents.goals) == sent  # standing there, not going round
    assert rig.intents.stops > stops
    assert rig.intents.looks[-1][:2] == (her.xy, "candidate")
    assert rig.approach(asked + wait, her, Pose2D(*first))
    front = rig.intents.goals[-1]
    assert front[0] > her.x  # round to her front now
    assert rig.intents.said == [WaypointSearch.ASK]  # once
    # ask_s 0: never asks, goes round at once
    quiet = Rig()
    quiet.leaf.params["ask_s"] = 0.0
    quiet.intents.can_speak = True
    assert quiet.approach(0.0, her, Pose2D(1.0, 3.0))
    quiet.intents.nav = "arrived"
    assert quiet.approach(4.0, her, Pose2D(*first))
    assert quiet.approach(4.0 + WaypointSearch.APPROACH_LOOK_S, her, Pose2D(*first))
    assert quiet.intents.said == [] and quiet.intents.goals[-1][0] > her.x


def test_the_way_up_to_a_candidate_does_not_count_against_approach_s() -> None:
    """Generated home 41: 15 s went on the way to her, across the room, and the robot gave up
    before it was near. ``approach_s`` counts from ``APPROACH_NEAR``; the way there is bounded
    by ``APPROACH_TRAVEL_S`` more."""
    rig = Rig()
    her = TargetState(4, 7.0, 3.0, 0.0, 0.0, 0.0)
    far = Pose2D(0.5, 3.0)  # 6.5 m off
    assert rig.approach(0.0, her, far)
    assert rig.approach(APPROACH_S + 5.0, her, Pose2D(3.5, 3.0))  # on the way, 3.5 m off
    assert rig.approach(APPROACH_S + 6.0, her, Pose2D(4.2, 3.0))  # near now
    assert not rig.approach(2 * APPROACH_S + 6.1, her, Pose2D(4.8, 3.0))
    # someone it never gets near is left after APPROACH_TRAVEL_S + approach_s
    someone = TargetState(5, 7.0, 1.0, 0.0, 0.0, 0.0)
    bound = WaypointSearch.APPROACH_TRAVEL_S + APPROACH_S
    start = 100.0
    assert rig.approach(start, someone, far)
    assert rig.approach(start + bound - 0.1, someone, far)
    assert not rig.approach(start + bound + 0.1, someone, far)


def test_she_is_gone_up_to_where_she_is_in_sight_not_through_a_wall() -> None:
    """Generated home 6: she stood in the bedroom 1.5 m to the side of its door, the robot in
    the corridor; 2.2 m along the straight line to her the robot stood behind the wall, its
    laser blind to her legs, and she was named only 15 s later. The place is one she is in
    sight from."""
    rig = Rig()
    p = np.zeros((round(6 / 0.05), round(8 / 0.05)))
    p[:2, :] = p[-2:, :] = p[:, :2] = p[:, -2:] = 1.0
    p[:, 80:82] = 1.0  # a wall at x = 4 m ...
    p[90:100, 80:82] = 0.0  # ... with a door at y 4.5-5 m
    rig.bb.world = SimpleNamespace(
        planner=GridPlanner(OccupancyGrid.from_probabilities(p, 0.05), 0.2)
    )
    her = TargetState(4, 5.0, 2.5, 0.0, 0.0, 0.0)  # beyond the wall, south of the door
    assert rig.approach(0.0, her, Pose2D(2.5, 2.5))
    goal = rig.intents.goals[-1]
    assert goal[0] > 4.1  # through the door, on her side of the wall
    assert math.dist(goal, her.xy) <= WaypointSearch.APPROACH_TO + 1e-9


def test_the_way_round_to_her_front_does_not_count_against_approach_s_for_a_while() -> None:
    """House seed 30: she stood facing a corner; the way round to her front took the rest of
    ``approach_s``. It does not count, for ``APPROACH_ROUND_S`` at most."""
    rig = Rig()
    her = TargetState(4, 5.0, 3.0, 0.0, 0.0, 0.0)
    rig.intents.nav = "arrived"
    assert rig.approach(0.0, her, Pose2D(3.0, 3.0))  # near at once, and there
    rig.intents.nav = "running"
    assert rig.approach(WaypointSearch.APPROACH_LOOK_S, her, Pose2D(3.0, 3.0))  # round now
    bound = APPROACH_S + WaypointSearch.APPROACH_ROUND_S
    assert rig.approach(bound - 0.1, her, Pose2D(4.0, 4.5))  # still on the way round
    assert not rig.approach(bound + 0.1, her, Pose2D(4.0, 4.5))


def test_nearer_a_candidate_the_head_aims_higher_up_to_the_face() -> None:
    """House seed 30: 0.9 m from her, the head aimed at her torso, the frame's top edge was at
    her shoulders. From ``APPROACH_TO`` m on the aim rises to ``APPROACH_FACE_HEIGHT`` at
    ``APPROACH_MIN``."""
    rig = Rig()
    her = TargetState(4, 5.0, 3.0, 0.0, 0.0, 0.0)
    heights = []
    for d in (3.0, WaypointSearch.APPROACH_TO, 1.6, WaypointSearch.APPROACH_MIN, 0.8):
        assert rig.approach(0.0, her, Pose2D(5.0 - d, 3.0))
        heights.append(rig.intents.looks[-1][2])
    torso = rig.intents.control.look_height
    assert heights[:2] == [None, None]
    assert torso < heights[2] < WaypointSearch.APPROACH_FACE_HEIGHT
    assert heights[3] == heights[4] == pytest.approx(WaypointSearch.APPROACH_FACE_HEIGHT)


def test_her_new_track_where_she_stood_goes_on_with_her_approach() -> None:
    """House seed 30: a walker passing her pulled her track's speed up for a second, then took
    the track away; her new track began afresh, from the side she did not face. A candidate
    near where she stood counts as standing, and a new track there goes on with her approach:
    to the front it was going round to, on the time it had."""
    rig = Rig()
    her = TargetState(4, 5.0, 3.0, 0.0, 0.0, 0.0)
    rig.intents.nav = "arrived"
    assert rig.approach(0.0, her, Pose2D(3.0, 3.0))
    rig.intents.nav = "running"
    assert rig.approach(WaypointSearch.APPROACH_LOOK_S, her, Pose2D(3.0, 3.0))
    front = rig.intents.goals[-1]
    assert front[0] > her.x
    jostled = TargetState(4, 5.2, 3.1, 0.5, 0.0, 0.0)  # her track, pulled by a passer-by
    assert rig.approach(3.0, jostled, Pose2D(3.5, 2.5))
    new_track = TargetState(9, 5.05, 3.0, 0.05, 0.0, 0.0)
    assert rig.approach(4.0, new_track, Pose2D(4.0, 2.2))
    goal = rig.intents.goals[-1]  # still round to her front, the side she faces
    assert abs(math.atan2(goal[1] - her.y, goal[0] - her.x)) <= math.radians(60) + 1e-6
    assert rig.intents.looks[-1][:2] == (new_track.xy, "candidate")
    # the old track walks off with the passer-by: no longer gone after
    assert not rig.approach(5.0, TargetState(4, 6.0, 3.5, 0.6, 0.0, 0.0), Pose2D(4.0, 2.2))
    # the time left is her approach's, not a new track's
    bound = APPROACH_S + WaypointSearch.APPROACH_ROUND_S
    assert not rig.approach(bound + 0.1, new_track, Pose2D(4.0, 2.2))


def test_a_place_in_front_of_her_found_once_is_kept_while_she_stands_there() -> None:
    """Crowd seed 1: she stood facing a corner; the only place in front of her lay at
    APPROACH_MIN, and her track's jitter took it in and out of reach. Each time it was out,
    the robot chose the nearest place, where it stood, and stopped with her back to it until
    approach_s ran out. The front found once is kept while she stands where she stood."""
    rig = Rig()
    her = TargetState(4, 7.18, 3.0, 0.0, 0.0, 0.0)  # facing east, 0.5 m from the east wall
    robot = Pose2D(5.0, 3.0)
    rig.intents.nav = "arrived"
    assert rig.approach(0.0, her, robot)  # at the nearest place already, her back to it
    rig.intents.nav = "running"
    assert rig.approach(WaypointSearch.APPROACH_LOOK_S, her, robot)
    front = rig.intents.goals[-1]
    assert abs(math.atan2(front[1] - her.y, front[0] - her.x)) <= math.radians(62)  # ~east
    stops = rig.stops
    on_the_way = Pose2D(6.0, 3.8)
    jittered = TargetState(4, 7.26, 3.0, 0.0, 0.0, 0.0)  # 8 cm east
    facing = rig.leaf._approach_facing[4]
    assert (  # the premise: from there, no place in front of her is found
        face_viewpoint(
            rig.bb.world.planner,
            (on_the_way.x, on_the_way.y),
            jittered.xy,
            facing,
            WaypointSearch.APPROACH_MIN,
            WaypointSearch.APPROACH_TO,
            clearance=WaypointSearch.APPROACH_CLEARANCE,
        )
        is None
    )
    t = WaypointSearch.APPROACH_LOOK_S + WaypointSearch.APPROACH_REPLAN_S
    assert rig.approach(t, jittered, on_the_way)
    assert rig.intents.goals[-1] == front and rig.stops == stops  # on round to her front
    # she stands elsewhere now: the front is found anew or the nearest place taken
    moved = TargetState(4, 6.5, 2.4, 0.0, 0.0, 0.0)
    assert rig.approach(t + 0.4 + WaypointSearch.APPROACH_REPLAN_S, moved, on_the_way)
    assert rig.intents.goals[-1] != front


def _bearing_off(a: tuple[float, float], b: tuple[float, float], her: TargetState) -> float:
    """The angle between places ``a`` and ``b`` as seen from her, rad."""
    ba = math.atan2(a[1] - her.y, a[0] - her.x)
    bb = math.atan2(b[1] - her.y, b[0] - her.x)
    return abs((ba - bb + math.pi) % (2 * math.pi) - math.pi)


def test_with_no_face_from_her_front_either_the_robot_goes_on_round_her() -> None:
    """Crowd seed 4: she stood facing south-west; the robot looked at her back, went round to
    where it took her front to be, saw no face there either, and stood there 10 s until the
    approach ran out. With no face from a place either, it goes on round her, to the side
    farthest from every place it has looked from, until her face decides or the time is up."""
    rig = Rig()
    her = TargetState(4, 4.0, 3.0, 0.0, 0.0, 0.0)
    rig.intents.nav = "arrived"
    assert rig.approach(0.0, her, Pose2D(2.0, 3.0))  # west of her, there at once
    rig.intents.nav = "running"
    assert rig.approach(WaypointSearch.APPROACH_LOOK_S, her, Pose2D(2.0, 3.0))
    front = rig.intents.goals[-1]
    assert front[0] > her.x  # round to the east
    # straight in front of her as far as a place within APPROACH_HEAD_ON allows
    assert _bearing_off(front, (5.0, 3.0), her) <= WaypointSearch.APPROACH_HEAD_ON + 1e-6
    at = 2.0 + WaypointSearch.APPROACH_LOOK_S  # the robot is there 2 s later
    rig.intents.nav = "arrived"
    assert rig.approach(at, her, Pose2D(*front))
    sent = len(rig.intents.goals)
    rig.intents.nav = "running"
    assert rig.approach(at + WaypointSearch.APPROACH_LOOK_S - 0.1, her, Pose2D(*front))
    assert len(rig.intents.goals) == sent  # still looking from her front
    assert rig.approach(at + WaypointSearch.APPROACH_LOOK_S, her, Pose2D(*front))
    side = rig.intents.goals[-1]
    looked = [(2.0, 3.0), front]
    assert all(_bearing_off(side, p, her) >= math.radians(60) for p in looked)
    assert WaypointSearch.APPROACH_MIN <= math.dist(side, her.xy) <= WaypointSearch.APPROACH_TO
    # the time going round from side to side adds up to APPROACH_ROUND_S at most
    bound = APPROACH_S + WaypointSearch.APPROACH_ROUND_S
    assert rig.approach(bound - 0.1, her, Pose2D(4.0, 4.0))
    assert not rig.approach(bound + 0.1, her, Pose2D(4.0, 4.0))


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


def test_a_person_the_camera_has_not_seen_is_glanced_at_base_turning_then_left() -> None:
    """House seed 43: her legs stood 1.5 m behind the robot, past the office's bookshelf; the
    head turned toward them from behind at 1 rad/s and the search drove on before the camera got
    there. A standing person whom no frame has shown (blackboard ``stranger``) is looked at, the
    base stopped and turned toward them, for ``glance_s`` at most; a walker is not."""
    rig = Rig()
    glance_s = rig.leaf.params["glance_s"]
    legs = TargetState(9, 0.0, 3.3, 0.05, 0.0, 0.0)  # standing 1 m behind the robot, left
    rig.bb.stranger = legs
    rig.bb.t, rig.bb.pose = 0.0, Pose2D(1.0, 3.0, 0.0)
    assert rig.leaf._glance_at_stranger()
    assert rig.intents.looks[-1] == (legs.xy, "stranger", None)
    assert rig.intents.turns == [pytest.approx(0.8)]  # at full speed, the short way: left
    rig.bb.t, rig.bb.pose = 2.0, Pose2D(1.0, 3.0, 2.8)  # turned to face them
    assert rig.leaf._glance_at_stranger()
    assert rig.intents.stops == 1 and len(rig.intents.turns) == 1
    rig.bb.t = glance_s + 0.1  # no frame has shown them in glance_s: on with the search
    assert not rig.leaf._glance_at_stranger()
    rig.bb.stranger = TargetState(10, 0.0, 3.0, 0.5, 0.0, 0.0)  # a walker
    assert not rig.leaf._glance_at_stranger()
    rig.bb.stranger = TargetState(11, 1.0, 4.0, 0.0, 0.0, 0.0)  # another standing person
    assert rig.leaf._glance_at_stranger()
    rig.leaf.params.update(glance_s=0.0)  # missions/trees/paper_literal.yaml
    rig.bb.stranger = TargetState(12, 1.0, 4.0, 0.0, 0.0, 0.0)
    assert not rig.leaf._glance_at_stranger()


def test_a_glance_counts_from_when_the_camera_points_at_them() -> None:
    """House seed 1 (this VM): the head looked behind at the belief when her legs appeared
    2.3 m off past the office's bookshelf; 3 s after the glance began the head was still
    1.4 rad off her and the glance ended with the camera on the wall. ``glance_s`` counts from
    when the camera (base heading + pan) points within ``GLANCE_ON`` of them; the turn there may
    take ``GLANCE_TURN_S`` more."""
    rig = Rig()
    glance_s = rig.leaf.params["glance_s"]
    her = TargetState(9, 3.0, 3.0, 0.0, 0.0, 0.0)  # 2 m ahead of the base
    rig.bb.stranger, rig.bb.pose = her, Pose2D(1.0, 3.0, 0.0)
    rig.bb.t, rig.bb.head = 0.0, HeadState(pan=-2.5)  # the head looks behind
    assert rig.leaf._glance_at_stranger()
    assert rig.intents.stops == 1 and rig.intents.turns == []  # the base faces her already
    rig.bb.t, rig.bb.head = glance_s + 0.1, HeadState(pan=-0.6)  # still turning toward her
    assert rig.leaf._glance_at_stranger()
    on = glance_s + 0.5
    rig.bb.t, rig.bb.head = on, HeadState(pan=-0.2)  # the camera on her
    assert rig.leaf._glance_at_stranger()
    rig.bb.t = on + glance_s - 0.1
    assert rig.leaf._glance_at_stranger()
    rig.bb.t = on + glance_s + 0.1  # no frame has shown her in glance_s: on with the search
    assert not rig.leaf._glance_at_stranger()
    # someone the camera never comes to point at is left after GLANCE_TURN_S + glance_s
    other = TargetState(10, 1.0, 5.0, 0.0, 0.0, 0.0)
    start = 100.0
    rig.bb.stranger, rig.bb.head = other, HeadState(pan=-2.5)
    rig.bb.t = start
    assert rig.leaf._glance_at_stranger()
    rig.bb.t = start + WaypointSearch.GLANCE_TURN_S + glance_s - 0.1
    assert rig.leaf._glance_at_stranger()
    rig.bb.t = start + WaypointSearch.GLANCE_TURN_S + glance_s + 0.1
    assert not rig.leaf._glance_at_stranger()


def _decision(goals: list[tuple[float, float]], utilities: list[float]) -> WaypointDecision:
    """Algorithm 1's frontier decision over one-point clusters at ``goals`` (Eq. 3 utilities)."""
    clusters = tuple(
        FrontierCluster(np.zeros((1, 2), dtype=np.intp), np.array([g]), g, 10) for g in goals
    )
    best = int(np.argmax(utilities))
    return WaypointDecision(
        waypoint=goals[best],
        heading_region=None,
        target_region=None,
        target_point=None,
        reason="frontier",
        clusters=clusters,
        goals=tuple(goals),
        utilities=tuple(utilities),
        best=best,
    )


def test_after_a_glance_the_search_goes_on_to_the_way_point_it_had() -> None:
    """``pfctl search`` over ROS, house seed 2: 1 m short of the living room's door, where she
    stood, a line of sight grazing the door's jamb made her legs a stranger for one tick. The
    glance dropped the way-point, the search chose afresh without the hysteresis that keeps a
    way-point (``KEEP_RADIUS``), went to the hall and did not find her in 60 s. After a glance
    the way-point goes on, and the next decision keeps it while its frontier is there."""
    rig = Rig()
    door, hall = (5.2, 2.4), (3.2, 4.2)
    later = _decision([(5.3, 2.5), hall], [0.5, 1.0])  # the hall's frontier scores higher now
    decisions = iter([_decision([door, hall], [1.0, 0.5])])
    rig.bb.world = SimpleNamespace(
        whereabouts=None,
        planner=_room(),
        search=SearchParams(strategy="paper"),
        next_waypoint=lambda history, here: next(decisions, later),
    )
    robot = Pose2D(3.8, 1.8)
    rig.bb.t, rig.bb.pose = 0.0, robot
    rig.leaf.tick_once()
    assert rig.intents.goals[-1] == door
    rig.bb.t, rig.bb.stranger = 1.0, TargetState(9, 7.1, 3.4, 0.0, 0.0, 0.0)  # her legs
    rig.leaf.tick_once()
    assert rig.intents.looks[-1][1] == "stranger" and len(rig.intents.turns) == 1
    rig.bb.t, rig.bb.stranger = 1.1, None  # out of sight again a tick later
    rig.leaf.tick_once()
    assert rig.intents.goals[-1] == door  # not the hall
    rig.bb.t = WaypointSearch.REPLAN_S + 0.1  # the next decision keeps the door's frontier
    rig.leaf.tick_once()
    assert rig.intents.goals[-1] == (5.3, 2.5)
    assert hall not in rig.intents.goals


def _frontier(wb: Whereabouts, x0: float, x1: float, y: float) -> FrontierCluster:
    """A frontier along ``y`` from ``x0`` to ``x1`` on the whereabouts' grid."""
    xs = np.arange(x0, x1, wb.geometry.resolution)
    points = np.column_stack([xs, np.full_like(xs, y)])
    cells = np.array([wb.geometry.world_to_cell(p) for p in points], dtype=np.intp)
    return FrontierCluster(cells, points, (float(xs.mean()), y), len(xs))


def test_a_frontier_the_camera_has_looked_round_is_not_worth_a_visit() -> None:
    """Generated home 16: round the kitchen's furniture the laser left frontiers long after
    the camera had looked over the room. A frontier counts as looked at once the camera has
    seen LOOKED_SHARE of the places within LOOKED_RADIUS of it since the loss."""
    rig = Rig()
    wb = Whereabouts(RegionMap(HOME), GEOMETRY, np.ones(GEOMETRY.shape, dtype=bool), PARAMS)
    rig.bb.world = SimpleNamespace(whereabouts=wb, planner=_room())
    frontier = _frontier(wb, 4.0, 5.0, 3.5)  # in the mid room
    assert not rig.leaf._looked_at(frontier)  # the belief rests: every frontier counts
    wb.lost(0.0, (4.5, 1.0), heading="mid")
    assert not rig.leaf._looked_at(frontier)
    xy = GEOMETRY.cell_to_world(*np.indices(GEOMETRY.shape))
    near = np.hypot(xy[..., 0] - 4.5, xy[..., 1] - 3.5) < 1.5
    wb.observe(2.0, near & (xy[..., 0] < 4.4))  # the camera saw the west half round it
    assert not rig.leaf._looked_at(frontier)
    wb.observe(3.0, near)  # and then all round it
    assert rig.leaf._looked_at(frontier)
    assert not rig.leaf._looked_at(_frontier(wb, 7.0, 8.0, 3.5))  # the east room: not seen


def test_with_no_frontier_worth_a_visit_the_paper_strategy_looks_where_the_belief_says() -> None:
    """Every frontier visited or looked round: rather than l*'s point again, the leaf looks
    where the belief over where she can be says (the likely room's doorway first), and goes
    on with that look once chosen."""
    rig = Rig()
    wb = Whereabouts(RegionMap(HOME), GEOMETRY, np.ones(GEOMETRY.shape, dtype=bool), PARAMS)
    wb.lost(0.0, (6.5, 1.0), heading="east", came_from="west")
    wb.observe(8.0, wb.labels == wb.regions.names.index("corridor"))  # the robot's own corridor
    spent = WaypointDecision(
        waypoint=(7.5, 3.5),
        heading_region="east",
        target_region="east",
        target_point=(7.5, 3.5),
        reason="visited_fallback",
    )
    rig.bb.world = SimpleNamespace(
        whereabouts=wb,
        planner=_room(),
        search=SearchParams(strategy="paper"),
        next_waypoint=lambda history, here: spent,
    )
    control = SimpleNamespace(max_linear_speed=0.22, max_angular_speed=0.8)
    rig.intents.control = control  # type: ignore[attr-defined]
    rig.bb.t, rig.bb.pose = 8.0, Pose2D(2.0, 1.0)
    rig.leaf.tick_once()
    assert rig.leaf.status is Status.RUNNING
    assert rig.intents.goals[-1] == (7.5, 2.0 + STEP_IN)  # the east room's doorway, not l*'s
    assert rig.leaf._look is not None and rig.leaf._look.region == "east"


def test_the_paper_literal_leaf_neither_goes_up_to_anyone_nor_skips_a_frontier() -> None:
    """``approach_s: 0`` and ``looked_round: false`` (``missions/trees/paper_literal.yaml``):
    Algorithm 1 as the paper has it."""
    rig = Rig()
    rig.leaf.params.update(approach_s=0.0, looked_round=False)
    her = TargetState(4, 6.0, 3.0, 0.0, 0.0, 0.0)
    assert not rig.approach(0.0, her, Pose2D(1.0, 3.0))
    wb = Whereabouts(RegionMap(HOME), GEOMETRY, np.ones(GEOMETRY.shape, dtype=bool), PARAMS)
    wb.lost(0.0, (4.5, 1.0), heading="mid")
    wb.observe(1.0, np.ones(GEOMETRY.shape, dtype=bool))  # everything seen
    rig.bb.world = SimpleNamespace(whereabouts=wb, planner=_room())
    assert not rig.leaf._looked_at(_frontier(wb, 4.0, 5.0, 3.5))
