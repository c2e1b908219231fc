"""Where the head looks while the robot drives in a search: at the unseen places in sight.

The paper's gaze priority (§II-E) looks at the target, else at the human belief's peak (Eq. 4),
else at leg candidates; with none of them the head looked where the base was going. Driving
along a corridor, the camera then passes every open door without looking in, and a person
standing in plain view of the doorway is not seen: the laser maps the room through the door
(Algorithm 1's frontiers close) but only the camera can tell her. This rung looks instead at the
most probable place not seen yet that is in sight from here: of the belief over where she can be
(:class:`~pfctl.core.search.whereabouts.Whereabouts`: after a loss, or uniform over the rooms
for a target never seen), the cells the camera has not seen since, within its range and in line
of sight through the static map, summed over a window of the camera's horizontal field of view
at each bearing the head can pan to. The best window wins, kept against another until that one
holds ``switch_gain`` times as much (the head does not dither between two doors). Once the
camera has looked there, those cells are seen, their mass goes, and the next window wins: the
head looks into each room the robot passes, and ahead when nothing unseen is in sight.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pfctl.core.perception.belief import visible_mask
from pfctl.core.perception.tracking import FieldOfView
from pfctl.core.robot import Pose2D
from pfctl.core.search.whereabouts import Whereabouts

XY = tuple[float, float]

__all__ = ["UnseenGaze", "UnseenView", "in_sight_all_round", "unseen_view"]

#: Bearing bins of the window sum (5°).
_BINS = 72


@dataclass(frozen=True)
class UnseenView:
    """A window of bearings: where to look (``xy``, on its centre bearing at the median range
    of its unseen cells), that bearing (map frame, rad) and the belief mass of those cells."""

    xy: XY
    bearing: float
    mass: float


def _angle_diff(a: ArrayLike, b: float) -> NDArray[np.float64]:
    """``|a − b|`` wrapped to [0, π]."""
    return np.abs((np.asarray(a, dtype=float) - b + math.pi) % (2.0 * math.pi) - math.pi)


def _window_mass(
    bearings: NDArray[np.float64], weights: NDArray[np.float64], width: int
) -> NDArray[np.float64]:
    """The weight in the window of ``width`` bins centred on each of :data:`_BINS` bins."""
    hist = np.bincount(
        (((bearings + math.pi) / (2.0 * math.pi)) * _BINS).astype(np.intp) % _BINS,
        weights=weights,
        minlength=_BINS,
    )
    half = width // 2
    padded = np.concatenate([hist[-half:], hist, hist[:half]]) if half else hist
    sums = np.convolve(padded, np.ones(2 * half + 1), mode="valid")
    return sums[:_BINS]


def in_sight_all_round(
    whereabouts: Whereabouts,
    blocked: NDArray[np.bool_],
    pose: Pose2D,
    camera_range: tuple[float, float],
) -> NDArray[np.bool_]:
    """The cells of ``whereabouts``' grid a camera at ``pose`` could see turning all round:
    within ``camera_range`` (m), in line of sight past ``blocked`` (walls, furniture)."""
    fov = FieldOfView(Pose2D(pose.x, pose.y, 0.0), math.pi, *camera_range)
    return visible_mask(whereabouts.geometry, fov, blocked)


def unseen_view(
    weights: NDArray[np.float64],
    unseen: NDArray[np.bool_],
    visible: NDArray[np.bool_],
    geometry_centres: tuple[NDArray[np.float64], NDArray[np.float64]],
    pose: Pose2D,
    hfov: float,
    pan_limits: tuple[float, float],
) -> list[UnseenView]:
    """Every window's :class:`UnseenView` the head can pan to, best first (module docstring).

    ``weights``: the belief over cells; ``unseen``: the cells not seen since the loss;
    ``visible``: the cells in sight from ``pose`` (all round, in range); ``geometry_centres``:
    the cells' x and y centres; ``hfov``: the camera's horizontal field of view, rad;
    ``pan_limits``: the head's pan range relative to the base, rad."""
    cells = visible & unseen & (weights > 0.0)
    if not cells.any():
        return []
    xs, ys = geometry_centres[0][cells], geometry_centres[1][cells]
    w = weights[cells]
    dx, dy = xs - pose.x, ys - pose.y
    bearings = np.arctan2(dy, dx)
    width = max(1, round(hfov / (2.0 * math.pi / _BINS)))
    sums = _window_mass(bearings, w, width)
    step = 2.0 * math.pi / _BINS
    centres = -math.pi + (np.arange(_BINS) + 0.5) * step
    pans = (centres - pose.theta + math.pi) % (2.0 * math.pi) - math.pi
    lo, hi = pan_limits
    reachable = np.zeros(_BINS, dtype=bool)
    for turn in (-2.0 * math.pi, 0.0, 2.0 * math.pi):  # a pan range may exceed ±π (the HSR's)
        reachable |= (pans + turn >= lo) & (pans + turn <= hi)
    dist = np.hypot(dx, dy)
    views: list[UnseenView] = []
    for i in np.argsort(-sums, kind="stable"):
        if sums[i] <= 0.0 or not reachable[i]:
            continue
        b = float(centres[i])
        inside = _angle_diff(bearings, b) <= 0.5 * width * step
        r = float(np.median(dist[inside])) if inside.any() else 1.0
        xy = (pose.x + r * math.cos(b), pose.y + r * math.sin(b))
        views.append(UnseenView(xy, b, float(sums[i])))
    return views


class UnseenGaze:
    """The gaze rung of the module docstring, re-decided every ``every_s`` seconds."""

    def __init__(
        self,
        whereabouts: Whereabouts,
        blocked: NDArray[np.bool_],
        pan_limits: tuple[float, float],
        *,
        every_s: float = 0.5,
        switch_gain: float = 1.5,
        min_mass: float = 1e-3,
    ) -> None:
        self.whereabouts = whereabouts
        self.blocked = blocked
        self.pan_limits = pan_limits
        self.every_s = every_s
        self.switch_gain = switch_gain
        self.min_mass = min_mass
        """A window holding less of the belief than this is not worth turning the head for."""
        geometry = whereabouts.geometry
        centres = geometry.cell_to_world(*np.indices(geometry.shape))
        self._centres = (centres[..., 0], centres[..., 1])
        self._decided_at = -math.inf
        self._view: UnseenView | None = None

    def reset(self) -> None:
        """Forget the window being looked at (the search ended)."""
        self._view = None
        self._decided_at = -math.inf

    def point(
        self, t: float, pose: Pose2D, hfov: float, camera_range: tuple[float, float]
    ) -> XY | None:
        """Where to look at ``t`` from ``pose`` with a camera of horizontal field of view
        ``hfov`` (rad) that sees people within ``camera_range`` (m): the best unseen window in
        sight, or None when the belief rests or nothing unseen worth a look is in sight."""
        wb = self.whereabouts
        if not wb.active:
            self.reset()
            return None
        if t - self._decided_at < self.every_s:
            return None if self._view is None else self._view.xy
        self._decided_at = t
        visible = in_sight_all_round(wb, self.blocked, pose, camera_range)
        unseen = ~np.isfinite(wb.seen_at)
        views = unseen_view(
            wb.cell_probabilities(t), unseen, visible, self._centres, pose, hfov, self.pan_limits
        )
        views = [v for v in views if v.mass >= self.min_mass]
        best = views[0] if views else None
        current = self._view
        if best is not None and current is not None:
            same = min(views, key=lambda v: float(_angle_diff(v.bearing, current.bearing)))
            close = float(_angle_diff(same.bearing, current.bearing))
            if close <= 2.0 * math.pi / _BINS and best.mass < self.switch_gain * same.mass:
                best = same
        self._view = best
        return None if best is None else best.xy
