"""Leg evidence over several scans: each segment's P(leg) averaged along its track (§II-E).

One scan's segment features leave real legs and leg-like clutter (chair and table legs, bins,
door frames) overlapping; Leigh et al. 2015 ("Person tracking and following with 2D laser
scanners") therefore let a leg's confidence build up over the scans in which it is tracked
rather than trusting a single classification. :class:`LegEvidence` does the simplest causal form
of that for the detector: the segments of each scan are matched to those of the previous scan
(minimum total distance, ``scipy.optimize.linear_sum_assignment``, pairs farther apart than
``radius`` left unmatched), a matched segment inherits the probabilities of its predecessor, and
its P(leg) becomes the mean over its last ``history`` scans (itself included). A segment seen for
the first time keeps its own P(leg): the average adds no delay to a newcomer.

``benchmarks/leg_real_ceiling.py`` measures what the mean gains on the real labelled bags.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import linear_sum_assignment

#: Segments of consecutive scans farther apart than this are different objects, metres (a leg
#: swings about 0.15 m between scans at 7.5–10 Hz and walking speed).
TRACK_RADIUS = 0.35
_FAR = 1e9


class LegEvidence:
    """Causal mean of P(leg) over the last ``history`` scans of each segment's track."""

    def __init__(self, history: int, radius: float = TRACK_RADIUS) -> None:
        if history < 1:
            raise ValueError(f"history must be at least 1 scan, got {history}")
        self.history = int(history)
        self.radius = float(radius)
        self.reset()

    def reset(self) -> None:
        """Forget every track (a new sequence of scans, or a different laser)."""
        self._xy = np.empty((0, 2))
        # Row per segment of the last scan: its track's last P(leg)s, oldest first, NaN = none.
        self._past = np.empty((0, self.history))

    @property
    def tracks(self) -> int:
        """Segments remembered from the last scan."""
        return len(self._xy)

    def update(self, xy: np.ndarray, probability: np.ndarray) -> np.ndarray:
        """The averaged P(leg) ``(k,)`` of this scan's segments at ``xy`` ``(k, 2)`` (one fixed
        frame across scans) with single-scan ``probability`` ``(k,)``."""
        xy = np.asarray(xy, dtype=float).reshape(-1, 2)
        prob = np.asarray(probability, dtype=float).reshape(-1)
        if len(xy) != len(prob):
            raise ValueError(f"{len(xy)} positions but {len(prob)} probabilities")
        past = np.full((len(xy), self.history), np.nan)
        past[:, -1] = prob
        if len(xy) and len(self._xy) and self.history > 1:
            d = np.hypot(
                xy[:, None, 0] - self._xy[None, :, 0], xy[:, None, 1] - self._xy[None, :, 1]
            )
            near = d <= self.radius
            rows_any, cols_any = near.any(axis=1), near.any(axis=0)
            if rows_any.any():
                r_idx, c_idx = np.flatnonzero(rows_any), np.flatnonzero(cols_any)
                sub = np.where(near[np.ix_(r_idx, c_idx)], d[np.ix_(r_idx, c_idx)], _FAR)
                rows, cols = linear_sum_assignment(sub)
                ok = sub[rows, cols] < _FAR
                past[r_idx[rows[ok]], :-1] = self._past[c_idx[cols[ok]], 1:]
        self._xy, self._past = xy.copy(), past
        seen = ~np.isnan(past)
        return np.where(seen, past, 0.0).sum(axis=1) / seen.sum(axis=1)


__all__ = ["TRACK_RADIUS", "LegEvidence"]
