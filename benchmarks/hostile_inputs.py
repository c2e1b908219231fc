"""How many bad inputs and interruptions does pfctl handle cleanly? (issue 21's must-show)

Runs every case of ``hostile_catalogue.py`` (bad YAML, missing and wrong-typed fields, loops,
damaged CSV/bag/npz/PNG files, unwritable outputs, out-of-range options, runaway-memory maps;
SIGINT once and twice, SIGTERM, SIGKILL of a bench worker during ``follow``, ``search``,
``sim run`` and ``bench``) as ``python -m pfctl ...`` with this interpreter, so it tests the
pfctl on PYTHONPATH. Each case runs in its own empty folder, in its own process group, under an
address-space limit (RLIMIT_AS) and a timeout, and is checked against what the README promises:

* bad input: exit 2, stderr exactly one line ``pfctl: error: ...`` naming the file, option or
  field, no traceback, no partial output (the case's folder unchanged);
* interruption: exit 130 (SIGINT) or 143 (SIGTERM) with one line saying so (a ``pfctl:`` line or
  one naming the interruption; ``bench`` keeps its log lines), the outputs measured so far written
  and parseable;
* always: finished within the timeout and memory limit, no process of the command left behind.

Interruption cases wait for the run to start by reading the progress bar (forced on with
FORCE_COLOR) or polling an output file, never by fixed sleeps.

Usage::

    PYTHONPATH=. python benchmarks/hostile_inputs.py [--jobs 2] [--only PATTERN] [--json FILE]

Prints a table (id, command, expected, got, ok/FAIL and why) and ``handled cleanly: N of M``;
exit status 0 when every case was handled cleanly, 1 otherwise.
"""

from __future__ import annotations

import argparse
import contextlib
import csv
import fnmatch
import io
import json
import os
import re
import resource
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Callable, Iterable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))

from hostile_catalogue import BENCH_ARGS, ROOT, Case, catalogue

ANSI = re.compile(r"\x1b\[[0-9;?]*[ -/]*[@-~]|\x1b\][^\x07]*\x07|\x1b[()][A-Z0-9]")
CURSOR = re.compile(r"\x1b\[[0-9;]*[A-HJK]")  # a redraw: what follows starts a new line
PROGRESS = re.compile(r"(\d+(?:\.\d+)?)/(\d+)\s")
BAR_CHARS = ("━", "╸", "╺")


@dataclass
class Shared:
    """Fixtures made once per run: a learned target, a recorded bag, a finished campaign."""

    root: Path
    target: Path | None = None
    bag: Path | None = None
    campaign: Path | None = None
    problems: dict[str, str] = field(default_factory=dict)


@dataclass
class Outcome:
    """What one case did and whether that was clean."""

    id: str
    command: str
    expected: str
    got: str = ""
    ok: bool = False
    reason: str = ""
    skipped: str = ""
    exit: int | None = None
    seconds: float = 0.0
    cpu_seconds: float = 0.0
    max_rss_mb: float = 0.0
    stderr: str = ""
    stdout_tail: str = ""


@dataclass
class Run:
    """The raw result of running a case's process."""

    exit: int | None
    stdout: str
    stderr: str
    seconds: float
    cpu_seconds: float
    max_rss_mb: float
    timed_out: bool
    leftover: list[str]
    signalled: list[str]
    note: str = ""


def pfctl_argv(args: Iterable[str]) -> list[str]:
    """``python -m pfctl ARGS`` with this interpreter."""
    return [sys.executable, "-m", "pfctl", *args]


def child_env(force_terminal: bool) -> dict[str, str]:
    """The environment of a case: no live ROS master reachable, UTF-8, and the progress bar
    forced on for interruption cases (it is how they see the run start)."""
    env = dict(os.environ)
    env["ROS_MASTER_URI"] = "http://127.0.0.1:9/"
    env["PYTHONIOENCODING"] = "utf-8"
    env["COLUMNS"] = "120"
    env.pop("FORCE_COLOR", None)
    if force_terminal:
        env["FORCE_COLOR"] = "1"
    return env


def _limit(memory_mb: int) -> Callable[[], None]:
    """In the child before exec: the memory limit, and Ctrl-C as a terminal gives it (a script
    started in the background, ``nohup … &``, hands its children SIGINT ignored, which pfctl
    rightly keeps ignored: the interruption cases would then measure the shell, not pfctl)."""

    def apply() -> None:
        limit = memory_mb * 1024 * 1024
        resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
        signal.signal(signal.SIGINT, signal.SIG_DFL)

    return apply


# ---------------------------------------------------------------- processes


def _proc_stat(pid: int) -> tuple[int, int] | None:
    """(parent pid, process group) of ``pid``, or None when it is gone."""
    try:
        text = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return None
    fields = text[text.rfind(")") + 2 :].split()
    return int(fields[1]), int(fields[2])


def _cmdline(pid: int) -> str:
    try:
        return (
            Path(f"/proc/{pid}/cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace")
        )
    except OSError:
        return ""


def _all_pids() -> list[int]:
    return [int(p) for p in os.listdir("/proc") if p.isdigit()]


def group_members(pgid: int) -> list[int]:
    """Live processes of process group ``pgid``."""
    out = []
    for pid in _all_pids():
        stat = _proc_stat(pid)
        if stat is not None and stat[1] == pgid:
            out.append(pid)
    return out


def bench_workers(parent: int) -> list[int]:
    """The spawned worker processes of ``parent`` (not its resource tracker)."""
    out = []
    for pid in _all_pids():
        stat = _proc_stat(pid)
        if stat is None or stat[0] != parent:
            continue
        cmd = _cmdline(pid)
        if "spawn_main" in cmd or ("multiprocessing" in cmd and "resource_tracker" not in cmd):
            out.append(pid)
    return out


def _reader(stream: Any, sink: bytearray) -> threading.Thread:
    def pump() -> None:
        for chunk in iter(lambda: stream.read1(65536), b""):
            sink.extend(chunk)

    thread = threading.Thread(target=pump, daemon=True)
    thread.start()
    return thread


def _ready(case: Case, ws: Path, stderr: bytearray, pid: int) -> bool:
    """Has the run of an interruption case started (progress shown, or output lines there)?"""
    spec = case.interrupt
    assert spec is not None
    if spec.lines_in is not None:
        path = ws / spec.lines_in
        try:
            lines = path.read_bytes().count(b"\n")
        except OSError:
            return False
        if lines < spec.progress and not (spec.progress == 0 and path.exists()):
            return False
        if any(target == "worker" for _, _, target in spec.signals):
            return bool(bench_workers(pid))
        return True
    text = ANSI.sub("", stderr[-4000:].decode("utf-8", "replace"))
    done = [float(m.group(1)) for m in PROGRESS.finditer(text)]
    return bool(done) and max(done) >= spec.progress


def _send(pid: int, name: str, target: str) -> str:
    sig = getattr(signal, name)
    try:
        if target == "group":
            os.killpg(pid, sig)
        elif target == "main":
            os.kill(pid, sig)
        else:
            workers = bench_workers(pid)
            if not workers:
                return f"{name} to a worker: none found"
            os.kill(workers[0], sig)
            return f"{name} to worker {workers[0]}"
    except ProcessLookupError:
        return f"{name} to {target}: already gone"
    return f"{name} to {target}"


def run_process(case: Case, argv: list[str], ws: Path) -> Run:
    """Run one case's command in ``ws``; send its signals once it has started."""
    start = time.monotonic()
    proc = subprocess.Popen(
        argv,
        cwd=ws,
        stdin=subprocess.DEVNULL,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        env=child_env(case.interrupt is not None),
        start_new_session=True,
        preexec_fn=_limit(case.memory_mb),
    )
    out, err = bytearray(), bytearray()
    readers = [_reader(proc.stdout, out), _reader(proc.stderr, err)]
    pending = list(case.interrupt.signals) if case.interrupt else []
    started_at: float | None = None
    signalled: list[str] = []
    timed_out = False
    status = rusage = None
    while True:
        pid, status, rusage = os.wait4(proc.pid, os.WNOHANG)
        if pid:
            break
        now = time.monotonic()
        if now - start > case.timeout:
            timed_out = True
            os.killpg(proc.pid, signal.SIGKILL)
            _, status, rusage = os.wait4(proc.pid, 0)
            break
        if pending and started_at is None and _ready(case, ws, err, proc.pid):
            started_at = now
        while pending and started_at is not None and now - started_at >= pending[0][0]:
            _, name, target = pending.pop(0)
            signalled.append(_send(proc.pid, name, target))
        time.sleep(0.05)
    seconds = time.monotonic() - start
    proc.returncode = os.waitstatus_to_exitcode(status)
    leftover = []
    deadline = time.monotonic() + 3.0
    while time.monotonic() < deadline:  # children get a moment to exit after the main process
        leftover = group_members(proc.pid)
        if not leftover:
            break
        time.sleep(0.1)
    described = [f"{p} {_cmdline(p)[:80]}" for p in leftover]
    if leftover:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(proc.pid, signal.SIGKILL)
    for thread in readers:
        thread.join(timeout=5)
    return Run(
        exit=proc.returncode,
        stdout=out.decode("utf-8", "replace"),
        stderr=err.decode("utf-8", "replace"),
        seconds=seconds,
        cpu_seconds=rusage.ru_utime + rusage.ru_stime if rusage else 0.0,
        max_rss_mb=rusage.ru_maxrss / 1024 if rusage else 0.0,
        timed_out=timed_out,
        leftover=described,
        signalled=signalled,
        note=""
        if started_at is not None or not pending
        else f"run never started: {len(pending)} signal(s) not sent",
    )


# ---------------------------------------------------------------- fixtures and checks


def write_files(case: Case, ws: Path, shared: Shared) -> None:
    """The case's input files in its folder."""
    import yaml

    for name, content in case.files.items():
        path = ws / name
        path.parent.mkdir(parents=True, exist_ok=True)
        if callable(content):
            data = content(shared)
        elif isinstance(content, dict):
            data = yaml.safe_dump(content, sort_keys=False).encode()
        elif isinstance(content, str):
            data = content.encode()
        else:
            data = content
        path.write_bytes(data)


def snapshot(ws: Path) -> set[tuple[str, int, int]]:
    """Every file and folder under ``ws`` with size and mtime (folders: size and mtime 0)."""
    out = set()
    for dirpath, dirnames, filenames in os.walk(ws):
        for d in dirnames:
            out.add((os.path.relpath(os.path.join(dirpath, d), ws) + "/", 0, 0))
        for f in filenames:
            path = os.path.join(dirpath, f)
            st = os.lstat(path)
            out.add((os.path.relpath(path, ws), st.st_size, st.st_mtime_ns))
    return out


def stderr_lines(text: str) -> list[str]:
    """The lines a user reads on stderr: ANSI codes and progress-bar redraws removed."""
    plain = ANSI.sub("", CURSOR.sub("\n", text))
    lines = [ln.strip() for ln in re.split(r"[\r\n]", plain)]
    return [ln for ln in lines if ln and not any(c in ln for c in BAR_CHARS)]


def interruption_lines(lines: list[str]) -> list[str]:
    """The lines that tell the user the run was interrupted: ``pfctl: ...`` lines and lines
    naming the interruption, not a traceback's ``KeyboardInterrupt``. (A command whose normal
    output is a log on stderr, like ``bench``, keeps its log; the one line is the
    interruption's.)"""
    words = ("interrupt", "terminated", "sigterm", "sigint", "ctrl-c")
    return [
        ln
        for ln in lines
        if ln.startswith("pfctl:")
        or ("KeyboardInterrupt" not in ln and any(w in ln.lower() for w in words))
    ]


def parses(path: Path) -> str:
    """Why ``path`` is not a complete output ('' when it is)."""
    if not path.is_file():
        return f"{path.name} missing"
    data = path.read_bytes()
    try:
        if path.suffix == ".json":
            json.loads(data)
        elif path.suffix == ".jsonl":
            lines = data.decode().splitlines()
            if not lines:
                return f"{path.name} empty"
            for line in lines:
                json.loads(line)
        elif path.suffix == ".csv":
            rows = list(csv.reader(io.StringIO(data.decode())))
            if not rows:
                return f"{path.name} empty"
        elif path.suffix == ".png" and not (
            data.startswith(b"\x89PNG\r\n\x1a\n") and b"IEND" in data[-16:]
        ):
            return f"{path.name} not a complete PNG"
    except (ValueError, UnicodeDecodeError) as err:
        return f"{path.name} does not parse: {err}"
    return ""


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def names(line: str, name: str, argv: tuple[str, ...]) -> bool:
    """Does ``line`` name ``name``? An option (``--out``) is also named by its value when that
    is not a number (``--out f/o`` is named by ``f/o``)."""
    if name in line:
        return True
    if not name.startswith("--"):
        return False
    values = [argv[i + 1] for i in range(len(argv) - 1) if argv[i] == name]
    return any(v in line for v in values if not _is_number(v) and "{" not in v)


def _short(text: str, n: int = 90) -> str:
    text = text.replace("\n", " | ")
    return text if len(text) <= n else text[: n - 1] + "…"


def judge(
    case: Case, run: Run, ws: Path, before: set[tuple[str, int, int]]
) -> tuple[bool, str, str]:
    """(clean?, what happened, why not clean)."""
    lines = stderr_lines(run.stderr)
    got = f"exit {run.exit}, {len(lines)} line{'s' if len(lines) != 1 else ''}"
    if lines:
        got += f": {lines[0] if len(lines) == 1 else lines[-1]}"
    problems: list[str] = []
    if run.timed_out:
        problems.append(f"timeout after {case.timeout:.0f} s")
    if "MemoryError" in run.stderr:
        problems.append(f"memory limit {case.memory_mb} MB hit")
    if run.exit is not None and run.exit < 0 and not run.timed_out:
        problems.append(f"died of {signal.Signals(-run.exit).name}")
    if "Traceback" in run.stderr or "Traceback" in run.stdout:
        problems.append("traceback")
    if run.leftover:
        problems.append(f"{len(run.leftover)} process(es) left: {run.leftover[0]}")
    if run.note:
        problems.append(run.note)
    kind = case.expect.kind
    if kind in ("error", "error_or_run"):
        ran_ok = kind == "error_or_run" and run.exit == 0
        if not ran_ok:
            if run.exit != 2:
                problems.append(f"exit {run.exit}, not 2")
            if len(lines) != 1:
                problems.append(f"{len(lines)} stderr lines, not 1")
            elif not lines[0].startswith("pfctl: error:"):
                problems.append("not a 'pfctl: error:' line")
            else:
                missing = [n for n in case.expect.names if not names(lines[0], n, case.argv)]
                if missing:
                    problems.append(f"does not name {', '.join(missing)}")
                said = [w for w in case.expect.avoid if w.lower() in lines[0].lower()]
                if said:
                    problems.append(f"says {', '.join(said)}")
            after = snapshot(ws)
            if after != before:
                changed = sorted({p for p, *_ in after ^ before})
                problems.append(f"left/changed files: {', '.join(changed[:3])}")
    elif kind == "interrupt":
        if run.exit != case.expect.code:
            problems.append(f"exit {run.exit}, not {case.expect.code}")
        said = interruption_lines(lines)
        if len(said) != 1:
            problems.append(f"{len(said)} lines say it was interrupted, not 1")
        for name in case.expect.outputs:
            why = parses(ws / name)
            if why:
                problems.append(why)
    elif kind == "warn":
        if run.exit != 0:
            problems.append(f"exit {run.exit}, not 0")
        said = [ln for ln in lines if not ln.startswith("wrote ")]
        if not any(all(n in ln for n in case.expect.names) for ln in said):
            problems.append(f"no line says what happened to {', '.join(case.expect.names)}")
    elif kind == "survive":
        if run.exit != 0:
            problems.append(f"exit {run.exit}, not 0")
        for name in case.expect.outputs:
            why = parses(ws / name)
            if why:
                problems.append(why)
        results = ws / "o" / "results.jsonl"
        if results.is_file():
            n = len([ln for ln in results.read_text().splitlines() if ln.strip()])
            if n < case.expect.records:
                problems.append(f"{n} of {case.expect.records} episodes in results.jsonl")
    if run.signalled:
        got += f" [{'; '.join(run.signalled)}]"
    return not problems, got, "; ".join(problems)


def run_case(case: Case, work: Path, shared: Shared) -> Outcome:
    """Make the case's folder and files, run it, judge it."""
    outcome = Outcome(case.id, case.command or "pfctl", case.expect.describe())
    missing = [n for n in case.needs if getattr(shared, n) is None]
    if missing:
        outcome.reason = "; ".join(
            f"fixture {n}: {shared.problems.get(n, 'not made')}" for n in missing
        )
        return outcome
    ws = work / case.id
    ws.mkdir(parents=True)
    write_files(case, ws, shared)
    if case.setup is not None:
        skip = case.setup(ws)
        if skip:
            outcome.skipped = skip
            outcome.ok = True
            outcome.got = "skipped"
            return outcome
    before = snapshot(ws)
    values = {
        "ws": str(ws),
        "repo": str(ROOT),
        "target": str(shared.target),
        "bag": str(shared.bag),
        "campaign": str(shared.campaign),
    }
    argv = pfctl_argv(a.format(**values) for a in case.argv)
    run = run_process(case, argv, ws)
    outcome.ok, outcome.got, outcome.reason = judge(case, run, ws, before)
    outcome.exit = run.exit
    outcome.seconds = round(run.seconds, 1)
    outcome.cpu_seconds = round(run.cpu_seconds, 1)
    outcome.max_rss_mb = round(run.max_rss_mb, 1)
    outcome.stderr = run.stderr[-3000:]
    outcome.stdout_tail = run.stdout[-500:]
    return outcome


def make_shared(root: Path, needs: set[str]) -> Shared:
    """The fixtures the selected cases need, made in parallel."""
    shared = Shared(root)
    root.mkdir(parents=True, exist_ok=True)
    m = str(ROOT / "missions" / "house.yaml")
    jobs = {
        "target": (
            ["learn-target", m, "--out", str(root / "target.npz"), "--seconds", "2"],
            root / "target.npz",
        ),
        "bag": (
            [
                "sim",
                "run",
                m,
                "--duration",
                "3",
                "--no-camera",
                "--record",
                str(root / "rec"),
                "--png",
                str(root / "rec.png"),
            ],
            root / "rec" / "episode.bag",
        ),
        "campaign": (["bench", m, *BENCH_ARGS, "--out", str(root / "campaign")], root / "campaign"),
    }

    def make(name: str) -> None:
        argv, result = jobs[name]
        done = subprocess.run(
            pfctl_argv(argv),
            cwd=root,
            capture_output=True,
            text=True,
            env=child_env(False),
            timeout=600,
        )
        if done.returncode == 0 and result.exists():
            setattr(shared, name, result)
        else:
            shared.problems[name] = f"exit {done.returncode}: {_short(done.stderr.strip()[-300:])}"

    with ThreadPoolExecutor(len(jobs)) as pool:
        list(pool.map(make, sorted(needs & set(jobs))))
    return shared


# ---------------------------------------------------------------- table


def table(outcomes: list[Outcome]) -> str:
    """The per-case table and the final count line."""
    rows = [("id", "command", "expected", "got", "result")]
    for o in outcomes:
        result = (
            "ok"
            if o.ok and not o.skipped
            else ("skip: " + o.skipped if o.skipped else "FAIL: " + o.reason)
        )
        rows.append((o.id, o.command, o.expected, _short(o.got), result))
    widths = [max(len(r[i]) for r in rows) for i in range(4)]
    lines = ["  ".join(r[i].ljust(widths[i]) for i in range(4)) + "  " + r[4] for r in rows]
    counted = [o for o in outcomes if not o.skipped]
    clean = sum(o.ok for o in counted)
    skipped = len(outcomes) - len(counted)
    lines.append("")
    lines.append(
        f"handled cleanly: {clean} of {len(counted)}" + (f" ({skipped} skipped)" if skipped else "")
    )
    return "\n".join(lines)


def select(cases: list[Case], patterns: list[str] | None) -> list[Case]:
    """Cases whose id or command matches any glob of ``patterns`` (all when none)."""
    if not patterns:
        return cases
    return [
        c
        for c in cases
        if any(
            fnmatch.fnmatch(c.id, p) or fnmatch.fnmatch(c.command, p) or p in c.id for p in patterns
        )
    ]


def run_all(
    cases: list[Case], jobs: int, signal_jobs: int, work: Path, progress: Callable[[str], None]
) -> list[Outcome]:
    """Fixtures, then bad-input cases ``jobs`` at a time, then interruptions ``signal_jobs`` at
    a time; outcomes in catalogue order."""
    needs = {n for c in cases for n in c.needs}
    t0 = time.monotonic()
    shared = make_shared(work / "_shared", needs) if needs else Shared(work / "_shared")
    if needs:
        progress(
            f"fixtures {', '.join(sorted(needs))} in {time.monotonic() - t0:.0f} s"
            + (f"; failed: {shared.problems}" if shared.problems else "")
        )
    done: dict[str, Outcome] = {}
    lock = threading.Lock()

    def one(case: Case) -> None:
        try:
            outcome = run_case(case, work, shared)
        except Exception as err:  # a bug of this script, not of pfctl: report it as the case's
            outcome = Outcome(
                case.id, case.command, case.expect.describe(), reason=f"runner: {err!r}"
            )
        with lock:
            done[case.id] = outcome
            mark = "ok" if outcome.ok else "FAIL"
            elapsed = time.monotonic() - t0
            progress(
                f"[{len(done)}/{len(cases)}] {elapsed:5.0f} s  {case.id}: {mark} {outcome.reason}"
            )

    plain = [c for c in cases if c.interrupt is None]
    signalled = [c for c in cases if c.interrupt is not None]
    with ThreadPoolExecutor(max(1, jobs)) as pool:
        list(pool.map(one, plain))
    with ThreadPoolExecutor(max(1, signal_jobs)) as pool:
        list(pool.map(one, signalled))
    return [done[c.id] for c in cases]


def _unprotect(path: Path) -> None:
    for dirpath, dirnames, _ in os.walk(path):
        for d in dirnames:
            with contextlib.suppress(OSError):
                os.chmod(os.path.join(dirpath, d), 0o755)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--jobs", type=int, default=2, help="bad-input cases at a time (default 2)")
    parser.add_argument(
        "--signal-jobs",
        type=int,
        default=None,
        help="interruption cases at a time (default min(jobs, 2))",
    )
    parser.add_argument(
        "--only", action="append", help="run cases whose id or command matches (glob; repeatable)"
    )
    parser.add_argument("--json", type=Path, help="also write every outcome as JSON here")
    parser.add_argument(
        "--work", type=Path, help="keep the cases' folders here (default: a temp dir, removed)"
    )
    parser.add_argument("--list", action="store_true", help="list the cases and exit")
    args = parser.parse_args(argv)
    cases = select(catalogue(), args.only)
    if args.list:
        for c in cases:
            print(f"{c.id:34} {c.command or 'pfctl':24} {c.expect.describe()}")
        print(f"{len(cases)} cases")
        return 0
    if not cases:
        print("no case matches --only", file=sys.stderr)
        return 2
    signal_jobs = args.signal_jobs or min(args.jobs, 2)
    work = args.work or Path(tempfile.mkdtemp(prefix="pfctl-hostile-"))
    if args.work and work.exists():
        _unprotect(work)
        shutil.rmtree(work)
    work.mkdir(parents=True, exist_ok=True)
    t0 = time.monotonic()
    try:
        outcomes = run_all(
            cases, args.jobs, signal_jobs, work, lambda s: print(s, file=sys.stderr, flush=True)
        )
    finally:
        if args.work is None:
            _unprotect(work)
            shutil.rmtree(work, ignore_errors=True)
    print(table(outcomes))
    elapsed = time.monotonic() - t0
    cpu = sum(o.cpu_seconds for o in outcomes)
    print(
        f"({elapsed:.0f} s wall, {cpu:.0f} s CPU in the cases, --jobs {args.jobs}, "
        f"interruptions {signal_jobs} at a time)"
    )
    if args.json:
        args.json.write_text(
            json.dumps([asdict(o) for o in outcomes], indent=2) + "\n", encoding="utf-8"
        )
    return 0 if all(o.ok for o in outcomes) else 1


if __name__ == "__main__":
    sys.exit(main())
