"""Generated homes (issue 22): random floor plans of several kinds, furniture that occludes but
never blocks, and a scenario in which the target walks through doors — the homes a search is
measured on, instead of the one shipped house.

=====================  ======================================================================
:mod:`.plans`          floor plans: layout kinds, rooms, doors and wide openings
:mod:`.furniture`      furniture against walls or free-standing, never blocking a door
:mod:`.reach`          reachability on the planner grid; the doors a walk passes
:mod:`.people`         the target's walk, the crowd, look-alikes, the robot's start
:mod:`.home`           :func:`generate_home`: all of it from a seed
=====================  ======================================================================

Core code: no files, no YAML; ``pfctl.mission.homes`` writes a home as a mission.
"""

from pfctl.core.homes.home import (
    DEFAULT_SIZE,
    Home,
    HomeOptions,
    ImpossibleHomeError,
    generate_home,
)
from pfctl.core.homes.plans import LAYOUTS, FloorPlan

__all__ = [
    "DEFAULT_SIZE",
    "LAYOUTS",
    "FloorPlan",
    "Home",
    "HomeOptions",
    "ImpossibleHomeError",
    "generate_home",
]
