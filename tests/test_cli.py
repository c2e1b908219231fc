"""The console entry point: a usage error (option out of range, unknown option or command, missing
argument, a value of the wrong type) is one line ``pfctl: error: ...`` and exit status 2, like
any other bad input; --help, --version and the bare command still behave as usual."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from tests.conftest import run_cli

ROOT = Path(__file__).resolve().parents[1]


def _assert_one_usage_line(err: str, *fragments: str) -> None:
    assert "Traceback" not in err and "╭" not in err and "Usage:" not in err, err
    lines = err.splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("pfctl: error: "), lines[0]
    for fragment in fragments:
        assert fragment in lines[0], lines[0]


@pytest.mark.parametrize(
    ("args", "fragments"),
    [
        (["predict", "evaluate", "data", "--jobs", "0"], ["predict evaluate: ", "'--jobs'", "1"]),
        (["follow", "missions/house.yaml", "--bogus"], ["follow: ", "No such option: --bogus"]),
        (["follow"], ["follow: ", "Missing argument MISSION"]),
        (["follow", "missions/house.yaml", "--seed", "abc"], ["follow: ", "'--seed'"]),
        (["mission", "nosuch"], ["mission: ", "No such command 'nosuch'"]),
        (["nosuch"], ["No such command 'nosuch'", "see pfctl --help"]),
    ],
)
def test_usage_errors_are_one_line_exit_2(
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
    args: list[str],
    fragments: list[str],
) -> None:
    code, out, err = run_cli(args, capsys, monkeypatch)
    assert code == 2 and out == ""
    _assert_one_usage_line(err, *fragments)


def test_help_version_and_bare_command_unchanged(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    code, out, err = run_cli(["predict", "evaluate", "--help"], capsys, monkeypatch)
    assert code == 0 and "Usage:" in out and "--jobs" in out and err == ""
    code, out, err = run_cli(["--version"], capsys, monkeypatch)
    assert code == 0 and out.startswith("pfctl ") and err == ""
    code, out, _ = run_cli([], capsys, monkeypatch)
    assert code == 2 and "Usage:" in out  # the bare command prints the help, as before
    code, out, _ = run_cli(["mission"], capsys, monkeypatch)
    assert code == 2 and "validate" in out


@pytest.mark.slow
def test_usage_error_in_a_real_process() -> None:
    """The console script for real (its own stderr, not the test's capture)."""
    run = subprocess.run(
        [sys.executable, "-m", "pfctl", "predict", "evaluate", "data", "--jobs", "0"],
        capture_output=True,
        text=True,
        timeout=60,
        cwd=ROOT,
    )
    assert run.returncode == 2 and run.stdout == ""
    _assert_one_usage_line(run.stderr, "predict evaluate: ", "'--jobs'")
