"""SimRobot behind the Robot port: sensors, occlusion, limits, collisions, MOVE_BASE, seeds."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from pfctl.app.sim import sim_config
from pfctl.backends.pybullet.simulation import SimOptions, SimRobot
from pfctl.backends.pybullet.walkers import LEG_RADIUS
from pfctl.core.robot import HeadTarget, NavStatus, Pose2D, Robot, Twist2D
from pfctl.mission import Mission, load_mission, loads_mission

pytestmark = pytest.mark.sim

HOUSE = Path(__file__).resolve().parents[3] / "missions" / "house.yaml"

# Two rooms side by side; the wall between them at x = 6 has its door at y = 3.0..3.9.
# Dan stands 2 m ahead of the robot; Eve stands in the other room, behind the wall.
TWO_ROOMS = """
name: two-rooms
map:
  regions:
    - {name: west, polygon: [[0, 0], [6, 0], [6, 4], [0, 4]]}
    - {name: east, polygon: [[6, 0], [10, 0], [10, 4], [6, 4]]}
  doors:
    - {between: [west, east], segment: [[6, 3.0], [6, 3.9]]}
robot: {start: {x: 1.5, y: 1.5, theta: 0.0}}
sensors:
  laser: {noise_std: 0.01}
  camera: {depth_noise: 0.0}
scenario:
  seed: 1
  people:
    - {name: dan, clothes: {upper: [20, 160, 40], lower: [30, 30, 30]}, route: [[3.5, 1.5]]}
    - {name: eve, clothes: {upper: [200, 30, 40], lower: [40, 40, 120]}, route: [[8.0, 2.6]]}
"""


@pytest.fixture(scope="module")
def two_rooms() -> Mission:
    return loads_mission(TWO_ROOMS, source="two_rooms.yaml")


@pytest.fixture(scope="module")
def house() -> Mission:
    return load_mission(HOUSE)


def _empty(mission: Mission) -> Mission:
    return mission.model_copy(
        update={"scenario": mission.scenario.model_copy(update={"people": ()})}
    )


@pytest.mark.parametrize("model", ["fast", "bullet"])
def test_scan_of_an_empty_room_matches_its_walls_within_noise(
    two_rooms: Mission, model: str
) -> None:
    with SimRobot(
        sim_config(_empty(two_rooms)), SimOptions(camera=False, laser_model=model)
    ) as robot:
        robot.step()
        scan = robot.observe().scan
    assert scan is not None and len(scan.ranges) == 1081
    pts = scan.points()
    inner = 0.05  # walls are 0.1 m thick, centred on the region boundary
    room = pts[pts[:, 0] < 6.0]  # the beams through the door end in the east room
    # distance from each return to the nearest inner wall face of the west room
    faces = np.column_stack(
        (room[:, 0] - inner, 6.0 - inner - room[:, 0], room[:, 1] - inner, 4.0 - inner - room[:, 1])
    )
    err = np.min(np.abs(faces), axis=1)
    assert len(room) > 900  # only the beams through the door leave the room
    assert np.percentile(err, 99) < 4 * 0.01 and np.max(err) < 0.06


@pytest.mark.parametrize("model", ["fast", "bullet"])
def test_legs_two_metres_ahead_are_two_short_arcs_where_they_stand(
    two_rooms: Mission, model: str
) -> None:
    with SimRobot(sim_config(two_rooms), SimOptions(camera=False, laser_model=model)) as robot:
        robot.step()
        scan = robot.observe().scan
        legs = robot.people[0].legs()  # dan's two legs (truth)
    assert scan is not None
    pts = scan.points()
    assert np.allclose(legs[:, 0], 3.5) and abs(legs[0, 1] - legs[1, 1]) == pytest.approx(0.2)
    near = np.linalg.norm(pts - [3.5, 1.5], axis=1) < 0.4
    arcs = np.flatnonzero(np.diff(np.r_[0, near.astype(int), 0]) == 1)
    assert len(arcs) == 2  # two separate runs of beams
    for leg in legs:
        mine = pts[np.linalg.norm(pts - leg[:2], axis=1) < 0.1]
        assert len(mine) >= 5  # 0.12 m of leg at 2 m is ~3.4 deg, 13 beams at 0.25 deg
        d = np.linalg.norm(mine - leg[:2], axis=1)
        assert np.all(np.abs(d - LEG_RADIUS) < 0.04)
        assert np.all(mine[:, 0] < leg[0] + 0.03)  # only the side facing the robot is seen


def _person_in_view(robot: SimRobot, name: str) -> tuple[int, int]:
    """(pixels of the person in the camera mask, laser returns on their legs)."""
    robot.step()
    obs = robot.observe()
    assert obs.rgbd is not None and obs.scan is not None and obs.rgbd.mask is not None
    ids = robot.people_bodies.body_ids[name]
    pixels = int(np.isin(obs.rgbd.mask, ids).sum())
    walker = next(w for w in robot.people if w.name == name)
    legs = walker.legs()
    pts = obs.scan.points()
    hits = int(sum((np.linalg.norm(pts - leg[:2], axis=1) < 0.1).sum() for leg in legs))
    return pixels, hits


def test_a_person_behind_a_wall_is_absent_from_scan_and_camera(two_rooms: Mission) -> None:
    with SimRobot(sim_config(two_rooms)) as robot:
        # eve at (8, 2.6) is 9.6 deg left of the view axis, inside the 58 deg camera and the
        # laser's field of view, but behind the wall at x = 6
        assert _person_in_view(robot, "eve") == (0, 0)
        assert min(_person_in_view(robot, "dan")) > 0  # dan, in the same room, is seen
        # the same eve is seen once the robot stands in her room
        robot.pose = Pose2D(6.8, 2.0, 0.4)
        pixels, hits = _person_in_view(robot, "eve")
        assert pixels > 500 and hits > 5


def test_camera_intrinsics_and_depth_agree_with_the_scene(two_rooms: Mission) -> None:
    with SimRobot(sim_config(two_rooms)) as robot:
        robot.step()
        frame = robot.observe().rgbd
    assert frame is not None and frame.mask is not None
    info = frame.info
    assert (info.width, info.height) == (320, 240)
    assert math.degrees(info.horizontal_fov) == pytest.approx(58.0)
    assert frame.rgb.shape == (240, 320, 3) and frame.depth.dtype == np.float32
    # the centre of dan's torso front face, projected with K through the camera's pose
    cam = np.array(frame.camera_position)
    torso = robot.people_bodies.body_ids["dan"][2]
    point = np.array([3.5 - 0.11, 1.5, 1.1])
    local = frame.camera_rotation.T @ (point - cam)  # x right, y down, z forward
    u = info.fx * local[0] / local[2] + info.cx
    v = info.fy * local[1] / local[2] + info.cy
    assert frame.mask[round(v), round(u)] == torso
    assert frame.depth[round(v), round(u)] == pytest.approx(local[2], abs=0.02)
    # nothing is seen closer than the torso along the view axis, and the floor has depth
    assert np.isfinite(frame.depth[-1]).all()


def test_commands_are_clamped_to_the_limits(house: Mission) -> None:
    limits = house.robot
    with SimRobot(sim_config(_empty(house)), SimOptions(camera=False)) as robot:
        assert isinstance(robot, Robot)
        start = robot.pose
        robot.command(Twist2D(2.0, 2.0, 5.0))
        assert math.hypot(robot.commanded.vx, robot.commanded.vy) == pytest.approx(
            limits.max_linear_speed
        )
        assert robot.commanded.wz == pytest.approx(limits.max_angular_speed)
        robot.command(Twist2D(-3.0, 0.0, -9.0))
        robot.step()
        moved = robot.pose.distance_to(start)
        # 0.1 s at the speed limit; the base turns meanwhile, so its four sub-steps make an arc
        assert moved == pytest.approx(limits.max_linear_speed * 0.1, rel=1e-3)
        assert robot.pose.theta == pytest.approx(start.theta - limits.max_angular_speed * 0.1)


def test_the_base_stops_at_a_wall_and_counts_one_collision(two_rooms: Mission) -> None:
    with SimRobot(sim_config(_empty(two_rooms)), SimOptions(camera=False)) as robot:
        robot.command(Twist2D(0.0, -0.22, 0.0))  # sideways toward the south wall at y = 0
        for _ in range(100):  # 10 s: 2.2 m of commands for 1.5 m of room
            robot.step()
        assert robot.pose.y > two_rooms.robot.radius + 0.05 - 1e-9
        assert robot.pose.y < two_rooms.robot.radius + 0.05 + 0.22 * 0.025 + 1e-9
        assert robot.collisions == 1 and robot.observe().collisions == 1
        robot.command(Twist2D(0.0, 0.22, 0.0))  # away from it and back again: a second one
        for _ in range(5):
            robot.step()
        robot.command(Twist2D(0.0, -0.22, 0.0))
        for _ in range(20):
            robot.step()
        assert robot.collisions == 2


def test_head_follows_its_pd_controller_within_limits(two_rooms: Mission) -> None:
    with SimRobot(sim_config(_empty(two_rooms)), SimOptions(camera=False)) as robot:
        robot.command(Twist2D(), HeadTarget(pan=1.0, tilt=-3.0))  # tilt beyond its limit
        pans = []
        for _ in range(30):
            robot.step()
            pans.append(robot.observe().head.pan)
        assert pans[-1] == pytest.approx(1.0, abs=1e-3)
        assert robot.head.state.tilt == pytest.approx(two_rooms.robot.head_tilt_limits[0], abs=1e-3)
        assert robot.head.state.tilt >= two_rooms.robot.head_tilt_limits[0]
        assert np.max(np.diff(pans)) <= two_rooms.robot.head_max_speed * 0.1 + 1e-9
        assert pans[3] < 0.5  # it accelerates: a PD loop, not a jump


def test_navigate_through_doors_succeeds_and_a_goal_in_a_wall_aborts(house: Mission) -> None:
    # without people: they may stand in a door and send the robot the long way round
    with SimRobot(sim_config(_empty(house)), SimOptions(camera=False)) as robot:
        robot.navigate(Pose2D(1.5, 7.5, 1.57))  # kitchen -> hall -> office, round the shelf
        path, speeds = [], []
        while robot.nav_status() is NavStatus.ACTIVE and robot.time < 120:
            before = robot.pose
            robot.step()
            path.append((robot.pose.x, robot.pose.y))
            speeds.append(robot.pose.distance_to(before) / 0.1)
        assert robot.nav_status() is NavStatus.SUCCEEDED
        assert robot.pose.distance_to(Pose2D(1.5, 7.5)) < 0.2
        assert max(speeds) <= house.robot.max_linear_speed + 1e-9
        xy = np.array(path)
        for y_wall, (x0, x1) in ((4.0, (2.0, 2.9)), (6.0, (3.5, 4.4))):
            k = int(np.argmax(xy[:, 1] > y_wall))  # first position past the wall
            assert x0 < xy[k, 0] < x1  # it went through the door
        robot.navigate(Pose2D(5.0, 0.5))  # inside the kitchen/living-room wall
        assert robot.nav_status() is NavStatus.ABORTED
        robot.step()
        assert robot.commanded == Twist2D()


def test_pose_noise_and_odometry_drift(two_rooms: Mission) -> None:
    noisy = two_rooms.model_copy(
        update={
            "sensors": two_rooms.sensors.model_copy(
                update={
                    "pose": two_rooms.sensors.pose.model_copy(
                        update={"localization_xy": 0.05, "odometry_linear": 0.05}
                    )
                }
            )
        }
    )
    for mission, exact in ((_empty(two_rooms), True), (_empty(noisy), False)):
        with SimRobot(sim_config(mission), SimOptions(camera=False)) as robot:
            robot.command(Twist2D(0.04, 0.0, 0.0))
            errors = []
            for _ in range(100):
                robot.step()
                obs = robot.observe()
                errors.append(obs.pose.distance_to(robot.pose))
                assert obs.scan is not None
                # the scan sits where the robot believes its laser is
                believed = robot.laser_spec.laser_pose(obs.pose)
                assert obs.scan.pose == believed
            odom = obs.odometry
            assert odom is not None
            truth = robot.pose.x - two_rooms.robot.start.x  # type: ignore[union-attr]
            if exact:
                assert max(errors) == 0 and odom.x == pytest.approx(truth)
            else:
                rms = math.sqrt(np.mean(np.square(errors[20:])))  # sigma * sqrt(2) = 0.07
                assert 0.02 < rms < 0.15
                assert odom.x != pytest.approx(truth, abs=1e-4)  # odometry drifted
                assert abs(odom.x - truth) < 0.2


@pytest.mark.slow
def test_same_seed_same_episode_other_seed_differs(house: Mission) -> None:
    def episode(seed: int) -> tuple:
        with SimRobot(sim_config(house, seed)) as robot:
            robot.navigate(Pose2D(9.0, 2.0))
            out = []
            for _ in range(40):
                robot.step()
                obs = robot.observe()
                out.append(
                    (
                        robot.pose,
                        obs.pose,
                        tuple(w.truth() for w in robot.people),
                        None if obs.scan is None else obs.scan.ranges.tobytes(),
                        None if obs.rgbd is None else obs.rgbd.rgb.tobytes(),
                    )
                )
            return tuple(out)

    a = episode(3)
    assert a == episode(3)
    assert a != episode(4)


def test_close_stops_the_base_and_is_idempotent(house: Mission) -> None:
    robot = SimRobot(sim_config(_empty(house)), SimOptions(camera=False))
    robot.command(Twist2D(0.2, 0.0, 0.0))
    robot.close()
    assert robot.commanded == Twist2D()
    robot.close()
    with pytest.raises(RuntimeError):
        robot.step()


def test_every_scan_of_a_tick_is_observed_in_order_at_its_own_pose(two_rooms: Mission) -> None:
    config = sim_config(_empty(two_rooms))
    assert (config.laser.rate_hz, 1.0 / config.tick_period) == (40.0, 10.0)
    with SimRobot(config, SimOptions(camera=False)) as robot:
        robot.observe()  # the scan taken at start
        robot.command(Twist2D(0.2, 0.0, 0.0))
        stamps: list[float] = []
        for _ in range(5):
            robot.step()
            obs = robot.observe()
            assert len(obs.scans) == 4 and obs.scan is obs.scans[-1]
            assert obs.scans[-1].stamp == pytest.approx(obs.stamp)
            xs = [scan.pose.x for scan in obs.scans]
            assert np.all(np.diff(xs) > 0)  # each at its own pose
            stamps += [scan.stamp for scan in obs.scans]
        assert np.allclose(np.diff(stamps), 0.025)  # increasing, none repeated nor skipped
        assert robot.dropped_scans == 0
        assert robot.observe().scans == ()  # each scan is handed out once


def test_unobserved_scans_are_kept_for_a_second_and_the_rest_counted(two_rooms: Mission) -> None:
    with SimRobot(sim_config(_empty(two_rooms)), SimOptions(camera=False)) as robot:
        for _ in range(15):  # 1.5 s: 60 scans after the one taken at start
            robot.step()
        scans = robot.observe().scans
        assert len(scans) == 40 and robot.dropped_scans == 21
        assert scans[0].stamp == pytest.approx(0.525) and scans[-1].stamp == pytest.approx(1.5)
