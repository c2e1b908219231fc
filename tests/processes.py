"""Helpers for tests that start processes and check that none outlives what started it."""

from __future__ import annotations

import time


def process_gone(pid: int) -> bool:
    """Whether process ``pid`` has ended (gone, or a zombie nobody reaped yet)."""
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().rsplit(")", 1)[1].split()[0] in ("Z", "X")
    except FileNotFoundError:
        return True


def processes_end(pids: list[int], timeout: float = 30.0) -> bool:
    """Whether every process of ``pids`` ends within ``timeout`` s. A process that has closed
    its files may still be tearing down its memory (a face worker's models) for a while on a
    busy machine, so a test waits for the condition instead of looking once."""
    deadline = time.monotonic() + timeout
    while not all(process_gone(pid) for pid in pids):
        if time.monotonic() > deadline:
            return False
        time.sleep(0.05)
    return True
