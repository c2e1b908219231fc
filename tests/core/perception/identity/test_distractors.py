"""The memory of people found not to be her (issue 23, item 4)."""

from __future__ import annotations

import numpy as np

from pfctl.core.perception.identity.distractors import DistractorMemory


def _hist(k: int) -> np.ndarray:
    h = np.zeros(8)
    h[k] = 1.0
    return h


def test_a_new_track_near_where_a_distractor_was_lost_is_linked_in_time_only() -> None:
    memory = DistractorMemory(link_radius=1.0, link_speed=1.0, link_s=4.0)
    memory.remember(5, (2.0, 0.0), 10.0, "face")
    assert memory.link((2.5, 0.0), 10.5) is None  # track 5 is still alive
    memory.track_ended(5)
    assert memory.link((2.5, 0.0), 10.5) is memory.people[5]
    assert memory.link((3.9, 0.0), 11.0) is memory.people[5]  # 1 m + 1 s at 1 m/s
    assert memory.link((3.9, 0.0), 10.5) is None  # too far for the time
    assert memory.link((2.5, 0.0), 14.5) is None  # too late


def test_a_new_track_dressed_like_a_distractor_more_than_like_her_is_linked_anywhere() -> None:
    memory = DistractorMemory(link_margin=0.1)
    memory.remember(5, (2.0, 0.0), 10.0, "face", _hist(1), _hist(2))
    memory.track_ended(5)
    target = (_hist(0), _hist(2))
    assert memory.link((9.0, 9.0), 60.0, _hist(1), _hist(2), target) is memory.people[5]
    assert memory.link((9.0, 9.0), 60.0, _hist(0), _hist(2), target) is None


def test_a_distractor_dressed_like_her_is_never_linked_by_clothes() -> None:
    """Crowd seed 3: a look-alike in her clothes, rejected by face in the hall; her new track
    in the office, under another light, was more like his histograms than like her profile,
    and was linked to him. Between two people in her clothes, clothes cannot decide."""
    memory = DistractorMemory(link_margin=0.1, clothes_match=0.6)
    target = (_hist(0), _hist(2))
    his = 0.8 * _hist(0) + 0.2 * _hist(3)  # her clothes, 0.8 like her profile
    memory.remember(5, (2.0, 0.0), 10.0, "face", his, _hist(2))
    memory.track_ended(5)
    hers_now = 0.65 * _hist(0) + 0.35 * _hist(3)  # 0.65 like her profile, 0.85 like his
    assert memory.link((9.0, 9.0), 60.0, hers_now, _hist(2), target) is None
    # a man dressed almost like her (0.5 like her profile) is still linked by clothes
    memory.people[5].upper = 0.5 * _hist(0) + 0.5 * _hist(3)
    assert memory.link((9.0, 9.0), 60.0, hers_now, _hist(2), target) is memory.people[5]
    # and by place and time whatever he wears
    memory.people[5].upper = his
    assert memory.link((2.5, 0.0), 10.5, hers_now, _hist(2), target) is memory.people[5]
