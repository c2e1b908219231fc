"""``pfctl replay`` of a bag whose people come as person keypoints (``/pfctl/person_keypoints``,
``sensor_msgs/PointCloud``, :mod:`pfctl.bags.person_keypoints`) and not as a label image:
the frames carry the people, and the GivenPersonDetector places them by the depth (§II-E).

The bag is written here with ``rosbags`` (no ROS needed): a laser looking back at nothing, a
camera 1 m above the map origin looking along +x, and one person standing 2.5 m ahead whom only
the keypoints name (the colour image is black: no image detector would find them).
"""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np
import pytest
from rosbags.rosbag1 import Writer
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

from pfctl.bags.person_keypoints import BOX_BOTTOM_RIGHT, BOX_TOP_LEFT, cloud_fields
from pfctl.bags.replay import open_replay
from pfctl.core.robot import RgbdFrame
from pfctl.errors import UserError
from tests.conftest import run_cli

W, H, F = 160, 120, 100.0
RGB, DEPTH, INFO = (
    "/hsrb/head_rgbd_sensor/rgb/image_rect_color",
    "/hsrb/head_rgbd_sensor/depth_registered/image_rect_raw",
    "/hsrb/head_rgbd_sensor/rgb/camera_info",
)
KEYPOINTS = "/pfctl/person_keypoints"
#: The camera's optical frame in the map: x right = -y, y down = -z, z forward = +x.
LOOK_X_QUATERNION = (-0.5, 0.5, -0.5, 0.5)
PERSON = {  # box and torso of a person at columns 70-90, rows 20-110
    BOX_TOP_LEFT: (70.0, 20.0, 0.75),
    BOX_BOTTOM_RIGHT: (90.0, 110.0, 0.75),
    1: (80.0, 35.0, 0.75),
    8: (80.0, 70.0, 0.75),
}


def _write_bag(path: Path, people: dict[int, dict[int, tuple[float, float, float]]]) -> None:
    store = get_typestore(Stores.ROS1_NOETIC)
    store.register(
        get_types_from_msg(
            "geometry_msgs/TransformStamped[] transforms\n", "tf2_msgs/msg/TFMessage"
        )
    )
    t = store.types
    topics = {
        "/scan": "sensor_msgs/msg/LaserScan",
        "/tf_static": "tf2_msgs/msg/TFMessage",
        RGB: "sensor_msgs/msg/Image",
        DEPTH: "sensor_msgs/msg/Image",
        INFO: "sensor_msgs/msg/CameraInfo",
        KEYPOINTS: "sensor_msgs/msg/PointCloud",
    }

    def header(ns: int, frame: str):
        stamp = t["builtin_interfaces/msg/Time"](sec=ns // 10**9, nanosec=ns % 10**9)
        return t["std_msgs/msg/Header"](seq=0, stamp=stamp, frame_id=frame)

    def transform(parent: str, child: str, xyz, quat):
        return t["geometry_msgs/msg/TransformStamped"](
            header=header(10**9, parent),
            child_frame_id=child,
            transform=t["geometry_msgs/msg/Transform"](
                translation=t["geometry_msgs/msg/Vector3"](*xyz),
                rotation=t["geometry_msgs/msg/Quaternion"](*quat),
            ),
        )

    depth = np.full((H, W), 6.0, np.float32)  # a wall 6 m ahead
    depth[20:110, 70:90] = 2.5  # the person
    points, person, part = cloud_fields(people)
    with Writer(path) as writer:
        conns = {k: writer.add_connection(k, v, typestore=store) for k, v in topics.items()}

        def write(topic: str, ns: int, msg) -> None:
            writer.write(conns[topic], ns, store.serialize_ros1(msg, topics[topic]))

        static = [
            transform("map", "laser", (0.0, 0.0, 0.3), (0.0, 0.0, 0.0, 1.0)),
            transform("map", "camera", (0.0, 0.0, 1.0), LOOK_X_QUATERNION),
        ]
        write("/tf_static", 10**9, t["tf2_msgs/msg/TFMessage"](transforms=static))
        for i in range(20):
            ns = 10**9 + i * 10**8
            scan = t["sensor_msgs/msg/LaserScan"](
                header=header(ns, "laser"),
                angle_min=2.0,  # behind the robot: the person is the camera's alone
                angle_max=4.0,
                angle_increment=0.01,
                time_increment=0.0,
                scan_time=0.1,
                range_min=0.1,
                range_max=10.0,
                ranges=np.full(201, np.inf, np.float32),
                intensities=np.zeros(0, np.float32),
            )
            write("/scan", ns, scan)
            image = t["sensor_msgs/msg/Image"]
            write(
                RGB,
                ns,
                image(header(ns, "camera"), H, W, "rgb8", 0, 3 * W, np.zeros(H * W * 3, np.uint8)),
            )
            write(
                DEPTH,
                ns,
                image(
                    header(ns, "camera"), H, W, "32FC1", 0, 4 * W, depth.reshape(-1).view(np.uint8)
                ),
            )
            k = np.array([F, 0, W / 2 - 0.5, 0, F, H / 2 - 0.5, 0, 0, 1], np.float64)
            info = t["sensor_msgs/msg/CameraInfo"](
                header=header(ns, "camera"),
                height=H,
                width=W,
                distortion_model="plumb_bob",
                D=np.zeros(5),
                K=k,
                R=np.eye(3).reshape(-1),
                P=np.zeros(12),
                binning_x=0,
                binning_y=0,
                roi=t["sensor_msgs/msg/RegionOfInterest"](
                    x_offset=0, y_offset=0, height=0, width=0, do_rectify=False
                ),
            )
            write(INFO, ns, info)
            cloud = t["sensor_msgs/msg/PointCloud"](
                header=header(ns, "camera"),
                points=[t["geometry_msgs/msg/Point32"](*p) for p in points],
                channels=[
                    t["sensor_msgs/msg/ChannelFloat32"](name, np.array(values, np.float32))
                    for name, values in (("person", person), ("part", part))
                ],
            )
            write(KEYPOINTS, ns, cloud)


def test_replay_places_the_keypoints_people_by_the_depth(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    bag = tmp_path / "keypoints.bag"
    _write_bag(bag, {0: PERSON})
    source = open_replay(bag)
    with source.bag:
        assert source.camera is not None
        assert (source.camera.labels, source.camera.keypoints) == (None, KEYPOINTS)
        frames = [f for f in source.stream() if isinstance(f, RgbdFrame)]
    assert len(frames) == 20
    assert all(f.mask is None and f.people is not None and len(f.people) == 1 for f in frames)
    (person,) = frames[0].people
    assert person.box == (70, 20, 90, 110) and person.score == 0.75
    assert person.keypoints == {"neck": (80.0, 35.0), "mid_hip": (80.0, 70.0)}

    code, out, err = run_cli(
        ["replay", str(bag), "--out", str(tmp_path / "out")], capsys, monkeypatch
    )
    assert code == 0, err
    assert "20 camera frames" in out
    with (tmp_path / "out" / "tracks.csv").open() as f:
        rows = list(csv.DictReader(f))
    assert rows  # only the keypoints saw the person (a black image; the laser looks back)
    for row in rows:  # 2.5 m ahead of the camera, pushed half a body back, on the axis
        assert math.hypot(float(row["x"]) - 2.6, float(row["y"])) < 0.05, row


def test_a_malformed_keypoints_message_in_a_bag_is_one_line(tmp_path: Path) -> None:
    bag = tmp_path / "bad.bag"
    _write_bag(bag, {0: {**PERSON, 30: (1.0, 1.0, 1.0)}})
    source = open_replay(bag)
    with source.bag, pytest.raises(UserError) as info:
        list(source.stream())
    assert str(info.value) == (
        f"{bag}: {KEYPOINTS}: expected part values a whole number in 0..26, got 30 at point 4"
    )
