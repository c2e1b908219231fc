"""Run the ROS tests (``pytest -m ros``) while CPU-bound processes spin, as a busy CI machine.

``python benchmarks/ros_tests_loaded.py [--spinners 2] [--runs 1] [PYTEST ARGS...]`` starts the
spinners (``python -c 'while True: pass'``), runs the tests ``--runs`` times, prints each run's
outcome line and wall time, and always stops the spinners (also on Ctrl-C).
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import time


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--spinners", type=int, default=2, help="CPU-bound processes")
    parser.add_argument("--runs", type=int, default=1, help="runs of the tests")
    args, pytest_args = parser.parse_known_args()
    spinners = [
        subprocess.Popen([sys.executable, "-c", "while True: pass"]) for _ in range(args.spinners)
    ]
    failed = 0
    try:
        for run in range(1, args.runs + 1):
            started = time.monotonic()
            done = subprocess.run(
                [sys.executable, "-m", "pytest", "-m", "ros", "-q", "-rfE", *pytest_args],
                capture_output=True,
                text=True,
            )
            lines = [s for s in done.stdout.splitlines() if s.strip()]
            summary = [s for s in lines if s.startswith(("FAILED", "ERROR"))] + lines[-1:]
            failed += done.returncode != 0
            print(f"run {run}: exit {done.returncode}, {time.monotonic() - started:.0f} s")
            for line in summary:
                print(f"  {line}")
    finally:
        for spinner in spinners:
            spinner.kill()
            spinner.wait()
    print(f"{args.runs - failed} of {args.runs} runs passed with {args.spinners} spinners")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
