"""The people the robot knows are not the target (issue 23, item 4): CARPE-ID's distractor list.

A person is remembered as a **distractor** when their track was rejected by face (a face that is
not hers), or when their track was seen at the same time as her face-confirmed track, away from
her (two places at once: not her). The memory keeps, per distractor, where and when their track
was last seen, their clothing histograms and their face, if one was found.

When the tracker loses such a person and makes a new track for them, the new track is **linked**
to the remembered distractor — and stays rejected — when its first sighting is within
``link_radius`` (plus the distance a walker covers at ``link_speed`` meanwhile) of where the
distractor's track ended, no more than ``link_s`` earlier; or when its clothes are closer to the
distractor's than to the target's profile by ``link_margin`` (look-alikes who are dressed
*almost* like her). A distractor dressed like her (their clothes match her profile at
``clothes_match``) is never linked by clothes: between two people in the same clothes, a few
points of histogram are the light, not the person (traced, crowd seed 3: her new track in the
office, 0.72 like her profile, was 0.88 like a look-alike rejected by face in the hall, and
stayed "not her" to the end). A face that matches her overrides a link (the identifier weighs
both), so she is never lost for good to a wrong link.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from pfctl.core.perception.clothes import histogram_intersection


@dataclass
class Distractor:
    """One person known not to be the target."""

    track_id: int
    x: float
    y: float
    t: float
    """When (and where) their track was last seen."""
    upper: np.ndarray | None = None
    lower: np.ndarray | None = None
    why: str = "face"
    """``face`` (rejected by face) or ``coexisted`` (seen beside her)."""
    alive: bool = True
    """Their track still exists (a live track is not a candidate for linking)."""


@dataclass
class DistractorMemory:
    """The distractors seen in this episode, and the linking of new tracks to them."""

    link_radius: float = 1.0
    link_speed: float = 1.0
    link_s: float = 4.0
    link_margin: float = 0.1
    clothes_match: float = 0.6
    """Clothes this like her profile (histogram intersection) are hers: such a distractor is
    not linked by clothes."""
    people: dict[int, Distractor] = field(default_factory=dict)
    """By the track id they were last seen under."""

    def remember(
        self,
        track_id: int,
        xy: tuple[float, float],
        t: float,
        why: str,
        upper: np.ndarray | None = None,
        lower: np.ndarray | None = None,
    ) -> None:
        """Note (or refresh) that ``track_id`` is not the target, last seen at ``xy`` at ``t``."""
        known = self.people.get(track_id)
        if known is None:
            self.people[track_id] = Distractor(track_id, xy[0], xy[1], t, upper, lower, why)
            return
        known.x, known.y, known.t, known.alive = xy[0], xy[1], t, True
        if upper is not None:
            known.upper = upper
        if lower is not None:
            known.lower = lower
        if why == "face":
            known.why = "face"

    def seen(self, track_id: int, xy: tuple[float, float], t: float) -> None:
        """A remembered distractor's track was seen again at ``xy``."""
        known = self.people.get(track_id)
        if known is not None:
            known.x, known.y, known.t = xy[0], xy[1], t

    def track_ended(self, track_id: int) -> None:
        """The tracker deleted ``track_id``: a later new track may be theirs."""
        known = self.people.get(track_id)
        if known is not None:
            known.alive = False

    def link(
        self,
        xy: tuple[float, float],
        t: float,
        upper: np.ndarray | None = None,
        lower: np.ndarray | None = None,
        target: tuple[np.ndarray, np.ndarray] | None = None,
    ) -> Distractor | None:
        """The remembered distractor a new track first seen at ``xy`` at ``t`` is (by place and
        time, else by clothes closer to theirs than to ``target``'s histograms, for one not
        dressed like her), or None."""
        best: tuple[float, Distractor] | None = None
        for d in self.people.values():
            if d.alive or t - d.t > self.link_s or t < d.t - 1e-6:
                continue
            gap = math.hypot(xy[0] - d.x, xy[1] - d.y)
            near = gap <= self.link_radius + self.link_speed * (t - d.t)
            if near and (best is None or gap < best[0]):
                best = (gap, d)
        if best is not None:
            return best[1]
        if target is None or upper is None or lower is None:
            return None
        s_target = min(
            histogram_intersection(upper, target[0]), histogram_intersection(lower, target[1])
        )
        for d in self.people.values():
            if d.alive or d.upper is None or d.lower is None:
                continue
            if self.may_be_dressed_like(d, target):
                continue
            s = min(histogram_intersection(upper, d.upper), histogram_intersection(lower, d.lower))
            if s >= s_target + self.link_margin:
                return d
        return None

    def may_be_dressed_like(self, d: Distractor, target: tuple[np.ndarray, np.ndarray]) -> bool:
        """Whether distractor ``d`` may be dressed like ``target`` (upper and lower
        histograms): their clothes match it at ``clothes_match``, or were never measured."""
        if d.upper is None or d.lower is None:
            return True
        return (
            min(
                histogram_intersection(d.upper, target[0]),
                histogram_intersection(d.lower, target[1]),
            )
            >= self.clothes_match
        )

    def forget(self, track_id: int) -> None:
        """Drop a distractor (their face turned out to be hers after all)."""
        self.people.pop(track_id, None)


__all__ = ["Distractor", "DistractorMemory"]
