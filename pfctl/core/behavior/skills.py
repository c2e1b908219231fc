"""The search settings of the behavior tree's way-point search (§II-C/D, Algorithm 1)."""

from __future__ import annotations

from dataclasses import dataclass

from pfctl.core.mapping.regions import WaypointChoice


@dataclass(frozen=True)
class SearchParams:
    """Eq. 2, Eq. 3 and Algorithm 1 settings (the mission's ``search`` section)."""

    alpha: float = 0.05
    beta: float = 1.0
    frontier_threshold: float = 0.1
    min_frontier_cells: int = 5
    heading_window_s: float = 3.0
    waypoint_choice: WaypointChoice = "utility"
    """``utility`` (Eq. 3, the paper) or ``nearest`` (the nearest reachable frontier, a
    baseline; :func:`~pfctl.core.mapping.regions.waypoint_search`)."""


__all__ = ["SearchParams"]
