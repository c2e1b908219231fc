"""Automatic room segmentation of an occupancy map's free space, and door proposals.

A door is an opening in a wall line between two spaces; a gap between two free-standing objects
inside one space is not. The default method (``method="walls"``) closes every opening of a wall
line and takes what the free space falls apart into as rooms; the distance-transform method of
Bormann et al. (2016), "Room segmentation: survey, implementation, and analysis" (§III-B there),
is kept as ``method="distance"`` (it cuts at every narrow place, furniture gaps included, and
cannot tell a 1.2 m corridor from a 1.4 m door). Both share the watershed growth step:

A SLAM map is usually turned by some angle from the grid (its frame is where the mapping
started); ``walls`` looks for wall lines along rows and columns, so :func:`segment_free_space`
first turns the map until its dominant wall orientation is axis-aligned, segments it there and
turns the rooms and doors back; a map with no dominant wall orientation is segmented with
``distance`` instead, with a warning.

0. **Clean-up.** Non-free specks smaller than ``noise_area`` inside the free space (laser
   noise, unknown pinholes of a SLAM map) count as free.
1. **Cores.**
   - ``walls``: per row (and per column), a run of non-occupied cells between
     ``min_door_width`` and ``door_width`` long is an opening if both its ends are *jambs*: a
     straight run of at least ``jamb_length`` of occupied cells continuing the row, at most
     ``wall_thickness`` thick across where it meets the opening. A wall seen end-on (the side
     wall of a corridor, crossed) is too short along the row; the side of a piece of furniture,
     or a wall with a wardrobe against it, is too thick across. The openings' cells are taken out
     of the free space; its connected parts (4-connectivity) are the cores.
   - ``distance``: the Euclidean distance transform of the free space; the cells farther than
     ``core_radius`` (default ``door_width/2 + resolution``) from any obstacle, so the free space
     is cut at every passage narrower than ``2·core_radius``.

   Cores smaller than ``min_core_area`` are dropped (nooks behind furniture).
2. **Growth.** The cores are grown back over the free cells by a priority flood on the distance
   transform (a watershed: the cell with the largest bottleneck distance to a core goes first),
   so two rooms meet at the narrowest place between them and never through a wall; with
   ``walls``, an opening's cells are split last, each to the nearest room, so rooms meet on the
   opening's middle line. Rooms smaller than ``min_room_area`` are merged into the neighbour they
   share most free border with. With ``walls``, each piece of furniture (an occupied blob thick
   enough to hold a square ``wall_thickness`` + one cell wide) goes whole to the room it borders
   most. Then each occupied cell (wall, furniture) connected to a room takes the label of the
   nearest room cell, so a wall between two rooms is split down its middle
   line; unlabelled cells the rooms enclose (furniture, unknown patches, one in a doorway) take
   the label of the nearest room cell; unknown cells outside stay unlabelled.
3. **Polygons.** Each room's label mask is vectorised along the cell edges, its holes (furniture)
   filled, and the rooms simplified together as a coverage (``shapely.coverage_simplify``), so
   neighbouring rooms keep sharing exactly the same edge.
4. **Doors.** Wherever two rooms touch (``walls``: in an opening, free or unknown cells there;
   ``distance``: in free space), a door is proposed: the part of their shared polygon edge that
   spans the touching cells, on one straight piece of it (the piece most of them are nearest
   to); its ends are added to both rooms' outlines, so the door lies exactly on their wall.

Rooms are named ``room_1``, ``room_2``, … by their centroid, south to north then west to east
(rows of ``name_row_height`` metres), or after the best-matching region of a reference layout
(:func:`name_after`).
"""

from __future__ import annotations

import heapq
import math
from dataclasses import dataclass, field, replace

import numpy as np
import shapely
from numpy.typing import NDArray
from scipy import ndimage
from shapely.geometry import LineString, MultiLineString, Point, Polygon
from shapely.geometry.base import BaseGeometry
from shapely.ops import substring, unary_union

from pfctl.core.mapping.grid import FREE, OCCUPIED, GridGeometry
from pfctl.core.mapping.house import Door, HouseLayout, Region
from pfctl.core.mapping.orientation import rotate_points, rotated_map, wall_orientation

XY = tuple[float, float]

_FOUR = np.array([[0, 1, 0], [1, 1, 1], [0, 1, 0]], dtype=bool)
_EIGHT = np.ones((3, 3), dtype=bool)


@dataclass(frozen=True)
class RoomParams:
    """Parameters of :func:`segment_rooms` (metres and square metres).

    Attributes:
        door_width: the widest door or opening to cut at (3.2 m: doors are ~0.8–1.4 m, the
            opening between a living room and a kitchen up to 3 m).
        method: ``walls`` (openings in wall lines) or ``distance`` (distance transform); see the
            module docstring.
        jamb_length: ``walls``: how far a wall line must continue past an opening (0.2 m).
        wall_thickness: ``walls``: the thickest a wall line may be where it meets an opening
            (0.2 m; furniture is 0.3 m deep or more).
        core_radius: the distance-transform threshold of step 1; ``None`` means
            ``door_width/2 + resolution``. Must be below half the narrowest room or corridor.
        min_core_area: cores smaller than this are dropped before growing (0.5 m²).
        min_room_area: grown rooms smaller than this are merged into a neighbour (2.0 m²).
        simplify_tolerance: coverage simplification of the polygons, roughly the square root of
            the largest triangle area removed; ``None`` means ``max(0.2, 3·resolution)``.
        wall_reach: occupied cells (walls, furniture) connected to a room and up to this far from
            its free space join the nearest room, so polygons reach the wall middle lines and
            cover furniture; ``None`` (default) means no limit.
        noise_area: non-free blobs (occupied or unknown, 8-connected) up to this size inside the
            free space count as free: speckle, pinholes, chair legs (0.1 m²; 0 = off).
        min_door_width: touching stretches narrower than this are not proposed as doors (0.3 m).
        name_row_height: centroid rows for the deterministic ``room_N`` order (1.0 m).
        align_walls: ``walls``: turn the map so its walls are axis-aligned before looking for
            wall lines, and the rooms and doors back (a SLAM map is rotated by wherever the
            mapping started); see :func:`segment_free_space`.
        min_manhattan: ``walls``: the least strength of the dominant wall orientation
            (:func:`~pfctl.core.mapping.orientation.wall_orientation`, 0–1) for the walls
            method; below it the walls run in too many directions and ``distance`` is used (0.35;
            Manhattan homes measure ~0.7).
    """

    door_width: float = 3.2
    method: str = "walls"
    jamb_length: float = 0.2
    wall_thickness: float = 0.2
    core_radius: float | None = None
    min_core_area: float = 0.5
    min_room_area: float = 2.0
    simplify_tolerance: float | None = None
    wall_reach: float | None = None
    noise_area: float = 0.1
    min_door_width: float = 0.3
    name_row_height: float = 1.0
    align_walls: bool = True
    min_manhattan: float = 0.35


@dataclass(frozen=True)
class ProposedRoom:
    """One segmented room: its label in the label image, name, polygon and area (m²)."""

    label: int
    name: str
    polygon: tuple[XY, ...]
    area: float

    def shape(self) -> Polygon:
        """The polygon as a shapely Polygon."""
        return Polygon(self.polygon)


@dataclass(frozen=True)
class ProposedDoor:
    """A door proposed where two rooms touch in free space: the two room names and the segment."""

    between: tuple[str, str]
    segment: tuple[XY, XY]

    @property
    def width(self) -> float:
        """The length of the door segment, metres."""
        return math.dist(*self.segment)


@dataclass(frozen=True)
class RoomSegmentation:
    """The result of :func:`segment_rooms`.

    Attributes:
        labels: int32 image of the grid's shape; 0 = no room (unknown, or unreachable), else the
            room's ``label``. Free cells and the walls/furniture they touch are labelled.
        geometry: the grid the labels live on.
        rooms: the rooms, in name order.
        doors: the proposed doors, sorted by the names they join.
        core_radius: the distance-transform threshold that was used, metres.
        wall_angle: the angle (radians, counter-clockwise) the walls were turned from the grid
            axes and segmented at; 0 if they were segmented as they are.
        warnings: one line each about how the map was segmented (e.g. a fallback method).
    """

    labels: NDArray[np.int32]
    geometry: GridGeometry
    rooms: tuple[ProposedRoom, ...]
    doors: tuple[ProposedDoor, ...] = field(default=())
    core_radius: float = 0.0
    wall_angle: float = 0.0
    warnings: tuple[str, ...] = ()

    def layout(self) -> HouseLayout:
        """The rooms and doors as a :class:`HouseLayout` (no obstacles)."""
        return HouseLayout(
            regions=tuple(Region(r.name, r.polygon) for r in self.rooms),
            doors=tuple(Door(d.between, d.segment) for d in self.doors),
        )

    def room(self, name: str) -> ProposedRoom:
        """The room called ``name``; KeyError if there is none."""
        for r in self.rooms:
            if r.name == name:
                return r
        raise KeyError(name)


# --------------------------------------------------------------------------------------------
# raster steps


def _cores(free: NDArray[np.bool_], dist: NDArray[np.float64], radius: float, min_cells: int):
    """Label the free cells farther than ``radius`` from obstacles; drop small components."""
    cores, n = ndimage.label(free & (dist > radius), structure=_FOUR)
    if n == 0:
        return cores.astype(np.int32)
    sizes = ndimage.sum_labels(np.ones_like(cores), cores, index=np.arange(1, n + 1))
    keep = np.zeros(n + 1, dtype=np.int32)
    kept = [i + 1 for i, s in enumerate(sizes) if s >= min_cells]
    for new, old in enumerate(kept, start=1):
        keep[old] = new
    return keep[cores]


def _runs_across(occupied: NDArray[np.bool_]) -> NDArray[np.int32]:
    """Per occupied cell, the length of the vertical run of occupied cells through it; 0 else."""
    h = occupied.shape[0]
    up = np.zeros(occupied.shape, dtype=np.int32)
    down = np.zeros(occupied.shape, dtype=np.int32)
    occ = occupied.astype(np.int32)
    up[0] = occ[0]
    for r in range(1, h):
        up[r] = (up[r - 1] + 1) * occ[r]
    down[h - 1] = occ[h - 1]
    for r in range(h - 2, -1, -1):
        down[r] = (down[r + 1] + 1) * occ[r]
    return np.where(occupied, up + down - 1, 0).astype(np.int32)


def _row_gaps(
    occupied: NDArray[np.bool_],
    gap_cells: tuple[int, int],
    jamb_cells: int,
    thin_cells: int,
) -> NDArray[np.bool_]:
    """Openings in horizontal wall lines: per row, a run of non-occupied cells ``gap_cells``
    (lowest, highest) long between two jambs, each a straight run of at least ``jamb_cells``
    occupied cells in the same row whose first two cells are at most ``thin_cells`` thick
    across (a wall, not the side of a piece of furniture, nor a wall seen end-on)."""
    h, w = occupied.shape
    across = _runs_across(occupied)
    occ = occupied.astype(np.int32)
    left = np.zeros(occupied.shape, dtype=np.int32)  # occupied run ending here, from the west
    right = np.zeros(occupied.shape, dtype=np.int32)  # occupied run starting here, to the east
    left[:, 0] = occ[:, 0]
    for c in range(1, w):
        left[:, c] = (left[:, c - 1] + 1) * occ[:, c]
    right[:, w - 1] = occ[:, w - 1]
    for c in range(w - 2, -1, -1):
        right[:, c] = (right[:, c + 1] + 1) * occ[:, c]
    thin = occupied & (across <= thin_cells)
    out = np.zeros(occupied.shape, dtype=bool)
    lo, hi = gap_cells
    for r in range(h):
        row = occupied[r]
        edges = np.flatnonzero(np.diff(row.astype(np.int8)))
        # a gap starts after an occupied cell (edge at c0-1) and ends before one (edge at c1)
        starts = [int(e) + 1 for e in edges if row[e]]
        ends = [int(e) for e in edges if not row[e]]
        for c0 in starts:
            c1 = next((e for e in ends if e >= c0), None)
            if c1 is None or not lo <= c1 - c0 + 1 <= hi:
                continue
            a, b = c0 - 1, c1 + 1
            if left[r, a] < jamb_cells or right[r, b] < jamb_cells:
                continue
            if a < 1 or b > w - 2:
                continue
            if thin[r, a] and thin[r, a - 1] and thin[r, b] and thin[r, b + 1]:
                out[r, c0 : c1 + 1] = True
    return out


def _wall_openings(
    occupied: NDArray[np.bool_], res: float, params: RoomParams
) -> NDArray[np.bool_]:
    """The cells of every opening in a wall line, horizontal or vertical (see :func:`_row_gaps`):
    doors and wide openings between two spaces, which the segmentation closes to find rooms."""
    gap = (
        max(1, math.ceil(params.min_door_width / res)),
        max(1, math.floor(params.door_width / res)),
    )
    jamb = max(2, round(params.jamb_length / res))
    thin = max(1, round(params.wall_thickness / res))
    return _row_gaps(occupied, gap, jamb, thin) | _row_gaps(occupied.T, gap, jamb, thin).T


def _furniture(occupied: NDArray[np.bool_], thick_cells: int) -> NDArray[np.bool_]:
    """The occupied cells of blobs thick enough to hold a ``thick_cells`` square: furniture (walls
    are thinner)."""
    return ndimage.binary_opening(occupied, structure=np.ones((thick_cells, thick_cells), bool))


def _despeckle(free: NDArray[np.bool_], max_cells: int) -> NDArray[np.bool_]:
    """Free space with every non-free blob of at most ``max_cells`` cells (8-connected) inside it
    counted as free: laser speckle and unknown pinholes of a mapped room, not walls."""
    blobs, n = ndimage.label(~free, structure=_EIGHT)
    if n == 0:
        return free
    sizes = np.bincount(blobs.ravel(), minlength=n + 1)
    small = sizes <= max_cells
    small[0] = False
    return free | small[blobs]


def _watershed(
    labels: NDArray[np.int32], free: NDArray[np.bool_], dist: NDArray[np.float64]
) -> NDArray[np.int32]:
    """Grow ``labels`` over ``free`` by a priority flood: largest bottleneck distance first.

    Each unlabelled free cell receives the label of the first neighbour that reaches it along the
    path whose smallest distance-transform value is largest (ties: first come, first served), so
    fronts from two cores meet at the narrowest point between them.
    """
    out = labels.copy()
    h, w = out.shape
    heap: list[tuple[float, int, int, int]] = []
    counter = 0
    rows, cols = np.nonzero(out)
    for r, c in zip(rows.tolist(), cols.tolist(), strict=True):
        heap.append((-float(dist[r, c]), counter, r, c))
        counter += 1
    heapq.heapify(heap)
    free_l = free.tolist()
    dist_l = dist.tolist()
    out_l = out.tolist()
    while heap:
        neg, _, r, c = heapq.heappop(heap)
        lab = out_l[r][c]
        for rr, cc in ((r - 1, c), (r + 1, c), (r, c - 1), (r, c + 1)):
            if 0 <= rr < h and 0 <= cc < w and free_l[rr][cc] and out_l[rr][cc] == 0:
                out_l[rr][cc] = lab
                prio = max(neg, -dist_l[rr][cc])
                heapq.heappush(heap, (prio, counter, rr, cc))
                counter += 1
    return np.asarray(out_l, dtype=np.int32)


def _grow_into(
    labels: NDArray[np.int32], allowed: NDArray[np.bool_], reach_cells: float
) -> NDArray[np.int32]:
    """Give ``allowed`` unlabelled cells within ``reach_cells`` the label of the nearest room.

    Only cells of the ``allowed ∪ labelled`` components (8-connectivity) that hold a room are
    considered. Nearest in the Euclidean sense (``distance_transform_edt`` with indices), so a
    wall between two rooms is split down its middle line and a T-junction splits cleanly.
    """
    comp, _ = ndimage.label(allowed | (labels > 0), structure=_EIGHT)
    holding = np.unique(comp[labels > 0])
    connected = np.isin(comp, holding[holding > 0])
    dist, (ir, ic) = ndimage.distance_transform_edt(labels == 0, return_indices=True)
    take = allowed & connected & (labels == 0) & (dist <= reach_cells)
    out = labels.copy()
    out[take] = labels[ir[take], ic[take]]
    return out


def _furniture_to_rooms(
    labels: NDArray[np.int32], occupied: NDArray[np.bool_], thick_cells: int
) -> NDArray[np.int32]:
    """Give each thick occupied blob (furniture: it holds a ``thick_cells`` square, a wall does
    not) wholly to the room it borders most, so a wardrobe against a wall stays in its room
    instead of being split with the room behind the wall."""
    blobs, n = ndimage.label(_furniture(occupied, thick_cells), structure=_EIGHT)
    if n == 0:
        return labels
    out = labels.copy()
    for k, sl in enumerate(ndimage.find_objects(blobs), start=1):
        if sl is None:
            continue
        grown = tuple(slice(max(0, s.start - 1), s.stop + 1) for s in sl)
        blob = blobs[grown] == k
        ring = ndimage.binary_dilation(blob, structure=_FOUR) & ~blob
        around = labels[grown][ring]
        around = around[around > 0]
        if around.size:
            out[grown][blob] = np.bincount(around).argmax()
    return out


def _relabel(labels: NDArray[np.int32]) -> NDArray[np.int32]:
    """Renumber the labels present to 1..n in order of first appearance (row-major)."""
    present = [v for v in dict.fromkeys(labels[labels > 0].tolist())]
    lut = np.zeros(int(labels.max()) + 1, dtype=np.int32)
    for new, old in enumerate(present, start=1):
        lut[old] = new
    return lut[labels]


def _contacts(labels: NDArray[np.int32], mask: NDArray[np.bool_]) -> dict[tuple[int, int], int]:
    """Count 4-neighbour contacts between different labels among cells of ``mask``."""
    counts: dict[tuple[int, int], int] = {}
    for a, b, ma, mb in (
        (labels[:, :-1], labels[:, 1:], mask[:, :-1], mask[:, 1:]),
        (labels[:-1, :], labels[1:, :], mask[:-1, :], mask[1:, :]),
    ):
        sel = ma & mb & (a > 0) & (b > 0) & (a != b)
        for x, y in zip(a[sel].tolist(), b[sel].tolist(), strict=True):
            key = (min(x, y), max(x, y))
            counts[key] = counts.get(key, 0) + 1
    return counts


def _merge_small(labels: NDArray[np.int32], min_cells: int) -> NDArray[np.int32]:
    """Merge rooms smaller than ``min_cells`` into the neighbour they touch most; drop if none."""
    out = labels.copy()
    while True:
        ids, sizes = np.unique(out[out > 0], return_counts=True)
        small = [(int(s), int(i)) for i, s in zip(ids, sizes, strict=True) if s < min_cells]
        if not small:
            return out
        _, victim = min(small)
        contacts = _contacts(out, out > 0)
        best = max(
            ((n, (b if a == victim else a)) for (a, b), n in contacts.items() if victim in (a, b)),
            default=None,
        )
        out[out == victim] = best[1] if best else 0


def _fill_holes(labels: NDArray[np.int32]) -> NDArray[np.int32]:
    """Give the unlabelled cells the rooms enclose (furniture islands, unknown pockets, also one
    in a doorway between two rooms) the label of the nearest room cell."""
    rooms = labels > 0
    holes = ndimage.binary_fill_holes(rooms) & ~rooms
    if not holes.any():
        return labels
    _, (ir, ic) = ndimage.distance_transform_edt(~rooms, return_indices=True)
    out = labels.copy()
    out[holes] = labels[ir[holes], ic[holes]]
    return out


# --------------------------------------------------------------------------------------------
# vectorisation


def _label_polygons(
    labels: NDArray[np.int32], geometry: GridGeometry, tolerance: float
) -> dict[int, Polygon]:
    """One simplified polygon per label, edge-matched with its neighbours (a coverage)."""
    res = geometry.resolution
    ox, oy = geometry.origin
    pad = np.pad(labels, 1, constant_values=0)
    segs: list[tuple[tuple[float, float], tuple[float, float]]] = []
    # vertical cell edges: between column c-1 and c (padded indices), at x = ox + (c-1)·res
    diff_v = pad[1:-1, :-1] != pad[1:-1, 1:]
    for r, c in zip(*np.nonzero(diff_v), strict=True):
        x = ox + c * res
        segs.append(((x, oy + r * res), (x, oy + (r + 1) * res)))
    diff_h = pad[:-1, 1:-1] != pad[1:, 1:-1]
    for r, c in zip(*np.nonzero(diff_h), strict=True):
        y = oy + r * res
        segs.append(((ox + c * res, y), (ox + (c + 1) * res, y)))
    if not segs:
        return {}
    lines = shapely.line_merge(MultiLineString(segs))
    faces = list(shapely.get_parts(shapely.polygonize(list(shapely.get_parts(lines)))))
    by_label: dict[int, list[Polygon]] = {}
    for face in faces:
        p = face.representative_point()
        r, c = geometry.world_to_cell(np.array([p.x, p.y]))
        if not geometry.in_bounds(r, c):
            continue
        lab = int(labels[int(r), int(c)])
        if lab > 0:
            by_label.setdefault(lab, []).append(face)
    keys = sorted(by_label)
    merged = [unary_union(by_label[k]) for k in keys]
    simplified = shapely.coverage_simplify(np.array(merged, dtype=object), tolerance)
    out: dict[int, Polygon] = {}
    for k, g in zip(keys, simplified, strict=True):
        parts = [p for p in shapely.get_parts(g) if isinstance(p, Polygon)]
        if parts:
            out[k] = max(parts, key=lambda p: p.area)
    return out


def _ring(poly: Polygon, res: float) -> tuple[XY, ...]:
    """The exterior ring, without collinear vertices, counter-clockwise from its lowest (then
    leftmost) vertex, without the closing point, rounded to the grid."""
    outline = Polygon(poly.exterior).simplify(0.0)  # drop collinear vertices (junctions)
    ring = shapely.orient_polygons(outline).exterior.coords[:-1]
    digits = max(3, -math.floor(math.log10(res)) + 1) if res < 1 else 3
    pts = [(round(x, digits) + 0.0, round(y, digits) + 0.0) for x, y in ring]
    start = min(range(len(pts)), key=lambda i: (pts[i][1], pts[i][0]))
    return tuple(pts[start:] + pts[:start])


def _with_vertices(ring: tuple[XY, ...], points: tuple[XY, XY], res: float) -> tuple[XY, ...]:
    """``ring`` with each of ``points`` inserted as a vertex on the edge it lies on (within a
    cell), unless it is a vertex already: a rounded door end on a slanted edge is then exactly on
    the outline of both rooms it joins."""
    out = list(ring)
    for p in points:
        if p in out:
            continue
        n = len(out)
        dists = [LineString([out[i], out[(i + 1) % n]]).distance(Point(p)) for i in range(n)]
        i = min(range(n), key=dists.__getitem__)
        if dists[i] <= res:
            out.insert(i + 1, p)
    return tuple(out)


def _door_segment(
    shared: BaseGeometry, points: NDArray[np.float64], res: float
) -> tuple[XY, XY] | None:
    """The part of the shared edge ``shared`` that spans ``points`` (plus half a cell each way)."""
    lines = [g for g in shapely.get_parts(shared) if isinstance(g, LineString | MultiLineString)]
    if not lines:
        return None
    merged = shapely.line_merge(unary_union(lines))
    # straight pieces only: a segment spanning a bend would cut the corner, off the shared wall
    pieces = [
        LineString(pair)
        for part in shapely.get_parts(merged)
        for pair in zip(part.coords[:-1], part.coords[1:], strict=True)
        if math.dist(*pair) > 0
    ]
    if not pieces:
        return None
    # the piece most of the touching points are nearest to (then the one nearest their centre)
    centre = Point(points.mean(axis=0))
    nearest = [min(range(len(pieces)), key=lambda i: pieces[i].distance(Point(p))) for p in points]
    line = pieces[
        max(range(len(pieces)), key=lambda i: (nearest.count(i), -pieces[i].distance(centre)))
    ]
    ts = [line.project(Point(p)) for p in points]
    t0, t1 = max(0.0, min(ts) - res / 2.0), min(line.length, max(ts) + res / 2.0)
    if t1 - t0 <= 0:
        return None
    seg = substring(line, t0, t1)
    coords = list(seg.coords)
    a, b = coords[0], coords[-1]
    digits = max(3, -math.floor(math.log10(res)) + 1) if res < 1 else 3
    a = (round(a[0], digits) + 0.0, round(a[1], digits) + 0.0)
    b = (round(b[0], digits) + 0.0, round(b[1], digits) + 0.0)
    return (a, b) if a <= b else (b, a)


def _doors(
    labels: NDArray[np.int32],
    free: NDArray[np.bool_],
    geometry: GridGeometry,
    polygons: dict[int, Polygon],
    min_width: float,
) -> list[tuple[tuple[int, int], tuple[XY, XY]]]:
    """Doors where two labels touch in free space: one per connected stretch of contact."""
    res = geometry.resolution
    pairs: dict[tuple[int, int], list[tuple[float, float]]] = {}
    ox, oy = geometry.origin
    for axis in (0, 1):
        if axis == 1:
            a, b = labels[:, :-1], labels[:, 1:]
            fa, fb = free[:, :-1], free[:, 1:]
        else:
            a, b = labels[:-1, :], labels[1:, :]
            fa, fb = free[:-1, :], free[1:, :]
        sel = fa & fb & (a > 0) & (b > 0) & (a != b)
        rr, cc = np.nonzero(sel)
        for r, c, la, lb in zip(rr, cc, a[sel], b[sel], strict=True):
            # midpoint between the two touching cell centres
            x = ox + (c + 1.0 if axis == 1 else c + 0.5) * res
            y = oy + (r + 1.0 if axis == 0 else r + 0.5) * res
            key = (int(min(la, lb)), int(max(la, lb)))
            pairs.setdefault(key, []).append((x, y))
    doors: list[tuple[tuple[int, int], tuple[XY, XY]]] = []
    for key in sorted(pairs):
        if key[0] not in polygons or key[1] not in polygons:
            continue
        pts = np.asarray(pairs[key])
        # split the contact points into stretches: a gap of up to 0.4 m (a speck, a bump, an
        # unknown patch in the doorway) does not split a door in two
        mask = np.zeros(geometry.shape, dtype=bool)
        rows, cols = geometry.world_to_cell(pts)
        mask[np.clip(rows, 0, geometry.height - 1), np.clip(cols, 0, geometry.width - 1)] = True
        bridge = max(1, math.ceil(0.2 / res))
        comp, n = ndimage.label(
            ndimage.binary_dilation(mask, structure=_EIGHT, iterations=bridge), _EIGHT
        )
        which = comp[np.clip(rows, 0, geometry.height - 1), np.clip(cols, 0, geometry.width - 1)]
        shared = polygons[key[0]].intersection(polygons[key[1]])
        for k in range(1, n + 1):
            stretch = pts[which == k]
            if len(stretch) == 0:
                continue
            seg = _door_segment(shared, stretch, res)
            if seg is not None and math.dist(*seg) >= min_width:
                doors.append((key, seg))
    return doors


def _proposed_rooms(
    order: list[int],
    names: dict[int, str],
    rings: dict[int, tuple[XY, ...]],
    polygons: dict[int, Polygon],
) -> tuple[ProposedRoom, ...]:
    """The rooms in ``order``: each label's name, outline (``rings``) and area (m², mm)."""
    return tuple(
        ProposedRoom(
            label=lab,
            name=names[lab],
            polygon=rings[lab],
            area=round(float(polygons[lab].area), 3),
        )
        for lab in order
    )


def _order(polygons: dict[int, Polygon], row_height: float) -> list[int]:
    """Labels sorted by centroid: rows of ``row_height`` m south to north, then west to east."""

    def key(lab: int) -> tuple[int, float, float]:
        c = polygons[lab].centroid
        return (math.floor(c.y / row_height), c.x, c.y)

    return sorted(polygons, key=key)


# --------------------------------------------------------------------------------------------
# public API


#: Walls turned less than this from the grid axes are segmented as they are (radians).
_ALIGNED = math.radians(0.2)
#: The largest ``door_width`` of the ``distance`` fallback: its cores need rooms wider than
#: ``door_width + 2·resolution``, and the walls method's 3.2 m would leave most rooms without one.
_FALLBACK_DOOR_WIDTH = 1.0


def segment_free_space(
    states: NDArray[np.integer],
    geometry: GridGeometry,
    params: RoomParams | None = None,
) -> RoomSegmentation:
    """Segment a trinary map (:data:`FREE`/:data:`OCCUPIED`/:data:`UNKNOWN` per cell) into rooms.

    See the module docstring for the method. With ``walls`` (and ``align_walls``), the map's
    dominant wall orientation is estimated first
    (:func:`~pfctl.core.mapping.orientation.wall_orientation`): walls turned from the grid axes
    are turned back (the map resampled, :func:`~pfctl.core.mapping.orientation.rotated_map`),
    segmented there, and the rooms, doors and labels turned into the map frame again; a map whose
    walls have no dominant orientation (strength below ``min_manhattan``) is segmented with
    ``distance`` (``door_width`` at most 1 m) and one warning in ``warnings``. Raises
    ``ValueError`` if no room is found (no free core wider than ``2·core_radius``).
    """
    params = params or RoomParams()
    states = np.asarray(states)
    if states.shape != geometry.shape:
        raise ValueError(f"states of shape {states.shape} do not match the grid {geometry.shape}")
    if params.method != "walls" or not params.align_walls:
        return _segment(states, geometry, params)
    angle, strength = wall_orientation(states == OCCUPIED)
    if strength < params.min_manhattan:
        fallback = replace(
            params, method="distance", door_width=min(params.door_width, _FALLBACK_DOOR_WIDTH)
        )
        warning = (
            f"the walls run in no dominant direction (strength {strength:.2f} < "
            f"{params.min_manhattan:g}): rooms by the distance transform, door width "
            f"{fallback.door_width:g} m"
        )
        return replace(_segment(states, geometry, fallback), warnings=(warning,))
    if abs(angle) < _ALIGNED:
        return _segment(states, geometry, params)
    turned, turned_geometry = rotated_map(states, geometry, -angle)
    turned = _fill_pinholes(turned)
    # resampled walls are a cell thicker across at each step of their staircase
    thicker = replace(params, wall_thickness=params.wall_thickness + geometry.resolution)
    return _turned_back(_segment(turned, turned_geometry, thicker), geometry, angle, params)


def _turned_back(
    seg: RoomSegmentation, geometry: GridGeometry, angle: float, params: RoomParams
) -> RoomSegmentation:
    """A segmentation made on the map turned by ``-angle``, turned by ``angle`` into the map
    frame of ``geometry``: polygons and doors turned and rounded to the grid as
    :func:`_ring` does (a door's ends stay vertices of both its rooms), labels sampled at each
    map cell's centre, rooms renamed in map-frame order."""
    res = geometry.resolution
    digits = max(3, -math.floor(math.log10(res)) + 1) if res < 1 else 3

    def turn(points: tuple[XY, ...]) -> list[XY]:
        out = rotate_points(np.asarray(points, dtype=np.float64), angle)
        return [(round(float(x), digits) + 0.0, round(float(y), digits) + 0.0) for x, y in out]

    polygons: dict[int, Polygon] = {}
    rings: dict[int, tuple[XY, ...]] = {}
    shared = _shared_vertices({room.label: room.polygon for room in seg.rooms})
    for room in seg.rooms:
        pts = turn(shared[room.label])
        start = min(range(len(pts)), key=lambda i: (pts[i][1], pts[i][0]))
        rings[room.label] = tuple(pts[start:] + pts[:start])
        polygons[room.label] = Polygon(rings[room.label])
    order = _order(polygons, params.name_row_height)
    names = {lab: f"room_{i}" for i, lab in enumerate(order, start=1)}
    label_of = {room.name: room.label for room in seg.rooms}
    doors = []
    for d in seg.doors:
        a, b = turn(d.segment)
        la, lb = (label_of[n] for n in d.between)
        pair = tuple(sorted((names[la], names[lb])))
        doors.append(ProposedDoor(between=pair, segment=(a, b) if a <= b else (b, a)))  # type: ignore[arg-type]
    centres = geometry.cell_to_world(*np.indices(geometry.shape))
    rows, cols = seg.geometry.world_to_cell(rotate_points(centres, -angle))
    inside = seg.geometry.in_bounds(rows, cols)
    labels = np.zeros(geometry.shape, dtype=np.int32)
    labels[inside] = seg.labels[rows[inside], cols[inside]]
    rooms = _proposed_rooms(order, names, rings, polygons)
    return replace(
        seg,
        labels=labels,
        geometry=geometry,
        rooms=rooms,
        doors=tuple(sorted(doors, key=lambda d: (d.between, d.segment))),
        wall_angle=angle,
    )


def _fill_pinholes(states: NDArray[np.integer]) -> NDArray[np.integer]:
    """``states`` with every non-occupied cell between two occupied ones (west and east, or south
    and north) occupied: the one-cell holes that resampling a turned map punches into its walls
    (they cut a wall line's jamb short). No opening is that narrow (``min_door_width``)."""
    occ = states == OCCUPIED
    pad = np.pad(occ, 1, constant_values=False)
    between = (pad[1:-1, :-2] & pad[1:-1, 2:]) | (pad[:-2, 1:-1] & pad[2:, 1:-1])
    out = states.copy()
    out[between & ~occ] = OCCUPIED
    return out


def _shared_vertices(rings: dict[int, tuple[XY, ...]]) -> dict[int, tuple[XY, ...]]:
    """Each ring with every vertex of another ring that lies on one of its edges (a T-junction)
    inserted as a vertex, so that after turning and rounding, neighbours still meet exactly."""
    out = dict(rings)
    for lab in rings:
        boundary = Polygon(rings[lab]).exterior
        own = set(rings[lab])
        extra = [
            p
            for other, ring in rings.items()
            if other != lab
            for p in ring
            if p not in own and boundary.distance(Point(p)) <= 1e-9
        ]
        for p in dict.fromkeys(extra):
            pts = list(out[lab])
            n = len(pts)
            i = min(
                range(n),
                key=lambda i: LineString([pts[i], pts[(i + 1) % n]]).distance(Point(p)),
            )
            pts.insert(i + 1, p)
            out[lab] = tuple(pts)
    return out


def _segment(
    states: NDArray[np.integer], geometry: GridGeometry, params: RoomParams
) -> RoomSegmentation:
    """:func:`segment_free_space` on the map as it is (no turning)."""
    res = geometry.resolution
    free = states == FREE
    occupied = states == OCCUPIED
    if params.noise_area > 0:
        free = _despeckle(free, max(1, math.floor(params.noise_area / (res * res))))
        occupied &= ~free
    radius = params.core_radius if params.core_radius is not None else params.door_width / 2 + res
    cell_area = res * res

    dist = ndimage.distance_transform_edt(free) * res
    min_core = max(1, math.ceil(params.min_core_area / cell_area))
    if params.method not in ("walls", "distance"):
        raise ValueError(f"expected method 'walls' or 'distance', got {params.method!r}")
    if params.method == "walls":
        gaps = _wall_openings(occupied, res, params)
        openings = gaps & free
        cores = _cores(free & ~openings, dist, 0.0, min_core)
        # rooms first grow over their own free space, then split each opening down its middle
        labels = _watershed(cores, free & ~openings, dist)
        labels = _grow_into(labels, openings, math.inf)
        # doors are where rooms touch in an opening (free or unknown cells there)
        door_cells = ndimage.binary_dilation(gaps, structure=_EIGHT) & ~occupied
    else:
        cores = _cores(free, dist, radius, min_core)
        labels = cores
        door_cells = free
    if cores.max() == 0:
        raise ValueError(
            f"no room found: no free space farther than {radius:.2f} m from an obstacle"
        )
    labels = _watershed(labels, free, dist)
    labels = _merge_small(labels, max(1, math.ceil(params.min_room_area / cell_area)))
    reach = math.inf if params.wall_reach is None else params.wall_reach / res
    if params.method == "walls":
        labels = _furniture_to_rooms(
            labels, occupied, max(2, round(params.wall_thickness / res) + 1)
        )
    labels = _grow_into(labels, occupied, reach)
    labels = _fill_holes(labels)
    labels = _relabel(labels)

    tolerance = (
        params.simplify_tolerance if params.simplify_tolerance is not None else max(0.2, 3 * res)
    )
    polygons = _label_polygons(labels, geometry, tolerance)
    order = _order(polygons, params.name_row_height)
    names = {lab: f"room_{i}" for i, lab in enumerate(order, start=1)}
    found = _doors(labels, door_cells, geometry, polygons, params.min_door_width)
    rings = {lab: _ring(polygons[lab], res) for lab in order}
    for (a, b), seg in found:  # door ends as vertices of both rooms: exactly on their wall
        rings[a] = _with_vertices(rings[a], seg, res)
        rings[b] = _with_vertices(rings[b], seg, res)
    rooms = _proposed_rooms(order, names, rings, polygons)
    doors = tuple(
        sorted(
            (ProposedDoor(between=(names[a], names[b]), segment=seg) for (a, b), seg in found),
            key=lambda d: (d.between, d.segment),
        )
    )
    return RoomSegmentation(
        labels=labels, geometry=geometry, rooms=rooms, doors=doors, core_radius=radius
    )


def segment_rooms(grid: object, params: RoomParams | None = None) -> RoomSegmentation:
    """Segment an :class:`~pfctl.core.mapping.grid.OccupancyGrid` (its ``states()`` and
    ``geometry``)."""
    return segment_free_space(grid.states(), grid.geometry, params)  # type: ignore[attr-defined]


def polygon_iou(a: BaseGeometry, b: BaseGeometry) -> float:
    """Intersection over union of two shapely areas (0 when both are empty)."""
    union = a.union(b).area
    return float(a.intersection(b).area / union) if union > 0 else 0.0


def match_regions(
    proposed: list[Region] | tuple[Region, ...],
    reference: list[Region] | tuple[Region, ...],
    min_iou: float = 0.5,
) -> dict[str, tuple[str, float]]:
    """Match proposed regions to reference regions one-to-one by polygon IoU.

    Greedy on decreasing IoU (optimal for the near-disjoint rooms of a house). Returns
    ``{proposed name: (reference name, iou)}`` for pairs with IoU ≥ ``min_iou``.
    """
    scores = []
    for p in proposed:
        pp = Polygon(p.polygon)
        for r in reference:
            iou = polygon_iou(pp, Polygon(r.polygon))
            if iou >= min_iou:
                scores.append((iou, p.name, r.name))
    scores.sort(key=lambda s: (-s[0], s[1], s[2]))
    used_p: set[str] = set()
    used_r: set[str] = set()
    out: dict[str, tuple[str, float]] = {}
    for iou, pn, rn in scores:
        if pn in used_p or rn in used_r:
            continue
        used_p.add(pn)
        used_r.add(rn)
        out[pn] = (rn, iou)
    return out


def name_after(
    segmentation: RoomSegmentation, reference: HouseLayout, min_iou: float = 0.5
) -> RoomSegmentation:
    """Rename the rooms after the reference regions they match (IoU ≥ ``min_iou``).

    Unmatched rooms keep a ``room_N`` name that does not clash with a reference name.
    """
    matches = match_regions(segmentation.layout().regions, reference.regions, min_iou)
    taken = {rn for rn, _ in matches.values()}
    names: dict[str, str] = {}
    counter = 0
    for room in segmentation.rooms:
        if room.name in matches:
            names[room.name] = matches[room.name][0]
        else:
            counter += 1
            while f"room_{counter}" in taken:
                counter += 1
            names[room.name] = f"room_{counter}"
    rooms = tuple(replace(r, name=names[r.name]) for r in segmentation.rooms)
    doors = tuple(
        sorted(
            (
                ProposedDoor(between=(names[d.between[0]], names[d.between[1]]), segment=d.segment)
                for d in segmentation.doors
            ),
            key=lambda d: (d.between, d.segment),
        )
    )
    return replace(segmentation, rooms=rooms, doors=doors)


__all__ = [
    "ProposedDoor",
    "ProposedRoom",
    "RoomParams",
    "RoomSegmentation",
    "match_regions",
    "name_after",
    "polygon_iou",
    "segment_free_space",
    "segment_rooms",
]
