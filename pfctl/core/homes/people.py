"""The people of a generated home: the target's walk through doors, the crowd, the look-alikes,
and where the robot starts.

The target walks from one room to another at least two doors away along the region graph (three
when the plan has such rooms), stopping on the way (``pause_s``: people at home stop, sit, turn)
in a region of the way or a room beside it, and ends where the doors of her last room do not see
her (behind a tall piece of furniture when there is one) — the robot, at 0.22 m/s against her
0.7–0.9 m/s, loses her on the way. The robot starts 1.2–2.2 m behind her, facing her, with a clear
line of sight. The crowd wears clothes of other colours than hers (hues at least
:data:`HUE_APART` away) and walks looping routes through random regions; look-alikes wear exactly
her clothes.
"""

from __future__ import annotations

import colorsys
import itertools
import math
from dataclasses import dataclass

import networkx as nx
import numpy as np
import shapely

from pfctl.core.homes.plans import CIRCULATION
from pfctl.core.homes.reach import doors_crossed
from pfctl.core.mapping.house import HouseLayout, Point
from pfctl.core.mapping.paths import line_of_sight
from pfctl.core.mapping.planning import GridPlanner

__all__ = ["HUE_APART", "PALETTE", "Cast", "PersonPlan", "cast_people"]

RGB = tuple[int, int, int]

#: Colours clothes are drawn from: saturated, far apart in hue, and a few neutrals.
PALETTE: tuple[RGB, ...] = (
    (200, 30, 40),
    (40, 40, 120),
    (30, 120, 200),
    (40, 150, 60),
    (220, 200, 40),
    (130, 40, 160),
    (230, 120, 30),
    (40, 180, 190),
    (230, 110, 170),
    (120, 80, 40),
    (60, 60, 60),
    (235, 235, 230),
)
#: The least hue difference (degrees) between a crowd member's colours and the target's.
HUE_APART = 40.0
_NAMES = ("bob", "carol", "dave", "erin", "frank", "grace", "heidi", "ivan", "judy", "mallory")
_TARGET = "alice"
#: A person standing still keeps this far (m) from furniture and walls, beyond their radius.
_STAND_CLEAR = 0.3
#: Standing spots of a room tried as her hiding place.
_CANDIDATES = 300


@dataclass(frozen=True)
class PersonPlan:
    """A person of the scenario: what ``scenario.people[*]`` holds."""

    name: str
    upper: RGB
    lower: RGB
    speed: float
    pause_s: float
    route: tuple[str | Point, ...]
    loop: bool = False
    role: str = "target"
    """``target``, ``crowd`` or ``look-alike``."""


@dataclass(frozen=True)
class Cast:
    """Everyone in the scenario, the robot's start, and the target's way through the doors."""

    people: tuple[PersonPlan, ...]
    start: tuple[float, float, float]
    """The robot's start: x, y, heading (facing the target)."""
    doors: tuple[int, ...]
    """Indices of the layout's doors the target's planned walk passes, in order."""
    rooms: tuple[str, ...]
    """The regions of her route's stops."""


def _hue(rgb: RGB) -> tuple[float, float]:
    h, s, _ = colorsys.rgb_to_hsv(*(c / 255 for c in rgb))
    return 360.0 * h, s


def _apart(a: RGB, b: RGB) -> bool:
    """Whether two colours look clearly different: hue far apart, or one of them grey."""
    (ha, sa), (hb, sb) = _hue(a), _hue(b)
    if sa < 0.25 or sb < 0.25:
        return (sa < 0.25) != (sb < 0.25) or abs(sum(a) - sum(b)) > 300
    d = abs(ha - hb) % 360
    return min(d, 360 - d) >= HUE_APART


def _graph(layout: HouseLayout) -> nx.Graph:
    g = nx.Graph()
    g.add_nodes_from(r.name for r in layout.regions)
    g.add_edges_from(d.between for d in layout.doors)
    return g


def _spots(planner: GridPlanner, polygon: tuple[Point, ...]) -> np.ndarray:
    """Cells of a region where a person can stand (free, clear of furniture), ``(n, 2)``."""
    ok = planner.free & (planner.clearance >= planner.robot_radius + _STAND_CLEAR)
    rows, cols = np.nonzero(ok)
    cells = planner.geometry.cell_to_world(rows, cols)
    return cells[shapely.contains_xy(shapely.Polygon(polygon), cells[:, 0], cells[:, 1])]


def _point(xy: np.ndarray) -> Point:
    return (round(float(xy[0]), 2) + 0.0, round(float(xy[1]), 2) + 0.0)


def _hidden_spot(
    layout: HouseLayout, planner: GridPlanner, region: str, rng: np.random.Generator
) -> np.ndarray:
    """A standing spot in ``region`` that none of its doors sees (else the farthest from them)."""
    spots = _spots(planner, layout.region(region).polygon)
    if not len(spots):
        raise ValueError(f"no free spot in {region}")
    if len(spots) > _CANDIDATES:
        spots = spots[np.sort(rng.choice(len(spots), _CANDIDATES, replace=False))]
    mids = [np.mean(d.segment, axis=0) for d in layout.doors if region in d.between]
    tall = np.zeros(planner.geometry.shape, dtype=bool)
    centres = planner.geometry.cell_to_world(*np.indices(tall.shape))
    for o in layout.obstacles:
        if o.height >= 1.2:
            tall |= shapely.contains_xy(
                shapely.Polygon(o.polygon), centres[..., 0], centres[..., 1]
            )
    tall |= planner.static.states() == 1  # walls
    seen = np.zeros(len(spots), dtype=bool)
    for mid in mids:
        seen |= line_of_sight(tall, planner.geometry, mid, spots)
    far = np.min([np.linalg.norm(spots - m, axis=1) for m in mids], axis=0)
    hidden = np.nonzero(~seen & (far >= 1.0))[0]
    if len(hidden):
        return spots[int(rng.choice(hidden))]
    return spots[int(np.argsort(far)[-1 - int(rng.integers(min(10, len(far))))])]


def _target_route(
    layout: HouseLayout, person: GridPlanner, rng: np.random.Generator
) -> tuple[list[np.ndarray], list[str]]:
    g = _graph(layout)
    rooms = [r.name for r in layout.regions if r.name not in CIRCULATION]
    hops = dict(nx.all_pairs_shortest_path_length(g))
    pairs = [(a, b) for a in rooms for b in rooms if a != b and hops[a].get(b, 0) >= 2]
    if not pairs:
        raise ValueError("no two rooms are two doors apart")
    far = max(hops[a][b] for a, b in pairs)
    pairs = [(a, b) for a, b in pairs if hops[a][b] >= min(3, far)]
    a, b = pairs[int(rng.integers(len(pairs)))]
    way = nx.shortest_path(g, a, b)
    stops_at = [a]
    middle = way[1:-1]
    beside = [
        n
        for n in sorted({m for w in middle for m in g.neighbors(w)})
        if n not in way and n in rooms
    ]
    if beside and rng.random() < 0.5:  # she looks into a room on the way
        stops_at.append(beside[int(rng.integers(len(beside)))])
    else:
        stops_at.append(middle[int(rng.integers(len(middle)))])
    stops_at.append(b)
    start_spots = _spots(person, layout.region(a).polygon)
    if not len(start_spots):
        raise ValueError(f"no free spot in {a}")
    points = [start_spots[int(rng.integers(len(start_spots)))]]
    for name in stops_at[1:-1]:
        spots = _spots(person, layout.region(name).polygon)
        if not len(spots):
            raise ValueError(f"no free spot in {name}")
        points.append(spots[int(rng.integers(len(spots)))])
    points.append(_hidden_spot(layout, person, b, rng))
    return points, stops_at


def _robot_start(
    robot: GridPlanner, her: np.ndarray, heading: np.ndarray, rng: np.random.Generator
) -> tuple[float, float, float]:
    """1.2–2.2 m behind her (against ``heading``), free, seeing her, facing her."""
    ok = robot.free & (robot.clearance >= robot.robot_radius + 0.1)
    back = math.atan2(-heading[1], -heading[0])
    for _ in range(300):
        angle = back + float(rng.uniform(-1.2, 1.2))
        r = float(rng.uniform(1.2, 2.2))
        p = her + r * np.array([math.cos(angle), math.sin(angle)])
        rows, cols = robot.geometry.world_to_cell(p)
        if not robot.geometry.in_bounds(rows, cols) or not ok[int(rows), int(cols)]:
            continue
        if not line_of_sight(robot.obstacle, robot.geometry, p, her):
            continue
        x, y = _point(p)
        theta = round(math.atan2(her[1] - y, her[0] - x), 3) + 0.0
        return (x, y, theta)
    raise ValueError("no free place for the robot behind the target")


def _clothes(rng: np.random.Generator, avoid: tuple[RGB, ...]) -> tuple[RGB, RGB]:
    options = [c for c in PALETTE if all(_apart(c, a) for a in avoid)]
    if len(options) < 2:
        raise ValueError("no colours left that differ from the target's")
    i, j = rng.choice(len(options), size=2, replace=False)
    return options[int(i)], options[int(j)]


def cast_people(
    layout: HouseLayout,
    robot: GridPlanner,
    person: GridPlanner,
    rng: np.random.Generator,
    *,
    crowd: int,
    look_alikes: int,
) -> Cast:
    """The scenario's people and the robot's start (see the module docstring).

    ``robot`` and ``person`` plan on the home's static map for the robot's and a person's
    radius (the simulator's walkers plan their legs on the latter).

    Raises:
        ValueError: this draw does not give a walk through two doors (callers draw again).
    """
    points, rooms = _target_route(layout, person, rng)
    path = [person.plan(a, b) for a, b in itertools.pairwise(points)]
    walk = np.vstack(path)
    crossed = doors_crossed(walk, layout.doors)
    if len(crossed) < 2:
        raise ValueError("the target's walk passes fewer than two doors")
    heading = path[0][1] - path[0][0] if len(path[0]) > 1 else np.array([1.0, 0.0])
    start = _robot_start(robot, points[0], heading / max(np.linalg.norm(heading), 1e-9), rng)
    i, j = rng.choice(len(PALETTE) - 2, size=2, replace=False)  # no neutral colours for her
    upper, lower = PALETTE[int(i)], PALETTE[int(j)]
    target = PersonPlan(
        name=_TARGET,
        upper=upper,
        lower=lower,
        speed=round(float(rng.uniform(0.7, 0.9)), 2),
        pause_s=round(float(rng.uniform(2.0, 4.0)), 1),
        route=tuple(_point(p) for p in points),
    )
    names = iter(_NAMES)
    regions = [r.name for r in layout.regions]
    others: list[PersonPlan] = []
    for role, count in (("crowd", crowd), ("look-alike", look_alikes)):
        for _ in range(count):
            k = int(rng.integers(2, 4))
            route = tuple(str(regions[int(n)]) for n in rng.choice(len(regions), k, replace=False))
            up, low = (upper, lower) if role == "look-alike" else _clothes(rng, (upper, lower))
            others.append(
                PersonPlan(
                    name=next(names, f"person_{len(others) + 1}"),
                    upper=up,
                    lower=low,
                    speed=round(float(rng.uniform(0.5, 0.9)), 2),
                    pause_s=round(float(rng.uniform(2.0, 5.0)), 1),
                    route=route,
                    loop=True,
                    role=role,
                )
            )
    return Cast(people=(target, *others), start=start, doors=tuple(crossed), rooms=tuple(rooms))
