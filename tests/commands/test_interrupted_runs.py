"""Ctrl-C and SIGTERM during ``pfctl follow``, ``search`` and ``sim run`` (the simulated house),
sent as a terminal and ``timeout`` send them, to the whole process group: once, or twice 0.3 s
apart. Each time the outputs of what was measured are written, the command ends with exactly one
``pfctl:`` line and 130 (SIGINT first) or 143 (SIGTERM first), and no traceback.

stderr is a terminal (a pty), as for a person at the keyboard: its progress bar says when the
episode runs, and the signals come once a simulated second has passed."""

from __future__ import annotations

import json
import os
import pty
import re
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

pytestmark = [pytest.mark.sim, pytest.mark.slow]

HOUSE = Path(__file__).resolve().parents[2] / "missions" / "house.yaml"
PNG = b"\x89PNG\r\n\x1a\n"
#: Wall seconds a command may take to reach its episode, and to end after the signals.
TIMEOUT = 300.0
_PROGRESS = re.compile(rb"(\d+\.\d)/\d+ s")
_ANSI = re.compile(r"\x1b\[[0-9;?]*[A-Za-z]")


def _default_signals() -> None:
    # a child of a shell without job control may inherit SIGINT ignored, which pfctl respects
    signal.signal(signal.SIGINT, signal.SIG_DFL)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)


class _Command:
    """``python -m pfctl ARGS`` in its own process group, stderr on a pty read by a thread."""

    def __init__(self, *args: str) -> None:
        master, slave = pty.openpty()
        self._master = master
        self._stderr = bytearray()
        self.process = subprocess.Popen(
            [sys.executable, "-m", "pfctl", *args],
            stdin=subprocess.DEVNULL,
            stdout=subprocess.PIPE,
            stderr=slave,
            start_new_session=True,
            preexec_fn=_default_signals,
        )
        os.close(slave)
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()

    def _read(self) -> None:
        while True:
            try:
                chunk = os.read(self._master, 4096)
            except OSError:  # the child closed its end
                return
            if not chunk:
                return
            self._stderr.extend(chunk)

    def wait_for_text(self, text: bytes) -> None:
        """Until ``text`` appears on stderr."""
        deadline = time.monotonic() + TIMEOUT
        while text not in bytes(self._stderr):
            assert self.process.poll() is None, self.finish()
            assert time.monotonic() < deadline, f"no {text!r}: {self.finish()}"
            time.sleep(0.05)

    def wait_for_episode(self, simulated: float = 1.0) -> None:
        """Until the progress bar shows ``simulated`` seconds of the episode."""
        deadline = time.monotonic() + TIMEOUT
        while time.monotonic() < deadline:
            shown = [float(m) for m in _PROGRESS.findall(bytes(self._stderr))]
            if shown and max(shown) >= simulated:
                return
            assert self.process.poll() is None, self.finish()
            time.sleep(0.05)
        raise AssertionError(f"no episode after {TIMEOUT:g} s: {self.finish()}")

    def signal(self, signum: int) -> None:
        os.killpg(self.process.pid, signum)

    def finish(self) -> tuple[int, str, str]:
        """(status, stdout, stderr as text: colours and the bar's redraws removed)."""
        try:
            out, _ = self.process.communicate(timeout=TIMEOUT)
        finally:
            if self.process.poll() is None:
                os.killpg(self.process.pid, signal.SIGKILL)
                self.process.wait()
            self._reader.join(5.0)
            os.close(self._master)
        err = _ANSI.sub("", bytes(self._stderr).decode(errors="replace")).replace("\r", "\n")
        return self.process.returncode, out.decode(errors="replace"), err


def _interrupt(command: _Command, signals: tuple[int, ...]) -> tuple[int, str, str]:
    command.wait_for_episode()
    for k, signum in enumerate(signals):
        if k:
            time.sleep(0.3)  # the spacing that lost everything (issue 21, item 3)
        command.signal(signum)
    return command.finish()


def _check_ending(code: int, err: str, signals: tuple[int, ...], wrote: str) -> None:
    first = signal.Signals(signals[0])
    assert code == 128 + first, err
    assert "Traceback" not in err
    lines = [line for line in err.splitlines() if line.startswith("pfctl:")]
    assert len(lines) == 1, err
    assert lines[0].startswith(f"pfctl: interrupted ({first.name}) after "), lines
    assert lines[0].endswith(f"wrote {wrote}"), lines
    assert "still stopping" not in err  # a second signal changes nothing, says nothing


@pytest.fixture(scope="module")
def alice(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The target's profile, learned once (the commands then start with their episode)."""
    path = tmp_path_factory.mktemp("profile") / "alice.npz"
    done = subprocess.run(
        [sys.executable, "-m", "pfctl", "learn-target", str(HOUSE), "--backend", "sim",
         "--seed", "1", "--out", str(path)],
        capture_output=True, text=True, timeout=900,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    return path


@pytest.mark.parametrize(
    "signals",
    [
        (signal.SIGINT,),
        (signal.SIGINT, signal.SIGINT),
        (signal.SIGTERM,),
        (signal.SIGTERM, signal.SIGINT),
    ],
    ids=["int", "int-int", "term", "term-int"],
)
def test_follow_writes_what_was_measured(
    alice: Path, tmp_path: Path, signals: tuple[int, ...]
) -> None:
    out = tmp_path / "follow"
    command = _Command(
        "follow", str(HOUSE), "--seed", "1", "--duration", "60", "--target", str(alice),
        "--out", str(out),
    )  # fmt: skip
    code, stdout, err = _interrupt(command, signals)
    _check_ending(code, err, signals, str(out))
    metrics = json.loads((out / "metrics.json").read_text())
    assert metrics["interrupted"] is True
    assert 1.0 <= metrics["sim_time_s"] < 60.0
    assert (out / "tracks.csv").read_text().count("\n") > 1
    for name in ("trajectory.png", "timeline.png"):
        assert (out / name).read_bytes()[:8] == PNG
    assert stdout.startswith("interrupted after")


@pytest.mark.parametrize(
    "signals", [(signal.SIGINT, signal.SIGINT), (signal.SIGTERM,)], ids=["int-int", "term"]
)
def test_search_writes_what_was_measured(
    alice: Path, tmp_path: Path, signals: tuple[int, ...]
) -> None:
    out = tmp_path / "search"
    command = _Command(
        "search", str(HOUSE), "--seed", "1", "--duration", "60", "--target", str(alice),
        "--region", "bedroom", "--out", str(out),
    )  # fmt: skip
    code, stdout, err = _interrupt(command, signals)
    _check_ending(code, err, signals, str(out))
    metrics = json.loads((out / "metrics.json").read_text())
    assert metrics["region"] == "bedroom" and metrics["found"] is False
    assert (out / "search.png").read_bytes()[:8] == PNG
    assert stdout.startswith("did not find the target")


@pytest.mark.parametrize(
    "signals", [(signal.SIGINT, signal.SIGINT), (signal.SIGTERM,)], ids=["int-int", "term"]
)
def test_sim_run_writes_what_was_measured(tmp_path: Path, signals: tuple[int, ...]) -> None:
    episode, png = tmp_path / "ep", tmp_path / "paths.png"
    command = _Command(
        "sim", "run", str(HOUSE), "--duration", "600", "--no-camera", "--record", str(episode),
        "--png", str(png),
    )  # fmt: skip
    code, stdout, err = _interrupt(command, signals)
    _check_ending(code, err, signals, f"the episode to {episode}/ and {png}")
    assert png.read_bytes()[:8] == PNG
    assert json.loads((episode / "episode.json").read_text())
    assert stdout.startswith("interrupted after")


def test_sigterm_while_learning_the_target_ends_follow_at_once(tmp_path: Path) -> None:
    """Before the episode (here: learning the target) SIGTERM ends the command at once with one
    line and 143; nothing is written."""
    out = tmp_path / "follow"
    command = _Command("follow", str(HOUSE), "--seed", "1", "--duration", "60", "--out", str(out))
    command.wait_for_text(b"learning the target")
    command.signal(signal.SIGTERM)
    code, stdout, err = command.finish()
    assert code == 143, err
    assert "Traceback" not in err
    assert [line for line in err.splitlines() if line.startswith("pfctl:")] == [
        "pfctl: interrupted (SIGTERM)"
    ]
    assert stdout == "" and not out.exists()
