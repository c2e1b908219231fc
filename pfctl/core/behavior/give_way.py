"""Giving way to a person who waits for the robot (a doorway, a narrow hall).

A MOVE_BASE goal stops the base while a person stands on its path, and a person stops when the
robot is in theirs: in a doorway both wait, for good. Traced, the shipped house (issue 8's
randomized campaign, seeds 12 and 14): two people going out of the office stood in its door
from 27 s to the end of the episode, the robot waiting in front of them to go in, and the
target stood unseen behind the office's bookshelf. People resolve this by one of them stepping
aside; the robot does.

:class:`GiveWay` watches the robot drive to its goals (:meth:`GiveWay.check`, called by
:meth:`~pfctl.core.behavior.intents.Intents.go_to` each tick). When the robot has made no progress
(``PROGRESS`` m) for ``AFTER_S`` seconds with a person within ``NEAR`` m, it steps out of that
person's way — to the side first, off the line from them through the robot (the way they want to go,
as far as the robot can tell), else back — along a straight line that is free on the static map, and
holds there until they have gone by (nobody within ``NEAR`` m of where it stood, ``SETTLE_S`` after
its step, and the way back ahead of it or to a side, where its laser sees) or ``FOR_S`` seconds have
passed since its last step; then it drives on to its goal. The step is ``SIDE_STEP`` m where that
takes it ``OUT_OF_WAY`` m off their ways, else ``STEP`` m: a robot at the HSR's 0.22 m/s drives each
metre of the step twice, there and back, in 9 s, and the person it gave way to has mostly gone by
long before. When a person stands in its way there (traced, the house, seed 14: its diagonal step
back was where he was going, and he waited), it steps aside again, a few times at most; a person
walking past it there, as the one it gave way to does, does not make it step again (traced, the
house, seed 7: the person it gave way to walked round it, 0.6 m off, and its second and third steps
took it 2 m back down the hall, 24 s from giving way to being where it gave way again). A person
waiting in a door of the robot's room may be going to any other door of it, so the step keeps off
those ways too (traced, the house, seed 40: a person coming into the kitchen from the hall, on her
way to the living room's door, waited in the hall's door; the robot's step to the side was onto her
way, and she walked behind it, 0.6 m off, as it stepped twice more, 13 s in all).
The robot's MOVE_BASE keeps its own recovery (re-plan, abort); giving way adds the one thing it
cannot do, moving off the goal's path.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import ArrayLike

from pfctl.core.mapping.planning import GridPlanner
from pfctl.core.mapping.regions import RegionMap
from pfctl.core.mapping.walls import segment_distance
from pfctl.core.robot import wrap_angle

XY = tuple[float, float]
Segment = tuple[XY, XY]


@dataclass(frozen=True)
class Yielding:
    """Giving way since ``since`` (s), at the place ``to``: the ``steps``-th step aside in a
    row, the first from ``stood`` (where the robot stood while the person waited for it)."""

    since: float
    to: XY
    steps: int = 1
    stood: XY | None = None


class GiveWay:
    """When and where to give way (module docstring), across ticks."""

    #: No progress of this much, m, ...
    PROGRESS = 0.2
    #: ... for this long, s, with a person this near, m, gives way.
    AFTER_S = 3.0
    NEAR = 1.0
    #: The step out of the way, m; the place must be at least ``CLEAR`` m from every person.
    STEP = 1.0
    CLEAR = 0.8
    #: The shorter step to a side, m, taken where it ends this far off their ways, m: the
    #: robot's radius (the HSR's 0.215 m), a person's (0.25 m) and some room to pass.
    SIDE_STEP = 0.7
    OUT_OF_WAY = 0.6
    #: The robot drives back before ``FOR_S`` only where it sees: within this angle, rad, of
    #: its heading — ahead or to a side; a base laser's 270° leaves a blind sector behind it.
    AHEAD = math.radians(100.0)
    #: Giving way (the step and the wait there) lasts this long, s, from the last step.
    FOR_S = 5.0
    #: The robot is at its place this close to it, m; a person standing within ``CLEAR`` m this
    #: long after a step gets another, up to ``STEPS`` in a row.
    ARRIVED = 0.15
    SETTLE_S = 1.0
    STEPS = 3
    #: A person who moved less than this, m, over the last ``SETTLE_S`` is standing.
    STILL = 0.3
    #: A go-to not asked for this long, s, starts the progress clock afresh.
    GAP_S = 0.5
    #: A person this near (m) a door of the robot's room is coming through it.
    AT_DOOR = 1.0

    def __init__(self) -> None:
        self.yielding: Yielding | None = None
        """Giving way now (None: not)."""
        self._progress: tuple[float, XY] | None = None
        """When and where the robot last made progress toward a goal."""
        self._asked_at = -math.inf
        self._seen: deque[tuple[float, np.ndarray]] = deque()
        """The people's positions at each call of the last ``2 · SETTLE_S`` (:meth:`_standing`)."""

    def check(
        self,
        now: float,
        here: XY,
        people: ArrayLike,
        planner: GridPlanner,
        regions: RegionMap | None = None,
        heading: float | None = None,
    ) -> XY | None:
        """The place to give way at this tick (None: drive on to the goal): called on every
        tick the robot drives to a goal, at time ``now``, position ``here`` and ``heading``
        (rad; None: not known), with the other people's positions ``(n, 2)``, the static map's
        ``planner`` and the house's ``regions`` (their doors: :meth:`ways`; None: not known).
        A person standing within ``CLEAR`` m once the robot stands at its place (they came on
        its way, and wait) gets a step aside from there too, up to ``STEPS`` in all."""
        gap = now - self._asked_at > self.GAP_S
        self._asked_at = now
        pts = np.asarray(people, dtype=float).reshape(-1, 2)
        self._seen.append((now, pts))
        while self._seen[0][0] < now - 2 * self.SETTLE_S:
            self._seen.popleft()
        y = self.yielding
        if y is not None and not gap and self._gone_by(now, here, heading, y, pts):
            y = self.yielding = None
            self._progress = (now, here)
            return None
        if y is not None and not gap and now - y.since < self.FOR_S:
            there = math.dist(here, y.to) <= self.ARRIVED
            if there and y.steps < self.STEPS and now - y.since >= self.SETTLE_S:
                standing = pts[self._standing(now, pts)]
                again = self._step(
                    now, here, pts, planner, regions, self.CLEAR, y.steps + 1, standing
                )
                if again is not None:
                    return again
            return y.to
        if y is not None or gap:
            self.yielding = None
            self._progress = (now, here)
            return None
        p = self._progress
        if p is None or math.dist(here, p[1]) > self.PROGRESS:
            self._progress = p = (now, here)
        if now - p[0] < self.AFTER_S:
            return None
        return self._step(now, here, pts, planner, regions, self.NEAR, 1)

    def _step(
        self,
        now: float,
        here: XY,
        people: np.ndarray,
        planner: GridPlanner,
        regions: RegionMap | None,
        near: float,
        n: int,
        whom: np.ndarray | None = None,
    ) -> XY | None:
        """Give way to the nearest person within ``near`` m (the ``n``-th step) of ``whom``
        (default: everyone in ``people``): the place, clear of all ``people``."""
        whom = people if whom is None else whom
        if len(whom) == 0:
            return None
        d = np.hypot(whom[:, 0] - here[0], whom[:, 1] - here[1])
        k = int(np.argmin(d))
        if d[k] > near:
            return None
        person = (float(whom[k, 0]), float(whom[k, 1]))
        ways = () if regions is None else self.ways(here, person, regions)
        to = self.place(here, person, people, planner, ways)
        if to is None:
            return None
        stood = here if self.yielding is None else self.yielding.stood
        self.yielding = Yielding(now, to, n, stood)
        return to

    def _gone_by(
        self, now: float, here: XY, heading: float | None, y: Yielding, people: np.ndarray
    ) -> bool:
        """Whether the people it gave way to have gone by, ``SETTLE_S`` after its last step:
        nobody stands or walks within ``NEAR`` m of where it stood (they came through it), and
        the way back there lies within ``AHEAD`` of the robot's ``heading`` (rad; None: not
        known), where its laser sees who is on it."""
        if y.stood is None or now - y.since < self.SETTLE_S:
            return False
        if heading is not None and math.dist(here, y.stood) > self.ARRIVED:
            back = math.atan2(y.stood[1] - here[1], y.stood[0] - here[0])
            if abs(wrap_angle(back - heading)) > self.AHEAD:
                return False
        if len(people) == 0:
            return True
        d = np.hypot(people[:, 0] - y.stood[0], people[:, 1] - y.stood[1])
        return bool(d.min() > self.NEAR)

    def _standing(self, now: float, people: np.ndarray) -> np.ndarray:
        """Which of ``people`` ``(n, 2)`` stand (a boolean mask): someone was within ``STILL`` m
        of each one's place at the newest call at least ``SETTLE_S`` ago (a person walking has
        moved on from it). Without such a call, or with nobody seen then, not known: standing,
        as before this was asked."""
        past = [pts for t, pts in self._seen if t <= now - self.SETTLE_S + 1e-9]
        if not past or len(past[-1]) == 0:
            return np.ones(len(people), dtype=bool)
        then = past[-1]
        d = np.hypot(people[:, None, 0] - then[None, :, 0], people[:, None, 1] - then[None, :, 1])
        return d.min(axis=1) < self.STILL

    def ways(self, here: XY, person: XY, regions: RegionMap) -> list[Segment]:
        """Where ``person`` may be going through the robot's room: from the door of the room
        they stand at (within ``AT_DOOR`` m) to each other door of it; none when they stand at
        no door, or the robot is in no region."""
        room = regions.locate(here)
        if room is None:
            return []
        doors = regions.door_midpoints(room)
        if len(doors) < 2:
            return []
        d = [math.dist(person, m) for m in doors]
        k = int(np.argmin(d))
        if d[k] > self.AT_DOOR:
            return []
        return [(doors[k], m) for i, m in enumerate(doors) if i != k]

    def place(
        self,
        here: XY,
        person: XY,
        people: np.ndarray,
        planner: GridPlanner,
        ways: Sequence[Segment] = (),
    ) -> XY | None:
        """Where to step out of ``person``'s way: to either side, then diagonally back, then
        straight back (away from them), ``STEP`` m from ``here`` — or ``SIDE_STEP`` m to a side
        — reached in a straight line free on the static map, and ``CLEAR`` m from everyone.
        Of those, the nearest that is ``OUT_OF_WAY`` m off the line from them through the robot
        and off their other ``ways`` (:meth:`ways`), the farther off among equals; else the
        first place farthest off them. None when there is no such place."""
        u = np.array([here[0] - person[0], here[1] - person[1]])
        norm = float(np.linalg.norm(u))
        u = u / norm if norm > 1e-9 else np.array([1.0, 0.0])
        n = np.array([-u[1], u[0]])
        segs = np.array([(*a, *b) for a, b in ways], dtype=float).reshape(-1, 4)
        steps = [(self.SIDE_STEP, n), (self.SIDE_STEP, -n)] + [
            (self.STEP, d) for d in (n, -n, (u + n) / math.sqrt(2), (u - n) / math.sqrt(2), u)
        ]
        best: tuple[float, XY] | None = None
        out: tuple[float, float, XY] | None = None
        for length, direction in steps:
            to = np.asarray(here) + length * direction
            line = np.linspace(here, to, 21)
            if not planner.free_mask(line[1:]).all():
                continue
            if np.min(np.hypot(people[:, 0] - to[0], people[:, 1] - to[1])) < self.CLEAR:
                continue
            off = min(abs(float(np.dot(to - np.asarray(person), n))), segment_distance(to, segs))
            xy = (float(to[0]), float(to[1]))
            if best is None or off > best[0] + 1e-6:
                best = (off, xy)
            if off >= self.OUT_OF_WAY and (out is None or (length, -off) < out[:2]):
                out = (length, -off, xy)
        if out is not None:
            return out[2]
        return None if best is None else best[1]

    def hold(self, here: XY) -> XY:
        """The robot cannot get to the place (or its MOVE_BASE stopped short): give way where it
        is for the rest of the time; the place to be at."""
        if self.yielding is not None:
            self.yielding = replace(self.yielding, to=here)
        return here

    def done(self) -> None:
        """The goal was reached or given up: the next goal starts the clock afresh."""
        self.yielding = None
        self._progress = None
