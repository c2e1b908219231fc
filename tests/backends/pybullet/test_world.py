"""FastLaser on the house's static scene agrees with PyBullet's rayTestBatch on the built world."""

from pathlib import Path

import numpy as np
import pybullet as p
import pytest

from pfctl.app.sim import house_config
from pfctl.backends.pybullet.laser import FastLaser
from pfctl.backends.pybullet.world import build_world
from pfctl.core.robot import Pose2D
from pfctl.mission import load_mission

pytestmark = pytest.mark.sim

HOUSE = Path(__file__).parents[3] / "missions" / "house.yaml"


def test_fast_laser_matches_ray_test_batch_in_house() -> None:
    mission = load_mission(HOUSE)
    client = p.connect(p.DIRECT)
    try:
        world = build_world(client, house_config(mission))
        laser = FastLaser(world.scene.segments)
        r0 = mission.layout().regions[0].polygon
        cx, cy = np.mean(np.array(r0), axis=0)
        scan = laser.scan(Pose2D(float(cx), float(cy), 0.4), np.empty((0, 3)), 0.0)
        lp = scan.pose
        ang = lp.theta + scan.angles
        start = [[lp.x, lp.y, 0.19]] * len(ang)
        end = [[lp.x + 20 * np.cos(a), lp.y + 20 * np.sin(a), 0.19] for a in ang]
        hits = p.rayTestBatch(start, end, physicsClientId=client)
        ref = np.array([h[2] * 20 if h[0] >= 0 else np.inf for h in hits])
        both = np.isfinite(ref) & np.isfinite(scan.ranges)
        assert both.mean() > 0.9
        assert np.median(np.abs(ref[both] - scan.ranges[both])) < 0.01
    finally:
        p.disconnect(client)
