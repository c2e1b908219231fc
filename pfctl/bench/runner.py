"""Running campaign episodes: local worker processes, or Ray tasks on a cluster.

Both run the same task, :func:`pfctl.bench.episode.run_episode_task` with the ``episode`` function
the caller gives (:func:`pfctl.app.campaign.run_campaign_episode`), and hand each record to
``on_record`` in the calling thread as the episode finishes (in finishing order). Neither
schedules anything itself:

- :func:`run_in_processes`: a :class:`concurrent.futures.ProcessPoolExecutor` with the ``spawn``
  start method (PyBullet connections must not be forked) and a fresh process per episode
  (``max_tasks_per_child=1``: no memory, allocator settings or PyBullet state carried from one
  episode to the next). Workers ignore SIGINT: Ctrl-C is the caller's, which stops them.
- :func:`run_on_ray`: the task as a ``ray.remote`` function (one CPU each, no retries) on the
  cluster at ``address`` — ``auto`` (the cluster this machine belongs to), ``ray://HOST:PORT``
  (Ray Client), or ``local`` (a new Ray instance in this process with ``workers`` CPUs). Ray is
  imported only here; without it the error says how to install it. The cluster's Python
  environment must have pfctl installed (and the missions' map files at the same paths).

A KeyboardInterrupt while waiting stops the running episodes (worker processes terminated, Ray
tasks cancelled) and is raised again; the records already handed over are the caller's.
"""

from __future__ import annotations

import contextlib
import multiprocessing as mp
import signal
from collections.abc import Callable, Sequence
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from typing import Any

from pfctl.bench.episode import Episode, error_record, one_blas_thread, run_episode_task
from pfctl.bench.plan import EpisodeSpec
from pfctl.errors import UserError

__all__ = ["RAY_INSTALL", "WorkerDiedError", "ray_available", "run_in_processes", "run_on_ray"]

OnRecord = Callable[[dict[str, Any]], None]
#: How to get Ray (the ``ray`` extra of pfctl).
RAY_INSTALL = "pip install 'pfctl[ray]' (or pip install ray)"


class WorkerDiedError(RuntimeError):
    """A worker process died without answering (killed, or crashed in native code); the
    episodes that had not finished were not recorded."""


def _init_worker() -> None:
    """Worker process start: Ctrl-C is the campaign's to handle; one BLAS thread."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    one_blas_thread()


def _terminate(pool: ProcessPoolExecutor) -> None:
    """Stop ``pool`` now: cancel what has not started, terminate the running workers."""
    processes = list(getattr(pool, "_processes", {}).values())  # no public handle before 3.14
    pool.shutdown(wait=False, cancel_futures=True)
    for process in processes:
        if process.is_alive():
            process.terminate()
    for process in processes:
        process.join(timeout=10)
        if process.is_alive():
            process.kill()
            process.join()


def run_in_processes(
    specs: Sequence[EpisodeSpec], workers: int, on_record: OnRecord, episode: Episode
) -> None:
    """Run ``specs`` with ``episode`` in at most ``workers`` spawned processes (module
    docstring).

    Raises:
        WorkerDiedError: a worker process died; the unfinished episodes were not recorded.
        KeyboardInterrupt: after the workers were stopped.
    """
    if not specs:
        return
    pool = ProcessPoolExecutor(
        max_workers=max(1, min(workers, len(specs))),
        mp_context=mp.get_context("spawn"),
        initializer=_init_worker,
        max_tasks_per_child=1,
    )
    try:
        running: dict[Future[dict[str, Any]], EpisodeSpec] = {
            pool.submit(run_episode_task, spec, episode): spec for spec in specs
        }
        while running:
            done, _ = wait(running, timeout=1.0, return_when=FIRST_COMPLETED)
            for future in done:
                spec = running.pop(future)
                try:
                    record = future.result()
                except BrokenProcessPool:
                    raise WorkerDiedError(
                        f"a worker process died (killed, or crashed in native code); "
                        f"{len(running) + 1} episodes were not run"
                    ) from None
                except Exception as err:  # the record could not come back (pickling)
                    record = error_record(spec, f"{type(err).__name__}: {err}")
                on_record(record)
    except BaseException:
        _terminate(pool)
        raise
    pool.shutdown(wait=True)


def ray_available() -> bool:
    """Whether ``import ray`` would work (without importing it)."""
    import importlib.util

    return importlib.util.find_spec("ray") is not None


def run_on_ray(
    specs: Sequence[EpisodeSpec],
    address: str,
    workers: int,
    on_record: OnRecord,
    episode: Episode,
) -> None:
    """Run ``specs`` as Ray tasks on the cluster at ``address`` (module docstring).

    Raises:
        UserError: Ray is not installed, or the cluster cannot be reached.
        KeyboardInterrupt: after the unfinished tasks were cancelled.
    """
    try:
        import ray
    except ImportError:
        raise UserError(f"--ray {address}: Ray is not installed; {RAY_INSTALL}") from None
    if not specs:
        return
    started_here = not ray.is_initialized()
    if started_here:
        options: dict[str, Any] = {"include_dashboard": False, "log_to_driver": False}
        if address == "local":
            options["num_cpus"] = max(1, workers)
        try:
            ray.init(address=address, **options)
        except (ConnectionError, RuntimeError, ValueError) as err:
            message = str(err).strip().splitlines()[0] if str(err).strip() else type(err).__name__
            raise UserError(f"--ray {address}: cannot start or reach Ray: {message}") from None
    try:
        task = ray.remote(num_cpus=1, max_retries=0)(run_episode_task)
        refs = {task.remote(spec, episode): spec for spec in specs}
        pending = list(refs)
        try:
            while pending:
                done, pending = ray.wait(pending, num_returns=1, timeout=1.0)
                for ref in done:
                    try:
                        record = ray.get(ref)
                    except Exception as err:  # the worker died, or the task was cancelled
                        first = str(err).strip().splitlines()[0] if str(err).strip() else ""
                        record = error_record(refs[ref], f"Ray: {type(err).__name__}: {first}")
                    on_record(record)
        except BaseException:
            for ref in pending:
                with contextlib.suppress(Exception):  # already finished or gone
                    ray.cancel(ref, force=True)
            raise
    finally:
        if started_here:
            ray.shutdown()
