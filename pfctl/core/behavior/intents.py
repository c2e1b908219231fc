"""What the behavior tree wants the robot to do this tick: the intents its leaves write (§II-E).

Leaves never command the robot. An :class:`Intents` object sits on the blackboard (key
``intents``); action leaves write into it what the base and the head should do, and the
follower's act stage (:meth:`pfctl.core.follower.Follower.act`) is the one place that turns the
tick's final intents into calls on the Robot port. What a leaf can ask for:

- the base: :meth:`Intents.follow` (TURN / GO_STRAIGHT / MOVE_BASE of
  :class:`~pfctl.core.control.BaseController`), :meth:`Intents.go_to` (MOVE_BASE to a goal moved
  into free space, sent again only when it moved; stepping aside for a person who waits for the
  robot, :mod:`~pfctl.core.behavior.give_way`), :meth:`Intents.turn` and
  :meth:`Intents.stop`; an action that drove the base gives it up with :meth:`Intents.release`;
- the head: :meth:`Intents.look_at` (a point) or :meth:`Intents.set_pan` (joint angles); a tick
  in which no leaf pointed the head gets the gaze rule's (:func:`~pfctl.core.control.gaze_rule`);
- the voice: :meth:`Intents.say`, on a robot that speaks (:attr:`Intents.can_speak`,
  :class:`~pfctl.core.robot.Speaker`).

A later write replaces an earlier one of the same tick (the last base intent is the one sent); a
write that needs no robot call (driving on to the goal under way, an arrival with no goal to
cancel) leaves the earlier one in place. Every head intent of the tick steps the head's PD
controller, in order; the last one is sent.

The MOVE_BASE bookkeeping lives here too (:class:`Navigation`): the goal the robot is driving
to, its status as the robot reported it when the tick began and as this tick's intents leave it
(a goal sent is ACTIVE, one cancelled or preempted by a velocity is PREEMPTED: the Robot port's
semantics), and whether a STOP was already sent. :meth:`Intents.end` applies the rule for a tick
in which no leaf drove the base: cancel the goal no leaf wants, else stop the base once.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from pfctl.core.behavior.give_way import GiveWay
from pfctl.core.behavior.world import WorldModel
from pfctl.core.control import BaseController, ControlParams
from pfctl.core.robot import STOP, NavStatus, Pose2D, Twist2D

#: A new MOVE_BASE goal is sent only when it moved farther than this from the one being driven to.
RESEND_DISTANCE = 0.4


# -- the base -------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Velocity:
    """Drive at ``twist`` (robot frame); a direct command preempts a MOVE_BASE goal
    (``Robot.command``)."""

    twist: Twist2D


@dataclass(frozen=True)
class Stop:
    """Stop the base (``Robot.command(STOP)``), first cancelling the MOVE_BASE goal under way
    when ``cancel_goal`` (``Robot.cancel``)."""

    cancel_goal: bool = False


@dataclass(frozen=True)
class Navigate:
    """Send a MOVE_BASE goal (``Robot.navigate``); a goal under way is preempted."""

    goal: Pose2D


@dataclass(frozen=True)
class CancelGoal:
    """Drop the MOVE_BASE goal under way (``Robot.cancel``; the base stops)."""


BaseIntent = Velocity | Stop | Navigate | CancelGoal
"""What the base should do this tick."""


# -- the head -------------------------------------------------------------------------------------


@dataclass(frozen=True)
class LookAt:
    """Point the camera at a person standing at ``xy`` (map frame); ``source`` says why (the
    log's gaze: ``target``, ``belief``, ``legs``, ``goal``)."""

    xy: tuple[float, float]
    source: str
    height: float | None = None
    """Aim at this height on them, m (None: the control's ``look_height``, the torso)."""


@dataclass(frozen=True)
class HeadAngles:
    """Move the head to ``pan``/``tilt`` (rad); ``source`` says why (``sweep``, ``none``)."""

    pan: float
    tilt: float
    source: str


HeadIntent = LookAt | HeadAngles
"""What the head should do this tick."""


# -- navigation bookkeeping -----------------------------------------------------------------------


@dataclass
class Navigation:
    """The MOVE_BASE goal across ticks, as the follower knows it."""

    goal: tuple[float, float] | None = None
    """The goal the robot was sent and is driving to (None: no goal under way)."""
    status: NavStatus = NavStatus.IDLE
    """The robot's status of its goal: as read when the tick began, then as this tick's intents
    leave it."""
    stopped: bool = False
    """A STOP was sent and nothing drove the base since (it is not sent again every tick)."""

    def sent(self, goal: tuple[float, float]) -> None:
        """A goal was sent: the robot accepts it (it lies in free space on the robot's map)."""
        self.goal = goal
        self.status = NavStatus.ACTIVE

    def dropped(self) -> None:
        """The goal was cancelled, or preempted by a velocity command."""
        self.goal = None
        if self.status in (NavStatus.ACTIVE, NavStatus.PENDING):
            self.status = NavStatus.PREEMPTED


class Intents:
    """The tick's intents and the abilities leaves write them with (module docstring)."""

    def __init__(
        self, control: ControlParams, world: WorldModel, navigation: Navigation | None = None
    ) -> None:
        self.control = control
        self.world = world
        self.navigation = navigation if navigation is not None else Navigation()
        """The MOVE_BASE bookkeeping; its status is the robot's, read when the tick began."""
        self.now = 0.0
        self.pose = Pose2D(0.0, 0.0)
        self.action: str | None = None
        """The action leaf acting this tick (for the log)."""
        self.base: BaseIntent | None = None
        """The base intent to send; None: no new command this tick."""
        self.base_claimed = False
        """A leaf drove the base this tick."""
        self.base_mode = "stop"
        """What the base does this tick, for the log (:data:`~pfctl.core.control.MODES`, or
        ``give_way``)."""
        self.head: list[HeadIntent] = []
        """The head intents of this tick, in the order they were written."""
        self._laws: dict[float, BaseController] = {}
        """The base control law for each following distance a leaf asked for."""
        self.give_way = GiveWay()
        """When the robot, driving to a goal, steps aside for a person waiting for it."""
        self.can_speak = False
        """The robot has a voice someone hears (:class:`~pfctl.core.robot.Speaker`); set by the
        follower each tick."""
        self.speech: str | None = None
        """What to say this tick (None: nothing)."""

    # -- tick bookkeeping -------------------------------------------------------------------------

    def begin(self, now: float, pose: Pose2D) -> None:
        """A new tick: the time and the robot's pose; nothing written yet."""
        self.now, self.pose = now, pose
        self.action = None
        self.base = None
        self.base_claimed = False
        self.base_mode = "stop"
        self.head = []
        self.speech = None

    def end(self) -> None:
        """After the tree: a tick in which no leaf drove the base cancels the goal no leaf wants,
        or else stops the base (once: not again while it stays stopped)."""
        nav = self.navigation
        if self.base_claimed:
            nav.stopped = False
            return
        self.base_mode = "stop"
        if nav.goal is not None:
            self._write(CancelGoal())
            nav.stopped = True
        elif not nav.stopped:
            self._write(Stop())
            nav.stopped = True

    def claim(self, action: str) -> None:
        """``action`` is the leaf acting this tick (for the log)."""
        self.action = action

    @property
    def gaze_source(self) -> str:
        """Why the head points where it does this tick (the last head intent's source)."""
        return self.head[-1].source if self.head else "none"

    def _write(self, intent: BaseIntent) -> None:
        """The base intent of the tick (it replaces an earlier one), and the goal it leaves."""
        self.base = intent
        if isinstance(intent, Navigate):
            self.navigation.sent((intent.goal.x, intent.goal.y))
        else:
            self.navigation.dropped()

    # -- base ---------------------------------------------------------------------------------

    def stop(self) -> None:
        """Stop the base (and drop any navigation goal)."""
        self.base_claimed = True
        self.base_mode = "stop"
        self._write(Stop(cancel_goal=self.navigation.goal is not None))

    def turn(self, wz: float) -> None:
        """Turn in place at ``wz`` rad/s."""
        self._drive(Twist2D(0.0, 0.0, wz), "turn")

    def _drive(self, twist: Twist2D, mode: str) -> None:
        self.base_claimed = True
        self.base_mode = mode
        self._write(Velocity(twist))

    def follow(self, target_xy: tuple[float, float], distance: float | None = None) -> str:
        """One step of following the target (§II-E base control); returns the mode."""
        law = self._law(distance)
        world = self.world
        cmd = law.follow(
            self.pose,
            target_xy,
            blocked=world.blocked(),
            geometry=world.grid.geometry,
            now=self.now,
            sensor_stamp=world.sensor_stamp,
            people_xy=world.people_xy,
        )
        if cmd.mode == "move_base" and cmd.goal is not None:
            status = self.go_to((cmd.goal.x, cmd.goal.y), tolerance=0.1, face=cmd.goal.theta)
            if status == "failed":
                self.stop()
                return "stop"
            self.base_mode = "move_base"
            return "move_base"
        self._drive(cmd.twist or STOP, cmd.mode)
        return cmd.mode

    def _law(self, distance: float | None) -> BaseController:
        """The base control law keeping ``distance`` (None: the mission's)."""
        key = self.control.following_distance if distance is None else distance
        if key not in self._laws:
            params = self.control
            if key != params.following_distance:
                params = replace(
                    params, following_distance=key, min_distance=min(params.min_distance, key)
                )
            self._laws[key] = BaseController(params)
        return self._laws[key]

    def go_to(self, xy: tuple[float, float], tolerance: float, face: float | None = None) -> str:
        """MOVE_BASE toward ``xy`` (moved into free space): ``running``, ``arrived`` or
        ``failed`` (no free goal nearby, or the robot aborted the navigation).

        The goal is sent when there is none under way, when it moved more than
        :data:`RESEND_DISTANCE` from the one under way, or when the robot no longer drives to
        that one (preempted, idle); otherwise the robot drives on and its status decides:
        SUCCEEDED is an arrival, ABORTED a failure."""
        self.base_claimed = True
        self.base_mode = "move_base"
        here = (self.pose.x, self.pose.y)
        if math.dist(here, xy) <= tolerance:
            return self._arrived()
        goal = self.world.free_goal(xy)
        if goal is None:
            self.give_way.done()
            return "failed"
        if math.dist(here, goal) <= tolerance:
            return self._arrived()
        world = self.world
        aside = self.give_way.check(
            self.now, here, world.people_xy, world.planner, world.regions, self.pose.theta
        )
        if aside is not None:
            return self._step_aside(aside)
        nav = self.navigation
        theta = face if face is not None else math.atan2(goal[1] - here[1], goal[0] - here[0])
        resend = nav.goal is None or math.dist(nav.goal, goal) > RESEND_DISTANCE
        if not resend:
            if nav.status is NavStatus.SUCCEEDED:
                return self._arrived()
            if nav.status is NavStatus.ABORTED:
                nav.goal = None
                self.give_way.done()
                return "failed"
            if nav.status in (NavStatus.PREEMPTED, NavStatus.IDLE):
                resend = True
        if resend:
            self._write(Navigate(Pose2D(goal[0], goal[1], theta)))
        nav.stopped = False
        return "running"

    def _arrived(self) -> str:
        if self.navigation.goal is not None:
            self._write(CancelGoal())
        self.base_mode = "hold"
        self.give_way.done()
        return "arrived"

    def _step_aside(self, aside: tuple[float, float]) -> str:
        """MOVE_BASE to ``aside`` out of a waiting person's way, keeping the heading, and hold
        there (:mod:`~pfctl.core.behavior.give_way`); the goal is still ``running``. Where the
        robot cannot get there, or its MOVE_BASE stops short, it holds where it is."""
        nav = self.navigation
        here = (self.pose.x, self.pose.y)
        self.base_mode = "give_way"
        sent = nav.goal is not None and math.dist(nav.goal, aside) <= 1e-6
        if sent and nav.status in (NavStatus.ABORTED, NavStatus.SUCCEEDED):
            nav.goal = None
            aside = self.give_way.hold(here)
        if math.dist(here, aside) <= GiveWay.ARRIVED:
            if nav.goal is not None:
                self._write(CancelGoal())
            return "running"
        if not sent or nav.status in (NavStatus.PREEMPTED, NavStatus.IDLE):
            self._write(Navigate(Pose2D(aside[0], aside[1], self.pose.theta)))
        return "running"

    def release(self) -> None:
        """A leaf that drove the base stops doing so (it was preempted or finished)."""
        if self.navigation.goal is not None:
            self._write(CancelGoal())

    # -- voice ----------------------------------------------------------------------------------

    def say(self, text: str) -> bool:
        """Say ``text`` this tick; False (nothing said) on a robot without a voice."""
        if not self.can_speak:
            return False
        self.speech = text
        return True

    # -- head -----------------------------------------------------------------------------------

    def look_at(
        self, xy: tuple[float, float], source: str = "target", height: float | None = None
    ) -> None:
        """Point the head at a person standing at ``xy`` (at ``height`` on them, m; None: the
        torso)."""
        self.head.append(LookAt((xy[0], xy[1]), source, height))

    def set_pan(self, pan: float, tilt: float = 0.0, source: str = "sweep") -> None:
        """Move the head to ``pan``/``tilt`` (a sweep)."""
        self.head.append(HeadAngles(pan, tilt, source))


__all__ = [
    "RESEND_DISTANCE",
    "BaseIntent",
    "CancelGoal",
    "HeadAngles",
    "HeadIntent",
    "Intents",
    "LookAt",
    "Navigate",
    "Navigation",
    "Stop",
    "Velocity",
]
