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
line (either colour) out of both. Keypoints without the torso (a person hidden behind another
but for their feet, or their head) leave both parts empty: the box is then only what shows, and
its fractions would take shoes for a shirt (traced, house seed 45: behind a passer-by, her feet
measured as her upper body made her "not her", and the robot lost her).

**Relit similarity** (:func:`relit_intersection`). The same clothes under other light — another
room, the side away from the lamp, a camera's exposure — keep their hue but move along the
brightness axis (V in HSV, L in Lab), by a whole bin as often as not: traced, generated home 28,
her pink trousers in the laundry measured S = 0.53 from 6 m to 2.7 m (V one bin below the
profile's), and ``pfctl search`` walked past her for 90 s. The relit similarity is the best S
over the candidate's histogram moved one bin darker, not moved, or one bin brighter; the
identifier (:mod:`pfctl.core.perception.identity`) takes only it as evidence that clothes are
*not* hers, and keeps the plain S as evidence that they are (a light change must not turn
someone else into her).
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np

from pfctl.core.params import param
from pfctl.core.perception.faces import Box

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

    color_space: ColorSpace = param("hsv", "Colour space of the clothing histograms.")
    bins: tuple[int, int, int] = param(
        (16, 4, 4), "Histogram bins per channel of ``color_space``.", ge=1
    )

    @property
    def size(self) -> int:
        """Number of bins of a flattened histogram."""
        return _size(tuple(self.bins))


@functools.lru_cache(maxsize=8)
def _size(bins: tuple[int, ...]) -> int:
    return int(np.prod(bins))


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

    Each pixel's bins and weights are read from tables over the 8-bit values
    (:func:`_soft_bins`), the same numbers as computed from the pixel; ValueError for an image
    that is not 8-bit.
    """
    return color_histograms(image, (mask,), params, converted)[0]


def color_histograms(
    image: np.ndarray,
    masks: Sequence[np.ndarray],
    params: ClothesParams,
    converted: bool = False,
) -> list[np.ndarray | None]:
    """:func:`color_histogram` of each of ``masks`` over the same ``image`` (a person's upper
    and lower body), the same arrays, bit for bit, in one pass: the masks' pixels one after
    the other, each mask's bins offset by the histogram size, so that every bin still sums its
    own pixels' weights in their row-major order, one ``bincount`` per corner for all."""
    sel = [np.asarray(mask).astype(bool, copy=False) for mask in masks]
    counts = [int(np.count_nonzero(mask)) for mask in sel]
    if not any(counts):
        return [None] * len(sel)
    img = image if converted else convert(image, params.color_space)
    if img.dtype != np.uint8:
        raise ValueError(f"color_histogram needs an 8-bit image, got {img.dtype}")
    # the selected pixels' channels one at a time (faster than selecting (n, 3) pixels)
    channels = []
    for c in range(3):
        plane = img[..., c]
        picked = [plane[mask] for mask, n in zip(sel, counts, strict=True) if n]
        channels.append(picked[0] if len(picked) == 1 else np.concatenate(picked))
    pairs, third = _soft_bins(params.color_space, tuple(int(b) for b in params.bins))
    first_two = channels[0].astype(np.intp) * 256 + channels[1]
    last = channels[2].astype(np.intp)
    corners = [(k[last], f[last]) for k, f in third]
    size = params.size
    shown = [i for i, n in enumerate(counts) if n]
    offset = None
    if len(shown) > 1:
        offset = np.repeat(np.arange(len(shown)) * size, [counts[i] for i in shown])
    hist = np.zeros(size * len(shown))
    for pair_index, pair_weight in pairs:  # the 8 corners of each pixel's trilinear cell
        index = pair_index[first_two]
        if offset is not None:
            index += offset
        weight = pair_weight[first_two]
        for k, f in corners:
            hist += np.bincount(index + k, weights=weight * f, minlength=len(hist))
    out: list[np.ndarray | None] = [None] * len(sel)
    for j, i in enumerate(shown):
        h = hist[j * size : (j + 1) * size].copy()
        total = float(h.sum())
        out[i] = h / total if total > 0 else None
    return out


@functools.lru_cache(maxsize=8)
def _soft_bins(
    space: str, bins: tuple[int, ...]
) -> tuple[list[tuple[np.ndarray, np.ndarray]], list[tuple[np.ndarray, np.ndarray]]]:
    """Lookup tables of :func:`color_histogram` over the 8-bit channel values: for channels 0
    and 1 together (index ``v0 · 256 + v1``), the flat bin ``k0 · bins[1] + k1`` times
    ``bins[2]`` (the flat bin of its channel-2 bin 0) and weight ``f0 · f1`` of each of their
    four pairs of neighbouring bins; for channel 2, its two bins and weights. Each entry is
    computed with the same floating-point operations, in the same order, as from the pixel
    itself, so the histogram is the same, bit for bit, as computing every pixel's bins and
    weights, in less time (a person near the camera has tens of thousands of pixels, each
    looked up instead of computed)."""
    ranges = _RANGES[space]
    values = np.arange(256, dtype=np.float64)
    channels: list[list[tuple[np.ndarray, np.ndarray]]] = []
    for channel, n in enumerate(bins):
        lo, hi = ranges[2 * channel], ranges[2 * channel + 1]
        u = (values - lo) / (hi - lo) * n - 0.5  # bin-centre coordinates
        k0 = np.floor(u)
        frac = u - k0
        k0 = k0.astype(np.intp)
        k1 = k0 + 1
        if space == "hsv" and channel == 0:  # hue is circular
            k0, k1 = k0 % n, k1 % n
        else:
            k0, k1 = np.clip(k0, 0, n - 1), np.clip(k1, 0, n - 1)
        channels.append([(k0, 1.0 - frac), (k1, frac)])
    pairs = [
        (
            (ka[:, None] * bins[1] + kb[None, :]).ravel() * bins[2],
            (fa[:, None] * fb[None, :]).ravel(),
        )
        for ka, fa in channels[0]
        for kb, fb in channels[1]
    ]
    return pairs, channels[2]


def histogram_intersection(candidate: np.ndarray, target: np.ndarray) -> float:
    """Algorithm 2's clothes similarity ``S = Σ min(I_j, T_j) / Σ T_j`` of a candidate's
    histogram ``I`` against the target's ``T`` (1: ``I`` covers ``T``; 0: disjoint)."""
    i = np.asarray(candidate, dtype=float).ravel()
    t = np.asarray(target, dtype=float).ravel()
    if i.shape != t.shape:
        raise ValueError(f"histograms differ in size: {i.size} vs {t.size}")
    total = float(t.sum())
    return float(np.minimum(i, t).sum() / total) if total > 0 else 0.0


#: The brightness channel of each colour space (None: brightness is spread over all three).
BRIGHTNESS_CHANNEL: dict[str, int | None] = {"hsv": 2, "lab": 0, "rgb": None}


def relit_intersection(candidate: np.ndarray, target: np.ndarray, params: ClothesParams) -> float:
    """The best :func:`histogram_intersection` of ``candidate`` moved by −1, 0 or +1 bins
    along the brightness channel of ``params.color_space`` against ``target`` (module
    docstring: relit similarity); the plain intersection in a space without one (RGB). Mass
    moved past the darkest or brightest bin stays in it."""
    channel = BRIGHTNESS_CHANNEL[params.color_space]
    best = histogram_intersection(candidate, target)
    bins = tuple(int(b) for b in params.bins)
    if channel is None or bins[channel] < 2:
        return best
    cube = np.moveaxis(np.asarray(candidate, dtype=float).reshape(bins), channel, -1)
    for darker in (True, False):
        moved = np.zeros_like(cube)
        if darker:
            moved[..., :-1] = cube[..., 1:]
            moved[..., 0] += cube[..., 0]
        else:
            moved[..., 1:] = cube[..., :-1]
            moved[..., -1] += cube[..., -1]
        flat = np.moveaxis(moved, -1, channel).ravel()
        best = max(best, histogram_intersection(flat, target))
    return best


def _part_rows(
    box: Box, keypoints: dict[str, tuple[float, float]] | None
) -> tuple[float, float, float, float]:
    """Image rows ``[u0, u1)`` of the upper and ``[l0, l1)`` of the lower body (module
    docstring)."""
    y0, y1 = box[1], box[3]
    kp = keypoints or {}
    height = y1 - y0
    if "neck" in kp and "mid_hip" in kp:
        top, hip = kp["neck"][1], kp["mid_hip"][1]
        gap = 0.04 * max(hip - top, 1.0)
        bottom = kp["ankles"][1] if "ankles" in kp else y1
        upper_rows = (top + gap, hip - gap)
        lower_rows = (hip + gap, bottom)
    elif kp:  # a pose without the torso: where the shirt ends is not known, so no part is
        upper_rows = lower_rows = (y0, y0)
    else:
        upper_rows = (y0 + UPPER_ROWS[0] * height, y0 + UPPER_ROWS[1] * height)
        lower_rows = (y0 + LOWER_ROWS[0] * height, y0 + LOWER_ROWS[1] * height)
    u0, u1, l0, l1 = (round(float(r), 6) for r in (*upper_rows, *lower_rows))  # no 110.00000001
    return u0, u1, l0, l1


def _body(
    shape: tuple[int, int], box: Box, mask: np.ndarray | None, window: tuple[int, int, int, int]
) -> np.ndarray:
    """The body's pixels (its mask, else the central part of its box) inside ``window`` =
    rows ``[r0, r1)``, columns ``[c0, c1)`` of the image."""
    r0, r1, c0, c1 = window
    if mask is not None:
        return mask[r0:r1, c0:c1].astype(bool)
    h, w = shape
    x0, y0, x1, y1 = box
    body = np.zeros((r1 - r0, c1 - c0), dtype=bool)
    half = CENTRAL_WIDTH * (x1 - x0) / 2
    cx = (x0 + x1) / 2
    rows = slice(max(0, y0, r0) - r0, min(h, y1, r1) - r0)
    cols = slice(max(0, int(cx - half), c0) - c0, min(w, int(np.ceil(cx + half)), c1) - c0)
    if rows.start < rows.stop and cols.start < cols.stop:
        body[rows, cols] = True
    return body


def body_parts(
    shape: tuple[int, int],
    box: Box,
    mask: np.ndarray | None = None,
    keypoints: dict[str, tuple[float, float]] | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """The upper- and lower-body pixel masks ``(h, w) bool`` of a person (see the module
    docstring for the split)."""
    _, upper, lower = body_parts_window(shape, box, mask, keypoints, crop=False)
    return upper, lower


def body_parts_window(
    shape: tuple[int, int],
    box: Box,
    mask: np.ndarray | None = None,
    keypoints: dict[str, tuple[float, float]] | None = None,
    *,
    crop: bool = True,
) -> tuple[tuple[int, int, int, int], np.ndarray, np.ndarray]:
    """:func:`body_parts` cut to the window that holds them: ``((r0, r1, c0, c1), upper,
    lower)`` with the masks of rows ``[r0, r1)`` and columns ``[c0, c1)`` of the image (the
    pixels of Algorithm 2's clothing histograms).

    The window is the person's box inside the image (the whole image when ``crop`` is False,
    or when a ``mask`` has pixels outside the box), so the masks select the same pixels, in
    the same row-major order, as the full-image ones: a histogram of them is the same, bit for
    bit, for a fraction of the work.
    """
    h, w = shape
    window = (0, h, 0, w)
    if crop:
        x0, y0, x1, y1 = box
        cut = (max(0, y0), min(h, y1), max(0, x0), min(w, x1))
        if cut[0] >= cut[1] or cut[2] >= cut[3]:
            cut = (0, 0, 0, 0)
        inside = mask is None or np.count_nonzero(
            mask[cut[0] : cut[1], cut[2] : cut[3]]
        ) == np.count_nonzero(mask)
        if inside:
            window = cut
    body = _body(shape, box, mask, window)
    u0, u1, l0, l1 = _part_rows(box, keypoints)
    rows = np.arange(window[0], window[1])[:, None]
    upper = body & (rows >= u0) & (rows < u1)
    lower = body & (rows >= l0) & (rows < l1)
    return window, upper, lower


__all__ = [
    "BRIGHTNESS_CHANNEL",
    "LOWER_ROWS",
    "UPPER_ROWS",
    "ClothesParams",
    "ColorSpace",
    "body_parts",
    "body_parts_window",
    "color_histogram",
    "color_histograms",
    "convert",
    "histogram_intersection",
    "relit_intersection",
]
