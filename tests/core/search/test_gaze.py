"""The search's gaze at the unseen places in sight: into the room whose door the robot is at,
then elsewhere once that room is seen; only bearings the head can pan to; nothing while the
belief rests."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pfctl.core.mapping.regions import RegionMap
from pfctl.core.perception.belief import visible_mask
from pfctl.core.perception.tracking import FieldOfView
from pfctl.core.robot import Pose2D
from pfctl.core.search.gaze import UnseenGaze
from pfctl.core.search.whereabouts import Whereabouts
from tests.core.search.test_whereabouts import GEOMETRY, HOME, PARAMS

HSR_PAN = (-3.84, 1.75)
CAMERA = (math.radians(58.0), (0.4, 8.0))


def _walls() -> np.ndarray:
    """The walls of ``HOME``: between the corridor and the rooms (but the doors) and between
    the rooms, one cell thick."""
    xy = GEOMETRY.cell_to_world(*np.indices(GEOMETRY.shape))
    x, y = xy[..., 0], xy[..., 1]
    along = np.abs(y - 2.0) < 0.05
    doors = ((x > 1) & (x < 2)) | ((x > 4) & (x < 5)) | ((x > 7) & (x < 8))
    between = ((np.abs(x - 3.0) < 0.05) | (np.abs(x - 6.0) < 0.05)) & (y > 2) & (y < 5)
    outside = (x > 9.05) | (y > 5.05) | (y < -0.05)
    return (along & ~doors) | between | outside


@pytest.fixture
def searching() -> Whereabouts:
    """Nobody seen yet, the robot in the corridor; the corridor itself already looked at."""
    wb = Whereabouts(RegionMap(HOME), GEOMETRY, ~_walls(), PARAMS)
    wb.never_seen(0.0, (4.5, 1.0))
    wb.observe(0.0, wb.labels == wb.regions.names.index("corridor"))
    return wb


def _room(wb: Whereabouts, xy: tuple[float, float] | None) -> str | None:
    return None if xy is None else wb.regions.locate(xy)


def test_at_a_door_the_head_looks_into_the_room_then_elsewhere_once_it_is_seen(
    searching: Whereabouts,
) -> None:
    wb = searching
    gaze = UnseenGaze(wb, _walls(), HSR_PAN)
    pose = Pose2D(4.5, 1.0, 0.0)  # at the mid room's door, driving east along the corridor
    first = gaze.point(1.0, pose, *CAMERA)
    assert _room(wb, first) == "mid"
    assert first is not None and abs(math.atan2(first[1] - 1.0, first[0] - 4.5) - math.pi / 2) < 0.3
    assert gaze.point(1.2, pose, *CAMERA) == first  # kept between decisions
    # the camera looked into the mid room through its door: it is seen, the head moves on
    into_mid = FieldOfView(Pose2D(4.5, 1.0, math.pi / 2), CAMERA[0] / 2, *CAMERA[1])
    wb.observe(1.5, visible_mask(GEOMETRY, into_mid, _walls()))
    after = gaze.point(1.6, pose, *CAMERA)
    assert after is not None
    bearing = math.atan2(after[1] - 1.0, after[0] - 4.5)
    assert abs(bearing - math.pi / 2) > CAMERA[0] / 2  # no longer into the mid room


def test_only_bearings_the_head_can_pan_to_are_looked_at(searching: Whereabouts) -> None:
    pose = Pose2D(4.5, 1.0, 0.0)
    narrow = UnseenGaze(searching, _walls(), (-0.3, 0.3))  # the mid door is 90° to the left
    point = narrow.point(1.0, pose, *CAMERA)
    assert point is not None  # the east room, through its door 20° to the left
    assert abs(math.atan2(point[1] - 1.0, point[0] - 4.5)) <= 0.3 + 2 * math.pi / 72


def test_nothing_to_look_at_while_the_belief_rests(searching: Whereabouts) -> None:
    gaze = UnseenGaze(searching, _walls(), HSR_PAN)
    pose = Pose2D(4.5, 1.0, 0.0)
    assert gaze.point(1.0, pose, *CAMERA) is not None
    searching.found()
    assert gaze.point(1.1, pose, *CAMERA) is None
    assert gaze.point(5.0, pose, *CAMERA) is None
