"""``pfctl bench`` arguments for generated homes (issue 22, item 1): a folder of missions, and
the bad cases of ``--homes`` and folders — one line, exit 2, nothing written."""

from __future__ import annotations

from pathlib import Path

import pytest

from pfctl.commands.bench import _expand_folders
from tests.conftest import HOUSE_MISSION, run_cli


def test_a_folder_stands_for_its_missions_under_one_label(tmp_path: Path) -> None:
    folder = tmp_path / "my_homes"
    folder.mkdir()
    for name in ("b.yaml", "a.yaml", "notes.txt"):
        (folder / name).write_text("name: x\n")
    files, labels = _expand_folders([HOUSE_MISSION, folder])
    assert files == [HOUSE_MISSION, folder / "a.yaml", folder / "b.yaml"]
    assert labels == [None, "my_homes", "my_homes"]


@pytest.mark.parametrize(
    ("args", "expected"),
    [
        (["--homes", "0"], "pfctl: error: --homes: expected at least 1, got 0\n"),
        ([], "pfctl: error: MISSION: expected mission files, a folder of missions, or --homes N\n"),
        (["EMPTY"], "pfctl: error: {empty}: a folder without mission files (*.yaml)\n"),
    ],
)
def test_bad_homes_arguments_are_one_line(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
    args: list[str],
    expected: str,
) -> None:
    empty = tmp_path / "empty"
    empty.mkdir()
    out = tmp_path / "out"
    args = [str(empty) if a == "EMPTY" else a for a in args]
    code, _, err = run_cli(["bench", *args, "--out", str(out)], capsys, monkeypatch)
    assert code == 2
    assert err == expected.format(empty=empty)
    assert not out.exists()
