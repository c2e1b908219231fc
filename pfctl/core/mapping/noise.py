"""SLAM-like noise on a trinary map, for testing what reads maps as a user has them.

A map made by a SLAM package is not the clean raster of a floor plan: it has laser speckle in the
free space, walls whose faces are ragged by a cell or two, and unknown patches inside rooms (spots
the laser never saw: behind furniture, under a table, a mirror). :func:`slam_noise` adds the three
to a map of :data:`FREE`/:data:`OCCUPIED`/:data:`UNKNOWN` states, from a random generator, so the
same seed gives the same noisy map. It never opens a wall: ragged faces only grow into the free
space, so rooms stay as closed as they were.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy import ndimage

from pfctl.core.mapping.grid import FREE, OCCUPIED, UNKNOWN

__all__ = ["SlamNoise", "slam_noise"]


@dataclass(frozen=True)
class SlamNoise:
    """How much noise :func:`slam_noise` adds.

    Attributes:
        speckle: fraction of free cells turned into isolated occupied cells (laser speckle).
        ragged: probability that a free cell on a wall's face becomes occupied (a bump of one
            cell; the wall's face is ragged by one cell).
        unknown_per_m2: unknown patches per square metre of free space.
        unknown_radius: radius range of an unknown patch, metres.
    """

    speckle: float = 0.002
    ragged: float = 0.3
    unknown_per_m2: float = 0.08
    unknown_radius: tuple[float, float] = (0.1, 0.3)


def slam_noise(
    states: NDArray[np.integer],
    resolution: float,
    rng: np.random.Generator,
    noise: SlamNoise | None = None,
) -> NDArray[np.int8]:
    """A copy of ``states`` with speckle, ragged wall faces and unknown patches in free space."""
    noise = noise or SlamNoise()
    out = np.asarray(states).astype(np.int8).copy()
    free = out == FREE
    occupied = out == OCCUPIED
    # ragged faces: free cells touching a wall (4-neighbours) become occupied with p = ragged
    face = free & ndimage.binary_dilation(
        occupied, structure=ndimage.generate_binary_structure(2, 1)
    )
    out[face & (rng.random(out.shape) < noise.ragged)] = OCCUPIED
    # unknown patches (discs) inside the free space
    free = out == FREE
    rows, cols = np.nonzero(free)
    n = rng.poisson(noise.unknown_per_m2 * len(rows) * resolution * resolution) if len(rows) else 0
    yy, xx = np.mgrid[0 : out.shape[0], 0 : out.shape[1]]
    for _ in range(int(n)):
        k = int(rng.integers(len(rows)))
        radius = float(rng.uniform(*noise.unknown_radius)) / resolution
        r0, c0 = rows[k], cols[k]
        lo_r, hi_r = max(0, int(r0 - radius) - 1), min(out.shape[0], int(r0 + radius) + 2)
        lo_c, hi_c = max(0, int(c0 - radius) - 1), min(out.shape[1], int(c0 + radius) + 2)
        disc = (yy[lo_r:hi_r, lo_c:hi_c] - r0) ** 2 + (xx[lo_r:hi_r, lo_c:hi_c] - c0) ** 2
        window = out[lo_r:hi_r, lo_c:hi_c]
        window[(disc <= radius * radius) & (window == FREE)] = UNKNOWN
    # speckle: isolated occupied cells in what is still free
    free = out == FREE
    out[free & (rng.random(out.shape) < noise.speckle)] = OCCUPIED
    return out
