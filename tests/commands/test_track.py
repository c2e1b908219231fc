"""``pfctl track evaluate``: CLEAR-MOT of the replay's tracks at a bag's annotated scans.

A small bag is written here with ``rosbags`` (no ROS needed): a laser that sees nothing and
``leg_tracker/Person`` annotations at three of its scans, so every annotation is a miss; the
real annotated bag of the shared data is scored in ``tests/app/test_track_evaluation.py``.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from rosbags.rosbag1 import Writer
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

from tests.conftest import run_cli

PEOPLE = "/ground_truth_people_tracks"
PERSON_MSG = "geometry_msgs/Pose pose\nuint32 id\n"


def write_annotated_bag(path: Path) -> int:
    """A bag of 10 empty scans (10 Hz, frame ``laser``) with people annotated at scans 2, 3
    and 7 (4 annotations; each just before its scan in bag time, as Leigh's bags have them);
    returns the number of annotations."""
    store = get_typestore(Stores.ROS1_NOETIC)
    store.register(get_types_from_msg(PERSON_MSG, "leg_tracker/msg/Person"))
    t = store.types
    topics = {"/scan": "sensor_msgs/msg/LaserScan", PEOPLE: "leg_tracker/msg/Person"}
    annotated = {2: [(1, 2.0, 0.5)], 3: [(1, 2.0, 0.6), (2, 3.0, -1.0)], 7: [(2, 3.1, -0.9)]}
    with Writer(path) as writer:
        conns = {k: writer.add_connection(k, v, typestore=store) for k, v in topics.items()}
        for i in range(10):
            ns = 10**9 + i * 10**8
            for pid, x, y in annotated.get(i, []):
                pose = t["geometry_msgs/msg/Pose"](
                    t["geometry_msgs/msg/Point"](x, y, 0.0),
                    t["geometry_msgs/msg/Quaternion"](0.0, 0.0, 0.0, 1.0),
                )
                msg = t["leg_tracker/msg/Person"](pose=pose, id=pid)
                writer.write(
                    conns[PEOPLE], ns - 2 * 10**6, store.serialize_ros1(msg, topics[PEOPLE])
                )
            stamp = t["builtin_interfaces/msg/Time"](sec=ns // 10**9, nanosec=ns % 10**9)
            scan = t["sensor_msgs/msg/LaserScan"](
                header=t["std_msgs/msg/Header"](seq=i, stamp=stamp, frame_id="laser"),
                angle_min=-2.0,
                angle_max=2.0,
                angle_increment=0.01,
                time_increment=0.0,
                scan_time=0.1,
                range_min=0.1,
                range_max=10.0,
                ranges=np.full(401, np.inf, np.float32),
                intensities=np.zeros(0, np.float32),
            )
            writer.write(conns["/scan"], ns, store.serialize_ros1(scan, topics["/scan"]))
    return sum(len(v) for v in annotated.values())


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
