"""`pfctl predict` through the real CLI: the default track command, evaluate, search, the door
experiment, and one-line errors with exit status 2."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from tests.conftest import run_cli

ROOT = Path(__file__).resolve().parents[2]
HOUSE = ROOT / "missions" / "house.yaml"
PEDESTRIANS = (ROOT / ".." / "shared" / "data" / "pedestrians").resolve()
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def assert_one_error_line(err: str, *fragments: str) -> None:
    assert "Traceback" not in err
    lines = err.splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("pfctl: error: "), lines[0]
    for fragment in fragments:
        assert fragment in lines[0], lines[0]


def _track_csv(path: Path, start: tuple[float, float], v: tuple[float, float], n: int = 31) -> Path:
    t = np.arange(n) * 0.1
    rows = [f"{ti:.2f},{start[0] + v[0] * ti:.4f},{start[1] + v[1] * ti:.4f}" for ti in t]
    path.write_text("t,x,y\n" + "\n".join(rows) + "\n", encoding="utf-8")
    return path


def _frames_file(path: Path, people: int = 6, steps: int = 26, seed: int = 0) -> Path:
    rng = np.random.default_rng(seed)
    lines = []
    for p in range(people):
        pos = rng.uniform(-5, 5, 2)
        heading = rng.uniform(-np.pi, np.pi)
        speed = rng.uniform(0.8, 1.3)
        for k in range(steps):
            heading += rng.normal(0.0, 0.05)
            pos = pos + 0.4 * speed * np.array([np.cos(heading), np.sin(heading)])
            xy = pos + rng.normal(0.0, 0.02, 2)
            lines.append(f"{10 * k}\t{p + 1}.0\t{xy[0]:.3f}\t{xy[1]:.3f}")
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


# ---------------------------------------------------------------------------- predict TRACK


def test_predict_track_is_the_default_command(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    track = _track_csv(tmp_path / "walk.csv", (0.0, 0.0), (1.0, 0.5))
    code, out, err = run_cli(
        ["predict", str(track), "--horizon", "2", "--model", "cv"], capsys, monkeypatch
    )
    assert code == 0, err
    lines = out.splitlines()
    assert lines[0] == "t,x,y"
    rows = np.array([[float(v) for v in line.split(",")] for line in lines[1:]])
    assert len(rows) == 20  # 2 s at the track's 0.1 s step
    np.testing.assert_allclose(rows[:, 0], 3.0 + 0.1 * np.arange(1, 21), atol=1e-9)
    np.testing.assert_allclose(rows[-1, 1:], [5.0, 2.5], atol=1e-3)  # exact for cv
    code2, out2, _ = run_cli(
        ["predict", "track", str(track), "--horizon", "2", "--model", "cv"], capsys, monkeypatch
    )
    assert code2 == 0 and out2 == out


def test_predict_json_out_file(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    track = _track_csv(tmp_path / "walk.csv", (0.0, 0.0), (1.0, 0.0))
    target = tmp_path / "out" / "pred.json"
    code, out, err = run_cli(
        ["predict", str(track), "--format", "json", "--out", str(target), "--step", "0.5"],
        capsys,
        monkeypatch,
    )
    assert code == 0, err
    assert out == "" and f"wrote {target}" in err
    doc = json.loads(target.read_text())
    assert doc["model"] == "svr" and doc["params"]["C"] == 1000.0
    assert [p["t"] for p in doc["points"]] == pytest.approx([3.5, 4.0, 4.5, 5.0, 5.5, 6.0])
    end = doc["points"][-1]
    assert 5.6 < end["x"] < 6.05 and abs(end["y"]) < 0.05  # ~95 % of 1 m/s for 3 s from x=3


def test_predict_csv_round_trips_ros_epoch_times_and_coordinates(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """ROS-epoch times (~1.73e9 s, 25 ms apart) and metre coordinates far from the origin: the
    CSV holds the same floats as the JSON (repr-exact), none repeated."""
    t0, x0 = 1_732_540_000.123456, 1234.56789012
    rows = [f"{t0 + 0.025 * k!r},{x0 + 0.03 * k!r},{-0.01 * k!r}" for k in range(40)]
    track = tmp_path / "epoch.csv"
    track.write_text("t,x,y\n" + "\n".join(rows) + "\n", encoding="utf-8")
    args = ["predict", str(track), "--horizon", "1", "--model", "cv"]
    code, out, err = run_cli(args, capsys, monkeypatch)
    assert code == 0, err
    code, text, err = run_cli([*args, "--format", "json"], capsys, monkeypatch)
    assert code == 0, err
    points = json.loads(text)["points"]
    cells = [[float(v) for v in line.split(",")] for line in out.splitlines()[1:]]
    assert cells == [[p["t"], p["x"], p["y"]] for p in points]
    assert len({c[0] for c in cells}) == len(cells) == 40  # 1 s at 25 ms, no repeated time
    assert cells[0][0] > t0 + 0.025 * 39


def test_predict_with_mission_clips_reports_region_and_plots(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    # in the hall, walking north at 1 m/s toward the office wall, away from its door
    track = _track_csv(tmp_path / "hall.csv", (5.0, 4.3), (0.0, 0.5))
    plot = tmp_path / "pred.png"
    code, out, err = run_cli(
        [
            "predict",
            str(track),
            "--horizon",
            "3",
            "--model",
            "cv",
            "--mission",
            str(HOUSE),
            "--plot",
            str(plot),
        ],
        capsys,
        monkeypatch,
    )
    assert code == 0, err
    header, *rows = out.splitlines()
    assert header == "t,x,y,region,clipped"
    cells = [r.split(",") for r in rows]
    ys = [float(c[2]) for c in cells]
    assert max(ys) < 6.0  # never into the office wall at y = 6
    assert cells[-1][3] == "hall" and cells[-1][4] == "1" and cells[0][4] == "0"
    assert "cv: predicted" in err and "in hall; stopped at a wall" in err
    assert plot.read_bytes().startswith(PNG_MAGIC) and plot.stat().st_size > 20_000


@pytest.mark.parametrize(
    ("content", "fragments"),
    [
        (None, ["no such file"]),
        ("x,y\n1,2\n2,3\n", ["header has no column t"]),
        ("t,x,y\n0,0,0\n0.1,abc,0\n0.2,0,0\n", [":3:", "x: expected a number, got 'abc'"]),
        ("t,x,y\n0,0,0\n0.1,0,0\n0.1,0,0\n", [":4:", "time must increase"]),
        ("t,x,y\n0,0,0\n0.1,1,0\n", ["2 point(s) in the history, model svr needs at least 3"]),
        ("t,x,y\n0,0,0\n", ["1 point(s), need at least 2"]),
    ],
)
def test_bad_track_files_exit_2_with_one_line(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
    content: str | None,
    fragments: list[str],
) -> None:
    path = tmp_path / "bad.csv"
    if content is not None:
        path.write_text(content, encoding="utf-8")
    code, out, err = run_cli(["predict", str(path)], capsys, monkeypatch)
    assert code == 2 and out == ""
    assert_one_error_line(err, str(path), *fragments)


def test_bad_options_exit_2(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    track = _track_csv(tmp_path / "walk.csv", (0.0, 0.0), (1.0, 0.0))
    code, _, err = run_cli(["predict", str(track), "--model", "lstm"], capsys, monkeypatch)
    assert code == 2
    assert_one_error_line(err, "--model lstm: unknown model")
    code, _, err = run_cli(["predict", str(track), "--horizon", "-1"], capsys, monkeypatch)
    assert code == 2
    assert_one_error_line(err, "--horizon")


@pytest.mark.parametrize(
    ("options", "words"),
    [
        (["--horizon", "1e9", "--step", "0.001"], "1e+12 predicted points at --step 0.001"),
        (["--horizon", "1e9"], "1e+10 predicted points at the track's step of 0.1 s"),
        (["--horizon", "1e300", "--step", "1e-300"], "inf predicted points at --step 1e-300"),
    ],
)
def test_a_horizon_of_too_many_points_is_refused_before_any_work(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
    options: list[str],
    words: str,
) -> None:
    """``--horizon 1e9 --step 0.001`` asked for a trillion points (a MemoryError traceback):
    refused up front, naming the option and the limit, nothing written."""
    track = _track_csv(tmp_path / "walk.csv", (0.0, 0.0), (1.0, 0.0))
    out, plot = tmp_path / "p.csv", tmp_path / "p.png"
    args = ["predict", str(track), *options, "--out", str(out), "--plot", str(plot)]
    code, stdout, err = run_cli(args, capsys, monkeypatch)
    assert code == 2 and stdout == ""
    assert_one_error_line(err, "--horizon", words, "over the limit of 1,000,000")
    assert [p.name for p in tmp_path.iterdir()] == ["walk.csv"]


@pytest.mark.slow
def test_real_process_contract(tmp_path: Path) -> None:
    """The console script for real: exit 2 and one line, no traceback."""
    bad = tmp_path / "bad.csv"
    bad.write_text("t,x,y\n0,0,0\n1,x,0\n2,0,0\n", encoding="utf-8")
    run = subprocess.run(
        [sys.executable, "-m", "pfctl", "predict", str(bad)],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert run.returncode == 2 and run.stdout == ""
    assert_one_error_line(run.stderr, f"{bad}:3: x: expected a number")


# ---------------------------------------------------------------------------- evaluate


def test_evaluate_prints_table_and_writes_json(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    data = _frames_file(tmp_path / "scene.txt")
    target = tmp_path / "scores.json"
    code, out, err = run_cli(
        [
            "predict",
            "evaluate",
            str(data),
            "--format",
            "frames",
            "--fps",
            "2.5",
            "--jobs",
            "2",
            "--json",
            str(target),
        ],
        capsys,
        monkeypatch,
    )
    assert code == 0, err
    assert "42 windows of 6 tracks" in out  # 6 people × (26 − 20 + 1)
    for name in ("svr", "svr-time", "poly3", "cv"):
        assert name in out
    doc = json.loads(target.read_text())
    assert set(doc["models"]) == {"svr", "svr-time", "poly3", "cv"}
    for scores in doc["models"].values():
        assert scores["n"] == 42
        for key in ("ade", "fde", "ms_per_call"):
            assert math.isfinite(scores[key]) and scores[key] >= 0.0
    assert doc["fps"] == 2.5 and doc["obs"] == 8 and doc["pred"] == 12


def test_evaluate_csv_folder_and_model_subset(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    for i in range(3):
        _track_csv(tmp_path / f"w{i}.csv", (i, 0.0), (1.0, 0.2 * i), n=25)
    code, out, err = run_cli(
        ["predict", "evaluate", str(tmp_path), "--format", "csv", "--models", "cv,svr"],
        capsys,
        monkeypatch,
    )
    assert code == 0, err
    assert "18 windows of 3 tracks" in out and "poly3" not in out
    cv_row = next(line for line in out.splitlines() if "│ cv" in line)
    assert "0.000" in cv_row  # straight tracks: cv is exact


@pytest.mark.parametrize(
    ("args", "fragments"),
    [
        (["--format", "frames"], ["--fps: required with --format frames"]),
        (["--format", "csv", "--fps", "2"], ["only for --format frames"]),
        (["--format", "frames", "--fps", "2.5", "--models", "knn"], ["--models knn"]),
        (["--format", "frames", "--fps", "2.5", "--obs", "3"], ["--obs 3", "at least 4"]),
        (["--format", "frames", "--fps", "2.5", "--pred", "40"], ["no track has 48"]),
    ],
)
def test_evaluate_bad_input(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
    args: list[str],
    fragments: list[str],
) -> None:
    data = _frames_file(tmp_path / "scene.txt")
    code, _, err = run_cli(["predict", "evaluate", str(data), *args], capsys, monkeypatch)
    assert code == 2
    assert_one_error_line(err, *fragments)


def test_search_reports_best_and_test_scores(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    scenes = []
    for k in range(2):
        folder = tmp_path / f"scene{k}"
        folder.mkdir()
        _frames_file(folder / "s.txt", people=8, seed=k)
        scenes.append(str(folder))
    target = tmp_path / "search.json"
    code, out, err = run_cli(
        [
            "predict",
            "search",
            *scenes,
            "--model",
            "cv",
            "--grid",
            "window_s=0.4,0.8,2.0",
            "--fps",
            "2.5",
            "--json",
            str(target),
        ],
        capsys,
        monkeypatch,
    )
    assert code == 0, err
    assert "best cv: window_s=" in out and "test ADE" in out
    doc = json.loads(target.read_text())
    assert len(doc["candidates"]) == 3 and set(doc["scenes"]) == {"scene0", "scene1"}
    assert math.isfinite(doc["best"]["test"]["ade"])
    code, _, err = run_cli(
        ["predict", "search", *scenes, "--grid", "bogus=1", "--fps", "2.5"], capsys, monkeypatch
    )
    assert code == 2
    assert_one_error_line(err, "--grid 'bogus=1'", "no parameter bogus")


# ---------------------------------------------------------------------------- experiment door


def test_door_experiment_reproduces_the_papers_finding(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    plot = tmp_path / "door.png"
    target = tmp_path / "door.json"
    code, out, err = run_cli(
        ["predict", "experiment", "door", "--plot", str(plot), "--json", str(target)],
        capsys,
        monkeypatch,
    )
    assert code == 0, err
    for word in ("left", "straight", "right", "1 s", "2 s", "3 s", "poly3", "svr"):
        assert word in out
    means = json.loads(target.read_text())["mean_error_m"]
    for case in ("left", "right"):
        assert means[case]["poly3"][2] > means[case]["svr"][2], means[case]
    assert plot.read_bytes().startswith(PNG_MAGIC) and plot.stat().st_size > 30_000


# ---------------------------------------------------------------------------- real data


@pytest.mark.skipif(
    not (PEDESTRIANS / "hotel").is_dir(),
    reason=f"real pedestrian data not found at {PEDESTRIANS}/hotel (not shipped with pfctl)",
)
def test_hotel_default_beats_constant_velocity(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """ETH hotel, 8 observed / 12 predicted steps at 0.4 s. Measured: svr 0.262/0.504 m,
    cv 0.270/0.521 m (ADE/FDE)."""
    target = tmp_path / "hotel.json"
    code, _, err = run_cli(
        [
            "predict",
            "evaluate",
            str(PEDESTRIANS / "hotel"),
            "--format",
            "frames",
            "--fps",
            "2.5",
            "--models",
            "svr,cv",
            "--jobs",
            "2",
            "--json",
            str(target),
        ],
        capsys,
        monkeypatch,
    )
    assert code == 0, err
    models = json.loads(target.read_text())["models"]
    assert models["svr"]["n"] == models["cv"]["n"] == 1197
    assert models["svr"]["ade"] < models["cv"]["ade"]
    assert models["svr"]["fde"] < models["cv"]["fde"]
    assert 0.2 < models["cv"]["ade"] < 0.35
