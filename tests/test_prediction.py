"""Predictors recover lines and arcs; recency weights change the SVR fit."""

import numpy as np
import pytest

from pfctl.core.prediction import MODELS, PredictionError, make_model, recency_weights


def _line() -> tuple[np.ndarray, np.ndarray]:
    t = np.arange(0, 3.0, 0.1)
    return t, np.stack([0.5 + 1.0 * t, -1.0 + 0.4 * t], axis=1)


@pytest.mark.parametrize("name", sorted(MODELS))
def test_straight_line(name: str) -> None:
    t, xy = _line()
    # svr-time reverts to its mean beyond ~1/sqrt(gamma) s, so it is held to a short horizon.
    tf = t[-1] + (np.array([0.1, 0.2]) if name == "svr-time" else np.array([1.0, 2.0]))
    truth = np.stack([0.5 + tf, -1.0 + 0.4 * tf], axis=1)
    pred = make_model(name).fit(t, xy, recency_weights(t)).predict(tf)
    # svr-time already bends toward its mean: 13 cm off at 0.2 s (measured), the flaw svr fixes.
    tol = 0.15 if name == "svr-time" else 0.05
    assert np.max(np.linalg.norm(pred - truth, axis=1)) < tol


@pytest.mark.parametrize("name", ["svr", "poly3", "cv"])
def test_circle_arc_at_1s(name: str) -> None:
    r, w = 3.0, 1.0 / 3.0  # 1 m/s on a 3 m circle
    t = np.arange(0, 3.0, 0.1)
    arc = lambda tt: np.stack([r * np.cos(w * tt), r * np.sin(w * tt)], axis=1)  # noqa: E731
    tf = np.array([t[-1] + 1.0])
    pred = make_model(name).fit(t, arc(t), recency_weights(t)).predict(tf)
    # cv cannot turn: 0.5 v^2/r t^2 = 0.17 m plus the median-velocity lag
    assert np.linalg.norm(pred - arc(tf)) < (0.4 if name == "cv" else 0.3)


def test_recency_weights_follow_a_late_turn_better() -> None:
    t = np.arange(0, 3.0, 0.1)
    turn = t > 2.0
    xy = np.stack([np.where(turn, 2.0, t), np.where(turn, t - 2.0, 0.0)], axis=1)
    tf = np.array([3.3])
    truth = np.array([[2.0, 1.3]])
    err = {}
    for kind in ("none", "exponential"):
        m = make_model("svr").fit(t, xy, recency_weights(t, kind, half_life_s=0.3))
        err[kind] = float(np.linalg.norm(m.predict(tf) - truth))
    assert err["exponential"] < err["none"]


def test_bad_input_raises() -> None:
    with pytest.raises(PredictionError):
        make_model("svr").fit(np.array([0.0, 0.0, 1.0]), np.zeros((3, 2)))
    with pytest.raises(PredictionError):
        make_model("nope")
