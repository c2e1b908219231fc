"""Measuring predictors on real tracks: observe/predict windows, ADE and FDE, time per call.

The standard protocol of the pedestrian-prediction literature (ETH/UCY): every run of
``obs + pred`` consecutive samples of a track is a window; a predictor is fitted on the first
``obs`` samples and asked for the next ``pred``; the *average displacement error* (ADE) is the mean
Euclidean distance over the ``pred`` predicted points and the *final displacement error* (FDE)
the distance at the last one, in metres. ``ms_per_call`` is the mean wall time of one
``fit`` + ``predict`` (the cost the robot pays each time it loses the target, §II-E).

Windows are evaluated in chunks, in this process or in ``jobs`` worker processes; a ``progress``
callback receives the number of windows finished after each chunk (core never draws progress
bars itself).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterable, Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pfctl.core.prediction.models import make_model
from pfctl.core.prediction.trajectories import Trajectory

__all__ = [
    "ModelSpec",
    "Score",
    "Windows",
    "evaluate",
    "make_windows",
    "window_errors",
]

FloatArray = NDArray[np.float64]
Progress = Callable[[int], None]


@dataclass(frozen=True, eq=False)
class Windows:
    """Observe/predict windows as stacked arrays (n windows).

    ``t_obs`` (n, obs), ``xy_obs`` (n, obs, 2), ``t_pred`` (n, pred), ``xy_pred`` (n, pred, 2);
    ``track`` (n,) the index of each window's track in the list given to :func:`make_windows`.
    """

    t_obs: FloatArray
    xy_obs: FloatArray
    t_pred: FloatArray
    xy_pred: FloatArray
    track: NDArray[np.intp]

    def __len__(self) -> int:
        return len(self.t_obs)

    def take(self, index: NDArray[np.intp] | slice) -> Windows:
        """The windows at ``index`` (an index array or a slice)."""
        return Windows(
            self.t_obs[index],
            self.xy_obs[index],
            self.t_pred[index],
            self.xy_pred[index],
            self.track[index],
        )


def make_windows(
    tracks: Sequence[Trajectory], obs: int = 8, pred: int = 12, stride: int = 1
) -> Windows:
    """Every run of ``obs + pred`` consecutive samples of every track, ``stride`` samples apart."""
    if obs < 1 or pred < 1 or stride < 1:
        raise ValueError(f"need obs ≥ 1, pred ≥ 1, stride ≥ 1; got {obs}, {pred}, {stride}")
    n = obs + pred
    t_all: list[FloatArray] = []
    xy_all: list[FloatArray] = []
    which: list[NDArray[np.intp]] = []
    for i, tr in enumerate(tracks):
        if len(tr) < n:
            continue
        starts = np.arange(0, len(tr) - n + 1, stride)
        idx = starts[:, None] + np.arange(n)[None, :]
        t_all.append(tr.t[idx])
        xy_all.append(tr.xy[idx])
        which.append(np.full(len(starts), i, dtype=np.intp))
    if not t_all:
        empty = np.empty((0, n))
        return Windows(
            empty[:, :obs],
            np.empty((0, obs, 2)),
            empty[:, obs:],
            np.empty((0, pred, 2)),
            np.empty(0, dtype=np.intp),
        )
    t = np.concatenate(t_all)
    xy = np.concatenate(xy_all)
    return Windows(t[:, :obs], xy[:, :obs], t[:, obs:], xy[:, obs:], np.concatenate(which))


@dataclass(frozen=True)
class ModelSpec:
    """A predictor to evaluate: its name in :data:`pfctl.core.prediction.models.MODELS` and
    parameters.

    ``label`` names it in tables (default: the name). Plain values only, so it can be sent to a
    worker process.
    """

    name: str
    params: tuple[tuple[str, Any], ...] = ()
    label: str = ""

    @classmethod
    def of(cls, name: str, label: str = "", **params: Any) -> ModelSpec:
        return cls(name, tuple(sorted(params.items())), label or name)

    @property
    def title(self) -> str:
        return self.label or self.name

    def build(self) -> Any:
        return make_model(self.name, **dict(self.params))


@dataclass(frozen=True)
class Score:
    """ADE and FDE (m) over ``n`` windows and the mean milliseconds per fit + predict."""

    ade: float
    fde: float
    n: int
    ms_per_call: float

    def as_dict(self) -> dict[str, float | int]:
        return {"ade": self.ade, "fde": self.fde, "n": self.n, "ms_per_call": self.ms_per_call}


def window_errors(spec: ModelSpec, windows: Windows) -> tuple[FloatArray, FloatArray, float]:
    """Per-window ADE and FDE of ``spec`` and the total seconds spent in fit + predict."""
    n = len(windows)
    ade = np.empty(n)
    fde = np.empty(n)
    spent = 0.0
    for i in range(n):
        start = time.perf_counter()
        model = spec.build().fit(windows.t_obs[i], windows.xy_obs[i])
        guess = model.predict(windows.t_pred[i])
        spent += time.perf_counter() - start
        d = np.linalg.norm(guess - windows.xy_pred[i], axis=1)
        ade[i] = d.mean()
        fde[i] = d[-1]
    return ade, fde, spent


def _chunk_job(
    spec: ModelSpec, windows: Windows, label: int, part: int
) -> tuple[int, int, FloatArray, FloatArray, float]:
    ade, fde, spent = window_errors(spec, windows)
    return label, part, ade, fde, spent


def _chunks(n: int, size: int) -> Iterable[slice]:
    for start in range(0, n, size):
        yield slice(start, min(n, start + size))


def evaluate(
    specs: Sequence[ModelSpec],
    windows: Windows,
    jobs: int = 1,
    progress: Progress | None = None,
    chunk: int = 256,
) -> dict[str, Score]:
    """:class:`Score` of every model on every window, keyed by ``spec.title``.

    ``jobs > 1`` spreads chunks of ``chunk`` windows over that many processes. ``progress(k)`` is
    called with ``k`` windows done (per model, so the total is ``len(specs) * len(windows)``).
    """
    results = evaluate_per_window(specs, windows, jobs, progress, chunk)
    return {
        title: Score(
            ade=float(ade.mean()) if len(ade) else float("nan"),
            fde=float(fde.mean()) if len(fde) else float("nan"),
            n=len(ade),
            ms_per_call=1000.0 * spent / max(len(ade), 1),
        )
        for title, (ade, fde, spent) in results.items()
    }


def evaluate_per_window(
    specs: Sequence[ModelSpec],
    windows: Windows,
    jobs: int = 1,
    progress: Progress | None = None,
    chunk: int = 256,
) -> dict[str, tuple[FloatArray, FloatArray, float]]:
    """Per-window ADE and FDE arrays and total seconds of every model (see :func:`evaluate`)."""
    titles = [s.title for s in specs]
    if len(set(titles)) != len(titles):
        raise ValueError(f"model labels must be unique, got {titles}")
    parts = list(_chunks(len(windows), max(1, chunk)))
    ade = {t: [np.empty(0)] * len(parts) for t in titles}
    fde = {t: [np.empty(0)] * len(parts) for t in titles}
    spent = dict.fromkeys(titles, 0.0)

    def collect(result: tuple[int, int, FloatArray, FloatArray, float]) -> None:
        label, part, a, f, s = result
        title = titles[label]
        ade[title][part], fde[title][part] = a, f
        spent[title] += s
        if progress is not None:
            progress(len(a))

    tasks = [
        (spec, windows.take(sl), k, p) for k, spec in enumerate(specs) for p, sl in enumerate(parts)
    ]
    if jobs <= 1 or len(tasks) <= 1:
        for task in tasks:
            collect(_chunk_job(*task))
    else:
        with ProcessPoolExecutor(max_workers=jobs) as pool:
            futures = [pool.submit(_chunk_job, *task) for task in tasks]
            for future in as_completed(futures):
                collect(future.result())
    return {
        t: (
            np.concatenate(ade[t]) if parts else np.empty(0),
            np.concatenate(fde[t]) if parts else np.empty(0),
            spent[t],
        )
        for t in titles
    }
