"""Predictors (§II-E): lines and arcs recovered, recency weights matter, SVR maths, invariance."""

from __future__ import annotations

import numpy as np
import pytest

from pfctl.core.prediction.models import (
    MIN_POINTS,
    MODELS,
    ConstantVelocity,
    PredictionError,
    SvrState,
    SvrTime,
    make_model,
    model_params,
    recency_weights,
)

HZ = 10.0
T = np.arange(0.0, 3.0, 1.0 / HZ)  # a 3 s history at 10 Hz


def _line(t: np.ndarray) -> np.ndarray:
    return np.stack([0.5 + 1.0 * t, -1.0 + 0.4 * t], axis=1)  # 1.08 m/s


def _arc(t: np.ndarray, r: float = 3.0, speed: float = 1.0) -> np.ndarray:
    w = speed / r
    return np.stack([r * np.cos(w * t), r * np.sin(w * t)], axis=1)


# Tolerances (m) at 1 s and 2 s past the last sample, for a straight walk at 1.08 m/s.
# cv and poly3 are exact; svr follows a line a little slower than it walks (its regularised end
# slope, a shrinkage that helps it on real tracks); svr-time bends back to its mean beyond ~1 s,
# so it is held to 0.1/0.2 s (the flaw svr fixes).
LINE_CASES = {
    "cv": ((1.0, 2.0), 1e-6),
    "poly3": ((1.0, 2.0), 1e-6),
    "svr": ((1.0, 2.0), 0.12),
    "svr-time": ((0.1, 0.2), 0.15),
}


@pytest.mark.parametrize("name", sorted(MODELS))
def test_straight_line_is_recovered(name: str) -> None:
    ahead, tol = LINE_CASES[name]
    tf = T[-1] + np.asarray(ahead)
    pred = make_model(name).fit(T, _line(T)).predict(tf)
    assert pred.shape == (2, 2)
    assert np.max(np.linalg.norm(pred - _line(tf), axis=1)) < tol


# Constant-speed arc, 1 m/s on a 3 m radius, 1 s ahead. cv cannot turn: 0.5·v²/r·t² = 0.17 m
# plus the lag of a 0.8 s mean velocity; svr likewise; poly3 fits the arc's Taylor expansion up
# to t³; svr-time 0.2 s ahead.
ARC_CASES = {
    "cv": (1.0, 0.35),
    "svr": (1.0, 0.35),
    "poly3": (1.0, 0.05),
    "svr-time": (0.2, 0.15),
}


@pytest.mark.parametrize("name", sorted(MODELS))
def test_constant_speed_arc_is_followed(name: str) -> None:
    ahead, tol = ARC_CASES[name]
    tf = np.array([T[-1] + ahead])
    pred = make_model(name).fit(T, _arc(T)).predict(tf)
    assert np.linalg.norm(pred - _arc(tf)) < tol


def _late_turn() -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """East at 1 m/s for 2 s, then north at 1 m/s (the last third of the history turns)."""
    turn = T > 2.0
    xy = np.stack([np.where(turn, 2.0, T), np.where(turn, T - 2.0, 0.0)], axis=1)
    tf = np.array([T[-1] + 0.5, T[-1] + 1.0])
    truth = np.stack([np.full(2, 2.0), tf - 2.0], axis=1)
    return T, xy, tf, truth


def _heading_error_deg(v: np.ndarray) -> float:
    """Angle between velocity ``v`` and north (the direction after the late turn), degrees."""
    return abs(90.0 - float(np.degrees(np.arctan2(v[1], v[0]))))


def test_recency_weights_follow_a_late_turn_better_svr() -> None:
    """svr's velocity at the last sample points after the turn only with weights.

    Measured (half-life 0.3 s): 21° off north without weights, 2° with.
    """
    t, xy, _, _ = _late_turn()
    off = {}
    for kind in ("none", "exponential"):
        model = make_model("svr", weighting=kind, half_life_s=0.3).fit(t, xy)
        _, vel = model.fitted(0.0)
        off[kind] = _heading_error_deg(vel[0])
    assert off["exponential"] < 0.5 * off["none"], off
    assert off["exponential"] < 5.0, off


def test_recency_weights_follow_a_late_turn_better_svr_time() -> None:
    """The paper's SVR (C = 1000, ε = 1 cm) interpolates a clean track whatever the weights, so
    the turn is given 5 cm of noise: with weights the fit gives up the old samples (their
    residual grows) and follows the last third closer to the true path. Measured: last third
    5.8 → 4.8 cm from the truth, first two thirds 3.0 → 5.8 cm."""
    t, xy, _, _ = _late_turn()
    noisy = xy + np.random.default_rng(0).normal(0.0, 0.05, xy.shape)
    last = t > 2.0
    err = {}
    for kind in ("none", "exponential"):
        model = make_model("svr-time", weighting=kind, half_life_s=0.3).fit(t, noisy)
        pos, _ = model.fitted(t - t[-1])
        d = np.linalg.norm(pos - xy, axis=1)
        err[kind] = (float(d[last].mean()), float(d[~last].mean()))
    assert err["exponential"][0] < 0.9 * err["none"][0], err
    assert err["exponential"][1] > 1.5 * err["none"][1], err


def test_recency_weights_follow_a_late_turn_better_poly3() -> None:
    """The cubic's prediction 0.5 and 1 s after the turn is closer with weights."""
    t, xy, tf, truth = _late_turn()
    err = {}
    for kind in ("none", "exponential"):
        model = make_model("poly3", weighting=kind, half_life_s=0.3).fit(t, xy)
        err[kind] = float(np.mean(np.linalg.norm(model.predict(tf) - truth, axis=1)))
    assert err["exponential"] < 0.7 * err["none"], err


def test_explicit_weights_override_the_models_own() -> None:
    t, xy, tf, _ = _late_turn()
    own = make_model("svr", weighting="none").fit(t, xy).predict(tf)
    ones = make_model("svr").fit(t, xy, np.ones_like(t)).predict(tf)
    recent = make_model("svr").fit(t, xy, recency_weights(t, "exponential", 0.3)).predict(tf)
    np.testing.assert_allclose(own, ones, atol=1e-9)
    assert np.linalg.norm(recent - ones) > 0.1


def test_recency_weights_shapes() -> None:
    t = np.array([0.0, 1.0, 2.0, 3.0])
    np.testing.assert_allclose(recency_weights(t, "exponential", 1.0), [0.125, 0.25, 0.5, 1.0])
    np.testing.assert_allclose(recency_weights(t, "linear"), [0.1, 0.4, 0.7, 1.0])
    np.testing.assert_allclose(recency_weights(t, "none"), np.ones(4))
    with pytest.raises(PredictionError):
        recency_weights(t, "cubic")


def test_svr_fitted_velocity_is_the_derivative_of_the_fit() -> None:
    rng = np.random.default_rng(1)
    xy = _arc(T) + rng.normal(0.0, 0.02, (len(T), 2))
    model = SvrTime(gamma=0.5).fit(T, xy)
    s = np.array([-1.0, -0.3, 0.0])
    h = 1e-5
    pos, vel = model.fitted(s)
    np.testing.assert_allclose(pos, model.predict(T[-1] + s), atol=1e-9)
    numeric = (model.predict(T[-1] + s + h) - model.predict(T[-1] + s - h)) / (2 * h)
    np.testing.assert_allclose(vel, numeric, atol=1e-5)


def test_svr_does_not_bend_back_but_svr_time_does() -> None:
    """Far ahead the paper's time-input SVR returns toward the track; svr keeps walking."""
    tf = T[-1] + np.array([3.0, 5.0])
    truth = _line(tf)
    far = {n: make_model(n).fit(T, _line(T)).predict(tf) for n in ("svr", "svr-time")}
    ahead_svr = np.linalg.norm(far["svr"][1] - _line(T)[-1])
    ahead_time = np.linalg.norm(far["svr-time"][1] - _line(T)[-1])
    assert ahead_svr > 4.5  # 5 s at ~1 m/s
    assert ahead_time < 2.0
    assert np.linalg.norm(far["svr"] - truth, axis=1).max() < 0.6


@pytest.mark.parametrize("name", sorted(MODELS))
def test_clock_origin_does_not_matter(name: str) -> None:
    rng = np.random.default_rng(2)
    xy = _arc(T) + rng.normal(0.0, 0.02, (len(T), 2))
    tf = T[-1] + np.array([0.5, 1.0, 2.0])
    a = make_model(name).fit(T, xy).predict(tf)
    b = make_model(name).fit(T + 86400.0, xy).predict(tf + 86400.0)
    # libsvm stops at its tolerance (1e-3), so SVR solutions agree to about a millimetre
    np.testing.assert_allclose(a, b, atol=2e-3 if name.startswith("svr") else 1e-9)


def test_svr_means_the_same_at_10_and_40_hz() -> None:
    """C is per second of track (weights × Δt): the same walk sampled 4× denser → same velocity."""
    v = {}
    for hz in (10.0, 40.0):
        t = np.arange(0.0, 3.0 + 1e-9, 1.0 / hz)
        v[hz] = SvrState().fit(t, _arc(t)).v_
    np.testing.assert_allclose(v[10.0], v[40.0], atol=0.05)


@pytest.mark.parametrize("dt", [0.4, 0.1])
def test_svr_keeps_the_speed_of_slow_and_fast_walkers(dt: float) -> None:
    """No collapse of the fitted velocity for fast people (the reason for the default C, γ)."""
    t = np.arange(0.0, 2.81, dt)
    for speed in (0.3, 1.0, 2.0, 3.0, 6.0):
        xy = np.stack([speed * t, -0.5 * speed * t], axis=1)
        v = SvrState().fit(t, xy).v_
        ratio = np.linalg.norm(v) / np.hypot(speed, 0.5 * speed)
        assert 0.9 < ratio <= 1.0, (speed, ratio)


def test_constant_velocity_estimators() -> None:
    t = np.arange(0.0, 2.0, 0.4)
    xy = np.stack([t, np.zeros_like(t)], axis=1)
    xy[-2, 0] += 0.3  # one bad sample
    mean = ConstantVelocity(window_s=1.2).fit(t, xy)
    median = ConstantVelocity(window_s=1.2, estimator="median").fit(t, xy)
    np.testing.assert_allclose(mean.v_, [1.0, 0.0], atol=1e-9)  # endpoints are good
    assert abs(median.v_[0] - 1.0) < abs(((xy[-1] - xy[-2]) / 0.4)[0] - 1.0)
    one_step = ConstantVelocity(window_s=0.01).fit(t, xy)
    np.testing.assert_allclose(one_step.v_, (xy[-1] - xy[-2]) / 0.4)


def test_min_points_and_bad_input() -> None:
    for name, need in MIN_POINTS.items():
        t = np.arange(need - 1, dtype=float)
        with pytest.raises(PredictionError, match="at least"):
            make_model(name).fit(t, np.zeros((len(t), 2)))
        make_model(name).fit(np.arange(need, dtype=float), np.zeros((need, 2)))
    with pytest.raises(PredictionError, match="increasing"):
        make_model("svr").fit(np.array([0.0, 0.0, 1.0]), np.zeros((3, 2)))
    with pytest.raises(PredictionError, match="finite"):
        make_model("cv").fit(np.array([0.0, 1.0]), np.array([[0.0, np.nan], [1.0, 1.0]]))
    with pytest.raises(PredictionError, match="weights"):
        make_model("svr").fit(T, _line(T), np.zeros_like(T))
    with pytest.raises(PredictionError, match="unknown model"):
        make_model("nope")
    with pytest.raises(PredictionError, match="C > 0"):
        make_model("svr", C=-1.0).fit(T, _line(T))


def test_make_model_takes_only_known_params() -> None:
    params = {"C": 5.0, "gamma": 0.2, "epsilon": 0.02, "half_life_s": 0.7, "window_s": 1.2}
    svr = make_model("svr", **params)
    cv = make_model("cv", **params)
    assert isinstance(svr, SvrState) and svr.C == 5.0 and svr.half_life_s == 0.7
    assert isinstance(cv, ConstantVelocity) and cv.window_s == 1.2
    assert "C" in model_params("svr-time") and "window_s" not in model_params("svr")


def test_libsvm_called_directly_gives_sklearns_svr_bit_for_bit() -> None:
    """fit_rbf_svr calls libsvm as ``sklearn.svm.SVR.fit`` does, without its validation: the
    same support vectors, dual coefficients and intercept, exactly, on random weighted tracks
    and settings (the paper's, the default svr's, others); predictions agree to 1e-9 m."""
    from sklearn.svm import SVR

    from pfctl.core.prediction.models import RbfSvr, fit_rbf_svr

    rng = np.random.default_rng(8)
    for trial in range(80):
        n = int(rng.integers(3, 130))
        t = np.cumsum(rng.uniform(0.02, 0.2, n))
        s = (t - t[-1])[:, None]
        y = np.cumsum(rng.normal(0.0, 0.1, n))
        w = rng.uniform(0.01, 2.0, n)
        c, eps, gamma = [(1000.0, 0.01, 1.0), (1000.0, 0.01, 0.01), (100.0, 0.05, 0.03)][trial % 3]
        fast = fit_rbf_svr(s, y, w, c, eps, gamma)
        slow = SVR(kernel="rbf", C=c, epsilon=eps, gamma=gamma).fit(s, y, sample_weight=w)
        assert isinstance(fast, RbfSvr)  # the direct path, not the fallback
        assert np.array_equal(fast.support_vectors_, slow.support_vectors_)
        assert np.array_equal(fast.dual_coef_, slow.dual_coef_)
        assert np.array_equal(fast.intercept_, slow.intercept_)
        q = np.linspace(-4.0, 3.0, 25)[:, None]
        np.testing.assert_allclose(fast.predict(q), slow.predict(q), rtol=0, atol=1e-9)
