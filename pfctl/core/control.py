"""Gaze control and base control of the follower (§II-E of Kim et al.).

The paper's robot keeps the target in view with its head and drives after it with its base:

* **Gaze control** points the head at the target, else at the highest human belief, else at leg
  candidates (:func:`gaze_rule`: the one rule for where the head looks when no behaviour points
  it), through the pan/tilt angles that aim the camera at a 3-D map point (:func:`gaze_angles`)
  and a PD joint controller that respects the joint limits and the head's top speed
  (:class:`GazeController`). :func:`sweep_pan` is the look-around profile.
* **Base control** (:class:`BaseController`) TURNs toward the target and GOes STRAIGHT when the
  line of sight on the occupancy grid is free, otherwise sends a MOVE_BASE goal toward it; it keeps
  the following distance, never drives into a person, and stops when the sensors go stale.

Everything here is plain geometry on :mod:`pfctl.core.robot` values (REP-103: x forward, y left,
angles CCW; head pan about z with left positive, tilt about y with down negative); nothing here
talks to a robot. The caller sends the resulting :class:`~pfctl.core.robot.HeadTarget` and
:class:`BaseCommand` through the Robot port.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, fields

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pfctl.core.mapping.grid import GridGeometry
from pfctl.core.mapping.paths import line_of_sight
from pfctl.core.params import param
from pfctl.core.robot import STOP, HeadState, HeadTarget, Pose2D, Twist2D, wrap_angle

__all__ = [
    "KNOWN_RADIUS",
    "MODES",
    "PEAK_CANDIDATES",
    "BaseCommand",
    "BaseController",
    "ControlParams",
    "GazeController",
    "choose_gaze",
    "gaze_angles",
    "gaze_rule",
    "peaks_in_sight",
    "sweep_pan",
    "unknown_peak",
]

_TWO_PI = 2.0 * math.pi

#: A belief peak or leg candidate this close (m) to a person identified as not the target is
#: that person: the gaze does not spend itself on them.
KNOWN_RADIUS = 1.0

#: Belief peaks considered for the gaze (the best one in sight and away from known people wins).
PEAK_CANDIDATES = 8

#: The base command modes, in the order :meth:`BaseController.follow` considers them.
MODES = ("stop", "hold", "turn", "go_straight", "move_base")

#: Length (m) of the pieces the line-of-sight corridor is checked in.
_CORRIDOR_PIECE = 1.5


@dataclass(frozen=True)
class ControlParams:
    """Gains and limits of gaze and base control (§II-E); defaults are the Toyota HSR's.

    Head PD law (see :class:`GazeController`): ``head_kp`` (1/s) is the joint speed commanded per
    radian of error, ``head_kd`` (dimensionless) the joint speed per rad/s of error rate. With a
    control period ``dt`` a head that follows its command exactly closes the error as
    ``e_{k+1} = (1 − kp·dt − kd)·e_k + kd·e_{k−1}``, monotonically (no overshoot) while
    ``kp·dt + kd ≤ 1`` — 0.9 with the defaults at the paper's 10 Hz; at slower rates the command is
    in any case never allowed past the desired angle. ``head_lead`` (s) is how far the command may
    run ahead of the measured angle (``head_max_speed·(dt + head_lead)``): a servo lags its
    command (the simulated HSR head by ~0.3 rad at 1 rad/s), and a lead shorter than that lag would
    keep it below its top speed.
    """

    following_distance: float = param(
        1.0, "Keep this far from the target (base centre to person centre).", unit="m", ge=0.3
    )
    min_distance: float = param(
        0.7,
        "Never drive closer than this to a person (base centre to person centre): inside it, no"
        " motion toward them.",
        unit="m",
        ge=0.3,
    )
    turn_threshold: float = param(
        0.5,
        "Above this bearing to the target the base turns in place (TURN), below it goes straight"
        " (GO_STRAIGHT).",
        unit="rad",
        gt=0,
        le=3.2,
    )
    k_turn: float = 1.5
    """Turn rate per radian of bearing, rad/s per rad."""
    k_distance: float = 0.8
    """Forward speed per metre beyond the following (or minimum) distance, m/s per m."""
    max_linear_speed: float = param(
        0.22, "Top speed of the omnidirectional base (norm of vx, vy).", unit="m/s", gt=0
    )
    max_angular_speed: float = param(0.8, "Top turn rate of the base.", unit="rad/s", gt=0)
    robot_radius: float = param(
        0.215,
        "Radius of the robot's footprint: planning keeps it clear of obstacles, and the"
        " line-of-sight check a corridor that wide.",
        unit="m",
        gt=0,
    )
    person_radius: float = 0.35
    """Occupied cells this close to the target's centre are its legs: the line-of-sight check
    never looks there, m."""
    stale_after: float = param(
        0.5, "The base stops when the laser or the pose is older than this.", unit="s", gt=0
    )
    pan_limits: tuple[float, float] = param(
        (-3.84, 1.75),
        "Head pan joint limits [low, high] (HSR: asymmetric).",
        unit="rad",
        ordered=True,
    )
    tilt_limits: tuple[float, float] = param(
        (-1.57, 0.52),
        "Head tilt joint limits [low, high] (down negative).",
        unit="rad",
        ordered=True,
    )
    head_max_speed: float = param(1.0, "Head joint speed limit.", unit="rad/s", gt=0)
    head_kp: float = 8.0
    """Proportional gain of the head PD law, 1/s."""
    head_kd: float = 0.1
    """Derivative gain of the head PD law (rad/s per rad/s, dimensionless)."""
    head_lead: float = 0.4
    """How far ahead of the measured angle the head command may run, in seconds of top speed."""
    camera_height: float = param(
        1.05, "Height of the head's pan/tilt pivot above the floor.", unit="m", gt=0
    )
    look_height: float = 1.1
    """Aim at this height on a person (torso / face), m."""

    def __post_init__(self) -> None:
        non_negative = ("head_kd", "head_lead", "person_radius")
        for f in fields(self):
            value = getattr(self, f.name)
            if f.name.endswith("_limits"):
                try:
                    lo, hi = (float(v) for v in value)
                except (TypeError, ValueError):
                    raise ValueError(
                        f"ControlParams.{f.name} must be a pair (low, high), got {value!r}"
                    ) from None
                object.__setattr__(self, f.name, (lo, hi))
                if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
                    raise ValueError(
                        f"ControlParams.{f.name} must be finite and ordered (low < high), "
                        f"got {value}"
                    )
                continue
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise ValueError(f"ControlParams.{f.name} must be a number, got {value!r}")
            if not math.isfinite(value):
                raise ValueError(f"ControlParams.{f.name} must be finite, got {value}")
            if f.name in non_negative:
                if value < 0:
                    raise ValueError(f"ControlParams.{f.name} must be >= 0, got {value}")
            elif value <= 0:
                raise ValueError(f"ControlParams.{f.name} must be > 0, got {value}")


# ----------------------------------------------------------------------------------------------
# Gaze control
# ----------------------------------------------------------------------------------------------


def _clip(value: float, lo: float, hi: float) -> float:
    return min(max(value, lo), hi)


def _pan_within(bearing: float, limits: tuple[float, float], current: float | None) -> float:
    """The 2π-equivalent of ``bearing`` inside ``limits`` (nearest ``current``, else smallest
    magnitude); if none fits, the limit nearest ``bearing`` around the circle."""
    lo, hi = limits
    eps = 1e-9
    k0 = math.ceil((lo - eps - bearing) / _TWO_PI)
    k1 = math.floor((hi + eps - bearing) / _TWO_PI)
    candidates = [_clip(bearing + k * _TWO_PI, lo, hi) for k in range(k0, k1 + 1)]
    if candidates:
        ref = 0.0 if current is None else current
        return min(candidates, key=lambda c: (abs(c - ref), abs(c)))
    return lo if abs(wrap_angle(bearing - lo)) < abs(wrap_angle(bearing - hi)) else hi


def gaze_angles(
    pose: Pose2D,
    point_xyz: ArrayLike,
    params: ControlParams | None = None,
    current_pan: float | None = None,
) -> HeadTarget:
    """The head pan/tilt that aim the camera at a map point (§II-E gaze control).

    ``point_xyz`` is ``(x, y, z)`` in the map frame, or ``(x, y)`` for a person there (aimed at
    ``params.look_height``). The pivot is above the base centre at ``params.camera_height``; the
    optical centre sits on the view ray through the pivot, so these angles aim it exactly.

    * pan = bearing of the point relative to the robot's heading, taken among its 2π-equivalents
      inside ``pan_limits`` (the HSR's −3.84..1.75: a point at bearing +2.5 rad is reached as
      −3.78); if several fit, the one nearest ``current_pan`` (default: the smallest); if none
      fits, the limit nearest the bearing.
    * tilt = ``atan2(z − camera_height, horizontal distance)`` (down negative), clamped to
      ``tilt_limits``.
    """
    params = ControlParams() if params is None else params
    p = np.asarray(point_xyz, dtype=float).ravel()
    if p.size not in (2, 3):
        raise ValueError(f"point_xyz must have 2 or 3 coordinates, got {p.size}")
    z = float(p[2]) if p.size == 3 else params.look_height
    dx, dy = float(p[0]) - pose.x, float(p[1]) - pose.y
    bearing = wrap_angle(math.atan2(dy, dx) - pose.theta)
    pan = _pan_within(bearing, params.pan_limits, current_pan)
    tilt = math.atan2(z - params.camera_height, math.hypot(dx, dy))
    return HeadTarget(pan, _clip(tilt, *params.tilt_limits))


class GazeController:
    """PD joint control of the head toward desired angles (§II-E), within limits and top speed.

    The law, per joint (pan, tilt), for a control period ``dt`` and the measured angle ``q``::

        q* = desired clamped to the joint limits        e = q* − q      ė = (e − e_prev) / dt
        u  = kp·e + kd·ė                                (rad/s; ė = 0 on the first update)
        c  = q + clip(u·dt, ±v_max·(dt + lead))         the PD step, led at most ``lead`` s ahead
        c  = clip(c, r ± v_max·dt)                      the command moves at most v_max·dt a tick
        c  = clip(c, between q and q*), then to the joint limits

    ``r`` is the previous command (or ``q`` after :meth:`reset`, or when the head has moved more
    than the lead away from it — e.g. another behaviour moved the head meanwhile).

    Why it does not overshoot: the command never passes ``q*``; on a head that follows its command
    the error evolves as ``e_{k+1} = (1 − kp·dt − kd)·e_k + kd·e_{k−1}`` with non-negative
    coefficients for the default gains (``kp·dt + kd ≤ 1`` at 10 Hz) — a monotone decay — and
    the command moves no faster than the head may. On a lagging servo (the simulated HSR head, a
    critically damped PD on its command) the command is a monotone ramp that stops at ``q*``, and a
    critically damped follower of a monotone input does not pass its final value. ``kd`` damps the
    command while the head moves fast toward the goal and, for a moving goal (a walking person),
    adds the goal's rate as a feed-forward.
    """

    def __init__(self, params: ControlParams | None = None) -> None:
        self.params = ControlParams() if params is None else params
        self._e_prev: tuple[float, float] | None = None
        self._cmd_prev: tuple[float, float] | None = None

    def reset(self) -> None:
        """Forget the derivative memory and the previous command (e.g. after a head sweep)."""
        self._e_prev = None
        self._cmd_prev = None

    def update(self, head: HeadState, desired: HeadTarget, dt: float) -> HeadTarget:
        """The joint command for this control period (see the class docstring for the law)."""
        if not dt > 0:
            raise ValueError(f"dt must be > 0, got {dt}")
        prm = self.params
        vmax = prm.head_max_speed
        lead = vmax * (dt + prm.head_lead)
        ramp = vmax * dt
        q = (head.pan, head.tilt)
        limits = (prm.pan_limits, prm.tilt_limits)
        goals = (_clip(desired.pan, *limits[0]), _clip(desired.tilt, *limits[1]))
        errors = (goals[0] - q[0], goals[1] - q[1])
        out = []
        for j in range(2):
            e = errors[j]
            de = 0.0 if self._e_prev is None else (e - self._e_prev[j]) / dt
            u = prm.head_kp * e + prm.head_kd * de
            c = q[j] + _clip(u * dt, -lead, lead)
            ref = q[j]
            if self._cmd_prev is not None and abs(self._cmd_prev[j] - q[j]) <= lead:
                ref = self._cmd_prev[j]
            c = _clip(c, ref - ramp, ref + ramp)
            c = _clip(c, min(q[j], goals[j]), max(q[j], goals[j]))
            out.append(_clip(c, *limits[j]))
        self._e_prev = errors
        self._cmd_prev = (out[0], out[1])
        return HeadTarget(out[0], out[1])


def choose_gaze(
    target_xy: ArrayLike | None,
    belief_peak: Sequence[float] | None,
    leg_candidates: ArrayLike,
    robot_xy: ArrayLike,
    belief_threshold: float = 0.3,
    *,
    known_xy: ArrayLike = (),
    known_radius: float = KNOWN_RADIUS,
    ahead: Sequence[float] | None = None,
) -> tuple[tuple[float, float] | None, str]:
    """Where to look and why (§II-E): the target, else the human belief, else leg candidates,
    else where the robot is going.

    Returns ``((x, y), source)``: the target's position if known → ``"target"``; else the belief
    peak ``(x, y, p)`` if ``p ≥ belief_threshold`` → ``"belief"``; else the leg candidate
    (``(n, 2)``) nearest ``robot_xy`` → ``"legs"``, leaving out candidates within
    ``known_radius`` of ``known_xy`` (people already identified as not the target: looking at
    them again tells nothing); else ``ahead`` (the navigation goal of a search, so the camera
    sees the places the robot drives into) → ``"goal"``; else ``(None, "none")``. The caller
    picks a belief peak away from ``known_xy`` (:func:`unknown_peak`).
    """
    if target_xy is not None:
        t = np.asarray(target_xy, dtype=float).ravel()
        return (float(t[0]), float(t[1])), "target"
    if belief_peak is not None:
        x, y, p = (float(v) for v in belief_peak)
        if p >= belief_threshold:
            return (x, y), "belief"
    legs = np.asarray(leg_candidates, dtype=float).reshape(-1, 2)
    known = np.asarray(known_xy, dtype=float).reshape(-1, 2)
    if len(legs) and len(known):
        near = np.linalg.norm(legs[:, None, :] - known[None, :, :], axis=2).min(axis=1)
        legs = legs[near > known_radius]
    if len(legs):
        r = np.asarray(robot_xy, dtype=float).ravel()[:2]
        i = int(np.argmin(np.linalg.norm(legs - r, axis=1)))
        return (float(legs[i, 0]), float(legs[i, 1])), "legs"
    if ahead is not None:
        return (float(ahead[0]), float(ahead[1])), "goal"
    return None, "none"


def unknown_peak(
    peaks: Sequence[Sequence[float]],
    known_xy: ArrayLike = (),
    known_radius: float = KNOWN_RADIUS,
) -> tuple[float, float, float] | None:
    """The first belief peak ``(x, y, p)`` of ``peaks`` (by decreasing p) farther than
    ``known_radius`` from every person in ``known_xy`` (identified as not the target): the
    human belief marks people, and a person already identified is not worth a look."""
    known = np.asarray(known_xy, dtype=float).reshape(-1, 2)
    for peak in peaks:
        x, y, p = (float(v) for v in peak)
        if not len(known) or np.linalg.norm(known - (x, y), axis=1).min() > known_radius:
            return x, y, p
    return None


def peaks_in_sight(
    peaks: Sequence[tuple[float, float, float]],
    robot_xy: tuple[float, float],
    max_range: float,
    blocked: NDArray[np.bool_] | None,
    geometry: GridGeometry | None,
) -> list[tuple[float, float, float]]:
    """The belief peaks ``(x, y, p)`` the camera could see from ``robot_xy``: within
    ``max_range`` and with a clear line of sight over ``blocked`` (the static map; None: every
    peak). A peak behind walls — a person seen there long ago — cannot be checked by turning
    the head, so it does not draw the gaze."""
    if not peaks or blocked is None or geometry is None:
        return list(peaks)
    here = np.array([robot_xy[0], robot_xy[1]])
    xy = np.array([(x, y) for x, y, _ in peaks])
    near = np.linalg.norm(xy - here, axis=1) <= max_range
    clear = line_of_sight(blocked, geometry, here, xy)
    return [p for p, ok in zip(peaks, near & clear, strict=True) if ok]


def gaze_rule(
    robot_xy: tuple[float, float],
    target_xy: tuple[float, float] | None,
    peaks: Sequence[tuple[float, float, float]],
    legs_xy: Sequence[tuple[float, float]],
    *,
    known_xy: Sequence[tuple[float, float]] = (),
    ahead: tuple[float, float] | None = None,
    belief_threshold: float = 0.3,
    max_range: float = math.inf,
    blocked: NDArray[np.bool_] | None = None,
    geometry: GridGeometry | None = None,
) -> tuple[tuple[float, float] | None, str]:
    """Where the head looks when no behaviour points it, and why: the paper's gaze priority
    (§II-E), the one rule of the follower's gaze.

    The target if it is tracked; else the most likely human belief peak of ``peaks`` (``(x, y,
    p)`` by decreasing p, e.g. :meth:`~pfctl.core.perception.belief.HumanBelief.most_likely`)
    at least ``belief_threshold`` likely, in sight (:func:`peaks_in_sight`) and away from the
    people of ``known_xy`` (identified as not the target: :func:`unknown_peak`); else the
    nearest leg candidate not of such a person; else ``ahead`` (the navigation goal being
    driven to); else nothing (:func:`choose_gaze`)."""
    likely = [p for p in peaks if p[2] >= belief_threshold]
    visible = peaks_in_sight(likely, robot_xy, max_range, blocked, geometry)
    peak = unknown_peak(visible, known_xy)
    return choose_gaze(target_xy, peak, legs_xy, robot_xy, known_xy=known_xy, ahead=ahead)


def sweep_pan(elapsed: float, seconds: float, amplitude: float) -> float:
    """The look-around head pan at ``elapsed`` s into a sweep of ``seconds`` (look_around action).

    ``amplitude · sin(2π · elapsed / seconds)``: from 0 to +amplitude (left) at a quarter, to
    −amplitude at three quarters and back to 0 at the end; 0 before the start and after the end.
    """
    if not seconds > 0:
        raise ValueError(f"seconds must be > 0, got {seconds}")
    if elapsed <= 0.0 or elapsed >= seconds:
        return 0.0
    return amplitude * math.sin(_TWO_PI * elapsed / seconds)


# ----------------------------------------------------------------------------------------------
# Base control
# ----------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class BaseCommand:
    """What the base should do this tick (§II-E).

    ``mode`` is one of :data:`MODES`. ``twist`` (robot frame) is set for every mode but
    ``"move_base"`` (``STOP`` for ``"stop"``); ``goal`` only for ``"move_base"``: the caller snaps
    it into free space and decides whether to re-send it. ``reason`` says why, for logs.
    """

    mode: str
    twist: Twist2D | None = None
    goal: Pose2D | None = None
    reason: str = ""


class BaseController:
    """TURN / GO_STRAIGHT / MOVE_BASE after the target (§II-E), keeping the following distance.

    :meth:`follow` decides, in order:

    1. **stop** when the laser/pose stamp is missing or older than ``stale_after``;
    2. **stop** when there is no target;
    3. **hold** when the target is within ``following_distance``: no translation, turn to face it
       (``wz = k_turn·bearing``) so the camera keeps it;
    4. when the **line of sight** to the target is free on the grid: **turn** in place
       (``wz = k_turn·bearing``) while ``|bearing| > turn_threshold``, else **go_straight** with
       ``vx = k_distance·(d − following_distance)`` and ``wz = k_turn·bearing``;
    5. otherwise **move_base** to the point ``following_distance`` short of the target on the
       segment robot → target, facing the target.

    Never into a person: the forward speed is scaled so that its component toward each person
    (the target and ``people_xy``) is at most ``k_distance·(distance − min_distance)`` — zero
    inside ``min_distance`` — so the base slows exponentially toward, and never crosses, that
    distance (at any control period ``dt < 1/k_distance``). All twists are clamped to
    ``max_linear_speed`` (norm) and ``max_angular_speed``.

    The line of sight is checked on ``blocked`` (the occupied cells of the robot's grid) as a
    corridor ``2·robot_radius`` wide — the robot's swept footprint — from the robot up to where its
    disc reaches when stopped at the following distance, and never within ``person_radius`` of the
    target: the target's own legs are occupied cells there and must not block
    (:meth:`line_of_sight_free`). No grid dilation per tick: only the cells inside the bounding
    boxes of pieces of the corridor are looked at.
    """

    def __init__(self, params: ControlParams | None = None) -> None:
        self.params = ControlParams() if params is None else params

    def line_of_sight_free(
        self,
        robot_xy: ArrayLike,
        target_xy: ArrayLike,
        blocked: NDArray[np.bool_] | None,
        geometry: GridGeometry | None,
    ) -> bool:
        """True when the corridor from the robot toward the target is free (see the class doc).

        The corridor is the rectangle from the robot's centre along the direction to the target,
        ``reach = d − max(following_distance − robot_radius, person_radius)`` long and
        ``2·robot_radius`` wide; it is blocked by any ``blocked`` cell whose centre lies in it, and
        when it leaves the map (as :func:`~pfctl.core.mapping.paths.line_of_sight` would say). Only
        the cells of the bounding boxes of 1.5 m pieces of it are looked at; no dilation of the
        grid.
        """
        if blocked is None or geometry is None:
            return True
        prm = self.params
        ax, ay = (float(v) for v in np.asarray(robot_xy, dtype=float).ravel()[:2])
        tx, ty = (float(v) for v in np.asarray(target_xy, dtype=float).ravel()[:2])
        d = math.hypot(tx - ax, ty - ay)
        reach = d - max(prm.following_distance - prm.robot_radius, prm.person_radius)
        if reach <= 0.0:
            return True
        if blocked.shape != geometry.shape:
            raise ValueError(f"blocked shape {blocked.shape} != grid shape {geometry.shape}")
        ux, uy = (tx - ax) / d, (ty - ay) / d
        half = prm.robot_radius
        # The corridor's bounding box must lie inside the map.
        ex, ey = half * abs(uy), half * abs(ux)  # half extents of the end edges
        xmin, xmax, ymin, ymax = geometry.extent
        bx = (min(ax, ax + reach * ux) - ex, max(ax, ax + reach * ux) + ex)
        by = (min(ay, ay + reach * uy) - ey, max(ay, ay + reach * uy) + ey)
        if bx[0] < xmin or by[0] < ymin or bx[1] > xmax or by[1] > ymax:
            return False  # the corridor leaves the map
        # Walk it in pieces of ~_CORRIDOR_PIECE m: small bounding boxes even on a diagonal, and an
        # early exit at the first blocked piece (the nearest obstacle is found first).
        pieces = max(1, math.ceil(reach / _CORRIDOR_PIECE))
        for k in range(pieces):
            s0, s1 = reach * k / pieces, reach * (k + 1) / pieces
            if not self._piece_free(blocked, geometry, (ax, ay), (ux, uy), s0, s1, half):
                return False
        return True

    @staticmethod
    def _piece_free(
        blocked: NDArray[np.bool_],
        geometry: GridGeometry,
        a: tuple[float, float],
        u: tuple[float, float],
        s0: float,
        s1: float,
        half: float,
    ) -> bool:
        """No blocked cell centre in the rectangle ``s ∈ [s0, s1], |t| ≤ half`` (t across u)."""
        (ax, ay), (ux, uy) = a, u
        ex, ey = half * abs(uy), half * abs(ux)
        x0, x1 = sorted((ax + s0 * ux, ax + s1 * ux))
        y0, y1 = sorted((ay + s0 * uy, ay + s1 * uy))
        res = geometry.resolution
        ox, oy = geometry.origin
        c0 = max(math.ceil((x0 - ex - ox) / res - 0.5), 0)
        c1 = min(math.floor((x1 + ex - ox) / res - 0.5), geometry.width - 1)
        r0 = max(math.ceil((y0 - ey - oy) / res - 0.5), 0)
        r1 = min(math.floor((y1 + ey - oy) / res - 0.5), geometry.height - 1)
        if c1 < c0 or r1 < r0:
            return True
        rows, cols = np.nonzero(blocked[r0 : r1 + 1, c0 : c1 + 1])
        if not rows.size:
            return True
        x = (ox - ax + (c0 + 0.5) * res) + cols * res
        y = (oy - ay + (r0 + 0.5) * res) + rows * res
        s = x * ux + y * uy
        t = y * ux - x * uy
        return not bool(np.any((s >= s0) & (s <= s1) & (np.abs(t) <= half)))

    def follow(
        self,
        pose: Pose2D,
        target_xy: ArrayLike | None,
        *,
        blocked: NDArray[np.bool_] | None = None,
        geometry: GridGeometry | None = None,
        now: float,
        sensor_stamp: float | None,
        people_xy: ArrayLike = (),
    ) -> BaseCommand:
        """The base command of this tick (see the class docstring for the rules)."""
        prm = self.params
        if sensor_stamp is None or now - sensor_stamp > prm.stale_after:
            return BaseCommand("stop", STOP, reason="stale sensors")
        if target_xy is None:
            return BaseCommand("stop", STOP, reason="no target")
        t = np.asarray(target_xy, dtype=float).ravel()[:2]
        tx, ty = float(t[0]), float(t[1])
        dx, dy = tx - pose.x, ty - pose.y
        d = math.hypot(dx, dy)
        heading = math.atan2(dy, dx) if d > 0 else pose.theta
        bearing = wrap_angle(heading - pose.theta)
        wz = _clip(prm.k_turn * bearing, -prm.max_angular_speed, prm.max_angular_speed)
        if d <= prm.following_distance:
            twist = Twist2D(0.0, 0.0, wz) if wz != 0.0 else STOP
            return BaseCommand("hold", twist, reason="within following distance")
        if not self.line_of_sight_free((pose.x, pose.y), (tx, ty), blocked, geometry):
            fd = prm.following_distance
            goal = Pose2D(tx - fd * dx / d, ty - fd * dy / d, heading)
            return BaseCommand("move_base", None, goal, reason="line of sight blocked")
        if abs(bearing) > prm.turn_threshold:
            return BaseCommand("turn", Twist2D(0.0, 0.0, wz), reason="line of sight free")
        vx = min(prm.k_distance * (d - prm.following_distance), prm.max_linear_speed)
        people = np.asarray(people_xy, dtype=float).reshape(-1, 2)
        vx, slowed = self._safe_speed(pose, vx, np.vstack([t[None, :], people]))
        reason = "line of sight free" + (", slowed for a person" if slowed else "")
        return BaseCommand("go_straight", Twist2D(max(vx, 0.0), 0.0, wz), reason=reason)

    def _safe_speed(
        self, pose: Pose2D, vx: float, people: NDArray[np.float64]
    ) -> tuple[float, bool]:
        """Scale the forward speed ``vx`` so its component toward every person stays within
        ``k_distance·(distance − min_distance)`` (0 inside ``min_distance``)."""
        if vx <= 0.0 or not len(people):
            return vx, False
        prm = self.params
        rel = people - np.array([pose.x, pose.y])
        dist = np.hypot(rel[:, 0], rel[:, 1])
        heading = np.array([math.cos(pose.theta), math.sin(pose.theta)])
        with np.errstate(invalid="ignore", divide="ignore"):
            cos_toward = np.where(dist > 0, rel @ heading / dist, 1.0)
        toward = vx * cos_toward
        allowed = prm.k_distance * np.maximum(dist - prm.min_distance, 0.0)
        limiting = toward > allowed
        if not limiting.any():
            return vx, False
        scale = float(np.min(allowed[limiting] / toward[limiting]))
        return vx * scale, True
