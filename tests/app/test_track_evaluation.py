"""CLEAR-MOT of the shipped perception on the shared annotated real bag (Leigh et al.'s
``general_tracking_moving_1.bag``: a moving robot among people, 7.5 Hz), at its native rate, at
half the rate and with each scan spread to five times the rate, scored where the bag is
annotated (:data:`BEARINGS`) unless said; and the thinning itself.

The bag is read once per module (about 5 s: its ``/tf``); each scoring then replays its 873 scans
(2-4 s), or the annotated stretch of them. Skipped when ``../shared/data/legs`` is absent.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from pfctl.app.perception import build_perception
from pfctl.app.track_evaluation import (
    TrackEvaluation,
    evaluation_mission,
    score_scans,
    thinned,
)
from pfctl.bags.annotations import AnnotatedPeople, read_annotations
from pfctl.bags.replay import open_replay
from pfctl.core.robot import LaserScan, Pose2D
from pfctl.mission import Mission

ROOT = Path(__file__).resolve().parents[2]
BAG = ROOT.parent / "shared" / "data" / "legs" / "general_tracking_moving_1.bag"
GROUND_TRUTH = "/ground_truth_people_tracks"


@pytest.fixture(scope="module")
def annotated() -> tuple[list[LaserScan], list[AnnotatedPeople]]:
    if not BAG.is_file():
        pytest.skip(f"{BAG} is absent (the shared real leg data)")
    source = open_replay(BAG, scan_topic="/scan", frame="odom", camera=False)
    with source.bag:
        annotations = read_annotations(source.bag, GROUND_TRUTH, source.scan_topic)
        scans = [s for s in source.stream() if isinstance(s, LaserScan)]
    return scans, annotations


#: The settings for real lasers (benchmarks/README.md, "People tracking on a real annotated
#: bag"): the static-scene filter, a lower leg threshold, and dual thresholds (weak candidates
#: keep tracks going, a track is confirmed by two detections 0.2 s apart).
REAL_LASER = {
    "perception": {
        "legs": {
            "static_after_s": 0.5,
            "history_scans": 1,
            "probability": 0.2,
            "weak_probability": 0.25,
        }
    },
    "tracking": {
        "process_noise": 1.0,
        "laser_noise": 0.15,
        "max_coast_s": 3.0,
        "confirm_hits": 2,
    },
}

#: Where the bag's people are annotated, bearings in the laser's frame (radians): the benchmark's
#: own CLEAR-MOT script scores this bag within −80° to 12° only (angusleigh/leg_tracker_benchmarks,
#: ``clear_mot/launch/tracking_benchmarks/general_tracking_moving_joint_leg.launch``); people
#: walking beside and behind the robot, outside it, are not annotated.
BEARINGS = (math.radians(-80.0), math.radians(12.0))


def _mission(settings: dict[str, Any] | None) -> Mission:
    """The default mission, with ``settings`` (mission sections) when given."""
    if settings is None:
        return evaluation_mission(None)
    data = evaluation_mission(None).model_dump(mode="json", exclude_unset=True)
    return Mission.model_validate({**data, **settings})


def _score(
    annotated: tuple[list[LaserScan], list[AnnotatedPeople]],
    decimate: int = 1,
    spread: int = 1,
    warm_up: float | None = None,
    settings: dict[str, Any] | None = None,
    bearings: tuple[float, float] | None = BEARINGS,
) -> TrackEvaluation:
    """The perception's score (shipped defaults, or ``settings``) within ``bearings`` (default:
    the annotated wedge); with ``warm_up`` only the scans from that many seconds before the
    first annotation to the last one are replayed."""
    scans, annotations = annotated
    if warm_up is not None:
        t0, t1 = annotations[0].time - warm_up, annotations[-1].time + 0.1
        scans = [s for s in scans if t0 <= s.stamp <= t1]
    perception = build_perception(_mission(settings))
    return score_scans(
        scans, annotations, perception, decimate=decimate, spread=spread, bearings=bearings
    )


@pytest.fixture(scope="module")
def native(annotated: tuple[list[LaserScan], list[AnnotatedPeople]]) -> TrackEvaluation:
    return _score(annotated, bearings=None)


def test_every_annotation_of_the_real_bag_is_scored_at_its_scan(native: TrackEvaluation) -> None:
    r = native.result
    assert (r.ground_truth, r.frames, native.unpaired) == (153, 123, 0)


def test_the_shipped_perception_holds_its_floor_on_the_real_annotated_bag(
    native: TrackEvaluation,
) -> None:
    """A floor, not the goal: the shipped detector finds few of these people (see
    benchmarks/README.md, "People tracking on a real annotated bag")."""
    r = native.result
    assert r.mota >= -0.05, r
    assert r.id_switches <= 2, r
    assert r.motp <= 0.15, r


def test_the_real_laser_settings_hold_their_floor_where_the_real_bag_is_annotated(
    annotated: tuple[list[LaserScan], list[AnnotatedPeople]],
) -> None:
    """The real-laser settings (:data:`REAL_LASER`) scored as the benchmark scores this bag
    (within :data:`BEARINGS`): MOTA at least 25 % (Leigh et al. report 10.2 % for their joint
    leg tracker, counting false positives at unannotated scans too), and the dual thresholds
    are what lift it (without them, with three hits to confirm, it scores 4 points less)."""
    r = _score(annotated, settings=REAL_LASER).result
    assert r.ground_truth == 133, r
    assert r.mota >= 0.25, r
    assert r.id_switches <= 2, r
    assert r.motp <= 0.15, r
    legs, tracking = REAL_LASER["perception"]["legs"], REAL_LASER["tracking"]
    single = {
        "perception": {"legs": {**legs, "weak_probability": 1.0}},
        "tracking": {**tracking, "confirm_hits": 3},
    }
    assert _score(annotated, settings=single).result.mota < r.mota - 0.04


@pytest.mark.parametrize(
    ("settings", "bearings"), [(None, None), (REAL_LASER, BEARINGS)], ids=["shipped", "real-laser"]
)
@pytest.mark.parametrize(
    ("decimate", "spread"), [(2, 1), pytest.param(1, 5, marks=pytest.mark.slow)]
)
def test_half_the_rate_or_five_times_it_scores_within_5_points_of_the_native_rate(
    annotated: tuple[list[LaserScan], list[AnnotatedPeople]],
    decimate: int,
    spread: int,
    settings: dict[str, Any] | None,
    bearings: tuple[float, float] | None,
) -> None:
    """3.75 Hz, and 37.5 Hz (each scan five times, stamps spread): the annotated stretch of the
    bag from 5 s before its first annotation (the 37.5 Hz replay takes about 7 s); the shipped
    defaults over the whole view (within :data:`BEARINGS` they find 7 of the 133 people at 7.5
    Hz and none at 3.75 Hz: 5.3 points), the real-laser settings within :data:`BEARINGS`.
    With the real-laser settings: there five copies of a scan confirmed
    clutter within one real scan period while confirmation counted hits (5.9 points below
    native; ``confirm_s`` counts seconds), and at 3.75 Hz the static-scene filter called a
    standing person's cells static after two scans while counting a whole scan period for a
    cell's first hit (13 points below native)."""
    native = _score(annotated, warm_up=5.0, settings=settings, bearings=bearings)
    other = _score(annotated, decimate, spread, warm_up=5.0, settings=settings, bearings=bearings)
    assert abs(other.result.mota - native.result.mota) <= 0.05, (other.result, native.result)


def _scan(stamp: float) -> LaserScan:
    return LaserScan(stamp, -1.0, 0.5, 0.1, 10.0, np.full(5, np.inf), Pose2D(0.0, 0.0, 0.0))


def test_thinning_keeps_every_nth_scan_and_spreads_copies_up_to_the_next() -> None:
    scans = [_scan(0.1 * k) for k in range(5)]
    out = [(round(s.stamp, 6), first) for s, first in thinned(scans, 2, 4)]
    assert out == [
        (0.0, True), (0.05, False), (0.1, False), (0.15, False),
        (0.2, True), (0.25, False), (0.3, False), (0.35, False),
        (0.4, True),
    ]  # fmt: skip
    with pytest.raises(ValueError, match="≥ 1"):
        list(thinned(scans, 0, 1))
