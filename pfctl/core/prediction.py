"""Trajectory predictors for the lost-target search (Kim et al., Sec. on motion prediction).

All predictors share one interface: ``fit(t, xy, weights=None)`` then ``predict(t_future) -> xy``.

* ``cv``: constant velocity from a robust (median) recent velocity.
* ``poly3``: weighted cubic polynomial per coordinate (the paper's comparison).
* ``svr-time``: the paper's SVR, one RBF ``sklearn.svm.SVR`` per coordinate with time as input.
  Time is normalised as ``(t - t_last) / 1 s`` so gamma means the same for any clock origin and
  sampling rate; per-sample weights rescale C (``sample_weight``) as in the paper.
* ``svr`` (default): the same kernel, C, epsilon, gamma and weights, regressing the residual from
  a constant-velocity motion, so far from the data it falls back to constant velocity instead of
  bending back to the mean.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from sklearn.svm import SVR

FloatArray = NDArray[np.float64]


class PredictionError(ValueError):
    """A trajectory that cannot be fitted (too few points, non-increasing time)."""


def recency_weights(
    t: FloatArray, kind: str = "exponential", half_life_s: float = 1.0
) -> FloatArray:
    """Sample weights growing toward the newest sample (1.0 at the newest)."""
    age = float(t[-1]) - t
    if kind == "none":
        return np.ones_like(t)
    if kind == "linear":
        span = max(float(age.max()), 1e-9)
        return 1.0 - 0.9 * age / span
    if kind == "exponential":
        return np.power(0.5, age / half_life_s)
    raise PredictionError(f"unknown weighting {kind!r}")


def _check(t: FloatArray, xy: FloatArray, need: int) -> tuple[FloatArray, FloatArray]:
    t = np.asarray(t, dtype=float)
    xy = np.asarray(xy, dtype=float).reshape(-1, 2)
    if len(t) != len(xy):
        raise PredictionError("t and xy differ in length")
    if len(t) < need:
        raise PredictionError(f"need at least {need} points, got {len(t)}")
    if np.any(np.diff(t) <= 0):
        raise PredictionError("time must be strictly increasing")
    return t, xy


def _robust_velocity(t: FloatArray, xy: FloatArray, window_s: float = 1.0) -> FloatArray:
    keep = t >= t[-1] - window_s
    if keep.sum() < 2:
        keep[-2:] = True
    tt, pp = t[keep], xy[keep]
    v = np.diff(pp, axis=0) / np.diff(tt)[:, None]
    return np.median(v, axis=0)


@dataclass
class ConstantVelocity:
    """Constant-velocity baseline from the median velocity over the last ``window_s`` seconds."""

    window_s: float = 1.0

    def fit(
        self, t: FloatArray, xy: FloatArray, weights: FloatArray | None = None
    ) -> ConstantVelocity:
        t, xy = _check(t, xy, 2)
        self.t0_, self.p0_ = float(t[-1]), xy[-1].copy()
        self.v_ = _robust_velocity(t, xy, self.window_s)
        return self

    def predict(self, t_future: FloatArray) -> FloatArray:
        dt = np.asarray(t_future, dtype=float) - self.t0_
        return self.p0_ + dt[:, None] * self.v_


@dataclass
class Poly3:
    """Weighted cubic polynomial per coordinate (``numpy.polyfit`` with sqrt weights)."""

    degree: int = 3

    def fit(self, t: FloatArray, xy: FloatArray, weights: FloatArray | None = None) -> Poly3:
        t, xy = _check(t, xy, self.degree + 1)
        self.t0_ = float(t[-1])
        w = None if weights is None else np.sqrt(np.asarray(weights, dtype=float))
        self.coef_ = [np.polyfit(t - self.t0_, xy[:, k], self.degree, w=w) for k in range(2)]
        return self

    def predict(self, t_future: FloatArray) -> FloatArray:
        dt = np.asarray(t_future, dtype=float) - self.t0_
        return np.stack([np.polyval(c, dt) for c in self.coef_], axis=1)


@dataclass
class SvrTime:
    """The paper's SVR: RBF SVR per coordinate, input t - t_last in s, C rescaled per sample."""

    C: float = 1000.0
    epsilon: float = 0.01
    gamma: float = 1.0

    def _svr(self) -> SVR:
        return SVR(kernel="rbf", C=self.C, epsilon=self.epsilon, gamma=self.gamma)

    def _targets(self, dt: FloatArray, xy: FloatArray) -> FloatArray:
        return xy - xy[-1]

    def _base(self, dt: FloatArray) -> FloatArray:
        return np.zeros((len(dt), 2)) + self.p0_

    def fit(self, t: FloatArray, xy: FloatArray, weights: FloatArray | None = None) -> SvrTime:
        t, xy = _check(t, xy, 3)
        self.t0_, self.p0_ = float(t[-1]), xy[-1].copy()
        self.v_ = _robust_velocity(t, xy)
        dt = (t - self.t0_)[:, None]
        y = self._targets(dt[:, 0], xy)
        sw = None if weights is None else np.asarray(weights, dtype=float)
        self.models_ = [self._svr().fit(dt, y[:, k], sample_weight=sw) for k in range(2)]
        return self

    def predict(self, t_future: FloatArray) -> FloatArray:
        dt = (np.asarray(t_future, dtype=float) - self.t0_)[:, None]
        out = self._base(dt[:, 0])
        for k, m in enumerate(self.models_):
            out[:, k] += m.predict(dt)
        return out


@dataclass
class SvrResidual(SvrTime):
    """Default SVR: same kernel/C/eps/gamma/weights on the residual from constant velocity."""

    def _targets(self, dt: FloatArray, xy: FloatArray) -> FloatArray:
        return xy - (self.p0_ + dt[:, None] * self.v_)

    def _base(self, dt: FloatArray) -> FloatArray:
        return self.p0_ + dt[:, None] * self.v_


MODELS = {"svr": SvrResidual, "svr-time": SvrTime, "poly3": Poly3, "cv": ConstantVelocity}


def make_model(name: str) -> SvrTime | Poly3 | ConstantVelocity:
    """A fresh predictor by its CLI/mission name."""
    if name not in MODELS:
        raise PredictionError(f"unknown model {name!r}; expected one of {sorted(MODELS)}")
    return MODELS[name]()
