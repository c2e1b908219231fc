"""Human belief grid (§II-E, Eq. 4 with P(h) in the numerator): Bayes updates of the visible
cells, occlusion by walls, decay, and the queries the gaze controller uses."""

from __future__ import annotations

import itertools
import math
from pathlib import Path

import numpy as np
import pytest

from pfctl.core.belief import BeliefParams, HumanBelief, bayes_update, visible_mask
from pfctl.core.grid import FREE, OCCUPIED, GridGeometry
from pfctl.core.robot import Pose2D
from pfctl.core.tracking import FieldOfView
from pfctl.core.walls import rasterize_house
from pfctl.mission import load_mission

ROOT = Path(__file__).resolve().parents[1]

# A 10 m x 6 m room at 0.05 m with a wall x = 6 from y = 0 to y = 4 (a door above y = 4).
GEO = GridGeometry(0.05, 200, 120, (0.0, 0.0))
CAMERA = FieldOfView(Pose2D(1.0, 2.0, 0.0), math.radians(29.0), 0.4, 8.0)


def walled() -> np.ndarray:
    blocked = np.zeros(GEO.shape, dtype=bool)
    blocked[0:80, 120:122] = True  # x in [6.0, 6.1), y in [0, 4)
    return blocked


def cell_of(xy: tuple[float, float]) -> tuple[int, int]:
    rows, cols = GEO.world_to_cell(np.array(xy))
    return int(rows), int(cols)


def test_eq4_closed_form_one_update() -> None:
    """prior 0.05, P(o|h) 0.9, P(o|hᶜ) 0.05:
    P(h|o)  = 0.9·0.05 / (0.9·0.05 + 0.05·0.95) = 0.045 / 0.0925 = 0.486486…
    P(h|¬o) = 0.1·0.05 / (0.1·0.05 + 0.95·0.95) = 0.005 / 0.9075 = 0.005509…"""
    assert bayes_update(0.05, True, 0.9, 0.05) == pytest.approx(0.045 / 0.0925)
    assert bayes_update(0.05, False, 0.9, 0.05) == pytest.approx(0.005 / 0.9075)
    assert float(bayes_update(0.05, True, 0.9, 0.05)) == pytest.approx(0.4864865, abs=1e-6)
    assert float(bayes_update(0.05, False, 0.9, 0.05)) == pytest.approx(0.0055096, abs=1e-6)

    belief = HumanBelief(GEO, BeliefParams(prior=0.05, p_o_given_h=0.9, p_o_given_not_h=0.05))
    belief.update(CAMERA, [(4.0, 2.0)], t=0.0)
    assert belief.p[cell_of((4.0, 2.0))] == pytest.approx(0.045 / 0.0925)
    assert belief.p[cell_of((3.0, 2.5))] == pytest.approx(0.005 / 0.9075)
    assert belief.p[cell_of((1.0, 5.0))] == 0.05  # outside the wedge


def test_cell_seen_empty_falls_and_cell_outside_the_view_does_not_change() -> None:
    belief = HumanBelief(GEO, BeliefParams(), blocked=walled())
    seen, outside = cell_of((4.0, 2.3)), cell_of((4.0, 5.5))
    values = []
    for k in range(5):
        visible = belief.update(CAMERA, [], t=0.1 * k)
        assert visible[seen] and not visible[outside]
        values.append(belief.p[seen])
    assert values[0] < 0.05 and all(b <= a for a, b in itertools.pairwise(values))
    assert values[-1] == pytest.approx(0.001)  # clipped at p_min, never 0
    assert belief.p[outside] == 0.05


def test_cell_behind_a_wall_inside_the_wedge_does_not_change() -> None:
    belief = HumanBelief(GEO, BeliefParams(), blocked=walled())
    in_front, behind = cell_of((5.5, 2.0)), cell_of((7.0, 2.0))
    assert abs(math.atan2(0.0, 6.0)) < CAMERA.half_angle and CAMERA.contains((7.0, 2.0))
    for k in range(3):
        belief.update(CAMERA, [], t=0.1 * k)
    assert belief.p[in_front] < 0.05
    assert belief.p[behind] == 0.05
    assert np.all(belief.p[walled()] == 0.0)  # blocked cells are not places to stand
    # without the wall, the same cell is seen
    assert visible_mask(GEO, CAMERA)[behind] and not visible_mask(GEO, CAMERA, walled())[behind]


def test_detected_person_rises_above_the_prior_and_is_the_argmax() -> None:
    belief = HumanBelief(GEO, BeliefParams(), blocked=walled())
    person = (3.5, 1.5)
    for k in range(3):
        belief.update(CAMERA, [person], t=0.1 * k)
    assert belief.p[cell_of(person)] > 0.5
    assert belief.p[cell_of((person[0] + 0.25, person[1]))] > 0.05  # within 0.3 m
    assert belief.p[cell_of((person[0] + 0.6, person[1]))] < 0.05  # seen empty
    assert math.dist(belief.argmax(), person) <= 0.3
    top = belief.most_likely(3, min_separation=1.0)
    assert math.dist(top[0][:2], person) <= 0.3
    assert all(p <= top[0][2] for _, _, p in top)
    assert all(math.dist(a[:2], b[:2]) >= 1.0 for a in top for b in top if a is not b)
    assert [p for _, _, p in belief.most_likely(2)] == sorted(
        [p for _, _, p in belief.most_likely(2)], reverse=True
    )


def test_decay_returns_toward_the_prior() -> None:
    params = BeliefParams(decay_per_s=0.5)
    belief = HumanBelief(GEO, params)
    person, empty = cell_of((3.5, 1.5)), cell_of((3.5, 2.5))
    belief.update(CAMERA, [(3.5, 1.5)], t=0.0)
    high, low = belief.p[person], belief.p[empty]
    belief.advance(2.0)
    keep = math.exp(-0.5 * 2.0)
    assert belief.p[person] == pytest.approx(0.05 + (high - 0.05) * keep)
    assert belief.p[empty] == pytest.approx(0.05 + (low - 0.05) * keep)
    belief.advance(60.0)
    assert belief.p[person] == pytest.approx(0.05, abs=1e-6)
    no_decay = HumanBelief(GEO, BeliefParams())
    no_decay.update(CAMERA, [(3.5, 1.5)], t=0.0)
    before = no_decay.p.copy()
    no_decay.advance(100.0)
    assert np.array_equal(no_decay.p, before)


def test_visible_mask_wedge_and_range() -> None:
    mask = visible_mask(GEO, CAMERA)
    assert mask[cell_of((8.5, 2.0))] and not mask[cell_of((9.5, 2.0))]  # range_max 8 m
    assert not mask[cell_of((1.2, 2.0))]  # nearer than range_min
    edge = math.radians(29.0)
    inside = (1.0 + 4 * math.cos(edge - 0.05), 2.0 + 4 * math.sin(edge - 0.05))
    outside = (1.0 + 4 * math.cos(edge + 0.05), 2.0 + 4 * math.sin(edge + 0.05))
    assert mask[cell_of(inside)] and not mask[cell_of(outside)]
    away = FieldOfView(Pose2D(-5.0, -5.0, math.pi), 0.5, 0.0, 3.0)  # looks away from the grid
    assert not visible_mask(GEO, away).any()
    with pytest.raises(ValueError, match="shape"):
        visible_mask(GEO, CAMERA, np.zeros((3, 3), dtype=bool))


def test_house_visibility_stops_at_walls_and_passes_doors() -> None:
    """From the hall of missions/house.yaml, all around: the hall is seen, the rooms are hidden
    except through their doors."""
    mission = load_mission(ROOT / "missions" / "house.yaml")
    grid = rasterize_house(mission.layout(), mission.map.resolution, mission.map.wall_thickness)
    states = grid.states()
    belief = HumanBelief(grid.geometry, BeliefParams(), states == OCCUPIED, states == FREE)
    visible = belief.update(FieldOfView(Pose2D(6.0, 5.0, 0.0), math.pi, 0.4, 8.0), [], t=0.0)

    def at(x: float, y: float) -> bool:
        rows, cols = grid.geometry.world_to_cell(np.array([x, y]))
        return bool(visible[int(rows), int(cols)])

    assert at(2.0, 5.0) and at(10.5, 4.5)  # hall
    assert not at(6.0, 2.0) and not at(3.0, 7.5)  # living room, office behind walls
    assert at(2.9, 6.5)  # through the office door (3.5..4.4 on y = 6)
    assert not visible[states != FREE].any()
    assert belief.p[visible].max() < 0.05 and belief.p[~visible & (states == FREE)].min() == 0.05


def test_params_validation() -> None:
    with pytest.raises(ValueError, match="p_o_given"):
        BeliefParams(p_o_given_h=0.05, p_o_given_not_h=0.05)
    with pytest.raises(ValueError, match="prior"):
        BeliefParams(prior=0.0)


def test_params_from_the_mission_by_name() -> None:
    belief = load_mission(ROOT / "missions" / "house.yaml").belief
    params = BeliefParams(**belief.model_dump())
    assert params.prior == belief.prior and params.p_o_given_h == belief.p_o_given_h
