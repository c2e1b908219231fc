"""SLAM-like noise on a trinary map: seeded, never opens a wall, adds what it says."""

from __future__ import annotations

import numpy as np

from pfctl.core.mapping.grid import FREE, OCCUPIED, UNKNOWN
from pfctl.core.mapping.house import HouseLayout, Region
from pfctl.core.mapping.noise import SlamNoise, slam_noise
from pfctl.core.mapping.walls import rasterize_house


def _states() -> np.ndarray:
    room = Region("room", ((0, 0), (6, 0), (6, 4), (0, 4)))
    return rasterize_house(HouseLayout(regions=(room,)), 0.05).states()


def test_the_same_seed_gives_the_same_noise() -> None:
    states = _states()
    a = slam_noise(states, 0.05, np.random.default_rng(3))
    b = slam_noise(states, 0.05, np.random.default_rng(3))
    c = slam_noise(states, 0.05, np.random.default_rng(4))
    assert np.array_equal(a, b) and not np.array_equal(a, c)


def test_noise_never_frees_a_wall_and_adds_speckle_bumps_and_unknown_patches() -> None:
    states = _states()
    noisy = slam_noise(states, 0.05, np.random.default_rng(0))
    assert np.all(noisy[states == OCCUPIED] == OCCUPIED)
    assert np.all(noisy[states == UNKNOWN] == UNKNOWN)
    was_free = states == FREE
    assert (noisy[was_free] == OCCUPIED).sum() > 0.002 * was_free.sum()
    assert (noisy[was_free] == UNKNOWN).sum() > 0
    quiet = slam_noise(states, 0.05, np.random.default_rng(0), SlamNoise(0.0, 0.0, 0.0))
    assert np.array_equal(quiet, states)
