"""Where can she be (issue 22, item 2): the belief over regions spreads along doors with time and
not through walls, follows her heading, and a room seen empty loses its mass."""

from __future__ import annotations

import numpy as np
import pytest

from pfctl.core.mapping.grid import GridGeometry
from pfctl.core.mapping.house import Door, HouseLayout, Region
from pfctl.core.mapping.regions import RegionMap
from pfctl.core.search.whereabouts import Whereabouts, WhereaboutsParams, spread

# A corridor (y 0-2) with three rooms off it (y 2-5) that share walls but no doors with each
# other, and a shed reached from nowhere.
HOME = HouseLayout(
    regions=(
        Region("corridor", ((0, 0), (9, 0), (9, 2), (0, 2))),
        Region("west", ((0, 2), (3, 2), (3, 5), (0, 5))),
        Region("mid", ((3, 2), (6, 2), (6, 5), (3, 5))),
        Region("east", ((6, 2), (9, 2), (9, 5), (6, 5))),
        Region("shed", ((20, 0), (22, 0), (22, 2), (20, 2))),
    ),
    doors=(
        Door(("corridor", "west"), ((1, 2), (2, 2))),
        Door(("corridor", "mid"), ((4, 2), (5, 2))),
        Door(("corridor", "east"), ((7, 2), (8, 2))),
    ),
)
PARAMS = WhereaboutsParams()
GEOMETRY = GridGeometry(0.1, 230, 60, (0.0, -0.5))


@pytest.fixture(scope="module")
def regions() -> RegionMap:
    return RegionMap(HOME)


def test_at_the_loss_she_is_in_her_own_room(regions: RegionMap) -> None:
    assert spread(regions, (1.5, 4.0), 0.0, PARAMS) == {"west": pytest.approx(1.0)}


def test_the_belief_spreads_along_doors_with_time_not_through_walls(regions: RegionMap) -> None:
    start = (1.5, 4.0)  # in the west room; mid is 1.5 m away through the wall, 5 m by the doors
    early = spread(regions, start, 3.0 / PARAMS.walking_speed, PARAMS)
    assert early["corridor"] > 0.0 and "mid" not in early and "east" not in early
    later = spread(regions, start, 20.0, PARAMS)
    assert later["mid"] > 0.0 and later["east"] > 0.0
    assert later["west"] < early["west"]  # she has had time to leave
    assert "shed" not in later  # no door leads there
    assert sum(later.values()) == pytest.approx(1.0)


def test_the_door_she_was_approaching_gets_more_than_the_one_behind_her(
    regions: RegionMap,
) -> None:
    p = spread(regions, (4.5, 1.0), 10.0, PARAMS, heading="east", came_from="west")
    assert p["east"] > p["mid"] > p["west"]


def test_a_room_seen_empty_loses_its_mass_and_the_others_gain(regions: RegionMap) -> None:
    wb = Whereabouts(regions, GEOMETRY, np.ones(GEOMETRY.shape, dtype=bool), PARAMS)
    wb.lost(0.0, (4.5, 1.0), heading="east")
    before = wb.probabilities(10.0)
    east = wb.labels == regions.names.index("east")
    wb.observe(10.0, east)
    after = wb.probabilities(10.0)
    assert after["east"] < 0.25 * before["east"]
    assert all(after[r] > before[r] for r in ("corridor", "west", "mid"))
    assert sum(after.values()) == pytest.approx(1.0)
    # later only what can have walked in since comes back, not the mass that was seen
    assert wb.probabilities(60.0)["east"] < wb.prior(60.0)["east"] - 0.15
    # the cells: the seen room's mass is gone from them, the rest sums to one
    cells = wb.cell_probabilities(10.0)
    assert cells.sum() == pytest.approx(1.0) and cells[east].sum() == pytest.approx(after["east"])


def test_a_target_never_seen_is_anywhere_the_robot_can_reach_alike(regions: RegionMap) -> None:
    wb = Whereabouts(regions, GEOMETRY, np.ones(GEOMETRY.shape, dtype=bool), PARAMS)
    wb.never_seen(0.0, (4.5, 1.0))
    p = wb.probabilities(30.0)
    assert set(p) == {"corridor", "west", "mid", "east"}
    assert all(v == pytest.approx(0.25) for v in p.values())


def test_a_room_seen_before_she_could_reach_it_fills_again(regions: RegionMap) -> None:
    wb = Whereabouts(regions, GEOMETRY, np.ones(GEOMETRY.shape, dtype=bool), PARAMS)
    wb.lost(0.0, (1.5, 4.0))  # in the west room; east is 9 m away by the doors
    east = wb.labels == wb.regions.names.index("east")
    wb.observe(1.0, east)
    assert wb.probabilities(1.0).get("east", 0.0) == pytest.approx(0.0)
    later = wb.probabilities(60.0)["east"]
    assert later > 0.5 * wb.prior(60.0)["east"]


def test_just_in_through_the_only_door_she_is_most_likely_still_in_there(
    regions: RegionMap,
) -> None:
    p = spread(regions, (1.5, 2.5), 5.0, PARAMS, came_from="corridor")
    assert max(p, key=p.__getitem__) == "west"
