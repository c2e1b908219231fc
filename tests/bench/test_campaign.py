"""pfctl bench end to end: a 4-episode campaign with 2 worker processes, interrupted with
Ctrl-C pressed twice (to the whole process group, as a terminal sends it) and resumed, and the
same campaign as Ray tasks (Ray started locally): the same seeds give the same per-episode
metrics, and the resumed campaign ran only what had not finished. Short episodes (15 s
simulated) keep it short."""

from __future__ import annotations

import importlib.util
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import pytest

pytestmark = [pytest.mark.sim, pytest.mark.slow]

HOUSE = Path(__file__).resolve().parents[2] / "missions" / "house.yaml"
ARGS = ["--episodes", "4", "--seed", "3", "--duration", "15", "--workers", "2"]
#: Wall seconds any one command may take (4 short episodes, generously, for a busy machine).
TIMEOUT = 900


def _default_sigint() -> None:
    # a child of a shell without job control may inherit SIGINT ignored: Python would then
    # never raise KeyboardInterrupt
    signal.signal(signal.SIGINT, signal.SIG_DFL)
    os.setsid()  # its own process group, which a Ctrl-C reaches as a whole


def _bench(out: Path, *extra: str) -> subprocess.Popen[str]:
    # the seed varies the target's speed and route points too (scenario.randomize), read from a
    # file by --vary: the episodes differ by more than sensor noise
    randomize = out.parent / "randomized.yaml"
    randomize.write_text("{speed_scale: [0.6, 1.4], route_jitter: 0.5}\n")
    vary = ["--vary", f"scenario.randomize=@{randomize}"]
    return subprocess.Popen(
        [
            sys.executable,
            "-m",
            "pfctl",
            "bench",
            str(HOUSE),
            *ARGS,
            *vary,
            "--out",
            str(out),
            *extra,
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        preexec_fn=_default_sigint,  # the test process has no other threads
    )


def _finish(proc: subprocess.Popen[str]) -> tuple[int, str]:
    try:
        output, _ = proc.communicate(timeout=TIMEOUT)
    except subprocess.TimeoutExpired:
        proc.kill()
        output, _ = proc.communicate()
        pytest.fail(f"pfctl bench took more than {TIMEOUT} s:\n{output}")
    return proc.returncode, output


def _records(out: Path) -> list[dict[str, Any]]:
    path = out / "results.jsonl"
    if not path.exists():
        return []
    return [json.loads(line) for line in path.read_text().splitlines() if line.strip()]


def _by_seed(records: list[dict[str, Any]]) -> dict[int, dict[str, Any]]:
    return {r["seed"]: r for r in records}


@pytest.fixture(scope="module")
def interrupted_and_resumed(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    """The campaign in worker processes: Ctrl-C once two episodes are recorded, then --resume."""
    out = tmp_path_factory.mktemp("bench") / "pool"
    started = time.monotonic()
    proc = _bench(out)
    while len(_records(out)) < 2 and proc.poll() is None:
        if time.monotonic() - started > TIMEOUT:
            proc.kill()
            pytest.fail("no two episodes recorded in time")
        time.sleep(0.2)
    os.killpg(proc.pid, signal.SIGINT)  # Ctrl-C twice, 0.3 s apart
    time.sleep(0.3)
    os.killpg(proc.pid, signal.SIGINT)
    code, first_output = _finish(proc)  # the output ends when the workers and their children do
    before = _records(out)
    summary_after_interrupt = (out / "summary.md").read_text() if code == 130 else ""
    resumed = _bench(out, "--resume")
    resume_code, resume_output = _finish(resumed)
    return {
        "code": code,
        "output": first_output,
        "before": before,
        "summary_after_interrupt": summary_after_interrupt,
        "resume_code": resume_code,
        "resume_output": resume_output,
        "after": _records(out),
        "out": out,
        "wall_s": time.monotonic() - started,
    }


def test_an_interrupted_campaign_resumes_without_rerunning_finished_episodes(
    interrupted_and_resumed: dict[str, Any],
) -> None:
    run = interrupted_and_resumed
    assert run["code"] == 130, run["output"]
    assert "Traceback" not in run["output"]
    assert [line for line in run["output"].splitlines() if line.startswith("pfctl:")] == [
        f"pfctl: interrupted (SIGINT); continue with: pfctl bench ... --out {run['out']} --resume"
    ]
    before, after = run["before"], run["after"]
    assert 2 <= len(before) < 4, run["output"]
    assert f"{len(before)}/4 episodes" in run["summary_after_interrupt"]
    assert run["resume_code"] == 0, run["resume_output"]
    assert f"{len(before)} done, {4 - len(before)} to run" in " ".join(run["resume_output"].split())
    # the finished episodes were kept as they were, and only the others ran
    assert after[: len(before)] == before
    assert sorted(r["seed"] for r in after) == [3, 4, 5, 6]
    assert len({r["run"]["id"] for r in after}) == 4
    assert all(r["status"] == "ok" for r in after)
    md = (run["out"] / "summary.md").read_text()
    assert "4/4 episodes" in md and "| scenario.randomize=randomized | 4 |" in md
    assert (run["out"] / "boxplots.png").read_bytes().startswith(b"\x89PNG")


def test_ray_gives_the_same_episodes_as_worker_processes(
    interrupted_and_resumed: dict[str, Any], tmp_path: Path
) -> None:
    if importlib.util.find_spec("ray") is None and not os.environ.get("CI"):
        pytest.skip("Ray is not installed (pip install -e '.[ray]'); CI installs it")
    out = tmp_path / "ray"
    code, output = _finish(_bench(out, "--ray", "local"))
    assert code == 0, output
    ray = _by_seed(_records(out))
    pool = _by_seed(interrupted_and_resumed["after"])
    assert sorted(ray) == sorted(pool) == [3, 4, 5, 6]
    for seed in pool:
        assert ray[seed]["status"] == pool[seed]["status"] == "ok"
        assert ray[seed]["metrics"] == pool[seed]["metrics"], f"seed {seed}"
        assert ray[seed]["run"]["id"] != pool[seed]["run"]["id"]
    # episodes with something to compare: the target was identified and followed
    assert all(r["metrics"]["first_identified_s"] is not None for r in pool.values())
    assert len({json.dumps(r["metrics"], sort_keys=True) for r in pool.values()}) == 4
    assert len({r["metrics"]["following_rate"] for r in pool.values()}) > 1


def test_a_campaign_runs_generated_homes_and_summarises_them_per_variant(tmp_path: Path) -> None:
    """``--homes 2``: two generated homes written into OUT/homes and one episode each under
    each variant; the summary has one row per variant over both homes (issue 22, item 1)."""
    out = tmp_path / "homes-bench"
    tree = HOUSE.parent / "trees" / "last_seen.yaml"
    done = subprocess.run(
        [sys.executable, "-m", "pfctl", "bench", "--homes", "2", "--home-seed", "3",
         "--duration", "8", "--workers", "2", "--vary",
         f"behavior.tree=@{HOUSE.parent / 'trees' / 'paper.yaml'},@{tree}", "--out", str(out)],
        capture_output=True,
        text=True,
        timeout=TIMEOUT,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert sorted(p.name for p in (out / "homes").iterdir()) == ["home-0003.yaml", "home-0004.yaml"]
    records = _records(out)
    assert sorted((Path(r["mission_file"]).name, r["variant"]) for r in records) == [
        ("home-0003.yaml", "behavior.tree=last_seen"),
        ("home-0003.yaml", "behavior.tree=paper"),
        ("home-0004.yaml", "behavior.tree=last_seen"),
        ("home-0004.yaml", "behavior.tree=paper"),
    ]
    rows = [line.split(",") for line in (out / "summary.csv").read_text().splitlines()[1:]]
    following = [(r[0], r[1], r[8]) for r in rows if r[2] == "following_rate"]
    assert following == [
        ("homes", "behavior.tree=paper", "2"),
        ("homes", "behavior.tree=last_seen", "2"),
    ]
