"""FastLaser: an empty room's walls and a person's two legs appear where they are."""

import numpy as np
import pytest

from pfctl.backends.pybullet.laser import FastLaser, LaserSpec
from pfctl.core.robot import Pose2D

pytestmark = pytest.mark.sim

ROOM = np.array([[-3, -3, 3, -3], [3, -3, 3, 3], [3, 3, -3, 3], [-3, 3, -3, -3]], dtype=float)


def test_empty_room_matches_walls_within_noise() -> None:
    laser = FastLaser(ROOM, LaserSpec(noise_std=0.01), seed=1)
    scan = laser.scan(Pose2D(0.0, 0.0, 0.3), np.empty((0, 3)), 0.0)
    pts = scan.points()
    assert len(pts) == 1081
    dist_to_wall = 3.0 - np.max(np.abs(pts), axis=1)
    assert np.all(np.abs(dist_to_wall) < 0.05)


def test_legs_two_metres_ahead_are_two_short_arcs() -> None:
    laser = FastLaser(ROOM, LaserSpec())
    legs = np.array([[2.167, 0.12, 0.06], [2.167, -0.12, 0.06]])
    scan = laser.scan(Pose2D(0.0, 0.0, 0.0), legs, 0.0)
    near = scan.ranges < 2.5
    runs = np.flatnonzero(np.diff(near.astype(int)) == 1)
    assert len(runs) == 2
    pts = scan.points()
    hit = pts[np.hypot(pts[:, 0] - 2.167, pts[:, 1]) < 0.3]
    for leg in legs:
        d = np.hypot(hit[:, 0] - leg[0], hit[:, 1] - leg[1])
        assert np.sum(np.abs(d - 0.06) < 1e-6) >= 3


def test_out_of_range_is_inf() -> None:
    laser = FastLaser(np.empty((0, 4)), LaserSpec())
    scan = laser.scan(Pose2D(0.0, 0.0, 0.0), np.empty((0, 3)), 0.0)
    assert np.all(np.isinf(scan.ranges))
