"""Leg evidence over several scans (core/leg_evidence.py) and its use by the detector and by
``pfctl legs evaluate --history``."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from pfctl.app.leg_data import real_sequences, sequences_dataset
from pfctl.app.leg_models import load_leg_model
from pfctl.core.perception.legs.detector import LegDetector, LegParams
from pfctl.core.perception.legs.evidence import LegEvidence
from pfctl.core.perception.legs.training import Score, evaluate_sequence, train_forest
from pfctl.core.robot import LaserScan, Pose2D

LEGS = Path(__file__).resolve().parents[5] / "shared" / "data" / "legs"


def test_mean_follows_a_segment_and_a_newcomer_keeps_its_own_probability() -> None:
    ev = LegEvidence(history=3)
    assert ev.update([[1.0, 0.0]], [0.9]).tolist() == [0.9]
    # The same segment moved 0.1 m, and a newcomer 2 m away.
    out = ev.update([[1.1, 0.0], [3.0, 0.0]], [0.3, 0.2])
    np.testing.assert_allclose(out, [0.6, 0.2])
    out = ev.update([[1.2, 0.0], [3.0, 0.1]], [0.3, 0.8])
    np.testing.assert_allclose(out, [0.5, 0.5])
    # Only the last three scans count.
    out = ev.update([[1.3, 0.0]], [0.0])
    np.testing.assert_allclose(out, [0.2])


def test_segments_beyond_the_radius_start_new_tracks_and_reset_forgets() -> None:
    ev = LegEvidence(history=5, radius=0.35)
    ev.update([[1.0, 0.0]], [1.0])
    np.testing.assert_allclose(ev.update([[1.5, 0.0]], [0.0]), [0.0])  # 0.5 m: another object
    ev.update([[1.5, 0.0]], [1.0])
    ev.reset()
    np.testing.assert_allclose(ev.update([[1.5, 0.0]], [0.2]), [0.2])
    assert ev.update(np.empty((0, 2)), np.empty(0)).shape == (0,)


def test_each_segment_inherits_at_most_one_track() -> None:
    ev = LegEvidence(history=2)
    ev.update([[1.0, 0.0]], [1.0])
    out = ev.update([[1.05, 0.0], [0.95, 0.0]], [0.0, 0.0])
    assert sorted(out.tolist()) == [0.0, 0.5]


def test_bad_arguments() -> None:
    with pytest.raises(ValueError, match="at least 1"):
        LegEvidence(0)
    with pytest.raises(ValueError, match="2 positions but 1"):
        LegEvidence(2).update([[0, 0], [1, 1]], [0.5])


def _arc_scan(stamp: float, centre: tuple[float, float]) -> LaserScan:
    """A 270° scan of a wall at 4 m with one leg (6 cm radius) at ``centre``."""
    angles = np.radians(np.arange(-135, 135, 0.25))
    r = np.full(len(angles), 4.0)
    cx, cy = centre
    d = np.array([np.cos(angles), np.sin(angles)])
    b = -(d[0] * cx + d[1] * cy)
    disc = b**2 - (cx**2 + cy**2 - 0.06**2)
    hit = disc >= 0
    r[hit] = np.minimum(r[hit], -b[hit] - np.sqrt(disc[hit]))
    return LaserScan(
        stamp, float(angles[0]), float(np.radians(0.25)), 0.05, 10.0, r, Pose2D(0, 0, 0)
    )


def test_detector_with_history_agrees_with_one_scan_on_a_still_scene() -> None:
    model = load_leg_model(None)
    single = LegDetector(model, LegParams())
    smoothed = LegDetector(model, LegParams(history_scans=5))
    scan = _arc_scan(0.0, (1.5, 0.2))
    first = single.detect(scan)
    for k in range(3):  # the same scan again and again: the mean is the scan's own P
        again = smoothed.detect(_arc_scan(0.1 * k, (1.5, 0.2)))
        assert [(leg.x, leg.y) for leg in again.legs] == [(leg.x, leg.y) for leg in first.legs]
        np.testing.assert_allclose(
            [leg.probability for leg in again.legs], [leg.probability for leg in first.legs]
        )
    smoothed.reset()
    assert smoothed.evidence is not None and smoothed.evidence.tracks == 0


@pytest.mark.slow
@pytest.mark.skipif(not LEGS.is_dir(), reason=f"no real leg bags in {LEGS}")
def test_history_raises_precision_and_recall_on_held_out_real_bags() -> None:
    """Leave one bag (one laser of negative_2) out, a small forest on the rest: averaging P(leg)
    over 10 scans finds more legs and calls fewer non-legs legs than one scan at a time."""
    seqs = dict(real_sequences(LEGS, LegParams()))
    total = {1: Score(0, 0, 0, 0), 10: Score(0, 0, 0, 0)}
    for held_out in seqs:
        train = sequences_dataset([(g, s) for g, s in seqs.items() if g != held_out])
        model = train_forest(train, seed=0, n_trees=16)
        for history in total:
            total[history] += evaluate_sequence(model, seqs[held_out], 0.5, history)[0]
    one, ten = total[1], total[10]
    assert ten.precision > one.precision + 0.05, (one, ten)
    assert ten.recall > one.recall, (one, ten)
    assert ten.f1 > one.f1 + 0.03, (one, ten)
