"""Trajectory files: CSV t,x,y and ETH/UCY frames, with one-line errors naming file, line, field."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from pfctl.app.trajectory_files import read_csv_trajectory, read_frames, read_trajectories
from pfctl.core.prediction.trajectories import trajectory_to_csv
from pfctl.errors import UserError


def _write(tmp_path: Path, name: str, text: str) -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def test_csv_any_column_order_and_extra_columns(tmp_path: Path) -> None:
    path = _write(tmp_path, "a.csv", "id,y,t,x\n7,0.5,0.0,1.0\n7,0.6,0.1,1.1\n\n7,0.7,0.2,1.2\n")
    tr = read_csv_trajectory(path)
    np.testing.assert_allclose(tr.t, [0.0, 0.1, 0.2])
    np.testing.assert_allclose(tr.xy, [[1.0, 0.5], [1.1, 0.6], [1.2, 0.7]])
    assert tr.name == str(path) and tr.person == str(path)


def test_csv_round_trip(tmp_path: Path) -> None:
    t = np.array([0.0, 0.5, 1.0])
    xy = np.array([[0.0, 1.0], [0.25, 1.5], [0.5, 2.0]])
    path = _write(tmp_path, "r.csv", trajectory_to_csv(t, xy))
    tr = read_csv_trajectory(path)
    np.testing.assert_allclose(tr.t, t)
    np.testing.assert_allclose(tr.xy, xy)


@pytest.mark.parametrize(
    ("text", "fragments"),
    [
        ("", ["empty file"]),
        ("0,1,2\n1,2,3\n", [":1:", "no header line"]),
        ("t,x\n0,1\n1,2\n", [":1:", "no column y"]),
        ("t,x,y\n0,1,2\n1,abc,3\n", [":3:", "x: expected a number, got 'abc'"]),
        ("t,x,y\n0,1,2\n1,,3\n", [":3:", "x: missing value"]),
        ("t,x,y\n0,1,2\n1,2\n", [":3:", "y: missing value"]),
        ("t,x,y\n0,1,2\n1,nan,3\n", [":3:", "finite"]),
        ("t,x,y\n0,1,2\n1,2,3\n1,3,4\n", [":4:", "t: time must increase, got 1 after 1"]),
        ("t,x,y\n0,1,2\n", ["1 point(s), need at least 2"]),
    ],
)
def test_csv_errors_name_file_line_and_field(
    tmp_path: Path, text: str, fragments: list[str]
) -> None:
    path = _write(tmp_path, "bad.csv", text)
    with pytest.raises(UserError) as info:
        read_csv_trajectory(path)
    message = str(info.value)
    assert message.startswith(str(path))
    assert "\n" not in message
    for fragment in fragments:
        assert fragment in message, message


def test_missing_file_and_folder(tmp_path: Path) -> None:
    with pytest.raises(UserError, match="no such file"):
        read_csv_trajectory(tmp_path / "nope.csv")
    with pytest.raises(UserError, match="is a directory"):
        read_csv_trajectory(tmp_path)
    with pytest.raises(UserError, match=r"no \*\.txt files"):
        read_trajectories(tmp_path, "frames", fps=2.5)
    with pytest.raises(UserError, match="needs a frame rate"):
        read_trajectories(tmp_path, "frames")


FRAMES = """\
0\t1.0\t0.0\t0.0
0\t2.0\t5.0\t5.0
10\t1.0\t0.4\t0.0
10\t2.0\t5.0\t5.4
20\t1.0\t0.8\t0.0
20\t2.0\t5.0\t5.8
30\t2.0\t5.0\t6.2
50\t2.0\t5.0\t7.0
60\t2.0\t5.0\t7.4
"""


def test_frames_fps_is_annotated_steps_per_second(tmp_path: Path) -> None:
    path = _write(tmp_path, "f.txt", FRAMES)
    tracks = read_frames(path, fps=2.5)
    by_name = {t.name.split("#")[1]: t for t in tracks}
    # frame step 10 (gcd) → one step per 10 frame ids → 0.4 s at 2.5 steps/s
    np.testing.assert_allclose(by_name["1"].t, [0.0, 0.4, 0.8])
    np.testing.assert_allclose(by_name["1"].xy[:, 0], [0.0, 0.4, 0.8])
    # person 2 misses frame 40: split into two tracks, same person
    np.testing.assert_allclose(by_name["2.0"].t, [0.0, 0.4, 0.8, 1.2])
    np.testing.assert_allclose(by_name["2.1"].t, [2.0, 2.4])
    assert by_name["2.0"].person == by_name["2.1"].person == f"{path}#2"
    # an explicit frame step of 5 makes frame ids step by 2 → no track with 2 consecutive steps
    with pytest.raises(UserError, match="no track has 2 consecutive steps"):
        read_frames(path, fps=5.0, frame_step=5.0)
    # 1 step per second: times in steps
    np.testing.assert_allclose(read_frames(path, fps=1.0)[0].t, [0.0, 1.0, 2.0])


@pytest.mark.parametrize(
    ("text", "fragments"),
    [
        ("0 1 2.0\n", [":1:", "expected 4 whitespace-separated fields", "got 3"]),
        ("0 1 2 3\n10 1 x 3\n", [":2:", "x: expected a number, got 'x'"]),
        ("0 1 2 3\n10 1 2 3\n10 1 2.5 3\n", [":3:", "person 1 appears twice in frame 10"]),
        ("0 1 2 3\n10 1 2 3\n15 1 2 3\n", [":3:", "not a multiple of the frame step"]),
        ("# only a comment\n", ["no data lines"]),
    ],
)
def test_frames_errors(tmp_path: Path, text: str, fragments: list[str]) -> None:
    path = _write(tmp_path, "bad.txt", text)
    step = 10.0 if "15" in text else None
    with pytest.raises(UserError) as info:
        read_frames(path, fps=2.5, frame_step=step)
    message = str(info.value)
    assert message.startswith(str(path)) and "\n" not in message
    for fragment in fragments:
        assert fragment in message, message


def test_frames_bad_fps(tmp_path: Path) -> None:
    path = _write(tmp_path, "f.txt", FRAMES)
    with pytest.raises(UserError, match="fps must be a positive number"):
        read_frames(path, fps=0.0)


def test_read_trajectories_folder_is_recursive(tmp_path: Path) -> None:
    (tmp_path / "a").mkdir()
    _write(tmp_path / "a", "one.txt", FRAMES)
    _write(tmp_path, "two.txt", FRAMES)
    _write(tmp_path, "ignored.csv", "t,x,y\n0,0,0\n1,1,1\n")
    tracks = read_trajectories(tmp_path, "frames", fps=2.5)
    assert len(tracks) == 6
    assert {Path(t.source).name for t in tracks} == {"one.txt", "two.txt"}
    csv_tracks = read_trajectories(tmp_path, "csv")
    assert len(csv_tracks) == 1


def test_track_last_seconds(tmp_path: Path) -> None:
    path = _write(tmp_path, "a.csv", "t,x,y\n" + "".join(f"{i / 10},{i},0\n" for i in range(40)))
    tr = read_csv_trajectory(path)
    assert len(tr.last(1.0)) == 11  # 2.9 s back to 3.9 s, both ends included
    assert len(tr.last(0.0)) == 2
    assert tr.duration == pytest.approx(3.9)
