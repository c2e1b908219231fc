"""The campaign's SIGINT and SIGTERM handling: the first one stops it, a record being written is
kept whole, later ones are ignored until the summary is written; the exit status says which
(issue 21: SIGTERM like Ctrl-C)."""

from __future__ import annotations

import signal

import pytest

from pfctl.bench.stop_signals import StopSignals


@pytest.mark.parametrize(("signum", "code"), [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_the_first_signal_stops_and_later_ones_are_ignored(
    signum: signal.Signals, code: int
) -> None:
    before = signal.getsignal(signum)
    stop = StopSignals()
    with stop:
        with pytest.raises(KeyboardInterrupt):
            signal.raise_signal(signum)
        signal.raise_signal(signal.SIGINT)  # while stopping: nothing happens
        signal.raise_signal(signal.SIGTERM)
    assert stop.received == signum and stop.exit_code == code
    assert signal.getsignal(signum) == before


def test_a_signal_while_a_record_is_written_stops_after_it() -> None:
    written = []
    with StopSignals() as stop, pytest.raises(KeyboardInterrupt):
        with stop.holding():
            signal.raise_signal(signal.SIGTERM)
            written.append("record")
        written.append("not reached")
    assert written == ["record"] and stop.exit_code == 143


def test_no_signal_is_exit_130_for_a_keyboard_interrupt_raised_otherwise() -> None:
    with StopSignals() as stop:
        pass
    assert stop.received is None and stop.exit_code == 130
