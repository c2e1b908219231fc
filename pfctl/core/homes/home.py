"""A whole generated home from a seed: floor plan, furniture, people, the robot's start.

:func:`generate_home` draws the size, the layout kind and the number of rooms from the seed
(unless given), then draws plans until one is furnished, open for the robot and a person, and
gives the target a walk through at least two doors (:mod:`.plans`, :mod:`.furniture`,
:mod:`.people`). Every draw comes from ``numpy.random.default_rng`` of the seed (and of the
attempt), so the same seed and options give the same home.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from pfctl.core.homes.furniture import furnish
from pfctl.core.homes.people import Cast, cast_people
from pfctl.core.homes.plans import (
    LAYOUTS,
    MIN_ROOM,
    FloorPlan,
    max_rooms,
    min_rooms,
    plan_home,
)
from pfctl.core.homes.reach import home_planner, open_issue
from pfctl.core.mapping.house import HouseLayout

__all__ = [
    "DEFAULT_SIZE",
    "MAX_SIDE",
    "MIN_SIDE",
    "Home",
    "HomeOptions",
    "ImpossibleHomeError",
    "generate_home",
]

#: The default size is drawn from these ranges of width and height, metres.
DEFAULT_SIZE = ((10.0, 16.0), (8.0, 12.0))
#: The smallest and largest side of a home, metres.
MIN_SIDE, MAX_SIDE = 3.0, 40.0
#: Floor area per room of the default number of rooms, m².
_AREA_PER_ROOM = 24.0
#: Plans drawn before giving up.
_ATTEMPTS = 60


class ImpossibleHomeError(ValueError):
    """The options ask for a home that cannot be made; ``option`` names the one to change."""

    def __init__(self, option: str, message: str) -> None:
        super().__init__(message)
        self.option = option


@dataclass(frozen=True)
class HomeOptions:
    """What to generate; None: drawn from the seed."""

    seed: int
    rooms: int | None = None
    size: tuple[float, float] | None = None
    layout: str | None = None
    crowd: int = 0
    look_alikes: int = 0


@dataclass(frozen=True)
class Home:
    """A generated home: its plan, the layout with furniture, and its people."""

    options: HomeOptions
    """The options with everything drawn filled in (rooms, size, layout)."""
    plan: FloorPlan
    layout: HouseLayout
    cast: Cast
    attempts: int
    """Plans drawn until this one passed."""


def _fitting(width: float, height: float, rooms: int | None) -> list[str]:
    return [
        k
        for k in LAYOUTS
        if max_rooms(k, width, height) >= max(min_rooms(k), rooms or 0)
        and (rooms is None or rooms >= min_rooms(k))
    ]


def _check(options: HomeOptions, width: float, height: float) -> None:
    """:class:`ImpossibleHomeError` for options no plan can satisfy."""
    for side in (width, height):
        if not MIN_SIDE <= side <= MAX_SIDE:
            raise ImpossibleHomeError(
                "size",
                f"expected each side within {MIN_SIDE:g}..{MAX_SIDE:g} m, got "
                f"{width:g} x {height:g}",
            )
    kinds = [options.layout] if options.layout is not None else list(LAYOUTS)
    best = max(max_rooms(k, width, height) for k in kinds)
    if best == 0:
        what = f"a {options.layout} layout" if options.layout else "any layout"
        raise ImpossibleHomeError(
            "size",
            f"a {width:g} x {height:g} m home is too small for {what} with rooms at least "
            f"{MIN_ROOM:g} m wide",
        )
    if options.rooms is not None:
        fewest = min(min_rooms(k) for k in kinds)
        if options.rooms > best or options.rooms < fewest:
            layout = f" ({options.layout} layout)" if options.layout else ""
            span = f"{fewest}" if fewest == best else f"{fewest} to {best}"
            raise ImpossibleHomeError(
                "rooms",
                f"expected {span} rooms for a {width:g} x {height:g} m home{layout} "
                f"(rooms at least {MIN_ROOM:g} m wide, the target walking through two doors), "
                f"got {options.rooms}",
            )


def generate_home(
    options: HomeOptions,
    *,
    resolution: float,
    wall_thickness: float,
    robot_radius: float,
    person_radius: float,
) -> Home:
    """The home of ``options`` (see the module docstring); the grid of ``resolution`` and
    ``wall_thickness`` is the one the reachability is checked on.

    Raises:
        ImpossibleHomeError: the options cannot be met (too many rooms for the size, a size
            outside :data:`MIN_SIDE`..:data:`MAX_SIDE`, a layout that does not fit).
    """
    if options.layout is not None and options.layout not in LAYOUTS:
        raise ImpossibleHomeError(
            "layout", f"expected one of {', '.join(LAYOUTS)}, got {options.layout!r}"
        )
    rng = np.random.default_rng(options.seed)
    if options.size is None:
        (w0, w1), (h0, h1) = DEFAULT_SIZE
        width, height = round(float(rng.uniform(w0, w1)), 1), round(float(rng.uniform(h0, h1)), 1)
    else:
        width, height = options.size
    _check(options, width, height)
    kinds = (
        [options.layout] if options.layout is not None else _fitting(width, height, options.rooms)
    )
    if not kinds:
        raise ImpossibleHomeError(
            "rooms", f"no layout holds {options.rooms} rooms in a {width:g} x {height:g} m home"
        )
    kind = kinds[int(rng.integers(len(kinds)))]
    rooms = options.rooms
    if rooms is None:
        guess = round(width * height / _AREA_PER_ROOM) + int(rng.integers(-1, 2))
        rooms = int(np.clip(guess, min_rooms(kind), max_rooms(kind, width, height)))
    drawn = replace(options, rooms=rooms, size=(width, height), layout=kind)
    why = ""
    for attempt in range(_ATTEMPTS):
        draw = np.random.default_rng([options.seed, attempt])
        try:
            plan = plan_home(kind, width, height, rooms, draw)
            bare = HouseLayout(regions=plan.regions, doors=plan.doors)
            obstacles = furnish(
                bare,
                draw,
                resolution=resolution,
                wall_thickness=wall_thickness,
                radii=(robot_radius, person_radius),
            )
            layout = HouseLayout(regions=plan.regions, doors=plan.doors, obstacles=obstacles)
            robot = home_planner(layout, resolution, wall_thickness, robot_radius)
            person = robot.with_radius(person_radius)
            for planner in (robot, person):
                issue = open_issue(layout, planner)
                if issue is not None:
                    raise ValueError(issue)
            cast = cast_people(
                layout, robot, person, draw, crowd=options.crowd, look_alikes=options.look_alikes
            )
        except ValueError as err:
            why = str(err)
            continue
        return Home(options=drawn, plan=plan, layout=layout, cast=cast, attempts=attempt + 1)
    raise ImpossibleHomeError(
        "rooms",
        f"no {kind} plan of {rooms} rooms in {width:g} x {height:g} m passed the checks in "
        f"{_ATTEMPTS} draws (last: {why}); try fewer rooms or another seed",
    )
