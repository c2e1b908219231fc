"""CLEAR-MOT: how well a multi-person tracker followed annotated people (Bernardin & Stiefelhagen,
"Evaluating multiple object tracking performance: the CLEAR MOT metrics", 2008).

A sequence of annotated frames is scored one frame at a time (:meth:`ClearMot.add`). In a frame,
each ground-truth person (an id and a position) is matched to at most one track (an id and a
position) and each track to at most one person, only within ``radius`` metres:

1. **Continuity**: a person whose last match (in an earlier annotated frame) is a track that is
   present again and still within ``radius`` keeps it, even if another track is now closer;
2. the remaining people and tracks are matched by the Hungarian algorithm, minimising the total
   distance among the pairs within ``radius`` (``scipy.optimize.linear_sum_assignment``);
3. a person left unmatched is a **miss**, a track left unmatched a **false positive**, and a
   person matched to another track than its last match is an **ID switch** (a person's first
   match is none).

Over the sequence, ``MOTA = 1 − (misses + false positives + ID switches) / annotations`` (it can be
negative) and ``MOTP`` is the mean distance of the matches (metres; lower is better).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike
from scipy.optimize import linear_sum_assignment

_FAR = 1e9  # cost of a pair farther apart than the radius


@dataclass(frozen=True)
class FrameScore:
    """What one annotated frame scored: matches ``(person id, track id, distance)``, the
    unmatched person ids (misses), the unmatched track ids (false positives) and the person ids
    whose match changed track (ID switches)."""

    stamp: float
    matches: tuple[tuple[int, int, float], ...]
    misses: tuple[int, ...]
    false_positives: tuple[int, ...]
    switches: tuple[int, ...]


@dataclass(frozen=True)
class ClearMotResult:
    """The CLEAR-MOT figures of a sequence."""

    frames: int
    ground_truth: int
    """Annotated people summed over the frames."""
    matches: int
    misses: int
    false_positives: int
    id_switches: int
    distance_sum: float
    """Sum of the match distances, m."""

    @property
    def mota(self) -> float:
        """``1 − (misses + FP + IDSW) / GT``; NaN without annotations."""
        if self.ground_truth == 0:
            return math.nan
        errors = self.misses + self.false_positives + self.id_switches
        return 1.0 - errors / self.ground_truth

    @property
    def motp(self) -> float:
        """Mean distance of the matches, m; NaN without matches."""
        return self.distance_sum / self.matches if self.matches else math.nan

    def as_dict(self) -> dict[str, float | int]:
        """The figures by name (MOTA, MOTP and the counts), for a JSON file."""
        return {
            "mota": self.mota,
            "motp": self.motp,
            "ground_truth": self.ground_truth,
            "matches": self.matches,
            "misses": self.misses,
            "false_positives": self.false_positives,
            "id_switches": self.id_switches,
            "frames": self.frames,
        }


def _points(xy: ArrayLike, n: int, what: str) -> np.ndarray:
    pts = np.asarray(xy, dtype=float).reshape(-1, 2) if n else np.empty((0, 2))
    if len(pts) != n:
        raise ValueError(f"expected one {what} position per id ({n}), got {len(pts)}")
    if not np.isfinite(pts).all():
        raise ValueError(f"expected finite {what} positions")
    return pts


@dataclass
class ClearMot:
    """Accumulates CLEAR-MOT over annotated frames (see the module docstring)."""

    radius: float = 0.75
    """Largest distance of a match, m."""
    frames: list[FrameScore] = field(default_factory=list)
    _last_match: dict[int, int] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if not (math.isfinite(self.radius) and self.radius > 0):
            raise ValueError(f"radius must be > 0 m, got {self.radius}")

    def add(
        self,
        stamp: float,
        truth_ids: Sequence[int],
        truth_xy: ArrayLike,
        track_ids: Sequence[int],
        track_xy: ArrayLike,
    ) -> FrameScore:
        """Score one annotated frame: the people ``truth_ids`` at ``truth_xy`` ``(n, 2)`` and
        the tracks ``track_ids`` at ``track_xy`` ``(m, 2)``, in one frame of reference."""
        people = [int(i) for i in truth_ids]
        tracks = [int(i) for i in track_ids]
        if len(set(people)) != len(people) or len(set(tracks)) != len(tracks):
            raise ValueError("expected each person id and each track id once per frame")
        p_xy = _points(truth_xy, len(people), "person")
        t_xy = _points(track_xy, len(tracks), "track")
        d = np.hypot(
            p_xy[:, None, 0] - t_xy[None, :, 0], p_xy[:, None, 1] - t_xy[None, :, 1]
        ).reshape(len(people), len(tracks))
        pairs: dict[int, int] = {}  # person index → track index
        track_index = {t: j for j, t in enumerate(tracks)}
        for i, pid in enumerate(people):
            j = track_index.get(self._last_match.get(pid, -1))
            if j is not None and d[i, j] <= self.radius and j not in pairs.values():
                pairs[i] = j
        rows = [i for i in range(len(people)) if i not in pairs]
        cols = [j for j in range(len(tracks)) if j not in pairs.values()]
        if rows and cols:
            sub = d[np.ix_(rows, cols)]
            cost = np.where(sub <= self.radius, sub, _FAR)
            for r, c in zip(*linear_sum_assignment(cost), strict=True):
                if sub[r, c] <= self.radius:
                    pairs[rows[r]] = cols[c]
        matches, switches = [], []
        for i, j in sorted(pairs.items()):
            pid, tid = people[i], tracks[j]
            if pid in self._last_match and self._last_match[pid] != tid:
                switches.append(pid)
            self._last_match[pid] = tid
            matches.append((pid, tid, float(d[i, j])))
        matched = set(pairs.values())
        score = FrameScore(
            stamp=float(stamp),
            matches=tuple(matches),
            misses=tuple(p for i, p in enumerate(people) if i not in pairs),
            false_positives=tuple(t for j, t in enumerate(tracks) if j not in matched),
            switches=tuple(switches),
        )
        self.frames.append(score)
        return score

    def result(self) -> ClearMotResult:
        """The figures over every frame added so far."""
        matches = [m for f in self.frames for m in f.matches]
        return ClearMotResult(
            frames=len(self.frames),
            ground_truth=sum(len(f.matches) + len(f.misses) for f in self.frames),
            matches=len(matches),
            misses=sum(len(f.misses) for f in self.frames),
            false_positives=sum(len(f.false_positives) for f in self.frames),
            id_switches=sum(len(f.switches) for f in self.frames),
            distance_sum=float(sum(m[2] for m in matches)),
        )


__all__ = ["ClearMot", "ClearMotResult", "FrameScore"]
