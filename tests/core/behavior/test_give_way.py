"""Giving way (no robot): a robot driving to a goal that makes no progress with a person close in
front steps aside, out of the line from them through the robot, holds there, and drives on; it
steps again when they come its way; a robot stuck with nobody about, or still moving, does not.
The place is the office door of ``missions/house.yaml`` (house seed 14's deadlock)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pfctl.core.behavior.give_way import GiveWay
from pfctl.core.behavior.intents import Intents, Navigate
from pfctl.core.behavior.world import WorldModel
from pfctl.core.control import ControlParams
from pfctl.core.mapping.grid import OccupancyGrid
from pfctl.core.mapping.house import HouseLayout
from pfctl.core.mapping.planning import GridPlanner
from pfctl.core.mapping.regions import RegionMap, SearchParams
from pfctl.core.mapping.walls import segment_distance
from pfctl.core.robot import NavStatus, Pose2D

DOOR = (3.9, 6.1)  # the robot, in the office's door, going in
WAITING = (3.9, 6.6)  # a person inside, waiting to come out
GOAL = (2.6, 7.8)  # inside the office


@pytest.fixture
def intents(planner: GridPlanner, layout: HouseLayout) -> Intents:
    grid = OccupancyGrid(planner.geometry)
    world = WorldModel(grid, planner, RegionMap(layout), SearchParams())
    return Intents(ControlParams(), world)


def _go(
    intents: Intents, t: float, xy: tuple[float, float], people: list[tuple[float, float]]
) -> str:
    """One tick at ``t`` with the robot at ``xy`` and ``people`` tracked, driving to GOAL."""
    status = NavStatus.ACTIVE if intents.navigation.goal is not None else NavStatus.IDLE
    intents.navigation.status = status
    intents.begin(t, Pose2D(xy[0], xy[1], math.pi / 2))
    intents.world.update(t, people)
    return intents.go_to(GOAL, tolerance=0.4)


def _stuck(intents: Intents, people: list[tuple[float, float]], until: float) -> float:
    """Tick every 0.1 s with the robot standing in the door until it gives way (or ``until``
    s); the time of that tick."""
    t = 0.0
    while t <= until + 1e-9:
        assert _go(intents, t, DOOR, people) == "running"
        if intents.base_mode == "give_way":
            break
        t += 0.1
    return t


def test_a_robot_stuck_before_a_waiting_person_steps_aside_then_drives_on(
    intents: Intents, planner: GridPlanner
) -> None:
    t = _stuck(intents, [WAITING], until=2 * GiveWay.AFTER_S)
    assert t == pytest.approx(GiveWay.AFTER_S)
    sent = intents.base
    assert isinstance(sent, Navigate)
    aside = (sent.goal.x, sent.goal.y)
    assert math.dist(aside, DOOR) == pytest.approx(GiveWay.STEP)
    assert math.dist(aside, WAITING) >= GiveWay.CLEAR
    assert abs(aside[0] - DOOR[0]) > 0.5  # off the line from them through the robot
    line = np.linspace(DOOR, aside, 50)
    assert planner.free_mask(line).all()  # a straight way there on the static map
    since = t
    t += 0.1
    _go(intents, t, aside, [WAITING])  # there: it holds while the person stands in the door
    assert intents.base_mode == "give_way" and intents.navigation.goal is None
    while t < since + GiveWay.FOR_S - 0.15:
        t += 0.1
        assert _go(intents, t, aside, [WAITING]) == "running"
        assert intents.base_mode == "give_way"
    t += 0.2
    assert _go(intents, t, aside, [WAITING]) == "running"
    assert intents.base_mode == "move_base" and isinstance(intents.base, Navigate)
    assert (intents.base.goal.x, intents.base.goal.y) == pytest.approx(GOAL, abs=0.1)


def test_the_robot_drives_on_once_the_person_it_gave_way_to_has_gone_by(
    intents: Intents,
) -> None:
    """The crowd, seed 14: the person came through the door 3 s after the robot's step; it
    drives on then, not ``FOR_S`` after its step, while walking through where it stood keeps it
    there."""
    t = _stuck(intents, [WAITING], until=2 * GiveWay.AFTER_S)
    assert isinstance(intents.base, Navigate)
    aside = (intents.base.goal.x, intents.base.goal.y)
    since = t
    way = [WAITING, DOOR, (3.6, 5.6), (3.3, 5.2), (2.9, 4.9), (2.6, 4.8)]
    released = None
    for k in range(1, round(GiveWay.FOR_S / 0.1)):
        t = since + 0.1 * k
        walker = way[min(k // 5, len(way) - 1)]  # through the door and down the hall
        _go(intents, t, aside, [walker])
        if intents.base_mode == "move_base":
            released = (t, walker)
            break
        assert math.dist(walker, DOOR) <= GiveWay.NEAR or t - since < GiveWay.SETTLE_S, t
    assert released is not None
    assert released[0] - since < GiveWay.FOR_S - 1.0
    assert math.dist(released[1], DOOR) > GiveWay.NEAR
    assert isinstance(intents.base, Navigate)
    assert (intents.base.goal.x, intents.base.goal.y) == pytest.approx(GOAL, abs=0.1)


def test_the_robot_drives_back_early_only_where_its_laser_sees_the_way(
    planner: GridPlanner,
) -> None:
    """The crowd, seed 24: the robot had turned on its way to its place, the way back lay
    behind it, in the laser's blind sector, and a man who stood there unseen was hit as it drove
    back once the person it gave way to had gone by. With the way back ahead or to a side, it
    drives back at once; behind it, it holds until ``FOR_S``."""
    here, person = (6.0, 5.0), (6.6, 5.0)  # in the hall, a person waiting east of it
    passed = (9.0, 5.0)  # down the hall, out of the way
    for heading, early in ((math.pi / 2, True), (0.0, True), (-math.pi / 2, False)):
        give_way = GiveWay()
        t, aside = 0.0, None
        while aside is None:
            aside = give_way.check(t, here, [person], planner, None, heading)
            t += 0.1
        assert aside == pytest.approx((6.0, 5.0 - GiveWay.SIDE_STEP))  # south: back is north
        since, drove_back = t - 0.1, None
        while drove_back is None:  # there, ticking; the person has gone by
            if give_way.check(t, aside, [passed], planner, None, heading) is None:
                drove_back = t - since
            t += 0.1
        if early:
            assert drove_back == pytest.approx(GiveWay.SETTLE_S, abs=0.15), heading
        else:
            assert drove_back == pytest.approx(GiveWay.FOR_S, abs=0.15), heading


def test_where_a_side_is_free_the_step_is_the_short_one_to_a_side(planner: GridPlanner) -> None:
    """In the hall (nothing but walls near), the robot steps ``SIDE_STEP`` m to a side, off the
    way of the person waiting in front of it, not ``STEP`` m: at 0.22 m/s each metre of the
    step is driven there and back."""
    here, person = (6.0, 5.0), (6.6, 5.0)
    aside = GiveWay().place(here, person, np.array([person]), planner)
    assert aside is not None
    assert math.dist(aside, here) == pytest.approx(GiveWay.SIDE_STEP)
    assert abs(aside[1] - here[1]) == pytest.approx(GiveWay.SIDE_STEP)  # to a side
    assert GiveWay.SIDE_STEP >= GiveWay.OUT_OF_WAY


def test_a_person_coming_its_way_gets_another_step_aside(intents: Intents) -> None:
    t = _stuck(intents, [WAITING], until=2 * GiveWay.AFTER_S)
    assert isinstance(intents.base, Navigate)
    first = (intents.base.goal.x, intents.base.goal.y)
    after = t + GiveWay.SETTLE_S + 0.1
    toward = (first[0], first[1] + 0.5)  # he came on to where the robot stepped
    while t < after:
        t += 0.1
        _go(intents, t, first, [toward])
    y = intents.give_way.yielding
    assert y is not None and y.steps == 2 and math.dist(y.to, first) == pytest.approx(1.0)
    assert math.dist(y.to, toward) >= GiveWay.CLEAR


def test_a_person_walking_past_the_place_it_stepped_to_gets_no_other_step(
    intents: Intents,
) -> None:
    """The house, seed 7: the person it gave way to walks round the robot at its place, 0.6 m
    off; the robot holds there and drives on, without a second step back down the hall. Had
    he stood there, he would have had one (the test above)."""
    t = _stuck(intents, [WAITING], until=2 * GiveWay.AFTER_S)
    assert isinstance(intents.base, Navigate)
    first = (intents.base.goal.x, intents.base.goal.y)
    since = t
    for k in range(1, round(GiveWay.FOR_S / 0.1) + 3):
        t = since + 0.1 * k
        walker = (first[0] - 1.5 + 0.05 * k, first[1] + 0.6)  # 0.5 m/s, past the robot
        _go(intents, t, first, [walker])
        y = intents.give_way.yielding
        if y is None:
            break
        assert y.steps == 1, t
    assert intents.base_mode == "move_base" and intents.give_way.yielding is None


def test_no_step_aside_with_nobody_near_or_while_the_robot_moves(intents: Intents) -> None:
    _stuck(intents, [(8.0, 2.0)], until=2 * GiveWay.AFTER_S)  # the nearest: across the house
    assert intents.base_mode == "move_base" and intents.give_way.yielding is None
    for k in range(round(2 * GiveWay.AFTER_S / 0.1)):
        xy = (DOOR[0] - 0.01 * k, DOOR[1] + 0.01 * k)  # slowly, but on its way
        _go(intents, 100.0 + 0.1 * k, xy, [(xy[0], xy[1] + 0.6)])
        assert intents.base_mode == "move_base"


def test_a_person_in_a_door_of_its_room_gets_a_step_off_the_ways_to_its_other_doors(
    planner: GridPlanner, layout: HouseLayout
) -> None:
    """The house's seed 40: the robot, just inside the kitchen's door to the hall, on its way
    out; a person waits in that door, coming in. Her way may be to the kitchen's other door
    (the living room's): the robot's step keeps off the line from the door she is in to that
    one, as well as off the line from her through it (before, it stepped onto that way: 0.15 m
    from it, and she walked behind it as it stepped twice more)."""
    regions = RegionMap(layout)
    here, person = (2.21, 3.72), (2.46, 4.22)
    give_way = GiveWay()
    t, aside = 0.0, None
    while aside is None and t <= 2 * GiveWay.AFTER_S:
        aside = give_way.check(t, here, [person], planner, regions)
        t += 0.1
    assert aside is not None
    assert math.dist(aside, here) == pytest.approx(GiveWay.STEP)
    doors = regions.door_midpoints("kitchen")
    (hall_door,) = [d for d in doors if math.dist(d, person) <= GiveWay.AT_DOOR]
    for other in doors:
        if other != hall_door:
            assert segment_distance(np.array(aside), np.array([(*hall_door, *other)])) >= 0.5
    assert give_way.ways(here, (3.0, 1.0), regions) == []  # in the room, at no door
    assert GiveWay().place(here, person, np.array([person]), planner) == pytest.approx(
        (2.84, 3.41), abs=0.02
    )  # without the doors: the short step, onto her way to the living room
