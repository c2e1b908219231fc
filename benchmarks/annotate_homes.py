"""`pfctl map annotate --auto` on generated homes: rooms and doors found against the truth.

Run ``python benchmarks/annotate_homes.py [--homes 50] [--first-seed 1] [--noise/--no-noise]
[--door-width W] [--rotate DEG|random]``. For each seed it generates the home ``pfctl mission
generate --seed N`` would write, exports its map as ``pfctl map export`` does (walls, doors,
furniture; map_server YAML + PGM, read back), optionally turns it by an angle as a SLAM map of
the home would be (the occupancy image resampled nearest-neighbour, unknown outside; the true
rooms and doors turned with it; ``random``: an angle in [0°, 90°) drawn from the home's seed),
optionally adds SLAM-like noise (:mod:`pfctl.core.mapping.noise`, seeded by the home's seed),
proposes rooms and doors as ``pfctl map annotate --auto`` does, and scores them:

- rooms: true regions (corridor and hall included) matched one-to-one by a proposed room with
  polygon IoU ≥ 0.7, % of the true regions;
- doors found: true doors and wide openings matched one-to-one by a proposed door lying on them
  (within 0.25 m, overlapping at least half the shorter of the two), % of the true doors;
- spurious doors: proposed doors matching no true door, % of the proposed doors;
- failures: homes where the proposal is not a valid annotation (``annotate`` would exit 2);
- Bormann recall / precision, the area measures of Bormann et al. (ICRA 2016, "Room segmentation:
  survey, implementation, and analysis") so the figures can be set beside theirs: recall is, per
  true region, the largest area it shares with one proposed room over the region's area;
  precision is, per proposed room, the largest area it shares with one true region over the
  room's area; each averaged over the rooms of all homes. Merging rooms lowers precision,
  splitting them lowers recall.

``--method distance`` scores the distance-transform segmentation (the family Bormann et al. call
distance segmentation) instead of the default wall-line one.

It prints one line per home that is not perfect, then the table; the shipped house too.
Maps and grids only: no simulation, a few seconds per home.
"""

from __future__ import annotations

import argparse
import math
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from shapely.geometry import LineString, Polygon

from pfctl.app.homes import make_home
from pfctl.commands.map import auto_layout
from pfctl.core.homes.home import HomeOptions
from pfctl.core.mapping.house import Door, HouseLayout, Region
from pfctl.core.mapping.noise import slam_noise
from pfctl.core.mapping.orientation import rotate_points, rotated_map
from pfctl.core.mapping.rooms import RoomParams, match_regions, segment_free_space
from pfctl.core.mapping.walls import rasterize_house
from pfctl.errors import UserError
from pfctl.mission import load_mission
from pfctl.mission.map_server import load_map_server, save_map_server

HOUSE = Path(__file__).resolve().parents[1] / "missions" / "house.yaml"
ROOM_IOU = 0.7
DOOR_NEAR = 0.25


@dataclass
class Score:
    """One home's figures."""

    regions: int
    rooms_matched: int
    proposed_rooms: int
    doors: int
    doors_found: int
    proposed_doors: int
    iou_sum: float = 0.0
    recall_sum: float = 0.0
    precision_sum: float = 0.0
    failed: str = ""
    warnings: int = 0

    @property
    def spurious(self) -> int:
        return self.proposed_doors - self.doors_found


def _door_matches(true: Door, proposed: Door) -> bool:
    a, b = LineString(true.segment), LineString(proposed.segment)
    if a.distance(b) > DOOR_NEAR:
        return False
    overlap = b.intersection(a.buffer(DOOR_NEAR)).length
    return overlap >= 0.5 * min(a.length, b.length)


def _largest_shares(rooms: tuple[Region, ...], others: tuple[Region, ...]) -> list[float]:
    """Per room of ``rooms``: the largest area it shares with one of ``others``, over its area."""
    other_polygons = [Polygon(o.polygon) for o in others]
    shares = []
    for room in rooms:
        polygon = Polygon(room.polygon)
        best = max((polygon.intersection(o).area for o in other_polygons), default=0.0)
        shares.append(best / polygon.area if polygon.area > 0 else 0.0)
    return shares


def score(truth: HouseLayout, proposal: HouseLayout) -> Score:
    """Rooms matched at IoU ≥ 0.7, doors matched one-to-one by position, Bormann's areas."""
    matched = match_regions(proposal.regions, truth.regions, ROOM_IOU)
    free = list(proposal.doors)
    found = 0
    for door in truth.doors:
        hit = next((d for d in free if _door_matches(door, d)), None)
        if hit is not None:
            free.remove(hit)
            found += 1
    return Score(
        regions=len(truth.regions),
        rooms_matched=len(matched),
        proposed_rooms=len(proposal.regions),
        doors=len(truth.doors),
        doors_found=found,
        proposed_doors=len(proposal.doors),
        iou_sum=sum(iou for _, iou in matched.values()),
        recall_sum=sum(_largest_shares(truth.regions, proposal.regions)),
        precision_sum=sum(_largest_shares(proposal.regions, truth.regions)),
    )


def exported_states(truth: HouseLayout, resolution: float, wall_thickness: float, tmp: Path):
    """The map as ``pfctl map export`` writes it, read back: (states, geometry)."""
    grid = rasterize_house(truth, resolution, wall_thickness=wall_thickness, margin=0.5)
    yaml_path, _ = save_map_server(grid, tmp / "map.yaml")
    loaded = load_map_server(yaml_path)
    return loaded.states(), loaded.geometry


def rotated_layout(layout: HouseLayout, angle: float) -> HouseLayout:
    """The rooms and doors turned counter-clockwise by ``angle`` radians about the origin."""

    def turn(points) -> tuple[tuple[float, float], ...]:
        return tuple((float(x), float(y)) for x, y in rotate_points(np.asarray(points), angle))

    return HouseLayout(
        regions=tuple(Region(r.name, turn(r.polygon)) for r in layout.regions),
        doors=tuple(Door(d.between, turn(d.segment)) for d in layout.doors),  # type: ignore[arg-type]
    )


def run_one(
    truth: HouseLayout,
    resolution: float,
    wall_thickness: float,
    noise_seed: int | None,
    params: RoomParams,
    tmp: Path,
    rotate_deg: float = 0.0,
) -> Score:
    states, geometry = exported_states(truth, resolution, wall_thickness, tmp)
    truth = HouseLayout(regions=truth.regions, doors=truth.doors)
    if rotate_deg:
        states, geometry = rotated_map(states, geometry, math.radians(rotate_deg))
        truth = rotated_layout(truth, math.radians(rotate_deg))
    if noise_seed is not None:
        states = slam_noise(states, resolution, np.random.default_rng([noise_seed, 25]))
    try:
        layout, warnings = auto_layout(states, geometry, params)
    except UserError as err:  # score what the segmentation proposed, and count the failure
        try:
            raw = segment_free_space(states, geometry, params).layout()
        except ValueError:
            raw = HouseLayout(regions=(), doors=())
        s = score(truth, raw)
        s.failed = str(err)
        return s
    s = score(truth, layout)
    s.warnings = len(warnings)
    return s


def _pct(num: int, den: int) -> str:
    return f"{100.0 * num / den:5.1f}" if den else "  n/a"


def _pct_f(total: float, count: int) -> str:
    return f"{100.0 * total / count:.1f}" if count else "n/a"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--homes", type=int, default=50)
    ap.add_argument("--first-seed", type=int, default=1)
    ap.add_argument("--noise", action=argparse.BooleanOptionalAction, default=True)
    ap.add_argument("--door-width", type=float, default=None)
    ap.add_argument("--method", choices=("walls", "distance"), default="walls")
    ap.add_argument(
        "--rotate",
        default="0",
        help="turn each exported map by DEG degrees, or by a seeded random angle ('random')",
    )
    args = ap.parse_args(argv)
    if args.rotate != "random":
        try:
            float(args.rotate)
        except ValueError:
            ap.error(f"--rotate: expected degrees or 'random', got {args.rotate!r}")
    # The distance method's default width is the one its fallback uses (1 m, rooms.py).
    door_width = args.door_width or (1.0 if args.method == "distance" else RoomParams.door_width)
    params = RoomParams(method=args.method, door_width=door_width)
    t0 = time.monotonic()
    total = Score(0, 0, 0, 0, 0, 0)
    failures = 0
    warned = 0
    with tempfile.TemporaryDirectory(prefix="annotate-homes-") as tmpdir:
        tmp = Path(tmpdir)
        house = load_mission(HOUSE)
        hs = run_one(
            house.layout(), house.map.resolution, house.map.wall_thickness, None, params, tmp
        )
        print(
            f"shipped house: {hs.rooms_matched} of {hs.regions} rooms, "
            f"{hs.doors_found} of {hs.doors} doors, {hs.spurious} spurious"
            + (f", FAILED: {hs.failed}" if hs.failed else "")
        )
        for seed in range(args.first_seed, args.first_seed + args.homes):
            gen = make_home(HomeOptions(seed=seed))
            m = gen.mission
            deg = (
                float(np.random.default_rng([seed, 90]).uniform(0.0, 90.0))
                if args.rotate == "random"
                else float(args.rotate)
            )
            s = run_one(
                m.layout(),
                m.map.resolution,
                m.map.wall_thickness,
                seed if args.noise else None,
                params,
                tmp,
                deg,
            )
            for name in ("regions", "rooms_matched", "proposed_rooms", "doors", "doors_found"):
                setattr(total, name, getattr(total, name) + getattr(s, name))
            total.proposed_doors += s.proposed_doors
            total.iou_sum += s.iou_sum
            total.recall_sum += s.recall_sum
            total.precision_sum += s.precision_sum
            failures += bool(s.failed)
            warned += bool(s.warnings)
            if s.failed or s.rooms_matched < s.regions or s.doors_found < s.doors or s.spurious:
                print(
                    f"seed {seed:3d} {gen.home.plan.kind:9s} {deg:5.1f}°: "
                    f"rooms {s.rooms_matched}/{s.regions}"
                    f" (proposed {s.proposed_rooms}), doors {s.doors_found}/{s.doors}"
                    f" (proposed {s.proposed_doors})"
                    + (f"  FAILED: {s.failed[:90]}" if s.failed else "")
                )
    print()
    print(
        f"{args.homes} homes (seeds {args.first_seed}..{args.first_seed + args.homes - 1}), "
        f"noise {'on' if args.noise else 'off'}, rotate {args.rotate}, "
        f"method {params.method}, door_width {params.door_width:g} m, "
        f"{time.monotonic() - t0:.0f} s"
    )
    print(
        "| rooms IoU≥0.7 | mean IoU of those | doors found | spurious doors "
        "| failures (exit 2) | homes warned | Bormann recall / precision |"
    )
    print("|---|---|---|---|---|---|---|")
    print(
        f"| {_pct(total.rooms_matched, total.regions)} % ({total.rooms_matched}/{total.regions}) "
        f"| {total.iou_sum / max(1, total.rooms_matched):.3f} "
        f"| {_pct(total.doors_found, total.doors)} % ({total.doors_found}/{total.doors}) "
        f"| {_pct(total.spurious, total.proposed_doors)} % "
        f"({total.spurious}/{total.proposed_doors}) | {failures} | {warned} "
        f"| {_pct_f(total.recall_sum, total.regions)} / "
        f"{_pct_f(total.precision_sum, total.proposed_rooms)} % |"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
