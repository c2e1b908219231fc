"""benchmarks/hostile_inputs.py: its catalogue is big enough, unique and covers every command;
its checks tell a clean outcome from an unclean one; a few cases run end to end."""

from __future__ import annotations

import importlib
import sys
import textwrap
from pathlib import Path
from typing import Any

import pytest
import typer

from pfctl import cli

BENCHMARKS = Path(__file__).resolve().parents[2] / "benchmarks"
sys.path.insert(0, str(BENCHMARKS))
hostile = importlib.import_module("hostile_inputs")
cases = importlib.import_module("hostile_catalogue")


def _leaf_commands() -> set[str]:
    """Every command of the CLI, as words after ``pfctl`` (``predict track`` is ``predict``)."""
    out: set[str] = set()

    def walk(command: Any, words: tuple[str, ...]) -> None:
        # typer carries its own click: its groups are not click.Group, so ask for subcommands
        commands = getattr(command, "commands", None)
        if commands is not None:
            for name, sub in commands.items():
                walk(sub, (*words, name))
        else:
            out.add(" ".join(words))

    walk(typer.main.get_command(cli.app), ())
    return {"predict" if c == "predict track" else c for c in out}


def test_the_catalogue_has_at_least_150_cases_with_unique_ids() -> None:
    every = cases.catalogue()
    ids = [c.id for c in every]
    assert len(every) >= 150
    assert len(set(ids)) == len(ids)


def test_every_command_of_the_cli_has_a_case() -> None:
    commands = {c.command for c in cases.catalogue()}
    missing = _leaf_commands() - commands
    assert not missing, f"commands without a hostile case: {sorted(missing)}"
    assert set(cases.COMMANDS) <= commands


def test_every_long_command_is_interrupted_by_sigint_twice_and_sigterm() -> None:
    plans: dict[str, set[tuple[str, ...]]] = {}
    for case in cases.catalogue():
        if case.interrupt is not None:
            names = tuple(name for _, name, _ in case.interrupt.signals)
            plans.setdefault(case.command, set()).add(names)
    for command in ("follow", "search", "sim run", "bench"):
        assert {("SIGINT",), ("SIGINT", "SIGINT"), ("SIGTERM",)} <= plans[command], command
    assert ("SIGKILL",) in plans["bench"]


def test_each_case_builds_its_files(tmp_path: Path) -> None:
    shared = hostile.Shared(tmp_path, target=tmp_path / "t.npz", bag=tmp_path / "b.bag")
    (tmp_path / "t.npz").write_bytes(b"PK" * 3000)
    (tmp_path / "b.bag").write_bytes(b"#ROSBAG" * 4000)
    for case in cases.catalogue():
        if "campaign" in case.needs:
            continue
        ws = tmp_path / case.id
        ws.mkdir()
        hostile.write_files(case, ws, shared)


def test_stderr_lines_drop_the_progress_bar_and_colour() -> None:
    text = (
        "\x1b[?25lfollowing \x1b[38;5;237m━━━━━\x1b[0m 1.5/40 s simulated 0:00:30\r"
        "\x1b[2Kfollowing ━━━━━━━╸ 2.0/40 s simulated\n\x1b[?25h"
        "\x1b[31mpfctl: interrupted\x1b[0m\n"
    )
    assert hostile.stderr_lines(text) == ["pfctl: interrupted"]
    after_bar = "episodes ━━━╺━━ 1/3 -:--:--\x1b[2K[1/3] house: following 77.5%\n"
    assert hostile.stderr_lines(after_bar) == ["[1/3] house: following 77.5%"]


def catalogue_png() -> bytes:
    return cases.png_bytes()


def _run(stderr: str, exit: int) -> object:
    return hostile.Run(exit, "", stderr, 1.0, 1.0, 50.0, False, [], [])


def test_judge_wants_one_error_line_naming_the_option_or_its_value(tmp_path: Path) -> None:
    case = cases.Case(
        "x",
        "map render",
        ("map", "render", "m.yaml", "--png", "f/o.png"),
        cases.Expect("error", ("--png",)),
    )
    before = hostile.snapshot(tmp_path)
    ok, _, why = hostile.judge(
        case, _run("pfctl: error: f/o.png: cannot write\n", 2), tmp_path, before
    )
    assert ok, why
    box = "Usage: pfctl\nTry 'pfctl --help'\n╭─ Error ─╮\n│ bad │\n╰─────╯\n"
    misled = cases.Case(
        "y", "follow", ("follow",), cases.Expect("error", ("t.npz",), avoid=("pickle",))
    )
    ok, _, why = hostile.judge(
        misled, _run("pfctl: error: t.npz: use allow_pickle\n", 2), tmp_path, before
    )
    assert not ok and "says pickle" in why
    ok, _, why = hostile.judge(case, _run(box, 2), tmp_path, before)
    assert not ok and "stderr lines" in why
    (tmp_path / "f.png").write_bytes(b"partial")
    ok, _, why = hostile.judge(case, _run("pfctl: error: --png: no\n", 2), tmp_path, before)
    assert not ok and "f.png" in why
    ok, _, why = hostile.judge(
        case, _run("Traceback (most recent call last):\n", 1), tmp_path, before
    )
    assert not ok and "traceback" in why


def test_judge_of_an_interruption_parses_the_outputs(tmp_path: Path) -> None:
    case = cases.Case(
        "x",
        "follow",
        ("follow",),
        cases.Expect("interrupt", code=130, outputs=("o/metrics.json", "o/p.png")),
    )
    (tmp_path / "o").mkdir()
    (tmp_path / "o" / "metrics.json").write_text('{"a": ')
    ok, _, why = hostile.judge(case, _run("pfctl: interrupted\n", 130), tmp_path, set())
    assert not ok and "metrics.json does not parse" in why and "p.png missing" in why
    (tmp_path / "o" / "metrics.json").write_text("{}")
    (tmp_path / "o" / "p.png").write_bytes(catalogue_png())
    log = "[1/3] house · seed 1: following 77%\npfctl: interrupted; 2 episodes not done\n"
    ok, _, why = hostile.judge(case, _run(log, 130), tmp_path, set())
    assert ok, why
    ok, _, why = hostile.judge(case, _run("", -15), tmp_path, set())
    assert not ok and "died of SIGTERM" in why and "0 lines say" in why


def test_a_signalled_run_waits_for_progress_and_finds_leftover_children(tmp_path: Path) -> None:
    """The process machinery on a stand-in for pfctl: progress on stderr, then SIGINT; the
    stand-in leaves a sleeping child behind, which is reported (and killed)."""
    script = textwrap.dedent(
        """
        import signal, subprocess, sys, time
        subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])
        def stop(signum, frame):
            sys.stderr.write("pfctl: interrupted\\n")
            sys.exit(130)
        signal.signal(signal.SIGINT, stop)
        for i in range(600):
            sys.stderr.write(f"following ━━ {i / 10:.1f}/60 s\\r")
            sys.stderr.flush()
            time.sleep(0.05)
        """
    )
    case = cases.Case(
        "stand-in",
        "follow",
        (),
        cases.Expect("interrupt", code=130),
        interrupt=cases.Interrupt(((0.0, "SIGINT", "main"),), progress=0.5),
        timeout=30,
    )
    run = hostile.run_process(case, [sys.executable, "-c", script], tmp_path)
    assert run.exit == 130 and run.signalled == ["SIGINT to main"]
    assert hostile.stderr_lines(run.stderr) == ["pfctl: interrupted"]
    assert len(run.leftover) == 1
    ok, _, why = hostile.judge(case, run, tmp_path, set())
    assert not ok and "left" in why


@pytest.mark.slow
def test_quick_cases_end_to_end(tmp_path: Path) -> None:
    """Two bad inputs pfctl handles cleanly, and a valid mission posing as a bad one (the
    script must call that unclean)."""
    by_id = {c.id: c for c in cases.catalogue()}
    posing = cases.Case(
        "valid-posing-as-bad",
        "mission validate",
        ("mission", "validate", "{repo}/missions/house.yaml"),
        cases.Expect("error", ("house.yaml",)),
    )
    chosen = [by_id["mv-yaml-syntax"], by_id["mv-missing-file"], posing]
    outcomes = hostile.run_all(chosen, 2, 1, tmp_path, lambda s: None)
    assert [o.ok for o in outcomes] == [True, True, False], [o.reason for o in outcomes]
    assert "exit 0, not 2" in outcomes[2].reason
    assert "handled cleanly: 2 of 3" in hostile.table(outcomes)
