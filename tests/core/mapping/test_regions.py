"""The region map of the shipped house (§II-B) and Algorithm 1 (way-point search)."""

from __future__ import annotations

import math

import networkx as nx
import numpy as np
import pytest
import shapely
from shapely.geometry import LineString
from shapely.ops import unary_union

from pfctl.core.mapping.frontiers import utility
from pfctl.core.mapping.grid import OccupancyGrid
from pfctl.core.mapping.house import Door, HouseLayout, Region
from pfctl.core.mapping.paths import distance_fields, traversability
from pfctl.core.mapping.regions import RegionMap, heading_region, heading_scores, waypoint_search

# missions/house.yaml, map.regions and map.doors (copied, not loaded: the mission models are
# written elsewhere).
HOUSE = HouseLayout(
    regions=(
        Region("kitchen", ((0, 0), (5, 0), (5, 4), (0, 4))),
        Region("living_room", ((5, 0), (12, 0), (12, 4), (5, 4))),
        Region("hall", ((0, 4), (12, 4), (12, 6), (0, 6))),
        Region("office", ((0, 6), (6, 6), (6, 9), (0, 9))),
        Region("bedroom", ((6, 6), (12, 6), (12, 9), (6, 9))),
    ),
    doors=(
        Door(("kitchen", "living_room"), ((5, 1.5), (5, 2.4))),
        Door(("kitchen", "hall"), ((2.0, 4), (2.9, 4))),
        Door(("living_room", "hall"), ((8.5, 4), (9.4, 4))),
        Door(("hall", "office"), ((3.5, 6), (4.4, 6))),
        Door(("hall", "bedroom"), ((9.0, 6), (9.9, 6))),
    ),
)
RES = 0.05
SEARCH = dict(alpha=0.05, beta=1.0, frontier_threshold=0.1, min_frontier_cells=5, window_s=3.0)


@pytest.fixture(scope="module")
def rmap() -> RegionMap:
    return RegionMap(HOUSE)


def _walk(start: tuple[float, float], end: tuple[float, float], seconds: float = 3.0, hz=10):
    """A straight walk as (t, x, y) samples at ``hz``."""
    n = int(seconds * hz) + 1
    t = np.linspace(0.0, seconds, n)
    xy = np.linspace(start, end, n)
    return np.column_stack([t, xy])


def _house_probabilities(unknown: tuple[str, ...] = ()) -> np.ndarray:
    """p(m) of the house at 0.05 m: 0.1 m walls on every region edge except the doors (p = 1),
    free inside (p = 0), the regions named in ``unknown`` unknown (p = 0.5)."""
    walls = unary_union([shapely.Polygon(r.polygon).boundary for r in HOUSE.regions])
    doors = unary_union([LineString(d.segment).buffer(0.06, cap_style="flat") for d in HOUSE.doors])
    walls = walls.buffer(0.05, cap_style="flat").difference(doors)
    h, w = round(9 / RES), round(12 / RES)
    rr, cc = np.mgrid[0:h, 0:w]
    x, y = (cc + 0.5) * RES, (rr + 0.5) * RES
    p = np.zeros((h, w))
    for name in unknown:
        p[shapely.contains_xy(shapely.Polygon(HOUSE.region(name).polygon), x, y)] = 0.5
    p[shapely.contains_xy(walls, x, y)] = 1.0
    return p


# ------------------------------------------------------------------------------- region map


def test_locate_each_region_and_outside(rmap: RegionMap) -> None:
    assert rmap.locate((2.5, 2.0)) == "kitchen"
    assert rmap.locate((8.0, 1.0)) == "living_room"
    assert rmap.locate((6.0, 5.0)) == "hall"
    assert rmap.locate((1.0, 8.0)) == "office"
    assert rmap.locate((11.0, 7.0)) == "bedroom"
    assert rmap.locate((-0.1, 2.0)) is None
    assert rmap.locate((13.0, 5.0)) is None
    # On a shared edge: the first region in layout order.
    assert rmap.locate((5.0, 2.0)) == "kitchen"
    assert rmap.locate((3.0, 4.0)) == "kitchen"
    assert rmap.locate((6.0, 6.0)) == "hall"
    assert rmap.locate((12.0, 9.0)) == "bedroom"  # a corner of the house


def test_region_graph_of_the_house(rmap: RegionMap) -> None:
    g = rmap.graph
    assert sorted(g.nodes) == sorted(["kitchen", "living_room", "hall", "office", "bedroom"])
    assert {frozenset(e) for e in g.edges} == {frozenset(d.between) for d in HOUSE.doors}
    assert g.number_of_edges() == 5
    edge = g.edges["kitchen", "hall"]
    assert edge["midpoint"] == pytest.approx((2.45, 4.0))
    assert edge["segment"] == ((2.0, 4), (2.9, 4))
    # weight: centroid (2.5, 2) → door midpoint (2.45, 4) → hall centroid (6, 5).
    assert edge["weight"] == pytest.approx(math.hypot(0.05, 2.0) + math.hypot(3.55, 1.0))
    assert rmap.neighbours("hall") == ["kitchen", "living_room", "office", "bedroom"]
    assert rmap.neighbours("office") == ["hall"]
    assert rmap.doors_between("office", "bedroom") == ()


def test_region_path_goes_through_the_hall(rmap: RegionMap) -> None:
    assert rmap.region_path("kitchen", "office") == ["kitchen", "hall", "office"]
    assert rmap.region_path("office", "bedroom") == ["office", "hall", "bedroom"]
    assert rmap.region_path("living_room", "bedroom") == ["living_room", "hall", "bedroom"]
    assert rmap.region_path("hall", "hall") == ["hall"]
    with pytest.raises(KeyError):
        rmap.region_path("kitchen", "garage")


def test_region_path_without_a_door_raises() -> None:
    lonely = HouseLayout(regions=(*HOUSE.regions, Region("shed", ((20, 0), (22, 0), (22, 2)))))
    with pytest.raises(nx.NetworkXNoPath):
        RegionMap(lonely).region_path("kitchen", "shed")


def test_polygon_and_distance(rmap: RegionMap) -> None:
    assert rmap.polygon("office").area == pytest.approx(18.0)
    assert rmap.distance_to_region((2.5, 5.0), "kitchen") == pytest.approx(1.0)
    assert rmap.distance_to_region((2.5, 2.0), "kitchen") == 0.0
    assert rmap.region_point("bedroom") == pytest.approx((9.0, 7.5))


def test_a_door_to_an_unknown_region_is_refused() -> None:
    bad = HouseLayout(regions=HOUSE.regions, doors=(Door(("hall", "garage"), ((0, 0), (1, 0))),))
    with pytest.raises(ValueError, match="garage"):
        RegionMap(bad)


# ---------------------------------------------------------------------- Algorithm 1, heading


def test_walking_east_along_the_hall_heads_for_the_bedroom(rmap: RegionMap) -> None:
    history = _walk((6.0, 5.5), (8.5, 5.5))
    assert heading_region(history, rmap, window_s=3.0) == "bedroom"
    current, scores = heading_scores(history, rmap, window_s=3.0)
    assert current == "hall"
    assert set(scores) == {"kitchen", "living_room", "office", "bedroom"}
    # The mean change per sample is (d_last − d_first) / (k − 1), to the door midpoint.
    d_first, d_last = math.hypot(9.45 - 6.0, 0.5), math.hypot(9.45 - 8.5, 0.5)
    assert scores["bedroom"] == pytest.approx((d_last - d_first) / 30)
    assert scores["office"] > 0 and scores["kitchen"] > 0


def test_walking_north_heads_for_the_office(rmap: RegionMap) -> None:
    assert heading_region(_walk((3.95, 4.3), (3.95, 5.8)), rmap, 3.0) == "office"


def test_walking_to_the_kitchen_door_from_the_living_room(rmap: RegionMap) -> None:
    assert heading_region(_walk((8.0, 2.0), (5.5, 2.0)), rmap, 3.0) == "kitchen"


def test_standing_still_or_outside_has_no_heading(rmap: RegionMap) -> None:
    still = _walk((6.0, 5.0), (6.0, 5.0))
    assert heading_region(still, rmap, 3.0) is None
    assert heading_region(still[:1], rmap, 3.0) is None  # one sample: no change to measure
    assert heading_region(_walk((13.0, 5.0), (14.0, 5.0)), rmap, 3.0) is None
    assert heading_scores(np.empty((0, 3)), rmap, 3.0) == (None, {})


def test_only_the_window_counts(rmap: RegionMap) -> None:
    to_office = _walk((3.95, 4.3), (3.95, 5.0))  # t = 0..3
    to_bedroom = _walk((3.95, 5.0), (7.0, 5.3))
    to_bedroom[:, 0] += 3.1  # t = 3.1..6.1
    history = np.vstack([to_office, to_bedroom])
    assert heading_region(history, rmap, window_s=3.0) == "bedroom"
    assert heading_region(history[::-1], rmap, window_s=3.0) == "bedroom"  # sorted by t
    assert heading_region(history, rmap, window_s=3.0, min_speed=5.0) is None


# ------------------------------------------------------------------------ Algorithm 1, search


def test_waypoint_search_goes_to_the_frontier_of_the_approached_region(rmap: RegionMap) -> None:
    grid = OccupancyGrid.from_probabilities(_house_probabilities(("bedroom",)), RES)
    decision = waypoint_search(
        grid, rmap, _walk((6.0, 5.5), (8.5, 5.5)), robot_xy=(3.0, 5.0), **SEARCH
    )
    assert decision.reason == "frontier"
    assert decision.heading_region == decision.target_region == "bedroom"
    assert decision.target_point == pytest.approx((9.0, 7.5))
    assert len(decision.clusters) == 1  # only the bedroom door opens onto unknown space
    x, y = decision.waypoint
    assert 9.0 < x < 9.9 and 5.9 < y < 6.0  # the hall side of the bedroom door
    # It is the cluster's point closest to l*'s point, (9, 7.5): the door's west end.
    assert x == pytest.approx(decision.clusters[0].points[:, 0].min())
    assert decision.best == 0 and len(decision.utilities) == 1
    assert np.isfinite(decision.utilities[0])


def test_waypoint_search_prefers_the_approached_region_by_utility(rmap: RegionMap) -> None:
    grid = OccupancyGrid.from_probabilities(_house_probabilities(("office", "bedroom")), RES)
    robot = (6.0, 5.0)  # between the two doors, nearer the office one
    to_bedroom = waypoint_search(grid, rmap, _walk((6.0, 5.5), (8.5, 5.5)), robot, **SEARCH)
    assert to_bedroom.reason == "frontier" and len(to_bedroom.clusters) == 2
    assert to_bedroom.waypoint[0] > 9.0
    to_office = waypoint_search(grid, rmap, _walk((5.5, 4.5), (4.2, 5.6)), robot, **SEARCH)
    assert to_office.heading_region == "office"
    assert 3.5 < to_office.waypoint[0] < 4.4
    assert to_office.utilities[to_office.best] == max(to_office.utilities)


def test_waypoint_search_without_frontier_falls_back_to_l_star(rmap: RegionMap) -> None:
    grid = OccupancyGrid.from_probabilities(_house_probabilities(), RES)
    decision = waypoint_search(
        grid, rmap, _walk((6.0, 5.5), (8.5, 5.5)), robot_xy=(3.0, 5.0), **SEARCH
    )
    assert decision.reason == "no_frontier_fallback"
    assert decision.clusters == () and decision.best is None
    assert decision.heading_region == "bedroom"
    assert decision.waypoint == pytest.approx((9.0, 7.5))


def test_fallback_point_avoids_furniture_and_no_heading_uses_the_current_region(
    rmap: RegionMap,
) -> None:
    p = _house_probabilities()
    p[140:160, 170:190] = 1.0  # a 1 m box on the bedroom centroid (9, 7.5)
    grid = OccupancyGrid.from_probabilities(p, RES)
    decision = waypoint_search(grid, rmap, _walk((6.0, 5.5), (8.5, 5.5)), (3.0, 5.0), **SEARCH)
    x, y = decision.waypoint
    r, c = int(y / RES), int(x / RES)
    assert grid.states()[r, c] != 1 and rmap.locate((x, y)) == "bedroom"
    assert math.hypot(x - 9.0, y - 7.5) == pytest.approx(0.5 + RES / 2, abs=RES)
    still = waypoint_search(grid, rmap, _walk((1.0, 8.0), (1.0, 8.0)), (3.0, 5.0), **SEARCH)
    assert still.heading_region is None and still.target_region == "office"
    assert still.reason == "no_frontier_fallback"
    nowhere = waypoint_search(grid, rmap, _walk((20, 20), (20, 20)), (30.0, 30.0), **SEARCH)
    assert nowhere.reason == "no_target" and nowhere.waypoint == (30.0, 30.0)
    # no history at all (a target never seen): the robot's region, unless that fallback is off
    empty = np.empty((0, 3))
    anchored = waypoint_search(grid, rmap, empty, (3.0, 5.0), **SEARCH)
    assert anchored.target_region == "hall"
    free = waypoint_search(grid, rmap, empty, (3.0, 5.0), **SEARCH, robot_region_fallback=False)
    assert free.target_region is None and free.reason == "no_target"


def test_waypoint_utilities_are_eq3(rmap: RegionMap) -> None:
    grid = OccupancyGrid.from_probabilities(_house_probabilities(("office", "bedroom")), RES)
    robot = (6.0, 5.0)
    decision = waypoint_search(grid, rmap, _walk((6.0, 5.5), (8.5, 5.5)), robot, **SEARCH)
    states = grid.states()
    tr = traversability(states != 1, geometry=grid.geometry, known=states != -1)
    from_x, to_l = distance_fields(tr, np.array([robot, decision.target_point]))
    for cluster, u in zip(decision.clusters, decision.utilities, strict=True):
        assert u == pytest.approx(
            utility(cluster, robot, decision.target_point, SEARCH["alpha"], from_x, to_l)
        )


def test_waypoint_search_ignores_frontiers_beyond_the_house(rmap: RegionMap) -> None:
    """A gap in the kitchen's outer wall opens onto unknown space outside every region: a frontier
    of the raw grid, but the person is in the house, so Algorithm 1 does not go there."""
    margin = 40  # 2 m of unknown space around the house
    p = np.pad(_house_probabilities(("office",)), margin, constant_values=0.5)
    gap = slice(margin + 76, margin + 92)  # x in [3.8, 4.6] m on the south wall (y = 0)
    p[margin - 1 : margin + 1, gap] = 0.0
    grid = OccupancyGrid.from_probabilities(p, RES, origin=(-2.0, -2.0))
    walk = _walk((5.5, 4.5), (4.2, 5.6))  # toward the office door

    def at_gap(decision) -> list[bool]:
        return [3.7 < c.centroid[0] < 4.7 and c.centroid[1] < 0.1 for c in decision.clusters]

    raw = waypoint_search(grid, rmap, walk, (3.0, 2.0), **SEARCH, confine_to_regions=False)
    confined = waypoint_search(grid, rmap, walk, (3.0, 2.0), **SEARCH)
    assert any(at_gap(raw))
    assert not any(at_gap(confined)) and confined.reason == "frontier"
    assert confined.heading_region == "office"
    assert all(rmap.locate(g) is not None for g in confined.goals)


def test_an_unseen_wall_between_regions_is_still_a_wall(rmap: RegionMap) -> None:
    """The office is explored but its east wall (to the bedroom) is not: on the raw grid the office
    cells along that wall are a frontier, and the straight way through the wall to the bedroom
    makes it the best one. The region map knows the wall: only the bedroom door is a frontier."""
    p = _house_probabilities(("bedroom",))
    p[119:180, 119:121] = 0.5  # the wall x = 6 m between office and bedroom, unseen
    grid = OccupancyGrid.from_probabilities(p, RES)
    walk = _walk((6.0, 5.5), (8.5, 5.5))  # along the hall, toward the bedroom door
    robot = (5.5, 7.5)  # in the office, next to that wall

    raw = waypoint_search(grid, rmap, walk, robot, **SEARCH, confine_to_regions=False)
    assert raw.heading_region == "bedroom" and 5.8 < raw.waypoint[0] < 6.0

    confined = waypoint_search(grid, rmap, walk, robot, **SEARCH)
    assert confined.reason == "frontier" and len(confined.clusters) == 1
    x, y = confined.waypoint
    assert 9.0 < x < 9.9 and 5.9 < y < 6.0  # the hall side of the bedroom door
    # d(x, c) now runs out of the office door and along the hall: at least 0.5 m to the office
    # door's east end (4.4, 6), then 4.6 m to the bedroom door's west end (9, 6).
    assert -confined.utilities[0] > math.hypot(5.5 - 4.4, 7.5 - 6.0) + 4.6
