"""An episode's log spilled to a temporary file reads back exactly what was appended."""

from __future__ import annotations

import pickle

from pfctl.app.spill import SpillFile, spill_log
from pfctl.core.episode import EpisodeLog, TickRecord
from pfctl.core.packed_records import CHUNK_ROWS
from pfctl.core.robot import GroundTruth, PersonTruth, Pose2D


def _tick(i: int) -> TickRecord:
    target = (i * 0.1, -i * 0.2) if i % 3 else None
    return TickRecord(i * 0.1, Pose2D(i, -i, 0.01 * i), "visible", "follow_target", i, target)


def _truth(i: int) -> GroundTruth:
    people = tuple(PersonTruth(f"p{k}", i + k, k * 0.5, 0.1, 0.9, k == 0) for k in range(i % 4))
    return GroundTruth(i * 0.1, Pose2D(i, 2.0 * i), people, collisions=i // 1000)


def test_a_spilled_log_reads_back_exactly() -> None:
    n = 2 * CHUNK_ROWS + 11
    log = EpisodeLog()
    store = spill_log(log, SpillFile())
    for i in range(n):
        log.ticks.append(_tick(i))
        log.truths.append(_truth(i))
        log.tracks.append((i * 0.1, i, 1.0, 2.0, 0.1, 0.2, 0.5, bool(i % 2)))
    assert log.ticks.nbytes <= CHUNK_ROWS * log.ticks.codec.dtype.itemsize * 3
    assert list(log.ticks) == [_tick(i) for i in range(n)]
    assert log.truths[CHUNK_ROWS + 1] == _truth(CHUNK_ROWS + 1) and log.truths[-1] == _truth(n - 1)
    assert log.tracks[CHUNK_ROWS][1] == CHUNK_ROWS
    copy = pickle.loads(pickle.dumps(log))  # a bench worker hands its log back pickled
    store.close()
    assert list(copy.truths) == [_truth(i) for i in range(n)]
