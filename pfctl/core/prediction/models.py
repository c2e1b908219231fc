"""Trajectory prediction of a lost target (Kim et al., "An Architecture for Person-Following
using Active Target Search", §II-E and §III).

When the target vanishes, the paper predicts where the person went from their recent track with
an RBF support-vector regressor (C = 1000, ε = 0.01, γ = 1.0) whose samples weigh more the more
recent they are, and compares it with a cubic polynomial. This module holds those two and two
more, all with one scikit-learn-style interface: hyperparameters in ``__init__``, then
``fit(t, xy, weights=None)`` (returns ``self``) and ``predict(t_future) -> (n, 2)``.

=============  ==============================================================================
``svr``        default: the paper's SVR used as a *state estimator* — its fitted velocity at the
               last sample — extrapolated at constant velocity (:class:`SvrState`).
``svr-time``   the paper's SVR as published: one RBF SVR per coordinate with time as input,
               predicting by evaluating it at future times (:class:`SvrTime`).
``poly3``      the paper's comparison, a weighted cubic polynomial per coordinate
               (:class:`Poly3`).
``cv``         constant velocity from a short, robust recent velocity (:class:`ConstantVelocity`),
               the strong baseline of the pedestrian-prediction literature.
=============  ==============================================================================

**Weights.** ``weights=None`` means the predictor's own recency weights
(:func:`recency_weights` with its ``weighting`` and ``half_life_s``); pass ``np.ones(n)`` for
uniform weights. Weights scale each sample's loss: for the SVRs they are passed as
``sample_weight``, which rescales C per sample as in the paper; for the polynomial they weight the
least squares. :class:`ConstantVelocity` ignores them.

**Normalisation of the SVR inputs (so γ and C mean the same for any clock and sampling rate).**
The input is the time relative to the last sample in seconds, ``s = (t − t_last) / 1 s``: the
clock origin drops out, and the RBF kernel ``exp(−γ s²)`` has a width of ``1/√γ`` seconds at any
sampling rate (γ = 1 → about one second). The targets are positions relative to the last sample in
metres, so ε is a tube half-width in metres. The per-sample weight given to libsvm is the recency
weight times the sample's share of time, ``w_i · Δt_i / 1 s`` (``Δt_i = numpy.gradient(t)``), so C
is a penalty *per second of track*: a 3 s history weighs the same at 10 Hz and at 40 Hz instead of
four times more at 40 Hz.

**Speed.** The SVRs are fitted by libsvm itself (:func:`fit_rbf_svr`), the solver
``sklearn.svm.SVR`` calls, with the same arguments: the same support vectors, coefficients and
intercept, bit for bit, without scikit-learn's input validation around it, which costs more
than the solver needs for a 3 s track, and most the first time in a process (it looks for
dataframe libraries; benchmarks/README.md). When that internal entry point is missing (another
scikit-learn), ``SVR`` is used.
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields
from typing import Any, Literal, Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray
from sklearn.svm import SVR

from pfctl.core.params import param

__all__ = [
    "DEFAULT_MODEL",
    "MIN_POINTS",
    "MODELS",
    "ConstantVelocity",
    "ModelName",
    "Poly3",
    "PredictionError",
    "Predictor",
    "RbfSvr",
    "SvrState",
    "SvrTime",
    "Weighting",
    "fit_rbf_svr",
    "make_model",
    "model_params",
    "recency_weights",
]

FloatArray = NDArray[np.float64]
Weighting = Literal["none", "linear", "exponential"]
ModelName = Literal["svr", "svr-time", "poly3", "cv"]
"""The predictors by their CLI/mission names (:data:`MODELS`)."""


class PredictionError(ValueError):
    """A track that cannot be fitted (too few points, non-increasing time) or a bad setting."""


class Predictor(Protocol):
    """What every predictor offers: fit a track, predict positions at future times."""

    def fit(self, t: ArrayLike, xy: ArrayLike, weights: ArrayLike | None = None) -> Predictor:
        """Learn from times ``t`` (n,) in seconds and positions ``xy`` (n, 2) in metres."""
        ...

    def predict(self, t_future: ArrayLike) -> FloatArray:
        """Positions (m, 2) at times ``t_future`` (m,) on the clock of ``fit``."""
        ...


def recency_weights(
    t: ArrayLike, kind: Weighting | str = "exponential", half_life_s: float = 1.0
) -> FloatArray:
    """Sample weights that grow toward the newest sample, 1.0 at the newest (§II-E).

    ``exponential``: ``0.5 ** (age / half_life_s)``; ``linear``: from 0.1 at the oldest sample up
    to 1.0; ``none``: all 1.
    """
    t = np.asarray(t, dtype=float)
    age = float(t[-1]) - t
    if kind == "none":
        return np.ones_like(t)
    if kind == "linear":
        span = max(float(age.max()), 1e-9)
        return 1.0 - 0.9 * age / span
    if kind == "exponential":
        if not half_life_s > 0:
            raise PredictionError(f"half_life_s must be > 0, got {half_life_s}")
        return np.power(0.5, age / half_life_s)
    raise PredictionError(f"unknown weighting {kind!r}; expected none, linear or exponential")


def _check(t: ArrayLike, xy: ArrayLike, need: int) -> tuple[FloatArray, FloatArray]:
    t = np.asarray(t, dtype=float).ravel()
    xy = np.asarray(xy, dtype=float).reshape(-1, 2)
    if len(t) != len(xy):
        raise PredictionError(f"t has {len(t)} samples but xy has {len(xy)}")
    if len(t) < need:
        raise PredictionError(f"need at least {need} points, got {len(t)}")
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(xy))):
        raise PredictionError("t and xy must be finite")
    if np.any(np.diff(t) <= 0):
        raise PredictionError("time must be strictly increasing")
    return t, xy


def _weights(t: FloatArray, weights: ArrayLike | None, kind: str, half_life_s: float) -> FloatArray:
    if weights is None:
        return recency_weights(t, kind, half_life_s)
    w = np.asarray(weights, dtype=float).ravel()
    if len(w) != len(t) or np.any(~np.isfinite(w)) or np.any(w < 0) or not np.any(w > 0):
        raise PredictionError("weights must be one finite value ≥ 0 per sample, not all 0")
    return w


def _future(t_future: ArrayLike) -> FloatArray:
    return np.atleast_1d(np.asarray(t_future, dtype=float)).ravel()


@dataclass
class ConstantVelocity:
    """Constant velocity from the mean velocity over the last ``window_s`` seconds.

    The velocity is the displacement between the last sample and the sample ``window_s`` before
    it, divided by the elapsed time (``estimator="mean"``, the least noisy of the per-step
    velocities' averages), or the median of the per-step velocities in the window
    (``estimator="median"``, robust to a single bad sample). With fewer than two samples in the
    window it uses the last step. ``window_s = 0.8`` s is the best window for this model on the
    ETH/UCY scenes (mean ADE over eth, hotel, univ; see ``pfctl predict search``); weights are
    ignored.
    """

    window_s: float = 0.8
    estimator: Literal["mean", "median"] = "mean"

    def fit(
        self, t: ArrayLike, xy: ArrayLike, weights: ArrayLike | None = None
    ) -> ConstantVelocity:
        t, xy = _check(t, xy, 2)
        self.t0_, self.p0_ = float(t[-1]), xy[-1].copy()
        first = int(np.searchsorted(t, t[-1] - self.window_s - 1e-6))
        first = min(first, len(t) - 2)
        if self.estimator == "median":
            v = np.diff(xy[first:], axis=0) / np.diff(t[first:])[:, None]
            self.v_ = np.median(v, axis=0)
        elif self.estimator == "mean":
            self.v_ = (xy[-1] - xy[first]) / (t[-1] - t[first])
        else:
            raise PredictionError(f"unknown estimator {self.estimator!r}; expected mean or median")
        return self

    def predict(self, t_future: ArrayLike) -> FloatArray:
        dt = _future(t_future) - self.t0_
        return self.p0_ + dt[:, None] * self.v_


@dataclass
class Poly3:
    """Weighted cubic polynomial per coordinate, the paper's comparison (§III, Fig. of the door).

    Least squares of ``x(s)`` and ``y(s)`` on ``s = t − t_last`` (seconds) with the recency weights
    (``numpy.polyfit`` with ``w = √weight``, so each squared residual is scaled by its weight).
    Extrapolated, the cubic term soon dominates: the divergence the paper reports.
    """

    degree: int = 3
    weighting: Weighting = "exponential"
    half_life_s: float = 1.0

    def fit(self, t: ArrayLike, xy: ArrayLike, weights: ArrayLike | None = None) -> Poly3:
        t, xy = _check(t, xy, self.degree + 1)
        w = _weights(t, weights, self.weighting, self.half_life_s)
        self.t0_ = float(t[-1])
        self.coef_ = [np.polyfit(t - self.t0_, xy[:, k], self.degree, w=np.sqrt(w)) for k in (0, 1)]
        return self

    def predict(self, t_future: ArrayLike) -> FloatArray:
        dt = _future(t_future) - self.t0_
        return np.stack([np.polyval(c, dt) for c in self.coef_], axis=1)


def svr_sample_weights(t: FloatArray, weights: FloatArray) -> FloatArray:
    """libsvm ``sample_weight``: recency weight × the sample's share of time in seconds.

    With ``Δt_i = numpy.gradient(t)`` the weights are a density, so C is a penalty per second of
    track and means the same at any sampling rate (module docstring).
    """
    return weights * np.gradient(t) if len(t) > 1 else weights.copy()


@dataclass(frozen=True)
class RbfSvr:
    """A fitted RBF ε-SVR on one input: ``f(s) = Σ αᵢ exp(−γ (s − sᵢ)²) + b`` with the support
    vectors ``support_vectors_`` (k, 1), dual coefficients ``dual_coef_`` (1, k) and intercept
    ``intercept_`` (1,), named as in ``sklearn.svm.SVR``."""

    support_vectors_: FloatArray
    dual_coef_: FloatArray
    intercept_: FloatArray
    gamma: float
    n_iter_: int = field(default=0, compare=False)

    def predict(self, s: ArrayLike) -> FloatArray:
        """``f`` at inputs ``s`` (m, 1) or (m,)."""
        x = np.asarray(s, dtype=float).reshape(-1)
        d = x[:, None] - self.support_vectors_[:, 0][None, :]
        return np.exp(-self.gamma * d * d) @ self.dual_coef_[0] + self.intercept_[0]


def _libsvm() -> Any:
    """scikit-learn's libsvm binding (internal), or None."""
    try:
        from sklearn.svm import _libsvm as libsvm  # the solver SVR.fit calls
    except ImportError:  # pragma: no cover - another scikit-learn
        return None
    return libsvm if hasattr(libsvm, "fit") else None


def fit_rbf_svr(
    s: FloatArray, y: FloatArray, sample_weight: FloatArray, C: float, epsilon: float, gamma: float
) -> RbfSvr | SVR:
    """The RBF ε-SVR of §II-E fitted to inputs ``s`` (n, 1) and targets ``y`` (n,) with
    ``sample_weight`` rescaling C per sample: libsvm called as ``sklearn.svm.SVR(kernel="rbf",
    C=C, epsilon=epsilon, gamma=gamma).fit(s, y, sample_weight=sample_weight)`` calls it (its
    defaults: tol 1e-3, shrinking, 200 MB cache, no iteration limit), so the solution is the
    same; the ``SVR`` itself when the binding is not there or refuses the call."""
    libsvm = _libsvm()
    x = np.ascontiguousarray(s, dtype=np.float64).reshape(len(s), -1)
    if libsvm is not None:
        try:
            libsvm.set_verbosity_wrap(0)
            _, vectors, _, coef, intercept, _, _, status, n_iter = libsvm.fit(
                x,
                np.ascontiguousarray(y, dtype=np.float64),
                svm_type=3,  # epsilon_svr
                sample_weight=np.ascontiguousarray(sample_weight, dtype=np.float64),
                class_weight=np.empty(0),
                kernel="rbf",
                C=float(C),
                nu=0.0,
                probability=False,
                degree=3,
                shrinking=True,
                tol=1e-3,
                cache_size=200,
                coef0=0.0,
                gamma=float(gamma),
                epsilon=float(epsilon),
                max_iter=-1,
                random_seed=0,  # probability estimates only; unused
            )
        except (TypeError, ValueError):  # pragma: no cover - another binding's signature
            pass
        else:
            if status == 0 and np.all(np.isfinite(coef)) and np.all(np.isfinite(intercept)):
                n = int(np.asarray(n_iter).ravel()[0]) if np.size(n_iter) else 0
                return RbfSvr(vectors, coef, intercept, float(gamma), n)
    return SVR(kernel="rbf", C=C, epsilon=epsilon, gamma=gamma).fit(
        x, y, sample_weight=sample_weight
    )


@dataclass
class SvrTime:
    """The paper's SVR (§II-E): an RBF ``sklearn.svm.SVR`` per coordinate, time as input.

    Defaults are the paper's C = 1000, ε = 0.01 m, γ = 1.0 s⁻². Input ``s = t − t_last`` in
    seconds, targets the positions relative to the last sample; recency weights rescale C per
    sample (see the module docstring for the normalisation). Far from the data the RBF expansion
    falls back to its constant term, so predictions more than ~1/√γ s ahead bend back toward the
    track's (weighted) mean position — the person seems to stop and return. :class:`SvrState`
    keeps this fit and extrapolates it sensibly.
    """

    C: float = 1000.0
    epsilon: float = 0.01
    gamma: float = 1.0
    weighting: Weighting = "exponential"
    half_life_s: float = 1.0

    def _fit_svrs(self, t: ArrayLike, xy: ArrayLike, weights: ArrayLike | None) -> None:
        t, xy = _check(t, xy, 3)
        if not (self.C > 0 and self.epsilon >= 0 and self.gamma > 0):
            raise PredictionError(
                f"SVR needs C > 0, epsilon ≥ 0, gamma > 0; got C={self.C}, "
                f"epsilon={self.epsilon}, gamma={self.gamma}"
            )
        w = svr_sample_weights(t, _weights(t, weights, self.weighting, self.half_life_s))
        self.t0_, self.p0_ = float(t[-1]), xy[-1].copy()
        s = (t - self.t0_)[:, None]
        y = xy - self.p0_
        self.models_ = [
            fit_rbf_svr(s, y[:, k], w, self.C, self.epsilon, self.gamma) for k in (0, 1)
        ]

    def fit(self, t: ArrayLike, xy: ArrayLike, weights: ArrayLike | None = None) -> SvrTime:
        self._fit_svrs(t, xy, weights)
        return self

    def fitted(self, s: ArrayLike) -> tuple[FloatArray, FloatArray]:
        """The fitted positions and velocities at ``s`` seconds from the last sample (analytic).

        ``f(s) = Σ αᵢ exp(−γ (s − sᵢ)²) + b`` and
        ``f'(s) = Σ αᵢ · (−2γ (s − sᵢ)) exp(−γ (s − sᵢ)²)`` with the support vectors ``sᵢ``
        and dual coefficients ``αᵢ`` of each coordinate's SVR.
        """
        s = _future(s)
        pos = np.empty((len(s), 2))
        vel = np.empty((len(s), 2))
        for k, m in enumerate(self.models_):
            d = s[:, None] - m.support_vectors_[:, 0][None, :]
            kern = np.exp(-self.gamma * d * d)
            a = m.dual_coef_[0]
            pos[:, k] = kern @ a + m.intercept_[0]
            vel[:, k] = (-2.0 * self.gamma * d * kern) @ a
        return self.p0_ + pos, vel

    def predict(self, t_future: ArrayLike) -> FloatArray:
        s = (_future(t_future) - self.t0_)[:, None]
        return self.p0_ + np.stack([m.predict(s) for m in self.models_], axis=1)


@dataclass
class SvrState(SvrTime):
    """Default predictor: the paper's weighted RBF SVR as a state estimator, then constant velocity.

    An RBF SVR cannot extrapolate (it falls back to its constant term, see :class:`SvrTime`), but
    it is a good weighted, ε-insensitive smoother of the track it has seen. So this model fits the
    same per-coordinate SVR as the paper (§II-E: RBF kernel, ε-tube, sample weights growing toward
    the newest sample) and takes its fitted velocity at the last sample, ``v̂ = f'(0)``
    (:meth:`SvrTime.fitted`), as the person's velocity; the prediction is the last observed
    position moved on at ``v̂``.

    The paper's C = 1000 (per second of track, see the module docstring), ε = 0.01 m and
    exponential recency weights are kept; γ = 0.01 s⁻² (a kernel ~10 s wide, smoother than the
    3 s history, so ``f'(0)`` is a weighted end slope rather than the interpolant's end wiggle)
    and a 0.5 s half-life come from :func:`pfctl.core.prediction.search.grid_search` with
    people split into train and test (``pfctl predict search``) on the ETH/UCY scenes, taking
    among the best grid points the one whose velocity does not collapse for fast walkers: the
    grid's top point (C = 100, γ = 0.03) lags a fast run, because its bounded dual coefficients
    cannot build a steep slope from a kernel that wide. With these values a straight walk is
    followed at nearly its speed (a little under: the regulariser flattens the fit wherever the
    ε-tube lets it); the paper's γ = 1 follows it far slower, the end slope of an interpolant
    bending back to its constant term, and is worse than ``cv`` on real tracks. README "pfctl
    predict" and benchmarks/README.md have the numbers.
    """

    C: float = param(
        1000.0,
        "Penalty of the fit's errors, per second of track (the same at any sampling rate).",
        gt=0,
    )
    epsilon: float = param(0.01, "Half-width of the ε-insensitive tube.", unit="m", gt=0)
    gamma: float = param(
        0.01,
        "RBF width parameter (time is in seconds since the last sample).",
        unit="s⁻²",
        gt=0,
    )
    weighting: Weighting = param(
        "exponential",
        "Sample weights of the fit, recent samples counting more: ``exponential`` (halved every"
        " ``half_life_s``), ``linear`` (from 0.1 at the oldest sample to 1) or ``none``.",
    )
    half_life_s: float = param(
        0.5, "Age at which an exponential weight has halved.", unit="s", gt=0
    )

    def fit(self, t: ArrayLike, xy: ArrayLike, weights: ArrayLike | None = None) -> SvrState:
        self._fit_svrs(t, xy, weights)
        _, vel = self.fitted(0.0)
        self.v_ = vel[0]
        return self

    def predict(self, t_future: ArrayLike) -> FloatArray:
        dt = _future(t_future) - self.t0_
        return self.p0_ + dt[:, None] * self.v_


MODELS: dict[str, type[Any]] = {
    "svr": SvrState,
    "svr-time": SvrTime,
    "poly3": Poly3,
    "cv": ConstantVelocity,
}
DEFAULT_MODEL = "svr"


#: The fewest samples each model can be fitted on.
MIN_POINTS = {"svr": 3, "svr-time": 3, "poly3": 4, "cv": 2}


def model_params(name: str) -> list[str]:
    """The hyperparameter names of model ``name`` (its ``__init__`` arguments)."""
    if name not in MODELS:
        raise PredictionError(f"unknown model {name!r}; expected one of {', '.join(MODELS)}")
    return [f.name for f in fields(MODELS[name])]


def make_model(name: str, **params: Any) -> Predictor:
    """A fresh predictor by its CLI/mission name, with hyperparameters ``params``.

    Parameters the model does not have are ignored, so one set of settings (say, a mission's SVR
    C/ε/γ and weighting) can be passed to every model.
    """
    known = set(model_params(name))
    model: Predictor = MODELS[name](**{k: v for k, v in params.items() if k in known})
    return model
