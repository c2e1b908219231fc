"""Reading ROS bags (rosbags) as core values, with one-line errors naming the bag."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from pfctl.bags.reading import LASER_SCAN, BagError, open_bag, read_scans
from pfctl.errors import UserError

ROOT = Path(__file__).resolve().parents[2]
LEGS = ROOT.parent / "shared" / "data" / "legs"
needs_legs = pytest.mark.skipif(
    not (LEGS / "positive_2_extracted.bag").is_file(), reason=f"no real leg bags in {LEGS}"
)


def test_missing_and_corrupt_bags_are_user_errors(tmp_path: Path) -> None:
    with pytest.raises(UserError, match=r"nope.bag: no such bag file"):
        open_bag(tmp_path / "nope.bag")
    bad = tmp_path / "bad.bag"
    bad.write_bytes(b"#ROSBAG V2.0\n garbage")
    with pytest.raises(BagError, match=r"bad.bag: cannot read the bag") as err:
        open_bag(bad)
    assert "\n" not in str(err.value)


@needs_legs
def test_real_bag_scans_and_labels() -> None:
    path = LEGS / "positive_2_extracted.bag"
    with open_bag(path) as bag:
        assert bag.topics["/training_scan"] == LASER_SCAN
        assert bag.count("/training_scan") == 83
        frame, scan = next(bag.scans("/training_scan"))
        labels = next(bag.pose_arrays("/leg_cluster_positions"))
        with pytest.raises(UserError, match=r"no topic /scan; the bag has: /leg_cluster_positions"):
            bag.require("/scan")
        with pytest.raises(UserError, match="is geometry_msgs/msg/PoseArray, expected"):
            list(bag.scans("/leg_cluster_positions"))
    assert frame == "right_laser"
    assert len(scan.ranges) == 768 and scan.pose.x == 0.0
    assert np.isfinite(scan.ranges).sum() > 100
    assert np.all(np.isinf(scan.ranges) | (scan.ranges >= scan.range_min))
    assert labels.frame_id == "right_laser" and labels.poses.shape[1] == 3
    assert len(read_scans(path, "/training_scan")) == 83
