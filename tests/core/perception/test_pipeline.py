"""The single-leg case of the perception (issue 22, item 5) on a constructed scan and camera
detection: a target standing side-on shows the laser one segment for both legs, scored below the
leg threshold; beside a person the camera sees it becomes a person candidate at the fused
position (so Algorithm 2's "has legs" holds for her track), while a lone leg-like segment far
from any camera detection (a table's leg) stays no one."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from pfctl.core.mapping.grid import GridGeometry
from pfctl.core.perception.legs.detector import (
    LegDetections,
    LegDetector,
    LegParams,
    PersonCandidate,
)
from pfctl.core.perception.pipeline import (
    CAMERA_MAX_AGE,
    SINGLE_LEG_DISTANCE,
    Perception,
    in_stamp_order,
)
from pfctl.core.perception.tracking import MultiPersonTracker, TrackStatus
from pfctl.core.perception.vision import PersonDetection
from pfctl.core.robot import (
    CameraInfo,
    HeadState,
    LaserScan,
    Observation,
    Pose2D,
    RgbdFrame,
)

#: Where she stands side-on, and a table's leg 2 m to her right.
HER = (3.0, 0.0)
TABLE_LEG = (2.5, -2.0)
#: The forest's score of both segments: below the leg threshold (0.5), as her side-on segment
#: is scored in the simulated house (0.3-0.6 per scan).
SCORE = 0.4


class FixedScore:
    """A leg model that gives every segment the same P(leg)."""

    def predict_proba(self, features: np.ndarray) -> np.ndarray:
        return np.full(len(features), SCORE)


class SeesAt:
    """A camera person detector that sees one person at ``xy`` (or no one)."""

    def __init__(self, xy: tuple[float, float] | None) -> None:
        self.xy = xy

    def detect(self, frame: RgbdFrame) -> list[PersonDetection]:
        if self.xy is None:
            return []
        return [PersonDetection((0, 0, 1, 1), (self.xy[0], self.xy[1], 1.0))]


def _scan(stamp: float) -> LaserScan:
    """A 360° scan from the origin that sees two 0.16 m wide arcs (one segment each): her two
    legs as one, side-on, and the table's leg; nothing else within range."""
    inc = math.radians(0.25)
    angles = -math.pi + inc * np.arange(1440)
    ranges = np.full(len(angles), np.inf)
    for cx, cy in (HER, TABLE_LEG):
        d, bearing = math.hypot(cx, cy), math.atan2(cy, cx)
        half = math.asin(0.08 / d)
        on = np.abs(angles - bearing) <= half
        ranges[on] = d - 0.06 * np.cos((angles[on] - bearing) / half * math.pi / 2)
    return LaserScan(stamp, -math.pi, inc, 0.05, 20.0, ranges, Pose2D(0.0, 0.0, 0.0))


def _frame(stamp: float) -> RgbdFrame:
    """A frame from a camera at the origin looking along +x (contents unused by the stub)."""
    rotation = np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])
    info = CameraInfo(320, 240, (277.0, 0.0, 160.0, 0.0, 277.0, 120.0, 0.0, 0.0, 1.0))
    return RgbdFrame(
        stamp,
        np.zeros((240, 320, 3), np.uint8),
        np.full((240, 320), np.inf, np.float32),
        info,
        (0.0, 0.0, 1.0),
        rotation,
    )


def _perception(camera_xy: tuple[float, float] | None) -> Perception:
    legs = LegDetector(FixedScore(), LegParams(history_scans=1))  # type: ignore[arg-type]
    return Perception(legs, MultiPersonTracker(), detector=SeesAt(camera_xy))


def _run(perception: Perception, seconds: float = 1.0, frame_lag: float = 0.025) -> None:
    """Frames at 10 Hz, each followed ``frame_lag`` s later by a scan."""
    for k in range(round(seconds * 10)):
        t = 0.1 * k
        perception.on_frame(_frame(t))
        perception.on_scan(_scan(t + frame_lag))


def test_both_segments_are_lone_legs_and_alone_no_one() -> None:
    found = _perception(None).on_scan(_scan(0.0))
    assert found.legs == () and found.people == ()
    lone = sorted((round(leg.x, 1), round(leg.y, 1)) for leg in found.lone_legs)
    assert lone == [(2.5, -2.0), (3.0, 0.0)]
    assert all(leg.probability == pytest.approx(SCORE) for leg in found.lone_legs)


def test_a_lone_leg_beside_a_camera_person_is_her_candidate_and_the_table_leg_no_one() -> None:
    camera_xy = (HER[0] + 0.2, HER[1] + 0.15)  # the camera's position is 0.25 m off
    perception = _perception(camera_xy)
    _run(perception)
    tracks = perception.tracks(confirmed_only=False)
    assert len(tracks) == 1  # hers: the table's leg made no track
    (track,) = tracks
    assert perception.has_legs(track.id)  # Algorithm 2 need not wait for legs
    # fused: much nearer the leg (laser noise 0.05 m) than the camera (0.15 m)
    assert math.dist(track.position, HER) < 0.1 < math.dist(track.position, camera_xy)


def test_without_the_leg_her_track_has_no_legs() -> None:
    """The same camera person without the fusion's leg (too far from it): no legs."""
    far = (HER[0] + SINGLE_LEG_DISTANCE + 0.2, HER[1])
    perception = _perception(far)
    _run(perception)
    tracks = perception.tracks(confirmed_only=False)
    assert len(tracks) == 1 and not perception.has_legs(tracks[0].id)


def test_a_stale_camera_detection_makes_no_candidate() -> None:
    perception = _perception((HER[0] + 0.1, HER[1]))
    _run(perception, frame_lag=CAMERA_MAX_AGE + 0.02)
    (track,) = perception.tracks(confirmed_only=False)
    assert not perception.has_legs(track.id)


class PersonAhead:
    """A leg detector that finds one person 2 m ahead of each scan's laser pose (no static-scene
    filter, as the shipped detector by default)."""

    scene = None

    def detect(
        self, scan: LaserScan, tracked: np.ndarray | None = None, classified: object = None
    ) -> LegDetections:
        x, y = scan.pose.x + 2.0, scan.pose.y
        return LegDetections(scan.stamp, (), (PersonCandidate(x, y, 0.9, ()),))


class CountingTracker(MultiPersonTracker):
    """The tracker, noting each update's sensor and stamp."""

    def __init__(self) -> None:
        super().__init__()
        self.updates: list[tuple[str, float]] = []

    def update(self, sensor: str, detections, fov, t: float):  # type: ignore[no-untyped-def,override]
        self.updates.append((sensor, t))
        return super().update(sensor, detections, fov, t)


def _tick(t: float, frame: bool) -> Observation:
    """A 10 Hz tick's observation: the four 40 Hz scans up to ``t``, the laser moving along x
    at 0.4 m/s; with ``frame``, a camera frame stamped between the second and third scan."""
    scans = tuple(
        replace(_scan(s), pose=Pose2D(0.4 * s, 0.0, 0.0))
        for s in t - np.array([0.075, 0.05, 0.025, 0])
    )
    return Observation(
        t, Pose2D(0.4 * t, 0.0), HeadState(), scans=scans, rgbd=_frame(t - 0.04) if frame else None
    )


def test_each_scan_of_an_observation_updates_the_tracker_at_its_stamp_frame_among_them() -> None:
    tracker = CountingTracker()
    perception = Perception(PersonAhead(), tracker, detector=SeesAt(None))  # type: ignore[arg-type]
    obs = _tick(0.1, frame=True)
    assert in_stamp_order(obs) == [obs.scans[0], obs.scans[1], obs.rgbd, obs.scans[2], obs.scans[3]]
    perception.on_observation(obs)
    assert [sensor for sensor, _ in tracker.updates] == [
        "laser",
        "laser",
        "camera",
        "laser",
        "laser",
    ]
    stamps = [t for _, t in tracker.updates]
    np.testing.assert_allclose(stamps, [0.025, 0.05, 0.06, 0.075, 0.1])


def test_a_track_is_confirmed_after_confirm_s_whatever_the_scans_per_tick() -> None:
    """Four scans per tick give four updates, but the track is confirmed only once its
    detections span ``confirm_s`` (0.2 s): at the third tick, as with one scan per tick, not
    within the first (``confirm_hits`` scans at 40 Hz are 75 ms); at the newest scan's position."""
    tracker = CountingTracker()
    assert tracker.params.confirm_s == pytest.approx(0.2)
    perception = Perception(PersonAhead(), tracker)  # type: ignore[arg-type]
    statuses = []
    for t in (0.1, 0.2, 0.3):
        perception.on_observation(_tick(t, frame=False))
        (track,) = tracker.tracks()
        statuses.append(track.status)
    assert len(tracker.updates) == 12
    assert statuses == [TrackStatus.TENTATIVE, TrackStatus.TENTATIVE, TrackStatus.CONFIRMED]
    assert perception.tracks() == [track]
    assert track.position == pytest.approx((0.4 * 0.3 + 2.0, 0.0), abs=0.02)


def test_with_the_static_scene_filter_a_person_standing_still_keeps_her_track() -> None:
    """Her cells stay occupied for 3 s, longer than ``static_after_s``: as a tracked person her
    segment is spared (and kept out of the scene), so her track is still seen at the end."""
    legs = LegDetector(FixedScore(), LegParams(history_scans=1, static_after_s=0.5))  # type: ignore[arg-type]
    perception = Perception(legs, MultiPersonTracker(), detector=SeesAt(HER))
    _run(perception, seconds=3.0)
    (track,) = perception.tracks()
    assert track.status is TrackStatus.CONFIRMED and track.last_seen == pytest.approx(2.925)
    assert math.dist(track.position, HER) < 0.1


def test_no_leg_counts_inside_an_occupied_cell_of_the_static_map() -> None:
    """Both segments make single-leg candidates (thresholds lowered to the forest's score);
    with the static map's occupied cells given, the one inside a wall — a door jamb's end face,
    as traced in the shipped house — is dropped, legs and candidate, and starts no track."""
    params = LegParams(history_scans=1, probability=0.3, single_leg_probability=0.3)
    geometry = GridGeometry(0.05, 160, 160, (-4.0, -4.0))
    occupied = np.zeros(geometry.shape, dtype=bool)
    rows, cols = geometry.world_to_cell(TABLE_LEG)
    occupied[rows - 2 : rows + 3, cols - 2 : cols + 3] = True  # a 0.25 m wall end there

    def tracked(walls: tuple[GridGeometry, np.ndarray] | None) -> list[tuple[float, float]]:
        legs = LegDetector(FixedScore(), params)  # type: ignore[arg-type]
        perception = Perception(legs, MultiPersonTracker(), occupied=walls)
        for k in range(10):
            found = perception.on_scan(_scan(0.1 * k))
        if walls is not None:
            assert all(math.dist((c.x, c.y), TABLE_LEG) > 0.3 for c in found.people)
            assert all(math.dist((g.x, g.y), TABLE_LEG) > 0.3 for g in found.legs)
        return sorted(
            (round(t.x, 1), round(t.y, 1)) for t in perception.tracks(confirmed_only=False)
        )

    assert tracked(None) == [(2.5, -2.0), (3.0, 0.0)]  # no map: the wall's "leg" is someone
    assert tracked((geometry, occupied)) == [(3.0, 0.0)]
