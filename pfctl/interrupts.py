"""Ctrl-C that ends a run gracefully: the first SIGINT asks the loop to stop (it keeps what was
measured and stops the robot), the second raises KeyboardInterrupt."""

from __future__ import annotations

import contextlib
import signal
import threading
from collections.abc import Iterator


class StopFlag:
    """Set by the first Ctrl-C inside :func:`graceful_interrupts`."""

    def __init__(self) -> None:
        self.set = False

    def __call__(self) -> bool:
        return self.set


@contextlib.contextmanager
def graceful_interrupts() -> Iterator[StopFlag]:
    """While open, the first SIGINT sets the flag instead of raising; the second raises."""
    flag = StopFlag()
    if threading.current_thread() is not threading.main_thread():
        yield flag
        return

    def handler(signum: int, frame: object) -> None:
        if flag.set:
            raise KeyboardInterrupt
        flag.set = True

    previous = signal.signal(signal.SIGINT, handler)
    try:
        yield flag
    finally:
        signal.signal(signal.SIGINT, previous)


__all__ = ["StopFlag", "graceful_interrupts"]
