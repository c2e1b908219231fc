"""Where can she be: a belief over the home's regions (and cells) after the target is lost.

The prior (:func:`spread`) says how far she can have walked along the region graph of §II-B in
the time since she was last seen. From where she was last seen she walks room to room through
doors at ``walking_speed``; in each room she reaches she either stops there (``stay``) or goes
on through one of its other doors. The first door is weighted by how she was heading: a door she
was approaching (Algorithm 1's heading scores, :func:`~pfctl.core.mapping.regions.heading_scores`)
up to ``heading_weight`` times any other, in proportion to how fast she approached it (the door
of l* the most: along a corridor she approaches every door ahead, not only the nearest), the door
she came in through ``back_weight`` times, and she rarely stops before the doors she was walking
toward (``stay_heading``). Because people at home pause (stop, sit,
turn), the distance she has walked by ``τ`` seconds is taken as uniform on ``[0, v·τ]``: a
route's region holds the share of that interval its stretch of the route covers — from the door
she enters it by to the door she leaves by (door-to-door lengths, not centroid guesses), and to
infinity for the room she stops in. So the belief starts in her room, spreads along doors only
(never through walls) as τ grows, and favours the way she was heading.

The evidence (:class:`Whereabouts`) is the camera's negative observations — the cells of the
human belief grid (Eq. 4) that the camera saw without a person in them. A region loses
``p_detect · f · prior(t_seen)``, with ``f`` the share of its walkable cells seen since the loss
and ``t_seen`` when they were seen (on average): the mass it held then was looked at and was not
her, and only what the prior says can have walked in since comes back (a dead-end room she could
have reached long ago stays empty once seen; a room seen before she could reach it fills again).
Then the regions are normalised: a room looked into and found empty loses its mass and the rest
gain it. Within a region the mass sits on its cells not seen yet
(:meth:`Whereabouts.cell_probabilities`).

A target never seen (``pfctl search``) has the uniform prior over the regions the robot can reach
(:meth:`Whereabouts.never_seen`), weighted by nothing else, with the same evidence.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import networkx as nx
import numpy as np
import shapely
from numpy.typing import ArrayLike, NDArray

from pfctl.core.mapping.grid import GridGeometry
from pfctl.core.mapping.regions import RegionMap
from pfctl.core.params import param

XY = tuple[float, float]

#: Routes less likely than this are not followed further (bounds the routes in a dense plan).
MIN_ROUTE_WEIGHT = 1e-3

__all__ = ["Whereabouts", "WhereaboutsParams", "region_cells", "spread"]


@dataclass(frozen=True)
class WhereaboutsParams:
    """How she walks and pauses, and how much a look counts (mission ``search``)."""

    walking_speed: float = param(0.7, "Her walking speed along the region graph.", unit="m/s", gt=0)
    stay: float = param(
        0.35, "Chance she stops in a room she reaches rather than going on.", ge=0, le=1
    )
    stay_heading: float = param(
        0.1,
        "Chance she stops in her own room when she was walking toward one of its doors.",
        ge=0,
        le=1,
    )
    heading_weight: float = param(
        6.0, "Weight of the door she was approaching (l*) against any other door.", ge=0
    )
    back_weight: float = param(0.25, "Weight of the door she came in through.", ge=0)
    p_detect: float = param(
        0.9, "Chance the camera shows her if she is in a cell it sees.", ge=0, le=1
    )
    max_rooms: int = 10
    """Routes are followed through at most this many regions."""


def _door_point(regions: RegionMap, a: str, b: str, near: XY) -> XY:
    """The midpoint of the door between ``a`` and ``b`` nearest ``near``."""
    best: XY | None = None
    for door in regions.doors_between(a, b):
        (x0, y0), (x1, y1) = door.segment
        mid = ((x0 + x1) / 2.0, (y0 + y1) / 2.0)
        if best is None or math.dist(mid, near) < math.dist(best, near):
            best = mid
    assert best is not None
    return best


def _share(a: float, b: float, reach: float) -> float:
    """P(a ≤ D < b) for D uniform on [0, reach] (D = 0 when reach is 0)."""
    if reach <= 0.0:
        return 1.0 if a <= 0.0 < b else 0.0
    lo, hi = min(max(a, 0.0), reach), min(b, reach)
    return max(hi - lo, 0.0) / reach


def spread(
    regions: RegionMap,
    start: XY,
    elapsed_s: float,
    params: WhereaboutsParams,
    *,
    heading: str | None = None,
    came_from: str | None = None,
    approach: Mapping[str, float] | None = None,
) -> dict[str, float]:
    """The prior over regions ``elapsed_s`` after she was last seen at ``start`` (module
    docstring): {region: probability}, summing to 1 over the regions reachable from her region
    (all of it on her region at τ = 0). ``heading`` is l*, ``came_from`` the region she was in
    before, ``approach`` the speed (m/s or any unit) at which she approached the door of each
    neighbour she approached (default: l*'s alone). Empty when ``start`` lies outside every
    region."""
    first = regions.locate(start)
    if first is None:
        return {}
    reach = params.walking_speed * max(elapsed_s, 0.0)
    rates = {n: a for n, a in (approach or {}).items() if a > 0.0}
    if not rates and heading is not None:
        rates = {heading: 1.0}
    fastest = max(rates.values(), default=1.0)
    bonus = {n: 1.0 + (params.heading_weight - 1.0) * a / fastest for n, a in rates.items()}
    mass: dict[str, float] = {name: 0.0 for name in regions.names}

    def walk(region: str, entry: XY, d_in: float, weight: float, route: tuple[str, ...]) -> None:
        if weight < MIN_ROUTE_WEIGHT:
            return  # a route this unlikely changes no region's mass noticeably
        onward = [n for n in regions.neighbours(region) if n not in route]
        if len(route) >= params.max_rooms:
            onward = []
        if region == first:
            weights = {
                n: bonus.get(n, params.back_weight if n == came_from else 1.0) for n in onward
            }
        else:
            weights = {n: 1.0 for n in onward}
        total = sum(weights.values())
        stay = params.stay_heading if region == first and bonus.keys() & weights else params.stay
        stay = 1.0 if total <= 0.0 else stay
        kept = stay + (1.0 - stay) * (1.0 - total / max(total, len(weights), 1))
        mass[region] += weight * kept * _share(d_in, math.inf, reach)
        if total <= 0.0 or (d_in > 0.0 and d_in >= reach):
            return  # no door on, or she cannot have got this far: nothing further
        for n, w in weights.items():
            door = _door_point(regions, region, n, entry)
            d_out = d_in + math.dist(entry, door)
            # a door weighs against an ordinary door's 1, not only against the others: the one
            # door back out of the room she just entered keeps its back_weight
            share = weight * (1.0 - stay) * w / max(total, len(weights))
            mass[region] += share * _share(d_in, d_out, reach)
            walk(n, door, d_out, share, (*route, n))

    walk(first, start, 0.0, 1.0, (first,))
    total = sum(mass.values())
    return {k: v / total for k, v in mass.items() if v > 0.0} if total > 0 else {}


def region_cells(regions: RegionMap, geometry: GridGeometry) -> NDArray[np.int32]:
    """The region index (``regions.names`` order) of each cell of ``geometry`` by its centre;
    −1 outside every region (the first region wins on shared edges, as :meth:`RegionMap.locate`)."""
    centres = geometry.cell_to_world(*np.indices(geometry.shape))
    label = np.full(geometry.shape, -1, dtype=np.int32)
    for i, name in enumerate(regions.names):
        inside = shapely.contains_xy(regions.polygon(name), centres[..., 0], centres[..., 1])
        label[(label < 0) & inside] = i
    return label


class Whereabouts:
    """The belief over where the lost target can be (module docstring), on the cells of
    ``geometry`` where a person can stand (``walkable``)."""

    def __init__(
        self,
        regions: RegionMap,
        geometry: GridGeometry,
        walkable: ArrayLike,
        params: WhereaboutsParams | None = None,
    ) -> None:
        self.regions = regions
        self.geometry = geometry
        self.params = params or WhereaboutsParams()
        self.labels = region_cells(regions, geometry)
        self.labels[~np.asarray(walkable, dtype=bool)] = -1
        self._cells = np.bincount(self.labels[self.labels >= 0], minlength=len(regions.names))
        self.seen_at = np.full(geometry.shape, -math.inf)
        """When each cell was last seen by the camera without a person in it, s."""
        self.start: XY | None = None
        self.lost_at: float | None = None
        self.heading: str | None = None
        self.came_from: str | None = None
        self.approach: dict[str, float] = {}
        self.active = False
        self._uniform: dict[str, float] | None = None

    # -- what happened -----------------------------------------------------------------------------

    def lost(
        self,
        t: float,
        start: XY,
        *,
        heading: str | None = None,
        came_from: str | None = None,
        approach: Mapping[str, float] | None = None,
    ) -> None:
        """She was last seen at ``start`` at ``t``, heading for ``heading`` (l*), coming from
        ``came_from``. What the camera saw before counts no more (she was elsewhere then)."""
        self.start, self.lost_at = start, t
        self.heading, self.came_from = heading, came_from
        self.approach = dict(approach or {})
        self.seen_at[:] = -math.inf
        self._uniform = None
        self.active = True

    def never_seen(self, t: float, robot_xy: XY) -> None:
        """She has not been seen at all: the uniform prior over the regions reachable from the
        robot's region (all regions when the robot is outside every region)."""
        here = self.regions.locate(robot_xy)
        names = self.regions.names
        if here is not None:
            reachable = nx.node_connected_component(self.regions.graph, here)
            names = [n for n in names if n in reachable]
        self._uniform = {n: 1.0 / len(names) for n in names}
        self.start, self.lost_at, self.heading, self.came_from = None, t, None, None
        self.approach = {}
        self.seen_at[:] = -math.inf
        self.active = True

    def found(self) -> None:
        """She is in sight again: the belief rests until the next loss."""
        self.active = False

    def observe(self, t: float, visible: ArrayLike) -> None:
        """The camera saw the cells ``visible`` (full grid mask) at ``t`` without her."""
        if self.active:
            self.seen_at[np.asarray(visible, dtype=bool)] = t

    # -- what it says ---------------------------------------------------------------------------

    def prior(self, t: float) -> dict[str, float]:
        """The prior over regions at ``t`` (:func:`spread`, or the uniform one)."""
        if self._uniform is not None:
            return dict(self._uniform)
        if self.start is None or self.lost_at is None:
            return {}
        return spread(
            self.regions,
            self.start,
            t - self.lost_at,
            self.params,
            heading=self.heading,
            came_from=self.came_from,
            approach=self.approach,
        )

    def seen_fraction(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Per region (``regions.names`` order): the share of its walkable cells seen empty
        since the loss, and the mean time they were (last) seen (NaN where none was)."""
        seen = np.isfinite(self.seen_at) & (self.labels >= 0)
        n = len(self.regions.names)
        count = np.bincount(self.labels[seen], minlength=n)
        when = np.bincount(self.labels[seen], weights=self.seen_at[seen], minlength=n)
        share = np.where(self._cells > 0, count / np.maximum(self._cells, 1), 1.0)
        with np.errstate(invalid="ignore", divide="ignore"):
            mean = np.where(count > 0, when / np.maximum(count, 1), np.nan)
        return share, mean

    def probabilities(self, t: float) -> dict[str, float]:
        """The posterior over regions at ``t`` (module docstring): each region's prior less the
        mass the camera saw it did not hold — ``p_detect`` × its seen share × its prior when it
        was seen (at most its prior now) — so a room seen empty gets back only what can have
        walked in since; then normalised (the prior itself when nothing is left)."""
        prior = self.prior(t)
        if not prior:
            return {}
        share, when = self.seen_fraction()
        index = {n: i for i, n in enumerate(self.regions.names)}
        then: dict[float, dict[str, float]] = {}
        post: dict[str, float] = {}
        for name, p in prior.items():
            i = index[name]
            if share[i] <= 0.0 or not np.isfinite(when[i]):
                post[name] = p
                continue
            at = float(min(when[i], t))
            if at not in then:
                then[at] = self.prior(at)
            seen_then = min(p, then[at].get(name, 0.0))
            post[name] = p - self.params.p_detect * float(share[i]) * seen_then
        total = sum(post.values())
        if total <= 1e-12:
            return prior
        return {n: v / total for n, v in post.items()}

    def ranked(self, t: float) -> list[tuple[str, float]]:
        """The regions by posterior, most likely first (ties by name)."""
        return sorted(self.probabilities(t).items(), key=lambda kv: (-kv[1], kv[0]))

    def unseen_cells(self, t: float, region: str) -> NDArray[np.bool_]:
        """The walkable cells of ``region`` not seen since the loss (``t`` is kept for the
        callers' clock)."""
        i = self.regions.names.index(region)
        return (self.labels == i) & ~np.isfinite(self.seen_at)

    def cell_probabilities(self, t: float) -> NDArray[np.float64]:
        """The belief over cells: each region's posterior spread evenly over its cells not seen
        yet (over all its cells when every one was seen)."""
        out = np.zeros(self.geometry.shape)
        for name, p in self.probabilities(t).items():
            cells = self.unseen_cells(t, name)
            if not cells.any():
                cells = self.labels == self.regions.names.index(name)
            n = int(cells.sum())
            if n:
                out[cells] += p / n
        return out
