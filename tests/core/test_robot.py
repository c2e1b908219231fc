"""The Robot port: its pose algebra (composition, inverse and relative poses agree with each
other) and the observation of every scan."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from pfctl.core.robot import HeadState, LaserScan, Observation, Pose2D, wrap_angle

coord = st.floats(-50, 50, allow_nan=False)
angle = st.floats(-10, 10, allow_nan=False)
poses = st.builds(Pose2D, coord, coord, angle)


def _close(a: Pose2D, b: Pose2D) -> bool:
    return (
        math.isclose(a.x, b.x, abs_tol=1e-7)
        and math.isclose(a.y, b.y, abs_tol=1e-7)
        and abs(wrap_angle(a.theta - b.theta)) < 1e-9
    )


@given(poses, poses)
def test_relative_undoes_compose(a: Pose2D, b: Pose2D) -> None:
    assert _close(a.relative(a.compose(b)), b)
    assert _close(a.compose(a.relative(b)), b)
    assert _close(a.compose(a.inverse()), Pose2D(0.0, 0.0, 0.0))


def test_compose_moves_in_the_pose_frame_and_transform_agrees() -> None:
    robot = Pose2D(1.0, 2.0, math.pi / 2)  # facing +y
    ahead = robot.compose(Pose2D(0.5, 0.1, 0.2))
    assert (ahead.x, ahead.y, ahead.theta) == pytest.approx((0.9, 2.5, math.pi / 2 + 0.2))
    assert np.allclose(robot.transform([[0.5, 0.1]])[0], (ahead.x, ahead.y))
    assert wrap_angle(3 * math.pi) == pytest.approx(math.pi)


def test_an_observation_carries_every_scan_and_its_scan_is_the_newest() -> None:
    scans = tuple(
        LaserScan(t, 0.0, 0.1, 0.05, 20.0, np.ones(3), Pose2D(t, 0.0)) for t in (0.025, 0.05)
    )
    obs = Observation(0.05, Pose2D(0.0, 0.0), HeadState(), scans=scans)
    assert obs.scan is scans[-1]
    assert Observation(0.05, Pose2D(0.0, 0.0), HeadState()).scan is None
    with pytest.raises(TypeError, match="scans must be a tuple"):
        Observation(0.05, Pose2D(0.0, 0.0), HeadState(), scans[0])  # type: ignore[arg-type]
