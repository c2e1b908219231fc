"""Human belief grid (§II-E, Eq. 4 with P(h) in the numerator): Bayes updates of the visible
cells, occlusion by walls, decay, and the queries the gaze controller uses."""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from pfctl.core.mapping.grid import FREE, OCCUPIED, GridGeometry
from pfctl.core.mapping.walls import rasterize_house
from pfctl.core.perception.belief import BeliefParams, HumanBelief, bayes_update, visible_mask
from pfctl.core.perception.tracking import FieldOfView
from pfctl.core.robot import Pose2D
from pfctl.mission import load_mission

ROOT = Path(__file__).resolve().parents[3]

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


# -- the fast visibility and peak queries equal their plain definitions ----------------------


def _reference_visible_mask(
    geometry: GridGeometry, fov: FieldOfView, blocked: np.ndarray
) -> np.ndarray:
    """The visibility of the module docstring written plainly (the implementation before the
    rays were cast a chunk at a time and the box cut at the longest free ray): every ray
    sampled out to the far range, the cells of the whole wedge's box."""
    from pfctl.core.perception.belief import RAY_STEP, _window

    out = np.zeros(geometry.shape, dtype=bool)
    window = _window(geometry, fov)
    if window is None:
        return out
    r0, r1, c0, c1, far = window
    res = geometry.resolution
    x = geometry.origin[0] + (np.arange(c0, c1) + 0.5) * res - fov.origin.x
    y = geometry.origin[1] + (np.arange(r0, r1) + 0.5) * res - fov.origin.y
    dx, dy = x[None, :], y[:, None]
    dist = np.hypot(dx, dy)
    bearing = np.arctan2(dy, dx) - fov.origin.theta
    bearing = (bearing + np.pi) % (2.0 * np.pi) - np.pi
    half = min(fov.half_angle, math.pi)
    mask = (dist >= fov.range_min) & (dist <= fov.range_max) & (np.abs(bearing) <= half)
    step = min(RAY_STEP, res / max(far, res))
    n_rays = max(2, math.ceil(2.0 * half / step) + 1)
    ray_step = 2.0 * half / (n_rays - 1)
    ray_angles = fov.origin.theta - half + ray_step * np.arange(n_rays)
    s = np.arange(0.0, far + res, res / 2.0)
    px = fov.origin.x + np.cos(ray_angles)[:, None] * s[None, :]
    py = fov.origin.y + np.sin(ray_angles)[:, None] * s[None, :]
    cols = np.floor((px - geometry.origin[0]) / res).astype(np.intp)
    rows = np.floor((py - geometry.origin[1]) / res).astype(np.intp)
    inside = (rows >= 0) & (rows < geometry.height) & (cols >= 0) & (cols < geometry.width)
    hit = ~inside
    hit[inside] = blocked[rows[inside], cols[inside]]
    first = np.where(hit.any(axis=1), hit.argmax(axis=1), len(s))
    free = np.append(s, np.inf)[first]
    ray = np.clip(np.rint((bearing + half) / ray_step).astype(np.intp), 0, n_rays - 1)
    mask &= dist < free[ray]
    mask &= ~blocked[r0:r1, c0:c1]
    out[r0:r1, c0:c1] = mask
    return out


def test_visibility_equals_the_plain_ray_casting_on_random_poses() -> None:
    """Chunked rays and the box cut at the longest free ray change nothing: the same cells, in
    the house (walls, doors, furniture) and in an open room, from random poses (some outside
    the map or at its edge), for the camera's wedge, narrow and wide ones and all around."""
    mission = load_mission(ROOT / "missions" / "house.yaml")
    grid = rasterize_house(mission.layout(), mission.map.resolution, mission.map.wall_thickness)
    rng = np.random.default_rng(4)
    cases = [(grid.geometry, grid.states() != FREE), (GEO, walled())]
    for geometry, blocked in cases:
        belief = HumanBelief(geometry, BeliefParams(), blocked)
        w, h = geometry.width * geometry.resolution, geometry.height * geometry.resolution
        for k in range(120):
            x, y = rng.uniform(-1.0, w + 1.0), rng.uniform(-1.0, h + 1.0)
            half = [math.radians(29.0), 0.05, 1.5, math.pi][k % 4]
            far = [8.0, 3.0, 20.0][k % 3]
            fov = FieldOfView(Pose2D(x, y, rng.uniform(-4.0, 4.0)), half, 0.4, far)
            want = _reference_visible_mask(geometry, fov, blocked)
            assert np.array_equal(visible_mask(geometry, fov, blocked), want), (k, fov)
            before = belief.p.copy()
            got = belief.update(fov, [], t=float(k))
            assert np.array_equal(got, want & belief.walkable), (k, fov)
            assert np.array_equal(belief.p != before, got & (before > belief.params.p_min))


def _reference_most_likely(
    belief: HumanBelief, k: int, min_separation: float
) -> list[tuple[float, float, float]]:
    """Greedy over the best ``max(64 k, 1024)`` cells (``k`` without a separation), by belief
    then by cell index, written plainly."""
    flat = belief.p.ravel()
    pool = k if min_separation <= 0 else max(64 * k, 1024)
    order = np.lexsort((np.arange(flat.size), -flat))[:pool]
    rows, cols = np.unravel_index(order, belief.p.shape)
    out: list[tuple[float, float, float]] = []
    for (x, y), i in zip(belief.geometry.cell_to_world(rows, cols), order, strict=True):
        if flat[i] <= 0.0 or len(out) == k:
            break
        if all(math.hypot(x - a, y - b) >= min_separation for a, b, _ in out):
            out.append((float(x), float(y), float(flat[i])))
    return out


def _random_belief(
    rng: np.random.Generator, trial: int, third: Callable[[tuple[int, int]], np.ndarray]
) -> HumanBelief:
    """A belief on a random grid of 1-69 cells a side: by ``trial`` % 3 a few repeated values
    (the prior, p_min, 0 and others: ties), uniform values, or ``third(shape)``."""
    shape = (int(rng.integers(1, 70)), int(rng.integers(1, 70)))
    kind = trial % 3
    if kind == 0:
        p = rng.choice([0.0, 0.001, 0.05, 0.3, 0.999], size=shape)
    elif kind == 1:
        p = rng.random(shape)
    else:
        p = third(shape)
    belief = HumanBelief(GridGeometry(0.05, shape[1], shape[0], (0.0, 0.0)), BeliefParams())
    belief.p = p
    return belief


def test_most_likely_equals_the_plain_greedy_with_ties() -> None:
    """Belief grids are full of equal values (the prior, p_min, 0): the peaks and their order
    are those of the plain sorted greedy, equal beliefs taken in cell order."""
    from pfctl.core.perception.belief import _kth_largest

    rng = np.random.default_rng(5)
    for trial in range(150):
        belief = _random_belief(
            rng, trial, lambda shape: np.round(rng.random(shape), 2) * (rng.random(shape) > 0.3)
        )
        p = belief.p
        for k in (1, 3, 8, 40):
            for separation in (0.0, 0.12, 1.0):
                want = _reference_most_likely(belief, k, separation)
                assert belief.most_likely(k, separation) == want, (trial, k, separation)
        flat = p.ravel()
        for rank in {1, 2, flat.size // 2 + 1, flat.size}:
            assert _kth_largest(flat, rank) == np.sort(flat)[::-1][rank - 1]
    # a grid the size of the house's, mostly at the prior, with a few people seen
    belief = HumanBelief(GridGeometry(0.05, 260, 200, (-0.5, -0.5)), BeliefParams())
    belief.p[rng.random(belief.p.shape) < 0.3] = 0.001
    belief.p[:, :20] = 0.0
    for x, y in ((2.0, 3.0), (2.4, 3.1), (8.0, 5.0)):
        rows, cols = belief.geometry.world_to_cell(np.array([x, y]))
        belief.p[int(rows) - 3 : int(rows) + 4, int(cols) - 3 : int(cols) + 4] = 0.6
    for k, separation in ((8, 1.0), (3, 0.0), (20, 0.3)):
        assert belief.most_likely(k, separation) == _reference_most_likely(belief, k, separation)


def test_most_likely_at_least_gives_the_leading_peaks_of_the_plain_greedy() -> None:
    """``at_least`` (the gaze rule's threshold) returns exactly the peaks of the plain list at
    least that likely: few likely cells (found by one comparison), more than the candidates
    (the counting path), ties at the threshold, none at all."""
    rng = np.random.default_rng(21)
    for trial in range(120):
        belief = _random_belief(
            rng,
            trial,
            lambda shape: np.where(
                rng.random(shape) < 0.02, rng.choice([0.3, 0.6, 0.9], shape), 0.05
            ),
        )
        for k in (1, 3, 8, 40):
            for separation in (0.0, 0.12, 1.0):
                plain = _reference_most_likely(belief, k, separation)
                for at_least in (0.3, 0.5, 0.95, 1.0):
                    want = [peak for peak in plain if peak[2] >= at_least]
                    got = belief.most_likely(k, separation, at_least=at_least)
                    assert got == want, (trial, k, separation, at_least)
