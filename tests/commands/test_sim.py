"""`pfctl sim export-map`: the static map round-trips; bad input is one line and exit 2."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from pfctl.core.mapping.walls import rasterize_house
from pfctl.mission import load_mission
from pfctl.mission.map_server import load_map_server

pytestmark = pytest.mark.sim

HOUSE = Path(__file__).resolve().parents[2] / "missions" / "house.yaml"


def _pfctl(*args: str) -> subprocess.CompletedProcess[str]:
    cmd = [sys.executable, "-c", "from pfctl.cli import main; main()", *args]
    return subprocess.run(cmd, capture_output=True, text=True, check=False)


def test_export_map_round_trips(tmp_path: Path) -> None:
    out = tmp_path / "maps" / "house.yaml"
    res = _pfctl("sim", "export-map", str(HOUSE), "--out", str(out))
    assert res.returncode == 0, res.stderr
    loaded = load_map_server(out)
    mission = load_mission(HOUSE)
    expected = rasterize_house(
        mission.layout(), mission.map.resolution, wall_thickness=mission.map.wall_thickness
    )
    assert loaded.shape == expected.shape
    assert np.array_equal(loaded.states(), expected.states())


@pytest.mark.slow
def test_bad_inputs_exit_2_with_one_line(tmp_path: Path) -> None:
    for args in (
        ("sim", "export-map", str(tmp_path / "nope.yaml"), "--out", str(tmp_path / "m.yaml")),
        ("sim", "export-map", str(HOUSE), "--out", str(tmp_path / "m.png")),
        ("sim", "export-map", str(HOUSE), "--out", str(tmp_path / "m.yaml"), "--resolution", "0"),
    ):
        res = _pfctl(*args)
        assert res.returncode == 2
        assert res.stderr.startswith("pfctl: error: ") and res.stderr.count("\n") == 1
    assert list(tmp_path.iterdir()) == []
