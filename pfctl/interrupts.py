"""Ctrl-C and SIGTERM, treated alike: a run that is interrupted keeps what it measured.

``pfctl`` (:func:`pfctl.cli.main`) handles SIGINT and SIGTERM for the whole command
(:func:`command_signals`). Before any run has started (loading a mission, learning the target,
connecting to the robot) a signal raises :class:`Interrupted` at once: the context managers stop
the base, and the command exits with one line, 130 for SIGINT and 143 for SIGTERM (128 + the
signal's number, as a shell reports a process it killed).

From the moment a run opens :func:`graceful_interrupts` until the command ends, signals no longer
raise: the first sets the run's :class:`StopFlag` (the loop ends at its next tick, stops the base,
and the command writes what was measured); the second, at any spacing, changes nothing (the
command still ends with its one line); only a third abandons the writing (raises
:class:`Interrupted`; the base is still stopped by the context managers). The command ends with
:meth:`StopFlag.exit_if_set`: one line saying what was written and the exit status of the first
signal.
"""

from __future__ import annotations

import contextlib
import signal
import sys
import threading
from collections.abc import Iterator
from types import FrameType
from typing import NoReturn

HANDLED = (signal.SIGINT, signal.SIGTERM)
"""The signals that end a command gracefully."""

ABANDON_AFTER = 3
"""The signal that abandons the writing of an interrupted run's outputs (the third)."""


def signal_name(signum: int) -> str:
    """``SIGINT``, ``SIGTERM``."""
    return signal.Signals(signum).name


def exit_status(signum: int) -> int:
    """128 + the signal's number: 130 for SIGINT, 143 for SIGTERM."""
    return 128 + int(signum)


class Interrupted(KeyboardInterrupt):
    """A SIGINT or SIGTERM that ends the command now (not gracefully at the next tick).

    A :class:`KeyboardInterrupt`, so that code which cleans up after Ctrl-C does so after SIGTERM
    too. ``during`` says what the command was doing (e.g. what it waited for), for the line."""

    def __init__(self, signum: int, during: str | None = None) -> None:
        super().__init__(signal_name(signum))
        self.signum = signum
        self.during = during

    @property
    def exit_status(self) -> int:
        return exit_status(self.signum)

    def line(self) -> str:
        """The one line on stderr: ``pfctl: interrupted (SIGTERM) while …``."""
        during = f" {self.during}" if self.during else ""
        return f"pfctl: interrupted ({signal_name(self.signum)}){during}\n"


class StopFlag:
    """Set by the first signal once a run has opened :func:`graceful_interrupts`; calling it
    says whether the run should stop."""

    def __init__(self) -> None:
        self.set = False
        self.signum: int | None = None
        """The first signal (SIGINT or SIGTERM), or None."""

    def __call__(self) -> bool:
        return self.set

    def exit_if_set(self, what: str) -> None:
        """After the outputs are written: if a signal came, write ``pfctl: interrupted (SIGINT)
        {what}`` on stderr and exit with its status (130 or 143)."""
        if self.signum is None:
            return
        _state.reported = True
        sys.stderr.write(f"pfctl: interrupted ({signal_name(self.signum)}) {what}\n")
        raise SystemExit(exit_status(self.signum))


class _Signals:
    """What the handler has seen in this command."""

    def __init__(self) -> None:
        self.installed = False
        self.flag: StopFlag | None = None
        """The flag of the run opened last; None before any run (signals raise at once)."""
        self.received: list[int] = []
        self.raised: Interrupted | None = None
        self.reported = False

    def handle(self, signum: int, frame: FrameType | None) -> None:
        flag = self.flag
        if flag is None:
            self.raise_now(signum)
        self.received.append(signum)
        if len(self.received) == 1:
            flag.signum = signum
            flag.set = True
        elif len(self.received) < ABANDON_AFTER:
            pass  # already stopping: the run ends and its outputs are written all the same
        else:
            self.raise_now(self.received[0], "three times: abandoned writing the outputs")

    def raise_now(self, signum: int, during: str | None = None) -> NoReturn:
        self.raised = Interrupted(signum, during)
        raise self.raised


_state = _Signals()


def _install() -> dict[int, object]:
    """Handle :data:`HANDLED`, except a signal this process was started ignoring (a background
    job of a shell ignores Ctrl-C, ``nohup`` hangups): the previous handlers, to restore."""
    previous = {s: signal.getsignal(s) for s in HANDLED}
    for s, handler in previous.items():
        if handler is not signal.SIG_IGN:
            signal.signal(s, _state.handle)
    return previous


def _restore(previous: dict[int, object]) -> None:
    for s, handler in previous.items():
        signal.signal(s, handler)  # type: ignore[arg-type]


@contextlib.contextmanager
def command_signals(*, ending: bool = False) -> Iterator[_Signals]:
    """While open (the whole command), SIGINT and SIGTERM are handled as the module docstring
    says; SIGTERM never kills the process without running its ``finally`` blocks. ``ending``:
    the process ends with the command, so after a signal the two stay ignored rather than
    restored (a later one could only turn the exit status already reported into a death by
    that signal)."""
    global _state
    _state = _Signals()
    if threading.current_thread() is not threading.main_thread():
        yield _state
        return
    previous = _install()
    _state.installed = True
    try:
        yield _state
    finally:
        if ending and _state.received:
            for signum in HANDLED:
                signal.signal(signum, signal.SIG_IGN)
        else:
            _restore(previous)
        _state.installed = False


def unreported(end: BaseException) -> Interrupted | None:
    """The :class:`Interrupted` behind ``end`` whose line was not written yet, if any (the
    command line framework turns a KeyboardInterrupt into a silent exit 130)."""
    if _state.reported:
        return None
    if isinstance(end, Interrupted):
        return end
    return _state.raised


def behind(err: BaseException) -> Interrupted | None:
    """The :class:`Interrupted` that ``err`` was raised from or while handling, if any.

    A signal's exception can surface as another one: a native extension whose import it cut
    short (dlib's pybind11 module) raises ``ImportError: initialization failed`` from it. The
    command still ends as interrupted, not with the other exception's traceback."""
    seen: set[int] = set()
    link: BaseException | None = err
    while link is not None and id(link) not in seen:
        if isinstance(link, Interrupted):
            return link
        seen.add(id(link))
        link = link.__cause__ or link.__context__
    return None


@contextlib.contextmanager
def graceful_interrupts() -> Iterator[StopFlag]:
    """Open a run: from now until the command ends, the first SIGINT or SIGTERM sets the flag
    (the loop ends at its next tick) instead of raising; see the module docstring. Outside
    :func:`command_signals` (tests, library use) the handlers are installed for the run only."""
    flag = StopFlag()
    if threading.current_thread() is not threading.main_thread():
        yield flag
        return
    if _state.flag is not None and _state.flag.set:
        flag.set, flag.signum = True, _state.flag.signum  # a run after an interrupted one
    _state.flag = flag
    if _state.installed:
        yield flag
        return
    _state.received.clear()
    previous = _install()
    try:
        yield flag
    finally:
        _restore(previous)
        _state.flag = None


__all__ = [
    "HANDLED",
    "Interrupted",
    "StopFlag",
    "behind",
    "command_signals",
    "exit_status",
    "graceful_interrupts",
    "signal_name",
    "unreported",
]
