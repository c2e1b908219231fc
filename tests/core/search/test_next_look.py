"""Where to look next (issue 22, item 3): the likely room's doorway first, inside it (the parts
not seen) after, and unlikely rooms not toured while a likely one is unseen."""

from __future__ import annotations

import numpy as np
import pytest

from pfctl.core.mapping.regions import RegionMap
from pfctl.core.search.next_look import STEP_IN, doorway, rank_looks
from pfctl.core.search.whereabouts import Whereabouts
from tests.core.search.test_whereabouts import GEOMETRY, HOME, PARAMS


@pytest.fixture
def lost_heading_east() -> Whereabouts:
    wb = Whereabouts(RegionMap(HOME), GEOMETRY, np.ones(GEOMETRY.shape, dtype=bool), PARAMS)
    wb.lost(0.0, (6.5, 1.0), heading="east", came_from="west")
    return wb


def test_the_doorway_is_on_the_way_through_the_doors() -> None:
    regions = RegionMap(HOME)
    point, length = doorway(regions, (1.5, 4.0), "east")  # type: ignore[misc]
    assert point == (7.5, 2.0)
    assert length == pytest.approx(2.0 + 6.0)  # to west's door, then along to east's
    assert doorway(regions, (7.5, 4.0), "east") is None  # already in it


def test_the_next_place_is_the_likely_rooms_doorway_first(lost_heading_east: Whereabouts) -> None:
    wb = lost_heading_east
    wb.observe(8.0, wb.labels == wb.regions.names.index("corridor"))  # the robot's own corridor
    looks = rank_looks(wb, 8.0, (2.0, 1.0), robot_speed=0.22, look_s=6.0)
    best = looks[0]
    assert (best.region, best.kind) == ("east", "doorway")
    assert best.viewpoint == (7.5, 2.0 + STEP_IN)  # a step into the room from its door
    assert best.score == pytest.approx(best.probability / (best.drive_s + 6.0))
    # the unlikely west room behind the robot is no candidate while east is unseen
    assert "west" not in {lk.region for lk in looks}


def test_after_the_doorway_it_looks_inside_at_what_was_not_seen(
    lost_heading_east: Whereabouts,
) -> None:
    wb = lost_heading_east
    east = wb.labels == wb.regions.names.index("east")
    seen = east & (wb.geometry.cell_to_world(*np.indices(GEOMETRY.shape))[..., 0] > 7.0)
    wb.observe(8.0, seen)  # from the door the camera saw the room's east part only
    looks = rank_looks(wb, 8.0, (7.5, 2.0), robot_speed=0.22, look_s=6.0, looked_from_door={"east"})
    inside = next(lk for lk in looks if lk.region == "east")
    assert inside.kind == "inside" and inside.viewpoint[0] < 7.0 and inside.viewpoint[1] > 2.0
