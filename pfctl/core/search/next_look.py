"""Where to look next: the place that finds her soonest for the time it costs (issue 22, item 3).

Every region the belief (:class:`~pfctl.core.search.whereabouts.Whereabouts`) gives mass to is a
candidate, with the place to look into it from:

- a region the robot is not in, not yet looked into: its **doorway** on the robot's way there
  (the door midpoint on the shortest region path, :meth:`RegionMap.region_path`, a step into
  the room) — a head sweep from there sees most of a room without driving around in it;
- a region already looked into from its door, or the robot's own region: **inside**, the cell
  not seen lately that is nearest the centre of the region's unseen cells — the occluded parts,
  behind shelves, that Algorithm 1's frontiers (Eq. 2/3) stand for in a known map.

Each candidate is scored ``P / (t_drive + t_look)``: its posterior over the time to drive there
(door-to-door lengths at the robot's speed) and look. Regions far less likely than the likeliest
(below ``min_share`` of it) are not candidates, so the robot never tours unlikely rooms while a
likely one is still unseen. The ranked candidates come back best first.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Collection
from dataclasses import dataclass
from typing import Literal

import networkx as nx
import numpy as np

from pfctl.core.mapping.regions import RegionMap
from pfctl.core.search.whereabouts import Whereabouts

XY = tuple[float, float]
LookKind = Literal["doorway", "inside"]

__all__ = ["STEP_IN", "Look", "LookKind", "doorway", "rank_looks"]

#: A room is looked into from this far inside its door, m (:func:`_step_in`).
STEP_IN = 0.5


@dataclass(frozen=True)
class Look:
    """A place to look for her: into ``region`` from ``viewpoint``, the head on ``look_at``."""

    region: str
    kind: LookKind
    viewpoint: XY
    look_at: XY
    probability: float
    drive_s: float
    score: float


def doorway(regions: RegionMap, here: XY, region: str) -> tuple[XY, float] | None:
    """The door of ``region`` on the shortest way from ``here`` (its midpoint) and the length of
    that way through the doors between (straight from door to door); None when ``here`` is in
    ``region``, outside every region, or no doors lead there."""
    start = regions.locate(here)
    if start is None or start == region:
        return None
    try:
        path = regions.region_path(start, region)
    except nx.NetworkXNoPath:
        return None
    point, length = here, 0.0
    for a, b in itertools.pairwise(path):
        best = min(
            (
                (
                    (d.segment[0][0] + d.segment[1][0]) / 2.0,
                    (d.segment[0][1] + d.segment[1][1]) / 2.0,
                )
                for d in regions.doors_between(a, b)
            ),
            key=lambda m: math.dist(m, point),
        )
        length += math.dist(point, best)
        point = best
    return point, length


def _step_in(door: XY, centre: XY) -> XY:
    """The place to look into a room from: ``STEP_IN`` m from its ``door`` (midpoint) toward its
    ``centre``. On the threshold the door's jambs hide the room's walls either side of the door
    (generated home 6: she stood 1.5 m to the side of the bedroom's door, unseen from the
    corridor); a step in, the head's sweep takes in the whole room."""
    d = math.dist(door, centre)
    if d <= STEP_IN:
        return centre
    k = STEP_IN / d
    return (door[0] + (centre[0] - door[0]) * k, door[1] + (centre[1] - door[1]) * k)


def _inside_point(wb: Whereabouts, t: float, region: str) -> XY | None:
    """The unseen cell of ``region`` nearest the centre of its unseen cells (None if all seen)."""
    cells = wb.unseen_cells(t, region)
    if not cells.any():
        return None
    rows, cols = np.nonzero(cells)
    centres = wb.geometry.cell_to_world(rows, cols)
    mean = centres.mean(axis=0)
    i = int(np.argmin(np.sum((centres - mean) ** 2, axis=1)))
    return (float(centres[i, 0]), float(centres[i, 1]))


def rank_looks(
    wb: Whereabouts,
    t: float,
    here: XY,
    *,
    robot_speed: float,
    look_s: float,
    looked_from_door: Collection[str] = (),
    skip: Collection[tuple[str, str]] = (),
    min_share: float = 0.25,
) -> list[Look]:
    """The candidate looks at ``t`` from ``here``, best first (module docstring).
    ``looked_from_door``: regions already looked into from their doorway; ``skip``: (region,
    kind) pairs that failed (no way there)."""
    posterior = wb.probabilities(t)
    if not posterior:
        return []
    top = max(posterior.values())
    looks: list[Look] = []
    for region, p in posterior.items():
        if p <= 0.0 or p < min_share * top:
            continue
        inner = _inside_point(wb, t, region)
        look_at = inner if inner is not None else wb.regions.region_point(region)
        door = doorway(wb.regions, here, region)
        if door is not None and region not in looked_from_door and (region, "doorway") not in skip:
            viewpoint, length = _step_in(door[0], wb.regions.region_point(region)), door[1]
            kind: LookKind = "doorway"
        elif inner is not None and (region, "inside") not in skip:
            viewpoint, kind = inner, "inside"
            length = (door[1] + math.dist(door[0], inner)) if door else math.dist(here, inner)
        else:
            continue
        drive = length / robot_speed
        looks.append(Look(region, kind, viewpoint, look_at, p, drive, p / (drive + look_s)))
    looks.sort(key=lambda lk: (-lk.score, lk.region))
    return looks
