"""The condition and action leaves of the behavior tree (§II-A, Fig. 2), on py_trees.

Every leaf reads the follower's state and world model from the blackboard keys of
:mod:`pfctl.core.behavior.blackboard` (declared per leaf) and writes what the robot should do into
the ``intents`` key (:class:`~pfctl.core.behavior.intents.Intents`); no leaf commands the robot:
the follower's act stage sends the tick's intents. The statuses are honest: a condition is SUCCESS
or FAILURE at once; an action is RUNNING while it works (a navigation in progress is running),
SUCCESS when it has done its job, FAILURE when it cannot. An action that drives the base gives it
up in ``terminate`` — also when a higher-priority branch preempts it (status INVALID).

Each leaf class declares its name, kind, summary and parameters (its ``spec``, Nav2's
``providedPorts()``); :data:`LEAF_CLASSES` is every leaf by name, and :func:`leaf_factory` makes
the ``factory`` that :func:`pfctl.core.behavior.tree.build_tree` calls for each leaf of a
mission's layout.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import replace
from typing import Any, ClassVar

import numpy as np
import py_trees
from py_trees.common import Access, Status
from scipy.ndimage import binary_dilation

from pfctl.core.behavior.blackboard import PredictionState, Sighting, TargetState
from pfctl.core.behavior.intents import Intents
from pfctl.core.behavior.spec import LeafSpec, param
from pfctl.core.behavior.world import WorldModel
from pfctl.core.control import sweep_pan
from pfctl.core.mapping.frontiers import FrontierCluster
from pfctl.core.mapping.regions import WaypointDecision
from pfctl.core.perception.viewpoints import face_viewpoint, nearest_viewpoint
from pfctl.core.robot import HeadState, wrap_angle
from pfctl.core.search.next_look import Look, rank_looks

#: Height of a standing person's face, m: where the head aims to see it.
FACE_HEIGHT = 1.55


class Leaf(py_trees.behaviour.Behaviour):
    """A leaf with its resolved parameters and a blackboard client in the follower's namespace.

    Each concrete leaf declares its ``spec``: its name in a mission's tree, its kind, what it
    does and its parameters (the registry and the mission's JSON Schema come from these)."""

    spec: ClassVar[LeafSpec]
    reads: ClassVar[tuple[str, ...]] = (
        "t",
        "pose",
        "target",
        "last_seen",
        "prediction",
        "world",
        "intents",
    )
    writes: ClassVar[tuple[str, ...]] = ()

    def __init__(self, name: str, namespace: str, params: dict[str, Any]) -> None:
        super().__init__(name)
        self.params = params
        self.bb = self.attach_blackboard_client(name=name, namespace=namespace)
        for key in self.reads:
            if key not in self.writes:
                self.bb.register_key(key, access=Access.READ)
        for key in self.writes:
            self.bb.register_key(key, access=Access.WRITE)

    # typed views of the keys
    @property
    def t(self) -> float:
        return float(self.bb.t)

    @property
    def target(self) -> TargetState | None:
        value: TargetState | None = self.bb.target
        return value

    @property
    def last_seen(self) -> Sighting | None:
        value: Sighting | None = self.bb.last_seen
        return value

    @property
    def prediction(self) -> PredictionState | None:
        value: PredictionState | None = self.bb.prediction
        return value

    @property
    def world(self) -> WorldModel:
        value: WorldModel = self.bb.world
        return value

    @property
    def intents(self) -> Intents:
        value: Intents = self.bb.intents
        return value

    def visible(self, max_age: float = 0.5) -> bool:
        target = self.target
        return target is not None and self.t - target.last_detected <= max_age

    def hold_on_target(self, since: float) -> bool:
        """Stop and point the camera at the target's track when it was detected at ``since`` or
        later but not lately: a search that showed her for a moment — her face decided on a
        frame the sweep has since turned away from — looks back at her, so she is detected
        again and followed, rather than lost again at once. False (nothing done) otherwise."""
        target = self.target
        if target is None or target.last_detected < since:
            return False
        self.intents.stop()
        self.intents.look_at(target.xy, "target")
        return True


# -- conditions -----------------------------------------------------------------------------------


class TargetVisible(Leaf):
    """SUCCESS when the identified target's track was detected within ``max_age`` s."""

    spec = LeafSpec(
        "target_visible",
        "condition",
        "The identified target's track was detected (laser legs or camera) within max_age s.",
        (param("max_age", 0.5, "seconds since the target's last detection", minimum=0.0),),
    )

    def update(self) -> Status:
        return Status.SUCCESS if self.visible(self.params["max_age"]) else Status.FAILURE


class TargetTracked(Leaf):
    """SUCCESS while the tracker holds the identified target's track (detected or coasting)."""

    spec = LeafSpec(
        "target_tracked",
        "condition",
        "The tracker still holds the identified target's track (detected or coasting).",
    )

    def update(self) -> Status:
        return Status.SUCCESS if self.target is not None else Status.FAILURE


class TargetLostFor(Leaf):
    """SUCCESS when the target has not been detected for ``seconds`` (or was never seen)."""

    spec = LeafSpec(
        "target_lost_for",
        "condition",
        "The target has not been visible for at least `seconds` (or was never seen).",
        (
            param(
                "seconds",
                None,
                "how long the target has been out of sight",
                minimum=0.0,
                required=True,
            ),
        ),
    )

    def update(self) -> Status:
        target, seen = self.target, self.last_seen
        last = target.last_detected if target is not None else (seen.t if seen else -math.inf)
        return Status.SUCCESS if self.t - last >= self.params["seconds"] else Status.FAILURE


class PredictionAvailable(Leaf):
    """SUCCESS when a prediction of the lost target exists and has not been used up."""

    spec = LeafSpec(
        "prediction_available",
        "condition",
        "A prediction of where the lost target went exists and has not been looked at yet.",
    )

    def update(self) -> Status:
        p = self.prediction
        return Status.SUCCESS if p is not None and p.available else Status.FAILURE


class NearTarget(Leaf):
    """SUCCESS when the robot is within ``distance`` of the target (else of where it was last
    seen)."""

    spec = LeafSpec(
        "near_target",
        "condition",
        "The robot is within `distance` metres of the target's estimated position.",
        (param("distance", 1.0, "metres", minimum=0.0),),
    )

    def update(self) -> Status:
        target, seen = self.target, self.last_seen
        xy = target.xy if target is not None else (seen.xy if seen is not None else None)
        if xy is None:
            return Status.FAILURE
        pose = self.bb.pose
        near = math.hypot(xy[0] - pose.x, xy[1] - pose.y) <= self.params["distance"]
        return Status.SUCCESS if near else Status.FAILURE


# -- actions -----------------------------------------------------------------------------------


class Action(Leaf):
    """An action: it names itself in the intents while it runs and gives up the base at the end."""

    def update(self) -> Status:
        self.intents.claim(self.name)
        return self.act()

    def act(self) -> Status:
        raise NotImplementedError

    def terminate(self, new_status: Status) -> None:
        if new_status in (Status.INVALID, Status.FAILURE):
            self.intents.release()


class FollowTarget(Action):
    """Drive after the target (§II-E): TURN + GO_STRAIGHT, or MOVE_BASE when the line of sight
    is blocked; keeps ``distance``. RUNNING while there is a target, FAILURE without one."""

    spec = LeafSpec(
        "follow_target",
        "action",
        "Drive after the target (TURN + GO_STRAIGHT when the line of sight is free, else "
        "MOVE_BASE), keeping the following distance; running while there is a target.",
        (
            param(
                "distance",
                None,
                "following distance, m (default control.following_distance)",
                minimum=0.3,
            ),
        ),
    )

    def act(self) -> Status:
        target = self.target
        if target is None:
            return Status.FAILURE
        self.intents.follow(target.xy, self.params["distance"])
        return Status.RUNNING


class GazeAtTarget(Action):
    """Point the head at the target; RUNNING while there is one, FAILURE without."""

    spec = LeafSpec(
        "gaze_at_target",
        "action",
        "Point the head at the target; running while there is one, failure otherwise.",
    )

    def act(self) -> Status:
        target = self.target
        if target is None:
            return Status.FAILURE
        self.intents.look_at(target.xy, "target")
        return Status.RUNNING

    def terminate(self, new_status: Status) -> None:
        """The head is the follower's again; the base was never this leaf's."""


class GoToPrediction(Action):
    """MOVE_BASE to where the prediction says the target went. SUCCESS on arrival (at once if
    the robot already arrived there), FAILURE without a prediction or a way there (the
    prediction is then used up)."""

    spec = LeafSpec(
        "go_to_prediction",
        "action",
        "Navigate to where the prediction says the target went; success on arrival, failure "
        "when there is no prediction or no way there.",
        (param("tolerance", 0.5, "arrival distance, m", minimum=0.05),),
    )

    def act(self) -> Status:
        p = self.prediction
        if p is None or p.used:
            return Status.FAILURE
        if p.reached:
            return Status.SUCCESS
        outcome = self.intents.go_to(p.goal, self.params["tolerance"])
        if outcome == "arrived":
            p.reached = True
            return Status.SUCCESS
        if outcome == "failed":
            p.used = True
            return Status.FAILURE
        return Status.RUNNING


class LookAround(Action):
    """Sweep the head ±``pan`` over ``seconds`` and, with ``turn``, turn the base once around.
    SUCCESS as soon as the target is detected; FAILURE when the sweep ends without it — the
    prediction (if any) is then used up, so the tree moves on (Fig. 2: way-point search). A
    target named during the sweep but not detected lately is looked back at
    (:meth:`Leaf.hold_on_target`). With ``until_looked`` the sweep ends sooner, after
    ``min_seconds``, once the camera has seen every place in sight from here where she can be
    (:meth:`~pfctl.core.behavior.world.WorldModel.unseen_in_sight`: less floor left unseen than
    ``UNSEEN_AREA``, less than a person stands on; slivers along the furniture's edges stay
    unseen): traced, the shipped house, seeds 41 and 48, the robot swept for 8 s at the
    office's east side while she stood behind the bookshelf, out of its sight, and the
    way-point search that found her then had too little time left."""

    spec = LeafSpec(
        "look_around",
        "action",
        "Sweep the head (and turn the base) to look for the target; success when the target "
        "is seen, failure when the sweep ends without it (the prediction is used up).",
        (
            param("seconds", 8.0, "length of the sweep, s", minimum=0.5),
            param("pan", 1.4, "head pan to either side, rad", minimum=0.0, maximum=3.0),
            param("turn", True, "also turn the base once around", kind=bool),
            param(
                "until_looked",
                True,
                "end the sweep once every place in sight where she can be has been seen"
                " (false: the full sweep, as the paper has it)",
                kind=bool,
            ),
            param("min_seconds", 1.0, "... but sweep at least this long, s", minimum=0.0),
        ),
    )

    #: Less floor than this (m²) unseen in sight where she can be: nothing left to look at
    #: here (a person's footprint, a disc of 0.2 m radius, is 0.126 m²).
    UNSEEN_AREA: ClassVar[float] = 0.12
    #: The check is made this often, s.
    CHECK_S: ClassVar[float] = 0.5

    def initialise(self) -> None:
        self._start = self.t
        self._checked_at = -math.inf

    def _looked(self, elapsed: float) -> bool:
        """Whether the camera has seen every place in sight where she can be (``until_looked``,
        after ``min_seconds``; checked every ``CHECK_S``)."""
        if not self.params["until_looked"] or elapsed < float(self.params["min_seconds"]):
            return False
        if self.t - self._checked_at < self.CHECK_S:
            return False
        self._checked_at = self.t
        area = self.world.unseen_in_sight(self.t, self.bb.pose)
        return area is not None and area < self.UNSEEN_AREA

    def act(self) -> Status:
        if self.visible():
            return Status.SUCCESS
        if self.hold_on_target(self._start):
            return Status.RUNNING
        elapsed = self.t - self._start
        seconds = float(self.params["seconds"])
        if elapsed >= seconds or self._looked(elapsed):
            if self.prediction is not None:
                self.prediction.used = True
            self.intents.stop()
            return Status.FAILURE
        self.intents.set_pan(sweep_pan(elapsed, seconds, float(self.params["pan"])))
        if self.params["turn"]:
            wz = min(2.0 * math.pi / seconds, self.intents.control.max_angular_speed)
            self.intents.turn(wz)
        else:
            self.intents.stop()
        return Status.RUNNING


class WaypointSearch(Action):
    """**Algorithm 1** as an action: go to the way-point toward the heading region l* (the
    target's last path decides l*), re-deciding every ``REPLAN_S`` seconds as the occupancy grid
    fills in. The robot keeps its way-point while that frontier still exists (so it does not
    dither between clusters), and a way-point it has reached or could not reach is not chosen
    again — a frontier still there is followed along to its next unvisited point; when every
    frontier left has been visited, it turns in place to look and starts
    afresh. RUNNING until the target is detected (SUCCESS); FAILURE when Algorithm 1 has nothing
    at all to search (no region to go to). With the strategy ``belief`` — ``search.strategy``
    for a target lost, ``search.never_seen_strategy`` for one not seen yet in the run — it
    looks where the belief over where she can be says (:meth:`_act_belief`), and uses
    Algorithm 1 only when that belief has no place left to look. A target named during the
    search but not detected lately is looked back at (:meth:`Leaf.hold_on_target`), and a
    person standing in her clothes whose face has not decided is gone up to first
    (:meth:`_approach_candidate`)."""

    spec = LeafSpec(
        "waypoint_search",
        "action",
        "Algorithm 1: go to the best frontier toward the heading region, look, repeat; "
        "running until the target is found, failure when nothing is left to search.",
        (
            param("tolerance", 0.4, "arrival distance at a way-point, m", minimum=0.05),
            param(
                "approach_s",
                15.0,
                "go up to a standing person in her clothes whose face has not decided, for at"
                " most this long each, s (0: never)",
                minimum=0.0,
            ),
            param(
                "ask_s",
                4.0,
                "on a robot that speaks: having looked at such a person's back, ask them to look"
                " at the robot, and wait this long for their face, s (0: never ask; go round)",
                minimum=0.0,
            ),
            param(
                "glance_s",
                3.0,
                "stop and turn to a person standing in sight whom the camera has not seen yet,"
                " for this long each from when the camera points at them, s (0: never)",
                minimum=0.0,
            ),
            param(
                "looked_round",
                True,
                "skip the frontiers the camera has looked round since the loss, and with none"
                " left look where the belief says (false: Algorithm 1 as the paper has it)",
                kind=bool,
            ),
        ),
    )
    reads = (*Leaf.reads, "candidate", "stranger", "head")
    writes = ("waypoint",)

    REPLAN_S: ClassVar[float] = 3.0
    #: A frontier goal this close to a visited way-point counts as visited, metres.
    VISITED_RADIUS: ClassVar[float] = 0.8
    #: A new decision keeps the current way-point if a goal lies this close to it, metres.
    KEEP_RADIUS: ClassVar[float] = 0.6

    #: A new look replaces the one under way only when it scores this much better.
    SWITCH_GAIN: ClassVar[float] = 1.3
    #: A place the robot could not drive to (a person in the door, say) is tried again after
    #: this long, s: a likely room is not given up for good.
    RETRY_S: ClassVar[float] = 10.0
    #: Looks inside one room (at its parts not seen yet) before the rest counts as unseeable.
    INSIDE_LOOKS: ClassVar[int] = 3
    #: Head sweep to either side of the room's bearing while looking, rad.
    LOOK_PAN: ClassVar[float] = 0.9
    #: A frontier cluster round which the camera has seen this share of the places a person
    #: could stand (within ``LOOKED_RADIUS`` m) since the loss is not worth a visit.
    LOOKED_SHARE: ClassVar[float] = 0.9
    LOOKED_RADIUS: ClassVar[float] = 0.6
    #: A candidate (blackboard ``candidate``) slower than this (m/s) is standing: gone up to.
    STANDING: ClassVar[float] = 0.2
    #: ... to this far from them, m: close enough for her face (> 14 px at 320x240 within
    #: 3.2 m) and her clothes to decide, far enough not to crowd them.
    APPROACH_TO: ClassVar[float] = 2.2
    #: ... and no nearer than this, m; the line of sight keeps ``APPROACH_CLEARANCE`` m from
    #: walls and furniture.
    APPROACH_MIN: ClassVar[float] = 1.0
    APPROACH_CLEARANCE: ClassVar[float] = 0.2
    #: The place to see them from is chosen again this often, s, and reached within this
    #: distance, m (a place at a door's edge is a few centimetres from one behind its jamb).
    APPROACH_REPLAN_S: ClassVar[float] = 1.0
    APPROACH_TOLERANCE: ClassVar[float] = 0.1
    #: Once there, a place chosen again within this distance, m, is not driven to (MOVE_BASE
    #: stops within its own tolerance, and each new goal then stopped at once: traced, house
    #: seed 12, the base went and stopped on alternate ticks for a second).
    APPROACH_KEEP: ClassVar[float] = 0.25
    #: ``approach_s`` counts from when the robot is this near them, m (where a face is big
    #: enough to count); the way there may take ``APPROACH_TRAVEL_S`` more at most.
    APPROACH_NEAR: ClassVar[float] = 3.0
    APPROACH_TRAVEL_S: ClassVar[float] = 40.0
    #: At the place to see them from this long with no face decided, s: they face away, and
    #: the robot goes round to the side they face — and on round them, a side at a time, while
    #: no face decides.
    APPROACH_LOOK_S: ClassVar[float] = 2.0
    #: What the robot says to a person who shows it their back (``ask_s``).
    ASK: ClassVar[str] = "Excuse me, could you look at me, please?"
    #: The camera on them this long within ``APPROACH_NEAR`` with no face decided, s, they show
    #: it their back: a robot that speaks asks them then, on its way up to them (a face turned
    #: to the camera decides within a few face searches, ``face_miss_backoff_s`` apart).
    ASK_LOOK_S: ClassVar[float] = 1.0
    #: Places in front of them this near head-on, rad, are taken before the rest of
    #: ``face_viewpoint``'s 60° (:func:`~pfctl.core.perception.viewpoints.face_viewpoint`).
    APPROACH_HEAD_ON: ClassVar[float] = math.radians(30.0)
    #: The way round to their front does not count against ``approach_s``, for this long at
    #: most, s.
    APPROACH_ROUND_S: ClassVar[float] = 20.0
    #: A new candidate track this near where an approached one stood, m, within this long,
    #: s, is the same person (:meth:`_approach_key`).
    APPROACH_SAME_PLACE: ClassVar[float] = 0.5
    APPROACH_SAME_S: ClassVar[float] = 10.0
    #: The head aims at their torso (the control's look height) from ``APPROACH_TO`` m and
    #: farther, at this height on them from ``APPROACH_MIN`` m and nearer, and in between at a
    #: height in proportion, m: with the house's camera (45° vertical field of view), nearer
    #: than about 1.3 m a camera aimed at the torso cuts the face off.
    APPROACH_FACE_HEIGHT: ClassVar[float] = FACE_HEIGHT
    #: A glanced-at person this far off the base's heading or less is looked at with the head
    #: alone; farther, the base turns toward them too, rad.
    GLANCE_ALIGNED: ClassVar[float] = 0.3
    #: ``glance_s`` counts from when the camera points this near them, rad (well inside any
    #: camera's half field of view); turning there may take ``GLANCE_TURN_S`` more at most.
    GLANCE_ON: ClassVar[float] = 0.3
    GLANCE_TURN_S: ClassVar[float] = 5.0

    def initialise(self) -> None:
        self._start = self.t
        self._decision: WaypointDecision | None = None
        self._decided_at = -math.inf
        self._visited: list[tuple[float, float]] = []
        self._look: Look | None = None
        self._look_chosen_at = -math.inf
        self._looking_since: float | None = None
        self._from_door: set[str] = set()
        self._failed: set[tuple[str, str]] = set()
        self._unreachable: dict[tuple[str, str], float] = {}
        """Looks the robot could not drive to, and when: skipped for ``RETRY_S``."""
        self._inside: dict[str, int] = {}
        self._approached: dict[int, float] = {}
        """Candidates gone up to, and when that began (-inf: given up)."""
        self._approach_near: dict[int, float] = {}
        """When the robot first came within ``APPROACH_NEAR`` of each candidate."""
        self._approach_facing: dict[int, float] = {}
        """The way a candidate who showed the robot no face is taken to face (rad)."""
        self._approach_looked: dict[int, list[tuple[float, float]]] = {}
        """The places each candidate was looked at from, ``APPROACH_LOOK_S`` with no face."""
        self._approach_place: tuple[int, float, tuple[float, float]] | None = None
        """The candidate's track, when its place to be seen from was chosen, and the place."""
        self._approach_reached: tuple[int, tuple[float, float], float] | None = None
        """The candidate, the place to see them from that the robot last reached, and when."""
        self._approach_round: dict[int, tuple[float, float]] = {}
        """When the way round to each candidate's front began, and when it ended (inf: not
        yet)."""
        self._approach_alias: dict[int, int] = {}
        """Each candidate track's approach key (:meth:`_approach_key`)."""
        self._approach_at: dict[int, tuple[tuple[float, float], float]] = {}
        """Where each approach key's candidate last stood still, and when."""
        self._approach_front: dict[int, tuple[tuple[float, float], tuple[float, float]]] = {}
        """The place in front of each candidate last found, and where they stood then."""
        self._asked: dict[int, float] = {}
        """Candidates asked to look at the robot, and when."""
        self._ask_on: dict[int, float] = {}
        """When the camera first pointed at each candidate within ``APPROACH_NEAR``."""
        self._glanced: dict[int, float] = {}
        """People the camera had not seen, glanced at, and when the glance began."""
        self._glance_on: dict[int, float] = {}
        """When the camera first pointed at each of them."""

    def _approach_candidate(self) -> bool:
        """Go up to a standing person who may be her (blackboard ``candidate``: her clothes,
        no face seen, not named), head on them: to the nearest place within ``APPROACH_TO`` m
        of them from which they are in sight
        (:func:`~pfctl.core.perception.viewpoints.nearest_viewpoint`, re-chosen every
        ``APPROACH_REPLAN_S``), so the laser sees their legs too. Seen across a room through a
        door, 5 m off, her clothes match only weakly (S ≈ 0.65) and her face is too small to
        count; nearer, one or the other decides. There ``APPROACH_LOOK_S`` with no face
        decided, they face away: the robot goes round to a place in front of them
        (:func:`~pfctl.core.perception.viewpoints.face_viewpoint`, taking them to face away
        from where it stood; traced, generated home 28: she stood with her back to the
        laundry's door, and the robot looked at her back until it gave up). A robot that
        speaks asks them, once, to look at it as soon as they show it their back
        (:meth:`_ask`), and waits for the face until ``ask_s`` has passed before going round
        (traced, the crowd, seeds 7, 10, 29 and 41: she stood facing the office's west wall
        0.9 m off, no place in front of her could be reached, and the robot looked at her back
        until it gave up; people turn to a robot that speaks to them). ``approach_s``
        per person counts from when the robot is within ``APPROACH_NEAR`` of them (traced,
        home 41: 15 s went on the way there, across the room), and the way there may take
        ``APPROACH_TRAVEL_S`` more; the way round to their front does not count
        (:meth:`_going_round`). The head aims higher up them the nearer the robot is
        (:meth:`_candidate_look_height`). A person on a re-created track is the same person
        (:meth:`_approach_key`). A walker is not chased (they walk on; the search's gaze keeps
        them in sight as it can). False (nothing done) when there is no such person."""
        c: TargetState | None = self.bb.candidate
        seconds = float(self.params["approach_s"])
        if c is None or seconds <= 0.0:
            return False
        track = self._approach_key(c)
        if track is None:
            return False
        began = self._approached.setdefault(track, self.t)
        pose = self.bb.pose
        if math.dist((pose.x, pose.y), c.xy) <= self.APPROACH_NEAR:
            self._approach_near.setdefault(track, self.t)
        near = self._approach_near.get(track, math.inf)
        round_ = self._going_round(track)
        if (
            self.t - near - round_ >= seconds
            or self.t - began - round_ >= self.APPROACH_TRAVEL_S + seconds
        ):
            return False
        reached = self._approach_reached
        there = reached[1] if reached is not None and reached[0] == track else None
        looked = self._approach_looked.setdefault(track, [])
        stood = reached is not None and there is not None
        if self._ask(c, track, stood):
            return True
        if (
            there is not None
            and reached is not None
            and self.t - reached[2] >= self.APPROACH_LOOK_S
            and all(math.dist(there, p) > self.APPROACH_KEEP for p in looked)
        ):
            looked.append(there)
            self._approach_facing[track] = _unlooked_side(c.xy, looked)
            self._approach_front.pop(track, None)
            self._start_round(track)
            self._approach_place = None  # go round now
        place = self._approach_place
        if place is None or place[0] != track or self.t - place[1] >= self.APPROACH_REPLAN_S:
            found = self._approach_viewpoint(c, track)
            if found is None:
                self._approached[track] = -math.inf  # no place to see them from
                return False
            place = self._approach_place = (track, self.t, found)
        self.intents.look_at(c.xy, "candidate", self._candidate_look_height(c))
        goal = place[2]
        if there is not None and math.dist(there, goal) <= self.APPROACH_KEEP:
            self.intents.stop()  # there already: a new place this near is not driven to
            return True
        facing = math.atan2(c.y - goal[1], c.x - goal[0])
        outcome = self.intents.go_to(goal, self.APPROACH_TOLERANCE, facing)
        if outcome == "failed":
            self._approached[track] = -math.inf  # no way there: on with the search
            return False
        if outcome == "arrived":
            self._approach_reached = (track, goal, self.t)
            round_ = self._approach_round.get(track)
            if round_ is not None and math.isinf(round_[1]):
                self._approach_round[track] = (round_[0], self.t)
            self.intents.stop()
        return True

    def _ask(self, c: TargetState, track: int, stood: bool) -> bool:
        """Ask candidate ``c`` (approach key ``track``) to look at the robot, once, when it can
        speak and the camera has been on them ``ASK_LOOK_S`` within ``APPROACH_NEAR`` with no
        face decided (:meth:`_shows_back`) — on the way up to them: traced, the shipped house
        with ``face_to_rename``, seed 4, asking only once it had stood ``APPROACH_LOOK_S`` at
        its place 2.2 m from her, the robot asked 4.2 s after her back came into view, and her
        face named her 4.2 s later than her clothes would have. While they turn it drives on to its
        place; ``stood`` there, it waits, head on them, until ``ask_s`` has passed since it
        asked before it goes round them. True while waiting there (the tick's intents are
        written)."""
        wait = float(self.params["ask_s"])
        asked = self._asked.get(track)
        if asked is None:
            if wait <= 0.0 or not self._shows_back(c, track) or not self.intents.say(self.ASK):
                return False
            asked = self._asked[track] = self.t
        if not stood or self.t - asked >= wait:
            return False
        self.intents.look_at(c.xy, "candidate", self._candidate_look_height(c))
        self.intents.stop()
        return True

    def _shows_back(self, c: TargetState, track: int) -> bool:
        """Whether candidate ``c`` (approach key ``track``) shows the robot their back: the
        camera (the base's heading plus the head's pan, blackboard ``head``) has pointed within
        ``GLANCE_ON`` of them, ``APPROACH_NEAR`` m off or nearer (where a face counts), for
        ``ASK_LOOK_S`` and their face has not decided (they are still the candidate)."""
        pose = self.bb.pose
        if math.dist((pose.x, pose.y), c.xy) > self.APPROACH_NEAR:
            return False
        bearing = math.atan2(c.y - pose.y, c.x - pose.x)
        head: HeadState | None = self.bb.head
        if head is None or abs(wrap_angle(bearing - pose.theta - head.pan)) <= self.GLANCE_ON:
            self._ask_on.setdefault(track, self.t)
        return self.t - self._ask_on.get(track, math.inf) >= self.ASK_LOOK_S

    def _approach_key(self, c: TargetState) -> int | None:
        """The track under which candidate ``c``'s approach is kept, or None for a walker (not
        gone up to). The key is their own track, or, for a new track within
        ``APPROACH_SAME_PLACE`` m of where an approached candidate stood in the last
        ``APPROACH_SAME_S`` s, that candidate's: the same person on a re-created track. A
        candidate near where they stood counts as standing whatever their track's speed says.
        Traced, house seed 30: a walker passing her pulled her track's speed over
        ``STANDING`` for a second, then took the track away; her new track began the approach
        afresh, from the side she was not facing."""
        standing = math.hypot(c.vx, c.vy) < self.STANDING
        key = self._approach_alias.get(c.track_id)
        if key is None:
            key = c.track_id
            if key not in self._approached:
                key = next(
                    (
                        k
                        for k, (xy, t) in self._approach_at.items()
                        if self.t - t <= self.APPROACH_SAME_S
                        and math.dist(xy, c.xy) <= self.APPROACH_SAME_PLACE
                    ),
                    key,
                )
            if not standing and key == c.track_id:
                return None  # a walker, not seen standing yet
            self._approach_alias[c.track_id] = key
        stood = self._approach_at.get(key)
        if standing:
            self._approach_at[key] = (c.xy, self.t)
        elif stood is None or math.dist(stood[0], c.xy) > self.APPROACH_SAME_PLACE:
            return None  # walked off: not chased
        return key

    def _start_round(self, track: int) -> None:
        """The way round to candidate ``track``'s front (or on to another side) begins now;
        the time of any way round before it goes on counting (:meth:`_going_round`)."""
        round_ = self._approach_round.get(track)
        if round_ is None:
            self._approach_round[track] = (self.t, math.inf)
        elif math.isfinite(round_[1]):
            self._approach_round[track] = (self.t - (round_[1] - round_[0]), math.inf)

    def _going_round(self, track: int) -> float:
        """How long the way round to candidate ``track``'s front took (so far), s, at most
        ``APPROACH_ROUND_S``: it does not count against ``approach_s``. Traced, house seed 30:
        she stood facing a corner 1 m off; the robot looked at her back from 2 m, and the way
        round, 2.6 m at walking pace, used up what was left of 15 s before it got there."""
        round_ = self._approach_round.get(track)
        if round_ is None:
            return 0.0
        return min(min(round_[1], self.t) - round_[0], self.APPROACH_ROUND_S)

    def _candidate_look_height(self, c: TargetState) -> float | None:
        """The height on candidate ``c`` to aim the head at (None: the torso, the control's
        look height): from ``APPROACH_TO`` m away the torso keeps the whole person and the
        face in the frame; nearer, the aim rises toward ``APPROACH_FACE_HEIGHT``, reached at
        ``APPROACH_MIN`` (traced, house seed 30: 0.9 m from her, aimed at her torso, the
        frame's top edge was at her shoulders)."""
        pose = self.bb.pose
        d = math.dist((pose.x, pose.y), c.xy)
        if d >= self.APPROACH_TO:
            return None
        torso = self.intents.control.look_height
        share = min((self.APPROACH_TO - d) / (self.APPROACH_TO - self.APPROACH_MIN), 1.0)
        return torso + share * (self.APPROACH_FACE_HEIGHT - torso)

    def _glance_at_stranger(self) -> bool:
        """Look at a person standing in sight whom no camera frame has shown yet (blackboard
        ``stranger``: the laser's legs alone): stop, and turn the base toward them while the
        head turns, for ``glance_s`` per person from when the camera (the base's heading plus
        the head's pan, blackboard ``head``) points within ``GLANCE_ON`` of them. The head pans
        at 1 rad/s, so from looking behind the turn takes up to 4 s; it is given
        ``GLANCE_TURN_S``. Traced, house seed 43: her legs stood 1.5 m off past the office's
        bookshelf, and the search drove on before the camera got there; house seed 1: a glance
        timed from its start ended with the head still 1.4 rad off her. Once a frame shows the
        person, they are no stranger: their clothes (then a candidate) or their face decide.
        The search then goes on with the way-point or look it had: a fresh choice would drop
        the hysteresis that keeps it (traced, ``pfctl search`` over ROS: a line of sight
        grazing a door's jamb made her legs a stranger for one tick, and the search chose
        another room). False when there is no such person."""
        s: TargetState | None = self.bb.stranger
        seconds = float(self.params["glance_s"])
        if s is None or seconds <= 0.0 or math.hypot(s.vx, s.vy) >= self.STANDING:
            return False
        began = self._glanced.setdefault(s.track_id, self.t)
        pose = self.bb.pose
        bearing = math.atan2(s.y - pose.y, s.x - pose.x)
        head: HeadState | None = self.bb.head
        if head is None or abs(wrap_angle(bearing - pose.theta - head.pan)) <= self.GLANCE_ON:
            self._glance_on.setdefault(s.track_id, self.t)
        on = self._glance_on.get(s.track_id, math.inf)
        if self.t - on >= seconds or self.t - began >= self.GLANCE_TURN_S + seconds:
            return False
        self.intents.look_at(s.xy, "stranger")
        off = wrap_angle(bearing - pose.theta)
        if abs(off) > self.GLANCE_ALIGNED:
            self.intents.turn(math.copysign(self.intents.control.max_angular_speed, off))
        else:
            self.intents.stop()
        return True

    def _approach_viewpoint(self, c: TargetState, key: int) -> tuple[float, float] | None:
        """Where to see candidate ``c`` (approached as ``key``) from: in front of them once
        they showed the robot no face (:meth:`_approach_candidate`), if there is such a place;
        else the nearest. In front, places within ``APPROACH_HEAD_ON`` of the way they face come
        first (:func:`~pfctl.core.perception.viewpoints.face_viewpoint`). A place in front
        found once is kept while they stand within ``APPROACH_SAME_PLACE`` of where they stood
        then: traced, crowd seed 1, she stood facing a corner, and the only place in front of
        her lay at ``APPROACH_MIN``; her track's few centimetres of jitter took it in and out
        of reach, and each time it was out the robot chose the nearest place, where it stood,
        and stopped there, her back to it, until ``approach_s`` ran out; crowd seed 4, chosen
        anew each second, the place went back and forth between her front and her side as the
        robot drove."""
        pose = self.bb.pose
        facing = self._approach_facing.get(key)
        if facing is not None:
            kept = self._approach_front.get(key)
            if kept is not None and math.dist(kept[1], c.xy) <= self.APPROACH_SAME_PLACE:
                return kept[0]
            front = face_viewpoint(
                self.world.planner,
                (pose.x, pose.y),
                c.xy,
                facing,
                self.APPROACH_MIN,
                self.APPROACH_TO,
                clearance=self.APPROACH_CLEARANCE,
                head_on=self.APPROACH_HEAD_ON,
            )
            if front is not None:
                self._approach_front[key] = (front.xy, c.xy)
                return front.xy
        found = nearest_viewpoint(
            self.world.planner,
            (pose.x, pose.y),
            c.xy,
            self.APPROACH_TO,
            self.APPROACH_MIN,
            self.APPROACH_CLEARANCE,
        )
        return None if found is None else found.xy

    def _fresh(self, goal: tuple[float, float]) -> bool:
        return all(math.dist(goal, v) >= self.VISITED_RADIUS for v in self._visited)

    def _decide(self) -> WaypointDecision:
        seen = self.last_seen
        history = seen.history if seen is not None else np.empty((0, 3))
        pose = self.bb.pose
        decision = self._unvisited(self.world.next_waypoint(history, (pose.x, pose.y)))
        self._decided_at = self.t
        current = self._decision
        keep = None
        if current is not None and current.reason == "frontier":
            keep = next(
                (
                    g
                    for g, u in zip(decision.goals, decision.utilities, strict=True)
                    if np.isfinite(u) and math.dist(g, current.waypoint) < self.KEEP_RADIUS
                ),
                None,
            )
        if keep is not None:
            decision = _with_waypoint(decision, keep)
        self._decision = decision
        self.bb.waypoint = decision
        return decision

    def _looked_at(self, cluster: FrontierCluster) -> bool:
        """Whether the camera has seen, since the loss, at least ``LOOKED_SHARE`` of the
        places a person could stand within ``LOOKED_RADIUS`` of ``cluster``: a frontier stands
        for places the laser has not mapped, and is worth a visit only while she could be
        there unseen. Round a kitchen's furniture the laser leaves frontiers long after the
        camera has looked over the room (generated home 16: 50 s of way-points in the kitchen
        while she stood in the bedroom)."""
        wb = self.world.whereabouts
        if wb is None or not wb.active or not self.params["looked_round"]:
            return False
        r = round(self.LOOKED_RADIUS / wb.geometry.resolution)
        rows, cols = cluster.cells[:, 0], cluster.cells[:, 1]
        r0, c0 = max(int(rows.min()) - r, 0), max(int(cols.min()) - r, 0)
        r1, c1 = int(rows.max()) + r + 1, int(cols.max()) + r + 1
        near = np.zeros((r1 - r0, c1 - c0), dtype=bool)
        near[rows - r0, cols - c0] = True
        near = binary_dilation(near, np.ones((2 * r + 1, 2 * r + 1), dtype=bool))
        walkable = wb.labels[r0:r1, c0:c1] >= 0
        places = near[: walkable.shape[0], : walkable.shape[1]] & walkable
        n = int(places.sum())
        if n == 0:
            return False
        seen = np.isfinite(wb.seen_at[r0:r1, c0:c1]) & places
        return int(seen.sum()) >= self.LOOKED_SHARE * n

    def _unvisited(self, decision: WaypointDecision) -> WaypointDecision:
        """``decision`` without the places already visited, nor the frontiers round which the
        camera has looked (:meth:`_looked_at`). A cluster whose goal (its point
        nearest l*) was visited but which is still a frontier — the robot got there and could
        not see past an obstacle, e.g. round the end of a bookshelf — gets its nearest point
        that is not near a visited way-point (keeping its utility): the robot follows the
        frontier along instead of leaving the room. A cluster with no such point is out; with
        no cluster left, the way-point is l*'s point (``visited_fallback``). With the
        nearest-frontier choice, "nearest" is to the robot, not to l*."""
        if decision.reason != "frontier":
            return decision  # no reachable frontier: Algorithm 1 already goes to l*
        pose = self.bb.pose
        here = (pose.x, pose.y)
        anchor = here if decision.choice == "nearest" else decision.target_point or here
        goals: list[tuple[float, float]] = []
        utilities: list[float] = []
        for cluster, goal, u in zip(
            decision.clusters, decision.goals, decision.utilities, strict=True
        ):
            if self._looked_at(cluster):
                goals.append(goal)
                utilities.append(-math.inf)
                continue
            if self._fresh(goal):
                goals.append(goal)
                utilities.append(u)
                continue
            pts = cluster.points
            far = np.ones(len(pts), dtype=bool)
            for v in self._visited:
                far &= np.hypot(pts[:, 0] - v[0], pts[:, 1] - v[1]) >= self.VISITED_RADIUS
            if far.any():
                cand = pts[far]
                i = int(np.argmin(np.hypot(cand[:, 0] - anchor[0], cand[:, 1] - anchor[1])))
                goals.append((float(cand[i, 0]), float(cand[i, 1])))
                utilities.append(u)
            else:
                goals.append(goal)
                utilities.append(-math.inf)
        decision = replace(decision, goals=tuple(goals), utilities=tuple(utilities))
        ranked = sorted(range(len(goals)), key=lambda i: -utilities[i])  # first on ties
        if np.isfinite(utilities[ranked[0]]):
            return _with_waypoint(decision, goals[ranked[0]])
        if decision.target_point is not None:
            return replace(
                decision, waypoint=decision.target_point, reason="visited_fallback", best=None
            )
        return decision

    def act(self) -> Status:
        if self.visible():
            return Status.SUCCESS
        if self.hold_on_target(self._start):
            return Status.RUNNING
        if self._approach_candidate():
            self._decision, self._look, self._looking_since = None, None, None
            return Status.RUNNING
        if self._glance_at_stranger():
            return Status.RUNNING  # the way-point or look under way goes on after the glance
        search = self.world.search
        strategy = search.strategy if self.last_seen is not None else search.never_seen_strategy
        believe = self.world.whereabouts is not None and self.world.whereabouts.active
        if believe and (strategy == "belief" or self._look is not None):
            # strategy paper: a look the belief chose when the frontiers ran out goes on
            status = self._act_belief()
            if status is not None:
                return status
        decision = self._decision
        if decision is None or self.t - self._decided_at >= self.REPLAN_S:
            decision = self._decide()
        if decision.reason == "no_target":
            return Status.FAILURE
        if believe and self.params["looked_round"] and decision.reason != "frontier":
            # no frontier is worth a visit (each visited, looked round by the camera, or none
            # reachable): look where the belief over where she can be says, not at l* again
            status = self._act_belief()
            if status is not None:
                return status
        outcome = self.intents.go_to(decision.waypoint, self.params["tolerance"])
        if outcome == "running":
            return Status.RUNNING
        self._visited.append(decision.waypoint)
        if decision.reason == "visited_fallback":
            self._visited.clear()  # everything was seen once: look here, then start afresh
        decision = self._decide()
        if decision.reason == "no_target":
            return Status.FAILURE
        if self.intents.go_to(decision.waypoint, self.params["tolerance"]) != "running":
            self.intents.turn(self.intents.control.max_angular_speed * 0.5)
        return Status.RUNNING

    # -- strategy "belief": where she can be, the next place by P / (t_drive + t_look) ----------

    def _choose(self) -> Look | None:
        pose = self.bb.pose
        p = self.prediction
        if p is not None and p.reached and p.region is not None:
            self._from_door.add(p.region)  # go_to_prediction went to its doorway and looked
        control = self.intents.control
        looks = rank_looks(
            self.world.whereabouts,  # type: ignore[arg-type]
            self.t,
            (pose.x, pose.y),
            robot_speed=control.max_linear_speed,
            look_s=self.world.search.look_s,
            looked_from_door=self._from_door,
            skip=self._failed
            | {k for k, at in self._unreachable.items() if self.t - at < self.RETRY_S},
        )
        self._look_chosen_at = self.t
        current = self._look
        if not looks:
            return None
        best = looks[0]
        if current is not None and self._looking_since is None:
            same = next(
                (lk for lk in looks if (lk.region, lk.kind) == (current.region, current.kind)),
                None,
            )
            if same is not None and best.score < self.SWITCH_GAIN * same.score:
                best = same
        return best

    def _act_belief(self) -> Status | None:
        """One tick of the belief search: drive to the chosen place, then sweep the head over
        the room from there for ``search.look_s``; then choose again. None when the belief has
        no place left to look (the caller falls back to Algorithm 1's frontiers)."""
        look = self._look
        if look is None or (
            self._looking_since is None and self.t - self._look_chosen_at >= self.REPLAN_S
        ):
            look = self._choose()
            if look is None:
                self._look = None
                return None
            if look != self._look:
                self._looking_since = None
            self._look = look
        if self._looking_since is None:
            outcome = self.intents.go_to(look.viewpoint, self.params["tolerance"])
            if outcome == "running":
                self.intents.look_at(look.look_at, "sweep")
                return Status.RUNNING
            if outcome == "failed":
                self._unreachable[(look.region, look.kind)] = self.t
                self._look = None
                self.intents.stop()
                return Status.RUNNING
            self._looking_since = self.t
        elapsed = self.t - self._looking_since
        seconds = self.world.search.look_s
        if elapsed >= seconds:
            if look.kind == "doorway":
                self._from_door.add(look.region)
            else:
                self._inside[look.region] = self._inside.get(look.region, 0) + 1
                if self._inside[look.region] >= self.INSIDE_LOOKS:
                    self._failed.add((look.region, "inside"))  # the rest cannot be seen
            self._look, self._looking_since = None, None
            self._look_chosen_at = -math.inf
            self.intents.stop()
            return Status.RUNNING
        pose = self.bb.pose
        bearing = math.atan2(look.look_at[1] - pose.y, look.look_at[0] - pose.x) - pose.theta
        bearing = math.atan2(math.sin(bearing), math.cos(bearing))
        if abs(bearing) > self.LOOK_PAN:
            self.intents.turn(math.copysign(0.5 * self.intents.control.max_angular_speed, bearing))
        else:
            self.intents.stop()
        self.intents.set_pan(bearing + sweep_pan(elapsed, seconds, self.LOOK_PAN), 0.0, "sweep")
        return Status.RUNNING


def _unlooked_side(person: tuple[float, float], looked: Sequence[tuple[float, float]]) -> float:
    """The way a person is taken to face when the robot has looked at them from ``looked``
    and seen no face (rad, map frame): the middle of the widest angle round them between the
    places looked from — away from the one place at first, then a side not looked from yet."""
    bearings = sorted(math.atan2(y - person[1], x - person[0]) for x, y in looked)
    if len(bearings) == 1:
        return wrap_angle(bearings[0] + math.pi)
    gap, start = max(
        ((bearings[(k + 1) % len(bearings)] - b) % (2 * math.pi), b) for k, b in enumerate(bearings)
    )
    return wrap_angle(start + gap / 2.0)


def _with_waypoint(decision: WaypointDecision, goal: tuple[float, float]) -> WaypointDecision:
    best = decision.goals.index(goal)  # the first on equal goals: the higher utility
    return replace(decision, waypoint=goal, best=best, reason="frontier")


class GoToLastSeen(Action):
    """MOVE_BASE to where the target was last detected: RUNNING while driving there, SUCCESS on
    arrival, FAILURE if the target was never seen or the place cannot be reached. The outcome
    holds for that sighting (as go_to_prediction's arrival does): a robot that turns or drifts
    at the place (look_around next) does not drive back into it, and one that could not get there
    does not try again on every tick; a new sighting starts afresh. The "go to the last seen
    position" baseline (``missions/trees/last_seen.yaml``)."""

    spec = LeafSpec(
        "go_to_last_seen",
        "action",
        "Navigate to where the target was last seen; success on arrival (and from then on "
        "for that sighting), failure when it was never seen or there is no way there.",
        (param("tolerance", 0.5, "arrival distance, m", minimum=0.05),),
    )

    def __init__(self, name: str, namespace: str, params: dict[str, Any]) -> None:
        super().__init__(name, namespace, params)
        self._outcome: tuple[float, Status] | None = None
        """(the sighting's time, SUCCESS or FAILURE) once the drive there has ended."""

    def act(self) -> Status:
        seen = self.last_seen
        if seen is None:
            return Status.FAILURE
        if self._outcome is not None and self._outcome[0] == seen.t:
            return self._outcome[1]
        outcome = self.intents.go_to(seen.xy, self.params["tolerance"])
        if outcome == "running":
            return Status.RUNNING
        status = Status.SUCCESS if outcome == "arrived" else Status.FAILURE
        self._outcome = (seen.t, status)
        return status


class OracleSearch(Action):
    """The oracle baseline (issue 22): **privileged**, simulator only. Reads the target's true
    position (blackboard key ``true_target``, the simulator's ground truth, which no other leaf
    declares) and drives to the nearest place from which she is in sight
    (:func:`~pfctl.core.perception.viewpoints.nearest_viewpoint`: free for the robot, within
    ``range`` of her, no wall or furniture between), re-planned every ``REPLAN_S`` seconds as
    she walks, the head on her true position; its time to re-find is the floor a search can be
    compared against. A line of sight that only just clears a door jamb shows the camera too
    little of her to detect: when the robot has stood at the place for ``settle`` seconds
    without seeing her, the line's clearance grows by ``CLEARANCE_STEP`` (up to
    ``MAX_CLEARANCE``) and the place is chosen again. RUNNING until the target is detected
    (SUCCESS); FAILURE without the truth or when no such place can be reached."""

    spec = LeafSpec(
        "oracle_search",
        "action",
        "PRIVILEGED, simulator only (reads the ground truth): drive to the nearest place from "
        "which the target's true position is in sight, head on her; the oracle baseline.",
        (
            param(
                "range",
                None,
                "how far she may be from the place, m (default the camera's range_max)",
                minimum=0.5,
            ),
            param("range_min", 0.6, "how near she may be to the place, m", minimum=0.0),
            param(
                "clearance",
                0.25,
                "the line of sight keeps this far from walls and furniture, m",
                minimum=0.0,
            ),
            param("tolerance", 0.3, "arrival distance at the place, m", minimum=0.05),
            param(
                "settle",
                2.0,
                "seconds at the place with her unseen before a clearer line of sight is sought",
                minimum=0.1,
            ),
        ),
    )
    reads = (*Leaf.reads, "true_target")

    REPLAN_S: ClassVar[float] = 1.0
    CLEARANCE_STEP: ClassVar[float] = 0.25
    MAX_CLEARANCE: ClassVar[float] = 1.0

    def initialise(self) -> None:
        self._goal: tuple[float, float] | None = None
        self._decided_at = -math.inf
        self._extra_clearance = 0.0
        self._arrived_at: float | None = None

    def _place(self, truth: tuple[float, float]) -> tuple[float, float] | None:
        """The nearest place with her in sight at the current clearance; at the mission's own
        clearance when no place has the larger one."""
        pose = self.bb.pose
        reach = self.params["range"]
        hi = math.inf if reach is None else float(reach)
        lo = min(float(self.params["range_min"]), hi / 2)
        base = float(self.params["clearance"])
        for clearance in dict.fromkeys((base + self._extra_clearance, base)):
            place = nearest_viewpoint(
                self.world.planner, (pose.x, pose.y), truth, hi, lo, clearance
            )
            if place is not None:
                return place.xy
        return None

    def act(self) -> Status:
        if self.visible():
            return Status.SUCCESS
        truth: tuple[float, float] | None = self.bb.true_target
        if truth is None:
            return Status.FAILURE
        if self._goal is None or self.t - self._decided_at >= self.REPLAN_S:
            self._decided_at = self.t
            self._goal = self._place(truth)
        self.intents.look_at(truth, "oracle")
        if self._goal is None:
            self.intents.stop()
            return Status.FAILURE
        outcome = self.intents.go_to(self._goal, self.params["tolerance"])
        if outcome == "failed":
            self._goal = None
            return Status.FAILURE
        if outcome != "arrived":
            self._arrived_at = None
        elif self._arrived_at is None:
            self._arrived_at = self.t
        elif self.t - self._arrived_at >= self.params["settle"]:
            base = float(self.params["clearance"])
            self._extra_clearance = min(
                self._extra_clearance + self.CLEARANCE_STEP, max(0.0, self.MAX_CLEARANCE - base)
            )
            self._arrived_at = None
            self._decided_at = -math.inf  # choose the place again on the next tick
        return Status.RUNNING


class SeeFace(Action):
    """Go and see the face of an ambiguous person (issue 23, item 3): someone in her clothes
    whose face has not been seen (blackboard key ``candidate``), while she is not named. Drives
    to a place in front of them ``range_min``..``range_max`` m away (the direction they walk, or
    the robot's side of them when they stand), at least ``aside`` off a walker's path ahead (not
    in their way; :func:`~pfctl.core.perception.viewpoints.face_viewpoint`), re-planned every
    ``REPLAN_S`` seconds, with the head aimed at their face (``face_height``). SUCCESS when the
    face has decided (she is the target now, or the person is no longer a candidate); FAILURE
    without a candidate, when no such place can be reached, or after ``timeout`` s — the same
    person is not tried again for ``retry_s``."""

    spec = LeafSpec(
        "see_face",
        "action",
        "Drive to a place in front of an ambiguous person (her clothes, no face seen yet), "
        "head at face height, until their face decides; gives up after timeout s.",
        (
            param("range_min", 1.5, "nearest distance to them, m", minimum=0.5),
            param("range_max", 2.5, "farthest distance to them, m", minimum=1.0),
            param("timeout", 15.0, "give up after this long, s", minimum=1.0),
            param("retry_s", 30.0, "a person given up on is not tried again for this long, s"),
            param(
                "face_height", FACE_HEIGHT, "height of the face to aim the head at, m", minimum=0.5
            ),
            param("aside", 20.0, "degrees off a walker's path ahead the place keeps", minimum=0.0),
            param("clearance", 0.25, "the line of sight keeps this far from walls, m"),
            param("tolerance", 0.3, "arrival distance at the place, m", minimum=0.05),
        ),
    )
    reads = (*Leaf.reads, "candidate")

    REPLAN_S: ClassVar[float] = 1.0
    #: Slower than this (m/s) a person is standing: they are seen from the robot's side.
    WALKING: ClassVar[float] = 0.2
    #: A walker's place is chosen where they will be this far ahead, s.
    LEAD_S: ClassVar[float] = 1.0

    def __init__(self, name: str, namespace: str, params: dict[str, Any]) -> None:
        super().__init__(name, namespace, params)
        self._given_up: dict[int, float] = {}

    def initialise(self) -> None:
        self._track: int | None = None
        self._started = self.t
        self._goal: tuple[float, float] | None = None
        self._decided_at = -math.inf

    @property
    def candidate(self) -> TargetState | None:
        value: TargetState | None = self.bb.candidate
        return value

    def act(self) -> Status:
        if self.visible():
            return Status.SUCCESS
        c = self.candidate
        if c is None or (self._track is not None and c.track_id != self._track):
            return Status.FAILURE if self._track is None else Status.SUCCESS
        if self.t - self._given_up.get(c.track_id, -math.inf) < self.params["retry_s"]:
            return Status.FAILURE
        if self._track is None:
            self._track, self._started = c.track_id, self.t
        if self.t - self._started >= self.params["timeout"]:
            self._given_up[c.track_id] = self.t
            return Status.FAILURE
        self.intents.look_at(c.xy, "see_face", self.params["face_height"])
        if self._goal is None or self.t - self._decided_at >= self.REPLAN_S:
            self._goal = self._place(c)
            self._decided_at = self.t
        if self._goal is None:
            self._given_up[c.track_id] = self.t
            self.intents.stop()
            return Status.FAILURE
        facing = math.atan2(c.y - self._goal[1], c.x - self._goal[0])
        if self.intents.go_to(self._goal, self.params["tolerance"], facing) == "failed":
            self._given_up[c.track_id] = self.t
            return Status.FAILURE
        return Status.RUNNING

    def _place(self, c: TargetState) -> tuple[float, float] | None:
        pose = self.bb.pose
        speed = math.hypot(c.vx, c.vy)
        walking = speed >= self.WALKING
        if walking:
            facing = math.atan2(c.vy, c.vx)
            at = (c.x + c.vx * self.LEAD_S, c.y + c.vy * self.LEAD_S)
        else:
            facing = math.atan2(pose.y - c.y, pose.x - c.x)
            at = c.xy
        place = face_viewpoint(
            self.world.planner,
            (pose.x, pose.y),
            at,
            facing,
            float(self.params["range_min"]),
            float(self.params["range_max"]),
            aside=math.radians(self.params["aside"]) if walking else 0.0,
            clearance=float(self.params["clearance"]),
        )
        return None if place is None else place.xy


class Stop(Action):
    """Stop the base; SUCCESS."""

    spec = LeafSpec("stop", "action", "Stop the base; success.")

    def act(self) -> Status:
        self.intents.stop()
        return Status.SUCCESS


#: Every leaf by name: the registry (:mod:`pfctl.core.behavior.registry`) is derived from these
#: classes' specs, conditions first.
LEAF_CLASSES: dict[str, type[Leaf]] = {
    cls.spec.name: cls
    for cls in (
        TargetVisible,
        TargetTracked,
        TargetLostFor,
        PredictionAvailable,
        NearTarget,
        FollowTarget,
        GazeAtTarget,
        GoToPrediction,
        LookAround,
        WaypointSearch,
        GoToLastSeen,
        OracleSearch,
        SeeFace,
        Stop,
    )
}

#: Search actions: when one of them runs while the target is lost, the robot is "predicted"
#: (going to the prediction and looking there) or "searching" (Algorithm 1).
PREDICTION_ACTIONS = ("go_to_prediction", "look_around")
SEARCH_ACTIONS = ("waypoint_search", "go_to_last_seen", "oracle_search", "see_face")

#: Leaves that read the simulator's ground truth (the oracle baseline): a tree naming one runs
#: only in the simulator, which gives it the truth; the real robot refuses it.
PRIVILEGED_LEAVES = (OracleSearch.spec.name,)


def leaf_factory(
    namespace: str, defaults: dict[str, dict[str, Any]] | None = None
) -> Callable[[str, str, dict[str, Any]], py_trees.behaviour.Behaviour]:
    """The ``factory(kind, name, params)`` of :func:`~pfctl.core.behavior.tree.build_tree`:
    leaves in ``namespace``; ``defaults[name][param]`` fills parameters left None (the
    mission's values, e.g. ``follow_target.distance``)."""

    def make(kind: str, name: str, params: dict[str, Any]) -> py_trees.behaviour.Behaviour:
        cls = LEAF_CLASSES[name]
        spec = cls.spec
        if spec.kind != kind:
            raise ValueError(f"{name} is a {spec.kind}, not a {kind}")
        filled = dict(params)
        for key, value in (defaults or {}).get(name, {}).items():
            if filled.get(key) is None:
                filled[key] = value
        return cls(name, namespace, filled)

    return make


__all__ = [
    "LEAF_CLASSES",
    "PREDICTION_ACTIONS",
    "PRIVILEGED_LEAVES",
    "SEARCH_ACTIONS",
    "Action",
    "Leaf",
    "leaf_factory",
]
