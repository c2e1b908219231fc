"""One campaign episode as a task: what a worker process or a Ray task runs.

:func:`run_episode_task` takes an :class:`~pfctl.bench.plan.EpisodeSpec` and returns the
episode's *record*, plain JSON-able data; it never raises for a failed episode (the record's
``status`` is ``error`` with the message). The episode is what ``pfctl follow`` / ``pfctl search
--backend sim --seed SEED`` does, headless: learn the target in the simulator with the episode's
seed (the faces depend on it), build the simulated house with that seed, for ``search`` hide the
target (a region chosen by the seed, or one of ``scenario.randomize.hide_in``), run the mission's
follower for the duration, and measure (:mod:`pfctl.core.metrics`).

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
import math
import os
import socket
import time
import traceback
import uuid
from pathlib import Path
from typing import Any

import numpy as np

from pfctl.bench.plan import EpisodeSpec

__all__ = [
    "BLAS_THREAD_VARIABLES",
    "error_record",
    "one_blas_thread",
    "record_header",
    "run_episode_task",
]

#: Environment variables that give numpy's BLAS / OpenMP one thread (read when it loads).
BLAS_THREAD_VARIABLES = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")
#: How the follower re-acquired a lost target (:class:`~pfctl.core.metrics.Reacquisition`).
HOW = ("prediction", "waypoint_search", "other")


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


def run_episode_task(spec: EpisodeSpec) -> dict[str, Any]:
    """Run the episode ``spec`` and return its record (module docstring); never raises for a
    failed episode."""
    run: dict[str, Any] = {
        "id": uuid.uuid4().hex,
        "host": socket.gethostname(),
        "pid": os.getpid(),
        "started": _now(),
    }
    one_blas_thread()
    try:
        status, metrics, timing = _run(spec)
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


def _run(spec: EpisodeSpec) -> tuple[str, dict[str, Any], dict[str, Any]]:
    from rich.console import Console

    from pfctl.app.episodes import hide_target, run_sim_episode, target_profile
    from pfctl.app.sim import sim_robot
    from pfctl.core.metrics import MetricParams, follow_metrics, search_metrics

    mission = spec.mission
    source = f"{spec.mission_file} [{spec.variant}]"
    start = time.perf_counter()
    deadline = start + spec.timeout if spec.timeout > 0 else math.inf
    profile = target_profile(mission, None, spec.seed, Console(stderr=True, quiet=True), source)
    learn_s = time.perf_counter() - start
    robot = sim_robot(mission, spec.seed, source)
    region = None
    with robot:
        if spec.task == "search":
            region = hide_target(mission, robot, None)
        result = run_sim_episode(
            mission,
            robot,
            profile,
            spec.duration,
            stop=lambda: time.perf_counter() > deadline,
            until_found=spec.task == "search",
        )
    lo, hi = mission.control.following_band
    params = MetricParams(band=(lo, hi))
    if spec.task == "search":
        found = search_metrics(result.log, params)
        metrics: dict[str, Any] = {
            "found": found.found,
            "time_to_find_s": found.time_to_find_s,
            "distance_m": found.distance_m,
            "collisions": found.collisions,
            "region": region,
        }
    else:
        follow = follow_metrics(result.log, params)
        metrics = {
            "following_rate": follow.following_rate,
            "first_identified_s": follow.first_identified_s,
            "losses": follow.losses,
            "reacquired": len(follow.reacquisitions),
            "unrecovered_losses": follow.unrecovered_losses,
            **{f"by_{how}": sum(r.how == how for r in follow.reacquisitions) for how in HOW},
            "refind_times_s": [r.time_to_refind for r in follow.reacquisitions],
            "median_time_to_refind_s": follow.median_time_to_refind_s,
            "identity_switches": follow.identity_switches,
            "collisions": follow.collisions,
            "distance_m": follow.distance_m,
            "duration_s": follow.duration_s,
        }
    metrics["sim_time_s"] = result.sim_time
    ticks = 1000.0 * np.asarray(result.tick_seconds, dtype=float)
    timing = {
        "wall_s": time.perf_counter() - start,
        "learn_wall_s": learn_s,
        "episode_wall_s": result.wall_time,
        "tick_ms_median": float(np.median(ticks)) if len(ticks) else None,
        "tick_ms_p99": float(np.percentile(ticks, 99)) if len(ticks) else None,
    }
    return ("timeout" if result.interrupted else "ok"), metrics, timing
