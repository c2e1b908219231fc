"""Soak: run ``pfctl follow`` for a long time and sample its memory every minute.

Starts ``python -m pfctl follow MISSION --backend sim --duration SECONDS`` (the interpreter that
runs this script, so the code on its path) and reads the resident set size (``VmRSS`` of
``/proc/PID/status``) of the command and of its children (the face worker) every ``--every``
seconds of wall time until it exits. Prints one line per sample and, at the end, the growth after
the first sample past ``--settle`` seconds (the first minute holds the loading, learning and the
follower's first allocations, which are not growth). Writes the samples to ``--csv``.

    python benchmarks/soak_follow.py --duration 3600 --csv out/soak.csv

Linux only (``/proc``). Exit status: the command's.
"""

from __future__ import annotations

import argparse
import csv
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]


def rss_mb(pid: int) -> float | None:
    """Resident set size of ``pid`` in MB, None once it is gone."""
    try:
        status = Path(f"/proc/{pid}/status").read_text()
    except OSError:
        return None
    for line in status.splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024
    return None


def children(pid: int) -> list[int]:
    """The direct children of ``pid``."""
    try:
        text = Path(f"/proc/{pid}/task/{pid}/children").read_text()
    except OSError:
        return []
    return [int(c) for c in text.split()]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--mission", default=str(REPO / "missions/house.yaml"))
    parser.add_argument("--duration", type=float, default=3600.0, help="simulated seconds")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--every", type=float, default=60.0, help="wall seconds between samples")
    parser.add_argument("--settle", type=float, default=60.0, help="wall seconds before growth")
    parser.add_argument("--csv", type=Path, default=None)
    parser.add_argument("--out", type=Path, default=None, help="pfctl follow's --out")
    args = parser.parse_args()
    out = args.out or Path(tempfile.mkdtemp(prefix="pfctl-soak-"))
    command = [sys.executable, "-m", "pfctl", "follow", args.mission, "--backend", "sim"]
    command += ["--seed", str(args.seed), "--duration", str(args.duration), "--out", str(out)]
    print(" ".join(command), flush=True)
    start = time.monotonic()
    process = subprocess.Popen(command, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL)
    samples: list[tuple[float, float, float]] = []
    try:
        while process.poll() is None:
            main_mb = rss_mb(process.pid)
            if main_mb is not None:
                kids = sum(rss_mb(c) or 0.0 for c in children(process.pid))
                elapsed = time.monotonic() - start
                samples.append((elapsed, main_mb, kids))
                print(f"{elapsed / 60:6.1f} min  pfctl {main_mb:7.1f} MB  children {kids:7.1f} MB")
                sys.stdout.flush()
            deadline = time.monotonic() + args.every
            while process.poll() is None and time.monotonic() < deadline:
                time.sleep(0.5)
    finally:
        if process.poll() is None:
            process.terminate()
        process.wait()
    if args.csv is not None:
        args.csv.parent.mkdir(parents=True, exist_ok=True)
        with args.csv.open("w", newline="") as f:
            writer = csv.writer(f)
            writer.writerow(["wall_s", "pfctl_rss_mb", "children_rss_mb"])
            writer.writerows((f"{t:.1f}", f"{a:.1f}", f"{b:.1f}") for t, a, b in samples)
    settled = [s for s in samples if s[0] >= args.settle]
    if len(settled) >= 2:
        first, last = settled[0], settled[-1]
        print(
            f"growth after {first[0] / 60:.1f} min: pfctl {last[1] - first[1]:+.1f} MB, "
            f"children {last[2] - first[2]:+.1f} MB over {(last[0] - first[0]) / 60:.1f} min; "
            f"peak pfctl {max(s[1] for s in samples):.1f} MB"
        )
    print(f"exit status {process.returncode}; outputs in {out}")
    return process.returncode if process.returncode >= 0 else 128 - process.returncode


if __name__ == "__main__":
    os.environ.setdefault("PYTHONUNBUFFERED", "1")
    sys.exit(main())
