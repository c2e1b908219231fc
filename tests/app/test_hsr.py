"""The HSR backend's config carries the mission's values (pfctl.app.hsr)."""

from __future__ import annotations

from dataclasses import asdict
from pathlib import Path

from pfctl.app.hsr import hsr_config
from pfctl.mission import BackendConfig, HsrConfig, load_mission

HOUSE = Path(__file__).resolve().parents[2] / "missions" / "house.yaml"


def test_topics_frames_timeouts_limits_and_period_are_the_missions() -> None:
    mission = load_mission(HOUSE)
    hsr = HsrConfig(pose="/global_pose", person_keypoints="/pfctl/person_keypoints")
    mission = mission.model_copy(update={"backend": BackendConfig(hsr=hsr)})
    config = hsr_config(mission)
    values = asdict(config)
    assert {k: v for k, v in values.items() if k in HsrConfig.model_fields} == hsr.model_dump()
    assert config.person_labels is None and config.pose == "/global_pose"
    assert config.limits.max_linear_speed == mission.robot.max_linear_speed
    assert config.limits.head_pan_limits == mission.robot.head_pan_limits
    assert config.tick_period == 1.0 / mission.behavior.tick_hz
    assert config.min_pixels == mission.perception.vision.min_pixels
