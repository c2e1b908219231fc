"""Tests of pfctl.core.mapping.grid: Eq. 1 on single cells, entropy, laser scans, nav_msgs values.

Expected values are worked out by hand in the comments; with the mission's sensor model
p_hit = 0.7, p_miss = 0.4, p_min = 0.02, p_max = 0.98 and the prior p(m) = 0.5 (log-odds 0).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from pfctl.core.mapping.grid import (
    FREE,
    OCCUPIED,
    UNKNOWN,
    GridGeometry,
    InverseSensorModel,
    OccupancyGrid,
    inv_logit,
    logit,
)

# ----------------------------------------------------------------------------------- helpers


def one_cell() -> OccupancyGrid:
    return OccupancyGrid(GridGeometry(resolution=0.1, width=1, height=1))


def observe(grid: OccupancyGrid, *events: str) -> list[float]:
    """Apply "hit"/"miss" events to every cell of ``grid``; p of cell (0, 0) after each."""
    ones = np.ones(grid.shape, dtype=bool)
    none = np.zeros(grid.shape, dtype=bool)
    out = []
    for event in events:
        if event == "hit":
            grid.update_cells(ones, none)
        else:
            grid.update_cells(none, ones)
        out.append(float(grid.prob()[0, 0]))
    return out


def eq1(p_z: float, p_prev: float, prior: float = 0.5) -> float:
    """Eq. 1 as printed in the paper (the product form), for cross-checking the log-odds form."""
    return 1.0 / (1.0 + (1 - p_z) / p_z * (1 - p_prev) / p_prev * prior / (1 - prior))


def room_ranges(
    pose: tuple[float, float, float], angles: np.ndarray, half: float, centre=(0.0, 0.0)
) -> np.ndarray:
    """Distance along each beam to the walls x = cx ± half, y = cy ± half (sensor inside)."""
    x, y, theta = pose
    a = theta + angles
    c, s = np.cos(a), np.sin(a)
    with np.errstate(divide="ignore", invalid="ignore"):
        tx = np.where(c > 0, (centre[0] + half - x) / c, (centre[0] - half - x) / c)
        ty = np.where(s > 0, (centre[1] + half - y) / s, (centre[1] - half - y) / s)
    tx = np.where(c == 0, np.inf, tx)
    ty = np.where(s == 0, np.inf, ty)
    return np.minimum(tx, ty)


# -------------------------------------------------------------------------------- Eq. 1


def test_eq1_hit_hit_miss_from_the_prior() -> None:
    # In odds o = p / (1 − p): the prior 0.5 is o = 1; a hit multiplies by 0.7/0.3 = 7/3,
    # a miss by 0.4/0.6 = 2/3 (Eq. 1 in log-odds: l_t = l_{t−1} + logit(p(m|z_t)) − logit(0.5)).
    #   hit:  o = 7/3            → p = 7/10            = 0.7
    #   hit:  o = 49/9           → p = 49/58           = 0.844827586…
    #   miss: o = 49/9 · 2/3 = 98/27 → p = 98/125      = 0.784
    grid = one_cell()
    assert observe(grid, "hit", "hit", "miss") == pytest.approx([0.7, 49 / 58, 0.784], abs=1e-12)
    # The product form of Eq. 1 gives the same numbers.
    p1 = eq1(0.7, 0.5)
    p2 = eq1(0.7, p1)
    p3 = eq1(0.4, p2)
    assert [p1, p2, p3] == pytest.approx([0.7, 49 / 58, 0.784], abs=1e-12)
    assert grid.logodds[0, 0] == pytest.approx(2 * math.log(7 / 3) + math.log(2 / 3))


def test_eq1_clamps_to_p_max_and_p_min() -> None:
    # Hits: o = (7/3)^n. n = 4: 2401/81 ≈ 29.64 → p = 2401/2482 ≈ 0.967365;
    # n = 5: 16807/243 ≈ 69.2 > 49 = 0.98/0.02 → clamped to p_max = 0.98.
    # One miss from there: o = 49 · 2/3 = 98/3 → p = 98/101 ≈ 0.970297.
    grid = one_cell()
    ps = observe(grid, "hit", "hit", "hit", "hit", "hit", "hit", "miss")
    assert ps[3] == pytest.approx(2401 / 2482, abs=1e-12)
    assert ps[4] == pytest.approx(0.98, abs=1e-12)
    assert ps[5] == pytest.approx(0.98, abs=1e-12)
    assert ps[6] == pytest.approx(98 / 101, abs=1e-12)
    # Misses: o = (2/3)^n. n = 9: 512/19683 ≈ 0.0260 > 1/49 ≈ 0.0204 → p = 512/20195 ≈ 0.025353;
    # n = 10: 1024/59049 ≈ 0.0173 < 1/49 → clamped to p_min = 0.02.
    grid = one_cell()
    ps = observe(grid, *["miss"] * 11)
    assert ps[8] == pytest.approx(512 / 20195, abs=1e-12)
    assert ps[9] == pytest.approx(0.02, abs=1e-12)
    assert ps[10] == pytest.approx(0.02, abs=1e-12)


def test_update_cells_hit_wins_and_untouched_cells_keep_their_value() -> None:
    grid = OccupancyGrid.from_probabilities([[0.5, 0.5, 1.0]], resolution=1.0)
    hit = np.array([[True, False, False]])
    free = np.array([[True, True, False]])
    grid.update_cells(hit, free)
    # cell 0: hit and passed through → counts as a hit only: p = 0.7.
    # cell 1: passed through: p = 0.4. cell 2: untouched, stays saturated (not clamped to 0.98).
    p = grid.prob()[0]
    assert p[0] == pytest.approx(0.7)
    assert p[1] == pytest.approx(0.4)
    assert p[2] > 0.999999


def test_sensor_model_is_validated() -> None:
    with pytest.raises(ValueError, match=r"p_miss < 0\.5 < p_hit"):
        InverseSensorModel(p_hit=0.4, p_miss=0.3)
    with pytest.raises(ValueError, match="p_max"):
        InverseSensorModel(p_max=1.0)
    model = InverseSensorModel()
    assert model.l_hit == pytest.approx(math.log(7 / 3))
    assert model.l_miss == pytest.approx(math.log(2 / 3))
    assert (model.l_min, model.l_max) == pytest.approx((-math.log(49), math.log(49)))


# ------------------------------------------------------------------------ grid basics


def test_empty_grid_geometry_and_states() -> None:
    grid = OccupancyGrid.empty(20.0, 10.0, 0.05, origin=(-10.0, -5.0))
    # 20 / 0.05 = 400 columns, 10 / 0.05 = 200 rows (not 401/201 from float noise).
    assert (grid.width, grid.height) == (400, 200)
    assert grid.shape == (200, 400)
    assert grid.resolution == 0.05
    assert grid.origin == (-10.0, -5.0)
    assert grid.logodds.dtype == np.float64
    assert np.all(grid.logodds == 0.0)
    assert np.all(grid.prob() == 0.5)
    assert np.all(grid.states() == UNKNOWN)


def test_states_thresholds_and_copy() -> None:
    grid = OccupancyGrid.from_probabilities([[0.1, 0.196, 0.5, 0.65, 0.9, 0.0, 1.0]], 0.1)
    # p < 0.196 → FREE, p > 0.65 → OCCUPIED, the thresholds themselves are UNKNOWN.
    expected = [FREE, UNKNOWN, UNKNOWN, UNKNOWN, OCCUPIED, FREE, OCCUPIED]
    assert grid.states().tolist() == [expected]
    assert np.all(np.isfinite(grid.logodds))  # 0 and 1 are saturated, not ±inf
    twin = grid.copy()
    twin.logodds[0, 0] = 5.0
    assert grid.logodds[0, 0] == pytest.approx(logit(0.1))
    assert inv_logit(logit(0.3)) == pytest.approx(0.3)


def test_constructor_checks_shape() -> None:
    with pytest.raises(ValueError, match="shape"):
        OccupancyGrid(GridGeometry(0.1, 3, 2), np.zeros((3, 2)))


# ---------------------------------------------------------------------------- entropy


def test_entropy_of_an_unknown_grid_is_one_bit_per_cell() -> None:
    grid = OccupancyGrid(GridGeometry(0.1, width=20, height=10))
    # N = 200 cells at p = 0.5: each −(0.5 ln 0.5 + 0.5 ln 0.5) = ln 2 nats = 1 bit.
    assert grid.entropy() == pytest.approx(200.0)
    assert grid.entropy(base=2) == pytest.approx(200.0)
    assert grid.entropy(base=math.e) == pytest.approx(200 * math.log(2))  # 138.629…


def test_entropy_of_a_known_grid_is_about_zero_and_of_one_cell_by_hand() -> None:
    known = OccupancyGrid.from_probabilities(np.tile([[0.0, 1.0]], (10, 10)), 0.1)
    assert known.entropy() == pytest.approx(0.0, abs=1e-4)
    # One cell at p = 0.7: 0.7·log2(1/0.7) + 0.3·log2(1/0.3)
    #   = 0.7 · 0.514573 + 0.3 · 1.736966 = 0.360201 + 0.521090 = 0.881291 bits.
    cell = OccupancyGrid.from_probabilities([[0.7]], 0.1)
    assert cell.entropy() == pytest.approx(0.881291, abs=1e-6)
    with pytest.raises(ValueError):
        cell.entropy(base=1.0)


# ------------------------------------------------------------------------------ scans


def strip_grid() -> OccupancyGrid:
    """5 m × 1 m at 0.1 m: 50 columns × 10 rows; the sensor sits at (0.05, 0.55) = cell (5, 0)."""
    return OccupancyGrid.empty(5.0, 1.0, 0.1)


def scan(grid: OccupancyGrid, ranges, **kw) -> np.ndarray:
    """One scan along +x from (0.05, 0.55); beams all at angle 0; returns p of row 5."""
    kw.setdefault("range_max", 3.0)
    grid.update_scan((0.05, 0.55, 0.0), np.asarray(ranges, dtype=float), 0.0, 0.0, **kw)
    return grid.prob()[5]


def test_scan_return_frees_the_beam_and_hits_the_end_cell() -> None:
    # r = 1.0: the end point x = 1.05 lies in column 10 ([1.0, 1.1)) → hit, p = 0.7;
    # columns 0..9 are passed through → p = 0.4; nothing beyond column 10 changes.
    grid = strip_grid()
    p = scan(grid, [1.0])
    assert p[:10] == pytest.approx([0.4] * 10)
    assert p[10] == pytest.approx(0.7)
    assert np.all(grid.logodds[:, 11:] == 0.0)
    others = np.delete(grid.logodds, 5, axis=0)
    assert np.all(others == 0.0)  # the beam runs along the middle of row 5 only


def test_scan_counts_each_cell_once_and_hit_beats_free() -> None:
    # Two beams in the same direction: 1.0 (hit in column 10) and 2.0 (hit in column 20, passing
    # through column 10). Column 10 counts as a hit (0.7, not a hit and a miss); columns 0..9 are
    # passed by both beams but updated once: 0.4, not (2/3)^2 → 0.3077.
    grid = strip_grid()
    p = scan(grid, [1.0, 2.0])
    assert p[:10] == pytest.approx([0.4] * 10)
    assert p[10] == pytest.approx(0.7)
    assert p[11:20] == pytest.approx([0.4] * 9)
    assert p[20] == pytest.approx(0.7)
    assert np.all(p[21:] == 0.5)


def test_rep117_inf_is_free_to_range_max_without_hit() -> None:
    # +inf, range_max = 1.0: free from x = 0.05 to 1.05, i.e. columns 0..10, no hit anywhere.
    for value in (np.inf, 7.0):  # a value above range_max is treated like +inf
        grid = strip_grid()
        p = scan(grid, [value], range_max=1.0)
        assert p[:11] == pytest.approx([0.4] * 11)
        assert np.all(p[11:] == 0.5)
        assert grid.prob().max() == 0.5


def test_rep117_minus_inf_nan_and_too_close_change_nothing() -> None:
    grid = strip_grid()
    scan(grid, [-np.inf, np.nan, 0.05], range_min=0.1)
    assert np.all(grid.logodds == 0.0)


def test_max_update_range_truncates_without_hit() -> None:
    # r = 2.0 is a valid return but beyond max_update_range = 1.0: free over columns 0..10 only.
    grid = strip_grid()
    p = scan(grid, [2.0], max_update_range=1.0)
    assert p[:11] == pytest.approx([0.4] * 11)
    assert np.all(p[11:] == 0.5)


def test_beams_are_clipped_to_the_grid() -> None:
    grid = strip_grid()
    # Sensor 1 m left of the grid, r = 2.0: end x = 1.05 → hit column 10, columns 0..9 free.
    grid.update_scan((-0.95, 0.55, 0.0), [2.0], 0.0, 0.0, range_max=3.0)
    p = grid.prob()[5]
    assert p[:10] == pytest.approx([0.4] * 10)
    assert p[10] == pytest.approx(0.7)
    # Sensor inside, the return lies outside the grid (x = 6.05 > 5): free to the edge, no hit.
    grid = strip_grid()
    grid.update_scan((0.05, 0.55, 0.0), [6.0], 0.0, 0.0, range_max=10.0)
    assert grid.prob()[5] == pytest.approx([0.4] * 50)
    # A scan entirely outside the grid changes nothing.
    grid = strip_grid()
    grid.update_scan((-3.0, -3.0, math.pi), [1.0, np.inf], 0.0, 0.1, range_max=10.0)
    assert np.all(grid.logodds == 0.0)


def test_scan_in_a_square_room_frees_the_inside_and_marks_the_walls() -> None:
    # Grid 6 m × 6 m at 0.1 m from (−3, −3): column c covers x ∈ [−3 + 0.1c, −2.9 + 0.1c).
    # Walls at x, y = ±2.05 run through the centres of cells 9 ([−2.1, −2.0)) and 50 ([2.0, 2.1)):
    # the inside is cells 10..49, the outside ≤ 8 and ≥ 51 in either axis.
    grid = OccupancyGrid.empty(6.0, 6.0, 0.1, origin=(-3.0, -3.0))
    n = 720
    angles = -math.pi + 2 * math.pi / n * np.arange(n)
    poses = [(0.33, -0.27, 0.1), (-0.81, 0.64, 1.3), (1.12, 1.07, -2.0), (-1.2, -1.3, 2.9)]
    for pose in poses:
        ranges = room_ranges(pose, angles, 2.05)
        grid.update_scan(pose, ranges, -math.pi, 2 * math.pi / n, range_max=10.0)
    p = grid.prob()
    # Inside (cells 10..49): passed through once in each of the 4 scans (the beams are 0.5° apart,
    # < 2.6 cm at 3 m, so no 0.1 m cell is skipped) → o = (2/3)^4 = 16/81, p = 16/97 ≈ 0.165
    # < 0.196 → FREE.
    assert p[10:50, 10:50] == pytest.approx(np.full((40, 40), 16 / 97), abs=1e-12)
    assert np.all(grid.states()[10:50, 10:50] == FREE)
    # The wall lines, corners included: hit in each scan → o = (7/3)^4, p = 2401/2482 ≈ 0.967.
    walls = np.concatenate([p[9, 9:51], p[50, 9:51], p[9:51, 9], p[9:51, 50]])
    assert walls == pytest.approx(np.full(walls.size, 2401 / 2482), abs=1e-12)
    # Outside the room: never touched, exactly 0.5.
    outside = np.ones(grid.shape, dtype=bool)
    outside[9:51, 9:51] = False
    assert np.all(grid.logodds[outside] == 0.0)


def test_scan_masks_are_the_update() -> None:
    grid = strip_grid()
    hit, free = grid.scan_masks((0.05, 0.55, 0.0), [1.0], 0.0, 0.0, range_max=3.0)
    assert hit.shape == free.shape == grid.shape
    assert np.argwhere(hit).tolist() == [[5, 10]]
    assert free[5, :11].all() and free.sum() == 11  # the end cell is both (hit wins on update)


# ---------------------------------------------------------------- nav_msgs/OccupancyGrid


def test_occupancy_values_round_trip() -> None:
    p = np.array([[0.05, 0.5, 0.9], [0.1955, 0.651, 0.3]])
    grid = OccupancyGrid.from_probabilities(p, 0.05, origin=(1.0, 2.0))
    values = grid.to_occupancy_values()
    # Row-major, row 0 first: 0.05 → 5; 0.5 → −1; 0.9 → 90;
    # 0.1955 → round(19.55) = 20 but 0.20 ≥ 0.196 is not free → nudged to 19;
    # 0.651 → round(65.1) = 65 but 0.65 is not > 0.65 → nudged to 66; 0.3 → unknown −1.
    assert values.dtype == np.int8
    assert values.tolist() == [5, -1, 90, 19, 66, -1]
    back = OccupancyGrid.from_occupancy_values(values, 3, 2, 0.05, (1.0, 2.0))
    assert back.geometry == grid.geometry
    assert np.array_equal(back.states(), grid.states())
    assert back.prob()[0, 2] == pytest.approx(0.9)
    assert back.prob()[0, 1] == 0.5
    with pytest.raises(ValueError):
        OccupancyGrid.from_occupancy_values([0, 101], 2, 1, 0.1)
    with pytest.raises(ValueError):
        OccupancyGrid.from_occupancy_values([0, 1, 2], 2, 1, 0.1)


# ------------------------------------------------------------------------- map_server


def test_crossings_without_padding_equal_the_padded_matrix() -> None:
    """The grid-line crossings of all beams in one flat array are those of the beams × longest
    beam matrix whose padding repeats a beam's last line (the set of cells, exactly)."""
    from pfctl.core.mapping.grid import _crossings

    rng = np.random.default_rng(6)
    for trial in range(50):
        beams, width = int(rng.integers(1, 300)), int(rng.integers(50, 400))
        counts = rng.integers(1, [2, 10, 400][trial % 3], beams)
        first = rng.integers(1, 40, beams).astype(float)
        slope = rng.uniform(-1.0, 1.0, beams)
        minor0 = rng.uniform(20.0, 40.0, beams)
        for along_x in (True, False):
            got = _crossings(first, slope, minor0, counts, width, along_x)
            k = np.minimum(
                np.arange(int(counts.max()), dtype=np.int32)[None, :],
                (counts - 1).astype(np.int32)[:, None],
            )
            minor = (k * slope[:, None] + minor0[:, None]).astype(np.int32)
            line = k + first.astype(np.int32)[:, None]
            want = minor * width + line if along_x else line * width + minor
            assert len(got) == counts.sum()
            assert set(got.tolist()) == set(want.ravel().tolist()), trial


def test_crossed_lines_lie_inside_so_the_cell_before_is_in_the_same_row() -> None:
    """scan_masks marks the cell before each crossed grid line by index − 1 (x-major beams) or
    index − width (y-major), in place of the full-grid shifted masks it used: the same cells as
    long as no crossing lies in column 0 (row 0), which the _EDGE clipping guarantees. Checked
    on random scans from inside, on the border of and outside the grid, beams along the axes
    included, and the masks are those of the shifted-mask formulation."""
    import pfctl.core.mapping.grid as grid_module

    rng = np.random.default_rng(12)
    seen: list[tuple[np.ndarray, bool]] = []
    original = grid_module._crossings

    def recording(first, slope, minor0, counts, width, along_x):  # type: ignore[no-untyped-def]
        out = original(first, slope, minor0, counts, width, along_x)
        seen.append((out.copy(), along_x))
        return out

    grid_module._crossings = recording  # type: ignore[assignment]
    try:
        for trial in range(60):
            w, h = int(rng.integers(1, 80)), int(rng.integers(1, 80))
            grid = OccupancyGrid(GridGeometry(resolution=0.05, width=w, height=h))
            x, y = rng.uniform(-1.0, w * 0.05 + 1.0), rng.uniform(-1.0, h * 0.05 + 1.0)
            if trial % 4 == 0:  # on a cell border
                x, y = round(x / 0.05) * 0.05, round(y / 0.05) * 0.05
            n = int(rng.integers(1, 400))
            ranges = rng.uniform(0.0, 6.0, n)
            ranges[rng.random(n) < 0.1] = np.inf
            increment = [2 * math.pi / n, math.pi / 2, 0.01][trial % 3]
            seen.clear()
            _, free = grid.scan_masks((x, y, rng.uniform(-4, 4)), ranges, 0.0, increment, 5.0)
            crossed = np.zeros(w * h, dtype=bool)
            shifted = np.zeros((h, w), dtype=bool)
            for cells, along_x in seen:
                if along_x:
                    assert np.all(cells % w >= 1), trial
                else:
                    assert np.all(cells // w >= 1), trial
                c = np.zeros(w * h, dtype=bool)
                c[cells] = True
                c2 = c.reshape(h, w)
                crossed |= c
                if along_x:
                    shifted[:, :-1] |= c2[:, 1:]
                else:
                    shifted[:-1, :] |= c2[1:, :]
            # every crossed cell and its shifted neighbour is free, and nothing else but the
            # segments' end cells is
            marked = crossed.reshape(h, w) | shifted
            assert np.all(free[marked]), trial
            assert np.count_nonzero(free & ~marked) <= 2 * n, trial
    finally:
        grid_module._crossings = original  # type: ignore[assignment]
