"""The Toyota HSR over ROS 1: :class:`HsrRobot` implements the Robot port (``pfctl.core.robot``).

One ROS node (rospy) per process. :class:`HsrRobot` subscribes to the topics of its
:class:`~pfctl.backends.hsr.config.HsrConfig` (the mission's ``backend.hsr``), looks poses up in
tf, publishes the base and head commands, and drives ``move_base`` through actionlib:

* **observe** — every laser scan since the previous observation, in order, each posed by tf
  ``map → <scan frame>`` at its stamp (the ``laser`` subscriber queues them, at most
  :data:`SCAN_QUEUE`; when more arrive between two observations the oldest are dropped and
  counted in :attr:`HsrRobot.dropped_scans`); the newest complete RGB-D frame (RGB, depth,
  camera info and, when configured, the person labels or the person keypoints of one stamp,
  paired within :data:`CAMERA_SLOP`; the keypoints become the frame's ``people``,
  :mod:`pfctl.bags.person_keypoints`), the camera's optical frame from tf
  ``map → <image frame>`` at the image's stamp; the base pose (tf ``map → base`` or the
  ``pose`` topic); the head from the joint states; the odometry; the collision count from the
  simulator's truth (0 without it). When tf has no ``map → odom`` at a stamp yet, the odom
  frame is held fixed (``map → odom`` latest, ``odom → frame`` at the stamp), so a slowly
  published localisation does not hold data back; after :data:`TF_WAIT` without a transform at
  the stamp the latest one is used.
* **voice** — :meth:`HsrRobot.say` (:class:`~pfctl.core.robot.Speaker`) publishes the text on
  ``speech`` (``std_msgs/String``) for a text-to-speech node; the robot speaks
  (:attr:`HsrRobot.speaks`) only while some node subscribes to it.
* **time** — every stamp the follower sees is seconds of ROS time since the robot was opened (the
  episode clock): sim seconds when the master's ``/use_sim_time`` is true and ``/clock`` runs
  (``pfctl sim serve-hsr``), wall seconds on a real robot.
* **step** — waits until the next multiple of the control period ``tick_period`` on that
  clock (a tick that overran waits for the next slot, it does not pile up).
* **safety** — velocities are always clamped to ``limits``. A watchdog thread (wall clock,
  :data:`WATCHDOG_HZ`) publishes zero velocity as soon as the newest laser scan, pose or (sim
  time) ``/clock`` is older than ``stale_timeout`` (wall seconds since it was *received*: sim time
  freezes when the simulator dies; judged from the first command on, since a simulator may hold
  its clock until then), or the laser's publisher goes away, or the ROS master stops answering
  (pinged every :data:`MASTER_PING_PERIOD`); the robot is then *lost*: no velocity but zero is
  published again (every :data:`LOST_ZERO_PERIOD`), and the next :meth:`HsrRobot.observe` /
  :meth:`HsrRobot.step` raises :class:`~pfctl.core.robot.RobotLostError` (``command`` never
  raises). Zero velocity is also published on :meth:`HsrRobot.close`, on any exception inside
  ``step``/``observe`` (Ctrl-C too), and at interpreter exit. Base and head commands, goals
  and log lines go out on one thread of their own (:mod:`~pfctl.backends.hsr.call_thread`),
  so a Ctrl-C never lands inside rospy's publish (where it would be lost, or leave a lock held).

Errors at start are :class:`RobotConnectionError` (a :class:`~pfctl.errors.UserError`: one line
naming the master or exactly what is missing); data the robot sends that cannot be read is
:class:`RobotDataError`; ROS 1 not installed is
:class:`~pfctl.backends.hsr.ros_import.RosUnavailableError`.
"""

from __future__ import annotations

import atexit
import contextlib
import math
import sys
import threading
import time
import warnings
from collections import deque
from dataclasses import replace
from typing import Any

from pfctl.backends.hsr import convert
from pfctl.backends.hsr.call_thread import CallThread
from pfctl.backends.hsr.config import HsrConfig
from pfctl.backends.hsr.master import MASTER_ERRORS, MasterError, check_master, master_proxy
from pfctl.backends.hsr.person_labels import label_detector
from pfctl.backends.hsr.ros_import import import_ros_module, import_rospy
from pfctl.bags.person_keypoints import people_from_cloud
from pfctl.bags.replay import image_labels
from pfctl.core.perception.vision import GivenPersonDetector, MaskPersonDetector
from pfctl.core.robot import (
    STOP,
    GivenPerson,
    GroundTruth,
    HeadState,
    HeadTarget,
    LaserScan,
    NavStatus,
    Observation,
    PersonTruth,
    Pose2D,
    RgbdFrame,
    RobotLostError,
    Twist2D,
)
from pfctl.core.tf_buffer import quaternion_matrix
from pfctl.errors import UserError
from pfctl.interrupts import Interrupted

MASTER_CHECK_TIMEOUT = 2.0
"""Wall seconds the ROS master may take to answer at start."""
CAMERA_SLOP = 0.02
"""Seconds by which the stamps of one RGB-D frame's images may differ (serve-hsr: 0)."""
TF_WAIT = 0.25
"""Wall seconds a scan or frame may wait for its transform at its stamp; then the latest is used."""
WATCHDOG_HZ = 50.0
"""How often (wall) the watchdog checks the age of the laser and the pose."""
MASTER_PING_PERIOD = 1.0
"""Wall seconds between two pings of the ROS master."""
LOST_ZERO_PERIOD = 0.1
"""While lost, zero velocity is published again this often (wall seconds)."""
CLOCK_BACKWARDS = 1.0
"""A ROS clock that jumps back by more than this (s) means the simulator restarted: lost."""
_QUEUE = 8
SCAN_QUEUE = 40
"""Scans kept between two observations (a second of the HSR's 40 Hz Hokuyo); older are dropped."""


class RobotConnectionError(UserError):
    """The robot could not be reached at start: the master is down, or a topic, tf frame or the
    clock did not arrive within the connect timeout (the message names each)."""


class RobotDataError(UserError):
    """The robot sends data that cannot be read (an unsupported encoding, images of different
    sizes); the message names the topic."""


# ------------------------------------------------------------------------------------- helpers


def _connect_master(uri: str) -> None:
    """Raise :class:`RobotConnectionError` unless the ROS master at ``uri`` answers within
    :data:`MASTER_CHECK_TIMEOUT` seconds (rospy would block forever in ``init_node``)."""
    try:
        check_master(uri, "/pfctl_check", MASTER_CHECK_TIMEOUT)
    except Interrupted as err:
        err.during = f"while waiting for the ROS master at {uri}"
        raise
    except MasterError as err:
        if err.error is None:
            raise RobotConnectionError(f"the ROS master at {uri} answered: {err.answer}") from None
        raise RobotConnectionError(
            f"cannot reach the ROS master at {uri} ({err.error}): start roscore, or point "
            "ROS_MASTER_URI at the robot's master"
        ) from None


def people_from_markers(msg: Any) -> tuple[PersonTruth, ...]:
    """The people of a ``visualization_msgs/MarkerArray`` in the simulator's truth encoding
    (:func:`pfctl.bags.recording.person_marker`: ``ns`` = name, pose = position and
    heading, ``text`` = ``"target speed=0.800"``); markers that are not ADD are skipped.

    The decoder is the episode recorder's (imported here, not at module level: a real robot
    publishes no truth, and the bag writer beside the decoder loads slowly)."""
    from pfctl.bags.recording import person_from_marker

    return tuple(
        person_from_marker(m.ns, convert.pose2d_from_pose(m.pose), m.text)
        for m in msg.markers
        if int(m.action) == 0
    )


def frame_people(msg: Any, topic: str, shape: tuple[int, int]) -> tuple[GivenPerson, ...]:
    """The people of a person-keypoints message (``sensor_msgs/PointCloud``,
    :mod:`pfctl.bags.person_keypoints`) for an image of ``shape``;
    :class:`RobotDataError` naming ``topic`` and what was expected when it is malformed."""
    try:
        return people_from_cloud(msg, shape)
    except ValueError as err:
        raise RobotDataError(f"{topic}: {err}") from None


def _ns(stamp: Any) -> int:
    return int(stamp.secs) * 1_000_000_000 + int(stamp.nsecs)


def _frame(frame_id: str) -> str:
    """tf2 frame ids never start with '/' (tf1 style ids are accepted)."""
    return frame_id.lstrip("/")


# ------------------------------------------------------------------------------------- the node

_NODE_LOCK = threading.Lock()


def _ensure_node(rospy: Any, node_name: str) -> str:
    """Initialise this process's ROS node once (rospy allows one per process); a later
    :class:`HsrRobot` in the same process uses the same node."""
    with _NODE_LOCK:
        if rospy.core.is_shutdown():
            raise RuntimeError(
                "rospy was shut down in this process; an HsrRobot needs a new process"
            )
        if not rospy.core.is_initialized():
            rospy.init_node(
                node_name, anonymous=True, disable_signals=True, argv=list(sys.argv[:1])
            )
        return str(rospy.get_name())


class HsrRobot:
    """The Toyota HSR (or ``pfctl sim serve-hsr``) over ROS 1; implements the Robot port.

    ``HsrRobot(config)`` connects: it checks the master, starts the node, subscribes, and waits
    (wall clock, ``config.connect_timeout`` unless ``connect_timeout`` is given) for the
    first laser scan and its tf, the pose, the head's joint states, a subscriber of the base
    command and, under sim time, ``/clock``; then, when their publishers exist, for the
    ``move_base`` action server and the simulator's truth. Use it as a context manager, or call
    :meth:`close`.
    """

    def __init__(
        self, config: HsrConfig, *, node_name: str = "pfctl", connect_timeout: float | None = None
    ) -> None:
        self.config = config
        self.period = config.tick_period
        """The control period (s of ROS time)."""
        timeout = self.config.connect_timeout if connect_timeout is None else connect_timeout
        if not (math.isfinite(timeout) and timeout > 0):
            raise ValueError(f"connect_timeout must be a positive number, got {timeout}")
        self._closed = False
        self._opened = False
        self._say_pub: Any = None
        """The ``speech`` publisher (None: no voice, or not set up yet)."""
        self._lock = threading.Lock()  # data written by the callbacks
        self._cmd_lock = threading.Lock()  # the lost flag and the base command, in order
        self._tick = threading.Condition()  # woken by /clock and by losing the robot
        self._stop = threading.Event()
        self._threads: list[threading.Thread] = []
        self._handles: list[Any] = []  # subscribers and publishers to unregister
        self._lost: str | None = None
        self._armed_at: float | None = None
        self._sent = STOP
        self._last_zero = 0.0

        self._rospy = rospy = import_rospy()
        self._tf2 = import_ros_module("tf2_ros")
        actionlib = import_ros_module("actionlib")
        msgs = {
            name: import_ros_module(name)
            for name in (
                "sensor_msgs.msg",
                "geometry_msgs.msg",
                "nav_msgs.msg",
                "trajectory_msgs.msg",
                "rosgraph_msgs.msg",
                "move_base_msgs.msg",
                "std_msgs.msg",
                "std_srvs.srv",
                "visualization_msgs.msg",
            )
        }
        self._msgs = msgs
        rosgraph = import_ros_module("rosgraph")
        self.master_uri = str(rosgraph.get_master_uri())
        """The ROS master this robot talks to (``ROS_MASTER_URI``)."""
        _connect_master(self.master_uri)
        self.node = _ensure_node(rospy, node_name)
        """This process's node name."""
        self.use_sim_time = not rospy.rostime.is_wallclock()
        """True when the master's ``/use_sim_time`` was set at start (ROS time from ``/clock``)."""

        # receipt state (wall = time.monotonic() when the message arrived)
        self._scans: deque[tuple[Any, float]] = deque(maxlen=SCAN_QUEUE)
        self.dropped_scans = 0
        """Scans dropped unobserved because :data:`SCAN_QUEUE` were already waiting."""
        self._laser_wall: float | None = None
        self._laser_frame: str | None = None
        self._laser_connected = False
        self._pose_msg: Any = None
        self._pose_wall: float | None = None
        self._pose_stamp = -1
        self._head: HeadState | None = None
        self._odometry: Pose2D | None = None
        self._clock_wall: float | None = None
        self._camera: dict[str, dict[int, Any]] = {}
        self._frames: deque[tuple[tuple[Any, ...], float]] = deque(maxlen=3)
        self._truth_robot: Any = None
        self._truth_markers: Any = None
        self._truth_people: tuple[Any, tuple[PersonTruth, ...]] = (None, ())
        self._truth_collisions: int | None = None
        self._warned: set[str] = set()
        self._t0_ns = 0
        self._last_ns = 0
        self._clock_started = False
        self._last_pose = Pose2D(0.0, 0.0, 0.0)

        # publishing, goals and logging run on this thread: a Ctrl-C never splits them
        self._calls = CallThread("pfctl-hsr-calls")
        try:
            self._setup(actionlib)
            self._connect(timeout)
        except BaseException as err:
            if isinstance(err, Interrupted) and err.during is None:
                err.during = f"while connecting to the HSR (ROS_MASTER_URI={self.master_uri})"
            self._release()
            raise
        self._opened = True
        atexit.register(self.close)
        for target in (self._watch, self._ping_master):
            thread = threading.Thread(target=target, name=f"pfctl-hsr{target.__name__}")
            thread.daemon = True
            thread.start()
            self._threads.append(thread)

    # -- setting up ---------------------------------------------------------------------------

    def _sub(self, topic: str, cls: Any, callback: Any, **kw: Any) -> Any:
        sub = self._rospy.Subscriber(topic, cls, callback, **kw)
        self._handles.append(sub)
        return sub

    def _setup(self, actionlib: Any) -> None:
        rospy, cfg, m = self._rospy, self.config, self._msgs
        sensor, geometry = m["sensor_msgs.msg"], m["geometry_msgs.msg"]
        self._buffer = self._tf2.Buffer(cache_time=rospy.Duration(10.0), debug=False)
        self._listener = self._tf2.TransformListener(self._buffer)
        self._laser_sub = self._sub(
            cfg.laser, sensor.LaserScan, self._on_scan, queue_size=SCAN_QUEUE
        )
        if cfg.pose is not None:
            self._sub(cfg.pose, geometry.PoseStamped, self._on_pose, queue_size=1)
        self._sub(cfg.joint_states, sensor.JointState, self._on_joints, queue_size=_QUEUE)
        self._sub(cfg.odom, m["nav_msgs.msg"].Odometry, self._on_odom, queue_size=1)
        camera = {"rgb": cfg.rgb, "depth": cfg.depth, "info": cfg.camera_info}
        if cfg.person_labels is not None:
            camera["labels"] = cfg.person_labels
        if cfg.person_keypoints is not None:
            camera["keypoints"] = cfg.person_keypoints
        classes = {"info": sensor.CameraInfo, "keypoints": sensor.PointCloud}
        for key, topic in camera.items():
            cls = classes.get(key, sensor.Image)
            self._camera[key] = {}
            self._sub(
                topic,
                cls,
                self._on_camera,
                callback_args=key,
                queue_size=2,
                buff_size=1 << 24,
            )
        if self.use_sim_time:
            self._follow_clock()
        if cfg.ground_truth is not None:
            ns = cfg.ground_truth.rstrip("/")
            self._sub(f"{ns}/robot", geometry.PoseStamped, self._on_truth_robot, queue_size=1)
            people = m["visualization_msgs.msg"].MarkerArray
            self._sub(f"{ns}/people", people, self._on_truth_people, queue_size=1)
            self._sub(
                f"{ns}/collisions",
                m["std_msgs.msg"].UInt32,
                self._on_truth_collisions,
                queue_size=1,
            )
        # The base command is published synchronously (no queue_size: written to the socket by
        # the call thread while the caller waits), so the zero sent by close() is delivered
        # before we unregister.
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", SyntaxWarning)
            self._cmd_pub = rospy.Publisher(cfg.command_velocity, geometry.Twist)
        self._handles.append(self._cmd_pub)
        self._head_pub = rospy.Publisher(
            cfg.head_command, m["trajectory_msgs.msg"].JointTrajectory, queue_size=1
        )
        self._handles.append(self._head_pub)
        self._say_pub = (
            None
            if cfg.speech is None
            else rospy.Publisher(cfg.speech, m["std_msgs.msg"].String, queue_size=10)
        )
        if self._say_pub is not None:
            self._handles.append(self._say_pub)
        self._nav = actionlib.SimpleActionClient(
            cfg.move_base, m["move_base_msgs.msg"].MoveBaseAction
        )
        self._nav_ready = False
        self._goal_sent = False
        self._nav_local: NavStatus | None = None

    def _follow_clock(self) -> None:
        """Note when ``/clock`` arrives (sharing rospy's own subscription: no queue_size)."""
        self._sub("/clock", self._msgs["rosgraph_msgs.msg"].Clock, self._on_clock)

    def _switch_to_sim_time(self) -> bool:
        """The master's ``/use_sim_time`` was set after this node started (the simulator came
        up after pfctl): let rospy follow ``/clock`` from now on, as ``init_node`` would have.
        True if it switched."""
        try:
            code, _, value = master_proxy(self.master_uri).getParam(self.node, "/use_sim_time")
        except MASTER_ERRORS:
            return False
        if code != 1 or value is not True:
            return False
        import_ros_module("rospy.impl.simtime").init_simtime()
        if self._rospy.rostime.is_wallclock():
            return False
        self.use_sim_time = True
        listener = self._listener  # it would take the jump from wall to sim time for a loop
        with listener.last_update_lock:  # of a bag and clear the buffer (the static laser too)
            listener.last_update = self._rospy.Time(0)
        self._follow_clock()
        self._log("loginfo", "pfctl: /use_sim_time was set: following /clock")
        return True

    # -- callbacks (rospy's threads) ------------------------------------------------------------

    def _on_scan(self, msg: Any) -> None:
        now = time.monotonic()
        with self._lock:
            if len(self._scans) == self._scans.maxlen:
                self.dropped_scans += 1
            self._scans.append((msg, now))
            self._laser_wall = now
            self._laser_frame = _frame(msg.header.frame_id)

    def _on_pose(self, msg: Any) -> None:
        with self._lock:
            self._pose_msg, self._pose_wall = msg, time.monotonic()

    def _on_joints(self, msg: Any) -> None:
        head = convert.head_state_from_joint_state(msg)
        if head is not None:
            self._head = head

    def _on_odom(self, msg: Any) -> None:
        self._odometry = convert.pose2d_from_odometry(msg)

    def _on_clock(self, msg: Any) -> None:
        self._clock_wall = time.monotonic()
        with self._tick:
            self._tick.notify_all()

    def _on_truth_robot(self, msg: Any) -> None:
        self._truth_robot = msg

    def _on_truth_people(self, msg: Any) -> None:
        self._truth_markers = msg  # decoded by ground_truth(), in the caller's thread

    def _on_truth_collisions(self, msg: Any) -> None:
        self._truth_collisions = int(msg.data)

    def _on_camera(self, msg: Any, key: str) -> None:
        """Keep the newest few messages of each camera topic by stamp; a stamp that every topic
        has (within :data:`CAMERA_SLOP`) makes a frame, and older partial ones are dropped."""
        stamp = _ns(msg.header.stamp)
        slop = int(CAMERA_SLOP * 1e9)
        with self._lock:
            mine = self._camera[key]
            mine[stamp] = msg
            while len(mine) > _QUEUE:
                del mine[min(mine)]
            found: dict[str, int] = {}
            for other, pending in self._camera.items():
                near = [s for s in pending if abs(s - stamp) <= slop]
                if not near:
                    return
                found[other] = min(near, key=lambda s: abs(s - stamp))
            msgs = {k: self._camera[k][s] for k, s in found.items()}
            for k, s in found.items():
                pending = self._camera[k]
                for old in [t for t in pending if t <= s]:
                    del pending[old]
            self._frames.append(
                (
                    (
                        msgs["rgb"],
                        msgs["depth"],
                        msgs["info"],
                        msgs.get("labels"),
                        msgs.get("keypoints"),
                    ),
                    time.monotonic(),
                )
            )

    # -- connecting -----------------------------------------------------------------------------

    def _published(self) -> set[str]:
        """The topics some node publishes (empty if the master does not answer)."""
        try:
            code, _, topics = master_proxy(self.master_uri).getPublishedTopics(self.node, "")
        except MASTER_ERRORS:
            return set()
        return {t for t, _ in topics} if code == 1 else set()

    def _tf_error(self, frame: str) -> str | None:
        """Why ``map → frame`` cannot be looked up now (None: it can)."""
        ok, error = self._buffer.can_transform_core(
            self.config.map_frame, frame, self._rospy.Time(0)
        )
        return None if ok else str(error).strip().rstrip(".")

    def _missing(self, published: set[str] | None) -> list[str]:
        """What the robot has not sent yet that the follower needs; ``published``: the topics
        the master lists (None: it has not answered yet, so no topic is said to be unpublished)."""
        cfg = self.config
        missing = []

        def no(what: str, topic: str) -> str:
            hint = "" if published is None or topic in published else " (no node publishes it)"
            return f"no {what} on {topic}{hint}"

        if self.use_sim_time and self._clock_wall is None:
            missing.append(no("clock although /use_sim_time is true", "/clock"))
        if self._laser_wall is None:
            missing.append(no("laser scan", cfg.laser))
        elif self._laser_frame is not None and (err := self._tf_error(self._laser_frame)):
            missing.append(f"no tf {cfg.map_frame} → {self._laser_frame} (laser frame): {err}")
        if cfg.pose is not None:
            if self._pose_msg is None:
                missing.append(no("pose", cfg.pose))
        elif err := self._tf_error(cfg.base_frame):
            missing.append(f"no tf {cfg.map_frame} → {cfg.base_frame} (pose): {err}")
        if self._head is None:
            missing.append(
                no("joint states with head_pan_joint and head_tilt_joint", cfg.joint_states)
            )
        if self._cmd_pub.get_num_connections() == 0:
            missing.append(f"nobody subscribes to {cfg.command_velocity} (the base)")
        return missing

    def _optional_pending(self, published: set[str]) -> list[str]:
        """What is published but not here yet: the move_base server, the simulator's truth."""
        cfg, pending = self.config, []
        if not self._nav_ready:
            self._nav_ready = self._server_ready()
            if not self._nav_ready and f"{cfg.move_base}/status" in published:
                pending.append(f"the move_base action server {cfg.move_base}")
        if cfg.ground_truth is not None:
            ns = cfg.ground_truth.rstrip("/")
            if self._truth_robot is None and f"{ns}/robot" in published:
                pending.append(f"the truth on {ns}/robot")
            if self._truth_collisions is None and f"{ns}/collisions" in published:
                pending.append(f"the truth on {ns}/collisions")
        return pending

    def _connect(self, timeout: float) -> None:
        cfg = self.config
        deadline = time.monotonic() + timeout
        published: set[str] = set()
        next_query = 0.0
        # interrupted before the master's first answer: what is missing all the same
        missing = [*self._missing(None), "the list of topics from the master"]
        pending: list[str] = []
        looked_again = False
        try:
            while True:
                now = time.monotonic()
                if now >= next_query:
                    published, next_query = self._published(), now + 0.5
                    if not self.use_sim_time:
                        self._switch_to_sim_time()
                missing = self._missing(published)
                if not missing and not looked_again:
                    # the data may have come before the last query saw the optional topics'
                    # publishers (a simulator started after us): ask the master once more
                    published, next_query, looked_again = self._published(), now + 0.5, True
                pending = [] if missing else self._optional_pending(published)
                if not missing and not pending:
                    if not self.use_sim_time and self._switch_to_sim_time():
                        continue  # the simulator came up meanwhile: wait for its clock too
                    break
                if now >= deadline:
                    if missing:
                        raise RobotConnectionError(
                            f"{'; '.join(missing)} after {timeout:g} s "
                            f"(ROS_MASTER_URI={self.master_uri})"
                        )
                    self._log("logwarn", "pfctl: going on without %s", ", ".join(pending))
                    break
                time.sleep(0.02)
        except Interrupted as err:  # Ctrl-C or SIGTERM while waiting: say what for
            err.during = (
                f"while waiting for the HSR: {'; '.join(missing or pending)} "
                f"(ROS_MASTER_URI={self.master_uri})"
            )
            raise
        if not self._nav_ready:
            self._log(
                "logwarn",
                "pfctl: no move_base action server on %s: navigation goals will abort",
                cfg.move_base,
            )
        now_ns = self._now_ns()
        self._t0_ns = self._last_ns = now_ns
        self._clock_started = False
        self._laser_connected = self._live_publishers() > 0
        with self._lock:  # the episode starts with the newest scan, not those of the wait
            while len(self._scans) > 1:
                self._scans.popleft()
        self._poll_pose(time.monotonic())
        self._last_pose = self._pose() if cfg.pose is None else self._last_pose
        self._stop_viewpoint()

    def _stop_viewpoint(self) -> None:
        """Call ``viewpoint_stop`` (std_srvs/Empty) once, if the service exists, so that HSR's
        viewpoint controller does not fight our head commands."""
        name = self.config.viewpoint_stop
        if name is None:
            return
        try:
            code, _, _ = master_proxy(self.master_uri).lookupService(self.node, name)
        except MASTER_ERRORS:
            return
        if code != 1:
            return
        proxy = self._rospy.ServiceProxy(name, self._msgs["std_srvs.srv"].Empty)
        errors: list[BaseException] = []

        def call() -> None:
            try:
                proxy()
            except Exception as err:  # a service that fails must not stop the robot
                errors.append(err)

        thread = threading.Thread(target=call, name="pfctl-hsr-viewpoint", daemon=True)
        thread.start()
        thread.join(2.0)
        if thread.is_alive() or errors:
            why = errors[0] if errors else "no answer in 2 s"
            self._log("logwarn", "pfctl: %s failed: %s", name, why)

    # -- time -----------------------------------------------------------------------------------

    def _now_ns(self) -> int:
        return int(self._rospy.get_rostime().to_nsec())

    @property
    def time(self) -> float:
        """Seconds of ROS time since the episode started: 0 until the caller first observes,
        steps or commands the robot (not when it connected: a caller may take seconds to get
        ready — face models, maps — in between), then the episode clock."""
        if not self._clock_started:
            return 0.0
        return (self._now_ns() - self._t0_ns) * 1e-9

    def _start_clock(self) -> None:
        """Start the episode clock now, the first time the robot is used."""
        if not self._clock_started:
            self._clock_started = True
            self._t0_ns = self._last_ns = max(self._last_ns, self._now_ns())

    @property
    def clock_origin(self) -> float:
        """The ROS time (s) of the episode clock's 0: a stamp in the robot's messages (and in a
        bag recorded from them) is ``clock_origin +`` the episode time the follower logs."""
        return self._t0_ns * 1e-9

    def _episode(self, stamp: Any) -> float:
        """A ROS stamp as episode seconds."""
        return (_ns(stamp) - self._t0_ns) * 1e-9

    # -- context manager ------------------------------------------------------------------------

    def __enter__(self) -> HsrRobot:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # -- safety ---------------------------------------------------------------------------------

    @property
    def lost(self) -> str | None:
        """Why the robot was lost (the :class:`RobotLostError` message), or None."""
        return self._lost

    def _live_publishers(self) -> int:
        """The laser's publishers we have a working connection to (a killed publisher's
        connection may linger while rospy tries to reconnect, without a socket)."""
        impl = getattr(self._laser_sub, "impl", None)
        connections = getattr(impl, "connections", None)
        if connections is None:
            return int(self._laser_sub.get_num_connections())
        return sum(
            1
            for c in list(connections)
            if not getattr(c, "done", False) and getattr(c, "socket", True) is not None
        )

    def _poll_pose(self, now: float) -> None:
        """With the pose from tf: note when the newest ``odom → base`` (or ``map → base``)
        transform advanced."""
        if self.config.pose is not None:
            return
        cfg, tf2 = self.config, self._tf2
        for parent in (cfg.odom_frame, cfg.map_frame):
            try:
                latest = _ns(self._buffer.get_latest_common_time(parent, cfg.base_frame))
            except tf2.TransformException:
                continue
            if latest != self._pose_stamp:
                self._pose_stamp, self._pose_wall = latest, now
            return

    def _arm(self) -> None:
        """Start judging the data's age: from the first command on (a simulator may hold its
        clock until the robot is first commanded; before that nothing moves by our command)."""
        if self._armed_at is None:
            self._armed_at = time.monotonic()

    def _age(self, received: float | None, now: float) -> float:
        """Wall seconds since ``received``, counted from the first command at the earliest."""
        if received is None or self._armed_at is None:
            return 0.0
        return now - max(received, self._armed_at)

    def _stale_reason(self) -> str | None:
        """Why the data are too old to drive on (None: fresh)."""
        cfg = self.config
        now = time.monotonic()
        limit = cfg.stale_timeout
        if self._live_publishers() > 0:
            self._laser_connected = True
        elif self._laser_connected:
            return f"the publisher of {cfg.laser} went away"
        if self._rospy.core.is_shutdown():
            return "the ROS node was shut down"
        if (age := self._age(self._laser_wall, now)) > limit:
            return f"no laser scan on {cfg.laser} for {age:.1f} s"
        self._poll_pose(now)
        if (age := self._age(self._pose_wall, now)) > limit:
            where = cfg.pose if cfg.pose is not None else f"tf {cfg.map_frame} → {cfg.base_frame}"
            return f"no pose ({where}) for {age:.1f} s"
        if self.use_sim_time and (age := self._age(self._clock_wall, now)) > limit:
            return f"no /clock for {age:.1f} s"
        return None

    def _publish(self, twist: Twist2D) -> None:
        """Publish a base command (the caller holds ``_cmd_lock``) on the call thread."""
        self._calls.call(self._publish_now, twist)

    def _publish_now(self, twist: Twist2D) -> None:
        try:
            self._cmd_pub.publish(convert.twist_to_msg(twist))
        except Exception as err:  # a closed topic during shutdown: nothing left to command
            self._warn_once("publish", f"pfctl: could not publish the base command: {err}")
            return
        self._sent = twist
        if twist == STOP:
            self._last_zero = time.monotonic()

    def _lose(self, reason: str) -> None:
        """Stop the base and remember why the robot is lost (the first reason wins)."""
        with self._cmd_lock:
            first = self._lost is None
            if first:
                self._lost = reason
            self._publish(STOP)
        if first:
            self._log("logerr", "pfctl: %s; the base was stopped", reason)
            self._cancel_goal()
            with self._tick:
                self._tick.notify_all()

    def _check(self) -> None:
        """Raise :class:`RobotLostError` if the robot is lost (checking the data's age now)."""
        if self._lost is None and (reason := self._stale_reason()):
            self._lose(f"lost the robot: {reason}")
        if self._lost is not None:
            raise RobotLostError(self._lost)

    def _watch(self) -> None:
        """The watchdog thread (wall clock)."""
        while not self._stop.wait(1.0 / WATCHDOG_HZ):
            try:
                if self._lost is None:
                    if reason := self._stale_reason():
                        self._lose(f"lost the robot: {reason}")
                elif time.monotonic() - self._last_zero >= LOST_ZERO_PERIOD:
                    with self._cmd_lock:
                        if not self._stop.is_set():
                            self._publish(STOP)
            except Exception as err:  # keep watching whatever one check did
                self._warn_once("watch", f"pfctl: watchdog: {err!r}")

    def _ping_master(self) -> None:
        """Ping the master every :data:`MASTER_PING_PERIOD`; a refused connection, or two
        failed pings in a row, lose the robot."""
        failures = 0
        while not self._stop.wait(MASTER_PING_PERIOD):
            try:
                code, _, _ = master_proxy(self.master_uri).getPid(self.node)
                failures = 0 if code == 1 else failures + 1
                error: object = f"code {code}"
            except ConnectionRefusedError as err:
                failures, error = 2, err
            except MASTER_ERRORS as err:
                failures, error = failures + 1, err
            if failures >= 2 and not self._stop.is_set():
                self._lose(f"lost the ROS master at {self.master_uri} ({error})")
                return

    def _warn_once(self, key: str, message: str) -> None:
        if key not in self._warned:
            self._warned.add(key)
            self._log("logwarn", message)

    def _log(self, level: str, message: str, *args: Any) -> None:
        """rospy's ``level`` (``logwarn``, ...) on the call thread (logging takes locks too)."""
        self._calls.call(getattr(self._rospy, level), message, *args)

    # -- the Robot port -------------------------------------------------------------------------

    def clamp(self, t: Twist2D) -> Twist2D:
        """The command within the mission's linear (vx, vy norm) and angular limits."""
        rc = self.config.limits
        vx, vy, wz = (v if math.isfinite(v) else 0.0 for v in (t.vx, t.vy, t.wz))
        n = math.hypot(vx, vy)
        k = min(1.0, rc.max_linear_speed / n) if n > 0 else 1.0
        return Twist2D(vx * k, vy * k, max(-rc.max_angular_speed, min(rc.max_angular_speed, wz)))

    @property
    def commanded(self) -> Twist2D:
        """The base velocity last published (after clamping; zero when stale or lost)."""
        return self._sent

    def command(self, base: Twist2D, head: HeadTarget | None = None) -> None:
        """Publish the clamped base velocity (zero while the data are stale or the robot is
        lost); a direct command cancels an active navigation goal (PREEMPTED)."""
        self._start_clock()
        if self._closed:
            return
        self._arm()
        twist = self.clamp(base)
        if self._goal_active():
            self._cancel_goal()
        if self._lost is None and (reason := self._stale_reason()):
            self._lose(f"lost the robot: {reason}")
        with self._cmd_lock:
            self._publish(STOP if self._lost is not None else twist)
        if head is not None:
            self.point_head(head)

    def point_head(self, head: HeadTarget) -> None:
        """Send the head toward ``head`` (clamped to the joint limits) in the time the head
        needs at ``limits.head_max_speed``, at least one control period."""
        self._start_clock()
        if self._closed or self._lost is not None:
            return
        self._arm()
        rc = self.config.limits
        pan = min(max(head.pan, rc.head_pan_limits[0]), rc.head_pan_limits[1])
        tilt = min(max(head.tilt, rc.head_tilt_limits[0]), rc.head_tilt_limits[1])
        now = self._head or HeadState()
        move = max(abs(pan - now.pan), abs(tilt - now.tilt))
        duration = max(self.period, move / rc.head_max_speed)
        msg = convert.head_target_to_trajectory(HeadTarget(pan, tilt), duration)
        self._calls.call(self._head_pub.publish, msg)

    # -- the voice (Speaker) --------------------------------------------------------------------

    @property
    def speaks(self) -> bool:
        """Some node listens to ``speech`` (a text-to-speech node): what is said is heard."""
        pub = self._say_pub
        return pub is not None and not self._closed and pub.get_num_connections() > 0

    def say(self, text: str) -> None:
        """Publish ``text`` on ``speech`` (std_msgs/String) for the text-to-speech node."""
        if self._say_pub is None or self._closed:
            return
        msg = self._msgs["std_msgs.msg"].String(data=text)
        self._calls.call(self._say_pub.publish, msg)

    def _server_ready(self) -> bool:
        """The move_base action server is connected (actionlib's own test, without waiting)."""
        ac = self._nav.action_client
        status = ac.last_status_msg
        if status is None:
            return False
        server = status._connection_header["callerid"]
        return (
            ac.pub_goal.impl.has_connection(server)
            and ac.pub_cancel.impl.has_connection(server)
            and any(c.callerid_pub == server for c in ac.result_sub.impl.connections)
            and any(c.callerid_pub == server for c in ac.feedback_sub.impl.connections)
        )

    def navigate(self, goal: Pose2D) -> None:
        """Send ``goal`` (map frame) to move_base; ABORTED at once (with a warning) when there
        is no action server or the robot is lost."""
        self._start_clock()
        if self._closed or self._lost is not None:
            self._nav_local = NavStatus.ABORTED
            return
        self._arm()
        if not self._nav_ready:
            self._nav_ready = self._server_ready()
        if not self._nav_ready:
            self._warn_once(
                "nav",
                f"pfctl: no move_base action server on {self.config.move_base}: goal aborted",
            )
            self._nav_local = NavStatus.ABORTED
            return
        mb = self._msgs["move_base_msgs.msg"]
        target = self._msgs["geometry_msgs.msg"].PoseStamped()
        target.header.frame_id = self.config.map_frame
        target.header.stamp = self._rospy.get_rostime()
        target.pose = convert.pose2d_to_pose(goal)
        self._calls.call(self._nav.send_goal, mb.MoveBaseGoal(target_pose=target))
        self._goal_sent, self._nav_local = True, None

    def nav_status(self) -> NavStatus:
        """IDLE before the first goal; then the goal's actionlib state."""
        if self._nav_local is not None:
            return self._nav_local
        if not self._goal_sent:
            return NavStatus.IDLE
        return convert.nav_status_from_goal_status(self._nav.get_state())

    def _goal_active(self) -> bool:
        return self.nav_status() in (NavStatus.PENDING, NavStatus.ACTIVE)

    def _cancel_goal(self) -> None:
        """Cancel the goal if it is still pending or active; it reads PREEMPTED from now on."""
        if self._goal_active():
            with contextlib.suppress(Exception):
                self._calls.call(self._nav.cancel_goal)
            self._nav_local = NavStatus.PREEMPTED

    def cancel(self) -> None:
        """Cancel the navigation goal (if any) and stop the base."""
        self.command(STOP)

    def step(self) -> None:
        """Wait until the next multiple of the control period on the episode clock (sim time
        under ``/clock``). Raises :class:`RobotLostError` when the robot is lost meanwhile, or
        when ``/clock`` stops for ``stale_timeout`` wall seconds."""
        self._start_clock()
        self._check_open()
        self._arm()
        try:
            target = (math.floor(self.time / self.period + 1e-6) + 1) * self.period
            while True:
                self._check()
                now_ns = self._now_ns()
                if now_ns < self._last_ns - int(CLOCK_BACKWARDS * 1e9):
                    self._lose(
                        f"lost the robot: the ROS clock jumped back by "
                        f"{(self._last_ns - now_ns) * 1e-9:.1f} s (the simulator restarted?)"
                    )
                    continue
                self._last_ns = max(self._last_ns, now_ns)
                now = (now_ns - self._t0_ns) * 1e-9
                if now >= target - 1e-9:
                    return
                wait = 0.02 if self.use_sim_time else min(target - now, 0.02)
                with self._tick:
                    self._tick.wait(wait)
        except RobotLostError:
            raise
        except BaseException:
            self._stop_base()
            raise

    def _stop_base(self) -> None:
        with contextlib.suppress(Exception), self._cmd_lock:
            self._publish(STOP)

    def _check_open(self) -> None:
        if self._closed:
            raise RuntimeError("the HSR robot is closed")

    def observe(self) -> Observation:
        """Every scan since the previous observation (in order), the newest frame since then (or
        None), the pose, head, odometry and collisions; stamps on the episode clock."""
        self._check_open()
        self._check()
        self._start_clock()
        try:
            scans = self._take_scans()
            frame = self._take_frame()
        except BaseException:
            self._stop_base()
            raise
        truth_collisions = self._truth_collisions
        return Observation(
            stamp=self.time,
            pose=self._pose(),
            head=self._head or HeadState(),
            scans=scans,
            rgbd=frame,
            collisions=truth_collisions if truth_collisions is not None else 0,
            odometry=self._odometry,
        )

    # -- poses ----------------------------------------------------------------------------------

    def _transform(self, frame: str, stamp: Any) -> Any | None:
        """tf ``map → frame`` at ``stamp`` (``Time(0)``: the latest); if ``map → odom`` has not
        reached the stamp yet (a localisation publishing slowly), the odom frame held fixed:
        ``map → odom`` latest, ``odom → frame`` at the stamp. None if neither is available."""
        cfg, buf, tf2 = self.config, self._buffer, self._tf2
        with contextlib.suppress(tf2.TransformException):
            return buf.lookup_transform_core(cfg.map_frame, frame, stamp)
        with contextlib.suppress(tf2.TransformException):
            return buf.lookup_transform_full_core(
                cfg.map_frame, self._rospy.Time(0), frame, stamp, cfg.odom_frame
            )
        return None

    def _posed(self, frame: str, stamp: Any, received: float) -> tuple[Any, bool]:
        """The transform of data from ``frame`` at ``stamp``: at the stamp if tf has it, else
        (after :data:`TF_WAIT`) the latest; ``(None, True)`` means wait for tf."""
        found = self._transform(frame, stamp)
        if found is not None:
            return found, False
        if time.monotonic() - received < TF_WAIT:
            return None, True
        found = self._transform(frame, self._rospy.Time(0))
        if found is not None:
            self._warn_once(
                f"tf-{frame}",
                f"pfctl: no tf {self.config.map_frame} → {frame} at the data's stamp; using the "
                "latest transform",
            )
        return found, False

    def _pose(self) -> Pose2D:
        cfg = self.config
        if cfg.pose is not None:
            return convert.pose2d_from_pose(self._pose_msg.pose)
        found = self._transform(cfg.base_frame, self._rospy.Time(0))
        if found is not None:
            self._last_pose = convert.pose2d_from_transform(found.transform)
        return self._last_pose

    def _take(self, pending: deque[tuple[Any, float]], header: Any, build: Any) -> Any:
        """The newest item of ``pending`` that tf can pose, built by ``build(item, transform)``;
        newer ones still waiting for tf stay for the next call (before those received since),
        older ones are dropped."""
        with self._lock:
            items = list(pending)
            pending.clear()
        waiting, out = [], None
        for item, received in reversed(items):  # newest first
            h = header(item)
            tf, wait = self._posed(_frame(h.frame_id), h.stamp, received)
            if tf is not None:
                out = build(item, tf)
                break
            if wait:
                waiting.append((item, received))
        with self._lock:
            pending.extendleft(waiting)
        return out

    def _take_scans(self) -> tuple[LaserScan, ...]:
        """Every queued scan that tf can pose, oldest first. The first one still waiting for its
        transform stays, with all newer ones, for the next call (so the order holds); one that
        cannot be posed at all is dropped."""
        with self._lock:
            items = list(self._scans)
            self._scans.clear()
        out: list[LaserScan] = []
        for k, (msg, received) in enumerate(items):
            tf, wait = self._posed(_frame(msg.header.frame_id), msg.header.stamp, received)
            if wait:
                with self._lock:
                    keep = items[k:] + list(self._scans)
                    self.dropped_scans += max(0, len(keep) - SCAN_QUEUE)
                    self._scans.clear()
                    self._scans.extend(keep[-SCAN_QUEUE:])
                break
            if tf is not None:
                out.append(self._posed_scan(msg, tf))
        return tuple(out)

    def _take_frame(self) -> RgbdFrame | None:
        return self._take(self._frames, lambda msgs: msgs[0].header, self._decode_frame)

    def _posed_scan(self, msg: Any, tf: Any) -> LaserScan:
        scan = convert.laser_scan_from_msg(msg, convert.pose2d_from_transform(tf.transform))
        return replace(scan, stamp=self._episode(msg.header.stamp))

    def _decode_frame(self, msgs: tuple[Any, ...], tf: Any) -> RgbdFrame:
        rgb_msg, depth_msg, info_msg, labels_msg, keypoints_msg = msgs
        cfg = self.config
        topic = cfg.rgb
        try:
            rgb = convert.rgb_from_image(rgb_msg)
            topic = cfg.depth
            depth = convert.depth_from_image(depth_msg)
            topic = cfg.camera_info
            info = convert.camera_info_from_msg(info_msg)
            mask = None
            if labels_msg is not None:
                topic = str(cfg.person_labels)
                mask = image_labels(labels_msg)
        except (ValueError, UserError) as err:
            raise RobotDataError(f"{topic}: {err}") from None
        shapes = {cfg.rgb: rgb.shape[:2], cfg.depth: depth.shape}
        if mask is not None:
            shapes[str(cfg.person_labels)] = mask.shape
        if len(set(shapes.values())) > 1:
            sizes = ", ".join(f"{t} {w}x{h}" for t, (h, w) in shapes.items())
            raise RobotDataError(f"camera images of different sizes: {sizes}")
        people = None
        if keypoints_msg is not None:
            people = frame_people(keypoints_msg, str(cfg.person_keypoints), depth.shape)
        t, q = tf.transform.translation, tf.transform.rotation
        return RgbdFrame(
            stamp=self._episode(rgb_msg.header.stamp),
            rgb=rgb,
            depth=depth,
            info=info,
            camera_position=(float(t.x), float(t.y), float(t.z)),
            camera_rotation=quaternion_matrix(q.x, q.y, q.z, q.w),
            mask=mask,
            people=people,
        )

    # -- beside the port ------------------------------------------------------------------------

    def ground_truth(self) -> GroundTruth | None:
        """The simulator's truth (``<ground_truth>/robot``, ``people``, ``collisions``) for the
        metrics only — never for the follower; None when none has been received (a real
        robot). Its stamp is on the episode clock; ``command`` is the last velocity sent."""
        robot, markers = self._truth_robot, self._truth_markers
        if robot is None:
            return None
        if markers is not None and markers is not self._truth_people[0]:
            self._truth_people = (markers, people_from_markers(markers))
        return GroundTruth(
            stamp=self._episode(robot.header.stamp),
            robot=convert.pose2d_from_pose(robot.pose),
            people=self._truth_people[1],
            command=self._sent,
            collisions=self._truth_collisions or 0,
        )

    def person_detector(self) -> MaskPersonDetector | GivenPersonDetector | None:
        """The camera's person detector: of the frames' people when ``person_keypoints`` is set
        (:class:`GivenPersonDetector`), else of the person-label images; None when neither
        topic is set."""
        if self.config.person_keypoints is not None:
            return GivenPersonDetector()
        if self.config.person_labels is None:
            return None
        return label_detector(self.config.min_pixels)

    def close(self) -> None:
        """Cancel the goal, publish zero velocity (delivered before the topics are released),
        stop the watchdog and unregister; safe to call twice, also after errors. The node
        itself stays up until the process exits (rospy allows one per process)."""
        if self._closed:
            return
        self._closed = True
        with contextlib.suppress(ValueError):
            atexit.unregister(self.close)
        if self._opened:
            with contextlib.suppress(Exception):
                self._cancel_goal()
            self._stop_base()
        self._release()

    def _release(self) -> None:
        self._stop.set()
        with self._tick:
            self._tick.notify_all()
        for thread in self._threads:
            if thread is not threading.current_thread():
                thread.join(timeout=2.0)
        self._calls.close()  # what was handed over (the zero of close()) goes out first
        with self._cmd_lock:  # no publish may be under way while the topics go
            for handle in self._handles:
                with contextlib.suppress(Exception):
                    handle.unregister()
        for name in ("_nav", "_listener"):
            obj = getattr(self, name, None)
            if obj is not None:
                with contextlib.suppress(Exception):
                    (obj.action_client.stop if name == "_nav" else obj.unregister)()
        self._closed = True


__all__ = [
    "CAMERA_SLOP",
    "HsrRobot",
    "RobotConnectionError",
    "RobotDataError",
    "frame_people",
    "people_from_markers",
]
