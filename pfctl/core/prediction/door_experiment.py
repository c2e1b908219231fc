"""The paper's door experiment, synthetic: predict a person who turned out of sight (§III-B).

In the paper's run the target walks from the kitchen through a door into the office and is lost
as they pass the door; the SVR's prediction is compared with a cubic polynomial's and the
polynomial diverges on turns. Here the same situation is generated, seeded, many times:

* A wall along the y axis (x = 0) with a door at the origin. A person starts 3–5 m before the
  wall, up to 1.5 m to the side, and walks to the door — people aim at a door from where they
  are and straighten up to pass it, so the last seconds before the door bend a little.
* Through the door they go on 0.3–1.0 m, then turn **left** (+y), go **straight**, or turn
  **right** (−y) with a turning radius of 0.8–1.5 m, and walk on.
* Walking: speed drawn in 0.6–1.4 m/s, varying smoothly by a few percent; heading steered toward
  the next way-point with a turn rate limited by the turning radius (a unicycle), so turns are
  smooth; sampled at 10 Hz with 2 cm of Gaussian noise on the observed positions (a leg tracker).
* The person is *lost* when they cross the door line. Every model is fitted on the last
  ``history_s`` seconds of the noisy observations up to the loss and asked for the positions 1, 2
  and 3 s later; the error is the distance to the true (noise-free) position then.

:func:`run_door_experiment` returns the errors of every model for every walk, and one example walk
per case with every model's predicted path, for the figure.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from pfctl.core.prediction.models import MODELS, make_model

__all__ = [
    "CASES",
    "DoorExperiment",
    "Walk",
    "run_door_experiment",
    "simulate_walk",
]

FloatArray = NDArray[np.float64]

CASES = ("left", "straight", "right")
DOOR_WIDTH = 0.9
#: Sampling period of the observations (a 10 Hz leg tracker), s.
DT = 0.1
#: Noise of the observed positions, m.
NOISE_M = 0.02


@dataclass(frozen=True, eq=False)
class Walk:
    """One synthetic walk: true positions ``xy`` at times ``t``, noisy ``observed`` positions,
    and ``t_loss``, the moment the door line x = 0 is crossed."""

    case: str
    t: FloatArray
    xy: FloatArray
    observed: FloatArray
    t_loss: float
    speed: float

    def truth_at(self, times: FloatArray) -> FloatArray:
        """True positions at ``times`` (linear interpolation)."""
        return np.stack([np.interp(times, self.t, self.xy[:, k]) for k in (0, 1)], axis=1)

    def history(self, seconds: float) -> tuple[FloatArray, FloatArray]:
        """Observed (t, xy) of the last ``seconds`` before (and at) the loss."""
        keep = (self.t <= self.t_loss + 1e-9) & (self.t >= self.t_loss - seconds - 1e-9)
        return self.t[keep], self.observed[keep]


def _wrap(angle: float) -> float:
    return (angle + math.pi) % (2.0 * math.pi) - math.pi


def simulate_walk(case: str, rng: np.random.Generator, after_s: float = 4.0) -> Walk:
    """A seeded walk through the door at the origin, then ``case`` (left, straight, right)."""
    if case not in CASES:
        raise ValueError(f"unknown case {case!r}; expected one of {', '.join(CASES)}")
    speed = float(rng.uniform(0.6, 1.4))
    radius = float(rng.uniform(0.8, 1.5))
    before = float(rng.uniform(0.3, 1.0))
    start = np.array([-rng.uniform(3.0, 5.0), rng.uniform(-1.5, 1.5)])
    side = {"left": 1.0, "straight": 0.0, "right": -1.0}[case]
    # way-points: in front of the door, through it, then the turn (or on straight ahead)
    lateral = float(rng.uniform(-0.05, 0.05)) * DOOR_WIDTH
    waypoints = [np.array([-1.2, lateral]), np.array([before, lateral])]
    if side == 0.0:
        waypoints.append(np.array([before + 8.0, lateral + rng.uniform(-0.3, 0.3)]))
    else:
        waypoints.append(np.array([before + radius, lateral + side * radius]))
        waypoints.append(np.array([before + radius + rng.uniform(-0.2, 0.2), side * 8.0]))
    heading = math.atan2(*(waypoints[0] - start)[::-1]) + float(rng.normal(0.0, 0.25))
    pos = start.copy()
    phase = float(rng.uniform(0.0, 2.0 * math.pi))
    gait = float(rng.uniform(0.03, 0.08))  # relative speed fluctuation
    sub = 10  # integration sub-steps per sample
    h = DT / sub
    ts: list[float] = [0.0]
    xs: list[FloatArray] = [pos.copy()]
    t = 0.0
    target = 0
    t_loss: float | None = None
    while True:
        for _ in range(sub):
            v = speed * (1.0 + gait * math.sin(2.0 * math.pi * 0.25 * t + phase))
            while target < len(waypoints) - 1 and np.hypot(*(waypoints[target] - pos)) < 0.3:
                target += 1
            want = math.atan2(*(waypoints[target] - pos)[::-1])
            rate_max = v / radius
            heading += max(-rate_max * h, min(rate_max * h, 2.5 * _wrap(want - heading) * h))
            prev = pos.copy()
            pos = pos + v * h * np.array([math.cos(heading), math.sin(heading)])
            t += h
            if t_loss is None and prev[0] < 0.0 <= pos[0]:
                t_loss = t - h * pos[0] / max(pos[0] - prev[0], 1e-12)
        ts.append(t)
        xs.append(pos.copy())
        if t_loss is not None and t > t_loss + after_s + DT:
            break
        if t > 60.0:  # pragma: no cover - the steering always reaches the door
            raise RuntimeError("simulated walk never reached the door")
    assert t_loss is not None
    times = np.round(np.asarray(ts), 9)
    true_xy = np.asarray(xs)
    observed = true_xy + rng.normal(0.0, NOISE_M, true_xy.shape)
    # the loss is the last sample before the crossing: the person is seen up to the door
    last_seen = float(times[times <= t_loss][-1])
    return Walk(case, times, true_xy, observed, last_seen, speed)


@dataclass(frozen=True, eq=False)
class DoorExperiment:
    """Errors (m) at ``horizons`` seconds after the loss: ``errors[case][model]`` has shape
    (walks, len(horizons)); ``examples[case]`` is one walk and ``paths[case][model]`` the
    model's predicted path for it (at ``path_times`` seconds after the loss)."""

    models: tuple[str, ...]
    horizons: tuple[float, ...]
    errors: dict[str, dict[str, FloatArray]]
    examples: dict[str, Walk]
    paths: dict[str, dict[str, FloatArray]]
    path_times: FloatArray
    seed: int
    walks: int
    history_s: float
    params: dict[str, dict[str, object]] = field(default_factory=dict)

    def mean_errors(self) -> dict[str, dict[str, list[float]]]:
        """case → model → mean error at each horizon."""
        return {
            case: {m: [float(v) for v in e.mean(axis=0)] for m, e in per.items()}
            for case, per in self.errors.items()
        }


def run_door_experiment(
    seed: int = 0,
    walks: int = 20,
    models: Sequence[str] = tuple(MODELS),
    history_s: float = 3.0,
    horizons: Sequence[float] = (1.0, 2.0, 3.0),
    params: dict[str, dict[str, object]] | None = None,
) -> DoorExperiment:
    """Simulate ``walks`` walks per case (seeded) and score every model at ``horizons``.

    ``params`` optionally maps a model name to its hyperparameters (default: the model's own).
    """
    if walks < 1:
        raise ValueError(f"walks must be ≥ 1, got {walks}")
    params = params or {}
    rng = np.random.default_rng(seed)
    hz = np.asarray(horizons, dtype=float)
    path_times = np.arange(1, round(float(max(hz)) / DT) + 1) * DT
    errors: dict[str, dict[str, FloatArray]] = {}
    examples: dict[str, Walk] = {}
    paths: dict[str, dict[str, FloatArray]] = {}
    for case in CASES:
        errs = {m: np.empty((walks, len(hz))) for m in models}
        for i in range(walks):
            walk = simulate_walk(case, rng, after_s=float(max(hz)) + 0.5)
            t_hist, xy_hist = walk.history(history_s)
            truth = walk.truth_at(walk.t_loss + hz)
            for m in models:
                model = make_model(m, **params.get(m, {})).fit(t_hist, xy_hist)
                errs[m][i] = np.linalg.norm(model.predict(walk.t_loss + hz) - truth, axis=1)
                if i == 0:
                    paths.setdefault(case, {})[m] = model.predict(walk.t_loss + path_times)
            if i == 0:
                examples[case] = walk
        errors[case] = errs
    return DoorExperiment(
        tuple(models),
        tuple(float(h) for h in hz),
        errors,
        examples,
        paths,
        path_times,
        seed,
        walks,
        history_s,
        params,
    )
