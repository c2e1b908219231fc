"""The paper's episode end to end (§III-B): ``pfctl follow missions/house.yaml --backend sim
--seed 1`` — the robot learns Alice, follows her from the kitchen, loses her at the office door,
goes to the SVR prediction and looks around, starts way-point search (Algorithm 1), reaches the
office's hidden side, re-identifies her and follows again; no identity switch, no collision."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = [pytest.mark.sim, pytest.mark.slow]

HOUSE = Path(__file__).resolve().parents[2] / "missions" / "house.yaml"
#: Re-identification must come within this long after the loss, seconds.
REFIND_WITHIN_S = 45.0


@pytest.fixture(scope="module")
def episode(tmp_path_factory: pytest.TempPathFactory) -> tuple[int, str, Path]:
    """One run of the real command line (it learns Alice first, as a user's run would)."""
    out = tmp_path_factory.mktemp("follow")
    args = ["follow", str(HOUSE), "--backend", "sim", "--seed", "1", "--duration", "60"]
    done = subprocess.run(
        [sys.executable, "-m", "pfctl", *args, "--out", str(out)],
        capture_output=True,
        text=True,
        timeout=900,
    )
    return done.returncode, done.stdout + done.stderr, out


def test_the_paper_episode_loses_predicts_searches_and_refinds(
    episode: tuple[int, str, Path],
) -> None:
    code, text, out = episode
    assert code == 0, text
    metrics = json.loads((out / "metrics.json").read_text())
    for key in (
        "following_rate",
        "losses",
        "reacquisitions",
        "identity_switches",
        "collisions",
        "distance_m",
    ):
        assert key in metrics
    assert metrics["first_identified_s"] is not None and metrics["first_identified_s"] < 2.0
    assert metrics["losses"] >= 1
    first = metrics["reacquisitions"][0]
    assert first["how"] == "waypoint_search", metrics["reacquisitions"]
    assert first["t_found"] - first["t_lost"] <= REFIND_WITHIN_S
    assert metrics["identity_switches"] == 0
    assert metrics["collisions"] == 0
    assert metrics["following_rate"] > 0.3
    assert "re-acquired" in text and "waypoint_search" in text


def test_the_episode_writes_its_figures(episode: tuple[int, str, Path]) -> None:
    _, _, out = episode
    for name in ("trajectory.png", "timeline.png"):
        data = (out / name).read_bytes()
        assert data.startswith(b"\x89PNG") and len(data) > 20_000
