"""ROS 1 message ⇄ Robot-port conversions (pfctl.backends.hsr.convert), without a master."""

from __future__ import annotations

import io
import math

import numpy as np
import pytest

from pfctl.backends.hsr import convert
from pfctl.core.perception.vision import pixels_to_map
from pfctl.core.robot import (
    CameraInfo,
    HeadTarget,
    LaserScan,
    NavStatus,
    Pose2D,
    RgbdFrame,
    Twist2D,
)

pytestmark = [pytest.mark.ros, pytest.mark.usefixtures("ros")]


def wire(msg):
    """``msg`` serialised and read back, as a subscriber receives it (bytes, tuples)."""
    buf = io.BytesIO()
    msg.serialize(buf)
    out = type(msg)()
    out.deserialize(buf.getvalue())
    return out


def scan_msg(ros, ranges, range_min=0.1, range_max=10.0):
    msg = ros["sensor_msgs.msg"].LaserScan()
    msg.header.stamp = convert.sec_to_time(12.25)
    msg.angle_min, msg.angle_increment = -0.5, 0.25
    msg.angle_max = 123.0  # inconsistent on purpose: the beam count comes from len(ranges)
    msg.range_min, msg.range_max = range_min, range_max
    msg.ranges = ranges
    return wire(msg)


def test_laser_scan_invalid_ranges_become_inf(ros):
    raw = [1.0, float("nan"), float("inf"), -float("inf"), 0.05, 10.5, 10.0, 0.1, 0.0]
    scan = convert.laser_scan_from_msg(scan_msg(ros, raw), pose=Pose2D(1.0, 2.0, math.pi / 2))
    assert scan.stamp == pytest.approx(12.25)
    assert (scan.angle_min, scan.angle_increment) == (-0.5, 0.25)
    np.testing.assert_allclose(scan.angles, -0.5 + 0.25 * np.arange(9))
    expected = [1.0, np.inf, np.inf, np.inf, np.inf, np.inf, 10.0, 0.1, np.inf]
    np.testing.assert_allclose(scan.ranges, expected, rtol=1e-6)
    # core uses the finite returns only: 3 map points, the first 1 m along beam -0.5 rad
    pts = scan.points()
    assert pts.shape == (3, 2)
    a = math.pi / 2 - 0.5
    np.testing.assert_allclose(pts[0], [1.0 + math.cos(a), 2.0 + math.sin(a)], atol=1e-6)


def test_laser_scan_round_trip(ros):
    ranges = np.array([0.5, np.inf, 3.25, 7.0, np.inf])
    scan = LaserScan(4.5, -1.0, 0.5, 0.05, 20.0, ranges, Pose2D(0.0, 0.0, 0.0))
    msg = convert.laser_scan_to_msg(scan, frame_id="base_range_sensor_link")
    assert msg.header.frame_id == "base_range_sensor_link"
    assert msg.angle_max == pytest.approx(1.0)
    assert math.isinf(msg.ranges[1]) and msg.ranges[1] > 0  # REP-117 "no return"
    back = convert.laser_scan_from_msg(wire(msg))
    assert back.stamp == pytest.approx(4.5)
    np.testing.assert_allclose(back.ranges, ranges, rtol=1e-6)
    assert (back.range_min, back.range_max) == (pytest.approx(0.05), pytest.approx(20.0))


def scene_depth() -> np.ndarray:
    """A 6x8 depth image in whole millimetres (float32 metres), with holes (inf)."""
    mm = np.arange(48, dtype=np.int64).reshape(6, 8) * 37 + 400
    depth = (mm / 1000.0).astype(np.float32)
    depth[0, 0] = depth[3, 5] = np.inf
    return depth


def test_depth_16uc1_and_32fc1_of_one_scene_agree(ros):
    depth = scene_depth()
    as_mm = wire(convert.depth_to_image(depth, 1.0, "head_rgbd_sensor", encoding="16UC1"))
    as_m = wire(convert.depth_to_image(depth, 1.0, "head_rgbd_sensor", encoding="32FC1"))
    assert (as_mm.encoding, as_mm.step, as_m.encoding, as_m.step) == ("16UC1", 16, "32FC1", 32)
    # on the wire: no return is 0 mm / NaN m
    assert np.frombuffer(as_mm.data, "<u2")[0] == 0 and math.isnan(
        np.frombuffer(as_m.data, "<f4")[0]
    )
    from_mm, from_m = convert.depth_from_image(as_mm), convert.depth_from_image(as_m)
    for d in (from_mm, from_m):
        assert d.dtype == np.float32 and d.shape == (6, 8)
        assert np.isinf(d[0, 0]) and np.isinf(d[3, 5])
    np.testing.assert_allclose(from_mm, depth, atol=1e-6)
    np.testing.assert_allclose(from_m, from_mm, atol=1e-6)
    # and the same 3-D points through core's back-projection
    info = convert.camera_info_from_msg(
        wire(
            convert.camera_info_to_msg(
                CameraInfo(8, 6, (5.0, 0.0, 3.5, 0.0, 5.0, 2.5, 0.0, 0.0, 1.0))
            )
        )
    )
    rot = np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])  # optical axes in map
    vs, us = np.mgrid[0:6, 0:8]
    us, vs = us.ravel(), vs.ravel()
    pts = [
        pixels_to_map(
            RgbdFrame(1.0, np.zeros((6, 8, 3), np.uint8), d, info, (1.0, 2.0, 1.0), rot), us, vs
        )
        for d in (from_mm, from_m)
    ]
    assert pts[0].shape == (46, 3)
    np.testing.assert_allclose(pts[0], pts[1], atol=1e-5)


def test_depth_32fc1_no_return_values_and_16uc1_overflow(ros):
    raw = np.array([[np.nan, -1.0, 0.0, np.inf, 1.5]], np.float32)
    msg = ros["sensor_msgs.msg"].Image(
        height=1, width=5, encoding="32FC1", step=20, data=raw.tobytes()
    )
    np.testing.assert_array_equal(convert.depth_from_image(wire(msg)), [[np.inf] * 4 + [1.5]])
    far = convert.depth_to_image(np.array([[70.0, 65.0]], np.float32), encoding="16UC1")
    np.testing.assert_array_equal(np.frombuffer(far.data, "<u2"), [0, 65000])


def test_image_rows_with_padding_and_big_endian(ros):
    mm = np.array([[1000, 2000], [0, 1500]], dtype=">u2")
    padded = np.zeros((2, 3), dtype=">u2")  # step 6 bytes for 4 bytes of pixels
    padded[:, :2] = mm
    msg = ros["sensor_msgs.msg"].Image(
        height=2, width=2, encoding="16UC1", is_bigendian=1, step=6, data=padded.tobytes()
    )
    np.testing.assert_allclose(convert.depth_from_image(wire(msg)), [[1.0, 2.0], [np.inf, 1.5]])


@pytest.mark.parametrize("encoding", ["rgb8", "bgr8"])
def test_colour_round_trip(ros, encoding):
    rgb = np.random.default_rng(3).integers(0, 256, (4, 5, 3), dtype=np.uint8)
    msg = wire(convert.rgb_to_image(rgb, 2.0, "head_rgbd_sensor", encoding=encoding))
    assert (msg.encoding, msg.step, msg.header.frame_id) == (encoding, 15, "head_rgbd_sensor")
    first = tuple(msg.data[:3])
    assert first == (tuple(rgb[0, 0]) if encoding == "rgb8" else tuple(rgb[0, 0, ::-1]))
    back = convert.rgb_from_image(msg)
    assert back.dtype == np.uint8 and back.shape == (4, 5, 3)
    np.testing.assert_array_equal(back, rgb)


def test_unsupported_encoding_is_a_clear_error(ros):
    msg = ros["sensor_msgs.msg"].Image(height=1, width=1, encoding="yuv422", step=2, data=b"\0\0")
    with pytest.raises(ValueError, match="yuv422"):
        convert.rgb_from_image(msg)
    with pytest.raises(ValueError, match="yuv422"):
        convert.depth_from_image(msg)


def test_camera_info_round_trip(ros):
    info = CameraInfo(640, 480, (554.0, 0.0, 320.5, 0.0, 555.0, 240.5, 0.0, 0.0, 1.0), "cam")
    msg = wire(convert.camera_info_to_msg(info, stamp=3.0))
    assert list(msg.P) == [554.0, 0.0, 320.5, 0.0, 0.0, 555.0, 240.5, 0.0, 0.0, 0.0, 1.0, 0.0]
    back = convert.camera_info_from_msg(msg)
    assert back == info
    assert back.horizontal_fov == pytest.approx(2 * math.atan2(320, 554))


def test_head_joints_by_name_among_others_in_any_order(ros):
    msg = convert.joint_state_msg(
        {
            "arm_lift_joint": 0.2,
            "head_tilt_joint": -0.4,
            "wrist_roll_joint": 1.0,
            "head_pan_joint": 0.7,
        }
    )
    head = convert.head_state_from_joint_state(wire(msg))
    assert (head.pan, head.tilt) == (pytest.approx(0.7), pytest.approx(-0.4))
    partial = convert.joint_state_msg({"arm_lift_joint": 0.2, "head_pan_joint": 0.7})
    assert convert.head_state_from_joint_state(wire(partial)) is None


def test_head_target_trajectory(ros):
    traj = wire(convert.head_target_to_trajectory(HeadTarget(0.5, -0.3), duration=0.75))
    assert list(traj.joint_names) == ["head_pan_joint", "head_tilt_joint"]
    assert list(traj.points[0].positions) == [0.5, -0.3]
    assert convert.time_to_sec(traj.points[0].time_from_start) == pytest.approx(0.75)
    assert convert.head_target_from_trajectory(traj) == HeadTarget(0.5, -0.3)
    swapped = ros["trajectory_msgs.msg"].JointTrajectory(
        joint_names=["head_tilt_joint", "head_pan_joint"],
        points=[ros["trajectory_msgs.msg"].JointTrajectoryPoint(positions=[-0.1, 0.2])],
    )
    assert convert.head_target_from_trajectory(wire(swapped)) == HeadTarget(0.2, -0.1)


@pytest.mark.parametrize("yaw", [0.0, 0.3, -1.2, math.pi / 2, 3.1, -3.1, math.pi])
def test_quaternion_yaw(ros, yaw):
    q = convert.quaternion_from_yaw(yaw)
    assert q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w == pytest.approx(1.0)
    got = convert.yaw_from_quaternion(q)
    assert math.cos(got - yaw) == pytest.approx(1.0)  # equal modulo 2 pi
    # a non-unit quaternion of the same rotation gives the same yaw
    q2 = ros["geometry_msgs.msg"].Quaternion(x=0.0, y=0.0, z=3 * q.z, w=3 * q.w)
    assert convert.yaw_from_quaternion(q2) == pytest.approx(got)


def test_yaw_of_a_tilted_quaternion():
    # roll 0.2 then yaw 1.0 (ZYX): yaw still 1.0
    cr, sr, cy, sy = math.cos(0.1), math.sin(0.1), math.cos(0.5), math.sin(0.5)

    class Q:
        x, y, z, w = cy * sr, sy * sr, sy * cr, cy * cr

    assert convert.yaw_from_quaternion(Q) == pytest.approx(1.0)


def test_poses_transforms_and_odometry(ros):
    def as_tuple(p: Pose2D) -> tuple[float, float, float]:
        return (p.x, p.y, p.theta)

    pose = Pose2D(1.5, -2.0, 2.5)
    msg = convert.pose2d_to_pose(pose)
    assert msg.position.z == 0.0
    assert as_tuple(convert.pose2d_from_pose(wire(msg))) == pytest.approx(as_tuple(pose))
    tf = convert.pose2d_to_transform(pose, z=0.3)
    assert tf.translation.z == 0.3
    assert as_tuple(convert.pose2d_from_transform(tf)) == pytest.approx(as_tuple(pose))
    odom = ros["nav_msgs.msg"].Odometry()
    odom.header.frame_id, odom.child_frame_id = "odom", "base_footprint"
    odom.pose.pose = convert.pose2d_to_pose(Pose2D(0.4, 0.1, -0.2))
    assert as_tuple(convert.pose2d_from_odometry(wire(odom))) == pytest.approx((0.4, 0.1, -0.2))


def test_twist_round_trip(ros):
    msg = wire(convert.twist_to_msg(Twist2D(0.3, -0.1, 0.8)))
    assert (msg.linear.z, msg.angular.x, msg.angular.y) == (0.0, 0.0, 0.0)
    assert convert.twist_from_msg(msg) == Twist2D(0.3, -0.1, 0.8)


def test_goal_status(ros):
    gs = ros["actionlib_msgs.msg"].GoalStatus
    assert convert.nav_status_from_goal_status(None) is NavStatus.IDLE
    expected = {
        gs.PENDING: NavStatus.PENDING,
        gs.ACTIVE: NavStatus.ACTIVE,
        gs.PREEMPTED: NavStatus.PREEMPTED,
        gs.SUCCEEDED: NavStatus.SUCCEEDED,
        gs.ABORTED: NavStatus.ABORTED,
        gs.REJECTED: NavStatus.ABORTED,
        gs.PREEMPTING: NavStatus.PREEMPTED,
        gs.RECALLING: NavStatus.PREEMPTED,
        gs.RECALLED: NavStatus.PREEMPTED,
        gs.LOST: NavStatus.ABORTED,
    }
    for code, status in expected.items():
        assert convert.nav_status_from_goal_status(code) is status
    for status in NavStatus:
        code = convert.nav_status_to_goal_status(status)
        assert convert.nav_status_from_goal_status(code) is status
    with pytest.raises(ValueError, match="42"):
        convert.nav_status_from_goal_status(42)


def test_time_round_trip(ros):
    t = convert.sec_to_time(1234.000000123)
    assert (t.secs, t.nsecs) == (1234, 123)
    assert convert.time_to_sec(t) == pytest.approx(1234.000000123, abs=1e-9)
    assert convert.time_to_sec(convert.sec_to_duration(0.5)) == 0.5
