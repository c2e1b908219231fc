"""``pfctl replay``: perception on recorded bags (the simulator's and a real stationary laser)."""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np
import pytest

from pfctl.bags.recording import read_episode
from pfctl.bags.replay import image_depth
from tests.conftest import run_cli

ROOT = Path(__file__).resolve().parents[2]
CROSSING = ROOT / "tests" / "app" / "crossing.yaml"
DEMO = ROOT.parent / "shared" / "data" / "legs" / "demo_stationary_simple_environment.bag"


def _rows(path: Path) -> list[dict[str, str]]:
    with path.open() as fh:
        return list(csv.DictReader(fh))


@pytest.fixture(scope="module")
def episode(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A 6 s recording of the crossing scenario, with camera images."""
    out = tmp_path_factory.mktemp("rec") / "ep"
    args = ["sim", "run", str(CROSSING), "--duration", "6", "--record", str(out)]
    mp = pytest.MonkeyPatch()
    try:
        status = _run([*args, "--record-images"], mp)
    finally:
        mp.undo()
    assert status == 0
    return out


def _run(args: list[str], mp: pytest.MonkeyPatch) -> int:
    import sys

    from pfctl import cli

    mp.setattr(sys, "argv", ["pfctl", *args])
    try:
        cli.main()
    except SystemExit as exited:
        return int(exited.code or 0)
    return 0


@pytest.mark.sim
def test_replay_of_a_sim_recording_tracks_the_people_in_the_map_frame(
    episode: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    out = tmp_path / "replay"
    status, stdout, _ = run_cli(
        ["replay", str(episode / "episode.bag"), "--frame", "map", "--out", str(out)],
        capsys,
        monkeypatch,
    )
    assert status == 0, stdout
    assert "camera frames" in stdout and "in frame 'map'" in stdout
    rows = _rows(out / "tracks.csv")
    assert list(rows[0]) == ["t", "track_id", "x", "y", "vx", "vy", "confidence", "is_target"]
    assert (out / "tracks.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    truth = read_episode(episode)
    stamps = truth.stamps
    near = 0
    for row in rows:
        k = int(np.argmin(np.abs(stamps - float(row["t"]))))
        people = truth.truths[k].people
        d = min(math.hypot(float(row["x"]) - p.x, float(row["y"]) - p.y) for p in people)
        near += d < 0.3
    assert near / len(rows) > 0.95  # the tracks are where the people were (map frame via /tf)
    assert len({r["track_id"] for r in rows}) == 2


def test_replay_errors_are_one_line_and_write_nothing(
    episode: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    bag = str(episode / "episode.bag")
    junk = tmp_path / "junk.bag"
    junk.write_bytes(b"#ROSBAG V2.0\nnot really a bag")
    out = tmp_path / "out"
    cases = [
        (["replay", str(tmp_path / "none.bag")], "no such bag file"),
        (["replay", str(junk)], "cannot read the bag"),
        (["replay", bag, "--scan-topic", "/nope"], "no topic /nope"),
        (["replay", bag, "--frame", "moon"], "no such frame"),
        (["replay", bag, "--no-camera", "--target", str(tmp_path / "t.npz")], "t.npz"),
        (
            ["replay", str(tmp_path)],
            f"{tmp_path}: a folder but not a ROS 2 bag (no metadata.yaml); expected a ROS 1 .bag "
            "file, a ROS 2 bag folder or its .mcap/.db3 file",
        ),
        (["replay", str(episode)], f"a pfctl recording: give {episode / 'episode.bag'}"),
    ]
    for args, message in cases:
        status, _, err = run_cli([*args, "--out", str(out)], capsys, monkeypatch)
        assert status == 2, args
        assert message in err and len(err.strip().splitlines()) == 1, err
    assert not out.exists()


def test_depth_in_millimetres_and_metres_reads_the_same() -> None:
    metres = np.array([[0.5, 1.25], [0.0, np.nan]], dtype=np.float32)

    class Msg:
        def __init__(self, enc: str, data: np.ndarray) -> None:
            self.encoding, self.height, self.width = enc, 2, 2
            self.is_bigendian = 0
            self.step = data.dtype.itemsize * 2
            self.data = data.tobytes()

    mm = np.nan_to_num(metres * 1000).astype(np.uint16)
    a = image_depth(Msg("32FC1", metres))
    b = image_depth(Msg("16UC1", mm))
    np.testing.assert_allclose(a, b)
    assert np.isinf(a[1]).all()


@pytest.mark.skipif(not DEMO.is_file(), reason=f"real data not here: {DEMO}")
def test_replay_of_a_real_stationary_laser_draws_walking_people(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    out = tmp_path / "demo"
    status, _, _ = run_cli(["replay", str(DEMO), "--out", str(out)], capsys, monkeypatch)
    assert status == 0
    rows = _rows(out / "tracks.csv")
    ids = {r["track_id"] for r in rows}
    assert len(ids) >= 5  # several people walk past in 126 s
    ranges = [math.hypot(float(r["x"]), float(r["y"])) for r in rows]
    assert min(ranges) > 0.3 and max(ranges) < 5.6  # within the laser's range (frame 'laser')
    speeds = [math.hypot(float(r["vx"]), float(r["vy"])) for r in rows]
    assert np.percentile(speeds, 75) > 0.3  # they walk
