"""HsrRobot (the Robot port over ROS 1) against a stand-in HSR on a real, private rosmaster.

Every ROS node runs in its own process (``tests/backends/hsr/nodes``): ``fake_hsr.py`` publishes
what an HSR (or ``pfctl sim serve-hsr``) publishes and logs what it receives, ``twist_listener.py``
records the base commands with their receive times, and ``hsr_driver.py`` runs ``HsrRobot``
through a scenario and prints JSON. pytest's own process never starts a node (conftest).
"""

from __future__ import annotations

import contextlib
import json
import math
import os
import signal
import subprocess
import threading
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

pytestmark = pytest.mark.ros

NODES = Path(__file__).parent / "nodes"
WAIT = 30.0
"""Wall seconds any one expected line may take."""
BAD_BEAMS = (10, 20, 30, 40, 50)  # fake_hsr.BAD_BEAMS: NaN, +inf, -inf, < range_min, > range_max
N_BEAMS = 181
BASE = (1.5, 2.0, math.pi / 2)  # fake_hsr: map→odom ⊕ odom→base_footprint
LASER = (1.5, 2.167, math.pi / 2)  # ⊕ the laser 0.167 m ahead of the base


class Output:
    """A node's stdout, read line by line in a thread; ``wait`` for a line by predicate."""

    def __init__(self, process: subprocess.Popen[str]) -> None:
        self.process = process
        self.lines: list[str] = []
        self._cond = threading.Condition()
        self._thread = threading.Thread(target=self._read, daemon=True)
        self._thread.start()

    def _read(self) -> None:
        assert self.process.stdout is not None
        for line in self.process.stdout:
            with self._cond:
                self.lines.append(line.rstrip("\n"))
                self._cond.notify_all()
        with self._cond:
            self._cond.notify_all()

    def wait(self, pred: Callable[[str], bool], timeout: float = WAIT) -> str:
        deadline = time.monotonic() + timeout
        with self._cond:
            while True:
                for line in self.lines:
                    if pred(line):
                        return line
                left = deadline - time.monotonic()
                if left <= 0 or (self.process.poll() is not None and not self._thread.is_alive()):
                    raise AssertionError(
                        f"no such line within {timeout} s (exit {self.process.poll()}); "
                        f"got: {self.lines[-20:]}"
                    )
                self._cond.wait(min(left, 0.2))

    def event(self, name: str, timeout: float = WAIT) -> dict:
        line = self.wait(lambda s: s.startswith("{") and json.loads(s)["event"] == name, timeout)
        return json.loads(line)

    def finish(self, timeout: float = WAIT) -> int:
        try:
            code = self.process.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            # a hung driver dumps its threads' stacks (faulthandler) into the test's output
            os.kill(self.process.pid, signal.SIGUSR1)
            with contextlib.suppress(subprocess.TimeoutExpired):
                self.process.wait(timeout=2)
            raise
        self._thread.join(timeout=5)
        return code

    def commands(self) -> list[tuple[float, float, float, float]]:
        """The ``CMD t vx vy wz`` lines as numbers."""
        with self._cond:
            return [tuple(map(float, s.split()[1:5])) for s in self.lines if s.startswith("CMD ")]


def _node(ros_nodes, name: str, *args: str) -> Output:
    return Output(ros_nodes((NODES / name).read_text(), *args))


def _sim_time(ros_master) -> None:
    assert ros_master.proxy().setParam("/pytest", "/use_sim_time", True)[0] == 1


def _fake(ros_nodes, *args: str) -> Output:
    fake = _node(ros_nodes, "fake_hsr.py", *args)
    fake.wait(lambda s: s == "READY")
    return fake


def _subscribed(ros_master, topic: str, node_prefix: str) -> None:
    """Wait until a node whose name starts with ``node_prefix`` subscribes to ``topic``."""
    deadline = time.monotonic() + WAIT
    while time.monotonic() < deadline:
        _, _, (_, subscribers, _) = ros_master.proxy().getSystemState("/pytest")
        nodes = dict((t, n) for t, n in subscribers).get(topic, [])
        if any(n.startswith(node_prefix) for n in nodes):
            return
        time.sleep(0.05)
    raise AssertionError(f"no {node_prefix}* subscribed to {topic} within {WAIT} s")


def _observe(
    ros_master, ros_nodes, *fake_args: str, driver_args: tuple[str, ...] = (), late: bool = False
) -> tuple[dict, Output, Output]:
    """The driver's ``observe`` scenario against a fake HSR; ``late``: the follower first, then
    the simulator sets ``/use_sim_time`` and starts (the follower switches to its clock)."""
    if late:
        driver = _node(ros_nodes, "hsr_driver.py", "observe", *driver_args)
        _subscribed(ros_master, "/hsrb/base_scan", "/pfctl_test")
        _sim_time(ros_master)
        fake = _fake(ros_nodes, *fake_args)
    else:
        fake = _fake(ros_nodes, *fake_args)
        driver = _node(ros_nodes, "hsr_driver.py", "observe", *driver_args)
    got = driver.event("observed")
    driver.event("closed")
    assert driver.finish() == 0, driver.lines[-10:]
    return got, fake, driver


def test_observe_over_ros(ros_master, ros_nodes):
    """Scan (REP-117 values), pose, head, odometry, truth, an RGB-D frame and its person, the
    step clock under sim time (set by a simulator started after the follower's node); limits:
    base and head commands clamped; close publishes zero."""
    got, fake, driver = _observe(
        ros_master, ros_nodes, "--sim-time", "--truth", driver_args=("--truth",), late=True
    )
    assert got["use_sim_time"] is True

    scan = got["scan"]
    assert scan["n"] == N_BEAMS
    bad = [i for i, r in enumerate(scan["ranges"]) if r is None]
    assert bad == list(BAD_BEAMS)  # NaN, ±inf and out-of-range: no return
    points = np.array(scan["points"])
    assert points.shape == (N_BEAMS - len(BAD_BEAMS), 2)
    assert np.isfinite(points).all()
    np.testing.assert_allclose(scan["pose"], LASER, atol=1e-6)
    ahead = points[90 - sum(i < 90 for i in BAD_BEAMS)]  # beam 90 points along the laser's x
    np.testing.assert_allclose(ahead, (LASER[0], LASER[1] + 3.0), atol=1e-5)
    assert scan["fov_ok"] and scan["legs"] >= 0  # the leg detector ran on it
    assert 0.0 <= scan["stamp"] <= scan["obs_stamp"] + 1e-9  # the episode clock

    np.testing.assert_allclose(got["pose"], BASE, atol=1e-6)
    np.testing.assert_allclose(got["head"], (0.3, -0.2))
    np.testing.assert_allclose(got["odometry"], (0.5, 0.0, math.pi / 2), atol=1e-6)
    assert got["collisions"] == 3

    truth = got["truth"]
    np.testing.assert_allclose(truth["robot"], BASE, atol=1e-6)
    assert truth["collisions"] == 3
    alice, bob = truth["people"]
    assert alice[0] == "alice" and alice[5] is True and alice[4] == pytest.approx(0.8)
    np.testing.assert_allclose(alice[1:4], (3.0, 4.0, 0.5), atol=1e-6)
    assert bob[0] == "bob" and bob[5] is False and bob[4] == pytest.approx(1.1)

    frame = got["frame"]
    assert frame["shape"] == [120, 160] and frame["mask_dtype"] == "int32"
    np.testing.assert_allclose(frame["position"], (1.5, 2.0, 1.0), atol=1e-6)
    # columns: the camera's x (right), y (down), z (forward) in the map; the base faces +y
    np.testing.assert_allclose(
        np.array(frame["rotation"]), [[1, 0, 0], [0, 0, 1], [0, -1, 0]], atol=1e-9
    )
    assert frame["rgb_at_person"] == [200, 30, 30]
    [(x, y, _)] = got["people"]
    assert x == pytest.approx(1.5, abs=0.02)
    assert 2.0 + 2.537 <= y <= 2.0 + 2.537 + 0.3  # the body's depth, pushed half a body back
    assert got["head_boxes"] == [[70, 20, 91, 36]]

    times = np.array(got["times"])  # robot.time after each step(): one period apart
    period = got["period"]
    steps = np.diff(times)
    assert np.all(steps > 0.5 * period) and np.all(steps < 2.5 * period), steps
    assert np.allclose(times[1:] / period, np.round(times[1:] / period), atol=0.15)

    assert driver.event("nav")["status"] == "idle"
    assert [json.loads(s)["status"] for s in driver.lines if '"nav"' in s] == ["idle", "aborted"]
    k = 0.22 / math.sqrt(2)
    np.testing.assert_allclose(driver.event("commanded")["twist"], (k, k, 0.8))

    fake.wait(lambda s: s.startswith("HEAD"))
    cmds = fake.commands()
    sent = [c for c in cmds if c[1:] != (0.0, 0.0, 0.0)]
    np.testing.assert_allclose([c[1:] for c in sent], [(k, k, 0.8)])
    assert cmds[-1][1:] == (0.0, 0.0, 0.0) and cmds[-1][0] > sent[-1][0]  # close() stopped it
    view = [s for s in fake.lines if s.startswith(("VIEWPOINT_STOP", "HEAD"))]
    assert view[0].startswith("VIEWPOINT_STOP") and len(view) == 2
    _, _, pan, tilt, duration = view[1].split()
    assert (float(pan), float(tilt)) == (1.75, -1.57)  # robot.head_pan/tilt_limits
    assert float(duration) == pytest.approx(max(abs(1.75 - 0.3), abs(-1.57 + 0.2)) / 1.0)


def test_every_queued_scan_is_observed_in_order_and_overflow_is_counted(ros_master, ros_nodes):
    """The fake laser runs at 20 Hz and the control period is 0.1 s: each observation hands out
    every scan since the previous one (about two), in order, none repeated or skipped; scans
    nobody observes queue up to ``SCAN_QUEUE``, the oldest dropped and counted."""
    _sim_time(ros_master)
    _fake(ros_nodes, "--sim-time")
    driver = _node(ros_nodes, "hsr_driver.py", "scans", "--periods", "10")
    got = driver.event("scans")
    assert driver.finish() == 0, driver.lines[-10:]
    observed = got["observed"]
    stamps = np.array([s for scans in observed[1:] for s in scans])  # from the second period
    assert sum(len(scans) >= 2 for scans in observed[1:]) >= 5  # more than one scan per tick
    np.testing.assert_allclose(np.diff(stamps), 0.05, atol=1e-6)  # in order, none lost
    late = np.array(got["late"])
    assert len(late) == got["queue"] == 40 and got["dropped"] >= 5
    np.testing.assert_allclose(np.diff(late), 0.05, atol=1e-6)  # the newest 40, in order
    assert late[0] > stamps[-1] + 0.05 * got["dropped"] - 1e-6  # the oldest were dropped


def test_depth_16uc1_and_32fc1_give_the_same_people(ros_master, ros_nodes):
    """The same person from millimetres (16UC1) and metres (32FC1, bgr8 colour), on a wall
    clock (a real robot: no /use_sim_time); the second with the pose from /global_pose and a
    localisation sending map → odom every 2 s (scans and frames posed with odom held fixed)."""
    mm, fake, _ = _observe(ros_master, ros_nodes, "--depth", "16UC1")
    stop_fake(fake)
    m, _, _ = _observe(
        ros_master,
        ros_nodes,
        "--depth",
        "32FC1",
        "--rgb",
        "bgr8",
        "--map-odom-every",
        "40",  # 2 s
        driver_args=("--pose", "/global_pose"),
    )
    assert mm["use_sim_time"] is False and mm["truth"] is None and mm["collisions"] == 0
    np.testing.assert_allclose(m["pose"], BASE, atol=1e-6)
    np.testing.assert_allclose(m["scan"]["pose"], LASER, atol=1e-6)
    np.testing.assert_allclose(m["frame"]["position"], mm["frame"]["position"], atol=1e-9)
    assert len(mm["people"]) == len(m["people"]) == 1
    np.testing.assert_allclose(mm["people"], m["people"], atol=1e-3)
    assert m["frame"]["rgb_at_person"] == [200, 30, 30]


def stop_fake(fake: Output) -> None:
    os.killpg(fake.process.pid, signal.SIGKILL)
    fake.finish()


def _driving(ros_master, ros_nodes, *driver_args: str) -> tuple[Output, Output, Output]:
    """A fake HSR on sim time, a listener of the base commands, and the driver commanding
    0.1 m/s every period (seen by the listener)."""
    _sim_time(ros_master)
    fake = _fake(ros_nodes, "--sim-time")
    listener = _node(ros_nodes, "twist_listener.py")
    listener.wait(lambda s: s == "READY")
    driver = _node(ros_nodes, "hsr_driver.py", "drive", *driver_args)
    driver.event("driving")
    listener.wait(lambda s: s.startswith("CMD") and float(s.split()[2]) == 0.1)
    return fake, listener, driver


def _zero_after(listener: Output, since: float) -> float:
    """Seconds from ``since`` to the first zero Twist the listener got after it; every command
    after that zero is zero too."""
    cmds = [c for c in listener.commands() if c[0] >= since]
    zero = next((c for c in cmds if c[1:] == (0.0, 0.0, 0.0)), None)
    assert zero is not None, listener.lines[-10:]
    assert all(c[1:] == (0.0, 0.0, 0.0) for c in cmds[cmds.index(zero) :])  # zero ever after
    return zero[0] - since


def _drive_until_lost(ros_master, ros_nodes, kill: Callable[[Output], None]) -> tuple:
    """Drive at 0.1 m/s, ``kill`` while driving: (seconds to the zero, the driver's error)."""
    fake, listener, driver = _driving(ros_master, ros_nodes)
    killed = time.monotonic()
    kill(fake)
    lost = driver.event("lost")
    after = driver.event("after")
    assert driver.finish() == 0
    assert after["commanded"] == 0.0 and after["again"] == lost["message"]
    return _zero_after(listener, killed), lost["message"]


def test_killed_robot_stops_the_base_at_once(ros_master, ros_nodes):
    """SIGKILL of the robot while driving: a zero Twist within 0.5 s, then RobotLostError."""
    delay, message = _drive_until_lost(ros_master, ros_nodes, stop_fake)
    assert delay <= 0.5
    assert message.startswith("lost the robot: ") and "/hsrb/base_scan" in message


def test_silent_robot_stops_the_base_after_the_stale_timeout(ros_master, ros_nodes):
    """A robot that stops sending (SIGSTOP: connections stay open) is stale after
    backend.hsr.stale_timeout (0.5 s) of wall time."""

    frozen: list[Output] = []

    def freeze(fake: Output) -> None:
        frozen.append(fake)
        os.killpg(fake.process.pid, signal.SIGSTOP)

    try:
        delay, message = _drive_until_lost(ros_master, ros_nodes, freeze)
    finally:
        for fake in frozen:  # a stopped process would not end on the fixture's SIGTERM
            stop_fake(fake)
    assert 0.5 - 0.15 <= delay <= 0.5 + 0.3  # the last scan came up to a period before
    assert message.startswith("lost the robot: no ")
    assert " for 0.5 s" in message or " for 0.6 s" in message


def test_lost_master_stops_the_base(ros_master, ros_nodes):
    """The master dies while the robot's topics still flow: lost within ~2 s."""

    def kill_master(_fake: Output) -> None:
        os.killpg(ros_master.process.pid, signal.SIGKILL)

    delay, message = _drive_until_lost(ros_master, ros_nodes, kill_master)
    assert message.startswith(f"lost the ROS master at {ros_master.uri}")
    assert delay <= 2.5


def test_ctrl_c_stops_the_base(ros_master, ros_nodes):
    """SIGINT (KeyboardInterrupt) in the driving process: the base gets zero before it exits."""
    _, listener, driver = _driving(ros_master, ros_nodes)
    interrupted = time.monotonic()
    os.kill(driver.process.pid, signal.SIGINT)
    assert driver.finish() != 0  # the KeyboardInterrupt ends the process
    assert _zero_after(listener, interrupted) <= 0.5


def test_ctrl_c_inside_a_base_command_stops_the_base(ros_master, ros_nodes):
    """SIGINT as a base command takes rospy's publish lock: the KeyboardInterrupt still ends the
    process and the base gets zero (raised inside rospy's publish, it became a RuntimeError of
    rospy's ``finally`` that the publish error handling swallowed: the driver drove on)."""
    _, listener, driver = _driving(ros_master, ros_nodes, "--interrupt-at-command", "20")
    interrupted = driver.event("interrupting")["at"]
    assert driver.finish() != 0
    assert _zero_after(listener, interrupted) <= 0.5


def test_missing_laser_is_one_line_naming_the_topic(ros_master, ros_nodes):
    _fake(ros_nodes, "--omit", "/hsrb/base_scan")
    driver = _node(ros_nodes, "hsr_driver.py", "connect", "--timeout", "1.5")
    err = driver.event("error")
    assert driver.finish() == 0
    assert err["kind"] == "RobotConnectionError" and err["exit_code"] == 2
    assert err["message"] == (
        "no laser scan on /hsrb/base_scan (no node publishes it) after 1.5 s "
        f"(ROS_MASTER_URI={ros_master.uri})"
    )
    assert 1.5 <= err["seconds"] < 10


def test_unreachable_master_is_one_line(ros, monkeypatch):
    """No master: a clear error before rospy's init_node (which would block forever)."""
    from pfctl.app.hsr import hsr_config
    from pfctl.backends.hsr.robot import HsrRobot, RobotConnectionError
    from pfctl.mission import load_mission

    from .conftest import _free_port

    uri = f"http://127.0.0.1:{_free_port()}/"
    monkeypatch.setenv("ROS_MASTER_URI", uri)
    mission = load_mission(Path(__file__).parents[3] / "missions" / "house.yaml")
    with pytest.raises(RobotConnectionError) as info:
        HsrRobot(hsr_config(mission))
    message = str(info.value)
    assert message.startswith(f"cannot reach the ROS master at {uri} (")
    assert "\n" not in message and info.value.exit_code == 2


def test_navigate_through_move_base(ros_master, ros_nodes):
    """IDLE before a goal; the goal goes to move_base in the map frame; a direct command
    preempts it; a second goal succeeds. Then a second HsrRobot in the same process."""
    fake = _fake(ros_nodes, "--move-base")
    driver = _node(ros_nodes, "hsr_driver.py", "navigate")
    seen = driver.event("nav")["seen"]
    second = driver.event("second")
    assert driver.finish() == 0
    assert second["same"] is True and second["beams"] == N_BEAMS
    # right after navigate() the goal is pending, or already active when move_base's acceptance
    # arrived first (a busy machine can deschedule the driver between the two calls)
    assert seen[0] == "idle" and seen[1] in ("pending", "active")
    assert seen[2:] == ["active", "preempted", "succeeded"]
    goals = [s.split() for s in fake.lines if s.startswith("GOAL")]
    assert [g[0] for g in goals] == ["GOAL", "GOAL_END", "GOAL", "GOAL_END"]
    assert goals[1][2] == "preempted" and goals[3][2] == "succeeded"
    np.testing.assert_allclose([float(v) for v in goals[0][2:5]], (3.0, 4.0, 0.5), atol=1e-9)
    assert goals[0][5] == "map"
