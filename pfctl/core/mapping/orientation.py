"""The dominant wall orientation of an occupancy map, and the map rotated by an angle.

A SLAM map's frame is where the mapping started, so a house whose walls meet at right angles is
usually drawn rotated by some arbitrary angle relative to the grid. Methods that look for wall
lines along grid rows and columns (room segmentation's ``walls`` method) need the walls axis-
aligned: :func:`wall_orientation` estimates the angle of the walls (modulo 90°) and how clearly
the map has one, and :func:`rotated_map` resamples the map into a frame rotated by an angle.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray
from scipy import ndimage

from pfctl.core.mapping.grid import UNKNOWN, GridGeometry

__all__ = ["rotate_points", "rotated_map", "wall_orientation"]


def wall_orientation(occupied: NDArray[np.bool_]) -> tuple[float, float]:
    """The dominant orientation of the walls in a mask of occupied cells, modulo 90°.

    The occupied mask is smoothed (a Gaussian of one cell) and its gradient taken; each edge
    cell's gradient direction ``θ`` votes ``exp(4iθ)`` weighted by the gradient's magnitude, so
    the faces of walls running at ``φ`` and at ``φ + 90°`` all vote for the same angle. The vote is
    refined by :func:`_sharpest` within 1.5° of it, which removes the pull of the staircase and
    corner cells of a rotated raster (the vote alone is off by up to ~0.7°).

    Returns ``(angle, strength)``: the angle in radians in ``[-π/4, π/4)`` by which the walls are
    turned counter-clockwise from the grid axes, and the share of the gradient magnitude that
    agrees with it (the resultant length of the first vote, 0–1): near 1 for a Manhattan house
    at any angle, low for walls in many directions. ``(0.0, 0.0)`` if there are no edges.
    """
    img = ndimage.gaussian_filter(occupied.astype(np.float64), 1.0)
    gx = ndimage.sobel(img, axis=1)
    gy = ndimage.sobel(img, axis=0)
    mag = np.hypot(gx, gy)
    edge = mag > 0.05 * mag.max() if mag.max() > 0 else mag > 0
    if not edge.any():
        return 0.0, 0.0
    theta = np.arctan2(gy[edge], gx[edge])
    weight = mag[edge]
    vote = np.sum(weight * np.exp(4j * theta))
    strength = float(abs(vote) / weight.sum())
    angle = float(np.angle(vote)) / 4.0
    angle = _sharpest(occupied, angle, math.radians(1.5), math.radians(0.05))
    angle = (angle + math.pi / 4) % (math.pi / 2) - math.pi / 4
    return angle, strength


def _sharpest(occupied: NDArray[np.bool_], guess: float, span: float, step: float) -> float:
    """The angle within ``guess ± span`` at which the occupied cells, turned back by it, pile up
    most in rows and columns: the sum of squared counts of their one-cell row and column
    histograms is largest when every straight wall falls into as few rows (or columns) as it
    can. Candidates are multiples of ``step``, so an axis-aligned map gives exactly 0."""
    rows, cols = np.nonzero(occupied)
    pts = np.stack([cols + 0.5, rows + 0.5], axis=-1).astype(np.float64)
    angles: list[float] = []
    scores: list[float] = []
    for k in range(round((guess - span) / step), round((guess + span) / step) + 1):
        turned = rotate_points(pts, -k * step)
        score = 0.0
        for axis in (0, 1):
            idx = np.floor(turned[:, axis]).astype(np.int64)
            counts = np.bincount(idx - idx.min())
            score += float(np.sum(counts.astype(np.float64) ** 2))
        angles.append(k * step)
        scores.append(score)
    # the middle of the best plateau: turning by less than a cell's worth changes no count
    top = [a for a, sc in zip(angles, scores, strict=True) if sc >= max(scores)]
    return top[len(top) // 2]


def rotate_points(xy: NDArray[np.float64], angle: float) -> NDArray[np.float64]:
    """Points ``(..., 2)`` rotated counter-clockwise by ``angle`` radians about the frame origin."""
    c, s = math.cos(angle), math.sin(angle)
    xy = np.asarray(xy, dtype=np.float64)
    return np.stack([c * xy[..., 0] - s * xy[..., 1], s * xy[..., 0] + c * xy[..., 1]], axis=-1)


def rotated_map(
    states: NDArray[np.integer], geometry: GridGeometry, angle: float
) -> tuple[NDArray[np.int8], GridGeometry]:
    """The map turned counter-clockwise by ``angle`` radians about the map frame's origin.

    A point ``p`` of the map is at ``R(angle)·p`` in the new map. The new grid has the same
    resolution and just covers the turned old one (origin a multiple of the resolution); each
    new cell takes the state of the old cell under its centre (nearest neighbour, so the map
    stays trinary), :data:`UNKNOWN` where that is outside the old grid.
    """
    res = geometry.resolution
    x0, x1, y0, y1 = geometry.extent
    corners = rotate_points(np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]]), angle)
    lo = np.floor(corners.min(axis=0) / res + 1e-9).astype(int)  # rounding off a turned corner
    hi = np.ceil(corners.max(axis=0) / res - 1e-9).astype(int)
    ox, oy = round(float(lo[0] * res), 9) + 0.0, round(float(lo[1] * res), 9) + 0.0
    width, height = int(hi[0] - lo[0]), int(hi[1] - lo[1])
    new = GridGeometry(resolution=res, width=int(width), height=int(height), origin=(ox, oy))
    centres = new.cell_to_world(*np.indices(new.shape))
    rows, cols = geometry.world_to_cell(rotate_points(centres, -angle))
    inside = geometry.in_bounds(rows, cols)
    out = np.full(new.shape, UNKNOWN, dtype=np.int8)
    out[inside] = np.asarray(states)[rows[inside], cols[inside]]
    return out, new
