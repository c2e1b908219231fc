"""One campaign episode as a task: what a worker process or a Ray task runs.

:func:`run_episode_task` takes an :class:`~pfctl.bench.plan.EpisodeSpec` and the function that
runs one episode (an :data:`Episode`, given by the app:
:func:`pfctl.app.campaign.run_campaign_episode`, what ``pfctl follow`` / ``pfctl search
--backend sim --seed SEED`` does, headless) and returns the episode's *record*, plain JSON-able
data; it never raises for a failed episode (the record's ``status`` is ``error`` with the
message).

Given the seed an episode is deterministic (the simulator is seeded, the face worker's timing is
``deterministic`` in the simulator, one BLAS thread): the record's ``metrics`` are the same in any
process, on any worker. Timings, process and run id are kept apart from them (``timing``,
``run``).

Record fields: ``mission`` (label), ``mission_file``, ``variant``, ``index``, ``seed``, ``task``,
``config`` (the campaign's fingerprint), ``status`` (``ok``, ``timeout``: ended after the
spec's wall-clock limit, ``error``), ``error``, ``metrics``, ``timing`` and ``run`` (``id``: a
fresh UUID per run, ``host``, ``pid``, ``started``/``finished``: UTC ISO 8601).
"""

from __future__ import annotations

import datetime as dt
import os
import socket
import traceback
import uuid
from collections.abc import Callable
from pathlib import Path
from typing import Any

from pfctl.bench.plan import EpisodeSpec

__all__ = [
    "BLAS_THREAD_VARIABLES",
    "Episode",
    "error_record",
    "one_blas_thread",
    "record_header",
    "run_episode_task",
]

#: Environment variables that give numpy's BLAS / OpenMP one thread (read when it loads).
BLAS_THREAD_VARIABLES = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")
Episode = Callable[[EpisodeSpec], tuple[str, dict[str, Any], dict[str, Any]]]
"""What runs one episode: ``spec`` → (status ``ok``/``timeout``, metrics, timing). The app gives
it (:func:`pfctl.app.campaign.run_campaign_episode`); it must be a module-level function, so a
worker process or a Ray task can import it."""


def one_blas_thread() -> None:
    """One BLAS/OpenMP thread in this process from now on (and in the processes it starts)."""
    for name in BLAS_THREAD_VARIABLES:
        os.environ[name] = "1"
    try:
        from threadpoolctl import threadpool_limits
    except ImportError:  # pragma: no cover - scikit-learn depends on it
        return
    threadpool_limits(limits=1)


def _now() -> str:
    return dt.datetime.now(dt.timezone.utc).isoformat(timespec="milliseconds")


def record_header(spec: EpisodeSpec) -> dict[str, Any]:
    """The fields of a record that name its episode (module docstring)."""
    return {
        "mission": spec.mission_label,
        "mission_file": spec.mission_file,
        "variant": spec.variant,
        "index": spec.index,
        "seed": spec.seed,
        "task": spec.task,
        "config": spec.config,
    }


def error_record(
    spec: EpisodeSpec, message: str, *, run: dict[str, Any] | None = None
) -> dict[str, Any]:
    """The record of an episode that did not finish: ``status`` ``error`` and ``message``."""
    return {
        **record_header(spec),
        "status": "error",
        "error": message,
        "metrics": None,
        "timing": None,
        "run": run or {"id": uuid.uuid4().hex, "host": None, "pid": None},
    }


def run_episode_task(spec: EpisodeSpec, episode: Episode) -> dict[str, Any]:
    """Run ``episode`` for ``spec`` and return its record (module docstring); never raises for
    a failed episode."""
    run: dict[str, Any] = {
        "id": uuid.uuid4().hex,
        "host": socket.gethostname(),
        "pid": os.getpid(),
        "started": _now(),
    }
    one_blas_thread()
    try:
        status, metrics, timing = episode(spec)
    except Exception as err:  # any failure of the episode becomes its record
        last = traceback.extract_tb(err.__traceback__)[-1:] if err.__traceback__ else []
        where = f" ({Path(last[0].filename).name}:{last[0].lineno})" if last else ""
        message = f"{type(err).__name__}: {err}{where}".replace("\n", " ")
        run["finished"] = _now()
        return error_record(spec, message, run=run)
    run["finished"] = _now()
    return {
        **record_header(spec),
        "status": status,
        "error": None if status == "ok" else "ended after the wall-clock timeout",
        "metrics": metrics,
        "timing": timing,
        "run": run,
    }
