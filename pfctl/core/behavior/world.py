"""What the robot knows of the house this tick, as the behavior tree's leaves use it (§II-B–E).

A :class:`WorldModel` sits on the blackboard (key ``world``). It holds the robot's occupancy grid
(Eq. 1: it starts unknown and fills in as the laser sees the house), the static map's planner
(walls and furniture inflated by the robot's radius), the region map of Algorithm 1, the
belief over where a lost target can be (:class:`~pfctl.core.search.whereabouts.Whereabouts`) with
what the camera can see of it (the static map's walls and furniture, the camera's range), and,
per tick, the other people the tracker holds and the stamp of the newest laser scan. The follower's
perceive stage keeps it up to date; leaves read it to run their control laws (the base's
line-of-sight check, Algorithm 1) and never write it.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pfctl.core.mapping.grid import OCCUPIED_THRESH, OccupancyGrid, logit
from pfctl.core.mapping.planning import GridPlanner
from pfctl.core.mapping.regions import RegionMap, SearchParams, WaypointDecision, waypoint_search
from pfctl.core.robot import Pose2D
from pfctl.core.search.gaze import in_sight_all_round
from pfctl.core.search.whereabouts import Whereabouts

#: Cells at least this likely occupied block the line of sight (the grid's occupied threshold).
_OCCUPIED_LOGODDS = float(logit(OCCUPIED_THRESH))


class WorldModel:
    """The robot's maps and the people around it (module docstring)."""

    def __init__(
        self,
        grid: OccupancyGrid,
        planner: GridPlanner,
        regions: RegionMap,
        search: SearchParams,
        whereabouts: Whereabouts | None = None,
        *,
        sight_blocked: ArrayLike | None = None,
        camera_range: tuple[float, float] | None = None,
    ) -> None:
        self.grid = grid
        """The robot's occupancy grid (Eq. 1), updated with every scan."""
        self.planner = planner
        """The static map's planner: where the robot can be (:meth:`free_goal`)."""
        self.regions = regions
        self.search = search
        self.whereabouts = whereabouts
        """Where the lost target can be (None: not kept); the follower feeds it."""
        self.sight_blocked = None if sight_blocked is None else np.asarray(sight_blocked, bool)
        """The static map's cells that block the camera's line of sight (None: not known)."""
        self.camera_range = camera_range
        """The depth interval in which the camera sees people, m (None: not known)."""
        self.sensor_stamp: float | None = None
        """Stamp of the newest laser scan, s (None before the first)."""
        self.people_xy: NDArray[np.float64] = np.empty((0, 2))
        """``(n, 2)``: the people the tracker holds this tick, the target left out."""

    def update(self, sensor_stamp: float | None, people_xy: ArrayLike) -> None:
        """This tick's newest scan stamp and the other people's positions."""
        self.sensor_stamp = sensor_stamp
        self.people_xy = np.asarray(people_xy, dtype=float).reshape(-1, 2)

    def blocked(self) -> NDArray[np.bool_]:
        """The cells of the robot's grid that are occupied (they block the line of sight)."""
        blocked: NDArray[np.bool_] = self.grid.logodds >= _OCCUPIED_LOGODDS
        return blocked

    def unseen_in_sight(self, t: float, pose: Pose2D) -> float | None:
        """The floor area (m²) where she can be (the belief over where she can be,
        :attr:`whereabouts`, at ``t``) that the camera has not seen since the loss and could
        see from ``pose``, turning all round: within :attr:`camera_range`, in line of sight on
        the static map. What looking round here can still find; None while there is no belief
        (none kept, or at rest) or the camera is not known."""
        wb = self.whereabouts
        if wb is None or not wb.active or self.sight_blocked is None or self.camera_range is None:
            return None
        cells = in_sight_all_round(wb, self.sight_blocked, pose, self.camera_range)
        cells &= ~np.isfinite(wb.seen_at)
        cells &= wb.cell_probabilities(t) > 0.0
        return float(cells.sum()) * wb.geometry.resolution**2

    def free_goal(self, xy: ArrayLike) -> tuple[float, float] | None:
        """``xy`` moved into free space for the robot (:meth:`GridPlanner.free_goal`)."""
        return self.planner.free_goal(xy)

    def next_waypoint(self, history: ArrayLike, here: tuple[float, float]) -> WaypointDecision:
        """Algorithm 1 on the robot's occupancy grid for the target's ``history`` (t, x, y),
        from the robot's position ``here``. With no history (the target was never seen) l* is
        None: the frontiers are scored by their size and distance alone (Eq. 3 without the
        d(c, l*) term). The frontier is chosen by ``search.waypoint_choice``."""
        s = self.search
        h = since_region_entered(np.asarray(history, dtype=float).reshape(-1, 3), self.regions)
        return waypoint_search(
            self.grid,
            self.regions,
            h,
            here,
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
    where = regions.locate_all(history[:, 1:3])  # one vectorised test per region, not per point
    elsewhere = np.flatnonzero(where != where[-1])
    start = int(elsewhere[-1]) + 1 if elsewhere.size else 0
    return history[start:]


__all__ = ["WorldModel", "since_region_entered"]
