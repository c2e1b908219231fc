"""Speed of the map core on one CPU core: scan update (Eq. 1), frontiers (Eq. 2), Algorithm 1.

Run ``python benchmarks/bench_map_core.py [--runs N]``. It builds the shipped house
(missions/house.yaml geometry, copied here) inside a 20 m × 20 m map at 0.05 m (400 × 400 cells),
simulates 1081-beam 270° laser scans (Hokuyo-like, as on the HSR) by ray casting the true walls
and furniture, explores the map with a few scans from the kitchen and the hall (so the office,
bedroom and living room are still largely unknown), and reports the median time, after warm-up,
of one :meth:`OccupancyGrid.update_scan`, of frontier extraction + clustering, and of one
``waypoint_search`` (Algorithm 1 including the grid path lengths). Goal: each under 10 ms.
It prints figures; it asserts nothing about time.
"""

from __future__ import annotations

import os

# One core, one thread: set before numpy is imported.
for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"
if hasattr(os, "sched_setaffinity"):
    os.sched_setaffinity(0, {0})

import argparse  # noqa: E402
import platform  # noqa: E402
import statistics  # noqa: E402
import time  # noqa: E402
from collections.abc import Callable  # noqa: E402

import numpy as np  # noqa: E402
import scipy  # noqa: E402
import shapely  # noqa: E402
from shapely.geometry import LineString  # noqa: E402
from shapely.ops import unary_union  # noqa: E402

from pfctl.core.mapping.frontiers import find_frontiers, frontier_map, trinary_map  # noqa: E402
from pfctl.core.mapping.grid import OCCUPIED, UNKNOWN, GridGeometry, OccupancyGrid  # noqa: E402
from pfctl.core.mapping.house import Door, HouseLayout, Obstacle, Region  # noqa: E402
from pfctl.core.mapping.paths import distance_fields, traversability  # noqa: E402
from pfctl.core.mapping.regions import RegionMap, waypoint_search  # noqa: E402

SIZE_M = 20.0
RES = 0.05
OFFSET = np.array([4.0, 5.5])  # the 12 m × 9 m house, centred in the 20 m × 20 m map
BEAMS = 1081
FOV = 1.5 * np.pi  # 270°
RANGE_MAX = 20.0
SEARCH = dict(alpha=0.05, beta=1.0, frontier_threshold=0.1, min_frontier_cells=5, window_s=3.0)


def _at(x: float, y: float) -> np.ndarray:
    """A house point in the map frame."""
    return OFFSET + np.array([x, y])


def _shift(points: tuple[tuple[float, float], ...]) -> tuple[tuple[float, float], ...]:
    return tuple((float(x + OFFSET[0]), float(y + OFFSET[1])) for x, y in points)


HOUSE = HouseLayout(
    regions=tuple(
        Region(name, _shift(poly))
        for name, poly in (
            ("kitchen", ((0, 0), (5, 0), (5, 4), (0, 4))),
            ("living_room", ((5, 0), (12, 0), (12, 4), (5, 4))),
            ("hall", ((0, 4), (12, 4), (12, 6), (0, 6))),
            ("office", ((0, 6), (6, 6), (6, 9), (0, 9))),
            ("bedroom", ((6, 6), (12, 6), (12, 9), (6, 9))),
        )
    ),
    doors=tuple(
        Door(between, _shift(segment))  # type: ignore[arg-type]
        for between, segment in (
            (("kitchen", "living_room"), ((5, 1.5), (5, 2.4))),
            (("kitchen", "hall"), ((2.0, 4), (2.9, 4))),
            (("living_room", "hall"), ((8.5, 4), (9.4, 4))),
            (("hall", "office"), ((3.5, 6), (4.4, 6))),
            (("hall", "bedroom"), ((9.0, 6), (9.9, 6))),
        )
    ),
    obstacles=tuple(
        Obstacle(_shift(poly), name=name)
        for name, poly in (
            ("kitchen_counter", ((0.1, 0.1), (3.5, 0.1), (3.5, 0.7), (0.1, 0.7))),
            ("dining_table", ((1.2, 2.0), (2.4, 2.0), (2.4, 2.8), (1.2, 2.8))),
            ("sofa", ((7.0, 0.1), (9.5, 0.1), (9.5, 0.9), (7.0, 0.9))),
            ("desk", ((0.1, 8.2), (1.7, 8.2), (1.7, 8.9), (0.1, 8.9))),
            ("bed", ((10.0, 6.9), (11.9, 6.9), (11.9, 8.9), (10.0, 8.9))),
        )
    ),
)


def truth_map(geometry: GridGeometry) -> np.ndarray:
    """Boolean (height, width): walls (0.1 m, doors open) and furniture."""
    walls = unary_union([shapely.Polygon(r.polygon).boundary for r in HOUSE.regions])
    doors = unary_union([LineString(d.segment).buffer(0.06, cap_style="flat") for d in HOUSE.doors])
    solid = unary_union(
        [walls.buffer(0.05, cap_style="flat").difference(doors)]
        + [shapely.Polygon(o.polygon) for o in HOUSE.obstacles]
    )
    rr, cc = np.mgrid[0 : geometry.height, 0 : geometry.width]
    centres = geometry.cell_to_world(rr, cc)
    return shapely.contains_xy(solid, centres[..., 0], centres[..., 1])


def simulate_scan(truth: np.ndarray, geometry: GridGeometry, pose: tuple[float, float, float]):
    """Ranges of a 1081-beam 270° scan from ``pose`` (ray marching at a quarter cell)."""
    x, y, theta = pose
    angles = theta - FOV / 2 + np.arange(BEAMS) * (FOV / (BEAMS - 1))
    steps = np.arange(1, int(RANGE_MAX / (RES / 4)) + 1) * (RES / 4)
    px = x + np.cos(angles)[:, None] * steps
    py = y + np.sin(angles)[:, None] * steps
    rows, cols = geometry.world_to_cell(np.stack([px, py], axis=-1))
    inside = geometry.in_bounds(rows, cols)
    hit = np.zeros(rows.shape, dtype=bool)
    hit[inside] = truth[rows[inside], cols[inside]]
    first = np.where(hit.any(axis=1), hit.argmax(axis=1), -1)
    return np.where(first >= 0, steps[first], np.inf), -FOV / 2, FOV / (BEAMS - 1)


def median_ms(fn: Callable[[], object], runs: int, setup: Callable[[], None] | None = None):
    for _ in range(5):  # warm-up
        if setup:
            setup()
        fn()
    times = []
    for _ in range(runs):
        if setup:
            setup()
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return 1e3 * statistics.median(times), 1e3 * min(times)


def cpu_name() -> str:
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=50)
    args = parser.parse_args()

    grid = OccupancyGrid.empty(SIZE_M, SIZE_M, RES)
    geometry = grid.geometry
    truth = truth_map(geometry)
    poses = [  # sensor poses (map frame): kitchen, then the hall looking east and west
        (OFFSET[0] + 1.0, OFFSET[1] + 3.3, 0.0),
        (OFFSET[0] + 3.0, OFFSET[1] + 5.0, 0.0),
        (OFFSET[0] + 7.0, OFFSET[1] + 5.0, np.pi),
    ]
    scans = [simulate_scan(truth, geometry, pose) for pose in poses]
    for pose, (ranges, a0, da) in zip(poses, scans, strict=True):
        for _ in range(5):
            grid.update_scan(pose, ranges, a0, da, RANGE_MAX)
    explored = grid.copy()

    rmap = RegionMap(HOUSE)
    t = np.linspace(0.0, 3.0, 31)
    walk = np.linspace(_at(7.0, 5.5), _at(9.0, 5.7), 31)  # toward the bedroom door
    history = np.column_stack([t, walk])
    robot = tuple(_at(3.0, 5.0))

    states = explored.states()
    clusters = find_frontiers(explored, SEARCH["beta"], SEARCH["frontier_threshold"], 5)
    decision = waypoint_search(explored, rmap, history, robot, **SEARCH)

    work = explored.copy()
    pose0, (ranges0, a0, da) = poses[1], scans[1]

    def reset() -> None:
        work.logodds[...] = explored.logodds

    rows: list[tuple[str, tuple[float, float]]] = []
    rows.append(
        (
            "OccupancyGrid.update_scan (1081 beams)",
            median_ms(
                lambda: work.update_scan(pose0, ranges0, a0, da, RANGE_MAX), args.runs, reset
            ),
        )
    )
    rows.append(("  grid.states()", median_ms(explored.states, args.runs)))
    occ = states == OCCUPIED
    lam = trinary_map(states)
    rows.append(
        ("  frontier_map (Eq. 2) alone", median_ms(lambda: frontier_map(lam, occ, 1.0), args.runs))
    )
    rows.append(
        (
            "find_frontiers (states + Eq. 2 + clusters)",
            median_ms(lambda: find_frontiers(explored, 1.0, 0.1, 5), args.runs),
        )
    )
    tr = traversability(states != OCCUPIED, geometry=geometry, known=states != UNKNOWN)
    starts = np.array([robot, rmap.region_point("bedroom")])
    rows.append(
        (
            "  traversability (coarse mask)",
            median_ms(
                lambda: traversability(
                    states != OCCUPIED, geometry=geometry, known=states != UNKNOWN
                ),
                args.runs,
            ),
        )
    )
    rows.append(
        ("  distance_fields, 2 sources", median_ms(lambda: distance_fields(tr, starts), args.runs))
    )
    rows.append(
        (
            "waypoint_search (Algorithm 1, all in)",
            median_ms(lambda: waypoint_search(explored, rmap, history, robot, **SEARCH), args.runs),
        )
    )

    # The worst case for the path search: the whole house explored (a scan in every room).
    full = explored.copy()
    for x, y in ((9.0, 2.0), (3.0, 7.5), (8.0, 7.5), (11.0, 5.0), (3.0, 2.0)):
        for theta in (0.0, np.pi):
            pose = (OFFSET[0] + x, OFFSET[1] + y, theta)
            ranges, a1, d1 = simulate_scan(truth, geometry, pose)
            for _ in range(5):
                full.update_scan(pose, ranges, a1, d1, RANGE_MAX)
    rows.append(
        (
            "waypoint_search, whole house explored",
            median_ms(lambda: waypoint_search(full, rmap, history, robot, **SEARCH), args.runs),
        )
    )

    known = np.mean(states != -1)
    print("pfctl map-core benchmark")
    affinity = sorted(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else "?"
    print(f"  machine : {platform.platform()} | {cpu_name()} | cpu affinity {affinity}")
    print(
        f"  python {platform.python_version()}, numpy {np.__version__}, scipy {scipy.__version__}, "
        f"shapely {shapely.__version__}"
    )
    print(
        f"  map     : {geometry.width}×{geometry.height} cells at {RES} m; {len(poses)} poses × 5 "
        f"scans; {100 * known:.0f}% known; {len(clusters)} frontier clusters, "
        f"{sum(c.size for c in clusters)} frontier cells"
    )
    print(
        f"  decision: {decision.reason} → "
        f"({decision.waypoint[0]:.2f}, {decision.waypoint[1]:.2f}), "
        f"l* = {decision.target_region}; coarse path grid {tr.coarse_geometry.width}×"
        f"{tr.coarse_geometry.height} at {tr.coarse_geometry.resolution:.2f} m"
    )
    print(f"  median of {args.runs} runs after 5 warm-up runs, one core\n")
    print(f"  {'step':<44} {'median ms':>10} {'min ms':>8}  {'< 10 ms':>7}")
    for name, (med, best) in rows:
        ok = "" if name.startswith("  ") else ("yes" if med < 10 else "NO")
        print(f"  {name:<44} {med:>10.2f} {best:>8.2f}  {ok:>7}")


if __name__ == "__main__":
    main()
