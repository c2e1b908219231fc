"""Median fit+predict time of each predictor on a 3 s history at 10 Hz and 40 Hz (one core)."""

from __future__ import annotations

import time

import numpy as np

from pfctl.core.prediction import MODELS, make_model, recency_weights


def main() -> None:
    rng = np.random.default_rng(0)
    for hz in (10, 40):
        t = np.arange(0.0, 3.0, 1.0 / hz)
        xy = np.stack([t, 0.2 * t**2], axis=1) + rng.normal(0, 0.02, (len(t), 2))
        w = recency_weights(t)
        tf = t[-1] + np.arange(1, 31) * 0.1
        for name in sorted(MODELS):
            runs = []
            for _ in range(50):
                t0 = time.perf_counter()
                make_model(name).fit(t, xy, w).predict(tf)
                runs.append(time.perf_counter() - t0)
            print(f"{hz:>3} Hz  {name:<9} median {1000 * np.median(runs):7.2f} ms per fit+predict")


if __name__ == "__main__":
    main()
