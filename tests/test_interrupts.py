"""SIGINT and SIGTERM alike (:mod:`pfctl.interrupts`), with real signals to this process: at once
before a run, at the next tick in one, the second changing nothing, the third abandoning."""

from __future__ import annotations

import signal

import pytest

from pfctl import cli
from pfctl.interrupts import Interrupted, behind, command_signals, graceful_interrupts


def _kill(signum: int) -> None:
    """Send ``signum`` to this thread: its Python handler runs before this returns."""
    signal.raise_signal(signum)


@pytest.mark.parametrize(("signum", "status"), [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_before_a_run_a_signal_ends_the_command_at_once(signum: int, status: int) -> None:
    with command_signals(), pytest.raises(Interrupted) as raised:
        _kill(signum)
    assert raised.value.exit_status == status
    assert raised.value.line() == f"pfctl: interrupted ({signal.Signals(signum).name})\n"


def test_in_a_run_the_first_stops_the_second_changes_nothing_the_third_abandons(
    capfd: pytest.CaptureFixture[str],
) -> None:
    with command_signals():
        with graceful_interrupts() as stop:
            assert not stop()
            _kill(signal.SIGTERM)
            assert stop() and stop.signum == signal.SIGTERM
        _kill(signal.SIGINT)  # after the run, while writing: still no exception
        err = capfd.readouterr().err
        assert err == ""  # the command's one line comes at its end
        with pytest.raises(Interrupted) as raised:
            _kill(signal.SIGINT)
    assert raised.value.signum == signal.SIGTERM and raised.value.exit_status == 143
    assert "abandoned" in raised.value.line()


def test_a_signal_while_writing_after_a_whole_run_is_not_lost(
    capsys: pytest.CaptureFixture[str],
) -> None:
    with command_signals():
        with graceful_interrupts() as stop:
            pass
        _kill(signal.SIGINT)
        assert stop() and stop.signum == signal.SIGINT
        with pytest.raises(SystemExit) as ended:
            stop.exit_if_set("after 3.0 s; wrote out")
    assert ended.value.code == 130
    assert capsys.readouterr().err == "pfctl: interrupted (SIGINT) after 3.0 s; wrote out\n"


def test_outside_a_command_a_run_handles_both_signals_and_restores_the_handlers() -> None:
    before = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)}
    with graceful_interrupts() as stop:
        _kill(signal.SIGTERM)
        assert stop.signum == signal.SIGTERM
    assert {s: signal.getsignal(s) for s in before} == before


def test_a_signal_ignored_at_start_stays_ignored() -> None:
    """A background job of a shell without job control ignores Ctrl-C: so does the command."""
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        with command_signals():
            assert signal.getsignal(signal.SIGINT) is signal.SIG_IGN
            with graceful_interrupts() as stop:
                _kill(signal.SIGINT)
            assert not stop()
    finally:
        signal.signal(signal.SIGINT, previous)


def _import_cut_short_by(signum: int) -> None:
    """What a native extension's import does when a signal's exception cuts its module's
    initialisation short (dlib's pybind11 module): it raises an ImportError from it."""
    try:
        _kill(signum)
    except Interrupted as err:
        raise ImportError("initialization failed") from err


def test_a_signal_that_surfaced_as_another_exception_is_found_behind_it() -> None:
    with command_signals(), pytest.raises(ImportError) as raised:
        _import_cut_short_by(signal.SIGTERM)
    found = behind(raised.value)
    assert found is not None and found.signum == signal.SIGTERM
    assert behind(ImportError("no module named dlib")) is None


def test_the_command_ends_as_interrupted_when_the_signal_surfaced_as_another_exception(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """CI once sent SIGTERM while ``follow`` imported dlib: the command ended with the
    ImportError's traceback and status 1 instead of its one line and 143."""
    monkeypatch.setattr(cli, "_run_app", lambda: _import_cut_short_by(signal.SIGTERM))
    with pytest.raises(SystemExit) as ended:
        cli.main()
    assert ended.value.code == 143
    assert capsys.readouterr().err == "pfctl: interrupted (SIGTERM)\n"


def test_an_exception_without_a_signal_behind_it_is_not_taken_for_one(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    def fails() -> None:
        raise ImportError("initialization failed")

    monkeypatch.setattr(cli, "_run_app", fails)
    with pytest.raises(ImportError):
        cli.main()
