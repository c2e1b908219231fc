"""What the behavior tree's actions can make the robot do (§II-E): follow, look, go, search.

A :class:`Skills` object sits on the blackboard (key ``skills``); action leaves call it. It turns
intentions into commands on the Robot port (DESIGN.md) and keeps the per-tick bookkeeping the
follower needs:

- the base: :meth:`follow` (TURN / GO_STRAIGHT / MOVE_BASE of :class:`BaseController`),
  :meth:`go_to` (MOVE_BASE to a goal moved into free space, re-sent only when it changes),
  :meth:`turn` and :meth:`stop`. A tick in which no leaf drove the base ends with the base
  stopped (:meth:`end_tick`), so a branch the tree left never keeps driving;
- the head: :meth:`look_at` or :meth:`set_pan` claim it for the tick; otherwise the follower
  points it by the paper's gaze priority (target, else belief, else legs: :meth:`default_gaze`);
- search: :meth:`next_waypoint` runs Algorithm 1 on the robot's occupancy grid.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from pfctl.core.control import (
    BaseController,
    ControlParams,
    GazeController,
    choose_gaze,
    gaze_angles,
)
from pfctl.core.mapping.grid import OCCUPIED_THRESH, OccupancyGrid, logit
from pfctl.core.mapping.planning import GridPlanner
from pfctl.core.mapping.regions import RegionMap, WaypointChoice, WaypointDecision, waypoint_search
from pfctl.core.params import param
from pfctl.core.robot import STOP, HeadState, HeadTarget, NavStatus, Pose2D, Robot, Twist2D

#: A new MOVE_BASE goal is sent only when it moved farther than this from the one being driven to.
RESEND_DISTANCE = 0.4
#: Goals are moved into free space by at most this much, metres.
GOAL_SNAP = 1.5
#: Cells at least this likely occupied block the line of sight (the grid's occupied threshold).
_OCCUPIED_LOGODDS = float(logit(OCCUPIED_THRESH))


@dataclass(frozen=True)
class SearchParams:
    """Eq. 2, Eq. 3 and Algorithm 1 settings (the mission's ``search`` section)."""

    alpha: float = param(0.05, "Utility per unknown cell a frontier borders (Eq. 3).", ge=0)
    beta: float = param(1.0, "Weight of obstacle boundaries in the frontier map (Eq. 2).", ge=0)
    frontier_threshold: float = param(0.1, "F above which a cell is a frontier cell.", gt=0)
    min_frontier_cells: int = param(5, "Smaller frontier clusters are dropped.", ge=1)
    heading_window_s: float = param(
        3.0, "T: the pose history Algorithm 1 looks back over.", unit="s", gt=0
    )
    waypoint_choice: WaypointChoice = param(
        "utility",
        "How Algorithm 1 picks the frontier to search: ``utility`` (Eq. 3, the paper) or"
        " ``nearest`` (the reachable frontier nearest the robot by path length, whatever its size"
        " or l*: the nearest-frontier baseline, ``missions/baselines/``).",
    )


class Skills:
    """The robot's abilities as the leaves use them (module docstring)."""

    def __init__(
        self,
        robot: Robot,
        control: ControlParams,
        planner: GridPlanner,
        grid: OccupancyGrid,
        regions: RegionMap,
        search: SearchParams,
        dt: float,
    ) -> None:
        self.robot = robot
        self.control = control
        self.base = BaseController(control)
        self._controllers: dict[float, BaseController] = {}
        """Controllers for leaves that ask for another following distance."""
        self.gaze = GazeController(control)
        self.planner = planner
        self.grid = grid
        self.regions = regions
        self.search = search
        self.dt = dt
        self.pose = Pose2D(0.0, 0.0)
        self.head = HeadState()
        self.now = 0.0
        self.sensor_stamp: float | None = None
        self.people_xy = np.empty((0, 2))
        # per tick
        self.base_claimed = False
        self.head_claimed = False
        self.action: str | None = None
        self.base_mode = "stop"
        self.gaze_source = "none"
        # navigation
        self.nav_goal: tuple[float, float] | None = None
        self._stopped = False

    # -- tick bookkeeping -----------------------------------------------------------------------

    def begin_tick(
        self,
        now: float,
        pose: Pose2D,
        head: HeadState,
        sensor_stamp: float | None,
        people_xy: ArrayLike,
    ) -> None:
        """New tick: what the robot knows now; nothing claimed yet."""
        self.now, self.pose, self.head = now, pose, head
        self.sensor_stamp = sensor_stamp
        self.people_xy = np.asarray(people_xy, dtype=float).reshape(-1, 2)
        self.base_claimed = self.head_claimed = False
        self.action = None
        self.base_mode = "stop"

    def end_tick(self) -> None:
        """Stop the base if no leaf drove it this tick (and cancel a goal no leaf wants)."""
        if self.base_claimed:
            self._stopped = False
            return
        self.base_mode = "stop"
        if self.nav_goal is not None:
            self.robot.cancel()
            self.nav_goal = None
            self._stopped = True
        elif not self._stopped:
            self.robot.command(STOP)
            self._stopped = True

    def claim(self, action: str) -> None:
        """``action`` is the leaf acting this tick (for the log)."""
        self.action = action

    # -- base -----------------------------------------------------------------------------------

    def stop(self) -> None:
        """Stop the base (and drop any navigation goal)."""
        self.base_claimed = True
        self.base_mode = "stop"
        if self.nav_goal is not None:
            self.robot.cancel()
            self.nav_goal = None
        self.robot.command(STOP)

    def turn(self, wz: float) -> None:
        """Turn in place at ``wz`` rad/s."""
        self._drive(Twist2D(0.0, 0.0, wz), "turn")

    def _drive(self, twist: Twist2D, mode: str) -> None:
        self.base_claimed = True
        self.base_mode = mode
        self.nav_goal = None  # a direct command preempts navigation (Robot.command)
        self.robot.command(twist)

    def follow(self, target_xy: tuple[float, float], distance: float | None = None) -> str:
        """One step of following the target (§II-E base control); returns the mode."""
        controller = self.base
        if distance is not None and distance != self.control.following_distance:
            if distance not in self._controllers:
                self._controllers[distance] = BaseController(_with_distance(self.control, distance))
            controller = self._controllers[distance]
        blocked = self.grid.logodds >= _OCCUPIED_LOGODDS
        cmd = controller.follow(
            self.pose,
            target_xy,
            blocked=blocked,
            geometry=self.grid.geometry,
            now=self.now,
            sensor_stamp=self.sensor_stamp,
            people_xy=self.people_xy,
        )
        if cmd.mode == "move_base" and cmd.goal is not None:
            status = self.go_to((cmd.goal.x, cmd.goal.y), tolerance=0.1, face=cmd.goal.theta)
            if status == "failed":
                self.stop()
                self.base_mode = "stop"
                return "stop"
            self.base_mode = "move_base"
            return "move_base"
        self._drive(cmd.twist or STOP, cmd.mode)
        return cmd.mode

    def free_goal(self, xy: ArrayLike) -> tuple[float, float] | None:
        """``xy`` moved to the nearest cell free for the robot (within :data:`GOAL_SNAP`)."""
        p = self.planner.nearest_free(np.asarray(xy, dtype=float), max_distance=GOAL_SNAP)
        return None if p is None else (float(p[0]), float(p[1]))

    def go_to(self, xy: tuple[float, float], tolerance: float, face: float | None = None) -> str:
        """MOVE_BASE toward ``xy`` (moved into free space): ``running``, ``arrived`` or
        ``failed`` (no free goal nearby, or the navigation aborted)."""
        self.base_claimed = True
        self.base_mode = "move_base"
        here = (self.pose.x, self.pose.y)
        if math.dist(here, xy) <= tolerance:
            return self._arrived()
        goal = self.free_goal(xy)
        if goal is None:
            return "failed"
        if math.dist(here, goal) <= tolerance:
            return self._arrived()
        theta = face if face is not None else math.atan2(goal[1] - here[1], goal[0] - here[0])
        resend = self.nav_goal is None or math.dist(self.nav_goal, goal) > RESEND_DISTANCE
        status = self.robot.nav_status()
        if not resend:
            if status is NavStatus.SUCCEEDED:
                return self._arrived()
            if status is NavStatus.ABORTED:
                self.nav_goal = None
                return "failed"
            if status in (NavStatus.PREEMPTED, NavStatus.IDLE):
                resend = True
        if resend:
            self.robot.navigate(Pose2D(goal[0], goal[1], theta))
            self.nav_goal = goal
            if self.robot.nav_status() is NavStatus.ABORTED:
                self.nav_goal = None
                return "failed"
        self._stopped = False
        return "running"

    def _arrived(self) -> str:
        if self.nav_goal is not None:
            self.robot.cancel()
            self.nav_goal = None
        self.base_mode = "hold"
        return "arrived"

    def release(self) -> None:
        """A leaf that drove the base stops doing so (it was preempted or finished)."""
        if self.nav_goal is not None:
            self.robot.cancel()
            self.nav_goal = None

    # -- head -----------------------------------------------------------------------------------

    def look_at(self, xy: tuple[float, float], source: str = "target") -> None:
        """Point the head at a person standing at ``xy`` (PD joint control toward the angles)."""
        desired = gaze_angles(self.pose, (xy[0], xy[1], self.control.look_height), self.control)
        self._head(self.gaze.update(self.head, desired, self.dt), source)

    def set_pan(self, pan: float, tilt: float = 0.0, source: str = "sweep") -> None:
        """Move the head to ``pan``/``tilt`` (a sweep)."""
        self._head(self.gaze.update(self.head, HeadTarget(pan, tilt), self.dt), source)

    def _head(self, command: HeadTarget, source: str) -> None:
        self.head_claimed = True
        self.gaze_source = source
        self.robot.point_head(command)

    def default_gaze(
        self,
        target_xy: tuple[float, float] | None,
        belief_peak: tuple[float, float, float] | None,
        legs_xy: Sequence[tuple[float, float]],
        known_xy: Sequence[tuple[float, float]] = (),
    ) -> None:
        """The paper's gaze priority when no leaf claimed the head: the target, else the
        highest human belief, else the nearest leg candidate not of a person in ``known_xy``
        (identified as not the target), else the navigation goal being driven to, else straight
        ahead (:func:`~pfctl.core.control.choose_gaze`)."""
        if self.head_claimed:
            return
        point, source = choose_gaze(
            target_xy,
            belief_peak,
            legs_xy,
            (self.pose.x, self.pose.y),
            known_xy=known_xy,
            ahead=self.nav_goal,
        )
        if point is None:
            self.set_pan(0.0, 0.0, source="none")
        else:
            self.look_at(point, source)

    # -- search ---------------------------------------------------------------------------------

    def next_waypoint(self, history: ArrayLike) -> WaypointDecision:
        """Algorithm 1 on the robot's occupancy grid for the target's ``history`` (t, x, y).
        With no history (the target was never seen) l* is None: the frontiers are scored by
        their size and distance alone (Eq. 3 without the d(c, l*) term). The frontier is chosen
        by ``search.waypoint_choice``."""
        s = self.search
        h = since_region_entered(np.asarray(history, dtype=float).reshape(-1, 3), self.regions)
        return waypoint_search(
            self.grid,
            self.regions,
            h,
            (self.pose.x, self.pose.y),
            s.alpha,
            s.beta,
            s.frontier_threshold,
            s.min_frontier_cells,
            s.heading_window_s,
            robot_region_fallback=False,
            choice=s.waypoint_choice,
        )


def since_region_entered(history: np.ndarray, regions: RegionMap) -> np.ndarray:
    """The trailing part of a ``(t, x, y)`` history spent in the region it ends in.

    Algorithm 1 scores a neighbour by how fast the path approached its door. A person who has
    just walked through a door into a room approached that door too, and would be "heading"
    back where they came from; counting only the samples since they entered the room keeps the
    door behind them out (they head for the room itself, or for a door they walk toward in it).
    """
    if len(history) == 0:
        return history
    last = regions.locate(history[-1, 1:3])
    inside = np.array([regions.locate(p) == last for p in history[:, 1:3]])
    start = len(history)
    while start > 0 and inside[start - 1]:
        start -= 1
    return history[start:]


def _with_distance(params: ControlParams, distance: float) -> ControlParams:
    from dataclasses import replace

    return replace(
        params, following_distance=distance, min_distance=min(params.min_distance, distance)
    )


__all__ = ["GOAL_SNAP", "RESEND_DISTANCE", "SearchParams", "Skills"]
