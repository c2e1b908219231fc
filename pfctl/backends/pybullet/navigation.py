"""A MOVE_BASE equivalent for an omnidirectional base: plan on the static map, follow, re-plan.

:class:`Navigator` plans with a :class:`~pfctl.core.mapping.planning.GridPlanner` (the static map
inflated by the robot's radius) — at once (:meth:`Navigator.start`), or, like move_base, in its
own control loop after the goal was accepted (:meth:`Navigator.accept`, then the next
:meth:`Navigator.update`) — and follows the path with a pure-pursuit controller for a
holonomic base: the command points at a carrot :data:`LOOKAHEAD` metres ahead on the path, at the
speed limit, slowing down near the goal, while the base turns toward its direction of travel (and
to the goal's heading at the end). Like move_base's local planner it never drives into what the
laser senses: :func:`keep_clear` removes the part of the command that would bring the base
closer than a margin to a sensed point (sliding along a wall, stopping short of a person; the
pure pursuit cuts the corners of a path, and people walk across it), nor to a person's point
sensed in the last :data:`RECENT_PEOPLE_S` seconds: the laser sees 270°, and a person who walked
round the robot into the blind sector behind it is still there (move_base's costmap, too, keeps
what the laser no longer sees). It re-plans when obstacle points (laser returns that are not
part of the static map) lie on the path ahead, or when the robot makes no progress for
:data:`STUCK_TIME` seconds, marking those points as obstacles; after :data:`MAX_REPLANS` re-plans
without success the goal is ABORTED. Like move_base's costmap, which clears what the laser no
longer shows, a marked point is forgotten once a beam of a scan passes beyond it with no return
near it (:meth:`Navigator.clear_seen`: the costmap's ray-trace clearing; a person who walked on
leaves no trail of marks behind), and in any case :data:`BLOCKER_MEMORY` seconds after the
laser last showed something there (a mark out of the laser's view); while the path goes round
marked points it is planned again every :data:`RECONSIDER_PERIOD` seconds and the new path taken
when it is :data:`RECONSIDER_GAIN` metres shorter — a person who stood in a door for a moment
does not send the robot round the house. Nor does a person crossing the path ahead: when the
way round the points that block it is more than :data:`DETOUR_EXTRA` metres longer than the path
through them (round a table, through another room), the robot first stands and waits up to
:data:`DETOUR_WAIT_S` seconds for them to pass (Nav2's *Wait* recovery; people walk on), and
takes the way round only if the path is still blocked — those seconds counted over goals, so
that following her (a new goal every few of her steps) never waits longer. A goal that lies
inside the marks (a person stands on or beside the place to look from) is planned to the
nearest point free of them within :data:`MARKED_GOAL_TOLERANCE`, as navfn's
``default_tolerance`` does for move_base, and the robot arrives there: the end of its path.
Pure numpy: no pybullet.
"""

from __future__ import annotations

import math

import numpy as np
from scipy import optimize
from scipy.spatial import cKDTree

from pfctl.core.mapping.planning import GridPlanner, NoPathError
from pfctl.core.robot import STOP, LaserScan, NavStatus, Pose2D, Twist2D

#: Pure-pursuit carrot distance along the path, metres.
LOOKAHEAD = 0.5
#: How far ahead on the path (m) obstacle points are looked for.
CHECK_AHEAD = 1.5
#: Obstacle points closer than this to a static obstacle are the static map itself, metres.
STATIC_MARGIN = 0.15
#: No progress of at least PROGRESS metres for this long triggers a re-plan, seconds.
STUCK_TIME = 4.0
PROGRESS = 0.1
#: Radius (m) of the disc each blocking point becomes in the re-planning map (a little more than
#: PERSON_MARGIN, so a path around a person is one :func:`keep_clear` lets the base drive).
BLOCKER_RADIUS = 0.25
#: Re-plans allowed per goal before ABORTED.
MAX_REPLANS = 5
#: Wait (s) after a failed re-plan before trying again (a person may walk away).
RETRY_WAIT = 1.0
#: Least time (s) between two re-plans; meanwhile a blocked robot stands still.
REPLAN_PERIOD = 1.0
#: Progress (m) after which the re-plan count starts again (a long trip may meet many people).
REPLAN_RESET = 1.5
#: A marked obstacle point is forgotten this long (s) after the laser last showed a point within
#: BLOCKER_RADIUS of it (people move on; move_base's costmap clears them too).
BLOCKER_MEMORY = 4.0
#: While the path goes round marked points, it is planned again this often (s) …
RECONSIDER_PERIOD = 2.0
#: … and the new path is taken when it is at least this much shorter than the rest (m).
RECONSIDER_GAIN = 1.0
#: A way round blocking points this much longer (m) than the path through them ...
DETOUR_EXTRA = 2.0
#: ... is taken only after the path has stayed blocked this long (s), the robot waiting.
DETOUR_WAIT_S = 3.0
#: A blockage is over once the path ahead has been clear this long (s): the next one may be
#: waited on again.
BLOCKAGE_OVER_S = 1.0
#: A goal inside the marked points is planned to the nearest point free of them within this,
#: metres (navfn's ``default_tolerance``); farther, the re-plan fails as before.
MARKED_GOAL_TOLERANCE = 0.6
#: The local safety layer (:func:`keep_clear`): no velocity toward a sensed point of the static
#: map (a wall, furniture) within the robot's radius plus this, metres …
WALL_MARGIN = 0.06
#: … nor toward any other sensed point (a person's leg) within the radius plus this, metres, …
PERSON_MARGIN = 0.2
#: … sensed in the last this many seconds (a person behind the robot, out of the laser's view).
RECENT_PEOPLE_S = 1.5


def _wrap(a: float) -> float:
    return (a + math.pi) % (2 * math.pi) - math.pi


class Navigator:
    """Plan-and-follow navigation to one goal at a time (``actionlib`` status semantics)."""

    def __init__(
        self,
        planner: GridPlanner,
        max_linear_speed: float,
        max_angular_speed: float,
        goal_tolerance: float = 0.15,
        yaw_tolerance: float = 0.2,
    ) -> None:
        self.planner = planner
        self.max_linear_speed = float(max_linear_speed)
        self.max_angular_speed = float(max_angular_speed)
        self.goal_tolerance = float(goal_tolerance)
        self.yaw_tolerance = float(yaw_tolerance)
        self._status = NavStatus.IDLE
        self.goal: Pose2D | None = None
        self.path: np.ndarray | None = None
        self.replans = 0
        """Re-plans since the last REPLAN_RESET metres of progress (bounded by MAX_REPLANS)."""
        self.total_replans = 0
        """Re-plans for the current goal in all."""
        self.reason = ""
        self._best = math.inf
        self._since_progress = 0.0
        self._wait = 0.0
        self._waited = 0.0
        """Seconds stood waiting for the path to clear before a long way round, since it was
        last clear for BLOCKAGE_OVER_S (over goals: following her, MOVE_BASE gets a new goal
        every few steps she takes)."""
        self._clear_for = 0.0
        """Seconds since sensed points last blocked the path ahead."""
        self._waiting = False
        """The way round this blockage was weighed and found long: stand (up to
        DETOUR_WAIT_S) without weighing it again."""
        self._blockers = np.empty((0, 2))
        """Obstacle points marked by re-plans (map frame), planned round until forgotten."""
        self._blocker_seen = np.empty(0)
        """When the laser last showed each of ``_blockers`` (the goal's clock, s)."""
        self._clock = 0.0
        """Seconds of :meth:`update` since the goal was accepted."""
        self._since_reconsider = 0.0
        self._round_marks = False
        """The path was planned round marked points (so it is reconsidered as they go)."""
        self._since_replan = math.inf
        self._rest_at_replan = math.inf
        self._unplanned = False
        """A goal was accepted and is not planned yet (the next update plans it)."""
        self._uptime = 0.0
        """Seconds of active :meth:`update` over all goals (never reset)."""
        self._recent: list[tuple[float, np.ndarray, object]] = []
        """``(uptime, dynamic points, the obstacle points they came from)`` of the last
        RECENT_PEOPLE_S seconds, one entry per scan, for :func:`keep_clear`."""

    @property
    def status(self) -> NavStatus:
        return self._status

    @property
    def marks(self) -> np.ndarray:
        """The obstacle points marked by re-plans and not forgotten yet, ``(n, 2)`` (map
        frame)."""
        return self._blockers.copy()

    def accept(self, goal: Pose2D) -> None:
        """Take a new goal without planning yet (a running one is PREEMPTED), as move_base
        accepts a goal and leaves the planning to its own loop: ACTIVE, and the path is planned
        by the next :meth:`update`; ABORTED at once if the goal itself is not free (a cheap
        look-up, no search)."""
        if self._status in (NavStatus.ACTIVE, NavStatus.PENDING):
            self._status = NavStatus.PREEMPTED
        self.goal = goal
        self.path = None
        self.replans = 0
        self.total_replans = 0
        self.reason = ""
        self._forget_blockers()
        self._clock = 0.0
        self._since_reconsider = 0.0
        self._round_marks = False
        self._since_replan = math.inf
        self._rest_at_replan = math.inf
        self._unplanned = False
        if not self.planner.is_free((goal.x, goal.y)):
            self.reason = f"goal ({goal.x:.2f}, {goal.y:.2f}) is inside an obstacle or off the map"
            self._status = NavStatus.ABORTED
            return
        self._unplanned = True
        self._status = NavStatus.ACTIVE

    def start(self, goal: Pose2D, pose: Pose2D) -> None:
        """Accept a new goal (a running one is PREEMPTED) and plan from ``pose`` now; ABORTED at
        once if there is no path."""
        self.accept(goal)
        if self._unplanned:
            self._plan(pose)

    def _plan(self, pose: Pose2D) -> None:
        """The first plan for the accepted goal; ABORTED if there is no path."""
        assert self.goal is not None
        self._unplanned = False
        try:
            self.path = self.planner.plan((pose.x, pose.y), (self.goal.x, self.goal.y))
        except NoPathError as err:
            self.path = None
            self.reason = str(err)
            self._status = NavStatus.ABORTED
            return
        self._reset_progress()

    def cancel(self) -> None:
        """Drop the goal: PREEMPTED if it was running."""
        if self._status in (NavStatus.ACTIVE, NavStatus.PENDING):
            self._status = NavStatus.PREEMPTED
        self.path = None
        self._unplanned = False

    def _forget_blockers(self) -> None:
        self._blockers = np.empty((0, 2))
        self._blocker_seen = np.empty(0)

    def _mark(self, points: np.ndarray) -> None:
        """Mark ``points`` as obstacles, seen now (the newest 400 marks are kept)."""
        self._blockers = np.vstack([self._blockers, points])[-400:]
        stamps = np.full(len(points), self._clock)
        self._blocker_seen = np.concatenate([self._blocker_seen, stamps])[-400:]

    def _refresh_blockers(self, dynamic: np.ndarray) -> None:
        """Marks with a sensed point within BLOCKER_RADIUS are seen now; marks not seen for
        BLOCKER_MEMORY seconds are forgotten."""
        if not len(self._blockers):
            return
        if len(dynamic):
            d, _ = cKDTree(dynamic).query(self._blockers, distance_upper_bound=BLOCKER_RADIUS)
            self._blocker_seen[np.isfinite(d)] = self._clock
        keep = self._clock - self._blocker_seen <= BLOCKER_MEMORY
        self._blockers, self._blocker_seen = self._blockers[keep], self._blocker_seen[keep]

    def clear_seen(self, scan: LaserScan) -> None:
        """Forget the marks ``scan`` sees free: a beam toward the mark returns from farther
        than BLOCKER_RADIUS beyond it (or not at all), and no return lies within BLOCKER_RADIUS
        of it (move_base's costmap ray-trace clearing; ``scan.pose`` in the map frame of the
        marks)."""
        if not len(self._blockers):
            return
        o = scan.pose
        rel = self._blockers - np.array([o.x, o.y])
        dist = np.hypot(rel[:, 0], rel[:, 1])
        bearing = (np.arctan2(rel[:, 1], rel[:, 0]) - o.theta + np.pi) % (2 * np.pi) - np.pi
        beam = np.rint((bearing - scan.angle_min) / scan.angle_increment).astype(int)
        inside = (beam >= 0) & (beam < len(scan.ranges)) & (dist < scan.range_max)
        ranges = np.asarray(scan.ranges, dtype=float)
        reach = np.where(np.isfinite(ranges), ranges, scan.range_max)
        beyond = np.zeros(len(dist), dtype=bool)
        beyond[inside] = reach[beam[inside]] > dist[inside] + BLOCKER_RADIUS
        if not beyond.any():
            return
        points = scan.points()
        if len(points):
            near, _ = cKDTree(points).query(self._blockers[beyond], k=1)
            beyond[np.flatnonzero(beyond)[near <= BLOCKER_RADIUS]] = False
        self._blockers, self._blocker_seen = self._blockers[~beyond], self._blocker_seen[~beyond]

    def _planner_now(self) -> GridPlanner:
        """The static map with the marked points as discs of BLOCKER_RADIUS."""
        if not len(self._blockers):
            return self.planner
        return self.planner.with_obstacles(self._blockers, BLOCKER_RADIUS)

    def _plan_round_marks(self, pose: Pose2D, extra: np.ndarray | None = None) -> np.ndarray:
        """A path from ``pose`` on :meth:`_planner_now`'s map (with the points ``extra`` marked
        too): to the goal, or, when the goal is inside the marks, to the nearest point free of
        them within MARKED_GOAL_TOLERANCE. Raises :class:`NoPathError` as
        :meth:`GridPlanner.plan` does."""
        assert self.goal is not None
        if extra is not None and len(extra):
            marks = np.vstack([self._blockers, extra])
            planner = self.planner.with_obstacles(marks, BLOCKER_RADIUS)
        else:
            planner = self._planner_now()
        goal = np.array([self.goal.x, self.goal.y])
        if planner is not self.planner and not planner.is_free(goal):
            near = planner.nearest_free(goal, MARKED_GOAL_TOLERANCE)
            if near is not None:
                goal = near
        return planner.plan((pose.x, pose.y), goal)

    def _reconsider(self, pose: Pose2D, rest: float) -> None:
        """Plan again round the marks still remembered; take the path if it is RECONSIDER_GAIN
        shorter than the ``rest`` of the current one (not a re-plan: nothing blocked). With no
        mark left the current path is kept unless the plain map's is that much shorter, and is
        not reconsidered again."""
        assert self.goal is not None
        self._since_reconsider = 0.0
        marked = len(self._blockers) > 0
        try:
            path = self._plan_round_marks(pose)
        except NoPathError:
            return
        if not marked:
            self._round_marks = False
        if float(np.linalg.norm(np.diff(path, axis=0), axis=1).sum()) < rest - RECONSIDER_GAIN:
            self.path = path
            self._round_marks = marked
            self._best = math.inf
            self._since_progress = 0.0
            self._rest_at_replan = self._remaining(np.array([pose.x, pose.y]))[0]

    def _reset_progress(self) -> None:
        self._best = math.inf
        self._since_progress = 0.0
        self._wait = 0.0

    def _wait_for(self, pose: Pose2D, blockers: np.ndarray, rest: float, dt: float) -> bool:
        """Whether to stand and wait for ``blockers`` to leave the path (``rest`` m to go)
        rather than plan round them now: while the robot has stood less than DETOUR_WAIT_S in
        all for this blockage (the path not clear for BLOCKAGE_OVER_S since, whatever the goals),
        and the way round them (and the marks) is more than DETOUR_EXTRA longer, or there is
        none."""
        if self._waited >= DETOUR_WAIT_S:
            return False
        if not self._waiting:
            try:
                way = self._plan_round_marks(pose, blockers)
                longer = float(np.linalg.norm(np.diff(way, axis=0), axis=1).sum()) - rest
            except NoPathError:
                longer = math.inf
            if longer <= DETOUR_EXTRA:
                return False  # a short way round: take it now (the next blocking is weighed anew)
        self._waiting = True
        self._waited += dt
        return True

    # ----------------------------------------------------------------------------------------

    def _dynamic(self, points: np.ndarray | None) -> np.ndarray:
        """The obstacle points that are not the static map (walls, furniture)."""
        if points is None or len(points) == 0:
            return np.empty((0, 2))
        pts = np.asarray(points, dtype=float).reshape(-1, 2)
        static_clear = self.planner.clearance_at(pts)
        return pts[static_clear > STATIC_MARGIN]

    def _static(self, points: np.ndarray | None) -> np.ndarray:
        """The sensed points that are the static map (walls, furniture)."""
        if points is None or len(points) == 0:
            return np.empty((0, 2))
        pts = np.asarray(points, dtype=float).reshape(-1, 2)
        return pts[self.planner.clearance_at(pts) <= STATIC_MARGIN]

    def _map_near(self, xy: np.ndarray) -> np.ndarray:
        """Centres of the static map's obstacle cells within reach of :func:`keep_clear`'s wall
        margin: the laser does not see everything that touches the base (a door jamb beside it,
        closer than the laser's minimum range or outside its field of view), the map does."""
        planner = self.planner
        geo = planner.geometry
        reach = planner.robot_radius + WALL_MARGIN + geo.resolution
        k = math.ceil(reach / geo.resolution)
        r0, c0 = (int(v) for v in geo.world_to_cell(xy))
        rs = slice(max(r0 - k, 0), max(min(r0 + k + 1, geo.height), 0))
        cs = slice(max(c0 - k, 0), max(min(c0 + k + 1, geo.width), 0))
        rr, cc = np.nonzero(planner.obstacle[rs, cs])
        if not len(rr):
            return np.empty((0, 2))
        return geo.cell_to_world(rr + rs.start, cc + cs.start)

    def _recent_people(self, dynamic: np.ndarray, source: object, dt: float) -> np.ndarray:
        """The dynamic points sensed in the last RECENT_PEOPLE_S seconds, ``dynamic`` (from the
        obstacle points ``source``) among them: a new entry per new scan."""
        self._uptime += dt
        self._recent = [r for r in self._recent if self._uptime - r[0] <= RECENT_PEOPLE_S]
        if not self._recent or self._recent[-1][2] is not source:
            self._recent.append((self._uptime, dynamic, source))
        return np.vstack([r[1] for r in self._recent])

    def _remaining(self, xy: np.ndarray) -> tuple[float, int, np.ndarray]:
        """Distance left along the path, the index of the nearest segment, the projection."""
        assert self.path is not None
        a, b = self.path[:-1], self.path[1:]
        if len(a) == 0:
            return float(np.linalg.norm(self.path[0] - xy)), 0, self.path[0]
        d = b - a
        L2 = np.maximum((d**2).sum(axis=1), 1e-12)
        t = np.clip(((xy - a) * d).sum(axis=1) / L2, 0.0, 1.0)
        proj = a + d * t[:, None]
        i = int(np.argmin(np.linalg.norm(proj - xy, axis=1)))
        seg_len = np.sqrt(L2)
        rest = float(seg_len[i] * (1 - t[i]) + seg_len[i + 1 :].sum())
        return rest, i, proj[i]

    def _ahead(self, i: int, proj: np.ndarray, distance: float) -> np.ndarray:
        """Points of the path from ``proj`` (on segment ``i``) up to ``distance`` metres on."""
        assert self.path is not None
        pts = [proj]
        left = distance
        cur = proj
        for k in range(i + 1, len(self.path)):
            seg = self.path[k] - cur
            n = float(np.linalg.norm(seg))
            if n >= left:
                pts.append(cur + seg * (left / max(n, 1e-12)))
                return np.array(pts)
            pts.append(self.path[k])
            left -= n
            cur = self.path[k]
        return np.array(pts)

    def _blocked(self, ahead: np.ndarray, dynamic: np.ndarray) -> np.ndarray:
        """The dynamic points within the robot's radius (+ margin) of the path ahead."""
        if len(dynamic) == 0 or len(ahead) < 2:
            return np.empty((0, 2))
        a, b = ahead[:-1], ahead[1:]
        d = b - a
        L2 = np.maximum((d**2).sum(axis=1), 1e-12)
        rel = dynamic[:, None, :] - a[None]
        t = np.clip((rel * d[None]).sum(axis=2) / L2[None], 0.0, 1.0)
        dist = np.linalg.norm(rel - d[None] * t[..., None], axis=2).min(axis=1)
        return dynamic[dist < self.planner.robot_radius + 0.05]

    def _replan(self, pose: Pose2D, blockers: np.ndarray) -> None:
        """Plan again with ``blockers`` as extra obstacles; ABORTED after MAX_REPLANS."""
        assert self.goal is not None
        self.replans += 1
        self.total_replans += 1
        if self.replans > MAX_REPLANS:
            self._status = NavStatus.ABORTED
            self.reason = f"no way through after {MAX_REPLANS} re-plans"
            return
        if len(blockers):
            self._mark(blockers)
        self._since_reconsider = 0.0
        try:
            self.path = self._plan_round_marks(pose)
            self._round_marks = len(self._blockers) > 0
        except NoPathError as err:
            self.reason = str(err)
            self._forget_blockers()  # the blocker may move on: try the plain map next
            self._wait = RETRY_WAIT
        self._since_progress = 0.0
        self._since_replan = 0.0
        if self.path is not None:
            self._rest_at_replan = self._remaining(np.array([pose.x, pose.y]))[0]

    def update(self, pose: Pose2D, dt: float, obstacle_points: np.ndarray | None = None) -> Twist2D:
        """The robot-frame command for this control period (STOP unless ACTIVE).

        A goal taken by :meth:`accept` is planned here first (from ``pose``).
        ``obstacle_points`` are map-frame points the robot currently senses (e.g.
        ``LaserScan.points()``); those away from the static map that lie on the path ahead
        trigger a re-plan around them.
        """
        if self._unplanned and self._status is NavStatus.ACTIVE:
            self._plan(pose)
        if self._status is not NavStatus.ACTIVE or self.goal is None or self.path is None:
            return STOP
        if self._wait > 0:
            self._wait -= dt
            if self._wait <= 0:
                self._replan(pose, np.empty((0, 2)))
            return STOP
        xy = np.array([pose.x, pose.y])
        goal_xy = self.path[-1]  # the goal, or the point planned to beside a marked one
        to_goal = float(np.linalg.norm(goal_xy - xy))
        if to_goal <= self.goal_tolerance:
            yaw_err = _wrap(self.goal.theta - pose.theta)
            if abs(yaw_err) <= self.yaw_tolerance:
                self._status = NavStatus.SUCCEEDED
                self.path = None
                return STOP
            wz = float(np.clip(1.5 * yaw_err, -self.max_angular_speed, self.max_angular_speed))
            return Twist2D(0.0, 0.0, wz)
        dynamic = self._dynamic(obstacle_points)
        self._clock += dt
        people = self._recent_people(dynamic, obstacle_points, dt)
        self._since_reconsider += dt
        self._refresh_blockers(dynamic)
        rest, i, proj = self._remaining(xy)
        if self._round_marks and self._since_reconsider >= RECONSIDER_PERIOD:
            self._reconsider(pose, rest)
            rest, i, proj = self._remaining(xy)
        self._since_replan += dt
        if rest < self._rest_at_replan - REPLAN_RESET:
            self.replans = 0
            self._rest_at_replan = rest
        # progress watchdog
        if rest < self._best - PROGRESS:
            self._best = rest
            self._since_progress = 0.0
        else:
            self._since_progress += dt
        blockers = self._blocked(self._ahead(i, proj, CHECK_AHEAD), dynamic)
        self._clear_for = 0.0 if len(blockers) else self._clear_for + dt
        if self._clear_for >= BLOCKAGE_OVER_S:
            self._waited, self._waiting = 0.0, False
        if len(blockers) and self._since_replan < REPLAN_PERIOD:
            return STOP  # just re-planned and still blocked: wait for the next re-plan
        if len(blockers) and self._wait_for(pose, blockers, rest, dt):
            return STOP
        if len(blockers) or self._since_progress > STUCK_TIME:
            if not len(blockers) and len(dynamic):
                blockers = dynamic[np.linalg.norm(dynamic - xy, axis=1) < 1.0]
            self._replan(pose, blockers)
            self._best = math.inf
            if self._status is not NavStatus.ACTIVE or self._wait > 0:
                return STOP
            rest, i, proj = self._remaining(xy)
        carrot = self._ahead(i, proj, LOOKAHEAD)[-1]
        direction = carrot - xy
        n = float(np.linalg.norm(direction))
        if n < 1e-9:
            direction, n = goal_xy - xy, to_goal
        speed = min(self.max_linear_speed, 0.8 * rest + 0.03)
        heading = math.atan2(direction[1], direction[0])
        # turn toward the travel direction (or the goal heading at the end); slow down while
        # the heading error is large so the base does not swing wide
        target_yaw = self.goal.theta if rest < 0.4 else heading
        yaw_err = _wrap(target_yaw - pose.theta)
        wz = float(np.clip(1.5 * yaw_err, -self.max_angular_speed, self.max_angular_speed))
        v_map = keep_clear(
            speed * direction / n,
            xy,
            people,
            np.vstack([self._static(obstacle_points), self._map_near(xy)]),
            self.planner.robot_radius,
        )
        vx_map, vy_map = float(v_map[0]), float(v_map[1])
        c, s = math.cos(pose.theta), math.sin(pose.theta)
        return Twist2D(c * vx_map + s * vy_map, -s * vx_map + c * vy_map, wz)


def keep_clear(
    v: np.ndarray,
    xy: np.ndarray,
    people: np.ndarray,
    walls: np.ndarray,
    radius: float = 0.215,
) -> np.ndarray:
    """The map-frame velocity ``v`` without its components toward sensed points too close.

    Every point of ``walls`` within ``radius + WALL_MARGIN`` and of ``people`` within
    ``radius + PERSON_MARGIN`` of ``xy`` gives a constraint ``v · n ≤ 0`` (``n`` the unit vector
    toward it): the result is the velocity nearest ``v`` that approaches none of them — the
    projection onto that cone, ``v − Nᵀλ`` with ``λ ≥ 0`` from non-negative least squares on the
    polar cone (Moreau's decomposition). Sliding along a wall or past a door jamb is kept; in a
    corner that surrounds the base the result is zero.
    """
    v0 = np.asarray(v, dtype=float)
    normals = []
    for pts, reach in (
        (np.asarray(walls, float).reshape(-1, 2), radius + WALL_MARGIN),
        (np.asarray(people, float).reshape(-1, 2), radius + PERSON_MARGIN),
    ):
        if len(pts):
            rel = pts - xy
            d = np.linalg.norm(rel, axis=1)
            close = (d < reach) & (d > 1e-9)
            normals.append(rel[close] / d[close, None])
    n = np.vstack(normals) if normals else np.empty((0, 2))
    if not len(n) or (n @ v0).max() <= 0.0:
        return v0.copy()
    lam, _ = optimize.nnls(n.T, v0)
    out = v0 - n.T @ lam
    return np.where(np.abs(out) < 1e-12, 0.0, out)


__all__ = ["Navigator", "keep_clear"]
