"""benchmarks/annotate_homes.py: its scores — rooms at IoU ≥ 0.7, doors by position, and Bormann
et al.'s area recall and precision — on hand-made layouts whose answers are known."""

from __future__ import annotations

import importlib
import sys
from pathlib import Path

import pytest

from pfctl.core.mapping.house import Door, HouseLayout, Region

BENCHMARKS = Path(__file__).resolve().parents[2] / "benchmarks"
sys.path.insert(0, str(BENCHMARKS))
annotate_homes = importlib.import_module("annotate_homes")

LEFT = Region("left", ((0, 0), (4, 0), (4, 4), (0, 4)))
RIGHT = Region("right", ((4, 0), (8, 0), (8, 4), (4, 4)))
DOOR = Door(("left", "right"), ((4, 1), (4, 2)))
TRUTH = HouseLayout(regions=(LEFT, RIGHT), doors=(DOOR,))


def test_a_perfect_proposal_scores_every_room_and_door_and_full_areas() -> None:
    s = annotate_homes.score(TRUTH, TRUTH)
    assert (s.rooms_matched, s.doors_found, s.spurious) == (2, 1, 0)
    assert s.recall_sum == pytest.approx(2.0)
    assert s.precision_sum == pytest.approx(2.0)


def test_merged_rooms_keep_recall_and_halve_precision() -> None:
    merged = Region("all", ((0, 0), (8, 0), (8, 4), (0, 4)))
    s = annotate_homes.score(TRUTH, HouseLayout(regions=(merged,), doors=()))
    assert s.rooms_matched == 0  # IoU 0.5 with either room
    assert s.recall_sum / s.regions == pytest.approx(1.0)
    assert s.precision_sum / s.proposed_rooms == pytest.approx(0.5)
    assert s.doors_found == 0


def test_a_split_room_keeps_precision_and_loses_recall() -> None:
    top = Region("left_top", ((0, 1), (4, 1), (4, 4), (0, 4)))
    bottom = Region("left_bottom", ((0, 0), (4, 0), (4, 1), (0, 1)))
    spurious = Door(("left_top", "left_bottom"), ((1, 1), (2, 1)))
    s = annotate_homes.score(
        TRUTH, HouseLayout(regions=(top, bottom, RIGHT), doors=(DOOR, spurious))
    )
    assert s.rooms_matched == 2  # left_top has IoU 0.75 with left; right is exact
    assert s.recall_sum / s.regions == pytest.approx((0.75 + 1.0) / 2)
    assert s.precision_sum / s.proposed_rooms == pytest.approx(1.0)
    assert (s.doors_found, s.spurious) == (1, 1)
