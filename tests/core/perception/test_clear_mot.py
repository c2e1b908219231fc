"""CLEAR-MOT on hand-made sequences: a switch, a miss, a false positive, the continuity rule."""

from __future__ import annotations

import math

import pytest

from pfctl.core.perception.clear_mot import ClearMot


def test_a_perfect_sequence_scores_mota_1_and_the_mean_distance() -> None:
    mot = ClearMot(radius=0.75)
    mot.add(0.0, [1, 2], [(0, 0), (3, 0)], [10, 20], [(0.1, 0), (3, 0.3)])
    mot.add(0.1, [1, 2], [(0, 1), (3, 1)], [10, 20], [(0, 1.1), (3, 1.1)])
    r = mot.result()
    assert (r.ground_truth, r.matches, r.misses, r.false_positives, r.id_switches) == (
        4, 4, 0, 0, 0,
    )  # fmt: skip
    assert r.mota == 1.0
    assert r.motp == pytest.approx((0.1 + 0.3 + 0.1 + 0.1) / 4)


def test_a_person_beyond_the_radius_is_a_miss_and_the_track_a_false_positive() -> None:
    mot = ClearMot(radius=0.5)
    score = mot.add(0.0, [1], [(0, 0)], [7], [(0.6, 0)])
    assert score.misses == (1,) and score.false_positives == (7,) and score.matches == ()
    r = mot.result()
    assert r.mota == pytest.approx(1 - 2 / 1)
    assert math.isnan(r.motp)


def test_a_person_matched_to_another_track_than_last_time_is_one_id_switch() -> None:
    mot = ClearMot()
    mot.add(0.0, [1], [(0, 0)], [5], [(0, 0)])
    mot.add(0.1, [1], [(0, 0)], [6], [(0, 0)])  # track 5 gone, 6 takes over: a switch
    mot.add(0.2, [1], [(0, 0)], [6], [(0, 0)])  # staying with 6 is no further switch
    mot.add(0.3, [1], [(0, 0)], [], [])  # a miss does not forget the last match
    score = mot.add(0.4, [1], [(0, 0)], [5], [(0, 0)])  # back to 5: another switch
    assert score.switches == (1,)
    r = mot.result()
    assert (r.id_switches, r.misses, r.matches) == (2, 1, 4)
    assert r.mota == pytest.approx(1 - 3 / 5)


def test_continuity_keeps_the_last_match_within_the_radius_even_when_another_is_closer() -> None:
    mot = ClearMot(radius=0.75)
    mot.add(0.0, [1], [(0, 0)], [5], [(0, 0)])
    # track 5 drifted to 0.6 m, track 6 sits on the person: 5 is kept, 6 is a false positive
    score = mot.add(0.1, [1], [(0, 0)], [5, 6], [(0.6, 0), (0.05, 0)])
    assert score.matches == ((1, 5, pytest.approx(0.6)),)
    assert score.false_positives == (6,) and score.switches == ()
    # beyond the radius the last match no longer holds: Hungarian picks 6, a switch
    score = mot.add(0.2, [1], [(0, 0)], [5, 6], [(0.8, 0), (0.05, 0)])
    assert score.matches == ((1, 6, pytest.approx(0.05)),) and score.switches == (1,)


def test_the_hungarian_step_minimises_the_total_distance() -> None:
    mot = ClearMot(radius=1.0)
    # greedy nearest-first would give a-t1 (0.1) and leave b unmatched (b-t2 1.2 > radius)
    score = mot.add(0.0, [1, 2], [(0, 0), (0.9, 0)], [10, 20], [(0.1, 0), (-0.8, 0)])
    assert sorted(score.matches) == [(1, 20, pytest.approx(0.8)), (2, 10, pytest.approx(0.8))]


def test_a_radius_that_is_not_positive_and_repeated_ids_are_refused() -> None:
    with pytest.raises(ValueError, match="radius"):
        ClearMot(radius=0.0)
    with pytest.raises(ValueError, match="once per frame"):
        ClearMot().add(0.0, [1, 1], [(0, 0), (1, 1)], [], [])
