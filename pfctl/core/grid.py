"""Occupancy grid of the paper (§II-B/C): p(m) per cell, O=1, F=0, U=0.5.

Layout: ``logodds`` has shape ``(height, width)``; row ``r`` is the y index and column ``c`` the x
index, so cell ``(r, c)`` covers ``[ox + c·res, ox + (c+1)·res) × [oy + r·res, oy + (r+1)·res)`` in
the map frame (REP-103: x forward, y left), with ``(ox, oy) = origin`` the lower-left corner of cell
``(0, 0)`` — the same convention as nav_msgs/OccupancyGrid (row-major, first row at the origin).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

FREE = 0
OCCUPIED = 1
UNKNOWN = -1


def logit(p: ArrayLike) -> NDArray[np.float64]:
    """log(p / (1 − p)), the log-odds of a probability."""
    p = np.asarray(p, dtype=float)
    return np.log(p / (1.0 - p))


def inv_logit(l: ArrayLike) -> NDArray[np.float64]:
    """The probability of a log-odds value: 1 / (1 + exp(−l))."""
    return 1.0 / (1.0 + np.exp(-np.asarray(l, dtype=float)))


@dataclass(frozen=True)
class GridGeometry:
    """Where a grid lies in the map frame: cell size (m), cells in x and y, lower-left corner."""

    resolution: float
    width: int
    height: int
    origin: tuple[float, float] = (0.0, 0.0)

    def world_to_cell(self, xy: ArrayLike) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
        """(rows, cols) of the cells containing points ``xy`` (shape (..., 2)); may be out of bounds."""
        xy = np.asarray(xy, dtype=float)
        cols = np.floor((xy[..., 0] - self.origin[0]) / self.resolution).astype(np.intp)
        rows = np.floor((xy[..., 1] - self.origin[1]) / self.resolution).astype(np.intp)
        return rows, cols

    def cell_to_world(self, rows: ArrayLike, cols: ArrayLike) -> NDArray[np.float64]:
        """Centres (..., 2) of cells ``(rows, cols)`` in the map frame."""
        rows = np.asarray(rows, dtype=float)
        cols = np.asarray(cols, dtype=float)
        x = self.origin[0] + (cols + 0.5) * self.resolution
        y = self.origin[1] + (rows + 0.5) * self.resolution
        return np.stack([x, y], axis=-1)

    def in_bounds(self, rows: ArrayLike, cols: ArrayLike) -> NDArray[np.bool_]:
        """True where ``(rows, cols)`` is a cell of this grid."""
        rows = np.asarray(rows)
        cols = np.asarray(cols)
        return (rows >= 0) & (rows < self.height) & (cols >= 0) & (cols < self.width)

    @property
    def shape(self) -> tuple[int, int]:
        return (self.height, self.width)

    @property
    def extent(self) -> tuple[float, float, float, float]:
        """(xmin, xmax, ymin, ymax) in metres, e.g. for matplotlib's ``imshow(origin='lower')``."""
        ox, oy = self.origin
        return (ox, ox + self.width * self.resolution, oy, oy + self.height * self.resolution)
