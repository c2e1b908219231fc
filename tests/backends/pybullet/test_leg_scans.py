"""Labelled simulated leg scans and the shipped leg model on them (§II-E)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from pfctl.app.leg_models import load_leg_model
from pfctl.app.sim import house_config
from pfctl.backends.pybullet.laser import FastLaser
from pfctl.backends.pybullet.leg_scans import LASERS, LegScanGenerator, simulate_leg_scans
from pfctl.backends.pybullet.walkers import LEG_RADIUS
from pfctl.core.perception.legs.detector import LegDetector, LegParams, describe_segments
from pfctl.core.perception.legs.training import LegDataset, label_by_circles, scan_samples
from pfctl.core.robot import Pose2D
from pfctl.mission import load_mission

pytestmark = pytest.mark.sim

HOUSE = Path(__file__).resolve().parents[3] / "missions" / "house.yaml"


@pytest.fixture(scope="module")
def generator() -> LegScanGenerator:
    return LegScanGenerator(house_config(load_mission(HOUSE)))


def test_scans_are_seeded_and_labelled(generator: LegScanGenerator) -> None:
    a = generator.draw(np.random.default_rng(5))
    b = generator.draw(np.random.default_rng(5))
    np.testing.assert_array_equal(a.scan.ranges, b.scan.ranges)
    assert a.legs.shape == (2 * a.people, 3)
    scans = list(simulate_leg_scans(house_config(load_mission(HOUSE)), 40, seed=1))
    assert {s.laser for s in scans} == {m.name for m in LASERS}
    people = [s.people for s in scans]
    assert min(people) >= 0 and max(people) <= 8 and sum(people) > 40
    params = LegParams()
    data = LegDataset("sim")
    for s in scans:
        data.add("x", *scan_samples(s.scan, params, circles=s.legs))
    assert 0.1 < data.positives / len(data) < 0.6
    for s in scans:  # every person's legs are 0.5–6 m from the laser
        if len(s.legs):
            d = np.hypot(s.legs[:, 0] - s.scan.pose.x, s.legs[:, 1] - s.scan.pose.y)
            assert d.min() > 0.3 and d.max() < 6.3
            assert np.all(
                (s.legs[:, 2] >= 0.8 * LEG_RADIUS - 1e-9)
                & (s.legs[:, 2] <= 1.35 * LEG_RADIUS + 1e-9)
            )


def test_leg_segments_are_labelled_by_the_true_circles(generator: LegScanGenerator) -> None:
    laser = FastLaser(generator.segments, LASERS[0].spec, seed=0, one_sided=True)
    pose = Pose2D(6.0, 2.0, 0.0)
    legs = np.array([[8.0, 2.12, LEG_RADIUS], [8.0, 1.88, LEG_RADIUS]])
    scan = laser.scan(pose, legs, 0.0)
    segs, _, ok = describe_segments(scan, LegParams())
    lab = label_by_circles(segs, scan.pose, legs)
    assert lab.sum() == 2 and ok[lab].all()


def test_shipped_model_finds_standing_people_and_nothing_in_an_empty_room(
    generator: LegScanGenerator,
) -> None:
    detector = LegDetector(load_leg_model(None), LegParams())
    spec = LASERS[0].spec
    laser = FastLaser(generator.segments, spec, seed=3, one_sided=True)
    pose = Pose2D(6.0, 2.0, 0.3)  # living room, looking along it
    for d in (1.0, 2.0, 3.0, 4.0):
        cx, cy = pose.x + d * math.cos(pose.theta), pose.y + d * math.sin(pose.theta)
        side = np.array([-math.sin(pose.theta), math.cos(pose.theta)]) * 0.1
        legs = np.array(
            [[cx + side[0], cy + side[1], LEG_RADIUS], [cx - side[0], cy - side[1], LEG_RADIUS]]
        )
        found = detector.detect(laser.scan(pose, legs, 0.0))
        assert len(found.legs) == 2, d
        assert len(found.people) == 1, d
        person = found.people[0]
        assert len(person.legs) == 2
        assert math.hypot(person.x - cx, person.y - cy) < 0.1, d
    empty = detector.detect(laser.scan(pose, np.empty((0, 3)), 0.0))
    assert empty.legs == () and empty.people == ()
