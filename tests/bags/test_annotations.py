"""Annotated people (``leg_tracker/Person``) read from a bag: grouped per annotated scan, each
group paired with the last scan recorded before it; bad topics are one line naming the bag."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from rosbags.rosbag1 import Writer
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

from pfctl.bags.annotations import nearest_scan, read_annotations
from pfctl.bags.reading import BagError, open_bag

PEOPLE = "/ground_truth_people_tracks"
PERSON_MSG = "geometry_msgs/Pose pose\nuint32 id\n"
#: Scan k → the people annotated on it: (id, x, y) in the laser frame.
ANNOTATED = {2: [(1, 2.0, 0.5)], 3: [(1, 2.0, 0.6), (2, 3.0, -1.0)], 7: [(2, 3.1, -0.9)]}


def scan_ns(k: int) -> int:
    """Header stamp of scan ``k`` of :func:`write_annotated_bag`, ns."""
    return 10**9 + k * 10**8


def write_annotated_bag(path: Path) -> int:
    """A bag of 10 empty scans (10 Hz, frame ``laser``) with :data:`ANNOTATED` people, each
    annotation recorded 67 ms after its scan's stamp, after the scan is recorded, as in Leigh's
    bags (so the next scan's stamp is the nearer one); returns the number of annotations."""
    store = get_typestore(Stores.ROS1_NOETIC)
    store.register(get_types_from_msg(PERSON_MSG, "leg_tracker/msg/Person"))
    t = store.types
    topics = {"/scan": "sensor_msgs/msg/LaserScan", PEOPLE: "leg_tracker/msg/Person"}
    with Writer(path) as writer:
        conns = {k: writer.add_connection(k, v, typestore=store) for k, v in topics.items()}
        for i in range(10):
            ns = scan_ns(i)
            stamp = t["builtin_interfaces/msg/Time"](sec=ns // 10**9, nanosec=ns % 10**9)
            scan = t["sensor_msgs/msg/LaserScan"](
                header=t["std_msgs/msg/Header"](seq=i, stamp=stamp, frame_id="laser"),
                angle_min=-2.0,
                angle_max=2.0,
                angle_increment=0.01,
                time_increment=0.0,
                scan_time=0.1,
                range_min=0.1,
                range_max=10.0,
                ranges=np.full(401, np.inf, np.float32),
                intensities=np.zeros(0, np.float32),
            )
            writer.write(conns["/scan"], ns + 10**6, store.serialize_ros1(scan, topics["/scan"]))
            for pid, x, y in ANNOTATED.get(i, []):
                pose = t["geometry_msgs/msg/Pose"](
                    t["geometry_msgs/msg/Point"](x, y, 0.0),
                    t["geometry_msgs/msg/Quaternion"](0.0, 0.0, 0.0, 1.0),
                )
                msg = t["leg_tracker/msg/Person"](pose=pose, id=pid)
                raw = store.serialize_ros1(msg, topics[PEOPLE])
                writer.write(conns[PEOPLE], ns + 67 * 10**6, raw)
    return sum(len(v) for v in ANNOTATED.values())


def test_annotations_are_grouped_per_scan_and_paired_with_the_scan_before_them(
    tmp_path: Path,
) -> None:
    path = tmp_path / "a.bag"
    write_annotated_bag(path)
    with open_bag(path) as bag:
        groups = read_annotations(bag, PEOPLE, "/scan")
    assert [g.ids for g in groups] == [(1,), (1, 2), (2,)]
    assert [g.scan_stamp for g in groups] == [pytest.approx(scan_ns(k) * 1e-9) for k in (2, 3, 7)]
    np.testing.assert_allclose(groups[1].xy, [[2.0, 0.6], [3.0, -1.0]])


def test_a_topic_of_another_type_or_missing_is_one_line_naming_the_bag(tmp_path: Path) -> None:
    path = tmp_path / "a.bag"
    write_annotated_bag(path)
    with open_bag(path) as bag:
        with pytest.raises(BagError, match=r"a\.bag: topic /scan is sensor_msgs/msg/LaserScan, "):
            read_annotations(bag, "/scan", "/scan")
        with pytest.raises(BagError, match=r"a\.bag: no topic /people; the bag has: "):
            read_annotations(bag, "/people", "/scan")


def test_nearest_scan_within_a_tolerance() -> None:
    assert nearest_scan([0.0, 0.1, 0.2], 0.12, 0.05) == 1
    assert nearest_scan([0.0, 0.1, 0.2], 0.16, 0.05) == 2
    assert nearest_scan([0.0, 0.1, 0.2], 0.5, 0.05) is None
    assert nearest_scan([], 0.0, 1.0) is None
