"""`pfctl sim run`: scripted driving, recording, teleop in a terminal, Ctrl-C, bad input."""

from __future__ import annotations

import os
import pty
import select
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from pfctl.backends.pybullet.drivers import ScriptError, read_velocity_script
from pfctl.bags.recording import read_episode
from tests.conftest import run_cli

pytestmark = pytest.mark.sim

HOUSE = Path(__file__).resolve().parents[2] / "missions" / "house.yaml"
PNG = b"\x89PNG\r\n\x1a\n"


def _cmd(*args: str) -> list[str]:
    return [sys.executable, "-c", "from pfctl.cli import main; main()", *args]


def _pfctl(*args: str, env: dict[str, str] | None = None) -> subprocess.CompletedProcess[str]:
    return subprocess.run(_cmd(*args), capture_output=True, text=True, check=False, env=env)


@pytest.mark.slow
def test_a_script_drives_the_robot_and_the_episode_is_recorded(tmp_path: Path) -> None:
    script = tmp_path / "drive.csv"
    script.write_text("t,vx,vy,wz,pan,tilt\n0,0.2,0,0,0.5,-0.2\n4,0,0,0,0,0\n")
    res = _pfctl(
        "sim", "run", str(HOUSE), "--duration", "6", "--script", str(script),
        "--record", str(tmp_path / "ep"), "--no-camera",
    )  # fmt: skip
    assert res.returncode == 0, res.stderr
    assert "ran 6.0 s simulated" in res.stdout and "0 collisions" in res.stdout
    assert "alice (target)" in res.stdout
    episode = read_episode(tmp_path / "ep")
    assert episode.duration == pytest.approx(5.9)
    first, last = episode.truths[0].robot, episode.truths[-1].robot
    assert last.x - first.x == pytest.approx(0.2 * 4 - 0.02, abs=0.01)  # 4 s at 0.2 m/s
    assert abs(last.y - first.y) < 1e-9
    assert episode.heads[30][1].pan == pytest.approx(0.5, abs=0.01)
    assert episode.truths[-1].command.vx == 0.0
    assert (tmp_path / "ep" / "paths.png").read_bytes()[:8] == PNG


@pytest.mark.slow
def test_the_picture_goes_where_asked_and_the_camera_runs(tmp_path: Path) -> None:
    out = tmp_path / "pics" / "run.png"
    res = _pfctl("sim", "run", str(HOUSE), "--duration", "1", "--png", str(out), "--seed", "3")
    assert res.returncode == 0, res.stderr
    assert "10 scans, 10 camera frames" in res.stdout
    assert out.read_bytes()[:8] == PNG


@pytest.mark.slow
def test_bad_input_is_one_line_and_exit_2(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    bad_script = tmp_path / "bad.csv"
    bad_script.write_text("t,vx,vy,wz\n0,0.1,0,0\n0,0.2,0,0\n")
    taken = tmp_path / "taken"
    taken.mkdir()
    (taken / "notes.txt").write_text("mine")
    monkeypatch.delenv("DISPLAY", raising=False)
    run = ("sim", "run", str(HOUSE), "--duration", "1", "--png", str(tmp_path / "x.png"))
    cases = [
        ((*run, "--script", str(bad_script)), "bad.csv:3: t: expected times to increase"),
        ((*run, "--script", str(tmp_path / "none.csv")), "none.csv: no such file"),
        ((*run, "--duration", "-1"), "--duration: expected a positive"),
        ((*run, "--script", str(bad_script), "--teleop"), "--script and --teleop"),
        ((*run, "--teleop"), "--teleop: stdin is not a terminal"),
        ((*run, "--gui"), "--gui: no display"),
        ((*run, "--record", str(taken)), "neither empty nor an episode"),
        ((*run, "--laser", "sonar"), "--laser: expected fast or bullet"),
        ((*run, "--png", str(tmp_path / "x.jpg")), "expected a path ending in .png"),
        (("sim", "run", str(tmp_path / "nope.yaml")), "nope.yaml"),
    ]
    for args, message in cases:
        code, _, err = run_cli(list(args), capsys, monkeypatch)
        assert code == 2, (args, err)
        assert err.startswith("pfctl: error: ") and err.count("\n") == 1
        assert message in err
    # the same contract from a real process
    res = _pfctl(*run, "--script", str(bad_script))
    assert res.returncode == 2 and res.stderr.count("\n") == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.csv", "taken"]
    assert [p.name for p in taken.iterdir()] == ["notes.txt"]


def test_velocity_script_errors_name_line_and_column(tmp_path: Path) -> None:
    path = tmp_path / "s.csv"
    for text, message in (
        ("", "empty"),
        ("time,vx,vy,wz\n", ":1: expected the header"),
        ("t,vx,vy,wz\n", "no rows after the header"),
        ("t,vx,vy,wz\n0,0.1,0\n", ":2: expected 4 values"),
        ("t,vx,vy,wz\n0,fast,0,0\n", ":2: vx: expected a number, got 'fast'"),
        ("t,vx,vy,wz\n0,nan,0,0\n", ":2: vx: expected a finite number"),
        ("t,vx,vy,wz\n-1,0,0,0\n", ":2: t: expected a time ≥ 0 s, got -1"),
    ):
        path.write_text(text)
        with pytest.raises(ScriptError, match=message):
            read_velocity_script(path)
    path.write_text("t,vx,vy,wz\n\n0,0.1,0,0\n2.5,0,0,0.3\n")
    steps = read_velocity_script(path)
    assert [s.t for s in steps] == [0.0, 2.5] and steps[1].base.wz == 0.3


def _read_until(fd: int, needle: bytes, timeout: float) -> bytes:
    seen = b""
    end = time.monotonic() + timeout
    while needle not in seen and time.monotonic() < end:
        if select.select([fd], [], [], 0.1)[0]:
            chunk = os.read(fd, 4096)
            if not chunk:
                break
            seen += chunk
    return seen


@pytest.mark.slow
def test_teleop_from_a_terminal_drives_and_quits(tmp_path: Path) -> None:
    master, slave = pty.openpty()
    proc = subprocess.Popen(
        _cmd("sim", "run", str(HOUSE), "--teleop", "--duration", "60", "--no-camera",
             "--record", str(tmp_path / "ep"), "--png", str(tmp_path / "p.png")),
        stdin=slave, stdout=subprocess.PIPE, stderr=slave,
    )  # fmt: skip
    os.close(slave)
    try:
        assert b"keys: w/s forward" in _read_until(master, b"keys:", 30)
        time.sleep(0.5)
        os.write(master, b"wwww")  # 4 steps of 0.05 m/s: 0.2 m/s forward
        time.sleep(2.0)
        os.write(master, b"x")
        out, _ = proc.communicate(timeout=30)
    finally:
        proc.kill()
        os.close(master)
    assert proc.returncode == 130  # ended by the quit key before the 60 s
    assert b"interrupted after" in out
    episode = read_episode(tmp_path / "ep")
    path = episode.robot_path()
    assert 0.15 < path[-1, 0] - path[0, 0] < 0.6  # about 2 s at 0.2 m/s, forward (east)
    assert 1.5 < episode.duration < 10  # paced to the clock


@pytest.mark.slow
def test_ctrl_c_ends_the_run_and_keeps_a_complete_episode(tmp_path: Path) -> None:
    proc = subprocess.Popen(
        _cmd("sim", "run", str(HOUSE), "--realtime", "--duration", "600", "--no-camera",
             "--record", str(tmp_path / "ep"), "--png", str(tmp_path / "p.png")),
        stdout=subprocess.PIPE, stderr=subprocess.PIPE,
    )  # fmt: skip
    try:
        end = time.monotonic() + 30
        while not list(tmp_path.glob(".ep.*")) and time.monotonic() < end:
            time.sleep(0.1)  # the recorder's working folder appears when the run starts
        time.sleep(1.5)
        proc.send_signal(signal.SIGINT)
        out, err = proc.communicate(timeout=30)
    finally:
        proc.kill()
    assert proc.returncode == 130, err
    assert b"interrupted after" in out
    episode = read_episode(tmp_path / "ep")
    assert 0.5 < episode.duration < 20 and len(episode.scans) == len(episode.truths)
    assert (tmp_path / "p.png").read_bytes()[:8] == PNG
    assert not list(tmp_path.glob(".ep.*"))  # no working folder left behind
