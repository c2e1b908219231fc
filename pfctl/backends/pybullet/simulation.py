"""SimRobot: the simulated house behind the Robot port (``pfctl.core.robot.Robot``).

A :class:`~pfctl.backends.pybullet.config.SimConfig` says what to simulate. One
:meth:`SimRobot.step` advances one control period (``tick_period``) in sub-steps no longer than
the laser's period. In each sub-step

1. MOVE_BASE (:class:`~pfctl.backends.pybullet.navigation.Navigator`) turns an active goal into a
   velocity command, using the newest scan to see blockers; a goal given by :meth:`SimRobot.
   navigate` since the last step is planned here, in the first sub-step (``navigate`` itself only
   takes the goal: ACTIVE, or ABORTED at once when the goal is not free; a goal that cannot be
   reached is ABORTED by the next step);
2. the omnidirectional base moves kinematically with the command, clamped to the robot's limits
   (``robot.max_linear_speed`` on the norm of (vx, vy), ``robot.max_angular_speed``); a move
   that would bring the base disc (``robot.radius``) into a wall, a piece of furniture or a
   person is refused, and each new contact counts one collision;
3. the head's PD controller (:class:`~pfctl.backends.pybullet.head.HeadServo`) moves pan and tilt;
4. the people walk their routes (:mod:`~pfctl.backends.pybullet.walkers`), waiting when the robot
   stands in their way;
5. sensors that are due fire at their own rates (``laser.rate_hz``, ``camera.rate_hz``): the
   laser (:class:`FastLaser`, or ``rayTestBatch`` with ``laser_model="bullet"``) and the RGB-D
   camera (``getCameraImage``); the PyBullet bodies of the people and the robot are placed
   before anything is rendered or ray cast.

:meth:`SimRobot.observe` hands out every scan taken since the previous observation (oldest first;
at most a second's worth is kept, older ones are dropped and counted in
:attr:`SimRobot.dropped_scans`) and the newest frame (each once), the head angles, the
collision count, the map-frame pose as localisation reports it (the true pose plus an error that
wanders slowly, std ``pose_noise.localization_*``; each scan's pose is the laser's pose as the
robot believes it, so the scan lands in the map as it would on the real robot) and the odometry
(integrated from the motion with ``pose_noise.odometry_*`` noise, so it drifts; its frame
starts at the start pose).
:meth:`SimRobot.say` (the robot's voice, :class:`~pfctl.core.robot.Speaker`) turns the people
standing within earshot toward the robot, unless ``scenario.turn_to_voice`` is off.
:meth:`SimRobot.ground_truth` is kept apart for metrics and recording. MOVE_BASE itself plans
with the true pose. Everything random is drawn from the config's seed, so the same config gives
the same episode; ``gui`` opens PyBullet's window and ``realtime`` paces the steps to the clock.
"""

from __future__ import annotations

import math
import time
from collections import deque
from dataclasses import dataclass, replace
from typing import Literal

import numpy as np
import pybullet as p

from pfctl.backends.pybullet.camera import SimCamera, camera_pose
from pfctl.backends.pybullet.config import SimConfig
from pfctl.backends.pybullet.head import HeadServo
from pfctl.backends.pybullet.laser import BulletLaser, FastLaser, LaserSpec
from pfctl.backends.pybullet.navigation import Navigator
from pfctl.backends.pybullet.people_bodies import PeopleBodies
from pfctl.backends.pybullet.robot_body import RobotBody
from pfctl.backends.pybullet.walkers import Earshot, Walker, make_walkers
from pfctl.backends.pybullet.world import build_world
from pfctl.core.mapping.planning import GridPlanner
from pfctl.core.mapping.walls import house_bounds, rasterize_house, segment_distance
from pfctl.core.robot import (
    STOP,
    GroundTruth,
    HeadTarget,
    LaserScan,
    NavStatus,
    Observation,
    Pose2D,
    RgbdFrame,
    Twist2D,
    wrap_angle,
)

#: Radius of a person's body for contacts with the robot, metres (the torso's half width).
PERSON_CONTACT_RADIUS = 0.2
#: Extra room a walking person leaves the robot, metres.
PERSON_COURTESY = 0.15
#: Correlation time of the localisation error, seconds.
LOCALIZATION_TAU = 2.0
#: Shortest sub-step rate when the laser is slow, Hz.
MIN_SUBSTEP_HZ = 20.0


@dataclass(frozen=True)
class SimOptions:
    """How to run the simulator (:class:`SimConfig` says what to simulate)."""

    gui: bool = False
    """Open PyBullet's window (default: headless, ``p.DIRECT``)."""
    realtime: bool = False
    """Pace the steps to the wall clock (default: as fast as the CPU allows)."""
    laser_model: Literal["fast", "bullet"] = "fast"
    """``fast``: vectorised 2-D ray casting; ``bullet``: PyBullet's ``rayTestBatch``."""
    camera: bool = True
    """Render the RGB-D camera (the slowest part of a step)."""


class SimRobot:
    """The simulated HSR-like robot in the house (implements ``pfctl.core.robot.Robot``)."""

    def __init__(self, config: SimConfig, options: SimOptions | None = None) -> None:
        self.config = config
        self.options = options or SimOptions()
        self.seed = config.seed
        rc, house = config.robot, config.house
        self.static_map = rasterize_house(house.layout, house.resolution, house.wall_thickness)
        self.planner = GridPlanner(self.static_map, rc.radius)
        self.people: list[Walker] = make_walkers(
            config.scenario, house.layout, self.planner, self.seed
        )
        self.earshot = Earshot(house.layout)
        self.said: list[tuple[float, str]] = []
        """What the robot said (:meth:`say`), and when."""
        self.navigator = Navigator(self.planner, rc.max_linear_speed, rc.max_angular_speed)
        self.laser_spec = LaserSpec.from_config(config.laser)
        rngs = [np.random.default_rng([self.seed, k]) for k in range(4)]
        laser_seed, camera_seed = (int(r.integers(2**31)) for r in rngs[:2])
        self._pose_rng, self._odom_rng = rngs[2], rngs[3]
        self._loc_error = np.zeros(3)  # localisation error (x, y, theta), map frame
        self._client = p.connect(p.GUI if self.options.gui else p.DIRECT)
        self._closed = False
        try:
            self.world = build_world(self._client, house)
            self.people_bodies = PeopleBodies(self._client, self.people, seed=self.seed)
            self.robot_body = RobotBody(self._client, rc.radius, config.camera.mount_height)
            self.laser: FastLaser | BulletLaser = (
                BulletLaser(self._client, self.laser_spec, laser_seed)
                if self.options.laser_model == "bullet"
                else FastLaser(self.world.scene.segments, self.laser_spec, laser_seed, True)
            )
            self.camera = (
                SimCamera(self._client, config.camera, camera_seed) if self.options.camera else None
            )
            if self.options.gui:
                self._setup_window()
        except BaseException:
            p.disconnect(self._client)
            raise
        self.pose = config.start
        self.odometry = Pose2D(0.0, 0.0, 0.0)
        self.head = HeadServo(rc)
        period = config.tick_period
        rate = max(config.laser.rate_hz, MIN_SUBSTEP_HZ)
        self.substeps = max(1, math.ceil(period * rate - 1e-9))
        """Sub-steps per control period: none longer than the laser's period."""
        self.substep = period / self.substeps
        self.time, self.collisions = 0.0, 0
        self._ticks = 0
        self._cmd = STOP
        self._navigating = False
        self._in_contact = False
        self._scans: deque[LaserScan] = deque(maxlen=max(self.substeps, math.ceil(rate)))
        """The scans not observed yet (a second's worth at most, oldest dropped)."""
        self.dropped_scans = 0
        """Scans dropped unobserved because more than a second's worth was waiting."""
        self._scan_points: np.ndarray | None = None
        self._frame: RgbdFrame | None = None
        self._next_scan = 0.0
        self._next_frame = 0.0
        self._wall_start: float | None = None
        self._sense()  # the first scan and frame exist before the first step

    @property
    def client(self) -> int:
        """The PyBullet client of this simulation."""
        return self._client

    # -- context manager ----------------------------------------------------------------------

    def __enter__(self) -> SimRobot:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # -- the Robot port -------------------------------------------------------------------------

    def clamp(self, t: Twist2D) -> Twist2D:
        """The command within the robot's linear (vx, vy norm) and angular limits."""
        rc = self.config.robot
        n = math.hypot(t.vx, t.vy)
        k = min(1.0, rc.max_linear_speed / n) if n > 0 else 1.0
        wz = max(-rc.max_angular_speed, min(rc.max_angular_speed, t.wz))
        return Twist2D(t.vx * k, t.vy * k, wz)

    @property
    def commanded(self) -> Twist2D:
        """The base velocity being executed (after clamping)."""
        return self._cmd

    def command(self, base: Twist2D, head: HeadTarget | None = None) -> None:
        if self._navigating:
            self.navigator.cancel()
            self._navigating = False
        self._cmd = self.clamp(base)
        if head is not None:
            self.head.set_target(head)

    def point_head(self, head: HeadTarget) -> None:
        """Move the head only (also while navigating)."""
        self.head.set_target(head)

    def navigate(self, goal: Pose2D) -> None:
        """Take the goal (ACTIVE; ABORTED at once if it is not free space); the path is planned
        at the start of the next :meth:`step`, as a real robot's move_base plans in its own
        process, not in the caller's."""
        self.navigator.accept(goal)
        self._navigating = self.navigator.status is NavStatus.ACTIVE
        if not self._navigating:
            self._cmd = STOP

    def nav_status(self) -> NavStatus:
        return self.navigator.status

    def cancel(self) -> None:
        self.navigator.cancel()
        self._navigating, self._cmd = False, STOP

    @property
    def speaks(self) -> bool:
        """The simulated robot has a voice (:class:`~pfctl.core.robot.Speaker`)."""
        return True

    def say(self, text: str) -> None:
        """Say ``text``: the people standing within earshot turn to the robot
        (:meth:`~pfctl.backends.pybullet.walkers.Walker.hear`), unless the scenario's
        ``turn_to_voice`` is off."""
        self.said.append((self.time, text))
        if not self.config.scenario.turn_to_voice:
            return
        here = (self.pose.x, self.pose.y)
        for walker in self.people:
            if self.earshot.hears(here, (walker.x, walker.y)):
                walker.hear(*here)

    def step(self) -> None:
        """Advance one control period (``tick_period``)."""
        for _ in range(self.substeps):
            self.advance_substep()
        if self.options.gui:
            self._sync_bodies()
        if self.options.realtime:
            self._pace()

    def advance_substep(self) -> None:
        """Advance one sub-step (:attr:`substep` seconds, steps 1-5 of the module docstring);
        :meth:`step` is :attr:`substeps` of these. For a caller that acts between sub-steps
        (``pfctl sim serve-hsr`` publishes every scan and takes commands at once); it neither
        syncs the GUI nor paces to the clock."""
        if self._closed:
            raise RuntimeError("the simulator is closed")
        dt = self.substep
        if self._navigating:
            self._cmd = self.clamp(self.navigator.update(self.pose, dt, self._scan_points))
            if self.navigator.status is not NavStatus.ACTIVE:
                self._navigating = False
        self._move(dt)
        self._localization_step(dt)
        self.head.update(dt)
        clear = self.config.robot.radius + PERSON_CONTACT_RADIUS + PERSON_COURTESY
        for walker in self.people:
            walker.step(dt, keep_clear=(self.pose.x, self.pose.y, clear))
        self._ticks += 1
        self.time = self._ticks * dt
        self._sense()

    def observe(self) -> Observation:
        """Every scan since the previous observation, the newest frame, the state now."""
        scans, frame = tuple(self._scans), self._frame
        self._scans.clear()
        self._frame = None
        return Observation(
            stamp=self.time,
            pose=self.localized_pose,
            head=self.head.state,
            scans=scans,
            rgbd=frame,
            collisions=self.collisions,
            odometry=self.odometry,
        )

    def resense(self) -> None:
        """Take the laser scan and camera frame again now, e.g. after people were moved by hand
        (:meth:`Walker.hold`), so that the next :meth:`observe` does not show the scene as it
        was before (the scans not observed yet are dropped: they show it too)."""
        if self._closed:
            raise RuntimeError("the simulator is closed")
        self._scans.clear()
        self._next_scan = self._next_frame = self.time
        self._sense()

    def person_instances(self) -> dict[int, int]:
        """Body id → person instance index, for the mask person detector (the simulator's
        stand-in for OpenPose); the index is not the person's name."""
        return self.people_bodies.instances()

    def ground_truth(self) -> GroundTruth:
        """The truth now (for metrics and recording; never for the follower's decisions)."""
        head = self.head.state
        return GroundTruth(
            stamp=self.time,
            robot=self.pose,
            people=tuple(w.truth() for w in self.people),
            command=self._cmd,
            collisions=self.collisions,
            extra={"head_pan": head.pan, "head_tilt": head.tilt},
        )

    def close(self) -> None:
        """Stop the base, drop the goal and release PyBullet; safe to call twice."""
        self._cmd = STOP
        self._navigating = False
        if not self._closed:
            self._closed = True
            self.people_bodies.close()
            p.disconnect(self._client)

    # -- internals ---------------------------------------------------------------------------------

    def _blocked(self, x: float, y: float) -> bool:
        r = self.config.robot.radius
        if segment_distance(np.array([x, y]), self.world.scene.segments) <= r:
            return True
        reach = r + PERSON_CONTACT_RADIUS
        return any(math.hypot(x - w.x, y - w.y) <= reach for w in self.people)

    def _move(self, dt: float) -> None:
        v = self._cmd
        dx, dy, dth = v.vx * dt, v.vy * dt, v.wz * dt
        target = self.pose.compose(Pose2D(dx, dy, dth))
        contact = False
        if dx or dy:
            contact = self._blocked(target.x, target.y)
            if contact:
                dx = dy = 0.0
                target = Pose2D(self.pose.x, self.pose.y, target.theta)
        if contact and not self._in_contact:
            self.collisions += 1
        self._in_contact = contact
        self.pose = target
        self._odometry_step(dx, dy, dth)

    def _odometry_step(self, dx: float, dy: float, dth: float) -> None:
        noise = self.config.pose_noise
        if noise.odometry_linear > 0 and (dx or dy):
            k = noise.odometry_linear * math.sqrt(math.hypot(dx, dy))
            dx += k * float(self._odom_rng.normal())
            dy += k * float(self._odom_rng.normal())
        if noise.odometry_angular > 0 and dth:
            dth += noise.odometry_angular * math.sqrt(abs(dth)) * float(self._odom_rng.normal())
        if dx or dy or dth:
            self.odometry = self.odometry.compose(Pose2D(dx, dy, dth))

    def _localization_step(self, dt: float) -> None:
        """The localisation error as a first-order Gauss-Markov process (correlation time
        :data:`LOCALIZATION_TAU`) whose steady-state std is ``pose_noise.localization_*``."""
        noise = self.config.pose_noise
        if noise.localization_xy == 0 and noise.localization_theta == 0:
            return
        a = math.exp(-dt / LOCALIZATION_TAU)
        sigma = np.array([noise.localization_xy, noise.localization_xy, noise.localization_theta])
        self._loc_error = a * self._loc_error + math.sqrt(1.0 - a * a) * sigma * (
            self._pose_rng.normal(size=3)
        )

    @property
    def localized_pose(self) -> Pose2D:
        """The map-frame pose as the robot's localisation reports it (true pose + its error)."""
        e = self._loc_error
        if not e.any():
            return self.pose
        return Pose2D(
            self.pose.x + float(e[0]),
            self.pose.y + float(e[1]),
            wrap_angle(self.pose.theta + float(e[2])),
        )

    def _legs(self) -> np.ndarray:
        if not self.people:
            return np.empty((0, 3))
        return np.vstack([w.legs() for w in self.people])

    def _sync_bodies(self) -> None:
        self.people_bodies.sync()
        self.robot_body.sync(self.pose, self.head.state)

    def _sense(self) -> None:
        """Fire the laser and the camera if they are due."""
        eps = 1e-9
        synced = False
        if self.time >= self._next_scan - eps:
            if isinstance(self.laser, BulletLaser):
                self._sync_bodies()
                synced = True
            scan = self.laser.scan(self.pose, self._legs(), self.time)
            self._scan_points = scan.points()  # MOVE_BASE's view, with the true pose
            self.navigator.clear_seen(scan)
            believed = self.laser_spec.laser_pose(self.localized_pose)
            if len(self._scans) == self._scans.maxlen:
                self.dropped_scans += 1
            self._scans.append(scan if believed == scan.pose else replace(scan, pose=believed))
            period = 1.0 / self.config.laser.rate_hz
            while self._next_scan <= self.time + eps:
                self._next_scan += period
        if self.camera is not None and self.time >= self._next_frame - eps:
            if not synced:
                self._sync_bodies()
            frame = self.camera.render(self.pose, self.head.state, self.time)
            # Rendered from the true pose, posed where the robot believes its camera is (as the
            # scans are), so that laser and camera positions agree in the follower's map frame.
            cam = self.config.camera
            position, rotation = camera_pose(
                self.localized_pose, self.head.state, cam.mount_height, cam.forward_offset
            )
            x, y, z = (float(v) for v in position)
            self._frame = replace(frame, camera_position=(x, y, z), camera_rotation=rotation)
            period = 1.0 / self.config.camera.rate_hz
            while self._next_frame <= self.time + eps:
                self._next_frame += period

    def _pace(self) -> None:
        now = time.perf_counter()
        if self._wall_start is None:
            self._wall_start = now - self.time
        ahead = self.time - (now - self._wall_start)
        if ahead > 0:
            time.sleep(ahead)

    def _setup_window(self) -> None:
        c = self._client
        p.configureDebugVisualizer(p.COV_ENABLE_GUI, 0, physicsClientId=c)
        x0, y0, x1, y1 = house_bounds(self.config.house.layout)
        p.resetDebugVisualizerCamera(
            cameraDistance=0.9 * max(x1 - x0, y1 - y0),
            cameraYaw=0.0,
            cameraPitch=-65.0,
            cameraTargetPosition=((x0 + x1) / 2, (y0 + y1) / 2, 0.0),
            physicsClientId=c,
        )


__all__ = ["SimOptions", "SimRobot", "segment_distance"]
