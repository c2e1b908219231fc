"""Identity as log-odds: what each cue may do (issue 23, item 1)."""

from __future__ import annotations

import pytest

from pfctl.core.perception.identity.log_odds import Cues, LogOddsWeights, log_odds

W = LogOddsWeights()


def _lo(**kw: object) -> tuple[float, str]:
    cues = dict(
        face_distance=None,
        clothes_similarity=None,
        look_alike_about=False,
        distractor=False,
        named=False,
    )
    cues.update(kw)
    return log_odds(Cues(**cues), W, 0.6, 0.6)  # type: ignore[arg-type]


def test_nothing_known_is_even_odds() -> None:
    assert _lo() == (0.0, "nothing")


def test_a_face_saturates_both_ways_and_outweighs_matching_clothes() -> None:
    assert _lo(face_distance=0.3) == (W.face_weight, "face")
    lo, basis = _lo(face_distance=0.9, clothes_similarity=1.0)
    assert lo == pytest.approx(-W.face_weight + W.clothes_weight) and basis == "face"
    assert lo <= -W.reject


def test_matching_clothes_are_no_evidence_while_a_look_alike_is_about() -> None:
    assert _lo(clothes_similarity=0.95)[0] == W.clothes_weight >= W.accept
    assert _lo(clothes_similarity=0.95, look_alike_about=True) == (0.0, "clothes")
    # clothes that are not hers still count against
    assert _lo(clothes_similarity=0.1, look_alike_about=True)[0] == -W.clothes_weight


def test_clothes_cannot_overcome_a_distractor_mark_and_her_face_can() -> None:
    assert _lo(clothes_similarity=1.0, distractor=True)[0] < W.accept
    lo, basis = _lo(face_distance=0.3, distractor=True)
    assert lo >= W.accept and basis == "face"


def test_continuity_keeps_the_named_track_unless_a_face_says_otherwise() -> None:
    assert _lo(named=True, clothes_similarity=0.95, look_alike_about=True)[0] >= W.accept
    assert _lo(named=True, face_distance=0.9)[0] <= -W.reject


def test_only_clothes_unlike_hers_under_every_light_count_against() -> None:
    """Her clothes under other light (the relit similarity over the threshold) are no evidence
    against her; the plain similarity alone says they are hers (none here: 0.53)."""
    assert _lo(clothes_similarity=0.53, clothes_relit=0.8) == (0.0, "clothes")
    assert _lo(clothes_similarity=0.53, clothes_relit=0.55)[0] == pytest.approx(
        W.clothes_weight * (0.55 - 0.6) / W.clothes_scale
    )
    assert _lo(clothes_similarity=0.1, clothes_relit=0.2)[0] == -W.clothes_weight
    # matching clothes count as before; the relit figure never adds to them
    assert _lo(clothes_similarity=0.95, clothes_relit=0.99)[0] == W.clothes_weight
