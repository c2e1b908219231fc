"""Every ``--seed`` (the shared check of :mod:`pfctl.commands`): a seed outside 0 … 2**32 - 1 is
one option error line with exit status 2 before any work starts, nothing written."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.conftest import run_cli

ROOT = Path(__file__).resolve().parents[2]
HOUSE = str(ROOT / "missions" / "house.yaml")

COMMANDS = [
    pytest.param(["follow", HOUSE, "--duration", "5"], "follow", id="follow"),
    pytest.param(["search", HOUSE, "--duration", "5"], "search", id="search"),
    pytest.param(["sim", "run", HOUSE, "--duration", "5"], "sim run", id="sim-run"),
    pytest.param(["bench", HOUSE, "--episodes", "1"], "bench", id="bench"),
    pytest.param(["learn-target", HOUSE, "--backend", "sim"], "learn-target", id="learn-target"),
    pytest.param(["legs", "train", "--sim-scans", "10"], "legs train", id="legs-train"),
    pytest.param(["legs", "evaluate", "--sim-scans", "10"], "legs evaluate", id="legs-evaluate"),
    pytest.param(["sim", "serve-hsr", HOUSE], "sim serve-hsr", id="serve-hsr"),
    pytest.param(["predict", "search", "data"], "predict search", id="predict-search"),
    pytest.param(["predict", "experiment", "door"], "predict experiment door", id="door"),
]


@pytest.mark.parametrize("seed", ["-1", str(2**32)])
@pytest.mark.parametrize(("args", "command"), COMMANDS)
def test_seed_out_of_range_is_one_option_error(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
    args: list[str],
    command: str,
    seed: str,
) -> None:
    monkeypatch.chdir(tmp_path)
    code, out, err = run_cli([*args, "--seed", seed], capsys, monkeypatch)
    assert code == 2 and out == ""
    lines = err.splitlines()
    assert len(lines) == 1 and "Traceback" not in err, err
    assert lines[0].startswith(f"pfctl: error: {command}: Invalid value for '--seed'"), lines[0]
    assert f"expected a seed from 0 to {2**32 - 1} (2**32 - 1), got {seed}" in lines[0]
    assert list(tmp_path.iterdir()) == []  # no output folder, no partial file


def test_bench_refuses_seeds_that_run_past_2_to_the_32(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    out_dir = tmp_path / "bench"
    args = ["bench", HOUSE, "--seed", str(2**32 - 3), "--episodes", "5", "--out", str(out_dir)]
    code, out, err = run_cli(args, capsys, monkeypatch)
    assert code == 2 and out == ""
    assert err == (
        f"pfctl: error: --seed {2**32 - 3} --episodes 5: the last episode's seed {2**32 + 1} "
        f"is above {2**32 - 1} (2**32 - 1)\n"
    )
    assert not out_dir.exists()
