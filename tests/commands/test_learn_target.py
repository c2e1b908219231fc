"""`pfctl learn-target`: from the simulated house, from pictures, and its one-line failures."""

from __future__ import annotations

import hashlib
import math
import subprocess
import sys
from pathlib import Path

import cv2
import numpy as np
import pytest
from rich.progress import Progress

from pfctl.app.learn_target import learn_from_images
from pfctl.app.perception import identity_params
from pfctl.app.profiles import load_target_profile
from pfctl.app.sim import sim_config
from pfctl.backends.pybullet.simulation import SimRobot
from pfctl.core.perception.clothes import histogram_intersection
from pfctl.core.perception.identity.profile import learn_profile
from pfctl.core.perception.vision import MaskPersonDetector
from pfctl.core.robot import HeadTarget
from pfctl.errors import UserError
from pfctl.mission import load_mission, loads_mission
from tests.conftest import run_cli

ROOT = Path(__file__).resolve().parents[2]
HOUSE = ROOT / "missions" / "house.yaml"

TWO = """
name: two-people
map:
  regions:
    - {name: room, polygon: [[0, 0], [9, 0], [9, 6], [0, 6]]}
robot: {start: {x: 1.0, y: 3.0, theta: 0.0}}
sensors:
  camera: {width: 640, height: 480}
scenario:
  seed: 5
  target: alice
  people:
    - {name: alice, clothes: {upper: [200, 30, 40], lower: [40, 40, 120]}, route: [[3.5, 2.6]]}
    - {name: bob, clothes: {upper: [30, 120, 200], lower: [60, 60, 60]}, route: [[3.5, 3.4]]}
"""


@pytest.mark.sim
@pytest.mark.slow
def test_learn_target_in_the_simulated_house(tmp_path, capsys, monkeypatch) -> None:
    out, png = tmp_path / "t.npz", tmp_path / "t.png"
    args = ["learn-target", str(HOUSE), "--backend", "sim", "--out", str(out)]
    code, stdout, stderr = run_cli(
        [*args, "--seconds", "3", "--plot", str(png)], capsys, monkeypatch
    )
    assert code == 0, stderr
    profile = load_target_profile(out)
    assert len(profile.faces) > 0 and profile.frames > 10
    mission = load_mission(HOUSE)
    assert profile.color_space == mission.perception.identity.color_space
    assert profile.upper.sum() == pytest.approx(1.0) and profile.lower.sum() == pytest.approx(1.0)
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "face samples" in stdout and "upper body" in stdout and str(out) in stdout


@pytest.fixture(scope="module")
def pictures(
    tmp_path_factory,
) -> tuple[Path, dict[str, list[tuple[tuple[int, int, int, int], float]]]]:
    """Three 640x480 frames of alice and bob side by side at 2.5 m (alice left), the crops of
    alice alone in crops/, and the boxes the mask detector found in each frame."""
    root = tmp_path_factory.mktemp("pictures")
    (root / "frames").mkdir()
    (root / "crops").mkdir()
    boxes: dict[str, list[tuple[tuple[int, int, int, int], float]]] = {}
    with SimRobot(sim_config(loads_mission(TWO, source="two.yaml"))) as robot:
        detector = MaskPersonDetector(
            robot.person_instances(), names=robot.people_bodies.instance_names()
        )
        for k, turn in enumerate((0.0, 0.3, -0.3)):
            for walker in robot.people:
                walker.hold(walker.x, walker.y, math.atan2(3.0 - walker.y, 1.0 - walker.x) + turn)
            robot.point_head(HeadTarget(0.0, -0.08))
            for _ in range(12):
                robot.step()
            frame = robot.observe().rgbd
            assert frame is not None
            bgr = cv2.cvtColor(frame.rgb, cv2.COLOR_RGB2BGR)
            cv2.imwrite(str(root / "frames" / f"f{k}.png"), bgr)
            seen = detector.detect(frame)
            boxes[hashlib.sha1(frame.rgb.tobytes()).hexdigest()] = [(d.box, 1.0) for d in seen]
            (alice,) = [d for d in seen if d.ground_truth_name == "alice"]
            x0, y0, x1, y1 = alice.box
            cv2.imwrite(
                str(root / "crops" / f"c{k}.png"),
                bgr[max(0, y0 - 5) : y1 + 5, max(0, x0 - 5) : x1 + 5],
            )
    return root, boxes


def test_learn_target_from_a_folder_of_pictures(pictures, tmp_path, capsys, monkeypatch) -> None:
    root, _ = pictures
    out = tmp_path / "alice.npz"
    code, stdout, stderr = run_cli(
        ["learn-target", str(HOUSE), "--from", str(root / "crops"), "--out", str(out)],
        capsys,
        monkeypatch,
    )
    assert code == 0, stderr
    profile = load_target_profile(out)
    assert profile.frames == 3 and len(profile.faces) >= 1
    assert "learned from 3 of 3 frames" in stdout


def test_learn_target_from_a_video(pictures, tmp_path, capsys, monkeypatch) -> None:
    root, _ = pictures
    crops = [cv2.imread(str(p)) for p in sorted((root / "crops").iterdir())]
    h, w = max(c.shape[0] for c in crops), max(c.shape[1] for c in crops)
    video = tmp_path / "alice.avi"
    writer = cv2.VideoWriter(str(video), cv2.VideoWriter_fourcc(*"MJPG"), 5.0, (w, h))
    for k in range(9):
        canvas = np.full((h, w, 3), 128, np.uint8)
        crop = crops[k % len(crops)]
        canvas[: crop.shape[0], : crop.shape[1]] = crop
        writer.write(canvas)
    writer.release()
    out = tmp_path / "alice.npz"
    args = ["learn-target", str(HOUSE), "--from", str(video), "--out", str(out)]
    code, stdout, stderr = run_cli(args, capsys, monkeypatch)
    assert code == 0, stderr
    assert "learned from 9 of 9 frames" in stdout
    assert len(load_target_profile(out).faces) >= 1


def test_several_people_need_pick_which_takes_the_nth_from_the_left(pictures) -> None:
    root, boxes = pictures

    def finder(rgb: np.ndarray) -> list[tuple[tuple[int, int, int, int], float]]:
        return boxes[hashlib.sha1(rgb.tobytes()).hexdigest()]  # the people in that frame

    params = identity_params(load_mission(HOUSE))
    with Progress(disable=True) as progress:
        with pytest.raises(UserError, match=r"several people in 3 image\(s\).*--pick N") as err:
            learn_from_images(root / "frames", None, params, progress, finder)
        assert "f0.png: 2" in str(err.value)
        left = learn_from_images(root / "frames", 1, params, progress, finder)
        right = learn_from_images(root / "frames", 2, params, progress, finder)
        with pytest.raises(UserError, match="only 2 people"):
            learn_from_images(root / "frames", 3, params, progress, finder)

    a, b = learn_profile(left.appearances, params), learn_profile(right.appearances, params)
    assert histogram_intersection(a.upper, b.upper) < 0.2  # red shirt (alice) vs blue (bob)
    assert left.others == 3 and len(left.appearances) == 3


@pytest.mark.parametrize(
    ("extra", "words"),
    [
        (["--backend", "gazebo"], "--backend gazebo: expected one of sim, hsr"),
        (["--pick", "1"], "--pick 1: expected a positive number, with --from"),
        (["--from", "nowhere"], "--from nowhere: no such file or folder"),
        (["--seconds", "0"], "--seconds"),
    ],
)
def test_bad_options_fail_with_one_line_and_write_nothing(
    extra, words, tmp_path, capsys, monkeypatch
) -> None:
    out = tmp_path / "t.npz"
    monkeypatch.chdir(tmp_path)
    code, _, stderr = run_cli(
        ["learn-target", str(HOUSE), "--out", str(out), *extra], capsys, monkeypatch
    )
    assert code == 2 and words in stderr
    assert stderr.count("\n") == 1 and not out.exists()
    assert list(tmp_path.iterdir()) == []


def test_seeing_no_person_fails_and_writes_nothing(tmp_path, capsys, monkeypatch) -> None:
    """The camera's depth starts at 2 m: the target posing at 1.4 m has no depth, so nobody is
    detected."""
    text = TWO.replace("{width: 640, height: 480}", "{width: 160, height: 120, range_min: 2.0}")
    mission = tmp_path / "blind.yaml"
    mission.write_text(text)
    out, png = tmp_path / "t.npz", tmp_path / "t.png"
    args = ["learn-target", str(mission), "--out", str(out), "--plot", str(png), "--seconds", "1"]
    code, _, stderr = run_cli(args, capsys, monkeypatch)
    assert code == 2 and "saw no person" in stderr and stderr.count("\n") == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == ["blind.yaml"]


def test_an_image_smaller_than_the_people_detector_window_is_refused_cleanly(
    tmp_path: Path,
) -> None:
    """A 64 × 48 grey picture is smaller than the HOG detector's 64 × 128 window, which made
    OpenCV crash the process (SIGSEGV): the detector is not run on it, so nobody is seen. A real
    process, so that a crash fails this test instead of ending pytest."""
    cv2.imwrite(str(tmp_path / "i.png"), np.full((48, 64), 128, np.uint8))
    args = ["learn-target", str(HOUSE), "--from", "i.png", "--out", "t.npz"]
    done = subprocess.run(
        [sys.executable, "-m", "pfctl", *args],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        check=False,
        timeout=300,
    )
    assert done.returncode == 2, done.stderr
    assert (
        done.stderr == "pfctl: error: --from i.png: saw no person in 1 frame(s); nothing written\n"
    )
    assert sorted(p.name for p in tmp_path.iterdir()) == ["i.png"]
