"""The follower: one tick of the paper's architecture (Fig. 1), on any Robot port.

:meth:`Follower.tick` runs these stages in order; each is a method that can be called (and
timed) on its own:

1. :meth:`~Follower.observe` — every laser scan since the previous tick, the newest RGB-D frame,
   pose and head angles, and the status of the navigation goal (Robot port);
2. :meth:`~Follower.perceive` — legs + vision → tracking → identification (Algorithm 2) and the
   human belief (Eq. 4): :class:`~pfctl.core.perception.pipeline.Perception`, each scan at its
   own stamp and laser pose, the frame at its stamp among them; the newest scan is fused
   into the robot's occupancy grid (Eq. 1), which starts unknown, so what the robot has not seen
   yet shows as frontiers for Algorithm 1. It gives the target's state: the identified track, if
   the tracker still has it;
3. :meth:`~Follower.predict` — the target's detected path is kept; when the target stops being
   detected, the prediction of §II-E is made from the path of the last ``prediction.history_s``
   seconds (the mission's model, the paper's weighted SVR), clipped to the map, and its end moved
   into free space;
4. :meth:`~Follower.decide` — the blackboard keys of :mod:`pfctl.core.behavior.blackboard` are
   written and the mission's tree is ticked once: its leaves write intents for the base and the
   head (:class:`~pfctl.core.behavior.intents.Intents`), never commands; a head no leaf pointed
   follows the gaze rule (:func:`~pfctl.core.control.gaze_rule`: target, belief, legs);
5. :meth:`~Follower.act` — the one place that sends the tick's intents to the robot (the head's
   PD controller turns the head intents into a joint command; what a leaf says goes to a robot
   that speaks, :class:`~pfctl.core.robot.Speaker`);
6. :meth:`~Follower.log_tick` — a :class:`~pfctl.core.episode.TickRecord`: awareness (visible /
   tracked / lost / predicted / searching), the active action, the base mode, the gaze.

The follower never reads ground truth, with one named exception: the oracle baseline's
``true_target`` (see :class:`Follower`), given only when its tree asks for it. :meth:`close`
stops the base.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import py_trees
from py_trees.common import Access

from pfctl.core.behavior.blackboard import (
    KEYS,
    PredictionState,
    Sighting,
    TargetState,
    clear_namespace,
    new_namespace,
)
from pfctl.core.behavior.intents import (
    CancelGoal,
    HeadAngles,
    HeadIntent,
    Intents,
    LookAt,
    Navigate,
    Navigation,
    Stop,
    Velocity,
)
from pfctl.core.behavior.leaves import PREDICTION_ACTIONS, SEARCH_ACTIONS, leaf_factory
from pfctl.core.behavior.tree import build_tree
from pfctl.core.behavior.world import WorldModel, since_region_entered
from pfctl.core.control import (
    KNOWN_RADIUS,
    PEAK_CANDIDATES,
    ControlParams,
    GazeController,
    gaze_angles,
    gaze_rule,
)
from pfctl.core.episode import (
    EpisodeLog,
    PredictionRecord,
    RoomPredictionRecord,
    SpeechRecord,
    TickRecord,
    WaypointRecord,
)
from pfctl.core.mapping.grid import FREE, InverseSensorModel, OccupancyGrid
from pfctl.core.mapping.paths import line_of_sight
from pfctl.core.mapping.planning import GridPlanner
from pfctl.core.mapping.regions import (
    RegionMap,
    SearchParams,
    WaypointDecision,
    heading_region,
    heading_scores,
)
from pfctl.core.params import param
from pfctl.core.perception.pipeline import Perception, in_stamp_order
from pfctl.core.perception.tracking import Track
from pfctl.core.prediction.clipping import clip_prediction
from pfctl.core.prediction.models import (
    DEFAULT_MODEL,
    MIN_POINTS,
    ModelName,
    PredictionError,
    make_model,
)
from pfctl.core.robot import STOP, HeadTarget, LaserScan, Observation, Pose2D, Robot, Speaker
from pfctl.core.search.gaze import UnseenGaze
from pfctl.core.search.next_look import doorway
from pfctl.core.search.whereabouts import Whereabouts


@dataclass(frozen=True)
class PredictionParams:
    """The predictor used when the target is lost (§II-E; the mission's ``prediction``)."""

    model: ModelName = param(
        DEFAULT_MODEL,
        "The predictor (README, ``pfctl predict``): ``svr`` (the paper's weighted SVR as a state"
        " estimator, then constant velocity), ``svr-time`` (the paper's SVR over time),"
        " ``poly3`` (the paper's weighted cubic polynomial) or ``cv`` (constant velocity).",
    )
    params: Mapping[str, Any] = field(default_factory=dict)
    """The model's hyperparameters by name (``make_model``)."""
    history_s: float = param(
        3.0, "The target's detected path of this long before the loss is fitted.", unit="s", gt=0
    )
    horizon_s: float = param(3.0, "How far ahead the prediction reaches.", unit="s", gt=0)
    step_s: float = 0.25
    """Spacing of the predicted points, s."""


@dataclass(frozen=True)
class FollowerParams:
    """Everything the follower needs besides the robot, the perception and the tree."""

    tick_hz: float = param(
        10.0, "Ticks of the behavior tree (and control periods) per second.", unit="Hz", gt=0
    )
    control: ControlParams = field(default_factory=ControlParams)
    search: SearchParams = field(default_factory=SearchParams)
    prediction: PredictionParams = field(default_factory=PredictionParams)
    visible_age: float = 0.5
    """The target counts as visible when detected within this many seconds."""
    keep_path_s: float = 10.0
    """How much of the target's detected path is kept, seconds."""
    belief_threshold: float = 0.3
    """The gaze looks at the belief peak only above this probability."""
    room_horizon_s: float = 5.0
    """The room prediction made at a loss is of where she is this long after it, s."""
    stranger_range: float = 4.0
    """A person the camera has not seen is worth a glance within this far, m (their clothes
    decide at that distance)."""


def _track_state(track: Track | None) -> TargetState | None:
    """A track as the blackboard's track state (None for None)."""
    if track is None:
        return None
    return TargetState(track.id, track.x, track.y, track.vx, track.vy, track.last_seen)


class Follower:
    """The paper's person follower on one robot (see the module docstring)."""

    def __init__(
        self,
        robot: Robot,
        perception: Perception,
        tree: Mapping[str, Any],
        params: FollowerParams,
        *,
        static_map: OccupancyGrid,
        regions: RegionMap,
        sensor_model: InverseSensorModel | None = None,
        robot_radius: float = 0.215,
        leaf_defaults: dict[str, dict[str, Any]] | None = None,
        log: EpisodeLog | None = None,
        true_target: Callable[[], tuple[float, float] | None] | None = None,
    ) -> None:
        """``true_target`` is **privileged**: the simulator's truth of where the target is,
        given only for a tree with the oracle baseline's ``oracle_search`` (the app layer
        decides); it is written to the blackboard key of that name, which only that leaf reads,
        and nothing else of the follower calls it."""
        self.robot = robot
        self.perception = perception
        self.params = params
        self.regions = regions
        self.log = log if log is not None else EpisodeLog()
        self.grid = OccupancyGrid(static_map.geometry, sensor_model=sensor_model)
        self.planner = GridPlanner(static_map, robot_radius)
        self.dt = 1.0 / params.tick_hz
        whereabouts = Whereabouts(regions, static_map.geometry, static_map.states() == FREE)
        self.world = WorldModel(
            self.grid,
            self.planner,
            regions,
            params.search,
            whereabouts,
            sight_blocked=static_map.states() != FREE,
            camera_range=perception.camera_range,
        )
        self.navigation = Navigation()
        self.intents = Intents(params.control, self.world, self.navigation)
        self._speaker = robot if isinstance(robot, Speaker) else None
        """The robot's voice, if it has one (whether anyone hears it is asked every tick)."""
        self.gaze = GazeController(params.control)
        """The head's PD joint controller (act: one step per head intent)."""
        self.unseen_gaze = (
            UnseenGaze(
                whereabouts,
                static_map.states() != FREE,
                params.control.pan_limits,
            )
            if params.search.gaze == "unseen"
            else None
        )
        """The search's gaze at the places not seen yet (None: ``search.gaze`` goal)."""
        self.namespace = new_namespace()
        self._writer = py_trees.blackboard.Client(name="follower", namespace=self.namespace)
        for key in KEYS:
            self._writer.register_key(key, access=Access.WRITE)
        self._writer.world = self.world
        self._writer.intents = self.intents
        self._writer.waypoint = None
        self._writer.candidate = None
        self._writer.stranger = None
        self._writer.true_target = None
        self._true_target = true_target
        self._now = 0.0
        defaults = {"follow_target": {"distance": params.control.following_distance}}
        defaults.update(leaf_defaults or {})
        self.root = build_tree(tree, leaf_factory(self.namespace, defaults), lambda: self._now)
        self.root.setup_with_descendants()
        self._path: deque[tuple[float, float, float]] = deque()
        self._last_seen: Sighting | None = None
        self._prediction: PredictionState | None = None
        self._had_target = False
        self._last_scan_stamp: float | None = None
        self._last_waypoint: object = None
        self._closed = False
        self.ticks = 0
        self.robot_pose: tuple[float, float] | None = None

    # -- the tick ---------------------------------------------------------------------------------

    def tick(self) -> TickRecord:
        """One tick: observe, perceive, predict, decide, act, log (module docstring)."""
        obs = self.observe()
        target = self.perceive(obs)
        self.predict(obs.stamp, target)
        self.decide(obs, target)
        self.act(obs)
        return self.log_tick(obs, target)

    def observe(self) -> Observation:
        """What the robot senses now (Robot port), the status of its navigation goal, and
        whether anyone hears it speak."""
        obs = self.robot.observe()
        self._now = obs.stamp
        self.robot_pose = (obs.pose.x, obs.pose.y)
        self.navigation.status = self.robot.nav_status()
        self.intents.can_speak = self._speaker is not None and self._speaker.speaks
        return obs

    def perceive(self, obs: Observation) -> TargetState | None:
        """Feed every scan (then log the tracks it leaves, as ``pfctl replay`` does after each
        scan of a bag) and the frame to the perception in the order of their stamps (the scans'
        segments classified in one pass first: a 40 Hz laser brings four scans a tick); update the
        occupancy grid (Eq. 1) with the newest scan (the inverse sensor model's evidence is
        per tick) and the people of the world model. The target's state: its identified track,
        if any."""
        whereabouts = self.world.whereabouts
        classified = iter(self.perception.legs.classify(obs.scans))
        for message in in_stamp_order(obs):
            if isinstance(message, LaserScan):
                self.perception.on_scan(message, next(classified))
                self.log.tracks += self.perception.seen_track_rows(message.stamp)
                continue
            self.perception.on_frame(message)
            visible = self.perception.last_visible
            if whereabouts is not None and visible is not None:
                whereabouts.observe(message.stamp, visible)
        scan = obs.scan
        if whereabouts is not None and self._last_seen is None and not whereabouts.active:
            whereabouts.never_seen(obs.stamp, (obs.pose.x, obs.pose.y))
        if scan is not None:
            self._last_scan_stamp = scan.stamp
            self.grid.update_scan(
                (scan.pose.x, scan.pose.y, scan.pose.theta),
                scan.ranges,
                scan.angle_min,
                scan.angle_increment,
                scan.range_max,
                scan.range_min,
            )
        target = self._target_state()
        people = [
            t.position
            for t in self.perception.tracks()
            if target is None or t.id != target.track_id
        ]
        self.world.update(self._last_scan_stamp, people)
        return target

    def _target_state(self) -> TargetState | None:
        return _track_state(self.perception.target())

    def _candidate_state(self) -> TargetState | None:
        """The ambiguous person worth a look at the face (issue 23, item 3), as a track state."""
        return _track_state(self.perception.candidate())

    def _stranger_state(self, now: float, pose: Pose2D) -> TargetState | None:
        """The nearest person whom no camera frame has shown yet (the laser's legs alone, seen
        within ``visible_age``), within ``stranger_range`` of the robot and in its line of sight
        on the static map: a glance tells whether she is the one (issue 22)."""
        here = (pose.x, pose.y)
        sight = self.world.sight_blocked
        best: tuple[float, Track] | None = None
        for track in self.perception.strangers(now, self.params.visible_age):
            d = math.dist(here, track.position)
            if d > self.params.stranger_range or (best is not None and d >= best[0]):
                continue
            if sight is not None and not line_of_sight(
                sight, self.planner.static.geometry, here, track.position
            ):
                continue
            best = (d, track)
        return _track_state(None if best is None else best[1])

    def _visible(self, now: float, target: TargetState | None) -> bool:
        """The target was detected within ``visible_age`` seconds."""
        return target is not None and now - target.last_detected <= self.params.visible_age

    def predict(self, now: float, target: TargetState | None) -> None:
        """Keep the target's detected path; predict where it went when it stops being detected
        (§II-E)."""
        visible = self._visible(now, target)
        if visible and target is not None:
            self._path.append((target.last_detected, target.x, target.y))
            while self._path and self._path[0][0] < now - self.params.keep_path_s:
                self._path.popleft()
            self._last_seen = Sighting(
                target.last_detected, target.xy, np.array(self._path, dtype=float)
            )
            self._prediction = None
            if self.world.whereabouts is not None:
                self.world.whereabouts.found()
        elif self._had_target and self._last_seen is not None:
            self._lost(now, self._last_seen)
            self._prediction = self._fit_prediction(now, self._last_seen)
        self._had_target = visible

    def _lost(self, now: float, seen: Sighting) -> None:
        """Start the belief over where she can be from the last sighting (heading for
        Algorithm 1's l*, coming from the region she was in before) and log its room prediction
        ``room_horizon_s`` ahead beside l* (issue 22, item 2)."""
        whereabouts = self.world.whereabouts
        if whereabouts is None:
            return
        h = seen.history.reshape(-1, 3)
        recent = since_region_entered(h, self.regions)
        window = self.params.search.heading_window_s
        heading = heading_region(recent, self.regions, window)
        _, scores = heading_scores(recent, self.regions, window)
        current = self.regions.locate(seen.xy)
        came_from = None
        for _, x, y in h[: len(h) - len(recent)][::-1]:
            came_from = self.regions.locate((x, y))
            if came_from is not None:
                break
        approach = {n: -v for n, v in scores.items() if v < 0.0}
        whereabouts.lost(seen.t, seen.xy, heading=heading, came_from=came_from, approach=approach)
        horizon = self.params.room_horizon_s
        ranked = sorted(whereabouts.prior(seen.t + horizon).items(), key=lambda kv: (-kv[1], kv[0]))
        self.log.room_predictions.append(
            RoomPredictionRecord(now, tuple(n for n, _ in ranked), heading, current, horizon)
        )

    def _fit_prediction(self, now: float, seen: Sighting) -> PredictionState | None:
        """§II-E: fit the mission's predictor to the last ``history_s`` of the detected path
        (the paper's weighted SVR), predict ``horizon_s`` ahead, clip to the map, and move the
        end into free space for the robot. With ``search.prediction_goal`` room the place to
        go is the predicted room's doorway instead (:meth:`_predicted_room`), also when the
        path is too short to fit."""
        p = self.params.prediction
        room = self._predicted_room(now)
        h = seen.history
        h = h[h[:, 0] >= seen.t - p.history_s]
        if len(h):  # strictly increasing times
            keep = np.concatenate([[True], np.diff(h[:, 0]) > 1e-6])
            h = h[keep]
        path = None
        if len(h) >= MIN_POINTS.get(p.model, 3):
            times = seen.t + np.arange(1, round(p.horizon_s / p.step_s) + 1) * p.step_s
            try:
                model = make_model(p.model, **dict(p.params)).fit(h[:, 0] - h[0, 0], h[:, 1:3])
                path = np.asarray(model.predict(times - h[0, 0]), dtype=float)
            except PredictionError:
                path = None
        if path is None and room is None:
            return None
        if path is not None:
            clipped = clip_prediction(seen.xy, path, self.planner_grid, self.regions)
            xy, end, region = clipped.xy, clipped.end, clipped.region
        else:  # too short a path for the model: the room alone
            xy, end, region = np.array([seen.xy], dtype=float), seen.xy, None
        if room is not None:  # the predicted room's doorway, not a point on its wall
            end, region = room
        goal = self.planner.free_goal(end)
        if goal is None:
            return None
        state = PredictionState(now, seen.xy, xy, goal, region)
        self.log.predictions.append(PredictionRecord(now, seen.xy, xy, goal))
        return state

    def _predicted_room(self, now: float) -> tuple[tuple[float, float], str] | None:
        """With ``search.prediction_goal`` room: the most probable room a few seconds on and
        where to look into it from (its doorway on the robot's way; the last sighting when she
        is most likely still in the robot's room or her own). None with ``path``."""
        whereabouts = self.world.whereabouts
        if self.params.search.prediction_goal != "room" or whereabouts is None:
            return None
        ranked = whereabouts.ranked(now + self.params.room_horizon_s)
        if not ranked or whereabouts.start is None:
            return None
        room = ranked[0][0]
        pose = self.robot_pose
        door = doorway(self.regions, pose, room) if pose is not None else None
        return (door[0] if door is not None else whereabouts.start), room

    @property
    def planner_grid(self) -> OccupancyGrid:
        """The static map the planner uses (walls and furniture)."""
        return self.planner.static

    def decide(self, obs: Observation, target: TargetState | None) -> None:
        """Write the blackboard and tick the tree once: its leaves write the tick's intents; a
        tick in which no leaf drove the base stops it (:meth:`Intents.end`), and a head no leaf
        pointed follows the gaze rule (:meth:`gaze_intent`)."""
        w = self._writer
        w.t = obs.stamp
        w.pose = obs.pose
        w.head = obs.head
        w.target = target
        w.last_seen = self._last_seen
        w.prediction = self._prediction
        w.candidate = self._candidate_state() if target is None else None
        w.stranger = self._stranger_state(obs.stamp, obs.pose) if target is None else None
        if self._true_target is not None:
            w.true_target = self._true_target()
        self.intents.begin(obs.stamp, obs.pose)
        self.root.tick_once()
        self.intents.end()
        if not self.intents.head:
            self.intents.head.append(self.gaze_intent(obs.pose, target))

    def gaze_intent(self, pose: Pose2D, target: TargetState | None) -> HeadIntent:
        """Where the head looks when no leaf points it: the gaze rule
        (:func:`~pfctl.core.control.gaze_rule`: the target, else the belief peak in sight, else
        the legs, else the navigation goal) on what the perception knows, leaving out the
        people Algorithm 2 has already identified as not the target."""
        perception = self.perception
        if target is not None:  # the rule's first choice (choose_gaze): nothing else matters
            return LookAt((float(target.xy[0]), float(target.xy[1])), "target")
        known = perception.not_target(None)
        belief = perception.belief
        # only the peaks at least belief_threshold likely can draw the gaze: the others are
        # left out here rather than in gaze_rule (the same peaks, found faster)
        peaks = (
            belief.most_likely(
                PEAK_CANDIDATES,
                min_separation=KNOWN_RADIUS,
                at_least=self.params.belief_threshold,
            )
            if belief is not None
            else []
        )
        legs = perception.last_legs
        point, source = gaze_rule(
            (pose.x, pose.y),
            None,
            peaks,
            [(c.x, c.y) for c in legs.people] if legs is not None else [],
            known_xy=known,
            ahead=self.navigation.goal,
            belief_threshold=self.params.belief_threshold,
            max_range=perception.camera_range[1],
            blocked=belief.blocked if belief is not None else None,
            geometry=belief.geometry if belief is not None else None,
        )
        if source in ("goal", "none") and self.unseen_gaze is not None:
            hfov = perception.camera_hfov
            unseen = (
                None
                if hfov is None
                else self.unseen_gaze.point(self._now, pose, hfov, perception.camera_range)
            )
            if unseen is not None:
                return LookAt(unseen, "unseen")
        if point is None:
            return HeadAngles(0.0, 0.0, source)
        return LookAt(point, source)

    def act(self, obs: Observation) -> None:
        """Send the tick's intents to the robot: the one place the follower commands it. The
        base intent becomes its Robot-port call; each head intent is one step of the head's PD
        controller toward it (:class:`~pfctl.core.control.GazeController`) and the last
        step's joint command is sent; what a leaf says is said (and logged)."""
        self._send_base()
        command: HeadTarget | None = None
        for intent in self.intents.head:
            command = self.gaze.update(obs.head, self._head_goal(obs.pose, intent), self.dt)
        if command is not None:
            self.robot.point_head(command)
        text = self.intents.speech
        if text is not None and self._speaker is not None:
            self._speaker.say(text)
            self.log.speech.append(SpeechRecord(obs.stamp, (obs.pose.x, obs.pose.y), text))

    def _send_base(self) -> None:
        base = self.intents.base
        if isinstance(base, Velocity):
            self.robot.command(base.twist)
        elif isinstance(base, Stop):
            if base.cancel_goal:
                self.robot.cancel()
            self.robot.command(STOP)
        elif isinstance(base, Navigate):
            self.robot.navigate(base.goal)
        elif isinstance(base, CancelGoal):
            self.robot.cancel()

    def _head_goal(self, pose: Pose2D, intent: HeadIntent) -> HeadTarget:
        """The head angles ``intent`` asks for from ``pose``."""
        if isinstance(intent, LookAt):
            control = self.params.control
            height = control.look_height if intent.height is None else intent.height
            point = (intent.xy[0], intent.xy[1], height)
            return gaze_angles(pose, point, control)
        return HeadTarget(intent.pan, intent.tilt)

    def log_tick(self, obs: Observation, target: TargetState | None) -> TickRecord:
        """The tick's record (appended to the log), and a way-point record for a new decision of
        Algorithm 1."""
        now = obs.stamp
        action = self.intents.action
        if self._visible(now, target):
            awareness = "visible"
        elif target is not None:
            awareness = "tracked"
        elif action in PREDICTION_ACTIONS:
            awareness = "predicted"
        elif action in SEARCH_ACTIONS:
            awareness = "searching"
        else:
            awareness = "lost"
        decision: WaypointDecision | None = self._writer.waypoint
        if decision is not None and decision is not self._last_waypoint:
            self._last_waypoint = decision
            self.log.waypoints.append(
                WaypointRecord(now, decision.waypoint, decision.reason, decision.heading_region)
            )
        record = TickRecord(
            t=now,
            pose=obs.pose,
            awareness=awareness,
            action=action,
            target_id=target.track_id if target is not None else None,
            target_xy=target.xy if target is not None else None,
            goal=self.navigation.goal,
            base_mode=self.intents.base_mode,
            gaze=self.intents.gaze_source,
        )
        self.log.ticks.append(record)
        self.ticks += 1
        return record

    def close(self) -> None:
        """Stop the running actions (a goal they drove to is cancelled) and the base, drop the
        blackboard keys and release the perception (its face worker); safe to call twice."""
        if self._closed:
            return
        self._closed = True
        try:
            self.intents.base = None
            self.root.stop(py_trees.common.Status.INVALID)
            self._send_base()
        finally:
            self.robot.command(STOP)
            clear_namespace(self.namespace)
            self.perception.close()


__all__ = ["Follower", "FollowerParams", "PredictionParams"]
