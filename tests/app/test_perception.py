"""The laser perception on simulated scans: legs → person candidates → tracks with stable ids."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from pfctl.app.perception import build_perception
from pfctl.app.sim import sim_config
from pfctl.backends.pybullet.simulation import SimOptions, SimRobot
from pfctl.mission import loads_mission

pytestmark = pytest.mark.sim

# Ann and Ben walk X-shaped paths that cross at (5, 3), 4 m in front of the robot; Ben is slower,
# so he passes the crossing point about 0.6 m behind Ann, partly hidden by her for a moment.
CROSSING = (Path(__file__).parent / "crossing.yaml").read_text()


@pytest.mark.parametrize("seed", [2, 3])
def test_two_people_crossing_paths_keep_their_track_ids(seed: int) -> None:
    mission = loads_mission(CROSSING.replace("seed: 2", f"seed: {seed}"), source="crossing.yaml")
    perception = build_perception(mission)
    owners: dict[str, set[int]] = {"ann": set(), "ben": set()}
    seen_crossing = False
    with SimRobot(sim_config(mission), SimOptions(camera=False)) as robot:
        while robot.time < 7.0:
            robot.step()
            observation = robot.observe()
            if observation.scan is None:
                continue
            perception.on_scan(observation.scan)
            truth = {p.name: (p.x, p.y) for p in robot.ground_truth().people}
            ann, ben = truth["ann"], truth["ben"]
            seen_crossing |= math.dist(ann, ben) < 0.8
            for track in perception.tracks():
                for name, (x, y) in truth.items():
                    if math.hypot(track.x - x, track.y - y) < 0.3:
                        owners[name].add(track.id)
    assert seen_crossing, "the two people never came close: the scenario does not test a crossing"
    assert len(owners["ann"]) == 1 and len(owners["ben"]) == 1, owners
    assert owners["ann"] != owners["ben"]
