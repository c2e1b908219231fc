"""Speed of the trajectory predictors (§II-E) on one CPU core: fit + predict on a 3 s history.

Run ``python benchmarks/bench_prediction.py [--runs N]``. For each sampling rate (10 Hz, the leg
tracker; 40 Hz, the laser) it builds a 3 s walk (1.1 m/s on a gentle curve, 2 cm of noise),
and times, after 5 warm-up calls, ``N`` calls of ``make_model(name).fit(t, xy).predict(t_future)``
with 30 future times (3 s at 0.1 s), the cost the robot pays when it loses the target. It prints
the median and minimum milliseconds per call of each model. Goal: svr under 5 ms at 10 Hz.
It prints figures; it asserts nothing about time.
"""

from __future__ import annotations

import os

# One core, one thread: set before numpy is imported.
for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"
if hasattr(os, "sched_setaffinity"):
    os.sched_setaffinity(0, {0})

import argparse  # noqa: E402
import platform  # noqa: E402
import statistics  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402
import sklearn  # noqa: E402

from pfctl.core.prediction.models import MODELS, make_model  # noqa: E402

HISTORY_S = 3.0
RATES_HZ = (10.0, 40.0)
FUTURE = np.arange(1, 31) * 0.1  # 3 s ahead at 0.1 s


def walk(hz: float, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """A 3 s walk at 1.1 m/s turning at 0.2 rad/s, sampled at ``hz`` with 2 cm noise."""
    t = np.arange(0.0, HISTORY_S, 1.0 / hz)
    heading = 0.2 * t
    xy = np.cumsum(1.1 / hz * np.stack([np.cos(heading), np.sin(heading)], axis=1), axis=0)
    return t, xy + np.random.default_rng(seed).normal(0.0, 0.02, xy.shape)


def time_model(name: str, t: np.ndarray, xy: np.ndarray, runs: int) -> list[float]:
    """Seconds per fit + predict, ``runs`` times after 5 warm-up calls."""
    tf = t[-1] + FUTURE
    for _ in range(5):
        make_model(name).fit(t, xy).predict(tf)
    out = []
    for _ in range(runs):
        start = time.perf_counter()
        make_model(name).fit(t, xy).predict(tf)
        out.append(time.perf_counter() - start)
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=200, help="timed calls per model and rate")
    args = parser.parse_args()
    cpu = platform.processor() or platform.machine()
    print(
        f"{platform.platform()} | {cpu} | Python {platform.python_version()} | "
        f"numpy {np.__version__} | scikit-learn {sklearn.__version__} | one core"
    )
    print(f"fit + predict, {HISTORY_S:g} s history, {len(FUTURE)} future points, {args.runs} runs")
    print(f"{'rate':>6}  {'samples':>7}  {'model':<9} {'median ms':>10} {'min ms':>8}")
    for hz in RATES_HZ:
        t, xy = walk(hz)
        for name in MODELS:
            runs = time_model(name, t, xy, args.runs)
            print(
                f"{hz:>4g} Hz  {len(t):>7}  {name:<9} {1000 * statistics.median(runs):>10.2f} "
                f"{1000 * min(runs):>8.2f}"
            )


if __name__ == "__main__":
    main()
