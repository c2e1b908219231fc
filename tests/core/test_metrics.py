"""Episode metrics (pfctl.core.metrics) on hand-built logs with known answers."""

from __future__ import annotations

import json

import numpy as np
import pytest

from pfctl.core.episode import EpisodeLog, TickRecord
from pfctl.core.metrics import (
    FollowMetrics,
    MetricParams,
    Reacquisition,
    episode_arrays,
    follow_metrics,
    runs,
    search_metrics,
)
from pfctl.core.robot import GroundTruth, PersonTruth, Pose2D

DT = 0.1
BOB = (0.0, 5.0)
AWARE = {"V": "visible", "T": "tracked", "L": "lost", "P": "predicted", "S": "searching"}
ACTION = {
    "f": "follow_target",
    "g": "go_to_prediction",
    "l": "look_around",
    "w": "waypoint_search",
    "s": "stop",
    "-": None,
}


def make_log(
    pattern: str,
    actions: str | None = None,
    distance: float | list[float] = 1.5,
    truths: bool = True,
    robot: list[tuple[float, float]] | None = None,
    collisions: list[int] | None = None,
    by_name: bool = False,
) -> EpisodeLog:
    """One tick per letter of ``pattern`` (every DT s): awareness V/T/L/P/S as :data:`AWARE`;
    ``W`` = visible but the track is on bob; ``F`` = visible, the track far from everyone.

    The robot stands at the origin (or walks ``robot``); alice, the target, stands ``distance``
    (per tick or fixed) along +x; bob at :data:`BOB`. ``actions`` one letter per tick
    (:data:`ACTION`, ``f`` by default).
    """
    n = len(pattern)
    actions = actions or "f" * n
    assert len(actions) == n
    dist = np.broadcast_to(np.asarray(distance, dtype=float), (n,))
    ticks = []
    gts = []
    for i, (c, a) in enumerate(zip(pattern, actions, strict=True)):
        rx, ry = robot[i] if robot is not None else (0.0, 0.0)
        alice = (rx + float(dist[i]), ry)
        if c == "W":
            aware, target_xy = "visible", (BOB[0] + 0.1, BOB[1])
        elif c == "F":
            aware, target_xy = "visible", (-20.0, -20.0)
        else:
            aware = AWARE[c]
            target_xy = (alice[0] + 0.05, alice[1]) if c in "VT" else None
        ticks.append(
            TickRecord(
                t=round(i * DT, 9),
                pose=Pose2D(rx + 0.01, ry),
                awareness=aware,
                action=ACTION[a],
                target_id=1 if target_xy else None,
                target_xy=target_xy,
            )
        )
        people = (
            PersonTruth("bob", *BOB, 0.0, 0.0),
            PersonTruth("alice", *alice, 0.0, 0.5, is_target=not by_name),
        )
        hits = collisions[i] if collisions is not None else 0
        gts.append(GroundTruth(round(i * DT, 9), Pose2D(rx, ry), people, collisions=hits))
    return EpisodeLog(
        ticks, gts if truths else [], target_name="alice" if by_name or truths else None
    )


# -- correctness, identification, following rate ------------------------------------------------


def test_correct_wrong_and_neutral_ticks() -> None:
    a = episode_arrays(make_log("VTWFLPS"))
    assert a.correct.tolist() == [True, True, False, False, False, False, False]
    assert a.wrong.tolist() == [False, False, True, False, False, False, False]
    assert a.has_truth and a.period == pytest.approx(DT)


def test_nearest_person_decides_identity() -> None:
    # the track is 0.5 m from alice but 0.3 m from bob: bob's, not correct, wrong
    log = make_log("V")
    tick = log.ticks[0]
    alice = (BOB[0] + 0.5, BOB[1])
    log.ticks[0] = TickRecord(tick.t, tick.pose, "visible", "follow_target", 1, (BOB[0] + 0.2, 5.0))
    people = (PersonTruth("bob", *BOB, 0, 0), PersonTruth("alice", *alice, 0, 0, is_target=True))
    log.truths[0] = GroundTruth(0.0, Pose2D(0, 0), people)
    a = episode_arrays(log)
    assert not a.correct[0] and a.wrong[0]


def test_target_found_by_name() -> None:
    m = follow_metrics(make_log("VVVV", by_name=True))
    assert m.first_identified_s == 0.0
    assert m.following_rate == 1.0


def test_following_rate_counts_band_from_first_identification() -> None:
    # 2 lost ticks before identification; then 8 correct ticks at various true distances
    dist = [1.0, 1.0, 1.0, 1.0, 2.5, 0.3, 0.3, 3.0, 3.0, 0.5]
    m = follow_metrics(make_log("LLVVVVVVVV", distance=dist))
    assert m.first_identified_s == pytest.approx(0.2)
    # in band [0.5, 2.5] (closed): 1.0, 1.0, 2.5, 0.5 of the 8 from identification on
    assert m.following_rate == pytest.approx(4 / 8)
    narrow = follow_metrics(make_log("LLVVVVVVVV", distance=dist), MetricParams(band=(0.9, 1.1)))
    assert narrow.following_rate == pytest.approx(2 / 8)
    assert narrow.band == (0.9, 1.1) and narrow.to_json()["band"] == [0.9, 1.1]


def test_wrong_and_lost_ticks_are_not_following() -> None:
    m = follow_metrics(make_log("VVVVWWLLVV"))
    assert m.following_rate == pytest.approx(6 / 10)


def test_never_identified() -> None:
    m = follow_metrics(make_log("LLLWWWWWWFF"))
    assert m.following_rate == 0.0
    assert m.first_identified_s is None
    assert m.losses == 0 and m.reacquisitions == ()
    assert m.identity_switches == 1  # the wrong run still counts


# -- losses and re-acquisitions -----------------------------------------------------------------


def test_short_flicker_is_not_a_loss() -> None:
    assert follow_metrics(make_log("VVVV" + "L" * 9 + "VVV")).losses == 0
    m = follow_metrics(make_log("VVVV" + "L" * 10 + "VVV"))  # exactly min_loss_s
    assert m.losses == 1
    assert m.loss_times == (pytest.approx(0.4),)


def test_losses_before_first_identification_do_not_count() -> None:
    m = follow_metrics(make_log("L" * 20 + "VVVVV"))
    assert m.losses == 0
    assert m.first_identified_s == pytest.approx(2.0)


def test_reacquired_by_prediction() -> None:
    pattern = "VVVVV" + "L" * 3 + "P" * 12 + "VVV"
    actions = "fffff" + "---" + "g" * 7 + "l" * 5 + "fff"
    m = follow_metrics(make_log(pattern, actions))
    assert m.losses == 1
    (r,) = m.reacquisitions
    assert r.how == "prediction"
    assert r.t_lost == pytest.approx(0.5)
    assert r.t_found == pytest.approx(2.0)
    assert r.time_to_refind == pytest.approx(1.5)
    assert m.median_time_to_refind_s == pytest.approx(1.5)


def test_reacquired_by_waypoint_search_after_prediction() -> None:
    pattern = "VVVVV" + "P" * 10 + "S" * 10 + "VV"
    actions = "fffff" + "g" * 5 + "l" * 5 + "w" * 10 + "ff"
    (r,) = follow_metrics(make_log(pattern, actions)).reacquisitions
    assert r.how == "waypoint_search"
    assert (r.t_lost, r.t_found) == (pytest.approx(0.5), pytest.approx(2.5))


def test_last_search_action_wins() -> None:
    # way-point search, then a new prediction looked at: the prediction found her
    pattern = "VVV" + "S" * 10 + "P" * 10 + "V"
    actions = "fff" + "w" * 10 + "g" * 5 + "l" * 5 + "f"
    (r,) = follow_metrics(make_log(pattern, actions)).reacquisitions
    assert r.how == "prediction"


def test_reacquired_otherwise() -> None:
    pattern = "VVVVV" + "L" * 15 + "VV"
    actions = "fffff" + "f" * 5 + "-" * 5 + "s" * 5 + "ff"
    (r,) = follow_metrics(make_log(pattern, actions)).reacquisitions
    assert r.how == "other"


def test_loss_never_reacquired() -> None:
    m = follow_metrics(make_log("VVVVV" + "S" * 20, "fffff" + "w" * 20))
    assert m.losses == 1
    assert m.reacquisitions == ()
    assert m.unrecovered_losses == 1
    assert m.median_time_to_refind_s is None
    assert m.loss_times == (pytest.approx(0.5),)


def test_reacquisition_is_the_first_correct_tick_after_wrong_and_flicker() -> None:
    # lost, then 2 ticks on bob, a 0.2 s flicker, then alice: found at that first correct tick
    pattern = "VVV" + "L" * 12 + "WW" + "LL" + "VV"
    m = follow_metrics(make_log(pattern))
    assert m.losses == 1
    (r,) = m.reacquisitions
    assert r.t_found == pytest.approx(1.9)
    assert m.identity_switches == 0  # 0.2 s on bob is a blip


def test_a_loss_ends_at_the_next_loss() -> None:
    # loss 1 is followed only by wrong ticks before loss 2 begins: only loss 2 is re-acquired
    pattern = "VVV" + "L" * 12 + "WWW" + "L" * 12 + "VV"
    m = follow_metrics(make_log(pattern))
    assert m.losses == 2
    assert m.loss_times == (pytest.approx(0.3), pytest.approx(1.8))
    (r,) = m.reacquisitions
    assert r.t_lost == pytest.approx(1.8)
    assert m.unrecovered_losses == 1


def test_min_loss_parameter() -> None:
    log = make_log("VVVV" + "L" * 6 + "VVV")
    assert follow_metrics(log).losses == 0
    assert follow_metrics(log, MetricParams(min_loss_s=0.5)).losses == 1


# -- identity switches --------------------------------------------------------------------------


def test_identity_switch_runs_vs_blips() -> None:
    m = follow_metrics(make_log("VVV" + "WWWWW" + "VVV" + "WWWW" + "VV" + "WWWWWW" + "V"))
    assert m.identity_switches == 2  # 0.5 s and 0.6 s; the 0.4 s run is a blip
    assert m.switch_times == (pytest.approx(0.3), pytest.approx(1.7))
    assert follow_metrics(make_log("VVWWWWV"), MetricParams(min_switch_s=0.3)).identity_switches


def test_neutral_tick_splits_a_wrong_run() -> None:
    assert follow_metrics(make_log("VWWWFWWWV")).identity_switches == 0


# -- distance, collisions, duration -------------------------------------------------------------


def test_distance_collisions_duration_from_truth() -> None:
    robot = [(0.3 * i, 0.4 * i) for i in range(11)]  # 0.5 m per tick, 5 m
    log = make_log("V" * 11, robot=robot, collisions=[0] * 5 + [1] * 5 + [2])
    m = follow_metrics(log)
    assert m.distance_m == pytest.approx(5.0)
    assert m.collisions == 2
    assert m.duration_s == pytest.approx(1.1)


def test_truth_and_ticks_must_match() -> None:
    log = make_log("VVVV")
    log.truths.pop()
    with pytest.raises(ValueError, match="3 truths for 4 ticks"):
        follow_metrics(log)


def test_empty_log() -> None:
    m = follow_metrics(EpisodeLog())
    assert (m.following_rate, m.losses, m.distance_m, m.duration_s, m.collisions) == (
        0.0,
        0,
        0.0,
        0.0,
        0,
    )
    s = search_metrics(EpisodeLog())
    assert not s.found and s.time_to_find_s is None


# -- without truths -----------------------------------------------------------------------------


def test_no_truth_fallback() -> None:
    robot = [(0.1 * i, 0.0) for i in range(20)]
    dist = [1.0] * 5 + [3.0] * 5 + [1.0] * 10
    pattern = "LL" + "VVVWW" + "VVV" + "L" * 10  # W: bob's track, but nothing can tell
    log = make_log(pattern, distance=dist, truths=False, robot=robot)
    m = follow_metrics(log)
    assert not m.ground_truth
    assert m.first_identified_s == pytest.approx(0.2)
    assert m.identity_switches == 0
    # from tick 2 on (18 ticks): V/W ticks 2..9 hold the target; believed distance in band for
    # ticks 2-4 (1.0 - 0.01 + 0.05) only: 5-9 are 3 m away (the W ticks at bob: 5 m)
    assert m.following_rate == pytest.approx(3 / 18)
    assert m.losses == 1 and m.reacquisitions == ()
    assert m.collisions == 0
    assert m.distance_m == pytest.approx(1.9)  # believed poses
    s = search_metrics(log)
    assert s.found and s.time_to_find_s == pytest.approx(0.2) and not s.ground_truth


# -- search -------------------------------------------------------------------------------------


def test_search_metrics() -> None:
    robot = [(0.5 * i, 0.0) for i in range(12)]
    log = make_log("S" * 8 + "WVVV", robot=robot, collisions=[0] * 6 + [1] * 6)
    s = search_metrics(log)
    assert s.found
    assert s.time_to_find_s == pytest.approx(0.9)  # the W tick (bob) is not a find
    assert s.distance_m == pytest.approx(4.5)  # up to the find
    assert s.collisions == 1
    missed = search_metrics(make_log("S" * 10, robot=robot[:10], collisions=[0] * 9 + [3]))
    assert not missed.found and missed.time_to_find_s is None
    assert missed.distance_m == pytest.approx(4.5)
    assert missed.collisions == 3


# -- JSON, helpers, speed -----------------------------------------------------------------------


def test_to_json_is_serialisable_with_the_keys() -> None:
    pattern = "VVVVV" + "P" * 12 + "VVV" + "WWWWWW" + "V"
    m = follow_metrics(make_log(pattern, "fffff" + "g" * 12 + "f" * 10))
    data = json.loads(json.dumps(m.to_json()))
    for key in (
        "following_rate",
        "first_identified_s",
        "losses",
        "reacquisitions",
        "identity_switches",
        "collisions",
        "distance_m",
        "duration_s",
        "median_time_to_refind_s",
    ):
        assert key in data
    assert data["losses"] == 1
    assert data["identity_switches"] == 1
    (r,) = data["reacquisitions"]
    assert {"t_lost", "t_found", "how"} <= set(r)
    assert r["how"] == "prediction"
    assert r["t_found"] - r["t_lost"] == pytest.approx(1.2)
    s = search_metrics(make_log("SSSV"))
    assert json.loads(json.dumps(s.to_json())) == {
        "found": True,
        "time_to_find_s": pytest.approx(0.3),
        "distance_m": 0.0,
        "collisions": 0,
        "ground_truth": True,
    }
    never = json.loads(json.dumps(follow_metrics(make_log("LLL")).to_json()))
    assert never["first_identified_s"] is None and never["median_time_to_refind_s"] is None


def test_reacquisition_and_metrics_values() -> None:
    r = Reacquisition(2.0, 5.5, "waypoint_search")
    assert r.time_to_refind == 3.5
    m = FollowMetrics(0.5, 0.0, 2, (r,), 0, 0, 1.0, 10.0)
    assert m.unrecovered_losses == 1


def test_runs() -> None:
    starts, ends = runs(np.array([1, 1, 0, 1, 0, 0, 1, 1, 1], dtype=bool))
    assert starts.tolist() == [0, 3, 6] and ends.tolist() == [1, 3, 8]
    starts, ends = runs(np.zeros(0, dtype=bool))
    assert len(starts) == len(ends) == 0


def test_room_prediction_is_scored_at_the_loss_against_where_she_is_later() -> None:
    from pfctl.core.episode import RoomPredictionRecord
    from pfctl.core.mapping.house import HouseLayout, Region
    from pfctl.core.mapping.regions import RegionMap
    from pfctl.core.metrics import RoomPredictionScores, room_prediction_scores

    # alice walks from x = 1 to x = 6 along +x; "near" is x < 3, "far" beyond
    regions = RegionMap(
        HouseLayout(
            regions=(
                Region("near", ((-1, -1), (3, -1), (3, 1), (-1, 1))),
                Region("far", ((3, -1), (9, -1), (9, 1), (3, 1))),
            )
        )
    )
    log = make_log("V" * 10 + "L" * 50, distance=list(np.linspace(1.0, 6.0, 60)))
    # at the loss (t = 1.0 s, x ≈ 1.8) the belief says "far" then "near"; l* is None, her room
    # "near"; 3 s later she is at x ≈ 4.4: in "far"
    log.room_predictions.append(RoomPredictionRecord(1.0, ("far", "near"), None, "near", 3.0))
    scores = room_prediction_scores(log, regions)
    assert scores == RoomPredictionScores(scored=1, top1=1, top2=1, heading_top1=0, heading_top2=0)
    # with l* "far" the baseline hits too
    log.room_predictions[0] = RoomPredictionRecord(1.0, ("near", "far"), "far", "near", 3.0)
    assert room_prediction_scores(log, regions) == RoomPredictionScores(1, 0, 1, 1, 1)
    # a horizon past the end of the episode is not scored
    log.room_predictions[0] = RoomPredictionRecord(1.0, ("far",), "far", "near", 30.0)
    assert room_prediction_scores(log, regions).scored == 0
