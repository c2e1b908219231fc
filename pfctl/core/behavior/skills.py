"""The search settings of the behavior tree's way-point search (§II-C/D, Algorithm 1)."""

from __future__ import annotations

from dataclasses import dataclass

from pfctl.core.mapping.regions import WaypointChoice
from pfctl.core.params import param


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


__all__ = ["SearchParams"]
