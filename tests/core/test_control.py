"""Gaze and base control (§II-E): pkg pfctl.core.control."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pfctl.core.control import (
    BaseCommand,
    BaseController,
    ControlParams,
    GazeController,
    choose_gaze,
    gaze_angles,
    gaze_rule,
    sweep_pan,
    unknown_peak,
)
from pfctl.core.mapping.grid import GridGeometry
from pfctl.core.robot import STOP, HeadState, HeadTarget, Pose2D, Twist2D, wrap_angle

PARAMS = ControlParams()

# ----------------------------------------------------------------------------------------------
# parameters


def test_default_params_are_the_hsr_mission_values() -> None:
    assert PARAMS.max_linear_speed == 0.22
    assert PARAMS.max_angular_speed == 0.8
    assert PARAMS.pan_limits == (-3.84, 1.75)
    assert PARAMS.tilt_limits == (-1.57, 0.52)
    assert PARAMS.camera_height == 1.05
    assert ControlParams(pan_limits=[-1, 1]).pan_limits == (-1.0, 1.0)  # type: ignore[arg-type]


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"following_distance": 0.0}, "following_distance must be > 0"),
        ({"k_turn": -1.0}, "k_turn must be > 0"),
        ({"stale_after": float("nan")}, "stale_after must be finite"),
        ({"head_kd": -0.1}, "head_kd must be >= 0"),
        ({"pan_limits": (1.0, -1.0)}, "pan_limits must be finite and ordered"),
        ({"tilt_limits": (0.5, 0.5)}, "tilt_limits must be finite and ordered"),
        ({"tilt_limits": (0.5,)}, "tilt_limits must be a pair"),
    ],
)
def test_params_are_validated(kwargs: dict, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        ControlParams(**kwargs)


# ----------------------------------------------------------------------------------------------
# gaze angles


def _at_bearing(bearing: float, distance: float = 2.0, z: float = 1.05) -> tuple:
    return (distance * math.cos(bearing), distance * math.sin(bearing), z)


def test_gaze_angles_ahead_and_left() -> None:
    pose = Pose2D(0.0, 0.0, 0.0)
    ahead = gaze_angles(pose, (3.0, 0.0, 1.05), PARAMS)
    assert ahead.pan == pytest.approx(0.0)
    assert ahead.tilt == pytest.approx(0.0)
    left = gaze_angles(pose, (0.0, 2.0, 1.05), PARAMS)
    assert left.pan == pytest.approx(math.pi / 2)
    right = gaze_angles(pose, (0.0, -2.0, 1.05), PARAMS)
    assert right.pan == pytest.approx(-math.pi / 2)


def test_gaze_angles_are_relative_to_the_robot_heading() -> None:
    pose = Pose2D(1.0, 2.0, math.pi / 2)  # facing +y
    ahead = gaze_angles(pose, (1.0, 5.0, 1.05), PARAMS)
    assert ahead.pan == pytest.approx(0.0, abs=1e-12)
    right = gaze_angles(pose, (3.0, 2.0, 1.05), PARAMS)  # +x is on the robot's right
    assert right.pan == pytest.approx(-math.pi / 2)


def test_gaze_angles_behind_use_the_asymmetric_pan_limits() -> None:
    pose = Pose2D(0.0, 0.0, 0.0)
    # Bearing +2.5 rad is beyond the +1.75 limit: reached the other way round, as 2.5 − 2π.
    g = gaze_angles(pose, _at_bearing(2.5), PARAMS)
    assert g.pan == pytest.approx(2.5 - 2 * math.pi)
    assert -3.84 <= g.pan <= 1.75
    # Straight behind: −π (π itself is beyond the left limit).
    assert gaze_angles(pose, _at_bearing(math.pi), PARAMS).pan == pytest.approx(-math.pi)
    # In the unreachable gap (1.75, 2π − 3.84 = 2.443): the nearer limit.
    assert gaze_angles(pose, _at_bearing(1.9), PARAMS).pan == pytest.approx(1.75)
    assert gaze_angles(pose, _at_bearing(2.35), PARAMS).pan == pytest.approx(-3.84)


def test_gaze_angles_pick_the_equivalent_nearest_the_current_pan() -> None:
    wide = ControlParams(pan_limits=(-4.0, 4.0))
    pose = Pose2D(0.0, 0.0)
    point = _at_bearing(2.5)
    assert gaze_angles(pose, point, wide).pan == pytest.approx(2.5)
    assert gaze_angles(pose, point, wide, current_pan=-3.0).pan == pytest.approx(2.5 - 2 * math.pi)


def test_tilt_sign_for_a_face_above_or_below_the_camera() -> None:
    pose = Pose2D(0.0, 0.0)
    above = gaze_angles(pose, (2.0, 0.0, 1.6), PARAMS)
    below = gaze_angles(pose, (2.0, 0.0, 0.5), PARAMS)
    assert above.tilt == pytest.approx(math.atan2(0.55, 2.0))
    assert above.tilt > 0
    assert below.tilt == pytest.approx(math.atan2(-0.55, 2.0))
    assert below.tilt < 0
    # Clamped to the tilt limits.
    assert gaze_angles(pose, (0.5, 0.0, 5.0), PARAMS).tilt == pytest.approx(0.52)
    # (x, y) only: aim at look_height on a person.
    xy = gaze_angles(pose, (2.0, 0.0), PARAMS)
    assert xy.tilt == pytest.approx(math.atan2(1.1 - 1.05, 2.0))


@pytest.mark.sim
def test_gaze_angles_aim_the_simulated_camera_at_the_point() -> None:
    camera = pytest.importorskip("pfctl.backends.pybullet.camera")
    pose = Pose2D(0.5, -1.0, 0.7)
    point = np.array([-1.0, 1.5, 0.3])
    g = gaze_angles(pose, point, PARAMS)
    position, rotation = camera.camera_pose(pose, HeadState(g.pan, g.tilt), 1.05, 0.1)
    ray = point - position
    forward = rotation[:, 2]
    assert np.dot(ray, forward) > 0
    assert np.linalg.norm(np.cross(ray / np.linalg.norm(ray), forward)) < 1e-9


# ----------------------------------------------------------------------------------------------
# gaze PD control


def _run_perfect(goal: HeadTarget, dt: float = 0.1, seconds: float = 6.0) -> list[HeadTarget]:
    """A head that reaches its command every period."""
    ctl = GazeController(PARAMS)
    head = HeadState()
    out = []
    for _ in range(round(seconds / dt)):
        cmd = ctl.update(head, goal, dt)
        out.append(cmd)
        head = HeadState(cmd.pan, cmd.tilt)
    return out


@pytest.mark.parametrize("dt", [0.05, 0.1, 0.2])
@pytest.mark.parametrize(
    "goal", [HeadTarget(0.1, -0.05), HeadTarget(1.0, 0.3), HeadTarget(-3.0, -1.0)]
)
def test_gaze_pd_converges_without_overshoot_on_a_head_following_its_command(
    goal: HeadTarget, dt: float
) -> None:
    cmds = _run_perfect(goal, dt)
    pans = np.array([c.pan for c in cmds])
    tilts = np.array([c.tilt for c in cmds])
    for series, target in ((pans, goal.pan), (tilts, goal.tilt)):
        assert series[-1] == pytest.approx(target, abs=1e-3)
        # never beyond the goal, monotone toward it
        assert np.all(np.sign(target) * (series - target) <= 1e-9)
        assert np.all(np.sign(target) * np.diff(series) >= -1e-12)
        # at most the head's top speed
        steps = np.abs(np.diff(np.concatenate([[0.0], series])))
        assert steps.max() <= PARAMS.head_max_speed * dt + 1e-9


@pytest.mark.sim
def test_gaze_pd_converges_on_the_simulated_head_servo() -> None:
    head_mod = pytest.importorskip("pfctl.backends.pybullet.head")
    from pfctl.app.sections import from_section
    from pfctl.core.robot import RobotLimits
    from pfctl.mission import RobotConfig

    servo = head_mod.HeadServo(from_section(RobotLimits, RobotConfig()))
    ctl = GazeController(PARAMS)
    goal = HeadTarget(-3.0, -0.6)
    dt = 0.1
    pans, tilts = [], []
    for _ in range(60):
        cmd = ctl.update(servo.state, goal, dt)
        assert PARAMS.pan_limits[0] <= cmd.pan <= PARAMS.pan_limits[1]
        assert PARAMS.tilt_limits[0] <= cmd.tilt <= PARAMS.tilt_limits[1]
        servo.set_target(cmd)
        servo.update(dt)
        pans.append(servo.state.pan)
        tilts.append(servo.state.tilt)
    assert pans[-1] == pytest.approx(-3.0, abs=0.01)
    assert tilts[-1] == pytest.approx(-0.6, abs=0.01)
    assert min(pans) >= -3.0 - 0.01  # overshoot within a small tolerance
    assert min(tilts) >= -0.6 - 0.01
    # it gets there at close to the top speed: 3 rad in well under 5 s
    assert abs(pans[44] + 3.0) < 0.03


def test_gaze_pd_keeps_within_joint_limits_for_unreachable_goals() -> None:
    cmds = _run_perfect(HeadTarget(3.0, 2.0))
    assert all(-3.84 <= c.pan <= 1.75 and -1.57 <= c.tilt <= 0.52 for c in cmds)
    assert cmds[-1].pan == pytest.approx(1.75)
    assert cmds[-1].tilt == pytest.approx(0.52)


def test_gaze_pd_reset_clears_the_derivative_memory() -> None:
    ctl = GazeController(PARAMS)
    goal = HeadTarget(0.3, 0.0)
    first = ctl.update(HeadState(), goal, 0.1)
    ctl.update(HeadState(0.05, 0.0), goal, 0.1)
    ctl.reset()
    assert ctl.update(HeadState(), goal, 0.1) == first
    with pytest.raises(ValueError, match="dt"):
        ctl.update(HeadState(), goal, 0.0)


def test_gaze_pd_tracks_a_moving_goal() -> None:
    ctl = GazeController(PARAMS)
    head = HeadState()
    dt = 0.1
    for k in range(40):
        goal = HeadTarget(0.3 * k * dt, 0.0)  # a person crossing at 0.3 rad/s
        cmd = ctl.update(head, goal, dt)
        head = HeadState(cmd.pan, cmd.tilt)
    assert abs(goal.pan - head.pan) < 0.1


# ----------------------------------------------------------------------------------------------
# gaze source and sweep


def test_choose_gaze_priorities() -> None:
    robot = (0.0, 0.0)
    legs = [(3.0, 0.0), (1.0, 1.0), (-2.0, 0.0)]
    assert choose_gaze((4.0, 5.0), (1.0, 1.0, 0.9), legs, robot) == ((4.0, 5.0), "target")
    assert choose_gaze(None, (1.0, 2.0, 0.5), legs, robot) == ((1.0, 2.0), "belief")
    assert choose_gaze(None, (1.0, 2.0, 0.1), legs, robot) == ((1.0, 1.0), "legs")
    assert choose_gaze(None, None, legs, (-1.5, 0.0)) == ((-2.0, 0.0), "legs")
    assert choose_gaze(None, (1.0, 2.0, 0.5), [], robot, belief_threshold=0.6) == (None, "none")
    assert choose_gaze(None, None, np.empty((0, 2)), robot) == (None, "none")


def test_gaze_skips_people_already_rejected_and_looks_where_the_search_goes() -> None:
    robot = (0.0, 0.0)
    legs = [(1.0, 1.0), (3.0, 0.0)]
    known = [(1.2, 1.1)]  # the person at (1, 1) was identified as not the target
    assert choose_gaze(None, None, legs, robot, known_xy=known) == ((3.0, 0.0), "legs")
    everyone = [(1.2, 1.1), (3.0, 0.4)]
    assert choose_gaze(None, None, legs, robot, known_xy=everyone) == (None, "none")
    ahead = (4.0, -2.0)
    assert choose_gaze(None, None, legs, robot, known_xy=everyone, ahead=ahead) == (
        ahead,
        "goal",
    )
    # a belief peak still comes first, then legs, then the goal
    assert choose_gaze(None, (5.0, 5.0, 0.8), legs, robot, ahead=ahead)[1] == "belief"
    assert choose_gaze(None, None, legs, robot, ahead=ahead)[1] == "legs"


def test_unknown_peak_is_the_best_peak_away_from_known_people() -> None:
    peaks = [(1.0, 1.0, 0.99), (4.0, 0.0, 0.7), (6.0, 0.0, 0.5)]
    assert unknown_peak(peaks) == (1.0, 1.0, 0.99)
    assert unknown_peak(peaks, [(1.3, 1.2)]) == (4.0, 0.0, 0.7)
    assert unknown_peak(peaks, [(1.3, 1.2), (4.5, 0.5)]) == (6.0, 0.0, 0.5)
    assert unknown_peak(peaks, [(1.05, 1.0)], known_radius=0.01) == (1.0, 1.0, 0.99)
    assert unknown_peak([], [(0.0, 0.0)]) is None


def test_gaze_rule_looks_at_a_likely_peak_in_sight_away_from_known_people() -> None:
    robot = (0.0, 0.0)
    geometry = GridGeometry(0.1, 100, 100, (-5.0, -5.0))
    blocked = np.zeros(geometry.shape, dtype=bool)
    blocked[50:60, 70] = True  # a wall at x = 2.05 between y = 0 and 1
    peaks = [(3.0, 0.5, 0.9), (0.0, 3.0, 0.6), (-2.0, 0.0, 0.5), (1.0, -1.0, 0.2)]
    legs = [(1.0, -1.0)]
    sight = {"max_range": 4.0, "blocked": blocked, "geometry": geometry}
    # the best peak is behind the wall: the next one in sight
    assert gaze_rule(robot, None, peaks, legs, **sight) == ((0.0, 3.0), "belief")
    # … unless that person was identified as not the target
    known = [(0.2, 3.1)]
    assert gaze_rule(robot, None, peaks, legs, known_xy=known, **sight) == ((-2.0, 0.0), "belief")
    # too far for the camera, or too unlikely: the legs
    near = {**sight, "max_range": 1.5}
    assert gaze_rule(robot, None, peaks[1:], legs, **near) == ((1.0, -1.0), "legs")
    assert gaze_rule(robot, None, peaks, legs, belief_threshold=0.95) == ((1.0, -1.0), "legs")
    # the target first; nothing at all: the goal ahead, else nowhere
    assert gaze_rule(robot, (4.0, 4.0), peaks, legs) == ((4.0, 4.0), "target")
    assert gaze_rule(robot, None, [], [], ahead=(2.0, 2.0)) == ((2.0, 2.0), "goal")
    assert gaze_rule(robot, None, [], []) == (None, "none")


def test_sweep_pan_profile() -> None:
    seconds, amp = 8.0, 1.4
    assert sweep_pan(0.0, seconds, amp) == 0.0
    assert sweep_pan(seconds, seconds, amp) == 0.0
    assert sweep_pan(seconds + 1.0, seconds, amp) == 0.0
    assert sweep_pan(2.0, seconds, amp) == pytest.approx(amp)
    assert sweep_pan(6.0, seconds, amp) == pytest.approx(-amp)
    ts = np.linspace(0.0, seconds, 801)
    values = np.array([sweep_pan(t, seconds, amp) for t in ts])
    assert values.max() == pytest.approx(amp)
    assert values.min() == pytest.approx(-amp)
    assert np.abs(np.diff(values)).max() < 0.02  # smooth
    assert np.argmax(values) < np.argmin(values)  # left first
    with pytest.raises(ValueError):
        sweep_pan(1.0, 0.0, amp)


# ----------------------------------------------------------------------------------------------
# base control

GEOM = GridGeometry(0.05, 300, 250, (-5.0, -5.0))  # 15 m × 12.5 m


def _empty() -> np.ndarray:
    return np.zeros(GEOM.shape, dtype=bool)


def _mark_disc(blocked: np.ndarray, xy: tuple[float, float], radius: float) -> None:
    rows, cols = np.mgrid[0 : GEOM.height, 0 : GEOM.width]
    centres = GEOM.cell_to_world(rows, cols)
    blocked[np.linalg.norm(centres - np.asarray(xy), axis=-1) <= radius] = True


def _follow(ctl: BaseController, pose: Pose2D, target, **kwargs) -> BaseCommand:
    kwargs.setdefault("now", 10.0)
    kwargs.setdefault("sensor_stamp", 9.9)
    return ctl.follow(pose, target, **kwargs)


def test_stale_or_missing_sensors_stop_the_base() -> None:
    ctl = BaseController(PARAMS)
    stale = _follow(ctl, Pose2D(0.0, 0.0), (3.0, 0.0), now=10.0, sensor_stamp=9.4)
    assert (stale.mode, stale.twist, stale.reason) == ("stop", STOP, "stale sensors")
    missing = _follow(ctl, Pose2D(0.0, 0.0), (3.0, 0.0), sensor_stamp=None)
    assert (missing.mode, missing.twist) == ("stop", STOP)
    no_target = _follow(ctl, Pose2D(0.0, 0.0), None)
    assert (no_target.mode, no_target.twist) == ("stop", STOP)


def test_within_following_distance_hold_and_face_the_target() -> None:
    ctl = BaseController(PARAMS)
    cmd = _follow(ctl, Pose2D(0.0, 0.0, 0.0), (0.0, 0.8))  # on the left, 0.8 m
    assert cmd.mode == "hold"
    assert cmd.twist is not None
    assert cmd.twist.vx == 0.0 and cmd.twist.vy == 0.0
    assert cmd.twist.wz > 0  # turn left to face it
    assert cmd.twist.wz <= PARAMS.max_angular_speed
    ahead = _follow(ctl, Pose2D(0.0, 0.0, 0.0), (0.9, 0.0))
    assert (ahead.mode, ahead.twist) == ("hold", STOP)


def test_free_line_of_sight_turn_then_go_straight() -> None:
    ctl = BaseController(PARAMS)
    blocked = _empty()
    turn = _follow(ctl, Pose2D(0.0, 0.0, 0.0), (0.0, -3.0), blocked=blocked, geometry=GEOM)
    assert turn.mode == "turn"
    assert turn.twist is not None
    assert turn.twist.vx == 0.0 and turn.twist.vy == 0.0
    assert turn.twist.wz == pytest.approx(-PARAMS.max_angular_speed)
    go = _follow(ctl, Pose2D(0.0, 0.0, 0.0), (4.0, 0.5), blocked=blocked, geometry=GEOM)
    assert go.mode == "go_straight"
    assert go.twist is not None
    assert 0.0 < go.twist.vx <= 0.22
    assert go.twist.vy == 0.0
    assert go.twist.wz == pytest.approx(PARAMS.k_turn * math.atan2(0.5, 4.0))
    # No grid at all counts as free.
    assert _follow(ctl, Pose2D(0.0, 0.0), (4.0, 0.0)).mode == "go_straight"
    # Near the following distance the speed lets the robot stop in time.
    near = _follow(ctl, Pose2D(0.0, 0.0), (1.1, 0.0), blocked=blocked, geometry=GEOM)
    assert near.mode == "go_straight"
    assert near.twist is not None
    assert near.twist.vx == pytest.approx(PARAMS.k_distance * 0.1)


def test_wall_between_sends_move_base_one_metre_short_of_the_target() -> None:
    ctl = BaseController(PARAMS)
    blocked = _empty()
    rows, cols = GEOM.world_to_cell(np.array([[2.0, y] for y in np.arange(-2.0, 2.0, 0.02)]))
    blocked[rows, cols] = True  # a wall across x = 2
    cmd = _follow(ctl, Pose2D(0.0, 0.0, 0.3), (4.0, 0.0), blocked=blocked, geometry=GEOM)
    assert cmd.mode == "move_base"
    assert cmd.twist is None
    assert cmd.goal is not None
    assert (cmd.goal.x, cmd.goal.y) == pytest.approx((3.0, 0.0))
    assert cmd.goal.theta == pytest.approx(0.0)
    diagonal = _follow(ctl, Pose2D(0.0, 0.0), (4.0, 3.0), blocked=_wall_x(2.0), geometry=GEOM)
    assert diagonal.goal is not None
    assert (diagonal.goal.x, diagonal.goal.y) == pytest.approx((3.2, 2.4))
    assert diagonal.goal.theta == pytest.approx(math.atan2(3.0, 4.0))


def _wall_x(x: float) -> np.ndarray:
    blocked = _empty()
    col = int(GEOM.world_to_cell(np.array([x, 0.0]))[1])
    blocked[:, col] = True
    return blocked


def test_an_obstacle_beside_the_centre_line_blocks_the_corridor() -> None:
    ctl = BaseController(PARAMS)
    blocked = _empty()
    r, c = GEOM.world_to_cell(np.array([2.0, 0.12]))  # a table leg 12 cm off the centre line
    blocked[r, c] = True
    assert (
        _follow(ctl, Pose2D(0.0, 0.0), (4.0, 0.0), blocked=blocked, geometry=GEOM).mode
        == "move_base"
    )
    # 40 cm off: the robot (radius 0.215) passes.
    blocked = _empty()
    r, c = GEOM.world_to_cell(np.array([2.0, 0.4]))
    blocked[r, c] = True
    assert (
        _follow(ctl, Pose2D(0.0, 0.0), (4.0, 0.0), blocked=blocked, geometry=GEOM).mode
        == "go_straight"
    )


def test_the_targets_own_cells_do_not_block_the_line_of_sight() -> None:
    ctl = BaseController(PARAMS)
    blocked = _empty()
    _mark_disc(blocked, (4.0, 0.1), 0.3)  # the target's legs and a little more
    cmd = _follow(ctl, Pose2D(0.0, 0.0), (4.0, 0.0), blocked=blocked, geometry=GEOM)
    assert cmd.mode == "go_straight"
    # ... but a bystander's blob halfway does.
    _mark_disc(blocked, (2.0, 0.0), 0.15)
    assert (
        _follow(ctl, Pose2D(0.0, 0.0), (4.0, 0.0), blocked=blocked, geometry=GEOM).mode
        == "move_base"
    )


def test_a_bystander_right_in_front_stops_forward_motion() -> None:
    ctl = BaseController(PARAMS)
    cmd = _follow(ctl, Pose2D(0.0, 0.0), (4.0, 0.0), people_xy=[(0.6, 0.05)])
    assert cmd.mode == "go_straight"
    assert cmd.twist is not None
    assert cmd.twist.vx == 0.0
    assert "person" in cmd.reason
    close = _follow(ctl, Pose2D(0.0, 0.0), (4.0, 0.0), people_xy=[(0.75, 0.0)])
    assert close.twist is not None
    assert 0.0 < close.twist.vx <= PARAMS.k_distance * 0.05 + 1e-12
    # People beside or behind the robot do not slow it.
    free = _follow(ctl, Pose2D(0.0, 0.0), (4.0, 0.0), people_xy=[(0.0, 0.75), (-0.5, 0.0)])
    assert free.twist is not None
    assert free.twist.vx == pytest.approx(0.22)


def test_twists_respect_the_speed_limits() -> None:
    ctl = BaseController(PARAMS)
    rng = np.random.default_rng(3)
    for _ in range(200):
        pose = Pose2D(*rng.uniform(-3, 3, 2), rng.uniform(-math.pi, math.pi))
        cmd = _follow(ctl, pose, tuple(rng.uniform(-6, 6, 2)))
        assert cmd.twist is not None
        assert math.hypot(cmd.twist.vx, cmd.twist.vy) <= 0.22 + 1e-12
        assert abs(cmd.twist.wz) <= 0.8 + 1e-12
        assert cmd.twist.vx >= 0.0


def _integrate(pose: Pose2D, twist: Twist2D, dt: float) -> Pose2D:
    """An omnidirectional base: the body-frame twist held for ``dt``."""
    c, s = math.cos(pose.theta), math.sin(pose.theta)
    return Pose2D(
        pose.x + (c * twist.vx - s * twist.vy) * dt,
        pose.y + (s * twist.vx + c * twist.vy) * dt,
        wrap_angle(pose.theta + twist.wz * dt),
    )


def test_closed_loop_follows_a_walking_target_along_a_corridor() -> None:
    ctl = BaseController(PARAMS)
    walls = _empty()
    rows, cols = np.mgrid[0 : GEOM.height, 0 : GEOM.width]
    y = GEOM.cell_to_world(rows, cols)[..., 1]
    walls[(np.abs(y) > 1.2) & (np.abs(y) < 1.35)] = True  # a 2.4 m wide corridor along x
    pose = Pose2D(-4.0, 0.3, 2.5)  # facing away: it must turn first
    target = np.array([-1.5, 0.0])
    dt, speed = 0.1, 0.15
    modes, closest = set(), math.inf
    for k in range(500):
        target = target + np.array([speed * dt, 0.0])
        blocked = walls.copy()
        r, c = GEOM.world_to_cell(target + np.array([[0.0, 0.12], [0.0, -0.12]]))
        blocked[r, c] = True  # its legs in the grid
        cmd = ctl.follow(
            pose, target, blocked=blocked, geometry=GEOM, now=k * dt, sensor_stamp=k * dt - 0.05
        )
        modes.add(cmd.mode)
        assert cmd.mode != "move_base"
        assert cmd.twist is not None
        pose = _integrate(pose, cmd.twist, dt)
        closest = min(closest, math.hypot(target[0] - pose.x, target[1] - pose.y))
    final = math.hypot(target[0] - pose.x, target[1] - pose.y)
    assert {"turn", "go_straight"} <= modes
    assert PARAMS.following_distance - 0.2 <= final <= PARAMS.following_distance + 0.6
    assert closest >= PARAMS.min_distance
    assert abs(wrap_angle(math.atan2(target[1] - pose.y, target[0] - pose.x) - pose.theta)) < 0.1


def test_corridor_agrees_with_paths_line_of_sight() -> None:
    """Away from its border (half a cell either side) the corridor blocks exactly the cells that
    lines of sight offset by up to ±robot_radius cross."""
    from pfctl.core.mapping.paths import line_of_sight

    ctl = BaseController(PARAMS)
    rng = np.random.default_rng(5)
    robot, target = np.array([-2.0, -1.0]), np.array([3.0, 2.5])
    d = float(np.linalg.norm(target - robot))
    u = (target - robot) / d
    n = np.array([-u[1], u[0]])
    reach = d - (PARAMS.following_distance - PARAMS.robot_radius)
    offsets = np.linspace(-PARAMS.robot_radius, PARAMS.robot_radius, 40)[:, None] * n
    checked, hits = 0, 0
    for _ in range(300):
        near = robot + rng.uniform(-0.5, reach + 0.5) * u + rng.uniform(-0.6, 0.6) * n
        r, c = (int(v) for v in GEOM.world_to_cell(near))
        rel = GEOM.cell_to_world(r, c) - robot
        s, t = float(rel @ u), float(rel @ n)
        margin = 0.75 * GEOM.resolution
        if abs(abs(t) - PARAMS.robot_radius) < margin or min(abs(s), abs(s - reach)) < margin:
            continue
        blocked = _empty()
        blocked[r, c] = True
        lines = bool(
            np.all(line_of_sight(blocked, GEOM, robot + offsets, robot + reach * u + offsets))
        )
        assert ctl.line_of_sight_free(robot, target, blocked, GEOM) == lines
        checked += 1
        hits += not lines
    assert checked > 200
    assert 50 < hits < checked - 50


def test_a_corridor_leaving_the_map_is_not_free() -> None:
    ctl = BaseController(PARAMS)
    outside = _follow(ctl, Pose2D(0.0, 0.0), (14.0, 0.0), blocked=_empty(), geometry=GEOM)
    assert outside.mode == "move_base"
