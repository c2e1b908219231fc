"""Episode recording: a ROS 1 bag written through rosbags reads back to the same values."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from pfctl.bags.recording import (
    BAG_NAME,
    EpisodeRecorder,
    RecordingError,
    read_episode,
)
from pfctl.core.robot import (
    GroundTruth,
    HeadState,
    LaserScan,
    Observation,
    PersonTruth,
    Pose2D,
    Twist2D,
)

pytestmark = pytest.mark.sim


def _tick(i: int) -> tuple[Observation, GroundTruth]:
    t = 0.1 * i
    pose = Pose2D(1.0 + 0.1 * i, 2.0, 0.3)
    laser = Pose2D(*map(float, pose.transform([[0.167, 0.0]])[0]), 0.3)
    scan = LaserScan(t, -2.0, 0.01, 0.05, 20.0, np.array([1.0, np.inf, 2.5 + i]), laser)
    odom = Pose2D(0.1 * i, 0.01 * i, 0.05)  # drifted: the map pose and odometry disagree
    obs = Observation(
        t, pose, HeadState(0.1, -0.2), (scan,) if i % 2 == 0 else (), None, i, odometry=odom
    )
    people = (
        PersonTruth("alice", 3.0, 4.0 + i, 1.0, 0.8, True),
        PersonTruth("bob", 5.0, 4.0, 0.0, 0.5),
    )
    return obs, GroundTruth(t, pose, people, Twist2D(0.2, 0.0, 0.1), i)


def test_episode_reads_back(tmp_path: Path) -> None:
    out = tmp_path / "ep"
    ticks = [_tick(i) for i in range(6)]
    with EpisodeRecorder(out, "house") as rec:
        for obs, truth in ticks:
            rec.add(obs, truth)
    assert sorted(p.name for p in out.iterdir()) == ["episode.bag", "episode.json", "truth.csv"]
    ep = read_episode(out)
    assert ep.mission_name == "house" and ep.target == "alice"
    assert len(ep.truths) == 6 and len(ep.scans) == 3
    for (_obs, truth), got in zip(ticks, ep.truths, strict=True):
        assert got.robot.x == pytest.approx(truth.robot.x)
        assert got.robot.theta == pytest.approx(truth.robot.theta)
        assert got.command == truth.command and got.collisions == truth.collisions
        assert [p.name for p in got.people] == ["alice", "bob"]
        assert got.people[0].y == pytest.approx(truth.people[0].y)
        assert got.people[0].is_target and not got.people[1].is_target
    for (_, got_pose), (obs, _) in zip(ep.poses, ticks, strict=True):
        assert (got_pose.x, got_pose.theta) == pytest.approx((obs.pose.x, obs.pose.theta))
    assert ep.odometry[3][1].x == pytest.approx(0.3) and ep.odometry[3][1].theta == 0.05
    scan = ep.scans[1]
    assert np.isinf(scan.ranges[1]) and scan.ranges[2] == pytest.approx(4.5)
    assert scan.pose.x == pytest.approx(ticks[2][0].scan.pose.x)
    assert ep.robot_path().shape == (6, 2) and ep.people_paths()["alice"].shape == (6, 2)


def test_error_leaves_nothing(tmp_path: Path) -> None:
    out = tmp_path / "ep"
    with pytest.raises(RuntimeError), EpisodeRecorder(out, "house") as rec:
        rec.add(*_tick(0))
        raise RuntimeError("boom")
    assert list(tmp_path.iterdir()) == []


def test_missing_bag_is_an_error(tmp_path: Path) -> None:
    with pytest.raises(RecordingError, match=BAG_NAME):
        read_episode(tmp_path)


def test_episode_png(tmp_path: Path) -> None:
    from pfctl.core.mapping.walls import rasterize_house
    from pfctl.mission import load_mission
    from pfctl.plots.sim_run import plot_paths

    mission = load_mission(Path(__file__).resolve().parents[2] / "missions" / "house.yaml")
    grid = rasterize_house(mission.layout(), 0.05, wall_thickness=mission.map.wall_thickness)
    with EpisodeRecorder(tmp_path / "ep", "house") as rec:
        for i in range(6):
            rec.add(*_tick(i))
    episode = read_episode(tmp_path / "ep")
    out = plot_paths(
        grid,
        mission.layout(),
        episode.robot_path(),
        episode.people_paths(),
        episode.target,
        tmp_path / "e.png",
        title=episode.mission_name,
    )
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
