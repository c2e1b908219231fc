"""Person keypoints (``backend.hsr.person_keypoints``, a ``sensor_msgs/PointCloud`` of 2-D
keypoints and boxes, :mod:`pfctl.bags.person_keypoints`): the message ⇄ people
conversion with the real ROS message classes, and the whole path over a private master —
``pfctl sim serve-hsr`` standing in for OpenPose, ``HsrRobot`` receiving frames that carry the
people, the GivenPersonDetector placing them where the simulator's truth has them (§II-E).
"""

from __future__ import annotations

import io
import math
import signal
import subprocess
from pathlib import Path

import numpy as np
import pytest

from pfctl.backends.hsr.robot import RobotDataError, frame_people
from pfctl.bags.person_keypoints import (
    BOX_BOTTOM_RIGHT,
    BOX_TOP_LEFT,
    cloud_message,
    given_person,
    people_from_cloud,
    read_cloud,
)
from pfctl.core.robot import GivenPerson
from tests.backends.hsr.conftest import RosMaster
from tests.backends.hsr.test_robot import Output
from tests.backends.hsr.test_sim_bridge import HOUSE, PFCTL, finish_bridge, wait_serving

pytestmark = [pytest.mark.ros, pytest.mark.sim, pytest.mark.usefixtures("ros")]

NODES = Path(__file__).parent / "nodes"
TOPIC = "/pfctl/person_keypoints"
SHAPE = (240, 320)
#: Horizontal distance (m) within which every person the GivenPersonDetector places from the
#: served keypoints lies from the simulator's truth at the frame's stamp, on the house's episode
#: held until the robot's first command (alice ahead of the robot, walking away). The test looks
#: at 10 frames; a loaded machine may skip some and reach later ones.
TRUTH_TOLERANCE = 0.12


def wire(msg):
    """``msg`` serialised and read back, as a subscriber receives it."""
    buf = io.BytesIO()
    msg.serialize(buf)
    out = type(msg)()
    out.deserialize(buf.getvalue())
    return out


def cloud(ros, people, header=None):
    sensor, geometry = ros["sensor_msgs.msg"], ros["geometry_msgs.msg"]
    header = header or ros["std_msgs.msg"].Header(frame_id="head_rgbd_sensor_rgb_frame")
    return wire(cloud_message(sensor, geometry, header, people))


def raw_cloud(ros, points, channels):
    """A PointCloud with the given points and ``{name: values}`` channels, as they are."""
    sensor, geometry = ros["sensor_msgs.msg"], ros["geometry_msgs.msg"]
    return sensor.PointCloud(
        points=[geometry.Point32(*p) for p in points],
        channels=[sensor.ChannelFloat32(name=k, values=v) for k, v in channels.items()],
    )


#: An OpenPose-like person (no box): nose, neck, shoulders, hips, ankles, eyes, ears;
#: a missing wrist (confidence 0, at 0, 0 as OpenPose writes it).
OPENPOSE = {
    0: (100.0, 40.0, 0.875),
    1: (100.0, 60.0, 0.75),
    2: (88.0, 61.0, 0.625),
    5: (112.0, 61.0, 0.625),
    4: (0.0, 0.0, 0.0),
    8: (100.0, 120.0, 0.75),
    9: (94.0, 120.0, 0.5),
    12: (106.0, 120.0, 0.5),
    11: (95.0, 200.0, 0.5),
    14: (105.0, 202.0, 0.5),
    15: (97.0, 37.0, 0.875),
    16: (103.0, 37.0, 0.875),
    17: (93.0, 40.0, 0.5),
    18: (107.0, 40.0, 0.5),
}
#: A detector that gives a box and two keypoints.
BOXED = {
    BOX_TOP_LEFT: (200.5, 20.0, 0.75),
    BOX_BOTTOM_RIGHT: (260.0, 230.25, 0.75),
    1: (230.0, 50.0, 0.5),
    8: (231.0, 120.0, 1.0),
}


def test_round_trip_through_the_message(ros):
    """Every point (found or not) comes back per person and part; stamp and frame kept."""
    header = ros["std_msgs.msg"].Header(frame_id="head_rgbd_sensor_rgb_frame")
    header.stamp.secs, header.stamp.nsecs = 101, 500_000_000
    msg = cloud(ros, {3: OPENPOSE, 0: BOXED}, header)
    assert msg.header.frame_id == "head_rgbd_sensor_rgb_frame"
    assert msg.header.stamp.to_nsec() == 101_500_000_000
    assert [c.name for c in msg.channels] == ["person", "part"]
    assert len(msg.points) == len(OPENPOSE) + len(BOXED)
    back = read_cloud(msg)
    assert back == {3: OPENPOSE, 0: BOXED}  # these values are exact in float32
    people = people_from_cloud(msg, SHAPE)
    assert people == (given_person(BOXED, SHAPE), given_person(OPENPOSE, SHAPE))
    assert people_from_cloud(cloud(ros, {}), SHAPE) == ()  # the detector found nobody


def test_decoded_people_have_core_names_boxes_and_head_boxes(ros):
    boxed = given_person(BOXED, SHAPE)
    assert boxed == GivenPerson(
        box=(200, 20, 260, 231),  # the corners, outwards to whole pixels
        keypoints={"neck": (230.0, 50.0), "mid_hip": (231.0, 120.0)},
        score=pytest.approx(0.75),  # the mean confidence, corners included
        head_box=None,
    )
    person = given_person(OPENPOSE, SHAPE)
    assert person is not None
    kp = person.keypoints
    assert kp is not None
    assert kp["head"] == pytest.approx((100.0, 38.8))  # nose, eyes and ears
    assert kp["neck"] == (100.0, 60.0) and kp["mid_hip"] == (100.0, 120.0)
    assert kp["ankles"] == (100.0, 201.0)
    assert (kp["right_shoulder"], kp["left_shoulder"]) == ((88.0, 61.0), (112.0, 61.0))
    assert (kp["right_hip"], kp["left_hip"]) == ((94.0, 120.0), (106.0, 120.0))
    assert person.score == pytest.approx(np.mean([c for _, _, c in OPENPOSE.values() if c > 0]))
    # the head box: centred on the head keypoint, half as wide as 0.6 x the ears' spread (14 px;
    # 0.35 x the 21 px to the neck is less), 1.2 times as tall as wide, outwards to pixels
    half = 0.6 * 14
    assert person.head_box == (
        math.floor(100 - half),
        math.floor(38.8 - 1.2 * half),
        math.ceil(100 + half),
        math.ceil(38.8 + 1.2 * half),
    )
    # the body box: the keypoints padded by 10 % of their height (eyes 37 to ankle 202)
    pad = 0.1 * (202 - 37)
    assert person.box == (
        math.floor(88 - pad),
        math.floor(37 - pad),
        math.ceil(112 + 1 + pad),
        math.ceil(202 + 1 + pad),
    )
    # clipped to the image; no mid_hip: the hips' mid-point; one ankle: that one
    near = {1: (5.0, 100.0, 1.0), 9: (0.0, 150.0, 1.0), 12: (10.0, 150.0, 1.0), 14: (4, 230, 1.0)}
    clipped = given_person(near, SHAPE)
    assert clipped is not None and clipped.box[0] == 0 and clipped.box[3] == SHAPE[0]
    assert clipped.keypoints["mid_hip"] == (5.0, 150.0)
    assert clipped.keypoints["ankles"] == (4.0, 230.0)
    assert clipped.head_box is None and "head" not in clipped.keypoints
    # too few keypoints found and no box: dropped; one corner is no box
    few = {0: (50.0, 50.0, 0.9), 1: (50.0, 70.0, 0.9), 8: (50.0, 120.0, 0.0)}
    assert given_person(few, SHAPE) is None
    assert given_person({**few, BOX_TOP_LEFT: (40.0, 30.0, 1.0)}, SHAPE) is None
    assert given_person({BOX_TOP_LEFT: (400.0, 0, 1), BOX_BOTTOM_RIGHT: (500, 9, 1)}, SHAPE) is None


@pytest.mark.parametrize(
    ("points", "channels", "expected"),
    [
        (
            [(1, 2, 1)],
            {"person": [0]},
            "expected channels 'person' and 'part' (one value per point), no 'part' among the "
            "channels ('person')",
        ),
        (
            [(1, 2, 1), (3, 4, 1)],
            {"person": [0, 0], "part": [1]},
            "expected one 'part' value per point (2 points), got 1 values",
        ),
        (
            [(1, 2, 1)],
            {"person": [0], "part": [27]},
            "expected part values a whole number in 0..26, got 27 at point 0",
        ),
        (
            [(1, 2, 1), (1, 2, 1)],
            {"person": [0, 0.5], "part": [1, 2]},
            "expected person values a whole number >= 0, got 0.5 at point 1",
        ),
        (
            [(1, 2, 1), (float("nan"), 2, 1)],
            {"person": [0, 0], "part": [1, 2]},
            "expected finite x (u), y (v) and z (confidence), got point 1 = (nan, 2, 1)",
        ),
        (
            [(1, 2, 1), (1, 2, 1)],
            {"person": [4, 4], "part": [8, 8]},
            "expected each part once per person, got part 8 of person 4 twice",
        ),
    ],
)
def test_malformed_messages_are_one_line_naming_the_topic(ros, points, channels, expected):
    msg = wire(raw_cloud(ros, points, channels))
    with pytest.raises(ValueError) as info:
        read_cloud(msg)
    assert str(info.value) == expected
    with pytest.raises(RobotDataError) as err:
        frame_people(msg, TOPIC, SHAPE)
    assert str(err.value) == f"{TOPIC}: {expected}"
    assert err.value.exit_code == 2 and "\n" not in str(err.value)


# ------------------------------------------------------------- over a master, with serve-hsr


def _mission(tmp: Path) -> Path:
    """The house with the keypoints as the person source (labels then unsubscribed)."""
    path = tmp / "house_keypoints.yaml"
    path.write_text(
        HOUSE.read_text() + f"\nbackend:\n  hsr:\n    person_keypoints: {TOPIC}\n",
        encoding="utf-8",
    )
    return path


def test_served_keypoints_place_people_where_the_truth_is(
    ros_master: RosMaster, ros_nodes, tmp_path
):
    """serve-hsr publishes the keypoints (and no labels) with the images' stamp; HsrRobot's
    frames carry the people; the GivenPersonDetector puts each within TRUTH_TOLERANCE of the
    simulator's truth at the frame's stamp."""
    mission = _mission(tmp_path)
    with (tmp_path / "bridge.out").open("wb") as out, (tmp_path / "bridge.err").open("wb") as err:
        bridge = subprocess.Popen(
            [PFCTL, "sim", "serve-hsr", str(mission), "--wait-for-command"],
            env=ros_master.env,
            stdin=subprocess.DEVNULL,
            stdout=out,
            stderr=err,
            start_new_session=True,
        )
    wait_serving(bridge, tmp_path)
    driver = Output(
        ros_nodes((NODES / "hsr_driver.py").read_text(), "people", "--keypoints", TOPIC)
    )
    got = driver.event("people", timeout=60.0)
    assert driver.finish() == 0, driver.lines[-10:]
    _, _, types = ros_master.proxy().getTopicTypes("/pytest")
    bridge.send_signal(signal.SIGINT)
    code, _, log = finish_bridge(bridge, tmp_path)
    assert code == 130, log  # Ctrl-C: served until then, one line (test_sim_bridge checks it)

    types = dict(types)
    assert types[TOPIC] == "sensor_msgs/PointCloud"
    assert "/pfctl/person_labels" not in types  # the keypoints are the person source
    assert got["detector"] == "GivenPersonDetector"
    frames = got["frames"]
    assert len(frames) >= 10
    assert not any(f["mask"] for f in frames) and all(f["given"] is not None for f in frames)
    errors = []
    for f in frames:
        assert len(f["detected"]) == len(f["given"]) >= 1
        for person in f["given"]:
            assert {"head", "neck", "mid_hip"} <= set(person["keypoints"])
            assert person["score"] == 1.0
        if f["truth"] is None:
            continue
        for x, y, _ in f["detected"]:
            errors.append(min(math.hypot(x - tx, y - ty) for _, tx, ty in f["truth"]))
    print(
        f"keypoints vs truth: {len(errors)} people in {len(frames)} frames, "
        f"max {max(errors):.3f} m, median {float(np.median(errors)):.3f} m"
    )
    assert len(errors) >= 5
    assert max(errors) < TRUTH_TOLERANCE and float(np.median(errors)) < 0.06
