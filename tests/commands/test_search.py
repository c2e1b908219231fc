"""``pfctl search``: the target hidden somewhere in the simulated house, the robot searches
(belief + Algorithm 1 + frontiers) until it identifies her; metrics.json and search.png."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from pfctl.app.episodes import hide_target
from pfctl.app.sim import sim_config
from pfctl.backends.pybullet.simulation import SimOptions, SimRobot
from pfctl.mission import load_mission

pytestmark = pytest.mark.sim

ROOT = Path(__file__).resolve().parents[2]
HOUSE = ROOT / "missions" / "house.yaml"


def _pfctl(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "pfctl", *args],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=600,
    )


def _near(points: np.ndarray, xy: tuple[float, float], radius: float) -> int:
    return int(np.count_nonzero(np.hypot(points[:, 0] - xy[0], points[:, 1] - xy[1]) < radius))


def test_the_hidden_target_is_gone_from_the_first_observation() -> None:
    mission = load_mission(HOUSE)
    with SimRobot(sim_config(mission, 3), SimOptions(camera=False)) as robot:
        alice = next(w for w in robot.people if w.is_target)
        start = (alice.x, alice.y)
        before = robot.observe().scan
        assert before is not None and _near(before.points(), start, 0.3) > 0  # her legs
    with SimRobot(sim_config(mission, 3), SimOptions(camera=False)) as robot:
        region = hide_target(mission, robot, "bedroom")
        after = robot.observe().scan
        alice = next(w for w in robot.people if w.is_target)
        assert region == "bedroom" and robot.ground_truth().stamp == 0.0
        assert after is not None and _near(after.points(), start, 0.3) == 0
        assert (alice.x, alice.y) != start


@pytest.mark.slow
def test_search_finds_the_target_in_the_hall_and_writes_its_files(tmp_path: Path) -> None:
    out = tmp_path / "search"
    result = _pfctl(
        "search", "missions/house.yaml", "--backend", "sim", "--seed", "3",
        "--region", "hall", "--duration", "60", "--out", str(out),
    )  # fmt: skip
    assert result.returncode == 0, result.stderr
    assert "found the target after" in result.stdout
    metrics = json.loads((out / "metrics.json").read_text())
    assert metrics["found"] is True and metrics["region"] == "hall"
    assert 0.0 < metrics["time_to_find_s"] < 60.0
    assert metrics["distance_m"] > 1.0 and metrics["collisions"] == 0
    assert (out / "search.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize(
    ("args", "expected"),
    [
        (["--region", "attic"], "--region attic: unknown region"),
        (["--duration", "0"], "--duration"),
    ],
)
@pytest.mark.slow
def test_bad_search_options_are_one_line_and_exit_2(
    tmp_path: Path, args: list[str], expected: str
) -> None:
    out = tmp_path / "never"
    result = _pfctl("search", "missions/house.yaml", "--backend", "sim", "--out", str(out), *args)
    assert result.returncode == 2
    assert expected in result.stderr and len(result.stderr.strip().splitlines()) == 1
    assert not out.exists()
