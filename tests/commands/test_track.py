"""``pfctl track evaluate``: CLEAR-MOT of the replay's tracks at a bag's annotated scans.

A small bag is written here with ``rosbags`` (no ROS needed): a laser that sees nothing and
``leg_tracker/Person`` annotations at three of its scans, so every annotation is a miss; the
real annotated bag of the shared data is scored in ``tests/app/test_track_evaluation.py``.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from tests.bags.test_annotations import PEOPLE, write_annotated_bag
from tests.conftest import run_cli


@pytest.fixture(scope="module")
def annotated_bag(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("track") / "annotated.bag"
    write_annotated_bag(path)
    return path


def test_evaluate_scores_the_annotated_scans_and_writes_metrics_and_a_picture(
    annotated_bag: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    out = tmp_path / "eval"
    status, stdout, stderr = run_cli(
        ["track", "evaluate", str(annotated_bag), "--ground-truth", PEOPLE, "--out", str(out)],
        capsys,
        monkeypatch,
    )
    assert status == 0, stderr
    assert "MOTA 0.0 %" in stdout and "misses 4" in stdout and "ID switches 0" in stdout
    metrics = json.loads((out / "metrics.json").read_text())
    assert metrics["ground_truth"] == 4 and metrics["misses"] == 4
    assert metrics["ground_truth_topic"] == PEOPLE and metrics["scans"] == 10
    assert metrics["frames"] == 3 and metrics["false_positives"] == 0
    assert metrics["mota"] == 0.0 and metrics["motp"] is None  # no match: no mean distance
    assert (out / "tracks.png").read_bytes()[:4] == b"\x89PNG"


@pytest.mark.parametrize(
    ("args", "expected"),
    [
        (["--ground-truth", "/people"], "no topic /people; the bag has: /ground_truth_people"),
        (["--ground-truth", "/scan"], "topic /scan is sensor_msgs/msg/LaserScan, expected leg"),
        (["--ground-truth", PEOPLE, "--radius", "0"], "--radius: expected a distance > 0 m"),
        (["--ground-truth", PEOPLE, "--radius", "-1"], "--radius: expected a distance > 0 m"),
        (["--ground-truth", PEOPLE, "--scan-topic", "/nope"], "no topic /nope"),
        (["--ground-truth", PEOPLE, "--min-bearing", "10", "--max-bearing", "0"], "min < max"),
    ],
)
def test_bad_input_is_one_line_exit_2_and_no_files(
    annotated_bag: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
    args: list[str],
    expected: str,
) -> None:
    out = tmp_path / "eval"
    status, _, stderr = run_cli(
        ["track", "evaluate", str(annotated_bag), *args, "--out", str(out)], capsys, monkeypatch
    )
    assert status == 2
    assert stderr.startswith("pfctl: error: ") and stderr.count("\n") == 1, stderr
    assert expected in stderr
    assert not out.exists()
