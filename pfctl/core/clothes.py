"""Clothing colour histograms and their similarity (Algorithm 2, §II-E).

The paper compares the clothes of a candidate with the target's by histogram intersection
(Swain & Ballard 1991), normalised by the target's mass:

    S(I, T) = Σ_j min(I_j, T_j) / Σ_j T_j                                  (Algorithm 2)

A person's clothes are two histograms, upper and lower body, of the pixels of that part in a
colour space (HSV by default: hue separates colours under changing light better than RGB), with
``bins`` per channel, each normalised to sum 1.

**Body split** (:func:`body_parts`). The body's pixels are its segmentation mask when the
detector gives one, else the central half of its box's width (a box holds background at its
sides). Rows: with keypoints, the upper body runs from ``neck`` to ``mid_hip`` and the lower body
from ``mid_hip`` down to ``ankles`` (or the box's bottom); without, fixed fractions of the box
height from human proportions (Drillis & Contini 1966: shoulders at ~18 %, hips at ~48-53 % of
the height from the top): upper 20-48 %, lower 55-95 %. The gap around the hips keeps the belt
line (either colour) out of both.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np

from pfctl.core.faces import Box

ColorSpace = Literal["hsv", "rgb", "lab"]

#: Box-height fractions (from the top) of the upper and lower body when no keypoints are known.
UPPER_ROWS = (0.20, 0.48)
LOWER_ROWS = (0.55, 0.95)
#: Without a mask, the central fraction of the box width taken as the body.
CENTRAL_WIDTH = 0.5

#: OpenCV's 8-bit channel ranges per colour space (hue is 0..180 in HSV).
_RANGES: dict[str, list[float]] = {
    "hsv": [0, 180, 0, 256, 0, 256],
    "rgb": [0, 256, 0, 256, 0, 256],
    "lab": [0, 256, 0, 256, 0, 256],
}


@dataclass(frozen=True)
class ClothesParams:
    """Colour space and bins of the clothing histograms (``perception.identity``)."""

    color_space: ColorSpace = "hsv"
    bins: tuple[int, int, int] = (16, 4, 4)

    @property
    def size(self) -> int:
        """Number of bins of a flattened histogram."""
        return int(np.prod(self.bins))


def convert(rgb: np.ndarray, space: ColorSpace) -> np.ndarray:
    """An ``(h, w, 3) uint8`` RGB image in ``space`` (OpenCV's 8-bit conventions)."""
    import cv2

    img = np.ascontiguousarray(rgb[..., :3], dtype=np.uint8)
    if space == "hsv":
        return cv2.cvtColor(img, cv2.COLOR_RGB2HSV)
    if space == "lab":
        return cv2.cvtColor(img, cv2.COLOR_RGB2LAB)
    return img


def color_histogram(
    image: np.ndarray, mask: np.ndarray, params: ClothesParams, converted: bool = False
) -> np.ndarray | None:
    """The normalised (sum 1) flattened histogram of the pixels ``mask`` ``(h, w) bool`` of an
    RGB ``image`` (or of an image already in ``params.color_space`` when ``converted``); None
    when the mask selects no pixel.

    The bins are **soft** (linear interpolation, as in Lowe's SIFT descriptors): a pixel adds to
    the two nearest bins of each channel in proportion to its distance from their centres, so a
    colour near a bin edge does not jump from one bin to the other when the light changes a
    little (hard 4-level value bins split the same red shirt at V = 128 between a dim hall and a
    bright office: S fell from 0.99 to 0.26). Hue is circular in HSV (bin 0 neighbours the last
    bin); the other channels are clamped at their ends.
    """
    if not np.any(mask):
        return None
    img = image if converted else convert(image, params.color_space)
    pixels = img[mask.astype(bool)].astype(np.float64)
    ranges = _RANGES[params.color_space]
    weights = np.ones(len(pixels))
    index = np.zeros(len(pixels), dtype=np.int64)
    parts: list[tuple[np.ndarray, np.ndarray]] = [(index, weights)]
    for channel, bins in enumerate(params.bins):
        lo, hi = ranges[2 * channel], ranges[2 * channel + 1]
        u = (pixels[:, channel] - lo) / (hi - lo) * bins - 0.5  # bin-centre coordinates
        k0 = np.floor(u)
        frac = u - k0
        k0 = k0.astype(np.int64)
        k1 = k0 + 1
        if params.color_space == "hsv" and channel == 0:
            k0, k1 = k0 % bins, k1 % bins
        else:
            k0, k1 = np.clip(k0, 0, bins - 1), np.clip(k1, 0, bins - 1)
        parts = [
            (idx * bins + k, w * f) for idx, w in parts for k, f in ((k0, 1.0 - frac), (k1, frac))
        ]
    hist = np.zeros(params.size)
    for idx, w in parts:
        hist += np.bincount(idx, weights=w, minlength=params.size)
    total = float(hist.sum())
    return hist / total if total > 0 else None


def histogram_intersection(candidate: np.ndarray, target: np.ndarray) -> float:
    """Algorithm 2's clothes similarity ``S = Σ min(I_j, T_j) / Σ T_j`` of a candidate's
    histogram ``I`` against the target's ``T`` (1: ``I`` covers ``T``; 0: disjoint)."""
    i = np.asarray(candidate, dtype=float).ravel()
    t = np.asarray(target, dtype=float).ravel()
    if i.shape != t.shape:
        raise ValueError(f"histograms differ in size: {i.size} vs {t.size}")
    total = float(t.sum())
    return float(np.minimum(i, t).sum() / total) if total > 0 else 0.0


def body_parts(
    shape: tuple[int, int],
    box: Box,
    mask: np.ndarray | None = None,
    keypoints: dict[str, tuple[float, float]] | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """The upper- and lower-body pixel masks ``(h, w) bool`` of a person (see the module
    docstring for the split)."""
    h, w = shape
    x0, y0, x1, y1 = box
    if mask is not None:
        body = mask.astype(bool)
    else:
        body = np.zeros(shape, dtype=bool)
        half = CENTRAL_WIDTH * (x1 - x0) / 2
        cx = (x0 + x1) / 2
        body[max(0, y0) : min(h, y1), max(0, int(cx - half)) : min(w, int(np.ceil(cx + half)))] = (
            True
        )
    kp = keypoints or {}
    height = y1 - y0
    if "neck" in kp and "mid_hip" in kp:
        top, hip = kp["neck"][1], kp["mid_hip"][1]
        gap = 0.04 * max(hip - top, 1.0)
        bottom = kp["ankles"][1] if "ankles" in kp else y1
        upper_rows = (top + gap, hip - gap)
        lower_rows = (hip + gap, bottom)
    else:
        upper_rows = (y0 + UPPER_ROWS[0] * height, y0 + UPPER_ROWS[1] * height)
        lower_rows = (y0 + LOWER_ROWS[0] * height, y0 + LOWER_ROWS[1] * height)
    rows = np.arange(h)[:, None]
    u0, u1, l0, l1 = (round(float(r), 6) for r in (*upper_rows, *lower_rows))  # no 110.00000001
    upper = body & (rows >= u0) & (rows < u1)
    lower = body & (rows >= l0) & (rows < l1)
    return upper, lower


__all__ = [
    "LOWER_ROWS",
    "UPPER_ROWS",
    "ClothesParams",
    "ColorSpace",
    "body_parts",
    "color_histogram",
    "convert",
    "histogram_intersection",
]
