"""Full chunks of an episode's log in a temporary file, so that a run of hours stays flat.

:class:`SpillFile` is a :class:`~pfctl.core.packed_records.ChunkStore`: it appends each full
chunk's rows to one anonymous temporary file (unlinked at once: the system frees it when the
file is closed or the process ends, however it ends) and gives back a memory map of them. The
rows then live in the page cache, not in the process: its resident memory holds the chunk being
filled, and a read (the metrics and figures at the end) pages the rest back in.
"""

from __future__ import annotations

import tempfile

import numpy as np

from pfctl.core.episode import EpisodeLog


class SpillFile:
    """Chunks appended to one temporary file, each read back as a writable memory map."""

    def __init__(self, directory: str | None = None) -> None:
        # open for the log's life: closed by close() or with the object
        self._file = tempfile.TemporaryFile(prefix="pfctl-log-", dir=directory)  # noqa: SIM115

    def put(self, chunk: np.ndarray) -> np.ndarray:
        offset = self._file.seek(0, 2)
        self._file.write(np.ascontiguousarray(chunk).tobytes())
        self._file.flush()
        return np.memmap(self._file, chunk.dtype, "r+", offset, chunk.shape)

    def close(self) -> None:
        """Close the file (the maps given out stay readable until they are dropped)."""
        self._file.close()


def spill_log(log: EpisodeLog, store: SpillFile | None = None) -> SpillFile:
    """Have ``log``'s per-tick records (and the truths' people) spill their full chunks to
    ``store`` (a new :class:`SpillFile` by default); the store is returned."""
    store = store or SpillFile()
    for records in (log.ticks, log.truths, log.tracks, log.truths.codec.people):  # type: ignore[attr-defined]
        records.spill_to(store)
    return store


__all__ = ["SpillFile", "spill_log"]
