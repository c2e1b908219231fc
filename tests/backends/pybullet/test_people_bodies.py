"""People bodies in PyBullet: seen by rayTestBatch and the camera, moved by sync, no contacts."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pybullet as p
import pytest

from pfctl.app.sim import sim_config
from pfctl.backends.pybullet.people_bodies import PeopleBodies, face_texture
from pfctl.backends.pybullet.walkers import LEG_RADIUS, Walker, make_walkers
from pfctl.core.mapping.planning import GridPlanner
from pfctl.core.mapping.walls import rasterize_house
from pfctl.mission import Mission, load_mission

pytestmark = pytest.mark.sim

HOUSE = Path(__file__).resolve().parents[3] / "missions" / "house.yaml"


def _make_walkers(mission: Mission, planner: GridPlanner, seed: int) -> list[Walker]:
    return make_walkers(sim_config(mission).scenario, mission.layout(), planner, seed)


@pytest.fixture()
def world():
    mission = load_mission(HOUSE)
    grid = rasterize_house(mission.layout(), mission.map.resolution, mission.map.wall_thickness)
    walkers = _make_walkers(mission, GridPlanner(grid, mission.robot.radius), seed=7)
    client = p.connect(p.DIRECT)
    bodies = PeopleBodies(client, walkers, seed=7)
    yield client, walkers, bodies
    bodies.close()
    p.disconnect(client)


def _scan(client: int, origin: np.ndarray, height: float, n: int = 721):
    angles = np.linspace(-math.pi, math.pi, n, endpoint=False)
    to = origin + 6.0 * np.column_stack((np.cos(angles), np.sin(angles)))
    res = p.rayTestBatch(
        [(*origin, height)] * n, [(*t, height) for t in to], physicsClientId=client
    )
    ids = np.array([r[0] for r in res])
    hits = np.array([r[3][:2] for r in res])
    return ids, hits


def test_the_laser_sees_two_legs_where_the_walker_puts_them(world) -> None:
    client, walkers, bodies = world
    alice = walkers[0]
    for _ in range(40):  # walking: legs apart
        alice.step(0.05)
    bodies.sync()
    state = alice.state
    origin = np.array([state.x, state.y]) + 1.5 * np.array(
        [math.cos(state.theta + 1.2), math.sin(state.theta + 1.2)]
    )
    ids, hits = _scan(client, origin, 0.19)
    legs = bodies.body_ids["alice"][:2]
    for leg_id, (lx, ly, r) in zip(legs, state.legs, strict=True):
        mine = hits[ids == leg_id]
        if len(mine) == 0:  # one leg may hide behind the other from this side
            continue
        d = np.linalg.norm(mine - (lx, ly), axis=1)
        assert np.allclose(d, r, atol=0.01)
        assert r == LEG_RADIUS
    assert np.isin(legs, ids).sum() >= 1
    # torso and head are above the laser plane; at 1.2 m the torso is hit instead
    ids_high, _ = _scan(client, origin, 1.2)
    assert bodies.body_ids["alice"][2] in ids_high and not set(legs) & set(ids_high)


def test_camera_segmentation_sees_the_person_and_sync_moves_it(world) -> None:
    client, walkers, bodies = world
    bob = walkers[1]
    state = bob.state
    eye = (state.x + 2.0 * math.cos(state.theta), state.y + 2.0 * math.sin(state.theta), 1.1)
    view = p.computeViewMatrix(eye, (state.x, state.y, 1.0), (0, 0, 1), physicsClientId=client)
    proj = p.computeProjectionMatrixFOV(45.0, 4 / 3, 0.1, 20.0, physicsClientId=client)

    def seg() -> np.ndarray:
        _, _, _, _, mask = p.getCameraImage(
            160, 120, view, proj, renderer=p.ER_TINY_RENDERER, physicsClientId=client
        )
        return np.reshape(mask, (120, 160))

    mask = seg()
    ids = set(np.unique(mask)) & set(bodies.body_ids["bob"])
    assert ids == set(bodies.body_ids["bob"])  # legs, torso and head are all in view
    assert bodies.owner(bodies.body_ids["bob"][3]) == "bob"
    # move him behind the camera, out of the view whichever way he faces
    bob.x, bob.y = state.x + 4.0 * math.cos(state.theta), state.y + 4.0 * math.sin(state.theta)
    bodies.sync()
    assert not set(np.unique(seg())) & set(bodies.body_ids["bob"])


def test_people_do_not_collide_with_each_other_but_block_a_robot(world) -> None:
    client, walkers, bodies = world
    walkers[1].x, walkers[1].y = walkers[0].x + 0.05, walkers[0].y
    bodies.sync()
    robot = p.createMultiBody(
        baseMass=30.0,
        baseCollisionShapeIndex=p.createCollisionShape(
            p.GEOM_CYLINDER, radius=0.215, height=0.3, physicsClientId=client
        ),
        basePosition=(walkers[0].x + 0.2, walkers[0].y, 0.15),
        physicsClientId=client,
    )
    p.stepSimulation(physicsClientId=client)
    alice, bob = bodies.body_ids["alice"], bodies.body_ids["bob"]
    for a in alice:
        for b in bob:
            assert not p.getContactPoints(a, b, physicsClientId=client)
    touching = {c[2] for c in p.getContactPoints(bodyA=robot, physicsClientId=client)}
    assert touching & set(alice[:2])


def test_faces_differ_per_person_and_are_seeded() -> None:
    a = face_texture(np.random.default_rng([7, 0]))
    b = face_texture(np.random.default_rng([7, 1]))
    assert a.shape == (64, 64, 3) and a.dtype == np.uint8
    assert not np.array_equal(a, b)
    assert np.array_equal(a, face_texture(np.random.default_rng([7, 0])))
