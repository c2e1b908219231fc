"""SIGINT and SIGTERM during a campaign: the first one stops it, later ones cannot cut it short.

While :class:`StopSignals` is open (in the main thread; elsewhere it does nothing), the first
SIGINT or SIGTERM raises KeyboardInterrupt in the main thread — where the runner stops its
workers — and is remembered, for the exit status (130 for SIGINT, 143 for SIGTERM). A signal
that arrives while a record is being written (:meth:`StopSignals.holding`) raises at the end of
it, so a received episode is never half kept. Later signals are ignored until the block is left:
stopping the workers and writing the summary of what finished take a few seconds, and a second
Ctrl-C or ``kill`` at any spacing must not lose them.
"""

from __future__ import annotations

import contextlib
import signal
import threading
from collections.abc import Iterator
from types import FrameType, TracebackType
from typing import Any

__all__ = ["StopSignals"]

#: The signals that stop a campaign.
STOPPING = (signal.SIGINT, signal.SIGTERM)


class StopSignals:
    """The campaign's handler of SIGINT and SIGTERM (module docstring)."""

    def __init__(self) -> None:
        self.received: signal.Signals | None = None
        """The first stopping signal that arrived."""
        self._holding = 0
        self._pending = False
        self._previous: dict[int, Any] = {}

    @property
    def exit_code(self) -> int:
        """128 + the first signal's number (130 SIGINT, 143 SIGTERM); 130 when none came (a
        KeyboardInterrupt raised otherwise)."""
        return 128 + int(self.received or signal.SIGINT)

    def _handle(self, signum: int, frame: FrameType | None) -> None:
        if self.received is not None:
            return  # already stopping: let it finish
        self.received = signal.Signals(signum)
        if self._holding:
            self._pending = True
            return
        raise KeyboardInterrupt

    @contextlib.contextmanager
    def holding(self) -> Iterator[None]:
        """A stretch no stopping signal cuts: one arriving meanwhile raises at its end."""
        self._holding += 1
        try:
            yield
        finally:
            self._holding -= 1
            if self._pending and not self._holding:
                self._pending = False
                raise KeyboardInterrupt

    def __enter__(self) -> StopSignals:
        if threading.current_thread() is threading.main_thread():
            for signum in STOPPING:
                self._previous[signum] = signal.signal(signum, self._handle)
        return self

    def __exit__(
        self,
        kind: type[BaseException] | None,
        error: BaseException | None,
        trace: TracebackType | None,
    ) -> None:
        for signum, previous in self._previous.items():
            signal.signal(signum, previous)
        self._previous.clear()
