"""The static scene (Leigh et al. 2015's local occupancy grid): seconds of occupancy per cell in the
fixed frame, whatever the laser's rate; and the leg detector dropping the segments on it."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pfctl.core.perception.legs.detector import LegDetector, LegParams
from pfctl.core.perception.legs.features import FEATURE_NAMES
from pfctl.core.perception.legs.static_scene import StaticScene
from pfctl.core.robot import LaserScan, Pose2D

N_BEAMS = 181
INC = math.radians(1.0)


ORIGIN = Pose2D(0.0, 0.0, 0.0)


def _scan(stamp: float, ranges: np.ndarray, pose: Pose2D = ORIGIN) -> LaserScan:
    return LaserScan(stamp, -math.pi / 2, INC, 0.05, 20.0, ranges, pose)


def _wall_and_post(post_at: float | None) -> np.ndarray:
    """A wall 4 m ahead (x = 4) and, when given, a post 2 m ahead across beams 88-92."""
    a = -math.pi / 2 + INC * np.arange(N_BEAMS)
    r = np.full(N_BEAMS, np.inf)
    ahead = np.cos(a) > 0.2
    r[ahead] = 4.0 / np.cos(a[ahead])
    if post_at is not None:
        r[88:93] = post_at
    return r


def _feed(
    scene: StaticScene, rate_hz: float, seconds: float, ranges: np.ndarray, t0: float
) -> float:
    t = t0
    for _ in range(round(seconds * rate_hz)):
        t += 1.0 / rate_hz
        scene.update(_scan(t, ranges))
    return t


@pytest.mark.parametrize("rate_hz", [7.5, 40.0])
def test_a_wall_becomes_static_after_its_seconds_whatever_the_rate(rate_hz: float) -> None:
    scene = StaticScene(static_after_s=1.0)
    wall = np.array([[4.0, 0.5]])
    t = _feed(scene, rate_hz, 0.8, _wall_and_post(None), 0.0)
    assert scene.static_fraction(wall)[0] == 0.0
    _feed(scene, rate_hz, 0.6, _wall_and_post(None), t)
    assert scene.static_fraction(wall)[0] == 1.0


@pytest.mark.parametrize("rate_hz", [3.75, 7.5])
def test_a_first_hit_holds_no_duration_so_a_slow_laser_waits_as_long(rate_hz: float) -> None:
    """A post appears in front of the wall: it has been there from the first scan that sees it
    to the last, so two scans 0.27 s apart at 3.75 Hz are 0.27 s of it (counting a whole period
    for the first hit made them 0.53 s, static at 0.5 s where 7.5 Hz needed four scans)."""
    scene = StaticScene(static_after_s=0.5)
    t = _feed(scene, rate_hz, 1.0, _wall_and_post(None), 0.0)
    post = np.array([[2.0, 0.0]])
    t = _feed(scene, rate_hz, 0.4, _wall_and_post(2.0), t)
    assert scene.static_fraction(post)[0] == 0.0
    _feed(scene, rate_hz, 0.3, _wall_and_post(2.0), t)
    assert scene.static_fraction(post)[0] == 1.0


def test_a_passer_by_seen_through_afterwards_never_becomes_static() -> None:
    scene = StaticScene(static_after_s=1.0)
    t = 0.0
    for _ in range(5):  # a leg at 2 m for 0.4 s, then the wall behind it for 0.6 s, again
        t = _feed(scene, 10.0, 0.4, _wall_and_post(2.0), t)
        t = _feed(scene, 10.0, 0.6, _wall_and_post(None), t)
    assert scene.static_fraction(np.array([[2.0, 0.0]]))[0] == 0.0
    assert scene.static_fraction(np.array([[4.0, 0.0]]))[0] == 1.0


def test_returns_kept_out_do_not_build_the_scene() -> None:
    scene = StaticScene(static_after_s=1.0)
    keep_out = np.zeros(N_BEAMS, dtype=bool)
    keep_out[88:93] = True
    t = 0.0
    for _ in range(30):
        t += 0.1
        scene.update(_scan(t, _wall_and_post(2.0)), keep_out)
    assert scene.static_fraction(np.array([[2.0, 0.0]]))[0] == 0.0


def test_the_window_follows_the_laser_and_forgets_what_it_leaves() -> None:
    scene = StaticScene(static_after_s=0.5)
    t = _feed(scene, 10.0, 1.0, _wall_and_post(None), 0.0)
    assert scene.static_fraction(np.array([[4.0, 0.0]]))[0] == 1.0
    far = Pose2D(100.0, 0.0, 0.0)
    scene.update(_scan(t + 0.1, np.full(N_BEAMS, np.inf), far))
    assert scene.static_fraction(np.array([[4.0, 0.0]]))[0] == 0.0
    # ... and the scene there is built in the same frame: the wall 4 m ahead of the new pose
    _feed(scene, 10.0, 1.0, _wall_and_post(None), t + 0.1)
    scene_far = StaticScene(static_after_s=0.5)
    for k in range(10):
        scene_far.update(_scan(0.1 * (k + 1), _wall_and_post(None), far))
    assert scene_far.static_fraction(np.array([[104.0, 0.0]]))[0] == 1.0


class _EveryoneIsALeg:
    """A model that scores every segment 0.9."""

    def predict_proba(self, features: np.ndarray) -> np.ndarray:
        return np.full(len(features), 0.9)


def test_the_detector_drops_legs_on_the_static_scene_but_not_a_tracked_persons() -> None:
    params = LegParams(static_after_s=1.0, history_scans=1, single_leg_probability=0.5)
    ranges = _wall_and_post(2.0)
    detector = LegDetector(_EveryoneIsALeg(), params)  # type: ignore[arg-type]
    first = detector.detect(_scan(0.1, ranges))
    assert any(abs(leg.x - 2.0) < 0.2 for leg in first.legs)
    t = 0.1
    for _ in range(15):
        t += 0.1
        found = detector.detect(_scan(t, ranges))
    assert not any(abs(leg.x - 2.0) < 0.2 for leg in found.legs)
    tracked = np.array([[2.05, 0.0]])
    beside = detector.detect(_scan(t + 0.1, ranges), tracked)
    assert any(abs(leg.x - 2.0) < 0.2 for leg in beside.legs)
    off = LegDetector(_EveryoneIsALeg(), LegParams(history_scans=1))  # type: ignore[arg-type]
    for k in range(15):
        found = off.detect(_scan(0.1 * (k + 1), ranges))
    assert any(abs(leg.x - 2.0) < 0.2 for leg in found.legs)


class _ByRange:
    """P(leg) 0.3 for segments nearer than 2.5 m, 0.9 for the others (a stand-in forest)."""

    def predict_proba(self, features: np.ndarray) -> np.ndarray:
        near = features[:, FEATURE_NAMES.index("distance")] < 2.5
        return np.where(near, 0.3, 0.9)


def test_weak_candidates_are_segments_between_the_two_thresholds_paired_as_legs() -> None:
    """Dual thresholds: with ``weak_probability`` 0.25 the 0.3 segments (two posts 0.2 m apart
    at 2 m) that make no candidate at ``probability`` 0.5 are one weak candidate between them;
    the 0.9 segment at 4 m stays a candidate as before; off (1.0) there is none."""
    ranges = np.full(N_BEAMS, np.inf)
    ranges[84:88] = ranges[94:98] = 2.0
    ranges[40:44] = 4.0
    scan = _scan(0.1, ranges)
    on = LegParams(history_scans=1, probability=0.5, weak_probability=0.25)
    found = LegDetector(_ByRange(), on).detect(scan)  # type: ignore[arg-type]
    assert [len(c.legs) for c in found.weak] == [2]
    (weak,) = found.weak
    assert abs(weak.x - 2.04) < 0.05 and abs(weak.y) < 0.05 and weak.probability == 0.3
    assert all(c.x > 0 and abs(math.hypot(c.x, c.y) - 4.0) < 0.2 for c in found.people)
    assert len(found.people) == 1
    off = LegDetector(_ByRange(), LegParams(history_scans=1, probability=0.5))  # type: ignore[arg-type]
    assert off.detect(scan).weak == () and off.detect(scan).people == found.people


def test_static_after_must_be_positive() -> None:
    with pytest.raises(ValueError, match="static_after_s"):
        StaticScene(0.0)
