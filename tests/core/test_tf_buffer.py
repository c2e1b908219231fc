"""The recorded-tf buffer: chains, inverse lookups, interpolation and clear refusals."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pfctl.core.robot import Pose2D
from pfctl.core.tf_buffer import (
    TransformBuffer,
    TransformLookupError,
    quaternion_from_yaw,
    quaternion_matrix,
    yaw_from_quaternion,
)


def _buffer() -> TransformBuffer:
    tf = TransformBuffer()
    for t, x in ((0.0, 0.0), (1.0, 1.0)):  # odom → base drives 1 m along x in 1 s
        tf.add("odom", "base", t, (x, 0.0, 0.0), quaternion_from_yaw(0.5 * t))
        tf.add("map", "odom", t, (2.0, 3.0, 0.0), quaternion_from_yaw(math.pi / 2))
    tf.add("base", "laser", 0.0, (0.2, 0.0, 0.3), quaternion_from_yaw(0.0), static=True)
    return tf


def test_chain_matches_composed_planar_poses() -> None:
    tf = _buffer()
    got = tf.lookup_pose2d("map", "laser", 1.0)
    want = Pose2D(2, 3, math.pi / 2).compose(Pose2D(1, 0, 0.5)).compose(Pose2D(0.2, 0, 0))
    assert got.x == pytest.approx(want.x) and got.y == pytest.approx(want.y)
    assert got.theta == pytest.approx(want.theta)
    assert tf.lookup("map", "laser", 1.0)[2, 3] == pytest.approx(0.3)


def test_interpolates_between_samples_and_inverts() -> None:
    tf = _buffer()
    mid = tf.lookup_pose2d("odom", "base", 0.5)
    assert (mid.x, mid.y, mid.theta) == pytest.approx((0.5, 0.0, 0.25))
    there = tf.lookup("map", "base", 0.5)
    back = tf.lookup("base", "map", 0.5)
    np.testing.assert_allclose(there @ back, np.eye(4), atol=1e-12)


def test_static_edge_holds_at_any_time_and_frames_are_listed() -> None:
    tf = _buffer()
    assert tf.lookup_pose2d("base", "laser", 99.0).x == pytest.approx(0.2)
    assert tf.frames == {"map", "odom", "base", "laser"}


def test_refuses_to_extrapolate_or_join_unconnected_frames() -> None:
    tf = _buffer()
    with pytest.raises(TransformLookupError, match=r"recorded from 0\.000 to 1\.000"):
        tf.lookup("map", "base", 5.0)
    tf.add("world", "camera", 0.0, (0, 0, 0), (0, 0, 0, 1))
    with pytest.raises(TransformLookupError, match="not connected"):
        tf.lookup("map", "camera", 0.0)


@pytest.mark.parametrize("yaw", [0.0, 0.3, -2.0, math.pi - 1e-9])
def test_yaw_and_quaternion_round_trip(yaw: float) -> None:
    x, y, z, w = quaternion_from_yaw(yaw)
    assert yaw_from_quaternion(x, y, z, w) == pytest.approx(yaw)
    c, s = math.cos(yaw), math.sin(yaw)
    assert np.allclose(quaternion_matrix(x, y, z, w)[:2, :2], [[c, -s], [s, c]])
