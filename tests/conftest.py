"""Shared fixtures and helpers: the shipped house, running the CLI in-process."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

from pfctl import cli
from pfctl.core.house import HouseLayout
from pfctl.mission import load_mission

HOUSE_MISSION = Path(__file__).resolve().parents[1] / "missions" / "house.yaml"


@pytest.fixture(scope="session")
def layout() -> HouseLayout:
    """The region map, doors and furniture of ``missions/house.yaml``."""
    return load_mission(HOUSE_MISSION).layout()


def run_cli(
    args: list[str], capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> tuple[int, str, str]:
    """Run ``pfctl ARGS`` in-process as the console script does; (status, stdout, stderr)."""
    monkeypatch.setattr(sys, "argv", ["pfctl", *args])
    with pytest.raises(SystemExit) as exited:
        cli.main()
    captured = capsys.readouterr()
    code = exited.value.code
    return (code if isinstance(code, int) else 0 if code is None else 1), captured.out, captured.err
