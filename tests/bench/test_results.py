"""pfctl bench's results file and --resume, with a stand-in runner (no simulation): records
appended as episodes end, finished episodes skipped, a different configuration refused, a line
cut short dropped (and said so), Ctrl-C keeping what finished (exit 130), failed episodes ending
the campaign with exit status 1."""

from __future__ import annotations

import json
import shutil
import sys
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import pytest

from pfctl import cli
from pfctl.bench.episode import record_header
from pfctl.bench.plan import EpisodeSpec
from pfctl.bench.results import RESULTS_FILE, read_records
from pfctl.commands import bench as bench_command
from pfctl.errors import UserError
from tests.conftest import HOUSE_MISSION, run_cli

BASE_ARGS = ["--episodes", "2", "--duration", "15", "--vary", "search.alpha=1,2"]


def fake_record(spec: EpisodeSpec, status: str = "ok") -> dict[str, Any]:
    """What run_episode_task returns, with metrics made from the seed."""
    rate = 0.1 * (spec.seed % 7)
    return {
        **record_header(spec),
        "status": status,
        "error": None if status == "ok" else "RuntimeError: boom",
        "metrics": {
            "following_rate": rate,
            "first_identified_s": 0.5,
            "losses": 1,
            "reacquired": 1,
            "refind_times_s": [10.0 + spec.seed],
            "identity_switches": 0,
            "collisions": 0,
            "distance_m": 5.0 + spec.seed,
        }
        if status == "ok"
        else None,
        "timing": {"wall_s": 1.0} if status == "ok" else None,
        "run": {"id": f"run-{len(calls)}-{spec.variant}-{spec.seed}", "pid": 1},
    }


calls: list[list[tuple[str, str, int]]] = []


class FakeRunner:
    """Stands in for run_in_processes: records which specs it got, answers from the seed."""

    def __init__(
        self,
        status: Callable[[EpisodeSpec], str] = lambda s: "ok",
        fail_after: int | None = None,
        error: BaseException | None = None,
    ) -> None:
        self.status = status
        self.fail_after = fail_after
        self.error = error

    def __call__(
        self,
        specs: Sequence[EpisodeSpec],
        workers: int,
        on_record: Callable[[dict[str, Any]], None],
        episode: Callable[[EpisodeSpec], Any],
        on_retry: Callable[[EpisodeSpec, str], None] | None = None,
    ) -> None:
        calls.append([s.key for s in specs])
        for i, spec in enumerate(specs):
            if self.fail_after is not None and i == self.fail_after:
                assert self.error is not None
                raise self.error
            on_record(fake_record(spec, self.status(spec)))


@pytest.fixture(autouse=True)
def _fresh_calls() -> None:
    calls.clear()


def bench(
    out: Path,
    args: list[str],
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
    fake: FakeRunner | None = None,
) -> tuple[int, str, str]:
    monkeypatch.setattr(bench_command, "run_in_processes", fake or FakeRunner())
    return run_cli(["bench", str(HOUSE_MISSION), "--out", str(out), *args], capsys, monkeypatch)


def lines(out: Path) -> list[str]:
    return (out / RESULTS_FILE).read_text().splitlines()


def test_a_campaign_writes_records_and_the_summary(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    out = tmp_path / "c"
    code, stdout, err = bench(out, BASE_ARGS, capsys, monkeypatch)
    assert code == 0, err
    # seed-major: both variants on seed 1, then on seed 2
    house = str(HOUSE_MISSION)
    assert calls == [
        [
            (house, "search.alpha=1", 1),
            (house, "search.alpha=2", 1),
            (house, "search.alpha=1", 2),
            (house, "search.alpha=2", 2),
        ]
    ]
    records = [json.loads(line) for line in lines(out)]
    assert len(records) == 4 and len({r["config"] for r in records}) == 1
    for name in ("campaign.json", "summary.csv", "summary.md", "episodes.csv", "boxplots.png"):
        assert (out / name).stat().st_size > 0
    md = (out / "summary.md").read_text()
    assert "| search.alpha=1 | 2 |" in md and "| search.alpha=2 | 2 |" in md
    assert "following rate" in stdout and "[4/4]" in err


@pytest.mark.slow
def test_resume_runs_only_what_is_missing(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    out = tmp_path / "c"
    assert bench(out, BASE_ARGS, capsys, monkeypatch)[0] == 0
    first = lines(out)
    # without --resume the results are not touched
    code, _, err = bench(out, BASE_ARGS, capsys, monkeypatch)
    assert code == 2 and "continue it with --resume" in err and lines(out) == first
    # keep two records and half of the third (a crash while writing it)
    (out / RESULTS_FILE).write_text("\n".join(first[:2]) + "\n" + first[2][:40])
    calls.clear()
    code, _, err = bench(out, [*BASE_ARGS, "--resume"], capsys, monkeypatch)
    assert code == 0, err
    # said in one line: which file, which line, that its episode runs again (issue 21, item 15)
    [said] = [line for line in err.splitlines() if "cut short" in line]
    assert f"{out / RESULTS_FILE}:3: the last line was cut short" in said
    assert "its episode runs again" in said
    house = str(HOUSE_MISSION)
    assert calls == [[(house, "search.alpha=1", 2), (house, "search.alpha=2", 2)]]
    now = lines(out)
    assert len(now) == 4 and now[:2] == first[:2]  # the finished ones kept their run ids
    records = [json.loads(line) for line in now]
    assert sorted((r["variant"], r["seed"]) for r in records) == [
        ("search.alpha=1", 1),
        ("search.alpha=1", 2),
        ("search.alpha=2", 1),
        ("search.alpha=2", 2),
    ]
    assert "4/4 episodes" in (out / "summary.md").read_text()
    # more episodes extend the campaign: only the new seed runs
    calls.clear()
    code, _, _ = bench(out, [*BASE_ARGS, "--resume", "--episodes", "3"], capsys, monkeypatch)
    assert code == 0
    assert calls == [[(house, "search.alpha=1", 3), (house, "search.alpha=2", 3)]]
    # nothing left: nothing runs, the summary is written again
    calls.clear()
    code, _, _ = bench(out, [*BASE_ARGS, "--resume", "--episodes", "3"], capsys, monkeypatch)
    assert code == 0 and calls in ([], [[]])
    assert len(lines(out)) == 6


def test_failed_episodes_run_again_on_resume(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    out = tmp_path / "c"
    flaky = FakeRunner(status=lambda s: "error" if s.seed == 2 else "ok")
    code, _, err = bench(out, BASE_ARGS, capsys, monkeypatch, flaky)
    # failed episodes: the summary of what finished, exit 1 and one line (issue 21, item 8)
    assert code == 1 and "error RuntimeError: boom" in err
    assert err.count("pfctl: error:") == 1
    assert f"pfctl: error: 2 of 4 episodes failed; their errors are in {out / RESULTS_FILE}" in (
        " ".join(err.split())
    )
    assert "2 (+2 failed)" not in (out / "summary.md").read_text()
    assert "| search.alpha=1 | 1 (+1 failed) |" in (out / "summary.md").read_text()
    calls.clear()
    assert bench(out, [*BASE_ARGS, "--resume"], capsys, monkeypatch)[0] == 0
    assert [seed for _, _, seed in calls[0]] == [2, 2]
    assert len(lines(out)) == 6  # the error records stay; the last record of an episode counts
    assert "| search.alpha=1 | 2 |" in (out / "summary.md").read_text()


@pytest.fixture(scope="module")
def finished(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A finished campaign of BASE_ARGS (made once; copy it before changing it)."""
    out = tmp_path_factory.mktemp("finished") / "c"
    with pytest.MonkeyPatch.context() as monkeypatch:
        monkeypatch.setattr(bench_command, "run_in_processes", FakeRunner())
        monkeypatch.setattr(
            sys, "argv", ["pfctl", "bench", str(HOUSE_MISSION), "--out", str(out), *BASE_ARGS]
        )
        with pytest.raises(SystemExit) as exited:
            cli.main()
    assert exited.value.code in (0, None)
    return out


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--episodes", "2", "--duration", "20", "--vary", "search.alpha=1,2"], "--duration 15"),
        (["--episodes", "2", "--duration", "15", "--vary", "search.alpha=1,3"], "was not in it"),
        (
            ["--episodes", "2", "--duration", "15", "--seed", "5", "--vary", "search.alpha=1,2"],
            "--seed 1",
        ),
        ([*BASE_ARGS, "--task", "search"], "--task follow now search"),
    ],
)
def test_resume_refuses_another_configuration(
    args: list[str],
    message: str,
    finished: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    out = tmp_path / "c"
    shutil.copytree(finished, out)
    before = lines(out)
    calls.clear()
    code, _, err = bench(out, [*args, "--resume"], capsys, monkeypatch)
    assert code == 2 and calls == []
    assert "was written by a different campaign" in err and message in err
    assert err.count("\n") == 1 and lines(out) == before


def test_ctrl_c_keeps_what_finished_and_exits_130(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    out = tmp_path / "c"
    stop = FakeRunner(fail_after=1, error=KeyboardInterrupt())
    code, _, err = bench(out, BASE_ARGS, capsys, monkeypatch, stop)
    assert code == 130 and "--resume" in err
    assert len(lines(out)) == 1
    assert "1/4 episodes" in (out / "summary.md").read_text()
    calls.clear()
    assert bench(out, [*BASE_ARGS, "--resume"], capsys, monkeypatch)[0] == 0
    assert len(calls[0]) == 3 and len(lines(out)) == 4


def test_a_campaign_whose_every_episode_fails_exits_1(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    out = tmp_path / "c"
    code, _, err = bench(out, BASE_ARGS, capsys, monkeypatch, FakeRunner(status=lambda s: "error"))
    assert code == 1 and "4 of 4 episodes failed" in " ".join(err.split())
    assert "Traceback" not in err and len(lines(out)) == 4
    assert (out / "summary.md").exists()


def test_ray_missing_is_one_line_and_writes_nothing(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(bench_command, "ray_available", lambda: False)
    out = tmp_path / "c"
    code, _, err = bench(out, [*BASE_ARGS, "--ray", "local"], capsys, monkeypatch)
    assert code == 2 and "Ray is not installed; pip install 'pfctl[ray]'" in err
    assert not out.exists()


@pytest.mark.parametrize("address", ["carrier-pigeon", "ray://", "host:port", ""])
def test_a_malformed_ray_address_is_one_line_and_writes_nothing(
    address: str,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """``--ray carrier-pigeon`` printed the plan line, wrote campaign.json and only then heard
    Ray's "Invalid address format": now refused before Ray is imported or anything written."""
    monkeypatch.setattr(bench_command, "connect_ray", lambda *_: pytest.fail("Ray was started"))
    out = tmp_path / "c"
    code, stdout, err = bench(out, [*BASE_ARGS, "--ray", address], capsys, monkeypatch)
    assert code == 2 and stdout == ""
    assert err == (
        f"pfctl: error: --ray {address}: expected auto, local, HOST:PORT or ray://HOST:PORT\n"
    )
    assert list(tmp_path.iterdir()) == []


def test_a_ray_cluster_out_of_reach_is_one_line_and_writes_nothing(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """Ray is reached before the campaign's files are written."""

    def unreachable(address: str, workers: int) -> bool:
        raise UserError(f"--ray {address}: cannot start or reach Ray: timed out")

    monkeypatch.setattr(bench_command, "ray_available", lambda: True)
    monkeypatch.setattr(bench_command, "connect_ray", unreachable)
    out = tmp_path / "c"
    code, stdout, err = bench(out, [*BASE_ARGS, "--ray", "ray://head:10001"], capsys, monkeypatch)
    assert code == 2 and stdout == ""
    assert err == "pfctl: error: --ray ray://head:10001: cannot start or reach Ray: timed out\n"
    assert list(tmp_path.iterdir()) == []


def test_a_bad_results_line_is_named(tmp_path: Path) -> None:
    path = tmp_path / RESULTS_FILE
    path.write_text('{"mission_file": "m.yaml", "variant": "base", "seed": 1}\nnot json\n')
    with pytest.raises(UserError, match=r"results\.jsonl:2: not an episode record"):
        read_records(path)
    path.write_text('{"mission_file": "m.yaml", "variant": "base", "seed": 1}\n{"mission_f')
    records, complete = read_records(path)
    assert len(records) == 1 and complete == len(path.read_text().split("\n")[0]) + 1
