"""The simulated HSR head: pan and tilt joints driven by a PD position controller.

Each joint follows ``q̈ = k_p (q* − q) − k_d q̇`` (critically damped, ``k_d = 2 √k_p``), its
speed limited to ``head_max_speed`` (HSR: 1 rad/s) and its angle to the joint limits (HSR: pan
−3.84..+1.75 rad, tilt −1.57..+0.52 rad), integrated with semi-implicit Euler in sub-steps of at
most :data:`MAX_DT` so the loop stays stable at any control rate.
"""

from __future__ import annotations

import math

from pfctl.core.robot import HeadState, HeadTarget, RobotLimits

#: Proportional gain, 1/s² (a ~0.6 s settling time for a small step).
KP = 40.0
#: Derivative gain, 1/s: critical damping.
KD = 2.0 * math.sqrt(KP)
#: Longest integration sub-step, seconds.
MAX_DT = 0.005


class HeadServo:
    """Pan/tilt joint state and its PD controller; :meth:`update` advances it by ``dt``."""

    def __init__(self, robot: RobotLimits) -> None:
        self.limits = (tuple(robot.head_pan_limits), tuple(robot.head_tilt_limits))
        self.max_speed = float(robot.head_max_speed)
        self.angles = [0.0, 0.0]
        self.speeds = [0.0, 0.0]
        self.target = HeadTarget()

    @property
    def state(self) -> HeadState:
        return HeadState(self.angles[0], self.angles[1])

    def set_target(self, target: HeadTarget) -> None:
        """A new goal; it is clamped to the joint limits."""
        (p0, p1), (t0, t1) = self.limits
        self.target = HeadTarget(min(max(target.pan, p0), p1), min(max(target.tilt, t0), t1))

    def update(self, dt: float) -> None:
        """Advance both joints by ``dt`` seconds."""
        goals = (self.target.pan, self.target.tilt)
        if self.speeds == [0.0, 0.0] and self.angles == list(goals):
            return  # at rest on the goal
        steps = max(1, math.ceil(dt / MAX_DT - 1e-9))
        h = dt / steps
        for _ in range(steps):
            for j in range(2):
                acc = KP * (goals[j] - self.angles[j]) - KD * self.speeds[j]
                v = self.speeds[j] + acc * h
                v = max(-self.max_speed, min(self.max_speed, v))
                q = self.angles[j] + v * h
                lo, hi = self.limits[j]
                if q < lo or q > hi:
                    q, v = min(max(q, lo), hi), 0.0
                self.angles[j], self.speeds[j] = q, v


__all__ = ["HeadServo"]
