"""The follower: one tick of the paper's architecture (Fig. 1), on any Robot port.

:meth:`Follower.tick` runs, in order:

1. **observe** — the newest laser scan, RGB-D frame, pose and head angles (Robot port);
2. **perceive** — legs + vision → tracking → identification (Algorithm 2) and the human belief
   (Eq. 4): :class:`~pfctl.core.perception.pipeline.Perception`;
3. **map** — the scan is fused into the robot's occupancy grid (Eq. 1), which starts unknown, so
   what the robot has not seen yet shows as frontiers for Algorithm 1;
4. **target state** — the identified track (if the tracker still has it), the last detection and
   the detected path; when the target stops being detected, the prediction of §II-E is made from
   the path of the last ``prediction.history_s`` seconds (the mission's model, the paper's
   weighted SVR), clipped to the map, and its end moved into free space;
5. **blackboard** — the keys of :mod:`pfctl.core.behavior.blackboard`;
6. **behavior tree** — one tick of the mission's tree; its actions drive the base and the head
   through :class:`~pfctl.core.behavior.skills.Skills`; a head no action claimed follows the
   paper's gaze priority (target, belief, legs);
7. **log** — a :class:`~pfctl.core.episode.TickRecord`: awareness (visible / tracked / lost /
   predicted / searching), the active action, the base mode, the gaze.

The follower never reads ground truth. :meth:`close` stops the base.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Mapping
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
from pfctl.core.behavior.leaves import PREDICTION_ACTIONS, SEARCH_ACTIONS, leaf_factory
from pfctl.core.behavior.skills import SearchParams, Skills
from pfctl.core.behavior.tree import build_tree
from pfctl.core.control import KNOWN_RADIUS, ControlParams, unknown_peak
from pfctl.core.episode import EpisodeLog, PredictionRecord, TickRecord, WaypointRecord
from pfctl.core.mapping.grid import InverseSensorModel, OccupancyGrid
from pfctl.core.mapping.paths import line_of_sight
from pfctl.core.mapping.planning import GridPlanner
from pfctl.core.mapping.regions import RegionMap
from pfctl.core.params import param
from pfctl.core.perception.identity.identifier import Decision
from pfctl.core.perception.pipeline import Perception
from pfctl.core.prediction.clipping import clip_prediction
from pfctl.core.prediction.models import (
    DEFAULT_MODEL,
    MIN_POINTS,
    ModelName,
    PredictionError,
    make_model,
)
from pfctl.core.robot import STOP, Observation, Robot

#: Belief peaks considered for the gaze (the best one away from known people wins).
PEAK_CANDIDATES = 8


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
    ) -> None:
        self.robot = robot
        self.perception = perception
        self.params = params
        self.regions = regions
        self.log = log if log is not None else EpisodeLog()
        self.grid = OccupancyGrid(static_map.geometry, sensor_model=sensor_model)
        self.planner = GridPlanner(static_map, robot_radius)
        self.dt = 1.0 / params.tick_hz
        self.skills = Skills(
            robot, params.control, self.planner, self.grid, regions, params.search, self.dt
        )
        self.namespace = new_namespace()
        self._writer = py_trees.blackboard.Client(name="follower", namespace=self.namespace)
        for key in KEYS:
            self._writer.register_key(key, access=Access.WRITE)
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

    # -- the tick ---------------------------------------------------------------------------------

    def tick(self) -> TickRecord:
        """One tick: observe, perceive, map, decide, act, log (module docstring)."""
        obs = self.robot.observe()
        now = obs.stamp
        self._now = now
        self._perceive(obs)
        target = self._target_state(now)
        visible = target is not None and now - target.last_detected <= self.params.visible_age
        self._update_sightings(now, target, visible)
        self._write_blackboard(now, obs, target)
        people = [
            t.position
            for t in self.perception.tracks()
            if target is None or t.id != target.track_id
        ]
        self.skills.begin_tick(now, obs.pose, obs.head, self._last_scan_stamp, people)
        self.root.tick_once()
        self.skills.end_tick()
        self._gaze(target)
        record = self._record(now, obs, target, visible)
        self.log.ticks.append(record)
        self.ticks += 1
        return record

    def _perceive(self, obs: Observation) -> None:
        """Feed the scan (then log the tracks it leaves, as ``pfctl replay`` does after each
        scan of a bag) and the frame to the perception; update the occupancy grid (Eq. 1)."""
        scan = obs.scan
        if scan is not None:
            self.perception.on_scan(scan)
            self.log.tracks += self.perception.seen_track_rows(scan.stamp)
        if obs.rgbd is not None:
            self.perception.on_frame(obs.rgbd)
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

    def _target_state(self, now: float) -> TargetState | None:
        track = self.perception.target()
        if track is None:
            return None
        return TargetState(track.id, track.x, track.y, track.vx, track.vy, track.last_seen)

    def _update_sightings(self, now: float, target: TargetState | None, visible: bool) -> None:
        """Keep the detected path; make a prediction when the target stops being detected."""
        if visible and target is not None:
            self._path.append((target.last_detected, target.x, target.y))
            while self._path and self._path[0][0] < now - self.params.keep_path_s:
                self._path.popleft()
            self._last_seen = Sighting(
                target.last_detected, target.xy, np.array(self._path, dtype=float)
            )
            self._prediction = None
        elif self._had_target and self._last_seen is not None:
            self._prediction = self._predict(now, self._last_seen)
        self._had_target = visible

    def _predict(self, now: float, seen: Sighting) -> PredictionState | None:
        """§II-E: fit the mission's predictor to the last ``history_s`` of the detected path
        (the paper's weighted SVR), predict ``horizon_s`` ahead, clip to the map, and move the
        end into free space for the robot."""
        p = self.params.prediction
        h = seen.history
        h = h[h[:, 0] >= seen.t - p.history_s]
        if len(h):  # strictly increasing times
            keep = np.concatenate([[True], np.diff(h[:, 0]) > 1e-6])
            h = h[keep]
        if len(h) < MIN_POINTS.get(p.model, 3):
            return None
        times = seen.t + np.arange(1, round(p.horizon_s / p.step_s) + 1) * p.step_s
        try:
            model = make_model(p.model, **dict(p.params)).fit(h[:, 0] - h[0, 0], h[:, 1:3])
            path = np.asarray(model.predict(times - h[0, 0]), dtype=float)
        except PredictionError:
            return None
        clipped = clip_prediction(seen.xy, path, self.planner_grid, self.regions)
        goal = self.skills.free_goal(clipped.end)
        if goal is None:
            return None
        state = PredictionState(now, seen.xy, clipped.xy, goal, clipped.region)
        self.log.predictions.append(PredictionRecord(now, seen.xy, clipped.xy, goal))
        return state

    @property
    def planner_grid(self) -> OccupancyGrid:
        """The static map the planner uses (walls and furniture)."""
        return self.planner.static

    def _write_blackboard(self, now: float, obs: Observation, target: TargetState | None) -> None:
        w = self._writer
        w.t = now
        w.pose = obs.pose
        w.target = target
        w.last_seen = self._last_seen
        w.prediction = self._prediction
        w.skills = self.skills

    def _gaze(self, target: TargetState | None) -> None:
        """The head when no leaf claimed it (§II-E gaze priority), not spent on people
        Algorithm 2 has already identified as not the target."""
        known = self._known_others(target)
        belief = self.perception.belief
        peak = None
        if belief is not None:
            peaks = belief.most_likely(PEAK_CANDIDATES, min_separation=KNOWN_RADIUS)
            peaks = [p for p in peaks if p[2] >= self.params.belief_threshold]
            peak = unknown_peak(self._in_sight(peaks), known)
        legs = self.perception.last_legs
        legs_xy = [(c.x, c.y) for c in legs.people] if legs is not None else []
        target_xy = target.xy if target is not None else None
        self.skills.default_gaze(target_xy, peak, legs_xy, known)

    def _in_sight(
        self, peaks: list[tuple[float, float, float]]
    ) -> list[tuple[float, float, float]]:
        """The belief peaks the camera could see from here: within its range and with a clear
        line of sight over the static map (a peak behind walls — a person seen there long ago —
        cannot be checked by turning the head, so it does not draw the gaze)."""
        belief = self.perception.belief
        if not peaks or belief is None or belief.blocked is None:
            return peaks
        here = np.array([self.skills.pose.x, self.skills.pose.y])
        xy = np.array([(x, y) for x, y, _ in peaks])
        near = np.linalg.norm(xy - here, axis=1) <= self.perception.camera_range[1]
        clear = line_of_sight(belief.blocked, belief.geometry, here, xy)
        return [p for p, ok in zip(peaks, near & clear, strict=True) if ok]

    def _known_others(self, target: TargetState | None) -> list[tuple[float, float]]:
        """Where the tracks identified as not the target are."""
        identifier = self.perception.identifier
        if identifier is None:
            return []
        others = {
            tid
            for tid, ident in identifier.identities().items()
            if ident.decision is Decision.NOT_TARGET
        }
        return [
            t.position
            for t in self.perception.tracks()
            if t.id in others and (target is None or t.id != target.track_id)
        ]

    def _record(
        self, now: float, obs: Observation, target: TargetState | None, visible: bool
    ) -> TickRecord:
        action = self.skills.action
        if visible:
            awareness = "visible"
        elif target is not None:
            awareness = "tracked"
        elif action in PREDICTION_ACTIONS:
            awareness = "predicted"
        elif action in SEARCH_ACTIONS:
            awareness = "searching"
        else:
            awareness = "lost"
        decision = getattr(self.skills, "waypoint", None)
        if decision is not None and decision is not self._last_waypoint:
            self._last_waypoint = decision
            self.log.waypoints.append(
                WaypointRecord(now, decision.waypoint, decision.reason, decision.heading_region)
            )
        return TickRecord(
            t=now,
            pose=obs.pose,
            awareness=awareness,
            action=action,
            target_id=target.track_id if target is not None else None,
            target_xy=target.xy if target is not None else None,
            goal=self.skills.nav_goal,
            base_mode=self.skills.base_mode,
            gaze=self.skills.gaze_source,
        )

    def close(self) -> None:
        """Stop the base, drop the blackboard keys and release the perception (its face
        worker); safe to call twice."""
        if self._closed:
            return
        self._closed = True
        try:
            self.root.stop(py_trees.common.Status.INVALID)
        finally:
            self.robot.command(STOP)
            clear_namespace(self.namespace)
            self.perception.close()


__all__ = ["Follower", "FollowerParams", "PredictionParams"]
