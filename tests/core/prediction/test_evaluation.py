"""Windows, ADE/FDE, parallel evaluation and the person-split grid search, on synthetic tracks."""

from __future__ import annotations

import numpy as np
import pytest

from pfctl.core.prediction.evaluation import ModelSpec, evaluate, evaluate_per_window, make_windows
from pfctl.core.prediction.search import grid_search, param_grid, split_by_person
from pfctl.core.prediction.trajectories import Trajectory


def _straight(n: int, v: tuple[float, float], name: str, dt: float = 0.4) -> Trajectory:
    t = np.arange(n) * dt
    xy = np.stack([v[0] * t, v[1] * t], axis=1)
    return Trajectory(t, xy, name=name, source="synthetic", person=name)


def _walkers(count: int, seed: int, n: int = 24, noise: float = 0.01) -> list[Trajectory]:
    """Walkers at 0.8–1.4 m/s with a slow constant turn and ``noise`` m of noise, 0.4 s steps."""
    rng = np.random.default_rng(seed)
    tracks = []
    for i in range(count):
        t = np.arange(n) * 0.4
        speed = rng.uniform(0.8, 1.4)
        heading = rng.uniform(-np.pi, np.pi) + rng.uniform(-0.15, 0.15) * t
        step = np.stack([np.cos(heading), np.sin(heading)], axis=1) * speed * 0.4
        xy = np.cumsum(step, axis=0) + rng.normal(0.0, noise, (n, 2))
        tracks.append(Trajectory(t, xy, name=f"w{i}", source="synthetic", person=f"w{i}"))
    return tracks


def test_windows_count_and_layout() -> None:
    tracks = [_straight(25, (1.0, 0.0), "a"), _straight(19, (0.0, 1.0), "short")]
    w = make_windows(tracks, obs=8, pred=12)
    assert len(w) == 25 - 20 + 1  # the short track has no full window
    assert w.t_obs.shape == (6, 8) and w.xy_pred.shape == (6, 12, 2)
    np.testing.assert_allclose(w.t_pred[0, 0] - w.t_obs[0, -1], 0.4)
    assert set(w.track.tolist()) == {0}
    assert len(make_windows(tracks, 8, 12, stride=2)) == 3
    assert len(make_windows([tracks[1]], 8, 12)) == 0


def test_cv_is_exact_on_straight_tracks_and_others_close() -> None:
    w = make_windows([_straight(30, (1.2, -0.3), "a")], 8, 12)
    scores = evaluate([ModelSpec.of(n) for n in ("cv", "poly3", "svr")], w)
    assert scores["cv"].ade < 1e-9 and scores["poly3"].ade < 1e-6
    assert scores["svr"].ade < 0.3  # the regularised end slope lags (core/prediction/models.py)
    for s in scores.values():
        assert s.n == len(w) and s.ms_per_call > 0
        assert s.fde >= s.ade - 1e-12  # straight: error grows with the horizon


def test_ade_fde_definitions() -> None:
    w = make_windows([_straight(20, (1.0, 0.0), "a")], 8, 12)
    # cv with a stopped person: the error at k steps ahead is 0.4·k m
    ade, fde, _ = evaluate_per_window([ModelSpec.of("cv", window_s=0.8)], w)["cv"]
    assert ade[0] == pytest.approx(0.0, abs=1e-9) and fde[0] == pytest.approx(0.0, abs=1e-9)
    stopped = Trajectory(
        np.arange(20) * 0.4,
        np.vstack([np.zeros((8, 2)), np.stack([np.arange(1, 13) * 0.4, np.zeros(12)], axis=1)]),
        name="s",
    )
    ade, fde, _ = evaluate_per_window([ModelSpec.of("cv")], make_windows([stopped], 8, 12))["cv"]
    assert ade[0] == pytest.approx(0.4 * np.mean(np.arange(1, 13)))
    assert fde[0] == pytest.approx(0.4 * 12)


def test_parallel_evaluation_equals_serial() -> None:
    w = make_windows(_walkers(6, seed=3), 8, 12)
    specs = [ModelSpec.of("cv"), ModelSpec.of("svr", label="svr C=30", C=30.0)]
    done: list[int] = []
    serial = evaluate(specs, w, jobs=1, chunk=7)
    parallel = evaluate(specs, w, jobs=2, chunk=7, progress=done.append)
    assert sum(done) == 2 * len(w)
    for name in ("cv", "svr C=30"):
        assert parallel[name].ade == pytest.approx(serial[name].ade, rel=1e-12)
        assert parallel[name].fde == pytest.approx(serial[name].fde, rel=1e-12)


def test_duplicate_labels_are_refused() -> None:
    w = make_windows([_straight(20, (1.0, 0.0), "a")], 8, 12)
    with pytest.raises(ValueError, match="unique"):
        evaluate([ModelSpec.of("cv"), ModelSpec.of("cv")], w)


def test_param_grid_and_person_split() -> None:
    assert param_grid({"a": [1, 2], "b": ["x"]}) == [{"a": 1, "b": "x"}, {"a": 2, "b": "x"}]
    with pytest.raises(ValueError):
        param_grid({"a": []})
    pieces = [
        Trajectory(np.arange(3.0), np.zeros((3, 2)), name=f"p{i}.{k}", person=f"p{i}")
        for i in range(10)
        for k in range(2)
    ]
    train, test = split_by_person(pieces, 0.3, seed=1)
    assert len(test) == 6 and len(train) == 14
    assert {t.person for t in train}.isdisjoint({t.person for t in test})
    again = split_by_person(pieces, 0.3, seed=1)
    assert [t.name for t in again[1]] == [t.name for t in test]


def test_grid_search_picks_on_train_and_scores_test() -> None:
    scenes = {"a": _walkers(16, seed=5, noise=0.08), "b": _walkers(16, seed=6, noise=0.08)}
    ticks: list[tuple[int, int]] = []
    result = grid_search(
        "cv",
        {"window_s": [0.4, 1.2, 2.8]},
        scenes,
        obs=8,
        pred=12,
        stride=2,
        baselines=[ModelSpec.of("cv", label="cv default")],
        progress=lambda k, total: ticks.append((k, total)),
    )
    best = result.best
    assert best.test is not None and np.isfinite(best.test["ade"])
    assert all(c.test is None for c in result.candidates[1:])
    trains = [c.train["ade"] for c in result.candidates]
    assert trains == sorted(trains)
    # 8 cm of noise and slow turns: a longer velocity window beats a single step
    assert best.params["window_s"] > 0.4
    assert set(result.baselines["cv default"]) == {"train", "test"}
    assert sum(k for k, _ in ticks) == ticks[0][1]
    assert set(result.n_train) == {"a", "b"} and all(n > 0 for n in result.n_test.values())
    with pytest.raises(ValueError, match="no parameter"):
        grid_search("cv", {"C": [1.0]}, scenes)
