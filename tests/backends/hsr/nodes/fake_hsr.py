"""A stand-in Toyota HSR for the tests of ``pfctl.backends.hsr.robot`` (a ROS 1 node).

It publishes what the HSR backend reads, with the names of ``backend.hsr``'s defaults: ``/clock``
(``--sim-time``; the test sets ``/use_sim_time``), tf (``map → odom → base_footprint``, the
laser on ``/tf_static``, the camera's optical frame; ``--map-odom-every N``: ``map → odom`` in
every N-th message only, as a slow localisation), ``/global_pose``, a LaserScan at 20 Hz
whose ranges mix valid returns with NaN, ±inf and values outside ``[range_min, range_max]``,
joint states, odometry, and at 5 Hz one camera frame (RGB, depth in ``--depth`` 16UC1 or 32FC1,
camera info, person labels) showing one synthetic person: a rectangle of flat depth in the label
image. With ``--truth`` it publishes the simulator's ground truth, with ``--move-base`` it
serves ``/move_base/move``; ``--omit TOPIC`` leaves a topic out.

It logs what it receives on stdout, one line each, with ``time.monotonic()`` (one clock for all
processes on Linux): ``CMD t vx vy wz``, ``HEAD t pan tilt duration``, ``VIEWPOINT_STOP t``,
``GOAL t x y theta frame``, ``GOAL_END t succeeded|preempted``; ``READY`` once everything is out.

Run it with the venv's python (ROS found through ``pfctl.backends.hsr.ros_import``).
"""

from __future__ import annotations

import argparse
import math
import sys
import threading
import time

import numpy as np

from pfctl.backends.hsr import convert
from pfctl.backends.hsr.person_labels import label_value
from pfctl.backends.hsr.ros_import import import_ros_module, import_rospy
from pfctl.core.robot import CameraInfo, Pose2D

MAP_ODOM = Pose2D(1.0, 2.0, 0.0)
ODOM_BASE = Pose2D(0.5, 0.0, math.pi / 2)
LASER_X, LASER_Z = 0.167, 0.19
CAMERA_Z = 1.0
OPTICAL = (-0.5, 0.5, -0.5, 0.5)
"""The optical frame's quaternion (x, y, z, w) in base_footprint: z forward, x right, y down."""
N_BEAMS = 181
BAD_BEAMS = {10: math.nan, 20: math.inf, 30: -math.inf, 40: 0.01, 50: 25.0}
"""Beams that are no valid return (REP-117): NaN, +inf, -inf, below range_min, above range_max."""
LEG_BEAMS = (*range(84, 88), *range(93, 97))
"""Two leg-sized clusters at 1.5 m among walls at 3 m."""
WIDTH, HEIGHT = 160, 120
INFO = CameraInfo(
    WIDTH, HEIGHT, (100.0, 0.0, 80.0, 0.0, 100.0, 60.0, 0.0, 0.0, 1.0), "head_rgbd_sensor_rgb_frame"
)
PERSON_DEPTH = 2.537
PERSON_COLUMNS = slice(70, 91)
HEAD_ROWS, BODY_ROWS = slice(20, 36), slice(36, 110)
HEAD = {"head_pan_joint": 0.3, "head_tilt_joint": -0.2}


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--depth", default="16UC1", choices=("16UC1", "32FC1"))
    parser.add_argument("--rgb", default="rgb8", choices=("rgb8", "bgr8"))
    parser.add_argument("--sim-time", action="store_true")
    parser.add_argument("--start", type=float, default=100.0, help="first sim time, s")
    parser.add_argument("--omit", action="append", default=[], help="a topic not to publish")
    parser.add_argument("--truth", action="store_true")
    parser.add_argument("--move-base", action="store_true")
    parser.add_argument("--goal-seconds", type=float, default=0.6)
    parser.add_argument(
        "--map-odom-every", type=int, default=1, help="map → odom in every n-th tf message"
    )
    args = parser.parse_args(sys.argv[1:])

    rospy = import_rospy()
    sensor = import_ros_module("sensor_msgs.msg")
    geometry = import_ros_module("geometry_msgs.msg")
    nav = import_ros_module("nav_msgs.msg")
    tf2_msgs = import_ros_module("tf2_msgs.msg")
    rosgraph_msgs = import_ros_module("rosgraph_msgs.msg")
    std_msgs = import_ros_module("std_msgs.msg")
    std_srvs = import_ros_module("std_srvs.srv")
    viz = import_ros_module("visualization_msgs.msg")
    trajectory = import_ros_module("trajectory_msgs.msg")

    log_lock = threading.Lock()  # callbacks come on several threads: whole lines only

    def log(*words: object) -> None:
        with log_lock:
            sys.stdout.write(" ".join(map(str, words)) + "\n")
            sys.stdout.flush()

    rospy.init_node("fake_hsr", argv=[sys.argv[0]], disable_signals=True)

    def pub(topic: str, cls: object, **kw: object) -> object | None:
        if topic in args.omit:
            return None
        return rospy.Publisher(topic, cls, queue_size=kw.pop("queue_size", 5), **kw)

    clock_pub = pub("/clock", rosgraph_msgs.Clock, queue_size=1) if args.sim_time else None
    tf_pub = pub("/tf", tf2_msgs.TFMessage, queue_size=20)
    static_pub = pub("/tf_static", tf2_msgs.TFMessage, queue_size=1, latch=True)
    scan_pub = pub("/hsrb/base_scan", sensor.LaserScan)
    joints_pub = pub("/hsrb/joint_states", sensor.JointState)
    odom_pub = pub("/hsrb/odom", nav.Odometry)
    pose_pub = pub("/global_pose", geometry.PoseStamped)
    rgb_pub = pub("/hsrb/head_rgbd_sensor/rgb/image_rect_color", sensor.Image, queue_size=2)
    depth_pub = pub(
        "/hsrb/head_rgbd_sensor/depth_registered/image_rect_raw", sensor.Image, queue_size=2
    )
    info_pub = pub("/hsrb/head_rgbd_sensor/rgb/camera_info", sensor.CameraInfo, queue_size=2)
    labels_pub = pub("/pfctl/person_labels", sensor.Image, queue_size=2)
    truth = {}
    if args.truth:
        truth = {
            "robot": pub("/ground_truth/robot", geometry.PoseStamped),
            "people": pub("/ground_truth/people", viz.MarkerArray),
            "collisions": pub("/ground_truth/collisions", std_msgs.UInt32),
        }

    rospy.Subscriber(
        "/hsrb/command_velocity",
        geometry.Twist,
        lambda m: log("CMD", time.monotonic(), m.linear.x, m.linear.y, m.angular.z),
    )

    def on_head(msg: object) -> None:
        target = convert.head_target_from_trajectory(msg)
        duration = convert.time_to_sec(msg.points[-1].time_from_start)
        log("HEAD", time.monotonic(), target.pan, target.tilt, duration)

    rospy.Subscriber(
        "/hsrb/head_trajectory_controller/command", trajectory.JointTrajectory, on_head
    )

    def on_viewpoint(_req: object) -> object:
        log("VIEWPOINT_STOP", time.monotonic())
        return std_srvs.EmptyResponse()

    rospy.Service("/viewpoint_controller/stop", std_srvs.Empty, on_viewpoint)

    if args.move_base:
        actionlib = import_ros_module("actionlib")
        mb = import_ros_module("move_base_msgs.msg")

        def execute(goal: object) -> None:
            p = convert.pose2d_from_pose(goal.target_pose.pose)
            log("GOAL", time.monotonic(), p.x, p.y, p.theta, goal.target_pose.header.frame_id)
            end = time.monotonic() + args.goal_seconds
            while time.monotonic() < end:
                if server.is_preempt_requested():
                    server.set_preempted()
                    log("GOAL_END", time.monotonic(), "preempted")
                    return
                time.sleep(0.01)
            server.set_succeeded(mb.MoveBaseResult())
            log("GOAL_END", time.monotonic(), "succeeded")

        server = actionlib.SimpleActionServer(
            "/move_base/move", mb.MoveBaseAction, execute_cb=execute, auto_start=False
        )
        server.start()

    def stamped(stamp: float, parent: str, child: str, transform: object) -> object:
        t = geometry.TransformStamped()
        t.header.stamp = convert.sec_to_time(stamp)
        t.header.frame_id, t.child_frame_id = parent, child
        t.transform = transform
        return t

    base = MAP_ODOM.compose(ODOM_BASE)
    if static_pub is not None:
        laser = convert.pose2d_to_transform(Pose2D(LASER_X, 0.0, 0.0), z=LASER_Z)
        static_pub.publish(
            tf2_msgs.TFMessage([stamped(0.0, "base_footprint", "base_range_sensor_link", laser)])
        )

    ranges = np.full(N_BEAMS, 3.0)
    ranges[list(LEG_BEAMS)] = 1.5
    for i, r in BAD_BEAMS.items():
        ranges[i] = r

    depth = np.full((HEIGHT, WIDTH), 4.0, dtype=np.float32)
    depth[:8, :] = np.inf  # no return
    labels = np.zeros((HEIGHT, WIDTH), dtype=np.uint16)
    labels[HEAD_ROWS, PERSON_COLUMNS] = label_value(0, "head")
    labels[BODY_ROWS, PERSON_COLUMNS] = label_value(0, "torso")
    depth[labels > 0] = PERSON_DEPTH
    rgb = np.full((HEIGHT, WIDTH, 3), 128, dtype=np.uint8)
    rgb[labels > 0] = (200, 30, 30)

    def publish_all(stamp: float, camera: bool, n: int) -> None:
        if tf_pub is not None:
            cam = geometry.Transform()
            cam.translation.z = CAMERA_Z
            cam.rotation.x, cam.rotation.y, cam.rotation.z, cam.rotation.w = OPTICAL
            transforms = [
                stamped(stamp, "odom", "base_footprint", convert.pose2d_to_transform(ODOM_BASE)),
                stamped(stamp, "base_footprint", INFO.frame_id, cam),
            ]
            if n % args.map_odom_every == 0:
                transforms.append(
                    stamped(stamp, "map", "odom", convert.pose2d_to_transform(MAP_ODOM))
                )
            tf_pub.publish(tf2_msgs.TFMessage(transforms))
        if scan_pub is not None:
            msg = sensor.LaserScan()
            msg.header.stamp = convert.sec_to_time(stamp)
            msg.header.frame_id = "base_range_sensor_link"
            msg.angle_min, msg.angle_increment = -math.pi / 2, math.pi / 180
            msg.angle_max = msg.angle_min + msg.angle_increment * (N_BEAMS - 1)
            msg.range_min, msg.range_max = 0.05, 20.0
            msg.ranges = [float(r) for r in ranges]
            scan_pub.publish(msg)
        if joints_pub is not None:
            joints_pub.publish(
                convert.joint_state_msg(
                    {"arm_lift_joint": 0.0, **HEAD, "wrist_roll_joint": 1.0}, stamp
                )
            )
        if odom_pub is not None:
            odom = nav.Odometry()
            odom.header.stamp = convert.sec_to_time(stamp)
            odom.header.frame_id, odom.child_frame_id = "odom", "base_footprint"
            odom.pose.pose = convert.pose2d_to_pose(ODOM_BASE)
            odom_pub.publish(odom)
        if pose_pub is not None:
            msg = geometry.PoseStamped()
            msg.header.stamp = convert.sec_to_time(stamp)
            msg.header.frame_id = "map"
            msg.pose = convert.pose2d_to_pose(base)
            pose_pub.publish(msg)
        if truth:
            robot = geometry.PoseStamped()
            robot.header.stamp = convert.sec_to_time(stamp)
            robot.header.frame_id = "map"
            robot.pose = convert.pose2d_to_pose(base)
            truth["robot"].publish(robot)
            markers = []
            for i, (name, role, x, y, theta, speed) in enumerate(
                (
                    ("alice", "target", 3.0, 4.0, 0.5, 0.8),
                    ("bob", "distractor", -1.0, 2.0, -1.0, 1.1),
                )
            ):
                m = viz.Marker()
                m.header = robot.header
                m.ns, m.id, m.type, m.action = name, i, 3, 0
                m.pose = convert.pose2d_to_pose(Pose2D(x, y, theta), z=0.85)
                m.text = f"{role} speed={speed:.3f}"
                markers.append(m)
            truth["people"].publish(viz.MarkerArray(markers))
            truth["collisions"].publish(std_msgs.UInt32(3))
        if camera:
            if rgb_pub is not None:
                rgb_pub.publish(convert.rgb_to_image(rgb, stamp, INFO.frame_id, args.rgb))
            if depth_pub is not None:
                depth_pub.publish(convert.depth_to_image(depth, stamp, INFO.frame_id, args.depth))
            if info_pub is not None:
                info_pub.publish(convert.camera_info_to_msg(INFO, stamp))
            if labels_pub is not None:
                img = sensor.Image()
                img.header.stamp = convert.sec_to_time(stamp)
                img.header.frame_id = INFO.frame_id
                img.height, img.width, img.encoding = HEIGHT, WIDTH, "16UC1"
                img.is_bigendian, img.step = 0, WIDTH * 2
                img.data = labels.astype("<u2").tobytes()
                labels_pub.publish(img)

    start = time.monotonic()
    tick = 0  # 10 ms of sim time each
    ready = False
    while not rospy.is_shutdown():
        stamp = args.start + tick * 0.01 if args.sim_time else rospy.get_time()
        if clock_pub is not None:
            clock_pub.publish(rosgraph_msgs.Clock(convert.sec_to_time(stamp)))
        if tick % 5 == 0:
            publish_all(stamp, camera=tick % 20 == 0, n=tick // 5)
            if not ready:
                ready = True
                log("READY")
        tick += 1
        time.sleep(max(0.0, start + tick * 0.01 - time.monotonic()))


if __name__ == "__main__":
    main()
