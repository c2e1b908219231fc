"""Person detections and their 3-D positions on synthetic RGB-D frames (exact geometry)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from pfctl.core.perception.vision import (
    BODY_HALF_DEPTH,
    GivenPersonDetector,
    HogPersonDetector,
    MaskPersonDetector,
    PersonDetector,
    body_position,
    hog_available,
    make_detector,
    non_max_suppression,
    pixels_to_map,
)
from pfctl.core.robot import CameraInfo, GivenPerson, RgbdFrame

W, H, F = 160, 120, 100.0
#: Camera 1 m above the origin looking along map +x (columns: x right, y down, z forward).
LOOK_X = np.column_stack(([0.0, -1.0, 0.0], [0.0, 0.0, -1.0], [1.0, 0.0, 0.0]))


def _frame(depth: np.ndarray, mask: np.ndarray | None = None) -> RgbdFrame:
    info = CameraInfo(W, H, (F, 0.0, W / 2 - 0.5, 0.0, F, H / 2 - 0.5, 0.0, 0.0, 1.0))
    rgb = np.zeros((H, W, 3), np.uint8)
    return RgbdFrame(0.0, rgb, depth.astype(np.float32), info, (0.0, 0.0, 1.0), LOOK_X, mask)


def _person(depth: np.ndarray, mask: np.ndarray, body: int, u0: int, z: float) -> None:
    """A 20x60 px person at columns u0.., depth z; bodies ``body`` (head) and ``body + 1``."""
    depth[30:90, u0 : u0 + 20] = z
    mask[30:42, u0 + 5 : u0 + 15] = body
    mask[42:90, u0 : u0 + 20] = body + 1


def test_pixels_back_project_through_the_camera_pose() -> None:
    depth = np.full((H, W), np.inf)
    depth[H // 2, W // 2] = 2.0
    depth[0, 0] = 4.0
    pts = pixels_to_map(_frame(depth), np.array([W // 2, 0, 5]), np.array([H // 2, 0, 5]))
    assert len(pts) == 2  # the pixel without depth is dropped
    assert pts[0] == pytest.approx([2.0, -0.5 * 2.0 / F, 1.0 - 0.5 * 2.0 / F])
    # top-left pixel: left (+y) and up (+z) of the optical axis
    assert pts[1] == pytest.approx([4.0, (W / 2 - 0.5) * 4 / F, 1.0 + (H / 2 - 0.5) * 4 / F])


def test_body_position_is_the_median_pushed_half_a_body_back() -> None:
    depth = np.full((H, W), 3.0)
    depth[50, 70] = 30.0  # an outlier does not move the median
    vs, us = np.mgrid[40:80, 70:90]
    x, y, z = body_position(_frame(depth), us.ravel(), vs.ravel())
    assert x == pytest.approx(3.0 + BODY_HALF_DEPTH, abs=1e-3)
    assert y == pytest.approx(0.0, abs=1e-6)  # the box is centred on the principal point
    assert z == pytest.approx(1.0, abs=1e-6)
    assert body_position(_frame(np.full((H, W), np.inf)), us.ravel(), vs.ravel()) is None


def test_mask_detector_gives_instances_boxes_keypoints_and_no_names() -> None:
    depth = np.full((H, W), np.inf)
    mask = np.full((H, W), -1, np.int32)
    _person(depth, mask, 10, 20, 2.0)
    _person(depth, mask, 20, 100, 4.0)
    mask[0:5, 0:5] = 99  # furniture: not a person
    det = MaskPersonDetector(
        {10: 0, 11: 0, 20: 1, 21: 1},
        {10: "head", 11: "torso", 20: "head", 21: "torso"},
        min_pixels=50,
    )
    assert isinstance(det, PersonDetector)
    found = sorted(det.detect(_frame(depth, mask)), key=lambda d: d.instance or 0)
    assert [d.instance for d in found] == [0, 1]
    near, far = found
    assert near.box == (20, 30, 40, 90) and near.head_box == (25, 30, 35, 42)
    assert near.keypoints is not None and near.keypoints["neck"][1] == 42
    assert near.mask is not None and near.mask.sum() == 12 * 10 + 48 * 20
    frame = _frame(depth, mask)
    for d in (near, far):  # the surface's median, pushed along the (slanted) line of sight
        assert d.mask is not None
        vs, us = np.nonzero(d.mask)
        surface = np.median(pixels_to_map(frame, us, vs), axis=0)
        push = BODY_HALF_DEPTH * surface[:2] / np.hypot(*surface[:2])
        assert d.position == pytest.approx((*(surface[:2] + push), surface[2]))
    assert near.position[0] == pytest.approx(2.1, abs=0.02)
    assert far.position[0] == pytest.approx(4.1, abs=0.02)
    assert near.position[1] > 0 > far.position[1]  # left of the axis / right of it
    assert near.ground_truth_name is None
    named = MaskPersonDetector({10: 0, 11: 0}, names={0: "alice"}, min_pixels=50)
    assert named.detect(_frame(depth, mask))[0].ground_truth_name == "alice"
    assert MaskPersonDetector({10: 0, 11: 0}, min_pixels=5000).detect(_frame(depth, mask)) == []


def test_given_detections_get_positions_from_the_central_depth() -> None:
    depth = np.full((H, W), 9.0)  # background
    depth[30:90, 60:100] = 2.5
    given = GivenPersonDetector()
    given.set([((50, 20, 110, 100), {"neck": (80.0, 40.0)}, 0.9)])
    (d,) = given.detect(_frame(depth))
    assert d.position[0] == pytest.approx(2.5 + BODY_HALF_DEPTH, abs=1e-3)
    assert d.keypoints == {"neck": (80.0, 40.0)} and d.score == 0.9


def test_given_people_on_the_frame_are_placed_by_the_depth_around_their_torso() -> None:
    """The frame's own people (a keypoint source, e.g. OpenPose over ROS) win over set(); with
    torso keypoints the depth is read around them, where the box's centre would miss the body
    (here: a person at the box's left side, background in its middle)."""
    depth = np.full((H, W), 9.0)
    depth[30:90, 40:56] = 2.5  # the body
    box = (30, 20, 110, 100)  # a loose box: its centre is background
    torso = {
        "neck": (47.0, 36.0),
        "right_shoulder": (42.0, 38.0),
        "left_shoulder": (53.0, 38.0),
        "mid_hip": (47.0, 70.0),
        "head": (47.0, 25.0),
    }
    person = GivenPerson(box, torso, 0.8, head_box=(42, 20, 53, 31))
    given = GivenPersonDetector()
    given.set([((0, 0, 10, 10), None, 1.0)])  # not used: the frame has its own people
    frame = replace(_frame(depth), people=(person, GivenPerson(box, None, 0.5)))
    placed, by_box = given.detect(frame)
    assert placed.position[0] == pytest.approx(2.5 + BODY_HALF_DEPTH, abs=0.01)  # the body
    assert (placed.box, placed.head_box, placed.score) == (box, (42, 20, 53, 31), 0.8)
    assert placed.keypoints == torso
    assert by_box.position[0] == pytest.approx(9.0 + BODY_HALF_DEPTH, abs=0.01)  # no keypoints
    assert given.detect(replace(frame, people=())) == []  # the source found nobody
    # torso keypoints without depth (or outside the image): the box's central depth
    hole = depth.copy()
    hole[30:90, 40:56] = np.inf
    (fallback,) = given.detect(replace(_frame(hole), people=(person,)))
    assert fallback.position[0] == pytest.approx(9.0 + BODY_HALF_DEPTH, abs=0.01)
    outside = GivenPerson(box, {"neck": (-5.0, 40.0), "mid_hip": (200.0, 70.0)})
    (far,) = given.detect(replace(frame, people=(outside,)))
    assert far.position[0] == pytest.approx(9.0 + BODY_HALF_DEPTH, abs=0.01)
    # without people on the frame, set() gives them (also as GivenPerson values)
    given.set([person])
    (again,) = given.detect(_frame(depth))
    assert again.position == placed.position


def test_non_max_suppression_keeps_the_best_of_overlapping_boxes() -> None:
    boxes = np.array([[0, 0, 10, 20], [1, 1, 11, 21], [30, 0, 40, 20]])
    assert non_max_suppression(boxes, np.array([0.5, 0.9, 0.1]), 0.4) == [1, 2]
    assert non_max_suppression(boxes, np.array([0.5, 0.9, 0.1]), 0.99) == [1, 0, 2]


def test_make_detector_auto_picks_mask_with_a_mask_else_hog() -> None:
    depth = np.full((H, W), 2.0)
    with_mask = _frame(depth, np.full((H, W), -1, np.int32))
    assert isinstance(make_detector("auto", with_mask, instances={1: 0}), MaskPersonDetector)
    assert isinstance(make_detector("mask", instances={1: 0}), MaskPersonDetector)
    with pytest.raises(ValueError, match="instance"):
        make_detector("mask")
    if hog_available():
        assert isinstance(make_detector("auto", _frame(depth)), HogPersonDetector)
    else:
        with pytest.raises(RuntimeError, match="HOG"):
            make_detector("auto", _frame(depth))


def _reference_detect(det: MaskPersonDetector, frame: RgbdFrame) -> list[tuple]:
    """The mask detector written plainly, one full-image pass per person (no lookup tables, no
    sort): its detections as comparable tuples."""
    from pfctl.core.perception.vision import _PARTS, _bbox

    assert frame.mask is not None
    ids = {int(b): i for b, i in det.instances.items()}
    inst = np.vectorize(lambda b: ids.get(int(b), -1))(frame.mask)
    part = np.vectorize(lambda b: _PARTS.get(det.parts.get(int(b), ""), 0))(frame.mask)
    out = []
    for k in np.unique(inst[inst >= 0]):
        body = inst == k
        vs, us = np.nonzero(body)
        if len(us) < det.min_pixels:
            continue
        position = body_position(frame, us, vs)
        if position is None:
            continue
        head_box, kp = None, None
        if det.parts:
            pix = {n: np.nonzero(body & (part == c)) for n, c in _PARTS.items()}
            kp = {}
            if len(pix["head"][0]):
                hv, hu = pix["head"]
                head_box = _bbox(hu, hv)
                kp["head"] = (float(np.mean(hu)), float(np.mean(hv)))
            if len(pix["torso"][0]):
                tv, tu = pix["torso"]
                kp["neck"] = (float(np.median(tu)), float(tv.min()))
                kp["mid_hip"] = (float(np.median(tu)), float(tv.max()))
            if len(pix["leg"][0]):
                lv, lu = pix["leg"]
                kp["ankles"] = (float(np.median(lu)), float(lv.max()))
            kp = kp or None
        out.append((int(k), _bbox(us, vs), position, head_box, kp, body.tobytes()))
    return out


def test_mask_detector_equals_the_plain_per_person_passes() -> None:
    """The lookup-table detector finds the same people with the same boxes, positions (bit for
    bit), keypoints and masks as one pass per person, on random crowded masks: bodies of
    several instances and parts, furniture ids above and below theirs, -1, missing depth."""
    rng = np.random.default_rng(11)
    bodies = {10: 0, 11: 0, 12: 0, 30: 1, 31: 1, 5: 2, 6: 2, 7: 2, 40: 4}
    parts = {10: "head", 11: "torso", 12: "leg", 30: "head", 31: "torso", 5: "leg", 40: "torso"}
    found = 0
    for trial in range(40):
        mask = np.full((H, W), -1, np.int32)
        depth = rng.uniform(1.0, 6.0, (H, W))
        depth[rng.random((H, W)) < 0.1] = np.inf
        for _ in range(int(rng.integers(0, 12))):
            u, v = int(rng.integers(0, W - 5)), int(rng.integers(0, H - 5))
            du, dv = int(rng.integers(3, 50)), int(rng.integers(3, 70))
            mask[v : v + dv, u : u + du] = rng.choice([*bodies, 0, 3, 99, 1000, 2**30])
        if trial % 3 == 1:
            mask = mask.astype(np.int64)
        elif trial % 3 == 2:
            mask = np.where(mask < 0, -1, mask % 128).astype(np.int16)
        frame = _frame(depth, mask)
        for det in (
            MaskPersonDetector(bodies, parts, min_pixels=int(rng.integers(1, 200))),
            MaskPersonDetector(bodies, min_pixels=50),
        ):
            got = [
                (d.instance, d.box, d.position, d.head_box, d.keypoints, d.mask.tobytes())
                for d in det.detect(frame)
                if d.mask is not None
            ]
            assert got == _reference_detect(det, frame), trial
            found += len(got)
    assert found > 100


def _plain_pixels_to_map(frame: RgbdFrame, us: np.ndarray, vs: np.ndarray) -> np.ndarray:
    """:func:`pixels_to_map` as first written (stacked columns, broadcast translation)."""
    z = frame.depth[vs, us].astype(float)
    ok = np.isfinite(z) & (z > 0)
    info = frame.info
    z, u, v = z[ok], us[ok].astype(float), vs[ok].astype(float)
    cam = np.column_stack(((u - info.cx) * z / info.fx, (v - info.cy) * z / info.fy, z))
    return cam @ np.asarray(frame.camera_rotation, dtype=float).T + np.asarray(
        frame.camera_position, dtype=float
    )


def test_back_projection_and_medians_equal_the_plain_formulas_bit_for_bit() -> None:
    """The in-place back-projection, the per-column medians of the body position and the
    counted median of the torso's and legs' columns give the numbers of the plain formulas
    (column_stack, ``numpy.median`` over axis 0 and of the columns), on random camera poses,
    depths with holes and pixel sets of odd and even sizes."""
    from pfctl.core.perception.vision import _int_median

    rng = np.random.default_rng(17)
    for trial in range(60):
        q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        depth = rng.uniform(0.3, 9.0, (H, W))
        depth[rng.random((H, W)) < 0.05] = [np.inf, 0.0, np.nan][trial % 3]
        frame = replace(
            _frame(depth), camera_rotation=q, camera_position=tuple(rng.uniform(-5, 5, 3))
        )
        n = int(rng.integers(1, 4000))
        us, vs = rng.integers(0, W, n), rng.integers(0, H, n)
        pts = pixels_to_map(frame, us, vs)
        want = _plain_pixels_to_map(frame, us, vs)
        assert pts.shape == want.shape and np.array_equal(pts, want), trial
        got = body_position(frame, us, vs, 0.0)
        assert got == tuple(float(v) for v in np.median(want, axis=0)), trial
        assert _int_median(us) == float(np.median(us)), trial
        assert _int_median(us[: max(1, n - 1)]) == float(np.median(us[: max(1, n - 1)]))
