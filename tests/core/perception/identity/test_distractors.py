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
