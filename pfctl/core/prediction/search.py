"""Grid search of predictor hyperparameters with an honest split by person (§II-E, §III).

The paper fixes the SVR at C = 1000, ε = 0.01, γ = 1.0 with recency weights; whether those suit
another formulation or another sampling rate is an empirical question. :func:`grid_search`
answers it like scikit-learn's ``GridSearchCV`` with a group split: the people of every scene are
shuffled (seeded) and split into a *train* and a *test* part (all pieces of one person's track on
the same side, so no person is scored on windows it was tuned on); every combination of the grid
is scored on the train windows only, the best one is chosen there, and only that one (and any
baselines) is scored on the test windows. The score is the mean over scenes of ADE, FDE or their
average, so a large scene does not drown the small ones.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

from pfctl.core.prediction.evaluation import ModelSpec, Score, Windows, evaluate, make_windows
from pfctl.core.prediction.models import model_params
from pfctl.core.prediction.trajectories import Trajectory

__all__ = [
    "Candidate",
    "GridSearchResult",
    "grid_search",
    "param_grid",
    "split_by_person",
]

Metric = Literal["ade", "fde", "both"]


def param_grid(grid: Mapping[str, Sequence[Any]]) -> list[dict[str, Any]]:
    """Every combination of the values in ``grid`` (as ``sklearn``'s ``ParameterGrid``)."""
    keys = list(grid)
    for k in keys:
        if len(grid[k]) == 0:
            raise ValueError(f"grid parameter {k!r} has no values")
    return [dict(zip(keys, values, strict=True)) for values in itertools.product(*grid.values())]


def split_by_person(
    tracks: Sequence[Trajectory], test_fraction: float = 0.5, seed: int = 0
) -> tuple[list[Trajectory], list[Trajectory]]:
    """Tracks split into (train, test) by person, ``test_fraction`` of the people in test."""
    if not 0.0 < test_fraction < 1.0:
        raise ValueError(f"test_fraction must be in (0, 1), got {test_fraction}")
    people = sorted({t.person or t.name for t in tracks})
    rng = np.random.default_rng(seed)
    order = rng.permutation(len(people))
    n_test = min(len(people) - 1, max(1, round(test_fraction * len(people))))
    test_people = {people[i] for i in order[:n_test]}
    train = [t for t in tracks if (t.person or t.name) not in test_people]
    test = [t for t in tracks if (t.person or t.name) in test_people]
    return train, test


def _value(scores: Mapping[str, float], metric: Metric) -> float:
    if metric == "both":
        return 0.5 * (scores["ade"] + scores["fde"])
    return scores[metric]


@dataclass(frozen=True)
class Candidate:
    """One grid point: its parameters and scene-averaged scores (test only for the chosen one)."""

    params: dict[str, Any]
    train: dict[str, float]
    test: dict[str, float] | None = None


@dataclass(frozen=True)
class GridSearchResult:
    """All candidates, best first by the train score, and the test scores of best and baselines."""

    model: str
    metric: Metric
    candidates: list[Candidate]
    baselines: dict[str, dict[str, dict[str, float]]]
    n_train: dict[str, int]
    n_test: dict[str, int]

    @property
    def best(self) -> Candidate:
        return self.candidates[0]


def _scene_mean(scores: Mapping[str, Score]) -> dict[str, float]:
    return {
        "ade": float(np.mean([s.ade for s in scores.values()])),
        "fde": float(np.mean([s.fde for s in scores.values()])),
        "ms_per_call": float(np.mean([s.ms_per_call for s in scores.values()])),
    }


def _score_all(
    specs: Sequence[ModelSpec],
    windows: Mapping[str, Windows],
    jobs: int,
    progress: Callable[[int], None],
) -> dict[str, dict[str, Score]]:
    """spec title → scene → Score."""
    out: dict[str, dict[str, Score]] = {s.title: {} for s in specs}
    for scene, w in windows.items():
        for title, score in evaluate(specs, w, jobs=jobs, progress=progress).items():
            out[title][scene] = score
    return out


def grid_search(
    model: str,
    grid: Mapping[str, Sequence[Any]],
    scenes: Mapping[str, Sequence[Trajectory]],
    obs: int = 8,
    pred: int = 12,
    test_fraction: float = 0.5,
    seed: int = 0,
    metric: Metric = "ade",
    stride: int = 1,
    baselines: Sequence[ModelSpec] = (),
    jobs: int = 1,
    progress: Callable[[int, int], None] | None = None,
) -> GridSearchResult:
    """Tune ``model`` over ``grid`` on the train people of every scene; test the winner.

    ``scenes`` maps a scene name to its tracks; each scene is split by
    :func:`split_by_person` (same ``seed``). Windows are ``obs``/``pred`` samples, ``stride``
    samples apart. Candidates are ranked by the train score (mean over scenes of ``metric``);
    the best and every baseline are then scored on the test windows. ``progress(k, total)`` is
    called with ``k`` more windows evaluated out of ``total``.
    """
    unknown = set(grid) - set(model_params(model))
    if unknown:
        raise ValueError(f"model {model!r} has no parameter {', '.join(sorted(unknown))}")
    train_w: dict[str, Windows] = {}
    test_w: dict[str, Windows] = {}
    for scene, tracks in scenes.items():
        train, test = split_by_person(tracks, test_fraction, seed)
        train_w[scene] = make_windows(train, obs, pred, stride)
        test_w[scene] = make_windows(test, obs, pred, stride)
        if len(train_w[scene]) == 0 or len(test_w[scene]) == 0:
            raise ValueError(
                f"scene {scene!r}: too few windows of {obs}+{pred} samples to split "
                f"({len(train_w[scene])} train, {len(test_w[scene])} test)"
            )
    points = param_grid(grid)
    specs = [ModelSpec.of(model, label=f"{model}#{i}", **p) for i, p in enumerate(points)]
    n_train = sum(len(w) for w in train_w.values())
    n_test = sum(len(w) for w in test_w.values())
    total = (len(points) + len(baselines)) * n_train + (1 + len(baselines)) * n_test

    def tick(k: int) -> None:
        if progress is not None:
            progress(k, total)

    train_scores = _score_all(specs, train_w, jobs, tick)
    ranked = sorted(
        (
            Candidate(params=p, train=_scene_mean(train_scores[s.title]))
            for p, s in zip(points, specs, strict=True)
        ),
        key=lambda c: _value(c.train, metric),
    )
    best_spec = ModelSpec.of(model, label=f"{model} (best)", **ranked[0].params)
    test_scores = _score_all([best_spec, *baselines], test_w, jobs, tick)
    base_train = _score_all(list(baselines), train_w, jobs, tick) if baselines else {}
    ranked[0] = Candidate(
        ranked[0].params, ranked[0].train, _scene_mean(test_scores[best_spec.title])
    )
    return GridSearchResult(
        model=model,
        metric=metric,
        candidates=ranked,
        baselines={
            b.title: {
                "train": _scene_mean(base_train[b.title]),
                "test": _scene_mean(test_scores[b.title]),
            }
            for b in baselines
        },
        n_train={s: len(w) for s, w in train_w.items()},
        n_test={s: len(w) for s, w in test_w.items()},
    )
