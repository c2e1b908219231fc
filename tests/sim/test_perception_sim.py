"""The laser perception on simulated scans: legs → person candidates → tracks with stable ids."""

from __future__ import annotations

import math

import pytest

from pfctl.backends.pybullet.simulation import SimOptions, SimRobot
from pfctl.mission import loads_mission
from pfctl.perception_setup import build_perception

# Ann and Ben walk X-shaped paths that cross at (5, 3), 4 m in front of the robot; Ben is slower,
# so he passes the crossing point about 0.6 m behind Ann, partly hidden by her for a moment.
CROSSING = """
name: crossing
map:
  regions:
    - {name: hall, polygon: [[0, 0], [10, 0], [10, 6], [0, 6]]}
robot: {start: {x: 1.0, y: 3.0, theta: 0.0}}
sensors: {laser: {noise_std: 0.01}}
scenario:
  seed: SEED
  people:
    - {name: ann, clothes: {upper: [200, 30, 40], lower: [40, 40, 120]}, speed: 0.8,
       route: [[3.5, 5.0], [6.5, 1.0]]}
    - {name: ben, clothes: {upper: [30, 120, 200], lower: [60, 60, 60]}, speed: 0.6,
       route: [[3.5, 1.0], [6.5, 5.0]]}
"""


@pytest.mark.parametrize("seed", [2, 3])
def test_two_people_crossing_paths_keep_their_track_ids(seed: int) -> None:
    mission = loads_mission(CROSSING.replace("SEED", str(seed)), source="crossing.yaml")
    perception = build_perception(mission)
    owners: dict[str, set[int]] = {"ann": set(), "ben": set()}
    seen_crossing = False
    with SimRobot(mission, SimOptions(camera=False)) as robot:
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
