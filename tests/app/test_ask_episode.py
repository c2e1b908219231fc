"""Asking to see the face, on rendered frames (issue 23): the target stands facing a wall 0.9 m
off, the robot behind her; a look-alike in her clothes, seen face on, stands in the same room,
so her clothes name no one and only her face can. There is no place in front of her to see it
from. ``pfctl search``'s episode: the robot goes up to her, looks at her back, asks her to look
at it, and she (within earshot, standing) turns; her face names her. With people who do not
turn to a voice (``scenario.turn_to_voice: false``) she is not found."""

from __future__ import annotations

import math

import pytest
from rich.progress import Progress

from pfctl.app.episodes import LEARN_SECONDS, metric_params, run_sim_episode
from pfctl.app.learn_target import learn_in_sim
from pfctl.app.perception import identity_params
from pfctl.app.sim import sim_config
from pfctl.backends.pybullet.simulation import SimRobot
from pfctl.core.behavior.leaves import WaypointSearch
from pfctl.core.metrics import follow_metrics
from pfctl.core.perception.identity.profile import learn_profile
from pfctl.mission import Mission, loads_mission

pytestmark = [pytest.mark.sim, pytest.mark.slow]

# One room, 7 x 5 m. Alice walks 0.6 m east and stands facing the east wall, 0.9 m from it;
# carol, in alice's clothes, walks 1 m west and stands facing the robot.
ROOM = """
name: facing-the-wall
map:
  regions:
    - {name: office, polygon: [[0, 0], [7, 0], [7, 5], [0, 5]]}
robot: {start: {x: 1.2, y: 2.5, theta: 0.0}}
sensors: {laser: {noise_std: 0.01}}
scenario:
  seed: 1
  target: alice
  people:
    - {name: alice, clothes: {upper: [200, 30, 40], lower: [40, 40, 120]}, speed: 0.6,
       route: [[5.5, 2.5], [6.1, 2.5]]}
    - {name: carol, clothes: {upper: [200, 30, 40], lower: [40, 40, 120]}, speed: 0.6,
       route: [[4.5, 4.2], [3.5, 4.2]]}
"""
SEED = 1
SECONDS = 40.0


def _mission(turn_to_voice: bool) -> Mission:
    mission = loads_mission(ROOM, source="facing_the_wall.yaml")
    scenario = mission.scenario.model_copy(update={"turn_to_voice": turn_to_voice})
    return mission.model_copy(update={"scenario": scenario})


def test_she_faces_a_wall_the_robot_asks_she_turns_and_her_face_names_her() -> None:
    runs = {}
    for turn_to_voice in (True, False):
        mission = _mission(turn_to_voice)
        params = identity_params(mission)
        with Progress(disable=True) as progress:
            learned = learn_in_sim(mission, LEARN_SECONDS, SEED, params, progress)
        profile = learn_profile(learned.appearances, params)
        with SimRobot(sim_config(mission, SEED)) as robot:
            log = run_sim_episode(mission, robot, profile, SECONDS, until_found=True).log
            runs[turn_to_voice] = (log, follow_metrics(log, metric_params(mission)))
            alice = next(w for w in robot.people if w.name == "alice")
            facing = alice.theta
    log, metrics = runs[True]
    assert [s.text for s in log.speech] == [WaypointSearch.ASK]  # asked her once
    asked = log.speech[0]
    assert math.dist(asked.xy, (6.1, 2.5)) <= WaypointSearch.APPROACH_NEAR
    found = metrics.first_identified_s
    assert found is not None and asked.t < found <= asked.t + 4.0  # named on her turned face
    assert metrics.identity_switches == 0 and metrics.collisions == 0
    ticks = zip(log.ticks, log.truths, strict=True)
    named, truth = next((t, g) for t, g in ticks if t.target_id is not None)
    her = next(p for p in truth.people if p.name == "alice")
    assert named.target_xy is not None
    assert math.dist(named.target_xy, (her.x, her.y)) < 0.5  # alice named, not carol
    # people who do not turn to a voice: asked just the same, and she stays unfound
    log, metrics = runs[False]
    assert [s.text for s in log.speech] == [WaypointSearch.ASK]
    assert metrics.first_identified_s is None
    assert abs(facing) < 0.1  # she still faces the wall
