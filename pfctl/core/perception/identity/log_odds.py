"""Identity as a log-odds belief per track (issue 23, item 1): every cue adds its evidence.

The belief that a track is the target is ``L = log P(target) / P(not target)``, the sum of what
each cue says, weighted by how reliable it is (:class:`LogOddsWeights`):

- **face** (strongest): ``face_weight × clip((face_distance − d) / face_scale, −1, 1)`` for the
  median distance ``d`` of the track's faces to her profile — a clear match or mismatch
  saturates at ± ``face_weight``;
- **clothes**: ``clothes_weight × clip((S − clothes_similarity) / clothes_scale, −1, 1)`` for the
  median histogram intersection S — but clothes count only as far as they *separate* her from
  the people about now (Koide & Miura's online discrimination): while a look-alike is about
  (another person in her clothes is tracked, or was seen lately) matching clothes are no
  evidence at all; clothes that do not match her still count against, by the same formula on
  the *relit* similarity (:func:`~pfctl.core.perception.clothes.relit_intersection`): clothes
  that match hers under other light are no evidence against her;
- **distractor**: ``−distractor_weight`` for a track known not to be her without a face of its
  own: a person seen at the same time as her face-confirmed track, away from her (two places at
  once), or a new track linked to a remembered distractor
  (:mod:`~pfctl.core.perception.identity.distractors`);
- **continuity**: ``+continuity_weight`` for the track that is named the target now (it was her
  and the tracker never lost it) — a face mismatch still outweighs it.

A track is TARGET at ``L ≥ accept``, NOT_TARGET at ``L ≤ −reject``, else UNKNOWN. The weights
are chosen so that clothes alone (at most ``clothes_weight``) cannot overcome a distractor mark,
and a face can overcome anything but a face.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class LogOddsWeights:
    """How much each cue may move a track's log-odds (module docstring)."""

    face_weight: float = 6.0
    face_scale: float = 0.15
    clothes_weight: float = 3.0
    clothes_scale: float = 0.1
    distractor_weight: float = 4.0
    continuity_weight: float = 3.0
    accept: float = 2.0
    reject: float = 2.0


@dataclass(frozen=True)
class Cues:
    """What is known about one track, as the belief needs it."""

    face_distance: float | None
    clothes_similarity: float | None
    look_alike_about: bool
    distractor: bool
    named: bool
    clothes_relit: float | None = None
    """The relit clothes similarity (None: as ``clothes_similarity``)."""


def _clip(v: float) -> float:
    return max(-1.0, min(1.0, v))


def log_odds(
    cues: Cues, weights: LogOddsWeights, face_threshold: float, clothes_threshold: float
) -> tuple[float, str]:
    """The track's log-odds of being the target and the cue that weighs most in it (``face``,
    ``distractor``, ``clothes`` or ``continuity``, the first of them on a tie; ``nothing`` when
    no cue is known)."""
    w = weights
    parts: dict[str, float] = {}
    if cues.face_distance is not None:
        parts["face"] = w.face_weight * _clip((face_threshold - cues.face_distance) / w.face_scale)
    if cues.clothes_similarity is not None:

        def clothes(s: float) -> float:
            return w.clothes_weight * _clip((s - clothes_threshold) / w.clothes_scale)

        c = clothes(cues.clothes_similarity)
        if c > 0 and cues.look_alike_about:
            c = 0.0
        elif c < 0 and cues.clothes_relit is not None:
            c = min(0.0, clothes(cues.clothes_relit))
        parts["clothes"] = c
    if cues.distractor:
        parts["distractor"] = -w.distractor_weight
    if cues.named:
        parts["continuity"] = w.continuity_weight
    if not parts:
        return 0.0, "nothing"
    order = ("face", "distractor", "clothes", "continuity")
    basis = max(parts, key=lambda k: (abs(parts[k]), -order.index(k)))
    return sum(parts.values()), basis


__all__ = ["Cues", "LogOddsWeights", "log_odds"]
