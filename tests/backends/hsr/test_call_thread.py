"""CallThread: calls run in order on one thread; results and errors come back to the caller;
a caller interrupted while waiting leaves the call to complete; after close, calls run inline.
(Marked ros with the other HSR backend tests, though it needs no ROS.)"""

from __future__ import annotations

import os
import signal
import threading

import pytest

from pfctl.backends.hsr.call_thread import CallThread

pytestmark = pytest.mark.ros


def test_calls_run_in_order_on_the_thread_and_return_or_raise():
    calls = CallThread("test-calls")
    seen: list[tuple[int, str]] = []
    for i in range(5):
        assert calls.call(lambda i=i: seen.append((i, threading.current_thread().name)) or i) == i
    assert seen == [(i, "test-calls") for i in range(5)]
    with pytest.raises(KeyboardInterrupt):  # an error of the call is raised in the caller
        calls.call(lambda: (_ for _ in ()).throw(KeyboardInterrupt))
    assert calls.call(lambda: calls.call(lambda: "nested")) == "nested"  # from the thread: inline
    calls.close()
    assert calls.call(threading.current_thread) is threading.current_thread()


def test_a_caller_interrupted_while_waiting_leaves_the_call_to_complete():
    """A real SIGINT while the main thread waits for a call: the KeyboardInterrupt reaches the
    caller at once, the call completes on the thread, and the next call runs after it."""

    def interrupt(signum: int, frame: object) -> None:
        raise KeyboardInterrupt

    calls = CallThread("test-calls")
    started, release, order = threading.Event(), threading.Event(), []

    def slow() -> None:
        started.set()
        release.wait(10)
        order.append("slow")

    def send_sigint() -> None:
        started.wait(10)
        os.kill(os.getpid(), signal.SIGINT)

    previous = signal.signal(signal.SIGINT, interrupt)
    try:
        threading.Thread(target=send_sigint, daemon=True).start()
        with pytest.raises(KeyboardInterrupt):
            calls.call(slow)
    finally:
        signal.signal(signal.SIGINT, previous)
    assert order == []  # the call was still waiting when the caller was interrupted
    release.set()
    calls.call(order.append, "next")
    assert order == ["slow", "next"]
    calls.close()
