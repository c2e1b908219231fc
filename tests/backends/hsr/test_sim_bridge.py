"""``pfctl sim serve-hsr``: the simulated house as an HSR on a real ROS 1 master.

The bridge runs as the venv's ``pfctl`` in a subprocess on the test's private master; probes are
node subprocesses (one ``init_node`` per process) that print one JSON line of what they saw. The
message builders are also checked in pytest's own process, which never starts a node.
"""

from __future__ import annotations

import json
import math
import os
import re
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from pfctl.app.hsr import hsr_config
from pfctl.app.sim import sim_config
from pfctl.backends.hsr import convert
from pfctl.backends.hsr.sim_bridge import CLOCK_OFFSET, HsrMessages, ros_time
from pfctl.backends.pybullet.camera import camera_pose, intrinsics
from pfctl.bags.recording import person_from_marker
from pfctl.core.robot import (
    GroundTruth,
    HeadState,
    Observation,
    PersonTruth,
    Pose2D,
    RgbdFrame,
)
from pfctl.mission import load_mission
from tests.backends.hsr.conftest import RosMaster, stop_node
from tests.backends.hsr.test_master import read_line
from tests.conftest import run_cli

pytestmark = [pytest.mark.ros, pytest.mark.sim]

ROOT = Path(__file__).resolve().parents[3]
HOUSE = ROOT / "missions" / "house.yaml"
PFCTL = str(Path(sys.executable).parent / "pfctl")
TIMEOUT = 90.0
"""Wall seconds a bridge or probe may take before the test counts it as hung."""


# ------------------------------------------------------------------------ processes and probes


def start_bridge(master: RosMaster, tmp: Path, *args: str) -> subprocess.Popen[bytes]:
    """``pfctl sim serve-hsr missions/house.yaml ARGS`` on the test's master; its stdout and
    stderr go to ``tmp/bridge.out`` and ``tmp/bridge.err``."""
    with (tmp / "bridge.out").open("wb") as out, (tmp / "bridge.err").open("wb") as err:
        return subprocess.Popen(
            [PFCTL, "sim", "serve-hsr", str(HOUSE), *args],
            env=master.env,
            stdin=subprocess.DEVNULL,
            stdout=out,
            stderr=err,
            start_new_session=True,
        )


def wait_serving(bridge: subprocess.Popen[bytes], tmp: Path) -> str:
    """The bridge's "serving ..." line (it prints it once the first messages are out)."""
    deadline = time.monotonic() + TIMEOUT
    while time.monotonic() < deadline:
        err = (tmp / "bridge.err").read_text(errors="replace")
        for line in err.splitlines():
            if line.startswith("serving "):
                return line
        assert bridge.poll() is None, f"the bridge exited with {bridge.returncode}: {err}"
        time.sleep(0.1)
    raise AssertionError("the bridge did not say it was serving")


def finish_bridge(bridge: subprocess.Popen[bytes], tmp: Path) -> tuple[int, str, str]:
    """Wait for the bridge to end; (status, stdout, stderr)."""
    try:
        code = bridge.wait(timeout=TIMEOUT)
    finally:
        stop_node(bridge)  # type: ignore[arg-type]
    return (
        code,
        (tmp / "bridge.out").read_text(errors="replace"),
        (tmp / "bridge.err").read_text(errors="replace"),
    )


def probe_result(process: subprocess.Popen[str]) -> dict:
    out, _ = process.communicate(timeout=TIMEOUT)
    assert process.returncode == 0, out
    return json.loads(out.strip().splitlines()[-1])


PRELUDE = """
import json, math, sys, threading, time
import numpy as np
from pfctl.backends.hsr import convert
from pfctl.backends.hsr.ros_import import import_ros_module, import_rospy
from pfctl.mission import load_mission
rospy = import_rospy()
m = {n: import_ros_module(n) for n in (
    "sensor_msgs.msg", "geometry_msgs.msg", "nav_msgs.msg", "rosgraph_msgs.msg", "tf2_msgs.msg",
    "visualization_msgs.msg", "std_msgs.msg", "trajectory_msgs.msg", "move_base_msgs.msg",
    "actionlib_msgs.msg", "std_srvs.srv")}
mission = load_mission(sys.argv[1])
cfg = mission.backend.hsr
T = lambda stamp: stamp.secs + stamp.nsecs * 1e-9
def pose2d(p):
    return convert.pose2d_from_pose(p)
"""

LISTENER = (
    PRELUDE
    + """
from pfctl.backends.hsr.person_labels import label_detector
from pfctl.core.robot import RgbdFrame
tf2_ros = import_ros_module("tf2_ros")
rospy.init_node("pfctl_test_listener", argv=[sys.argv[0]], disable_signals=True)
end = float(sys.argv[2])
buf = tf2_ros.Buffer(cache_time=rospy.Duration(60.0))
tf_listener = tf2_ros.TransformListener(buf)
sensor, geometry = m["sensor_msgs.msg"], m["geometry_msgs.msg"]
topics = {
    "clock": ("/clock", m["rosgraph_msgs.msg"].Clock),
    "tf": ("/tf", m["tf2_msgs.msg"].TFMessage),
    "tf_static": ("/tf_static", m["tf2_msgs.msg"].TFMessage),
    "laser": (cfg.laser, sensor.LaserScan),
    "odom": (cfg.odom, m["nav_msgs.msg"].Odometry),
    "joints": (cfg.joint_states, sensor.JointState),
    "rgb": (cfg.rgb, sensor.Image),
    "depth": (cfg.depth, sensor.Image),
    "info": (cfg.camera_info, sensor.CameraInfo),
    "labels": (cfg.person_labels, sensor.Image),
    "robot": (cfg.ground_truth + "/robot", geometry.PoseStamped),
    "people": (cfg.ground_truth + "/people", m["visualization_msgs.msg"].MarkerArray),
    "collisions": (cfg.ground_truth + "/collisions", m["std_msgs.msg"].UInt32),
}
got = {k: [] for k in topics}
subs = [rospy.Subscriber(t, c, got[k].append, queue_size=1000, buff_size=1 << 26)
        for k, (t, c) in topics.items()]
print("READY", flush=True)
deadline = time.monotonic() + 60.0
while not got["clock"] and time.monotonic() < deadline:
    time.sleep(0.01)
master = rospy.get_master()  # while the bridge serves
types = dict(master.getTopicTypes()[2])
service = master.lookupService(cfg.viewpoint_stop)[0] == 1
ready = rospy.get_param("/pfctl/sim/ready", None)
while time.monotonic() < deadline:
    if got["clock"] and T(got["clock"][-1].clock) >= end - 1e-6:
        break
    time.sleep(0.05)
time.sleep(1.0)  # the last messages of the other topics
clock = [T(c.clock) for c in got["clock"]]
stamps = lambda k: [T(x.header.stamp) for x in got[k]]
frames = lambda k: sorted({x.header.frame_id for x in got[k]})
out = {
    "use_sim_time": rospy.get_param("/use_sim_time"),
    "offset": rospy.get_param("/pfctl/sim/clock_offset"),
    "ready": ready,
    "types": {k: types.get(t) for k, (t, _) in topics.items()},
    "action_types": {n: types.get(cfg.move_base + "/" + n) for n in ("goal", "cancel", "status",
                                                                       "result", "feedback")},
    "service": service,
    "counts": {k: len(v) for k, v in got.items()},
    "clock": clock,
    "frames": {k: frames(k) for k in ("laser", "rgb", "depth", "info", "labels", "robot")},
    "odom_frames": sorted({(o.header.frame_id, o.child_frame_id) for o in got["odom"]}),
    "encodings": {k: sorted({x.encoding for x in got[k]}) for k in ("rgb", "depth", "labels")},
    "joint_names": sorted({tuple(j.name) for j in got["joints"]}),
    "laser_stamps": stamps("laser"),
    "odom_stamps": stamps("odom"),
    "camera_stamps": {k: stamps(k) for k in ("rgb", "depth", "info", "labels")},
    "truth_stamps": stamps("robot"),
}
tf_pairs = sorted({(t.header.frame_id, t.child_frame_id) for msg in got["tf"]
                   for t in msg.transforms})
out["tf_pairs"] = tf_pairs
out["tf_static"] = [
    (t.header.frame_id, t.child_frame_id, t.transform.translation.x, t.transform.translation.z)
    for msg in got["tf_static"] for t in msg.transforms]
# tf map -> base_footprint at each truth stamp, against the true pose
errors = []
for msg in got["robot"]:
    tf = buf.lookup_transform(cfg.map_frame, cfg.base_frame, msg.header.stamp)
    believed = convert.pose2d_from_transform(tf.transform)
    true = pose2d(msg.pose)
    errors.append((believed.distance_to(true), abs(believed.theta - true.theta)))
out["tf_errors"] = errors
# every scan can be posed at its own stamp
posed = 0
for scan in got["laser"]:
    buf.lookup_transform(cfg.map_frame, scan.header.frame_id, scan.header.stamp)
    posed += 1
out["scans_posed"] = posed
# the person labels, decoded as HsrRobot decodes them, against the truth at the frame's stamp
people = {round(T(msg.markers[0].header.stamp), 6): msg for msg in got["people"] if msg.markers}
out["markers"] = [(mk.ns, mk.type, mk.text, (mk.color.r, mk.color.g, mk.color.b))
                  for mk in got["people"][0].markers]
detector = label_detector(mission.perception.vision.min_pixels)
seen = []
for rgb, depth, info, labels in zip(got["rgb"], got["depth"], got["info"], got["labels"]):
    stamp = T(rgb.header.stamp)
    tf = buf.lookup_transform(cfg.map_frame, rgb.header.frame_id, rgb.header.stamp)
    t, q = tf.transform.translation, tf.transform.rotation
    from scipy.spatial.transform import Rotation
    mask = np.frombuffer(bytes(labels.data), dtype="<u2").reshape(labels.height, labels.width)
    frame = RgbdFrame(
        stamp=stamp, rgb=convert.rgb_from_image(rgb), depth=convert.depth_from_image(depth),
        info=convert.camera_info_from_msg(info), camera_position=(t.x, t.y, t.z),
        camera_rotation=Rotation.from_quat([q.x, q.y, q.z, q.w]).as_matrix(),
        mask=mask.astype(np.int32))
    truth = people.get(round(stamp, 6))
    for det in detector.detect(frame):
        near = min(((math.hypot(det.position[0] - mk.pose.position.x,
                                det.position[1] - mk.pose.position.y), mk.ns)
                    for mk in truth.markers), default=(math.inf, None))
        seen.append((stamp, near[1], near[0], t.z))
out["seen"] = seen
print(json.dumps(out), flush=True)
rospy.signal_shutdown("done")
"""
)


COMMANDER = (
    PRELUDE
    + """
actionlib = import_ros_module("actionlib")
rospy.init_node("pfctl_test_commander", argv=[sys.argv[0]], disable_signals=True)
geometry, mb = m["geometry_msgs.msg"], m["move_base_msgs.msg"]
GoalStatus = m["actionlib_msgs.msg"].GoalStatus
truth = {}
def on_robot(msg): truth["robot"] = msg
def on_people(msg): truth["people"] = msg
def on_joints(msg): truth["head"] = convert.head_state_from_joint_state(msg)
subs = [rospy.Subscriber(cfg.ground_truth + "/robot", geometry.PoseStamped, on_robot),
        rospy.Subscriber(cfg.ground_truth + "/people", m["visualization_msgs.msg"].MarkerArray,
                         on_people),
        rospy.Subscriber(cfg.joint_states, m["sensor_msgs.msg"].JointState, on_joints)]
cmd = rospy.Publisher(cfg.command_velocity, geometry.Twist, queue_size=10)
head = rospy.Publisher(cfg.head_command, m["trajectory_msgs.msg"].JointTrajectory, queue_size=1)
nav = actionlib.SimpleActionClient(cfg.move_base, mb.MoveBaseAction)
other = actionlib.SimpleActionClient(cfg.move_base, mb.MoveBaseAction)
out = {"use_sim_time": rospy.get_param("/use_sim_time")}
deadline = time.monotonic() + 30
while ("robot" not in truth or "head" not in truth or cmd.get_num_connections() == 0
       or head.get_num_connections() == 0) and time.monotonic() < deadline:
    time.sleep(0.05)
out["servers"] = [c.wait_for_server(rospy.Duration(10)) for c in (nav, other)]
robot = lambda: pose2d(truth["robot"].pose)
def target(x, y, theta=0.0, frame="map"):
    goal = mb.MoveBaseGoal()
    goal.target_pose.header.frame_id = frame
    goal.target_pose.header.stamp = rospy.get_rostime()
    goal.target_pose.pose = convert.pose2d_to_pose(convert.Pose2D(x, y, theta))
    return goal
def twist(vx, vy=0.0, wz=0.0):
    return convert.twist_to_msg(convert.Twist2D(vx, vy, wz))

# the viewpoint controller's stop service answers
rospy.wait_for_service(cfg.viewpoint_stop, 10)
rospy.ServiceProxy(cfg.viewpoint_stop, m["std_srvs.srv"].Empty)()

# a Twist drives the base (forward = +x at the start, theta 0)
start = robot()
t_end = rospy.get_rostime().to_sec() + 1.0
while rospy.get_rostime().to_sec() < t_end:
    cmd.publish(twist(0.2))
    rospy.sleep(0.1)
cmd.publish(twist(0.0))
rospy.sleep(0.3)
moved = robot()
out["twist"] = [moved.x - start.x, moved.y - start.y]
rospy.sleep(0.3)
out["stopped"] = robot().distance_to(moved)

# the head follows a trajectory
traj = convert.head_target_to_trajectory(convert.HeadTarget(0.5, -0.2), 0.5)
head.publish(traj)
rospy.sleep(1.5)
out["head"] = [truth["head"].pan, truth["head"].tilt]

# a short goal succeeds
here = robot()
nav.send_goal(target(here.x + 0.5, here.y, 0.0))
out["short_goal_done"] = nav.wait_for_result(rospy.Duration(20))
out["short_goal"] = [nav.get_state(), robot().x - here.x, robot().y - here.y]

# a goal in the base frame (0.3 m to the left) succeeds too
here = robot()
nav.send_goal(target(0.0, 0.3, 0.0, frame=cfg.base_frame))
nav.wait_for_result(rospy.Duration(20))
out["base_goal"] = [nav.get_state(), robot().x - here.x, robot().y - here.y]

# cancel -> PREEMPTED, and the base stops
nav.send_goal(target(4.3, 3.3))
rospy.sleep(0.8)
out["far_state"] = nav.get_state()
nav.cancel_goal()
nav.wait_for_result(rospy.Duration(5))
rospy.sleep(0.3)
p = robot()
rospy.sleep(0.5)
out["cancel"] = [nav.get_state(), robot().distance_to(p)]

# a Twist preempts a goal
nav.send_goal(target(4.3, 3.3))
rospy.sleep(0.5)
cmd.publish(twist(0.0))
nav.wait_for_result(rospy.Duration(5))
out["twist_preempts"] = nav.get_state()

# a new goal (another client) preempts the running one
nav.send_goal(target(4.3, 3.3))
rospy.sleep(0.5)
other.send_goal(target(1.5, 3.3))
nav.wait_for_result(rospy.Duration(5))
out["new_goal_preempts"] = nav.get_state()
other.cancel_goal()
other.wait_for_result(rospy.Duration(5))

# a goal inside the dining table aborts; a goal in an unknown frame is rejected
nav.send_goal(target(1.8, 2.4))
nav.wait_for_result(rospy.Duration(5))
out["blocked_goal"] = [nav.get_state(), nav.get_goal_status_text()]
nav.send_goal(target(1.0, 1.0, frame="elsewhere"))
nav.wait_for_result(rospy.Duration(5))
out["bad_frame"] = [nav.get_state(), nav.get_goal_status_text()]

out["people"] = {mk.ns: [mk.pose.position.x, mk.pose.position.y, mk.text]
                 for mk in truth["people"].markers}
print(json.dumps(out), flush=True)
rospy.signal_shutdown("done")
"""
)


HOLDER = (
    PRELUDE
    + """
rospy.init_node("pfctl_test_holder", argv=[sys.argv[0]], disable_signals=True)
geometry = m["geometry_msgs.msg"]
seen = []
def on_people(msg):
    seen.append((T(msg.markers[0].header.stamp),
                 {mk.ns: (mk.pose.position.x, mk.pose.position.y) for mk in msg.markers}))
robot = []
subs = [rospy.Subscriber(cfg.ground_truth + "/people", m["visualization_msgs.msg"].MarkerArray,
                         on_people),
        rospy.Subscriber(cfg.ground_truth + "/robot", geometry.PoseStamped, robot.append)]
head = rospy.Publisher(cfg.head_command, m["trajectory_msgs.msg"].JointTrajectory, queue_size=1)
while (len(seen) < 2 or head.get_num_connections() == 0):
    time.sleep(0.05)
rospy.sleep(1.0)  # ROS time runs while the episode is held
held = list(seen)
head.publish(convert.head_target_to_trajectory(convert.HeadTarget(0.0, -0.1), 0.5))
rospy.sleep(1.5)
after = [s for s in seen if s[0] > held[-1][0]]
out = {
    "held": [held[0], held[-1]],
    "after": [after[0], after[-1]],
    "offset": rospy.get_param("/pfctl/sim/clock_offset"),
    "robot": [pose2d(robot[-1].pose).x, pose2d(robot[-1].pose).y, pose2d(robot[-1].pose).theta],
}
print(json.dumps(out), flush=True)
rospy.signal_shutdown("done")
"""
)


# ----------------------------------------------------------------------------------------- tests


def test_serves_the_hsr_interfaces(ros_master, ros_nodes, tmp_path):
    """Topics, types, frames and stamps; tf against the truth; the labels decode to the people
    in view; the bridge ends at --duration with exit 0."""
    duration = 2.0
    listener = ros_nodes(LISTENER, str(HOUSE), str(CLOCK_OFFSET + duration))
    assert read_line(listener) == "READY"
    bridge = start_bridge(ros_master, tmp_path, "--duration", str(duration), "--rate", "0")
    got = probe_result(listener)
    code, out, err = finish_bridge(bridge, tmp_path)
    assert code == 0, err
    assert "Traceback" not in err
    assert err.splitlines()[0].startswith("serving ")
    assert "served 2.0 s simulated" in out

    cfg = load_mission(HOUSE).backend.hsr
    assert got["use_sim_time"] is True
    assert got["offset"] == CLOCK_OFFSET
    assert got["ready"] is True
    assert got["types"] == {
        "clock": "rosgraph_msgs/Clock",
        "tf": "tf2_msgs/TFMessage",
        "tf_static": "tf2_msgs/TFMessage",
        "laser": "sensor_msgs/LaserScan",
        "odom": "nav_msgs/Odometry",
        "joints": "sensor_msgs/JointState",
        "rgb": "sensor_msgs/Image",
        "depth": "sensor_msgs/Image",
        "info": "sensor_msgs/CameraInfo",
        "labels": "sensor_msgs/Image",
        "robot": "geometry_msgs/PoseStamped",
        "people": "visualization_msgs/MarkerArray",
        "collisions": "std_msgs/UInt32",
    }
    assert got["action_types"] == {
        "goal": "move_base_msgs/MoveBaseActionGoal",
        "cancel": "actionlib_msgs/GoalID",
        "status": "actionlib_msgs/GoalStatusArray",
        "result": "move_base_msgs/MoveBaseActionResult",
        "feedback": "move_base_msgs/MoveBaseActionFeedback",
    }
    assert got["service"]

    # the clock: from the offset, one tick per 25 ms sub-step, every one received
    clock = np.array(got["clock"])
    assert clock[0] == pytest.approx(CLOCK_OFFSET)
    assert clock[-1] == pytest.approx(CLOCK_OFFSET + duration)
    np.testing.assert_allclose(np.diff(clock), 0.025, atol=1e-8)
    counts = got["counts"]
    assert counts["clock"] == counts["laser"] == counts["odom"] == counts["joints"] == 81
    assert counts["rgb"] == counts["depth"] == counts["info"] == counts["labels"] == 21
    assert counts["robot"] == counts["people"] == counts["collisions"] == 21

    # frames
    assert got["frames"] == {
        "laser": ["base_range_sensor_link"],
        "rgb": ["head_rgbd_sensor_rgb_frame"],
        "depth": ["head_rgbd_sensor_rgb_frame"],
        "info": ["head_rgbd_sensor_rgb_frame"],
        "labels": ["head_rgbd_sensor_rgb_frame"],
        "robot": ["map"],
    }
    assert got["odom_frames"] == [["odom", "base_footprint"]]
    assert got["encodings"] == {"rgb": ["rgb8"], "depth": ["16UC1"], "labels": ["16UC1"]}
    assert got["joint_names"] == [["head_pan_joint", "head_tilt_joint"]]
    assert got["tf_pairs"] == [
        ["base_footprint", "head_rgbd_sensor_rgb_frame"],
        ["map", "odom"],
        ["odom", "base_footprint"],
    ]
    laser = load_mission(HOUSE).sensors.laser
    assert got["tf_static"] == [
        ["base_footprint", "base_range_sensor_link", laser.mount_x, laser.mount_height]
    ]

    # stamps: the sensors on the clock's ticks; the four camera topics share each stamp
    assert got["laser_stamps"] == got["odom_stamps"] == got["clock"]
    cams = got["camera_stamps"]
    assert cams["rgb"] == cams["depth"] == cams["info"] == cams["labels"]
    assert cams["rgb"] == got["truth_stamps"]
    np.testing.assert_allclose(cams["rgb"], CLOCK_OFFSET + 0.1 * np.arange(21), atol=1e-9)
    assert got["scans_posed"] == 81

    # tf map -> base is the localised pose: near the truth (localisation std 0.02 m, 0.01 rad)
    errors = np.array(got["tf_errors"])
    assert len(errors) == 21
    assert errors[:, 0].max() < 0.1 and errors[:, 1].max() < 0.05

    # the truth's people, encoded as a recorded episode encodes them
    markers = {ns: (kind, text, color) for ns, kind, text, color in got["markers"]}
    assert set(markers) == {"alice", "bob", "carol"}
    assert markers["alice"][0] == 3  # CYLINDER
    assert re.fullmatch(r"target speed=\d\.\d{3}", markers["alice"][1])
    assert re.fullmatch(r"distractor speed=\d\.\d{3}", markers["bob"][1])
    assert markers["alice"][2][0] > 0.5 > markers["bob"][2][0]

    # the person labels: alice (ahead of the robot at the start) in every frame, placed where
    # the truth has her; the camera at its mount height
    seen = got["seen"]
    assert {stamp for stamp, _, _, _ in seen} == set(cams["rgb"])
    assert all(name == "alice" and distance < 0.4 for _, name, distance, _ in seen), seen
    mount = load_mission(HOUSE).sensors.camera.mount_height
    assert all(abs(z - mount) < 0.11 for _, _, _, z in seen)
    assert cfg.person_labels == "/pfctl/person_labels"


def test_commands_drive_the_served_robot(ros_master, ros_nodes, tmp_path):
    """Twist, head trajectory, move_base (succeeded, cancelled, preempted by a Twist and by a
    new goal, aborted, rejected) and the viewpoint stop service; --hide puts the target in the
    bedroom; Ctrl-C ends the bridge with exit 130 and one line."""
    bridge = start_bridge(ros_master, tmp_path, "--rate", "2", "--hide", "bedroom")
    wait_serving(bridge, tmp_path)
    got = probe_result(ros_nodes(COMMANDER, str(HOUSE)))
    os.killpg(bridge.pid, signal.SIGINT)
    code, out, err = finish_bridge(bridge, tmp_path)
    assert code == 130, err
    assert "Traceback" not in err
    assert [line for line in err.splitlines() if line.startswith("pfctl:")] == [
        f"pfctl: interrupted (SIGINT) after serving {out.split()[2]} s simulated"
    ]
    assert out.startswith("interrupted after")
    assert "1 viewpoint stops, 0 sentences to say" in out and "0 collisions" in out

    assert got["use_sim_time"] is True
    assert got["servers"] == [True, True]
    dx, dy = got["twist"]
    assert 0.12 < dx < 0.3 and abs(dy) < 0.02  # 0.2 m/s for 1 s of ROS time, +x
    assert got["stopped"] < 0.01
    assert got["head"] == pytest.approx([0.5, -0.2], abs=0.02)
    succeeded, preempted, aborted, rejected, active = 3, 2, 4, 5, 1
    done, (state, dx, dy) = got["short_goal_done"], got["short_goal"]
    assert done and state == succeeded
    assert 0.5 - 0.2 < dx < 0.5 + 0.15 and abs(dy) < 0.15  # within the goal tolerance, 0.15 m
    state, dx, dy = got["base_goal"]  # 0.3 m to the robot's left; it faces about +x
    assert state == succeeded and 0.3 - 0.2 < dy < 0.3 + 0.15 and abs(dx) < 0.15
    assert got["far_state"] == active
    assert got["cancel"][0] == preempted and got["cancel"][1] < 0.01
    assert got["twist_preempts"] == preempted
    assert got["new_goal_preempts"] == preempted
    assert got["blocked_goal"][0] == aborted and "obstacle" in got["blocked_goal"][1]
    assert got["bad_frame"][0] == rejected and "elsewhere" in got["bad_frame"][1]
    x, y, text = got["people"]["alice"]
    assert 6 <= x <= 12 and 6 <= y <= 9 and text.startswith("target")  # hidden in the bedroom


def test_what_the_robot_says_reaches_the_simulated_house(ros_master, ros_nodes, tmp_path):
    """``HsrRobot`` speaks once a node listens to ``backend.hsr.speech`` (the bridge, standing
    in for a text-to-speech node); what it says goes to the simulator (``SimRobot.say``)."""
    bridge = start_bridge(ros_master, tmp_path, "--rate", "2")
    wait_serving(bridge, tmp_path)
    driver = (Path(__file__).parent / "nodes" / "hsr_driver.py").read_text()
    got = probe_result(ros_nodes(driver, "speak"))
    os.killpg(bridge.pid, signal.SIGINT)
    code, out, err = finish_bridge(bridge, tmp_path)
    assert code == 130, err
    assert got["speaks"] is True
    assert "1 viewpoint stops, 1 sentences to say" in out


def test_wait_for_command_holds_the_episode(ros_master, ros_nodes, tmp_path):
    """--wait-for-command: the clock runs and the truth is published again with new stamps
    while nobody moves; the first (head) command starts the episode; SIGTERM ends the bridge
    with exit 143 and one line. --pose-target: the target stands 1.4 m in front of the robot."""
    bridge = start_bridge(
        ros_master, tmp_path, "--rate", "2", "--wait-for-command", "--pose-target"
    )
    serving = wait_serving(bridge, tmp_path)
    assert "held until the first command" in serving
    got = probe_result(ros_nodes(HOLDER, str(HOUSE)))
    os.killpg(bridge.pid, signal.SIGTERM)
    code, out, err = finish_bridge(bridge, tmp_path)
    assert code == 143, err
    assert "Traceback" not in err
    assert sum(line.startswith("pfctl: interrupted (SIGTERM)") for line in err.splitlines()) == 1
    assert "the first command came after" in err
    assert out.startswith("interrupted after") and "simulated (after holding for" in out

    (t0, held0), (t1, held1) = got["held"]
    assert t1 - t0 >= 0.9  # ROS time ran ...
    assert held0 == held1  # ... and nobody moved
    (t2, after0), (t3, after1) = got["after"]
    assert t1 < t2 < t3
    assert after0["bob"] != after1["bob"]  # the episode runs
    assert got["offset"] > CLOCK_OFFSET + 0.9
    x, y, theta = got["robot"]
    ax, ay = held0["alice"]
    assert math.hypot(ax - x, ay - y) == pytest.approx(1.4, abs=0.05)
    assert abs(math.atan2(ay - y, ax - x) - theta) < 0.3  # straight ahead


def test_a_missing_master_is_one_line(ros, capsys, monkeypatch):
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]  # closed again: nobody listens there
    monkeypatch.setenv("ROS_MASTER_URI", f"http://127.0.0.1:{port}/")
    code, out, err = run_cli(["sim", "serve-hsr", str(HOUSE)], capsys, monkeypatch)
    assert code == 2
    assert out == ""
    assert err.count("\n") == 1
    assert err.startswith(f"pfctl: error: no ROS master at http://127.0.0.1:{port}/")
    monkeypatch.delenv("ROS_MASTER_URI")
    code, _, err = run_cli(["sim", "serve-hsr", str(HOUSE)], capsys, monkeypatch)
    assert code == 2 and err == (
        "pfctl: error: ROS_MASTER_URI is not set: start a ROS master (roscore) and point "
        "ROS_MASTER_URI at it\n"
    )


def test_bad_options_are_one_line(capsys, monkeypatch):
    for args, message in (
        (["--rate", "-1"], "--rate: expected a number >= 0"),
        (["--duration", "0"], "--duration: expected a positive number"),
        (["--depth-encoding", "8UC1"], "--depth-encoding 8UC1: expected one of 16UC1, 32FC1"),
        (["--hide", "attic"], "--hide attic: unknown region (regions: kitchen, living_room"),
        (["--hide", "office", "--pose-target"], "--hide and --pose-target"),
    ):
        code, _, err = run_cli(["sim", "serve-hsr", str(HOUSE), *args], capsys, monkeypatch)
        assert code == 2 and err.startswith(f"pfctl: error: {message}"), err
        assert err.count("\n") == 1


# ------------------------------------------------------------------ the messages, without a node


def test_stamps_are_whole_nanoseconds_of_sim_time_plus_the_offset(ros):
    t = ros_time(0.025)
    assert (t.secs, t.nsecs) == (100, 25_000_000)  # Time.from_sec(100.025) gives 24999999
    assert ros_time(3 * 0.1).nsecs == 300_000_000
    assert ros_time(0.0, offset=100.5).to_nsec() == 100_500_000_000


def _messages(mission, depth_encoding: str = "16UC1") -> HsrMessages:
    return HsrMessages(hsr_config(mission), sim_config(mission).laser, depth_encoding)


def _observation(mission, pose: Pose2D, odometry: Pose2D, head: HeadState) -> Observation:
    cam = mission.sensors.camera
    position, rotation = camera_pose(pose, head, cam.mount_height, cam.forward_offset)
    info = intrinsics(sim_config(mission).camera)
    depth = np.full((info.height, info.width), 2.5, dtype=np.float32)
    depth[0, 0] = np.inf
    frame = RgbdFrame(
        stamp=1.5,
        rgb=np.zeros((info.height, info.width, 3), np.uint8),
        depth=depth,
        info=info,
        camera_position=tuple(float(v) for v in position),
        camera_rotation=rotation,
        mask=np.full((info.height, info.width), -1, np.int32),
    )
    return Observation(stamp=1.5, pose=pose, head=head, rgbd=frame, odometry=odometry)


def _matrix(transform) -> np.ndarray:
    from scipy.spatial.transform import Rotation

    q, t = transform.rotation, transform.translation
    out = np.eye(4)
    out[:3, :3] = Rotation.from_quat([q.x, q.y, q.z, q.w]).as_matrix()
    out[:3, 3] = (t.x, t.y, t.z)
    return out


def test_tf_chain_puts_the_camera_where_the_frame_says(ros):
    """map → odom → base_footprint → optical frame = the frame's camera pose (map frame)."""
    mission = load_mission(HOUSE)
    msgs = _messages(mission)
    pose, odometry = Pose2D(3.0, 2.0, 0.7), Pose2D(0.4, -0.2, 0.3)
    obs = _observation(mission, pose, odometry, HeadState(0.4, -0.3))
    tf = msgs.tf(obs)
    assert [(t.header.frame_id, t.child_frame_id) for t in tf.transforms] == [
        ("map", "odom"),
        ("odom", "base_footprint"),
        ("base_footprint", "head_rgbd_sensor_rgb_frame"),
    ]
    assert {t.header.stamp.to_nsec() for t in tf.transforms} == {101_500_000_000}
    chain = np.linalg.multi_dot([_matrix(t.transform) for t in tf.transforms])
    np.testing.assert_allclose(chain[:3, 3], obs.rgbd.camera_position, atol=1e-9)
    np.testing.assert_allclose(chain[:3, :3], obs.rgbd.camera_rotation, atol=1e-9)
    base = convert.pose2d_from_transform(tf.transforms[0].transform).compose(
        convert.pose2d_from_transform(tf.transforms[1].transform)
    )
    assert base.distance_to(pose) < 1e-9


def test_camera_messages_share_stamp_and_frame_in_either_depth_encoding(ros):
    mission = load_mission(HOUSE)
    obs = _observation(mission, Pose2D(1.0, 1.0), Pose2D(0.0, 0.0), HeadState())
    labels = np.zeros(obs.rgbd.depth.shape, np.uint16)
    labels[10, 20] = 7
    for encoding, none in (("16UC1", 0), ("32FC1", None)):
        rgb, depth, info, lab = _messages(mission, encoding).camera(obs.rgbd, labels)
        assert {m.header.frame_id for m in (rgb, depth, info, lab)} == {
            "head_rgbd_sensor_rgb_frame"
        }
        assert {m.header.stamp.to_nsec() for m in (rgb, depth, info, lab)} == {101_500_000_000}
        assert depth.encoding == encoding
        back = convert.depth_from_image(depth)
        assert back[5, 5] == pytest.approx(2.5) and math.isinf(back[0, 0])
        raw = np.frombuffer(bytes(depth.data), "<u2" if encoding == "16UC1" else "<f4")
        assert raw[0] == none if none is not None else math.isnan(raw[0])
        assert lab.encoding == "16UC1"
        assert np.frombuffer(bytes(lab.data), "<u2").reshape(labels.shape)[10, 20] == 7
    with pytest.raises(ValueError, match="8UC1"):
        _messages(mission, "8UC1")


def test_truth_markers_read_back_as_the_people(ros):
    mission = load_mission(HOUSE)
    people = (
        PersonTruth("alice", 3.0, 2.0, 0.5, 0.9, is_target=True),
        PersonTruth("bob", 7.0, 1.0, -2.0, 0.7),
    )
    truth = GroundTruth(stamp=0.3, robot=Pose2D(1.0, 3.3, 0.1), people=people, collisions=2)
    robot, markers, collisions = _messages(mission).truth(truth)
    assert robot.header.frame_id == "map" and robot.header.stamp.to_nsec() == 100_300_000_000
    assert convert.pose2d_from_pose(robot.pose).distance_to(truth.robot) < 1e-12
    assert collisions.data == 2
    back = [
        person_from_marker(mk.ns, convert.pose2d_from_pose(mk.pose), mk.text)
        for mk in markers.markers
    ]
    for got, want in zip(back, people, strict=True):
        assert (got.name, got.is_target, got.speed) == (want.name, want.is_target, want.speed)
        assert (got.x, got.y, got.theta) == pytest.approx((want.x, want.y, want.theta))
    assert [mk.lifetime.to_nsec() for mk in markers.markers] == [200_000_000] * 2


def test_goals_in_odom_and_base_frames_are_taken_to_the_map(ros):
    msgs = _messages(load_mission(HOUSE))
    pose, odometry = Pose2D(2.0, 3.0, math.pi / 2), Pose2D(0.5, 0.0, 0.2)
    goal = Pose2D(1.0, 0.0, 0.0)

    def stamped(frame: str):
        msg = ros["geometry_msgs.msg"].PoseStamped()
        msg.header.frame_id = frame
        msg.pose = convert.pose2d_to_pose(goal)
        return msg

    assert msgs.goal_in_map(stamped("map"), pose, odometry) == goal
    assert msgs.goal_in_map(stamped(""), pose, odometry) == goal
    in_base = msgs.goal_in_map(stamped("base_footprint"), pose, odometry)
    assert (in_base.x, in_base.y) == pytest.approx((2.0, 4.0))
    in_odom = msgs.goal_in_map(stamped("/odom"), pose, odometry)
    expected = pose.compose(odometry.inverse()).compose(goal)
    assert in_odom.distance_to(expected) < 1e-12
    with pytest.raises(ValueError, match="frame 'camera'"):
        msgs.goal_in_map(stamped("camera"), pose, odometry)
