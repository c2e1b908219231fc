"""Trajectories and their text: CSV t,x,y and ETH/UCY frames parsed, with one-line errors naming
the source, line and field (the files themselves: tests/app/test_trajectory_files.py)."""

from __future__ import annotations

import numpy as np
import pytest

from pfctl.core.prediction.trajectories import (
    Trajectory,
    TrajectoryFormatError,
    frame_step_of,
    parse_csv_trajectory,
    parse_frames,
    trajectory_to_csv,
)


def test_csv_text_round_trips_and_names_the_source() -> None:
    t = np.array([0.0, 0.5, 1.0])
    xy = np.array([[0.0, 1.0], [0.25, 1.5], [0.5, 2.0]])
    tr = parse_csv_trajectory(trajectory_to_csv(t, xy), "walk.csv")
    np.testing.assert_allclose(tr.t, t)
    np.testing.assert_allclose(tr.xy, xy)
    assert tr.name == tr.source == tr.person == "walk.csv"


def test_bad_text_is_a_value_error_naming_source_line_and_field() -> None:
    with pytest.raises(TrajectoryFormatError, match=r"^walk\.csv:3: x: missing value$"):
        parse_csv_trajectory("t,x,y\n0,1,2\n1,,3\n", "walk.csv")
    with pytest.raises(ValueError, match=r"^f\.txt: fps must be a positive number, got 0\.0$"):
        parse_frames("0 1 2 3\n", "f.txt", fps=0.0)


def test_frames_text_is_split_per_person() -> None:
    trajectories = parse_frames("0 1 0 0\n10 1 0.4 0\n0 2 5 5\n10 2 5 5.4\n", "f.txt", fps=2.5)
    assert [tr.name for tr in trajectories] == ["f.txt#1", "f.txt#2"]
    np.testing.assert_allclose(trajectories[0].t, [0.0, 0.4])


def test_frame_step_is_the_gcd() -> None:
    assert frame_step_of([780, 790, 800, 840]) == 10.0
    assert frame_step_of([0, 6, 12]) == 6.0
    assert frame_step_of([3]) == 1.0


def test_trajectory_last_seconds() -> None:
    t = np.arange(40) / 10
    tr = Trajectory(t, np.stack([np.arange(40.0), np.zeros(40)], axis=1))
    assert len(tr.last(1.0)) == 11  # 2.9 s back to 3.9 s, both ends included
    assert len(tr.last(0.0)) == 2
    assert tr.duration == pytest.approx(3.9)
