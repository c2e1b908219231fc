"""Drives ``HsrRobot`` for the tests in its own process (one ROS node per process; rospy's
interrupt exceptions must not reach pytest). ``hsr_driver.py SCENARIO [--timeout S] [--pose T]``
prints one JSON object per line (``{"event": ...}``) and exits 0 when the scenario ran.

Scenarios:

* ``observe``: connect, step until a scan and an RGB-D frame were observed (with ``--truth``:
  and the truth's robot and people, which come on topics of their own), report them (the
  scan's ranges and points, the leg detector's and the person detector's results), the pose,
  head, odometry, collisions, truth, the step times; then command out of limits, point the head
  out of limits, navigate without a server, close.
* ``drive``: command 0.1 m/s every period until the robot is lost; report the error.
  ``--interrupt-at-command N``: SIGINT as the N-th base command takes rospy's publish lock.
* ``navigate``: a goal to move_base, preempted by a direct command; a second one to the end;
  then a second ``HsrRobot`` in the same process.
* ``scans``: step and observe ``--periods`` control periods, then observe nothing until more
  scans than the queue holds came in (``dropped_scans`` counts them), then once more; report the
  scan stamps of each observation and the dropped count.
* ``connect``: only connect (``--timeout``), report the error if there is one.
* ``people`` (with ``--keypoints TOPIC``: ``backend.hsr.person_keypoints``): command zero once
  (a bridge holding its episode starts it), then observe ``--frames`` RGB-D frames; report each
  frame's given people, the person detector's positions and the truth of the frame's stamp.
* ``speak``: wait until the robot speaks (a node listens to ``backend.hsr.speech``), say one
  sentence, command zero and step a few periods; report whether it spoke.
"""

from __future__ import annotations

import argparse
import faulthandler
import json
import math
import os
import signal
import sys
import time
from pathlib import Path

import numpy as np

import pfctl
from pfctl.app.hsr import hsr_config
from pfctl.app.leg_models import load_leg_model
from pfctl.backends.hsr.robot import SCAN_QUEUE, HsrRobot
from pfctl.backends.hsr.ros_import import import_ros_module
from pfctl.core.perception.legs.detector import LegDetector
from pfctl.core.perception.tracking import FieldOfView
from pfctl.core.robot import STOP, HeadTarget, Pose2D, RobotLostError, Twist2D
from pfctl.errors import UserError
from pfctl.mission import BackendConfig, HsrConfig, load_mission

HOUSE = Path(pfctl.__file__).resolve().parents[1] / "missions" / "house.yaml"


def say(event: str, **data: object) -> None:
    print(json.dumps({"event": event, **data}), flush=True)


def finite(v: float) -> float | None:
    return float(v) if math.isfinite(v) else None


def observe(robot: HsrRobot, want_truth: bool = False) -> None:
    scan = frame = truth = None
    times = [robot.time]
    for _ in range(60):
        robot.step()
        times.append(robot.time)
        obs = robot.observe()
        assert obs.stamp >= times[-1] - 1e-9, (obs.stamp, times[-1])
        # the fake HSR's topics arrive in any order: the first scan seen with the odometry too
        if obs.scan is not None and obs.odometry is not None and scan is None:
            scan, scan_obs = obs.scan, obs
        if obs.rgbd is not None and frame is None:
            frame = obs.rgbd
        truth = robot.ground_truth()
        truth_in = not want_truth or (truth is not None and len(truth.people) > 0)
        if scan is not None and frame is not None and truth_in and len(times) > 6:
            break
    assert scan is not None and frame is not None, "no scan or no frame observed"
    assert truth_in, "no ground truth of the robot and the people observed"
    legs = LegDetector(load_leg_model()).detect(scan)
    fov = FieldOfView.from_scan(scan)
    detector = robot.person_detector()
    people = detector.detect(frame) if detector is not None else []
    say(
        "observed",
        times=times,
        period=robot.period,
        use_sim_time=robot.use_sim_time,
        scan={
            "stamp": scan.stamp,
            "obs_stamp": scan_obs.stamp,
            "n": len(scan.ranges),
            "ranges": [finite(r) for r in scan.ranges],
            "points": np.asarray(scan.points()).tolist(),
            "pose": [scan.pose.x, scan.pose.y, scan.pose.theta],
            "legs": len(legs.legs),
            "fov_ok": fov is not None,
        },
        pose=[scan_obs.pose.x, scan_obs.pose.y, scan_obs.pose.theta],
        head=[scan_obs.head.pan, scan_obs.head.tilt],
        odometry=[scan_obs.odometry.x, scan_obs.odometry.y, scan_obs.odometry.theta],
        collisions=scan_obs.collisions,
        frame={
            "stamp": frame.stamp,
            "shape": list(frame.depth.shape),
            "mask_dtype": str(frame.mask.dtype) if frame.mask is not None else None,
            "position": list(frame.camera_position),
            "rotation": frame.camera_rotation.tolist(),
            "rgb_at_person": frame.rgb[60, 80].tolist(),
        },
        people=[list(p.position) for p in people],
        head_boxes=[list(p.head_box) if p.head_box else None for p in people],
        truth=None
        if truth is None
        else {
            "stamp": truth.stamp,
            "robot": [truth.robot.x, truth.robot.y, truth.robot.theta],
            "people": [[p.name, p.x, p.y, p.theta, p.speed, p.is_target] for p in truth.people],
            "collisions": truth.collisions,
        },
    )
    say("nav", status=robot.nav_status().value)
    robot.navigate(Pose2D(3.0, 4.0, 0.0))
    say("nav", status=robot.nav_status().value)
    robot.command(Twist2D(1.0, 1.0, 5.0))
    say("commanded", twist=[robot.commanded.vx, robot.commanded.vy, robot.commanded.wz])
    robot.point_head(HeadTarget(9.0, -9.0))
    robot.step()
    robot.close()
    say("closed")
    robot.close()  # safe twice


def drive(robot: HsrRobot) -> None:
    say("driving", time=robot.time)
    try:
        while True:
            robot.command(Twist2D(0.1, 0.0, 0.0))
            robot.step()
            robot.observe()
    except RobotLostError as err:
        say("lost", message=str(err), at=time.monotonic(), commanded=robot.commanded.vx)
    # after losing: commands are zero, observe raises again
    robot.command(Twist2D(0.1, 0.0, 0.0))
    try:
        robot.observe()
        again = None
    except RobotLostError as err:
        again = str(err)
    say("after", commanded=robot.commanded.vx, again=again)


def navigate(robot: HsrRobot) -> None:
    seen = [robot.nav_status().value]
    robot.navigate(Pose2D(3.0, 4.0, 0.5))
    seen.append(robot.nav_status().value)
    deadline = time.monotonic() + 5.0
    while robot.nav_status().value != "active" and time.monotonic() < deadline:
        robot.step()
    seen.append(robot.nav_status().value)
    robot.command(Twist2D(0.05, 0.0, 0.0))  # a direct command preempts the goal
    seen.append(robot.nav_status().value)
    robot.navigate(Pose2D(-1.0, 2.0, 0.0))
    while robot.nav_status().value in ("pending", "active") and time.monotonic() < deadline:
        robot.step()
    seen.append(robot.nav_status().value)
    say("nav", seen=seen)
    robot.close()
    # a second robot in the same process (rospy: one node per process) uses the same node
    with HsrRobot(robot.config, node_name="pfctl_test", connect_timeout=15.0) as second:
        scan = None
        while scan is None:
            second.step()
            scan = second.observe().scan
        say("second", node=second.node, same=second.node == robot.node, beams=len(scan.ranges))


def scans(robot: HsrRobot, periods: int) -> None:
    observed = []
    for _ in range(periods):
        robot.step()
        observed.append([scan.stamp for scan in robot.observe().scans])
    deadline = time.monotonic() + 30.0
    while robot.dropped_scans < 5 and time.monotonic() < deadline:
        time.sleep(0.05)  # polling the backend's count: the scans queue meanwhile
    dropped = robot.dropped_scans
    late = [scan.stamp for scan in robot.observe().scans]
    say("scans", observed=observed, late=late, dropped=dropped, queue=SCAN_QUEUE)


def people(robot: HsrRobot, frames: int) -> None:
    detector = robot.person_detector()
    robot.command(STOP)  # the first command ends the bridge's hold: the episode starts
    truths, seen = {}, []
    for _ in range(30 * frames):
        robot.step()
        obs = robot.observe()
        truth = robot.ground_truth()
        if truth is not None:
            truths[round(truth.stamp, 6)] = truth
        if obs.rgbd is not None:
            seen.append(obs.rgbd)
        if len(seen) >= frames and round(seen[-1].stamp, 6) in truths:
            break
    out = []
    for frame in seen:
        truth = truths.get(round(frame.stamp, 6))
        out.append(
            {
                "stamp": frame.stamp,
                "mask": frame.mask is not None,
                "given": [
                    {
                        "box": list(p.box),
                        "head_box": list(p.head_box) if p.head_box else None,
                        "keypoints": sorted(p.keypoints or {}),
                        "score": p.score,
                    }
                    for p in frame.people or ()
                ]
                if frame.people is not None
                else None,
                "detected": [list(d.position) for d in detector.detect(frame)],
                "truth": None if truth is None else [[p.name, p.x, p.y] for p in truth.people],
            }
        )
    say("people", detector=type(detector).__name__, frames=out)


def interrupt_inside_publish(n: int) -> None:
    """Send this process SIGINT as the ``n``-th base command takes rospy's publish lock: the
    KeyboardInterrupt then falls inside ``Publisher.publish`` if it runs in the main thread."""
    topics = import_ros_module("rospy.topics")
    acquire = topics._PublisherImpl.acquire
    seen = [0]

    def interrupting(impl: object) -> None:
        if impl.resolved_name == "/hsrb/command_velocity":
            seen[0] += 1
            if seen[0] == n:
                say("interrupting", at=time.monotonic())
                os.kill(os.getpid(), signal.SIGINT)
        acquire(impl)

    topics._PublisherImpl.acquire = interrupting


def speak(robot: HsrRobot) -> None:
    deadline = time.monotonic() + 10.0
    while not robot.speaks and time.monotonic() < deadline:
        time.sleep(0.05)
    speaks = robot.speaks
    robot.say("Excuse me, could you look at me, please?")
    robot.command(STOP)
    for _ in range(4):
        robot.step()
    say("spoke", speaks=speaks)


def main() -> None:
    faulthandler.register(signal.SIGUSR1, all_threads=True)  # a hung driver's stacks
    parser = argparse.ArgumentParser()
    parser.add_argument(
        "scenario",
        choices=("observe", "drive", "navigate", "connect", "people", "scans", "speak"),
    )
    parser.add_argument("--timeout", type=float, default=15.0)
    parser.add_argument("--pose", default=None, help="backend.hsr.pose")
    parser.add_argument("--keypoints", default=None, help="backend.hsr.person_keypoints")
    parser.add_argument("--frames", type=int, default=10, help="frames to observe (people)")
    parser.add_argument("--periods", type=int, default=10, help="periods to observe (scans)")
    parser.add_argument("--truth", action="store_true", help="observe: wait for the truth too")
    parser.add_argument(
        "--interrupt-at-command",
        type=int,
        default=0,
        help="Ctrl-C (SIGINT) as the N-th base command enters rospy's publish lock",
    )
    args = parser.parse_args(sys.argv[1:])
    if args.interrupt_at_command:
        interrupt_inside_publish(args.interrupt_at_command)
    mission = load_mission(HOUSE)
    hsr = HsrConfig(pose=args.pose, person_keypoints=args.keypoints)
    mission = mission.model_copy(update={"backend": BackendConfig(hsr=hsr)})
    started = time.monotonic()
    try:
        robot = HsrRobot(hsr_config(mission), node_name="pfctl_test", connect_timeout=args.timeout)
    except UserError as err:
        say(
            "error",
            kind=type(err).__name__,
            message=str(err),
            exit_code=err.exit_code,
            seconds=time.monotonic() - started,
        )
        return
    say("connected", seconds=time.monotonic() - started, node=robot.node)
    with robot:
        {
            "observe": lambda r: observe(r, args.truth),
            "drive": drive,
            "navigate": navigate,
            "connect": lambda r: None,
            "people": lambda r: people(r, args.frames),
            "scans": lambda r: scans(r, args.periods),
            "speak": speak,
        }[args.scenario](robot)


if __name__ == "__main__":
    main()
