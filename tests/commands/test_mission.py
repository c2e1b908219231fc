"""``pfctl mission generate`` (issue 22, item 1): a home that can be made is written and
validates; one that cannot is one line naming the option, exit 2, nothing written."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.conftest import run_cli


def test_a_generated_home_is_written_and_validates(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    out = tmp_path / "homes" / "home.yaml"
    args = ["mission", "generate", "--seed", "4", "--crowd", "1", "--out", str(out)]
    code, stdout, err = run_cli(args, capsys, monkeypatch)
    assert code == 0, err
    assert stdout.startswith(f"wrote {out}: ")
    code, stdout, err = run_cli(["mission", "validate", str(out)], capsys, monkeypatch)
    assert code == 0 and stdout.startswith(f"OK {out}"), err


@pytest.mark.parametrize(
    ("options", "expected"),
    [
        (
            ["--rooms", "40", "--size", "5x5"],
            "pfctl: error: --rooms 40: expected 2 rooms for a 5 x 5 m",
        ),
        (["--size", "3x3"], "pfctl: error: --size 3x3: a 3 x 3 m home is too small"),
        (["--size", "50x10"], "pfctl: error: --size 50x10: expected each side within 3..40 m"),
        (["--size", "14by10"], "pfctl: error: --size 14by10: expected WIDTHxHEIGHT in metres"),
        (["--layout", "igloo"], "pfctl: error: --layout igloo: expected one of corridor, "),
        (["--rooms", "2", "--layout", "open_plan"], "pfctl: error: --rooms 2: expected 3 to "),
        (["--crowd", "11"], "pfctl: error: --crowd 11: expected 0 to 10 people"),
    ],
)
def test_a_home_that_cannot_be_made_is_one_line_and_nothing_written(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
    options: list[str],
    expected: str,
) -> None:
    out = tmp_path / "home.yaml"
    code, stdout, err = run_cli(
        ["mission", "generate", *options, "--out", str(out)], capsys, monkeypatch
    )
    assert code == 2
    assert err.startswith(expected), err
    assert err.count("\n") == 1 and stdout == ""
    assert list(tmp_path.iterdir()) == []


def test_an_unwritable_out_is_refused_before_any_work(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    code, _, err = run_cli(
        ["mission", "generate", "--rooms", "40", "--out", str(tmp_path)], capsys, monkeypatch
    )
    assert code == 2
    assert err == f"pfctl: error: --out {tmp_path}: is a directory, expected a file path\n"
