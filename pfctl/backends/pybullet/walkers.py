"""Kinematic people for the simulated house: routes through doors, gait, pauses (no pybullet).

Each :class:`Walker` starts at the first stop of its route (``scenario.people[*].route``: a region
name becomes a free point of that region, an ``[x, y]`` point stays as it is) and walks the legs
between stops along paths planned on the static map for a person-sized disc, so people go through
doors and around furniture. Speed ramps up and down smoothly (bounded acceleration, braking
before a stop); at each intermediate stop the person pauses for about ``pause_s``. After the last
stop a person stays there, or walks back to the first stop and starts again when ``loop``. A
person whose way the robot stands in waits, and after :data:`STEP_ROUND_AFTER` seconds steps round
it when there is room (a path no more than :data:`STEP_ROUND_DETOUR` metres longer), as people
do: nobody stands in a hall for a minute waiting for a robot to move. A person whose next stop
the robot stands on (within the distance they keep from it) stops short of it, as if there, and
goes on with the route. A person standing within earshot of the robot when it speaks (the
robot asks someone who shows it their back to look at it) turns to face it after
:data:`REACTION_S`, looks at it for :data:`ATTEND_S`, and turns back (:class:`Earshot`,
:meth:`Walker.hear`); a person walking walks on.

The two legs are what a laser sees (the paper detects people by their legs, §II-E): cylinders of
:data:`LEG_RADIUS` beside the body centre, swinging forward and back in opposite phase with a
stride that grows with speed, and standing side by side when the person is still.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import shapely

from pfctl.backends.pybullet.config import Clothes, PersonConfig, ScenarioConfig
from pfctl.core.mapping.house import HouseLayout
from pfctl.core.mapping.planning import GridPlanner, NoPathError
from pfctl.core.robot import PersonTruth

#: A person's footprint for planning, metres.
PERSON_RADIUS = 0.25
#: Radius of each leg cylinder, metres.
LEG_RADIUS = 0.06
#: Lateral distance between the legs' centres (hip width), metres.
HIP_WIDTH = 0.2
#: Walking acceleration and braking, m/s².
ACCELERATION = 0.6
#: Fastest turn of the body, rad/s.
TURN_RATE = 3.0
#: A person's walking speed limits (``scenario.people[*].speed``), m/s.
MIN_SPEED, MAX_SPEED = 0.3, 1.4
#: A person the robot has kept waiting this long (s) looks for a way round it …
STEP_ROUND_AFTER = 2.0
#: … and takes one at most this much longer (m) than the rest of the way it was walking.
STEP_ROUND_DETOUR = 4.0
#: A person this near (m) the next stop is there, though the robot keeps them from the last step.
AT_STOP = 0.1
#: A person within this distance (m) of the robot, with no wall between, hears it speak …
HEARING_RANGE = 4.0
#: … and, standing, turns to face it after this long (s) …
REACTION_S = 0.8
#: … looks at it this long (s), and turns back to the way they faced.
ATTEND_S = 6.0
#: A door lets the voice through within this distance (m) of its opening.
DOOR_SLACK = 0.15
#: The first word of the seeds of ``scenario.randomize``'s random streams.
RANDOMIZE = 7919


@dataclass(frozen=True)
class WalkerState:
    """A person at one instant: pose, speed, looks and leg positions (map frame)."""

    name: str
    x: float
    y: float
    theta: float
    speed: float
    is_target: bool
    height: float
    clothes: Clothes
    legs: np.ndarray
    """Rows ``[x, y, radius]`` of the two legs."""
    paused: bool = False


def _region_point(
    planner: GridPlanner,
    polygon: tuple[tuple[float, float], ...],
    rng: np.random.Generator | None = None,
) -> np.ndarray:
    """A free point of the region: with ``rng``, a random free cell at least 0.3 m from
    obstacles (so people sent to the same room spread out); without, the centroid if free, else
    the free cell nearest to it.
    """
    poly = shapely.Polygon(polygon)
    centre = np.array(poly.centroid.coords[0])
    if rng is not None:
        rows, cols = np.nonzero(planner.free & (planner.clearance >= PERSON_RADIUS + 0.3))
        cells = planner.geometry.cell_to_world(rows, cols)
        cand = cells[shapely.contains_xy(poly, cells[:, 0], cells[:, 1])]
        if len(cand):
            return cand[int(rng.integers(len(cand)))]
    if planner.is_free(centre) and poly.contains(shapely.Point(centre)):
        return centre
    rows, cols = np.nonzero(planner.free)
    cells = planner.geometry.cell_to_world(rows, cols)
    inside = shapely.contains_xy(poly, cells[:, 0], cells[:, 1])
    if not inside.any():
        raise NoPathError("a region has no free point for a person")
    cand = cells[inside]
    return cand[int(np.argmin(np.linalg.norm(cand - centre, axis=1)))]


class Walker:
    """One simulated person walking a planned polyline; advance it with :meth:`step`."""

    def __init__(
        self,
        name: str,
        stops: list[np.ndarray],
        planner: GridPlanner,
        *,
        speed: float,
        clothes: Clothes,
        height: float = 1.7,
        pause_s: float = 2.0,
        loop: bool = False,
        is_target: bool = False,
        seed: int = 0,
    ) -> None:
        self.name = name
        self.clothes = clothes
        self.height = float(height)
        self.is_target = is_target
        self.cruise = float(speed)
        self.pause_s = float(pause_s)
        self.loop = loop
        self._rng = np.random.default_rng(seed)
        self.stops = [np.asarray(s, dtype=float) for s in stops]
        legs = []
        pairs = list(zip(self.stops[:-1], self.stops[1:], strict=True))
        if loop and len(self.stops) > 1:
            pairs.append((self.stops[-1], self.stops[0]))
        for a, b in pairs:
            legs.append(planner.plan(a, b))
        self._legs_paths = legs
        self._planner = planner
        self._waited = 0.0
        """Seconds the robot has kept this person from the next step (:meth:`_step_round`)."""
        self._leg_index = 0
        self._path = legs[0] if legs else self.stops[0][None]
        self._s = 0.0  # distance walked along the current path
        self._cum = self._cumulative(self._path)
        self.x, self.y = (float(v) for v in self.stops[0])
        self.theta = self._initial_heading()
        self.speed = 0.0
        self.phase = 0.0
        self._pause_left = 0.0
        self.done = not legs
        self._attend: tuple[float, float, float, float] | None = None
        """Turned to the robot's voice: where it spoke, the time left (reaction, then looking
        at it), and the heading to turn back to (:meth:`hear`)."""

    @staticmethod
    def _cumulative(path: np.ndarray) -> np.ndarray:
        return np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(path, axis=0), axis=1))])

    def _initial_heading(self) -> float:
        if len(self._path) > 1:
            d = self._path[1] - self._path[0]
            return math.atan2(d[1], d[0])
        return 0.0

    def _point_at(self, s: float) -> tuple[np.ndarray, np.ndarray]:
        """Position and unit direction at arc length ``s`` of the current path."""
        cum = self._cum
        i = int(np.clip(np.searchsorted(cum, s, side="right") - 1, 0, len(cum) - 2))
        seg = self._path[i + 1] - self._path[i]
        length = max(float(cum[i + 1] - cum[i]), 1e-12)
        t = np.clip((s - cum[i]) / length, 0.0, 1.0)
        return self._path[i] + seg * t, seg / length

    def step(self, dt: float, keep_clear: tuple[float, float, float] | None = None) -> None:
        """Advance ``dt`` seconds: pause, or walk with bounded acceleration toward the next stop.

        ``keep_clear`` ``(x, y, distance)``: an obstacle the person will not walk into (the
        robot). A step that would end closer than ``distance`` to it, and closer than now, is
        not taken: the person stands and waits, as people do when a robot is in their way, and
        after STEP_ROUND_AFTER seconds of it walks round the robot (:meth:`_step_round`).
        """
        if dt <= 0:
            return
        if self.done or self._pause_left > 0:
            self._pause_left = max(self._pause_left - dt, 0.0)
            self.speed = 0.0
            self._settle_legs(dt)
            self._turn_to_voice(dt)
            return
        self._attend = None  # walking on: the way ahead turns them
        remaining = float(self._cum[-1]) - self._s
        brake = math.sqrt(max(2.0 * ACCELERATION * remaining, 0.0))
        target = min(self.cruise, brake)
        if target > self.speed:
            speed = min(target, self.speed + ACCELERATION * dt)
        else:
            speed = max(target, self.speed - 2.0 * ACCELERATION * dt)
        speed = max(speed, min(0.05, remaining / dt))  # never stall short of a stop
        s = min(self._s + speed * dt, float(self._cum[-1]))
        pos, direction = self._point_at(s)
        if keep_clear is not None:
            ox, oy, clear = keep_clear
            after = math.hypot(pos[0] - ox, pos[1] - oy)
            if after < clear and after < math.hypot(self.x - ox, self.y - oy):
                if remaining <= AT_STOP:
                    self._arrive()
                    return
                self.speed = 0.0
                self._settle_legs(dt)
                self._waited += dt
                if self._waited >= STEP_ROUND_AFTER:
                    self._waited = 0.0
                    self._step_round(ox, oy, clear)
                return
        self._waited = 0.0
        self.speed, self._s = speed, s
        self.x, self.y = float(pos[0]), float(pos[1])
        want = math.atan2(direction[1], direction[0])
        turn = (want - self.theta + math.pi) % (2 * math.pi) - math.pi
        self.theta += float(np.clip(turn, -TURN_RATE * dt, TURN_RATE * dt))
        self.theta = (self.theta + math.pi) % (2 * math.pi) - math.pi
        self.phase = (self.phase + 2 * math.pi * self._cadence() * dt) % (2 * math.pi)
        if self._s >= float(self._cum[-1]) - 1e-9:
            self._arrive()

    def hear(self, x: float, y: float) -> None:
        """The robot at ``(x, y)`` spoke within earshot: a person standing turns to face it
        after :data:`REACTION_S`, looks at it for :data:`ATTEND_S` and turns back; a person
        walking walks on. Spoken to again while turned, they look on from then."""
        if not self.paused:
            return
        back = self.theta if self._attend is None else self._attend[3]
        self._attend = (float(x), float(y), REACTION_S + ATTEND_S, back)

    def _turn_to_voice(self, dt: float) -> None:
        """A standing person's turn toward the robot's voice and back (:meth:`hear`)."""
        if self._attend is None:
            return
        x, y, left, back = self._attend
        left -= dt
        if left > ATTEND_S:
            self._attend = (x, y, left, back)
            return
        want = math.atan2(y - self.y, x - self.x) if left > 0 else back
        turn = (want - self.theta + math.pi) % (2 * math.pi) - math.pi
        self.theta += float(np.clip(turn, -TURN_RATE * dt, TURN_RATE * dt))
        self.theta = (self.theta + math.pi) % (2 * math.pi) - math.pi
        done = left <= 0 and abs(turn) <= TURN_RATE * dt
        self._attend = None if done else (x, y, left, back)

    def _step_round(self, ox: float, oy: float, clear: float) -> None:
        """Walk the rest of this leg round the obstacle at ``(ox, oy)``: re-plan from here to the
        leg's end with it a disc that keeps ``clear`` metres from its centre, and take the path
        if it is at most STEP_ROUND_DETOUR longer. Where there is no room (the robot in a
        door) the person waits on; where the leg's end itself is that near the robot, the person
        stops here instead, as people do when the place they were going is taken. The route's own
        legs are unchanged, so a looping person walks them again next time."""
        rest = float(self._cum[-1]) - self._s
        end = self._path[-1]
        if math.hypot(end[0] - ox, end[1] - oy) < clear:
            self._arrive()
            return
        disc = clear - self._planner.robot_radius + 0.05
        try:
            path = self._planner.with_obstacles([(ox, oy)], disc).plan(
                (self.x, self.y), self._path[-1]
            )
        except NoPathError:
            return
        cum = self._cumulative(path)
        if float(cum[-1]) > rest + STEP_ROUND_DETOUR:
            return
        self._path, self._cum, self._s = path, cum, 0.0

    def _cadence(self) -> float:
        """Gait cycles per second: two steps of ``0.3 + 0.25·v`` metres per cycle (≈0.8 Hz at
        0.8 m/s, about a human's walking cadence)."""
        return self.speed / (2.0 * (0.3 + 0.25 * self.speed))

    def _stride(self) -> float:
        """Fore-aft swing of the feet apart (m): grows with speed, at most 0.34 m, so the legs
        stay 0.2–0.4 m apart while walking, as a laser sees them."""
        return min(0.1 + 0.2 * self.speed, 0.34)

    def _settle_legs(self, dt: float) -> None:
        """Bring the legs together when standing: the phase moves to the nearest 0 or π."""
        near = round(self.phase / math.pi) * math.pi
        self.phase += float(np.clip(near - self.phase, -8.0 * dt, 8.0 * dt))

    def _arrive(self) -> None:
        self.speed = 0.0
        self._leg_index += 1
        last = self._leg_index >= len(self._legs_paths)
        if last and not self.loop:
            self.done = True
            return
        self._leg_index %= len(self._legs_paths)
        self._path = self._legs_paths[self._leg_index]
        self._cum = self._cumulative(self._path)
        self._s = 0.0
        self._pause_left = self.pause_s * float(self._rng.uniform(0.5, 1.5))

    def hold(self, x: float, y: float, theta: float) -> None:
        """Stand still at ``(x, y)`` facing ``theta`` from now on, the route given up (e.g. the
        target posing in front of the robot for ``pfctl learn-target``)."""
        self.x, self.y = float(x), float(y)
        self.theta = (float(theta) + math.pi) % (2 * math.pi) - math.pi
        self.speed, self._pause_left, self.done = 0.0, 0.0, True

    @property
    def paused(self) -> bool:
        return self.done or self._pause_left > 0

    def legs(self) -> np.ndarray:
        """The two legs ``(2, 3)``: ``[x, y, LEG_RADIUS]`` in the map frame."""
        c, s = math.cos(self.theta), math.sin(self.theta)
        swing = 0.5 * self._stride() * math.sin(self.phase)
        out = np.empty((2, 3))
        for k, side in enumerate((1.0, -1.0)):
            fwd = side * swing
            lat = side * HIP_WIDTH / 2
            out[k] = (self.x + c * fwd - s * lat, self.y + s * fwd + c * lat, LEG_RADIUS)
        return out

    @property
    def state(self) -> WalkerState:
        return WalkerState(
            name=self.name,
            x=self.x,
            y=self.y,
            theta=self.theta,
            speed=self.speed,
            is_target=self.is_target,
            height=self.height,
            clothes=self.clothes,
            legs=self.legs(),
            paused=self.paused,
        )

    def truth(self) -> PersonTruth:
        return PersonTruth(self.name, self.x, self.y, self.theta, self.speed, self.is_target)


class Earshot:
    """Who hears the robot speak in the house ``layout``: a person within
    :data:`HEARING_RANGE` of it, the straight line between them crossing no wall (the rooms'
    outlines, open within :data:`DOOR_SLACK` of each door)."""

    def __init__(self, layout: HouseLayout) -> None:
        outlines = shapely.union_all([shapely.Polygon(r.polygon).exterior for r in layout.regions])
        doors = shapely.union_all(
            [shapely.LineString(d.segment).buffer(DOOR_SLACK) for d in layout.doors]
        )
        self.walls = shapely.difference(outlines, doors)
        shapely.prepare(self.walls)

    def hears(self, robot: tuple[float, float], person: tuple[float, float]) -> bool:
        """Whether a person at ``person`` hears the robot at ``robot``."""
        if math.dist(robot, person) > HEARING_RANGE:
            return False
        return not self.walls.intersects(shapely.LineString([robot, person]))


def _stops(
    scenario: ScenarioConfig,
    layout: HouseLayout,
    person: PersonConfig,
    planner: GridPlanner,
    rng: np.random.Generator,
    jitter_rng: np.random.Generator | None = None,
) -> list[np.ndarray]:
    jitter = scenario.randomize.route_jitter
    out = []
    for stop in person.route:
        if isinstance(stop, str):
            out.append(_region_point(planner, layout.region(stop).polygon, rng))
        else:
            p = planner.nearest_free(stop, max_distance=1.0)
            if p is None:
                raise NoPathError(f"{person.name}: route point {stop} is not free for a person")
            point = np.asarray(p, dtype=float)
            if jitter > 0 and jitter_rng is not None:
                point = _jittered(layout, planner, point, jitter, jitter_rng)
            out.append(point)
    return out


def _jittered(
    layout: HouseLayout,
    planner: GridPlanner,
    point: np.ndarray,
    jitter: float,
    rng: np.random.Generator,
    tries: int = 20,
) -> np.ndarray:
    """``point`` moved by up to ``jitter`` metres (uniform over the disc) to a free spot of the
    same region (``scenario.randomize.route_jitter``); ``point`` itself if no draw lands there."""
    regions = [shapely.Polygon(r.polygon) for r in layout.regions]
    home = next((r for r in regions if r.covers(shapely.Point(point))), None)
    for _ in range(tries):
        r = jitter * math.sqrt(float(rng.uniform()))
        a = float(rng.uniform(-math.pi, math.pi))
        q = point + r * np.array([math.cos(a), math.sin(a)])
        if planner.is_free(q) and (home is None or home.contains(shapely.Point(q))):
            return q
    return point


def _random_walkers(
    scenario: ScenarioConfig,
    layout: HouseLayout,
    planner: GridPlanner,
    rng: np.random.Generator,
    taken: set[str],
    count: int | None = None,
    *,
    prefix: str = "walker",
    dress_like: Clothes | None = None,
    jitter: int = 0,
) -> list[Walker]:
    """``count`` (default ``scenario.random_people``) distractors: random free stops, clothes
    and speed; with ``dress_like``, clothes within ``jitter`` of those per RGB channel."""
    walkers = []
    for i in range(scenario.random_people if count is None else count):
        name = f"{prefix}_{i}"
        while name in taken:
            name += "_"
        regions = rng.choice(len(layout.regions), size=3, replace=True)
        stops = []
        for r in regions:
            stops.append(_region_point(planner, layout.regions[int(r)].polygon, rng))
        if dress_like is None:
            clothes = Clothes(
                tuple(int(v) for v in rng.integers(0, 256, 3)),  # type: ignore[arg-type]
                tuple(int(v) for v in rng.integers(0, 256, 3)),  # type: ignore[arg-type]
            )
        else:
            clothes = Clothes(
                _near(dress_like.upper, jitter, rng), _near(dress_like.lower, jitter, rng)
            )
        walkers.append(
            Walker(
                name,
                stops,
                planner,
                speed=float(rng.uniform(0.5, 1.2)),
                clothes=clothes,
                height=float(rng.uniform(1.55, 1.9)),
                pause_s=float(rng.uniform(1.0, 4.0)),
                loop=True,
                seed=int(rng.integers(2**31)),
            )
        )
    return walkers


def make_walkers(
    scenario: ScenarioConfig, layout: HouseLayout, planner: GridPlanner, seed: int
) -> list[Walker]:
    """The scenario's people in the house ``layout`` (plus ``random_people`` distractors, and
    what ``scenario.randomize`` adds: speeds, moved route points, extra distractors and
    look-alikes dressed like the target), deterministic for ``seed``.

    ``planner`` may be the robot's: routes are planned with a copy for :data:`PERSON_RADIUS`.
    Raises :class:`NoPathError` if a route cannot be walked.
    """
    if abs(planner.robot_radius - PERSON_RADIUS) > 1e-9:
        planner = planner.with_radius(PERSON_RADIUS)
    rng = np.random.default_rng(seed)
    vary = scenario.randomize
    # scenario.randomize draws from streams of its own: the draws above stay as they were
    speed_rng, jitter_rng, extra_rng = (
        np.random.default_rng([seed, RANDOMIZE, k]) for k in range(3)
    )
    walkers = []
    for person in scenario.people:
        clothes = Clothes(
            tuple(int(v) for v in person.clothes.upper),  # type: ignore[arg-type]
            tuple(int(v) for v in person.clothes.lower),  # type: ignore[arg-type]
        )
        speed = person.speed
        if vary.speed_scale != (1.0, 1.0):
            scale = float(speed_rng.uniform(*vary.speed_scale))
            speed = min(MAX_SPEED, max(MIN_SPEED, speed * scale))
        walkers.append(
            Walker(
                person.name,
                _stops(scenario, layout, person, planner, rng, jitter_rng),
                planner,
                speed=speed,
                clothes=clothes,
                height=person.height,
                pause_s=person.pause_s,
                loop=person.loop,
                is_target=person.name == scenario.target,
                seed=int(rng.integers(2**31)),
            )
        )
    walkers += _random_walkers(scenario, layout, planner, rng, {w.name for w in walkers})
    extra = int(extra_rng.integers(vary.extra_people[0], vary.extra_people[1] + 1))
    alikes = int(extra_rng.integers(vary.look_alikes[0], vary.look_alikes[1] + 1))
    if extra:
        taken = {w.name for w in walkers}
        walkers += _random_walkers(
            scenario, layout, planner, extra_rng, taken, extra, prefix="extra"
        )
    target = next((w for w in walkers if w.is_target), None)
    if alikes and target is not None:
        walkers += _random_walkers(
            scenario,
            layout,
            planner,
            extra_rng,
            {w.name for w in walkers},
            alikes,
            prefix="look_alike",
            dress_like=target.clothes,
            jitter=vary.look_alike_jitter,
        )
    return walkers


def _near(rgb: tuple[int, int, int], jitter: int, rng: np.random.Generator) -> tuple[int, int, int]:
    """``rgb`` with each channel moved by up to ``jitter`` (uniform integers), kept in 0..255."""
    moved = np.asarray(rgb) + rng.integers(-jitter, jitter + 1, 3)
    return tuple(int(v) for v in np.clip(moved, 0, 255))  # type: ignore[return-value]


__all__ = ["LEG_RADIUS", "PERSON_RADIUS", "Earshot", "Walker", "WalkerState", "make_walkers"]
