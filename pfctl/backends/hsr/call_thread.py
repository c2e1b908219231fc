"""One thread for the rospy calls that a Ctrl-C must not split: publishing, goals, logging.

Python raises KeyboardInterrupt in the main thread, between any two bytecodes. rospy's
``Publisher.publish`` takes its topic lock in a Python method inside ``try`` and releases it in
``finally``: an interrupt raised as the lock is taken makes that ``finally`` raise
``RuntimeError("cannot release un-acquired lock")``, which hides the KeyboardInterrupt (a caller
catching ``Exception`` then carries on: the Ctrl-C is lost and the robot keeps driving); one
raised as the lock is released leaves it held, and the next publish from another thread waits
forever. Logging handlers have the same pattern. :class:`CallThread` runs such calls on a
thread of its own, where no KeyboardInterrupt is ever raised; the caller waits for the result
on a plain lock, which an interrupt leaves cleanly (the call itself still completes).
"""

from __future__ import annotations

import queue
import threading
from collections.abc import Callable
from typing import Any

_POLL = 0.5
"""Seconds between two checks, while waiting for a call, that the thread is still running."""


class _Call:
    """One call: run once, by whichever thread claims it first (the call thread, or the caller
    when the thread has ended)."""

    def __init__(self, fn: Callable[..., Any], args: tuple[Any, ...]) -> None:
        self.fn, self.args = fn, args
        self.claim = threading.Lock()
        self.done = threading.Lock()
        self.done.acquire()
        self.result: Any = None
        self.error: BaseException | None = None

    def run(self) -> None:
        if not self.claim.acquire(blocking=False):
            return
        try:
            self.result = self.fn(*self.args)
        except BaseException as err:  # handed to the caller, re-raised there
            self.error = err
        finally:
            self.done.release()


class CallThread:
    """A daemon thread running the calls handed to :meth:`call`, one at a time, in order."""

    def __init__(self, name: str) -> None:
        self._queue: queue.SimpleQueue[_Call | None] = queue.SimpleQueue()
        self._closed = False
        self._thread = threading.Thread(target=self._run, name=name, daemon=True)
        self._thread.start()

    def _run(self) -> None:
        while (item := self._queue.get()) is not None:
            item.run()

    def call(self, fn: Callable[..., Any], *args: Any) -> Any:
        """``fn(*args)`` on the call thread, after the calls handed over before it; its result,
        or its exception raised here. Runs in the caller's thread when called from the call
        thread itself or after :meth:`close`."""
        if self._closed or threading.current_thread() is self._thread:
            return fn(*args)
        item = _Call(fn, args)
        self._queue.put(item)
        while not item.done.acquire(timeout=_POLL):
            if not self._thread.is_alive():  # closed meanwhile: nobody else will run it
                item.run()
        if item.error is not None:
            raise item.error
        return item.result

    def close(self, timeout: float = 2.0) -> None:
        """Run the calls handed over so far (waiting up to ``timeout`` seconds), then end the
        thread; later calls run in their caller's thread."""
        if self._closed:
            return
        self._closed = True
        self._queue.put(None)
        if self._thread is not threading.current_thread():
            self._thread.join(timeout)


__all__ = ["CallThread"]
