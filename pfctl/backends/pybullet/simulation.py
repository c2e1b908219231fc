"""SimRobot: the simulated house behind the Robot port (first cut: kinematic omni base).

Base motion is integrated kinematically and refused where the base disc (``robot.radius``) would
overlap a wall or furniture outline (a collision is counted); the laser is :class:`FastLaser`;
people are SIM-NAV's walkers; ``navigate`` uses SIM-NAV's :class:`Navigator`. No camera yet.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pybullet as p

from pfctl.backends.pybullet.laser import FastLaser
from pfctl.backends.pybullet.navigation import Navigator
from pfctl.backends.pybullet.walkers import make_walkers
from pfctl.backends.pybullet.world import build_world
from pfctl.core.planning import GridPlanner
from pfctl.core.robot import (
    GroundTruth,
    HeadState,
    HeadTarget,
    LaserScan,
    NavStatus,
    Observation,
    Pose2D,
    Twist2D,
)
from pfctl.core.walls import rasterize_house
from pfctl.mission import Mission


@dataclass
class SimOptions:
    """Simulator options (seed, window, pacing, laser model, camera)."""

    seed: int = 0
    gui: bool = False
    realtime: bool = False
    laser_model: str = "fast"
    camera: bool = False
    laser_hz: float = 40.0


def _seg_dist(xy: np.ndarray, segs: np.ndarray) -> float:
    a, b = segs[:, :2], segs[:, 2:]
    e = b - a
    t = np.clip(np.sum((xy - a) * e, axis=1) / np.maximum(np.sum(e * e, axis=1), 1e-12), 0, 1)
    return float(np.min(np.hypot(*(a + t[:, None] * e - xy).T))) if len(segs) else math.inf


class SimRobot:
    """The simulated HSR-like robot in the house (``pfctl.core.robot.Robot``)."""

    def __init__(self, mission: Mission, options: SimOptions | None = None) -> None:
        self.mission, self.options = mission, options or SimOptions()
        self._client = p.connect(p.GUI if self.options.gui else p.DIRECT)
        self.world = build_world(self._client, mission)
        rc = mission.robot
        self.laser = FastLaser(self.world.scene.segments, seed=self.options.seed)
        grid = rasterize_house(mission.layout(), mission.map.resolution, mission.map.wall_thickness)
        self.planner = GridPlanner(grid, rc.radius)
        self.people = make_walkers(mission, self.planner, self.options.seed)
        self.navigator = Navigator(self.planner, rc.max_linear_speed, rc.max_angular_speed)
        if rc.start is not None:
            self.pose = Pose2D(float(rc.start.x), float(rc.start.y), float(rc.start.theta))
        else:
            c = np.mean(np.array(mission.layout().regions[0].polygon), axis=0)
            self.pose = Pose2D(float(c[0]), float(c[1]), 0.0)
        self.time, self.collisions = 0.0, 0
        self.head, self._head_target = HeadState(), HeadTarget()
        self._cmd, self._navigating, self._scan = Twist2D(), False, None
        self._next_scan, self._closed = 0.0, False

    def __enter__(self) -> SimRobot:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def clamp(self, t: Twist2D) -> Twist2D:
        """The command within the mission's linear (vx, vy norm) and angular limits."""
        rc = self.mission.robot
        n = math.hypot(t.vx, t.vy)
        k = min(1.0, rc.max_linear_speed / n) if n > 0 else 1.0
        wz = max(-rc.max_angular_speed, min(rc.max_angular_speed, t.wz))
        return Twist2D(t.vx * k, t.vy * k, wz)

    def command(self, base: Twist2D, head: HeadTarget | None = None) -> None:
        if self._navigating:
            self.navigator.cancel()
            self._navigating = False
        self._cmd = self.clamp(base)
        if head is not None:
            self._head_target = head

    def navigate(self, goal: Pose2D) -> None:
        self.navigator.start(goal, self.pose)
        self._navigating = True

    def nav_status(self) -> NavStatus:
        return self.navigator.status

    def cancel(self) -> None:
        self.navigator.cancel()
        self._navigating, self._cmd = False, Twist2D()

    def _legs(self) -> np.ndarray:
        if not self.people:
            return np.empty((0, 3))
        return np.vstack([w.state.legs for w in self.people])

    def _move(self, dt: float) -> None:
        c, s = math.cos(self.pose.theta), math.sin(self.pose.theta)
        v = self._cmd
        x = self.pose.x + (c * v.vx - s * v.vy) * dt
        y = self.pose.y + (s * v.vx + c * v.vy) * dt
        free = _seg_dist(np.array([x, y]), self.world.scene.segments) > self.mission.robot.radius
        people = [w.state for w in self.people]
        free = free and all(
            math.hypot(x - q.x, y - q.y) > self.mission.robot.radius + 0.2 for q in people
        )
        if not free:
            moving = math.hypot(v.vx, v.vy) > 0
            self.collisions += int(moving)
            x, y = self.pose.x, self.pose.y
        self.pose = Pose2D(x, y, self.pose.theta + v.wz * dt)
        rc = self.mission.robot
        step = rc.head_max_speed * dt
        pan = min(max(self._head_target.pan, rc.head_pan_limits[0]), rc.head_pan_limits[1])
        tilt = min(max(self._head_target.tilt, rc.head_tilt_limits[0]), rc.head_tilt_limits[1])
        self.head = HeadState(
            self.head.pan + max(-step, min(step, pan - self.head.pan)),
            self.head.tilt + max(-step, min(step, tilt - self.head.tilt)),
        )

    def step(self) -> None:
        """Advance one control period ``1 / tick_hz`` at the laser rate."""
        period = 1.0 / self.mission.behavior.tick_hz
        dt = 1.0 / self.options.laser_hz
        end = self.time + period
        while self.time < end - 1e-9:
            if self._navigating:
                pts = self._scan.points() if self._scan is not None else None
                self._cmd = self.clamp(self.navigator.update(self.pose, dt, pts))
            self._move(dt)
            for w in self.people:
                w.step(dt)
            self.time += dt
            if self.time >= self._next_scan - 1e-9:
                self._scan = self.laser.scan(self.pose, self._legs(), self.time)
                self._next_scan += dt

    def observe(self) -> Observation:
        scan: LaserScan | None = self._scan
        self._scan = None
        return Observation(self.time, self.pose, self.head, scan, None, self.collisions)

    def ground_truth(self) -> GroundTruth:
        people = tuple(w.truth() for w in self.people)
        return GroundTruth(self.time, self.pose, people, self._cmd, self.collisions)

    def close(self) -> None:
        if not self._closed:
            self._closed = True
            self._cmd = Twist2D()
            p.disconnect(self._client)
