"""`pfctl legs train` and `pfctl legs evaluate` in-process (small simulated data sets)."""

from __future__ import annotations

import errno
import os
from pathlib import Path

import pytest

from pfctl.app.leg_data import real_dataset
from pfctl.app.leg_models import read_leg_model
from pfctl.commands import legs as legs_command
from pfctl.core.perception.legs.detector import LegParams
from pfctl.core.perception.legs.features import FEATURE_NAMES
from pfctl.core.perception.legs.training import evaluate_model
from tests.conftest import run_cli

ROOT = Path(__file__).resolve().parents[2]
LEGS = ROOT.parent / "shared" / "data" / "legs"


def test_train_writes_a_loadable_model_and_evaluate_prints_the_table(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    out = tmp_path / "m.npz"
    code, stdout, stderr = run_cli(
        ["legs", "train", "--sim-scans", "40", "--seed", "2", "--out", str(out)],
        capsys,
        monkeypatch,
    )
    assert code == 0, stderr
    assert "sim: 40 scans" in stdout and f"wrote {out}" in stdout
    model = read_leg_model(out, FEATURE_NAMES)
    assert model.metadata["seed"] == 2 and model.metadata["sim_scans"] == 40
    assert [p.name for p in tmp_path.iterdir()] == ["m.npz"]  # no temporaries left
    code, stdout, stderr = run_cli(
        ["legs", "evaluate", "--model", str(out), "--sim-scans", "15"], capsys, monkeypatch
    )
    assert code == 0, stderr
    assert "precision 0.5–5 m" in stdout and "sim, seed" in stdout
    assert "no --real DIR given" in stderr


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["legs", "train", "--sim-scans", "-1"], "--sim-scans: expected an integer ≥ 0, got -1"),
        (["legs", "train", "--sim-scans", "0"], "nothing to train on"),
        (["legs", "train", "--real", "/no/such/dir", "--sim-scans", "0"], "no such folder"),
        (["legs", "train", "--out", "/no/such/dir/m.npz"], "--out /no/such/dir/m.npz: no such"),
        (["legs", "evaluate", "--model", "/no/m.npz"], "/no/m.npz: no such leg model file"),
        (["legs", "evaluate", "--sim-scans", "0"], "--sim-scans: expected an integer ≥ 1"),
        (["legs", "evaluate", "--mission", "/no/house.yaml"], "--mission /no/house.yaml"),
        (["legs", "evaluate", "--history", "0"], "--history: expected an integer ≥ 1, got 0"),
    ],
)
def test_bad_inputs_exit_2_with_one_line(
    args: list[str],
    message: str,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    code, _, stderr = run_cli(args, capsys, monkeypatch)
    assert code == 2
    assert message in stderr
    assert stderr.count("\n") == 1


def test_corrupt_model_exits_2(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    bad = tmp_path / "bad.npz"
    bad.write_text("hello")
    code, _, stderr = run_cli(["legs", "evaluate", "--model", str(bad)], capsys, monkeypatch)
    assert code == 2 and "bad.npz: not a leg model" in stderr


@pytest.mark.parametrize("command", ["train", "evaluate"])
def test_a_wrong_real_folder_is_refused_before_the_simulation(
    command: str,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setattr(legs_command, "_sim", lambda *_: pytest.fail("simulated first"))
    (tmp_path / "d").mkdir()
    args = ["legs", command, "--sim-scans", "20", "--real", str(tmp_path / "d")]
    if command == "train":
        args += ["--out", str(tmp_path / "m.npz")]
    code, stdout, stderr = run_cli(args, capsys, monkeypatch)
    assert code == 2 and stdout == ""
    assert (
        stderr.startswith(f"pfctl: error: {tmp_path / 'd'}: no leg bags")
        and stderr.count("\n") == 1
    )
    assert [p.name for p in tmp_path.iterdir()] == ["d"]


def test_an_error_after_the_evaluation_is_the_only_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """The note that no --real was given came before a late error (the --json write)."""

    def disk_full(path: Path, data: str) -> None:
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr("pfctl.files.atomic_write", disk_full)
    out = tmp_path / "l.json"
    code, _, stderr = run_cli(
        ["legs", "evaluate", "--sim-scans", "20", "--json", str(out)], capsys, monkeypatch
    )
    assert code == 2
    assert stderr == f"pfctl: error: --json {out}: cannot write: No space left on device\n"
    assert not out.exists()


@pytest.mark.skipif(not LEGS.is_dir(), reason=f"no real leg bags in {LEGS}")
@pytest.mark.xfail(
    strict=True,
    reason="goal not met yet: on positive_2 + negative_2 (both in its training data) the shipped "
    "model's recall and precision at 0.5-5 m stay below 0.9 (benchmarks/leg_real_ceiling.py)",
)
def test_shipped_model_on_a_real_bag(tmp_path: Path) -> None:
    """The shipped model (trained on sim + every real bag) on one positive bag and the
    negative bag's scans: most legs found, few non-legs called legs."""
    for name in ("positive_2_extracted.bag", "negative_2.bag"):
        (tmp_path / name).symlink_to(LEGS / name)
    data = real_dataset(tmp_path, LegParams())
    from pfctl.app.leg_models import load_leg_model

    band, _ = evaluate_model(load_leg_model(None), data, 0.5)
    assert band.recall >= 0.9
    assert band.precision >= 0.9
