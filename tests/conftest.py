"""Shared fixtures and helpers: the shipped house, running the CLI in-process."""

from __future__ import annotations

import signal
import sys
from pathlib import Path

import pytest

from pfctl import cli
from pfctl.core.mapping.house import HouseLayout
from pfctl.core.mapping.planning import GridPlanner
from pfctl.core.mapping.walls import rasterize_house
from pfctl.mission import Mission, load_mission

HOUSE_MISSION = Path(__file__).resolve().parents[1] / "missions" / "house.yaml"


def pytest_configure(config: pytest.Config) -> None:
    """Ctrl-C as in a terminal for the commands the tests start and interrupt: a run started in
    the background (``nohup … &``, some CI runners) inherits SIGINT ignored, passes it on to its
    children, and pfctl rightly keeps a signal it was started ignoring ignored."""
    if signal.getsignal(signal.SIGINT) == signal.SIG_IGN:
        signal.signal(signal.SIGINT, signal.default_int_handler)


@pytest.fixture(scope="session")
def layout() -> HouseLayout:
    """The region map, doors and furniture of ``missions/house.yaml``."""
    return load_mission(HOUSE_MISSION).layout()


@pytest.fixture(scope="module")
def mission() -> Mission:
    """``missions/house.yaml`` (a test module may define its own ``mission``)."""
    return load_mission(HOUSE_MISSION)


@pytest.fixture(scope="module")
def planner(mission: Mission) -> GridPlanner:
    """The grid planner of ``mission``'s house (walls rasterised) for the robot's radius."""
    grid = rasterize_house(mission.layout(), mission.map.resolution, mission.map.wall_thickness)
    return GridPlanner(grid, mission.robot.radius)


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


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """Every test of the HSR backend needs ROS 1: one without the ``ros`` marker would run in the
    quick loop (``-m "not slow and not ros"``) and fail or skip there."""
    for item in items:
        if item.nodeid.startswith("tests/backends/hsr/") and item.get_closest_marker("ros") is None:
            raise pytest.UsageError(
                f"{item.nodeid}: a test of the HSR backend without the ros marker"
            )
