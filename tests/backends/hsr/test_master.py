"""A LaserScan made by pfctl.backends.hsr.convert goes through a real ROS 1 master; the master
check of pfctl.backends.hsr.master.

Two node processes (talker, listener) use the test's private ``rosmaster``; pytest's own process
never calls ``rospy.init_node`` (one node per process, see conftest).
"""

from __future__ import annotations

import json
import math
import selectors
import subprocess
import time

import numpy as np
import pytest

from pfctl.backends.hsr.master import MasterError, check_master
from tests.backends.hsr.conftest import _free_port

pytestmark = pytest.mark.ros

NODE_TIMEOUT = 60.0
"""Wall seconds a node may take."""

NODE_PRELUDE = """
import json, sys
from pfctl.backends.hsr import convert
from pfctl.backends.hsr.ros_import import import_ros_module, import_rospy
rospy = import_rospy()
LaserScanMsg = import_ros_module("sensor_msgs.msg").LaserScan
"""

TALKER = (
    NODE_PRELUDE
    + """
import numpy as np
from pfctl.core.robot import LaserScan, Pose2D
rospy.init_node("pfctl_test_talker", argv=[sys.argv[0]], disable_signals=True)
pub = rospy.Publisher("/hsrb/base_scan", LaserScanMsg, queue_size=1, latch=True)
ranges = np.array([0.5, np.inf, 2.25, 19.5])
scan = LaserScan(101.5, -0.75, 0.5, 0.05, 20.0, ranges, Pose2D(0.0, 0.0, 0.0))
pub.publish(convert.laser_scan_to_msg(scan, frame_id="base_range_sensor_link"))
print("PUBLISHED", flush=True)
sys.stdin.readline()  # latched: stay up until the test closes our stdin
rospy.signal_shutdown("test done")
"""
)

LISTENER = (
    NODE_PRELUDE
    + """
rospy.init_node("pfctl_test_listener", argv=[sys.argv[0]], disable_signals=True)
msg = rospy.wait_for_message("/hsrb/base_scan", LaserScanMsg, timeout=30.0)  # wall time
scan = convert.laser_scan_from_msg(msg)
print(json.dumps({
    "frame_id": msg.header.frame_id,
    "stamp": scan.stamp,
    "angle_min": scan.angle_min,
    "angle_increment": scan.angle_increment,
    "range_max": scan.range_max,
    "ranges": [float(r) for r in scan.ranges],
}), flush=True)
rospy.signal_shutdown("test done")
"""
)


def read_line(process: subprocess.Popen[str], timeout: float = NODE_TIMEOUT) -> str:
    """The process's next stdout line; fails if it exits or says nothing within ``timeout``."""
    assert process.stdout is not None
    with selectors.DefaultSelector() as sel:
        sel.register(process.stdout, selectors.EVENT_READ)
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if sel.select(timeout=0.5):
                line = process.stdout.readline()
                assert line, f"node exited with {process.wait()} before printing a line"
                return line.strip()
    raise AssertionError(f"no line from the node within {timeout} s")


def test_laser_scan_round_trip_through_a_master(ros_master, ros_nodes):
    talker = ros_nodes(TALKER, stdin=subprocess.PIPE)
    assert read_line(talker) == "PUBLISHED"
    code, _, (publishers, _, _) = ros_master.proxy().getSystemState("/pytest")
    assert code == 1
    assert ["/hsrb/base_scan", ["/pfctl_test_talker"]] in publishers

    listener = ros_nodes(LISTENER)
    out, _ = listener.communicate(timeout=NODE_TIMEOUT)
    assert listener.returncode == 0, out
    got = json.loads(out.strip().splitlines()[-1])
    assert got["frame_id"] == "base_range_sensor_link"
    assert got["stamp"] == 101.5
    assert (got["angle_min"], got["angle_increment"], got["range_max"]) == (-0.75, 0.5, 20.0)
    np.testing.assert_allclose(got["ranges"], [0.5, math.inf, 2.25, 19.5])

    assert talker.stdin is not None
    talker.stdin.close()
    assert talker.wait(timeout=NODE_TIMEOUT) == 0


def test_master_fixture_is_private(ros_master):
    """The fixture's master is the process it started, on loopback, with logs in the tmp dir."""
    proxy = ros_master.proxy()
    assert proxy.getPid("/pytest")[2] == ros_master.process.pid
    assert ros_master.uri == f"http://127.0.0.1:{ros_master.port}/"
    assert ros_master.env["ROS_HOSTNAME"] == "127.0.0.1"
    assert ros_master.env["ROS_LOG_DIR"].startswith(str(ros_master.log.parent))
    assert proxy.setParam("/pytest", "/use_sim_time", True)[0] == 1
    assert proxy.getParam("/pytest", "/use_sim_time")[2] is True


def test_check_master_passes_a_live_master_and_says_why_there_is_none(ros_master):
    check_master(ros_master.uri, "/pytest")
    uri = f"http://127.0.0.1:{_free_port()}/"
    with pytest.raises(MasterError) as info:
        check_master(uri, "/pytest", timeout=1.0)
    assert isinstance(info.value.error, OSError) and info.value.answer == ""
