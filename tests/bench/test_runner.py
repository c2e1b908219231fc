"""pfctl bench's worker processes without the simulator: stand-in episodes (module-level here,
so the spawned workers import them) that die, sleep or hold a face worker, under ``pfctl bench``
run as a real process (signals, exit status, stderr). A killed worker's episode runs again on a
new worker, once; SIGINT and SIGTERM, once or twice, keep what finished, leave no process behind
and end in one line (issue 21, items 8, 9 and 15)."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import pytest

from pfctl.bench.plan import EpisodeSpec
from pfctl.core.perception.face_worker import FaceWorker
from tests.conftest import HOUSE_MISSION
from tests.processes import process_gone, processes_end

pytestmark = [pytest.mark.slow]

ROOT = Path(__file__).resolve().parents[2]
#: The environment variable naming the folder where the stand-ins leave their marks.
STATE = "PFCTL_TEST_BENCH_STATE"
#: Wall seconds any one command may take.
TIMEOUT = 300

Outcome = tuple[str, dict[str, Any], dict[str, Any]]


def _ok(spec: EpisodeSpec) -> Outcome:
    metrics = {
        "following_rate": 0.1 * (spec.seed % 7),
        "first_identified_s": 0.5,
        "losses": 1,
        "reacquired": 1,
        "refind_times_s": [10.0 + spec.seed],
        "identity_switches": 0,
        "collisions": 0,
        "distance_m": 5.0 + spec.seed,
    }
    return "ok", metrics, {"wall_s": 0.1}


def _state() -> Path:
    return Path(os.environ[STATE])


def dies_once(spec: EpisodeSpec) -> Outcome:
    """kill -9 of its worker on the episode's first run."""
    mark = _state() / f"died-{spec.seed}"
    if not mark.exists():
        mark.write_text("")
        os.kill(os.getpid(), signal.SIGKILL)
    return _ok(spec)


def seed_2_always_dies(spec: EpisodeSpec) -> Outcome:
    """kill -9 of its worker whenever it runs seed 2."""
    if spec.seed == 2:
        os.kill(os.getpid(), signal.SIGKILL)
    return _ok(spec)


def seed_1_finishes(spec: EpisodeSpec) -> Outcome:
    """Seed 1 finishes at once; the others start a face worker (a child of the worker), say
    their process ids and run for ten minutes."""
    if spec.seed == 1:
        return _ok(spec)
    worker = FaceWorker()
    worker.wait_ready()
    (_state() / f"pids-{spec.seed}").write_text(f"{os.getpid()} {worker.pid}\n")
    time.sleep(600)
    return _ok(spec)


def quick(spec: EpisodeSpec) -> Outcome:
    """A tenth of a second."""
    time.sleep(0.1)
    return _ok(spec)


def _bench(episode: str, out: Path, *args: str) -> subprocess.Popen[str]:
    """``pfctl bench`` with ``episode`` (a stand-in above) for its episodes, in a new session
    (a Ctrl-C on the terminal goes to the whole group: :func:`_ctrl_c`)."""
    driver = (
        "import sys, pfctl.commands.bench as b, tests.bench.test_runner as t\n"
        "b.run_campaign_episode = getattr(t, sys.argv[1])\n"
        "sys.argv = ['pfctl', *sys.argv[2:]]\n"
        "from pfctl.cli import main\n"
        "main()\n"
    )
    state = out.parent / "state"
    state.mkdir(exist_ok=True)
    env = {**os.environ, STATE: str(state), "PYTHONPATH": str(ROOT)}
    command = [sys.executable, "-c", driver, episode, "bench", str(HOUSE_MISSION)]
    return subprocess.Popen(
        [*command, "--out", str(out), "--duration", "10", *args],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
        cwd=ROOT,
        start_new_session=True,
    )


def _finish(proc: subprocess.Popen[str]) -> tuple[int, str]:
    """Exit status and stderr; returns once every process holding stderr has ended (the
    workers and their face workers inherit it)."""
    try:
        _, err = proc.communicate(timeout=TIMEOUT)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        _, err = proc.communicate()
        pytest.fail(f"pfctl bench (or a child holding its stderr) ran past {TIMEOUT} s:\n{err}")
    return proc.returncode, err


def _records(out: Path) -> list[dict[str, Any]]:
    path = out / "results.jsonl"
    if not path.exists():
        return []
    return [json.loads(line) for line in path.read_text().splitlines() if line.strip()]


def test_a_killed_worker_s_episode_runs_again_on_a_new_one(tmp_path: Path) -> None:
    out = tmp_path / "c"
    code, err = _finish(_bench("dies_once", out, "--episodes", "2", "--workers", "2"))
    assert code == 0, err
    assert err.count("the worker process died (killed by SIGKILL); running the episode again") == 2
    records = _records(out)
    assert sorted(r["seed"] for r in records) == [1, 2]
    assert all(r["status"] == "ok" for r in records)
    assert "Traceback" not in err and "2/2 episodes" in (out / "summary.md").read_text()


def test_a_worker_that_dies_twice_is_an_error_and_the_others_go_on(tmp_path: Path) -> None:
    out = tmp_path / "c"
    code, err = _finish(_bench("seed_2_always_dies", out, "--episodes", "2", "--workers", "2"))
    assert code == 1, err
    by_seed = {r["seed"]: r for r in _records(out)}
    assert sorted(by_seed) == [1, 2]
    assert by_seed[1]["status"] == "ok"
    assert by_seed[2]["status"] == "error"
    assert "died (killed by SIGKILL) 2 times" in by_seed[2]["error"]
    [last] = [line for line in err.splitlines() if line.startswith("pfctl: error:")]
    assert last.startswith("pfctl: error: 1 of 2 episodes failed; their errors are in ")
    assert "Traceback" not in err


def _ctrl_c(proc: subprocess.Popen[str], name: str) -> None:
    """SIGINT as the terminal sends it (to the whole process group); SIGTERM as ``kill``,
    ``timeout`` or systemd send it (to the process)."""
    if name == "SIGINT":
        os.killpg(proc.pid, signal.SIGINT)
    else:
        proc.send_signal(signal.SIGTERM)


def _wait_for(what: str, ready: Any, proc: subprocess.Popen[str]) -> None:
    deadline = time.monotonic() + TIMEOUT
    while not ready():
        if proc.poll() is not None or time.monotonic() > deadline:
            os.killpg(proc.pid, signal.SIGKILL)
            pytest.fail(f"{what}: not in time (pfctl bench: {proc.poll()})\n{proc.communicate()}")
        time.sleep(0.05)


@pytest.mark.parametrize(
    ("signals", "spacing"),
    [
        (["SIGINT", "SIGINT"], 0.3),
        (["SIGTERM"], 0.0),
        (["SIGTERM", "SIGTERM"], 0.0),
    ],
    ids=["sigint-twice-0.3s", "sigterm", "sigterm-twice"],
)
def test_signals_keep_what_finished_and_leave_no_process(
    signals: list[str], spacing: float, tmp_path: Path
) -> None:
    out = tmp_path / "c"
    proc = _bench("seed_1_finishes", out, "--episodes", "3", "--workers", "3")
    state = tmp_path / "state"
    _wait_for("seed 1's record", lambda: len(_records(out)) == 1, proc)
    _wait_for("two face workers", lambda: len(list(state.glob("pids-*"))) == 2, proc)
    pids = [int(p) for f in state.glob("pids-*") for p in f.read_text().split()]
    for i, name in enumerate(signals):
        if i:
            time.sleep(spacing)
        _ctrl_c(proc, name)
    code, err = _finish(proc)
    first = signals[0]
    assert code == 128 + signal.Signals[first], err
    assert [line for line in err.splitlines() if line.startswith("pfctl:")] == [
        f"pfctl: interrupted ({first}); continue with: pfctl bench ... --out {out} --resume"
    ]
    assert "Traceback" not in err and "Error" not in err
    assert [r["seed"] for r in _records(out)] == [1]
    assert "1/3 episodes" in (out / "summary.md").read_text()
    assert processes_end(pids), [pid for pid in pids if not process_gone(pid)]


def test_ctrl_c_while_workers_start_prints_no_traceback(tmp_path: Path) -> None:
    out = tmp_path / "c"
    proc = _bench("quick", out, "--episodes", "12", "--workers", "2")
    _wait_for("two records", lambda: len(_records(out)) >= 2, proc)
    _ctrl_c(proc, "SIGINT")  # a new worker is being started for each record
    code, err = _finish(proc)
    assert code == 130, err
    assert "Traceback" not in err and "KeyboardInterrupt" not in err, err
