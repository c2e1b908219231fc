"""The simulator's config carries the mission's values (pfctl.app.sim)."""

from __future__ import annotations

from dataclasses import asdict
from pathlib import Path

from pfctl.app.sim import sim_config
from pfctl.core.robot import Pose2D
from pfctl.mission import load_mission

CROWD = Path(__file__).resolve().parents[2] / "missions" / "house_crowd.yaml"


def _same(config: object, section: object) -> None:
    values = asdict(config)  # type: ignore[call-overload]
    dumped = section.model_dump()  # type: ignore[attr-defined]
    assert values == {k: dumped[k] for k in values}


def test_every_value_is_the_missions() -> None:
    mission = load_mission(CROWD)
    config = sim_config(mission)
    _same(config.laser, mission.sensors.laser)
    _same(config.camera, mission.sensors.camera)
    _same(config.pose_noise, mission.sensors.pose)
    _same(config.robot, mission.robot)
    _same(config.scenario.randomize, mission.scenario.randomize)
    assert config.house.layout == mission.layout()
    assert config.house.wall_height == mission.map.wall_height
    assert [p.name for p in config.scenario.people] == [p.name for p in mission.scenario.people]
    assert config.scenario.people[0].route == mission.scenario.people[0].route
    assert config.scenario.people[0].clothes.upper == mission.scenario.people[0].clothes.upper
    assert config.scenario.target == mission.scenario.target
    assert config.start == Pose2D(*mission.start_pose())
    assert config.tick_period == 1.0 / mission.behavior.tick_hz
    assert config.seed == mission.scenario.seed and sim_config(mission, 11).seed == 11
