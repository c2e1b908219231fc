"""The simulated house served as a Toyota HSR on a ROS 1 master (``pfctl sim serve-hsr``).

:class:`SimHsrBridge` runs a :class:`~pfctl.backends.pybullet.simulation.SimRobot` and serves the
interfaces of an :class:`~pfctl.backends.hsr.config.HsrConfig` (the mission's ``backend.hsr``)
with the message types, frames and stamps of Toyota's ROS 1 stack, so that
:mod:`pfctl.backends.hsr.robot` cannot tell it from the robot.

Time
    The master's ``/use_sim_time`` is set to true before the node exists, and ``/clock``
    (``rosgraph_msgs/Clock``) carries the simulation time. ROS time is the simulated time plus
    :data:`CLOCK_OFFSET` (100 s): rospy reads time 0 as "no clock yet", and a node that looks a
    few seconds back (``now - Duration(5)``) must not meet a negative time. Every stamp (sensors,
    tf, truth, actionlib) is on this clock, converted to whole nanoseconds by :func:`ros_time`, so
    equal simulated times give equal stamps. The offset is also the master parameter
    :data:`OFFSET_PARAM`.

What is published when
    The simulator advances in sub-steps (``SimRobot.substeps`` per control period ``1 /
    behavior.tick_hz``; 4 of 25 ms in the house, one per laser scan). After each sub-step, paced
    to ``rate`` × real time (``rate`` 0: as fast as the CPU allows), the bridge publishes in this
    order, everything stamped with the sub-step's time ``t``:

    1. ``/clock`` = ``t``;
    2. ``/tf``: ``map → odom`` (localised pose ∘ odometry⁻¹) and ``odom → base_footprint``
       (odometry), plus ``base_footprint → head_rgbd_sensor_rgb_frame`` (3-D, the optical frame)
       when a camera frame was taken;
    3. ``odom`` (``nav_msgs/Odometry``, ``odom`` → ``base_footprint``, the twist from the
       odometry's last move), ``joint_states`` (``head_pan_joint``, ``head_tilt_joint``), and
       ``pose`` (``geometry_msgs/PoseStamped``, map) when the mission names that topic;
    4. ``laser``: every scan (40 Hz in the house: the Hokuyo's rate, one per sub-step), frame
       ``base_range_sensor_link``, REP-117 ranges. All scans rather than the newest per period:
       that is what the robot does, and the leg detector and MOVE_BASE's blockers see each one;
    5. at the camera's rate (10 Hz): ``rgb`` (rgb8), ``depth`` (16UC1 mm like the Xtion's
       ``image_rect_raw``, or 32FC1 m), ``camera_info`` and ``person_labels`` (16UC1, see
       :mod:`pfctl.backends.hsr.person_labels`: the simulator's stand-in for OpenPose) or, when
       the mission sets it, ``person_keypoints`` (``sensor_msgs/PointCloud``, see
       :mod:`pfctl.bags.person_keypoints`: the mask detector's people — box, head,
       neck, mid-hip, ankles — as BODY_25 keypoints and box corners, standing in for OpenPose
       too), all with the same stamp and frame ``head_rgbd_sensor_rgb_frame``;
    6. once per control period (and at ``t`` = 0): the truth for metrics, never for the follower:
       ``<ground_truth>/robot`` (``geometry_msgs/PoseStamped``, the true pose),
       ``<ground_truth>/people`` (``visualization_msgs/MarkerArray``, one CYLINDER per person as
       :func:`pfctl.bags.recording.person_marker` encodes it) and
       ``<ground_truth>/collisions`` (``std_msgs/UInt32``).

    ``/tf_static`` (latched) holds ``base_footprint → base_range_sensor_link`` (the laser mount of
    ``sensors.laser``). The first batch, at ``t`` = 0, is published once every subscriber the
    master already knows of is connected (at most :data:`PEER_WAIT` s), so a node subscribed
    before the bridge gets the episode from its first scan; :data:`READY_PARAM` is set just
    before it.

Holding the episode (``wait_for_command``, ``pfctl sim serve-hsr --wait-for-command``)
    Until the first velocity, head or move_base command, the simulator does not advance (nobody
    walks) but the clock runs: the ``t`` = 0 instant is published again every sub-step with new
    stamps (its scan at the laser's rate, its frame at the camera's, its truth every period), so
    a follower connects and finds fresh data. From the first command on, ROS time = simulated
    time + :data:`CLOCK_OFFSET` + the time held (:data:`OFFSET_PARAM` is updated then).

Commands
    Callbacks come on rospy's threads and only queue what they got; the simulation thread applies
    the queue in arrival order before each sub-step (PyBullet is touched from one thread only):

    * ``command_velocity`` (``geometry_msgs/Twist``) → ``SimRobot.command``: a Twist preempts a
      running move_base goal, as the Robot port says;
    * ``head_command`` (``trajectory_msgs/JointTrajectory``) → ``SimRobot.point_head`` (the last
      point's pan and tilt);
    * ``move_base`` (``move_base_msgs/MoveBaseAction``, :class:`actionlib.ActionServer`): a goal in
      ``map`` (or ``odom``, ``base_footprint``: transformed at once) → ``SimRobot.navigate``; a new
      goal preempts the running one; a cancel → ``SimRobot.cancel`` (PREEMPTED); SUCCEEDED and
      ABORTED as the simulated MOVE_BASE ends; feedback (the base's pose) once per period;
    * ``viewpoint_stop`` (``std_srvs/Empty``): answered and counted;
    * ``speech`` (``std_msgs/String``) → ``SimRobot.say``: the people within earshot turn to the
      robot.
"""

from __future__ import annotations

import contextlib
import functools
import math
import os
import queue
import sys
import threading
import time
import xmlrpc.client
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from pfctl.backends.hsr import convert
from pfctl.backends.hsr.config import HsrConfig
from pfctl.backends.hsr.master import MasterError, check_master, master_proxy
from pfctl.backends.hsr.person_labels import ENCODING as LABEL_ENCODING
from pfctl.backends.hsr.person_labels import encode_labels
from pfctl.backends.hsr.ros_import import import_ros_module, import_rospy
from pfctl.bags.person_keypoints import cloud_message, detection_parts
from pfctl.bags.recording import (
    CAMERA_FRAME,
    LASER_FRAME,
    camera_in_base,
    person_marker,
)
from pfctl.core.perception.vision import MaskPersonDetector, PersonDetection
from pfctl.core.robot import (
    STOP,
    GroundTruth,
    LaserScan,
    Observation,
    Pose2D,
    RgbdFrame,
    Twist2D,
)
from pfctl.errors import UserError

if TYPE_CHECKING:
    from pfctl.backends.pybullet.config import LaserConfig
    from pfctl.backends.pybullet.simulation import SimRobot

CLOCK_OFFSET = 100.0
"""ROS time minus simulated time, seconds (see the module docstring)."""
NODE_NAME = "pfctl_sim_hsr"
READY_PARAM = "/pfctl/sim/ready"
"""True while the bridge serves (set just before the first batch of messages; deleted at the
end)."""
OFFSET_PARAM = "/pfctl/sim/clock_offset"
SEED_PARAM = "/pfctl/sim/seed"
DEPTH_ENCODINGS = ("16UC1", "32FC1")
MASTER_CHECK_TIMEOUT = 3.0
"""Wall seconds the master may take to answer before it counts as missing."""
PEER_WAIT = 3.0
"""Wall seconds to wait for subscribers (and publishers) the master already knows to connect."""
MAX_LAG = 0.25
"""Wall seconds the bridge may fall behind ``rate`` × real time before it stops catching up
(then the clock runs slower instead of publishing a burst)."""
CANCELLABLE = (0, 1, 6, 7)
"""actionlib_msgs/GoalStatus PENDING, ACTIVE, PREEMPTING, RECALLING: set_canceled applies."""


def _msgs(module: str) -> Any:
    return import_ros_module(module)


def ros_time(t: float, offset: float = CLOCK_OFFSET) -> Any:
    """The ``rospy.Time`` of simulated time ``t``: ``t + offset`` in whole nanoseconds (rounded;
    ``Time.from_sec`` truncates, so 100.025 would become ...024999999)."""
    ns = round((float(t) + offset) * 1e9)
    return _time_class()(ns // 1_000_000_000, ns % 1_000_000_000)


@functools.cache
def _time_class() -> Any:
    return import_rospy().Time


# ------------------------------------------------------------------------------------- master


def master_uri() -> str:
    """``ROS_MASTER_URI``; a UserError when it is not set."""
    uri = os.environ.get("ROS_MASTER_URI", "").strip()
    if not uri:
        raise UserError(
            "ROS_MASTER_URI is not set: start a ROS master (roscore) and point ROS_MASTER_URI at it"
        )
    return uri


def reach_master(uri: str) -> None:
    """A UserError (one line) unless a ROS master answers at ``uri`` within
    :data:`MASTER_CHECK_TIMEOUT` seconds (``rospy.init_node`` would wait for it forever)."""
    try:
        check_master(uri, "/" + NODE_NAME, MASTER_CHECK_TIMEOUT)
    except MasterError as err:
        if err.error is None:
            raise UserError(
                f"the ROS master at {uri} does not answer getPid: {err.answer}"
            ) from None
        reason = getattr(err.error, "strerror", None) or str(err.error) or type(err.error).__name__
        raise UserError(
            f"no ROS master at {uri} ({reason}); start roscore or set ROS_MASTER_URI"
        ) from None


def claim_sim_time(uri: str) -> None:
    """Set the master's ``/use_sim_time`` to true (and :data:`OFFSET_PARAM`): as early as
    possible, since a node reads it once, when it starts."""
    proxy = master_proxy(uri)
    caller = "/" + NODE_NAME
    proxy.setParam(caller, "/use_sim_time", True)
    proxy.setParam(caller, OFFSET_PARAM, CLOCK_OFFSET)


# ------------------------------------------------------------------------------------ messages


class HsrMessages:
    """The messages of the bridge, built from the simulator's values (no node needed)."""

    def __init__(
        self, config: HsrConfig, laser: LaserConfig, depth_encoding: str = "16UC1"
    ) -> None:
        if depth_encoding not in DEPTH_ENCODINGS:
            raise ValueError(
                f"unsupported depth encoding {depth_encoding!r} (expected 16UC1 or 32FC1)"
            )
        self.cfg = config
        self.laser = laser
        self.depth_encoding = depth_encoding
        self.geometry = _msgs("geometry_msgs.msg")
        self.std = _msgs("std_msgs.msg")
        self.sensor = _msgs("sensor_msgs.msg")
        self.nav = _msgs("nav_msgs.msg")
        self.tf2 = _msgs("tf2_msgs.msg")
        self.viz = _msgs("visualization_msgs.msg")
        self.clock_msgs = _msgs("rosgraph_msgs.msg")
        self.offset = CLOCK_OFFSET
        """ROS time minus simulated time of every stamp built (the bridge adds the time it held
        the clock, ``--wait-for-command``)."""

    def stamp(self, t: float) -> Any:
        """The ROS stamp of simulated time ``t``."""
        return ros_time(t, self.offset)

    def header(self, t: float, frame_id: str) -> Any:
        return self.std.Header(stamp=self.stamp(t), frame_id=frame_id)

    def clock(self, t: float) -> Any:
        return self.clock_msgs.Clock(clock=self.stamp(t))

    def _transform(
        self,
        t: float,
        parent: str,
        child: str,
        xyz: tuple[float, float, float],
        quat: tuple[float, float, float, float],
    ) -> Any:
        g = self.geometry
        return g.TransformStamped(
            header=self.header(t, parent),
            child_frame_id=child,
            transform=g.Transform(translation=g.Vector3(*xyz), rotation=g.Quaternion(*quat)),
        )

    def _planar(self, t: float, parent: str, child: str, pose: Pose2D, z: float = 0.0) -> Any:
        h = pose.theta / 2.0
        return self._transform(
            t, parent, child, (pose.x, pose.y, z), (0.0, 0.0, math.sin(h), math.cos(h))
        )

    def tf_static(self) -> Any:
        """``/tf_static``: ``base_footprint → base_range_sensor_link`` (the laser's mount)."""
        laser = self.laser
        mount = self._planar(
            0.0, self.cfg.base_frame, LASER_FRAME, Pose2D(laser.mount_x, 0.0), laser.mount_height
        )
        return self.tf2.TFMessage(transforms=[mount])

    @staticmethod
    def odometry_pose(obs: Observation) -> Pose2D:
        """The base in the odom frame (the localised pose when there is no odometry: odom =
        map)."""
        return obs.odometry if obs.odometry is not None else obs.pose

    def tf(self, obs: Observation) -> Any:
        """``/tf`` at ``obs.stamp``: map → odom → base_footprint, and the camera with a frame."""
        cfg, t = self.cfg, obs.stamp
        odom = self.odometry_pose(obs)
        transforms = [
            self._planar(t, cfg.map_frame, cfg.odom_frame, obs.pose.compose(odom.inverse())),
            self._planar(t, cfg.odom_frame, cfg.base_frame, odom),
        ]
        if obs.rgbd is not None:
            transforms.append(self.camera_transform(obs.rgbd, obs.pose))
        return self.tf2.TFMessage(transforms=transforms)

    def camera_transform(self, frame: RgbdFrame, base: Pose2D) -> Any:
        """``base_footprint → head_rgbd_sensor_rgb_frame`` at the frame's stamp; ``base`` is the
        localised pose the frame was posed with, so map → odom → base → camera puts the camera
        where the frame says it is."""
        xyz, quat = camera_in_base(frame, base)
        return self._transform(frame.stamp, self.cfg.base_frame, CAMERA_FRAME, xyz, quat)

    def odometry(self, obs: Observation, twist: Twist2D) -> Any:
        """``nav_msgs/Odometry`` (odom → base_footprint); ``twist`` in the base frame."""
        g = self.geometry
        msg = self.nav.Odometry(
            header=self.header(obs.stamp, self.cfg.odom_frame),
            child_frame_id=self.cfg.base_frame,
        )
        msg.pose.pose = convert.pose2d_to_pose(self.odometry_pose(obs))
        msg.twist.twist = g.Twist(
            linear=g.Vector3(twist.vx, twist.vy, 0.0), angular=g.Vector3(0.0, 0.0, twist.wz)
        )
        return msg

    def joint_states(self, obs: Observation) -> Any:
        msg = convert.joint_state_msg(
            {convert.HEAD_PAN_JOINT: obs.head.pan, convert.HEAD_TILT_JOINT: obs.head.tilt}
        )
        msg.header.stamp = self.stamp(obs.stamp)
        return msg

    def pose(self, obs: Observation) -> Any:
        """The localised pose as ``geometry_msgs/PoseStamped`` (e.g. ``/global_pose``)."""
        return self.geometry.PoseStamped(
            header=self.header(obs.stamp, self.cfg.map_frame), pose=convert.pose2d_to_pose(obs.pose)
        )

    def scan(self, scan: LaserScan) -> Any:
        msg = convert.laser_scan_to_msg(scan, frame_id=LASER_FRAME)
        msg.header.stamp = self.stamp(scan.stamp)
        return msg

    def camera(self, frame: RgbdFrame, labels: np.ndarray | None) -> tuple[Any, Any, Any, Any]:
        """``(rgb, depth, camera_info, person_labels or None)``, same stamp and frame."""
        stamp = self.stamp(frame.stamp)
        rgb = convert.rgb_to_image(frame.rgb, None, CAMERA_FRAME)
        depth = convert.depth_to_image(frame.depth, None, CAMERA_FRAME, self.depth_encoding)
        info = convert.camera_info_to_msg(frame.info)
        info.header.frame_id = CAMERA_FRAME
        label_msg = None
        if labels is not None:
            h, w = labels.shape
            label_msg = self.sensor.Image(
                header=self.std.Header(frame_id=CAMERA_FRAME),
                height=h,
                width=w,
                encoding=LABEL_ENCODING,
                is_bigendian=0,
                step=2 * w,
                data=np.ascontiguousarray(labels, dtype="<u2").tobytes(),
            )
        for msg in (rgb, depth, info, label_msg):
            if msg is not None:
                msg.header.stamp = stamp
        return rgb, depth, info, label_msg

    def person_keypoints(self, frame: RgbdFrame, people: list[PersonDetection]) -> Any:
        """``sensor_msgs/PointCloud`` of the mask detector's ``people`` in ``frame``
        (:func:`~pfctl.bags.person_keypoints.detection_parts`, person = the simulator's
        instance index), with the frame's stamp and the camera's optical frame."""
        parts = {
            int(d.instance if d.instance is not None else i): detection_parts(d)
            for i, d in enumerate(people)
        }
        header = self.header(frame.stamp, CAMERA_FRAME)
        return cloud_message(self.sensor, self.geometry, header, parts)

    def truth(self, truth: GroundTruth) -> tuple[Any, Any, Any]:
        """``(robot PoseStamped, people MarkerArray, collisions UInt32)`` (module docstring)."""
        g, t, frame = self.geometry, truth.stamp, self.cfg.map_frame
        robot = g.PoseStamped(
            header=self.header(t, frame), pose=convert.pose2d_to_pose(truth.robot)
        )
        markers = []
        for i, person in enumerate(truth.people):
            m = person_marker(person, i)
            r, gr, b, a = m.color
            markers.append(
                self.viz.Marker(
                    header=self.header(t, frame),
                    ns=m.ns,
                    id=m.id,
                    type=m.type,
                    action=m.action,
                    pose=convert.pose2d_to_pose(m.pose, z=m.z),
                    scale=g.Vector3(*m.scale),
                    color=self.std.ColorRGBA(r, gr, b, a),
                    lifetime=convert.sec_to_duration(m.lifetime),
                    text=m.text,
                )
            )
        people = self.viz.MarkerArray(markers=markers)
        return robot, people, self.std.UInt32(data=int(truth.collisions))

    def goal_in_map(self, target: Any, pose: Pose2D, odometry: Pose2D) -> Pose2D:
        """A move_base goal (``geometry_msgs/PoseStamped``) in the map frame: given in ``map``
        (or with no frame), ``odom`` (through the current map → odom) or ``base_footprint``
        (relative to the localised ``pose``). ValueError for any other frame."""
        cfg = self.cfg
        goal = convert.pose2d_from_pose(target.pose)
        frame = target.header.frame_id.lstrip("/")
        if frame in ("", cfg.map_frame):
            return goal
        if frame == cfg.odom_frame:
            return pose.compose(odometry.inverse()).compose(goal)
        if frame == cfg.base_frame:
            return pose.compose(goal)
        raise ValueError(
            f"goal in frame {frame!r}: expected {cfg.map_frame}, {cfg.odom_frame} or "
            f"{cfg.base_frame}"
        )


# -------------------------------------------------------------------------------------- bridge


@dataclass
class BridgeStats:
    """What a run served and received."""

    sim_time: float = 0.0
    wall_time: float = 0.0
    scans: int = 0
    frames: int = 0
    velocity_commands: int = 0
    head_commands: int = 0
    goals: int = 0
    viewpoint_stops: int = 0
    said: int = 0
    """Sentences the robot said (``speech``)."""
    collisions: int = 0
    held: float = 0.0
    """Seconds of ROS time the clock ran before the first command (``wait_for_command``)."""
    held_wall: float = 0.0
    """Wall seconds of that hold (not part of :attr:`wall_time`)."""
    interrupted: bool = False
    lost: str | None = None
    """Why ROS ended the node under the bridge (another node took its name, ...)."""

    @property
    def real_time_factor(self) -> float:
        return self.sim_time / self.wall_time if self.wall_time > 0 else math.inf


class SimHsrBridge:
    """Serve ``robot`` (a fresh :class:`SimRobot`) as the HSR of ``config`` on the master at
    ``uri``.

    :meth:`start` sets ``/use_sim_time``, starts the node and its topics, services and action
    server and waits for known peers; :meth:`run` steps and publishes (module docstring);
    :meth:`shutdown` ends the node (the caller closes the simulator). Only the thread that calls
    :meth:`run` touches the simulator.

    With ``wait_for_command`` the episode waits for its robot: until the first velocity, head
    or move_base command arrives, the simulator does not advance (nobody walks) while the clock
    runs and the first instant is published again and again with new stamps, at the sensors'
    rates, so that a follower can connect and get ready (its watchdog sees fresh data). From
    the first command on, ROS time = simulated time + :data:`CLOCK_OFFSET` + the time held
    (:data:`OFFSET_PARAM` is updated).
    """

    def __init__(
        self,
        robot: SimRobot,
        config: HsrConfig,
        uri: str,
        *,
        rate: float = 1.0,
        depth_encoding: str = "16UC1",
        node_name: str = NODE_NAME,
        wait_for_command: bool = False,
    ) -> None:
        if not (math.isfinite(rate) and rate >= 0):
            raise ValueError(f"rate must be >= 0, got {rate}")
        self.robot = robot
        self.cfg = config
        self.uri = uri
        self.rate = float(rate)
        self.node_name = node_name
        self.wait_for_command = wait_for_command
        self.messages = HsrMessages(config, robot.config.laser, depth_encoding)
        self.stats = BridgeStats()
        self._events: queue.SimpleQueue[tuple[str, Any]] = queue.SimpleQueue()
        self._lock = threading.Lock()
        self._viewpoint_stops = 0
        self._goal: Any = None
        self._started = False
        self._pubs: dict[str, Any] = {}
        self._subs: list[Any] = []
        self._action: Any = None
        self._service: Any = None
        self._last_odometry: Pose2D | None = None
        self._instances = robot.person_instances()
        self._parts = robot.people_bodies.parts()
        self._keypoint_detector = MaskPersonDetector(
            self._instances, self._parts, min_pixels=config.min_pixels
        )

    # -- start and stop ------------------------------------------------------------------------

    def start(self, peer_wait: float = PEER_WAIT) -> None:
        """``/use_sim_time`` true, then the node, its publishers, subscribers, service and action
        server; waits up to ``peer_wait`` s for the peers the master knows of to connect."""
        rospy = import_rospy()
        claim_sim_time(self.uri)
        master_proxy(self.uri).setParam("/" + self.node_name, SEED_PARAM, int(self.robot.seed))
        rospy.init_node(self.node_name, argv=[sys.argv[0]], disable_signals=True)
        self._started = True
        cfg = self.cfg
        geometry, sensor, nav = self.messages.geometry, self.messages.sensor, self.messages.nav
        tf2, viz, std = self.messages.tf2, self.messages.viz, self.messages.std
        pub = rospy.Publisher
        self._pubs = {
            "clock": pub("/clock", self.messages.clock_msgs.Clock, queue_size=10),
            "tf": pub("/tf", tf2.TFMessage, queue_size=100),
            "tf_static": pub("/tf_static", tf2.TFMessage, queue_size=1, latch=True),
            "odom": pub(cfg.odom, nav.Odometry, queue_size=10),
            "joints": pub(cfg.joint_states, sensor.JointState, queue_size=10),
            "laser": pub(cfg.laser, sensor.LaserScan, queue_size=10),
            "rgb": pub(cfg.rgb, sensor.Image, queue_size=2),
            "depth": pub(cfg.depth, sensor.Image, queue_size=2),
            "info": pub(cfg.camera_info, sensor.CameraInfo, queue_size=2),
        }
        if cfg.pose is not None:
            self._pubs["pose"] = pub(cfg.pose, geometry.PoseStamped, queue_size=10)
        if cfg.person_labels is not None:
            self._pubs["labels"] = pub(cfg.person_labels, sensor.Image, queue_size=2)
        if cfg.person_keypoints is not None:
            self._pubs["keypoints"] = pub(cfg.person_keypoints, sensor.PointCloud, queue_size=2)
        if cfg.ground_truth is not None:
            ns = cfg.ground_truth.rstrip("/")
            self._pubs["truth_robot"] = pub(f"{ns}/robot", geometry.PoseStamped, queue_size=10)
            self._pubs["truth_people"] = pub(f"{ns}/people", viz.MarkerArray, queue_size=10)
            self._pubs["truth_collisions"] = pub(f"{ns}/collisions", std.UInt32, queue_size=10)
        self._subs = [
            rospy.Subscriber(cfg.command_velocity, geometry.Twist, self._on_twist, queue_size=50),
            rospy.Subscriber(
                cfg.head_command,
                _msgs("trajectory_msgs.msg").JointTrajectory,
                self._on_head,
                queue_size=50,
            ),
        ]
        if cfg.speech is not None:
            self._subs.append(rospy.Subscriber(cfg.speech, std.String, self._on_say, queue_size=10))
        if cfg.viewpoint_stop is not None:
            self._service = rospy.Service(
                cfg.viewpoint_stop, _msgs("std_srvs.srv").Empty, self._on_viewpoint_stop
            )
        actionlib = import_ros_module("actionlib")
        self._action = actionlib.ActionServer(
            cfg.move_base,
            _msgs("move_base_msgs.msg").MoveBaseAction,
            self._on_goal,
            self._on_cancel,
            auto_start=False,
        )
        self._action.start()
        self._pubs["tf_static"].publish(self.messages.tf_static())
        self._wait_for_peers(peer_wait)

    def _wait_for_peers(self, timeout: float) -> bool:
        """Until each of our publishers has as many connections as the master lists other
        subscribers of its topic (and each subscriber as many as other publishers), at most
        ``timeout`` wall seconds; True when all are connected."""
        rospy = import_rospy()
        me = rospy.get_name()
        action = self._action
        pubs = list(self._pubs.values()) + [
            getattr(action, n) for n in ("status_pub", "result_pub", "feedback_pub")
        ]
        subs = self._subs + [getattr(action, n) for n in ("goal_sub", "cancel_sub")]
        proxy = master_proxy(self.uri)
        deadline = time.monotonic() + timeout
        while True:
            try:
                code, _, (publishers, subscribers, _) = proxy.getSystemState(me)
            except (OSError, xmlrpc.client.Error):
                code = 0
            if code == 1:
                readers = {topic: [n for n in nodes if n != me] for topic, nodes in subscribers}
                writers = {topic: [n for n in nodes if n != me] for topic, nodes in publishers}
                if all(
                    p.get_num_connections() >= len(readers.get(p.resolved_name, [])) for p in pubs
                ) and all(
                    s.get_num_connections() >= len(writers.get(s.resolved_name, [])) for s in subs
                ):
                    return True
            if time.monotonic() >= deadline:
                return False
            time.sleep(0.05)

    def shutdown(self, reason: str = "done") -> None:
        """End a running goal (ABORTED), clear the ready flag, shut the node down; safe twice."""
        if not self._started:
            return
        self._started = False
        rospy = import_rospy()
        if self._goal is not None and not rospy.is_shutdown():
            self._goal.set_aborted(text=f"the simulator stopped ({reason})")
            self._goal = None
        with contextlib.suppress(OSError, xmlrpc.client.Error):
            master_proxy(self.uri, 1.0).deleteParam("/" + self.node_name, READY_PARAM)
        rospy.signal_shutdown(f"pfctl sim serve-hsr: {reason}")

    # -- callbacks (rospy threads: they only queue) --------------------------------------------

    def _on_twist(self, msg: Any) -> None:
        self._events.put(("twist", convert.twist_from_msg(msg)))

    def _on_head(self, msg: Any) -> None:
        target = convert.head_target_from_trajectory(msg)
        if target is None:
            import_rospy().logwarn_throttle(
                5.0, "pfctl sim serve-hsr: a head trajectory without a point for both head joints"
            )
            return
        self._events.put(("head", target))

    def _on_say(self, msg: Any) -> None:
        self._events.put(("say", str(msg.data)))

    def _on_goal(self, handle: Any) -> None:
        self._events.put(("goal", handle))

    def _on_cancel(self, handle: Any) -> None:
        self._events.put(("cancel", handle))

    def _on_viewpoint_stop(self, request: Any) -> Any:
        with self._lock:
            self._viewpoint_stops += 1
        return _msgs("std_srvs.srv").EmptyResponse()

    # -- the simulation thread -----------------------------------------------------------------

    def _apply_events(self) -> None:
        robot = self.robot
        while True:
            try:
                kind, value = self._events.get_nowait()
            except queue.Empty:
                return
            if kind == "twist":
                robot.command(value)
                self.stats.velocity_commands += 1
                self._update_goal("preempted by a velocity command")
            elif kind == "head":
                robot.point_head(value)
                self.stats.head_commands += 1
            elif kind == "goal":
                self._start_goal(value)
            elif kind == "cancel":
                self._cancel_goal(value)
            elif kind == "say":
                robot.say(value)
                self.stats.said += 1

    def _start_goal(self, handle: Any) -> None:
        self.stats.goals += 1
        if handle.get_goal_status().status != 0:  # PENDING: else cancelled before it was taken
            if handle.get_goal_status().status in CANCELLABLE:
                handle.set_canceled(text="cancelled before it started")
            return
        robot = self.robot
        pose = robot.localized_pose
        try:
            goal = self.messages.goal_in_map(handle.get_goal().target_pose, pose, robot.odometry)
        except ValueError as err:
            handle.set_rejected(text=str(err))
            return
        if self._goal is not None:
            if self._goal.get_goal_status().status in CANCELLABLE:
                self._goal.set_canceled(text="preempted by a new goal")
            self._goal = None
        handle.set_accepted()
        robot.navigate(goal)
        self._goal = handle
        self._update_goal("")

    def _cancel_goal(self, handle: Any) -> None:
        if self._goal is not None and handle == self._goal:
            self.robot.cancel()
            self._goal = None
        if handle.get_goal_status().status in CANCELLABLE:
            handle.set_canceled(text="cancelled")

    def _update_goal(self, preempted_by: str = "preempted") -> None:
        """Report the end of the running goal (SUCCEEDED, ABORTED, PREEMPTED) to its client."""
        if self._goal is None:
            return
        status = self.robot.nav_status()
        code = convert.nav_status_to_goal_status(status)
        if code in (0, 1):  # PENDING, ACTIVE
            return
        handle, self._goal = self._goal, None
        if code == 3:
            handle.set_succeeded(_msgs("move_base_msgs.msg").MoveBaseResult(), text="goal reached")
        elif code == 2:
            handle.set_canceled(text=preempted_by or "preempted")
        else:
            reason = self.robot.navigator.reason or f"navigation ended {status.value}"
            handle.set_aborted(text=reason)

    def _feedback(self, obs: Observation) -> None:
        if self._goal is None:
            return
        feedback = _msgs("move_base_msgs.msg").MoveBaseFeedback()
        feedback.base_position = self.messages.pose(obs)
        self._goal.publish_feedback(feedback)

    def _publish(self, obs: Observation, period_end: bool, twist: Twist2D = STOP) -> None:
        """Publish the instant ``obs`` (module docstring, steps 1-6)."""
        msgs, pubs = self.messages, self._pubs
        pubs["clock"].publish(msgs.clock(obs.stamp))
        pubs["tf"].publish(msgs.tf(obs))
        pubs["odom"].publish(msgs.odometry(obs, twist))
        pubs["joints"].publish(msgs.joint_states(obs))
        if "pose" in pubs:
            pubs["pose"].publish(msgs.pose(obs))
        for scan in obs.scans:
            pubs["laser"].publish(msgs.scan(scan))
            self.stats.scans += 1
        if obs.rgbd is not None:
            frame = obs.rgbd
            labels = None
            if "labels" in pubs and frame.mask is not None:
                labels = encode_labels(frame.mask, self._instances, self._parts)
            rgb, depth, info, label_msg = msgs.camera(frame, labels)
            pubs["rgb"].publish(rgb)
            pubs["depth"].publish(depth)
            pubs["info"].publish(info)
            if label_msg is not None:
                pubs["labels"].publish(label_msg)
            if "keypoints" in pubs and frame.mask is not None:
                people = self._keypoint_detector.detect(frame)
                pubs["keypoints"].publish(msgs.person_keypoints(frame, people))
            self.stats.frames += 1
        if period_end:
            if "truth_robot" in pubs:
                robot_msg, people, collisions = msgs.truth(self.robot.ground_truth())
                pubs["truth_robot"].publish(robot_msg)
                pubs["truth_people"].publish(people)
                pubs["truth_collisions"].publish(collisions)
            self._feedback(obs)

    def _observe(self) -> tuple[Observation, Twist2D]:
        """The simulator's newest observation and the odometry's velocity since the last one."""
        obs = self.robot.observe()
        odom = self.messages.odometry_pose(obs)
        twist = Twist2D()
        if self._last_odometry is not None:
            d = self._last_odometry.relative(odom)
            dt = self.robot.substep
            twist = Twist2D(d.x / dt, d.y / dt, d.theta / dt)
        self._last_odometry = odom
        return obs, twist

    def run(
        self,
        duration: float | None = None,
        stop: Callable[[], bool] | None = None,
        on_period: Callable[[float], None] | None = None,
        scene: Callable[[float], None] | None = None,
        on_ready: Callable[[], None] | None = None,
        on_release: Callable[[float], None] | None = None,
    ) -> BridgeStats:
        """Serve until ``duration`` simulated seconds (None: no end), ``stop()`` says so, or ROS
        shuts the node down. ``scene(t)`` (on this thread, before each control period) may move
        people by hand; ``on_ready()`` is called once :data:`READY_PARAM` is set and the first
        batch is out; ``on_release(held)`` when the first command ends the hold
        (``wait_for_command``); ``on_period(t)`` is told the time after each period."""
        rospy = import_rospy()
        robot, stats, msgs = self.robot, self.stats, self.messages
        proxy = master_proxy(self.uri)
        caller = "/" + self.node_name
        start = time.perf_counter()
        ref_wall, ref_ros = start, robot.time
        substep, held_steps = 0, 0
        holding = self.wait_for_command
        if scene is not None:
            scene(robot.time)
        first, _ = self._observe()
        proxy.setParam(caller, READY_PARAM, True)
        self._publish(first, period_end=True)
        if on_ready is not None:
            on_ready()
        laser_every = max(1, round(1.0 / (robot.substep * robot.config.laser.rate_hz)))
        try:
            while True:
                if stop is not None and stop():
                    stats.interrupted = True
                    break
                if rospy.is_shutdown():
                    stats.lost = "the ROS node was shut down (another node took its name?)"
                    break
                if duration is not None and robot.time >= duration - 1e-9:
                    break
                if holding and self._events.empty():
                    held_steps += 1
                    msgs.offset = CLOCK_OFFSET + held_steps * robot.substep
                    if self.rate > 0:
                        ref_wall, ref_ros = self._pace(ref_wall, ref_ros, msgs.offset, stop)
                    self._publish(
                        self._held(first, held_steps, laser_every),
                        period_end=(held_steps % robot.substeps == 0),
                    )
                    continue
                if holding:
                    holding = False
                    stats.held = msgs.offset - CLOCK_OFFSET
                    stats.held_wall = time.perf_counter() - start
                    proxy.setParam(caller, OFFSET_PARAM, msgs.offset)
                    if on_release is not None:
                        on_release(stats.held)
                if scene is not None and substep % robot.substeps == 0 and substep > 0:
                    scene(robot.time)
                self._apply_events()
                robot.advance_substep()
                substep += 1
                if self.rate > 0:
                    ref_wall, ref_ros = self._pace(ref_wall, ref_ros, msgs.offset, stop)
                period_end = substep % robot.substeps == 0
                obs, twist = self._observe()
                self._publish(obs, period_end, twist)
                self._update_goal()
                if period_end and on_period is not None:
                    on_period(robot.time)
        finally:
            stats.sim_time = robot.time
            stats.wall_time = time.perf_counter() - start - stats.held_wall
            stats.collisions = robot.collisions
            with self._lock:
                stats.viewpoint_stops = self._viewpoint_stops
        return stats

    def _held(self, first: Observation, k: int, laser_every: int) -> Observation:
        """The first instant again for the ``k``-th held sub-step: its scan every
        ``laser_every`` sub-steps, its camera frame at the camera's rate."""
        robot = self.robot
        t = k * robot.substep
        period = 1.0 / robot.config.camera.rate_hz
        frame_due = math.floor(t / period + 1e-9) > math.floor((t - robot.substep) / period + 1e-9)
        return replace(
            first,
            scans=first.scans if k % laser_every == 0 else (),
            rgbd=first.rgbd if frame_due else None,
        )

    def _pace(
        self,
        ref_wall: float,
        ref_ros: float,
        offset: float,
        stop: Callable[[], bool] | None,
    ) -> tuple[float, float]:
        """Wait until the wall clock reaches the ROS time about to be published (simulated time
        plus ``offset``) at ``rate``; a bridge more than :data:`MAX_LAG` behind starts its
        reference again (no burst to catch up)."""
        ros = self.robot.time + offset - CLOCK_OFFSET
        due = ref_wall + (ros - ref_ros) / self.rate
        while True:
            now = time.perf_counter()
            if now >= due:
                if now - due > MAX_LAG:
                    return now, ros
                return ref_wall, ref_ros
            if stop is not None and stop():
                return ref_wall, ref_ros
            time.sleep(min(due - now, 0.1))


__all__ = [
    "CLOCK_OFFSET",
    "DEPTH_ENCODINGS",
    "NODE_NAME",
    "OFFSET_PARAM",
    "READY_PARAM",
    "SEED_PARAM",
    "BridgeStats",
    "HsrMessages",
    "SimHsrBridge",
    "claim_sim_time",
    "master_proxy",
    "master_uri",
    "reach_master",
    "ros_time",
]
