"""Shared fixtures: the shipped house."""

from __future__ import annotations

from pathlib import Path

import pytest

from pfctl.core.house import HouseLayout
from pfctl.mission import load_mission

HOUSE_MISSION = Path(__file__).resolve().parents[1] / "missions" / "house.yaml"


@pytest.fixture(scope="session")
def layout() -> HouseLayout:
    """The region map, doors and furniture of ``missions/house.yaml``."""
    return load_mission(HOUSE_MISSION).layout()
