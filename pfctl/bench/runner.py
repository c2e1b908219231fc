"""Running campaign episodes: local worker processes, or Ray tasks on a cluster.

Both run the same task, :func:`pfctl.bench.episode.run_episode_task` with the ``episode`` function
the caller gives (:func:`pfctl.app.campaign.run_campaign_episode`), and hand each record to
``on_record`` in the calling thread as the episode finishes (in finishing order). Neither
schedules anything itself:

- :func:`run_in_processes`: a fresh process per episode (no memory, allocator settings or PyBullet
  state carried from one episode to the next), started with the ``spawn`` start method (PyBullet
  connections must not be forked), at most ``workers`` at a time; the record comes back on a
  pipe. Workers are born with Ctrl-C blocked and ignore it, and SIGINT and SIGTERM are held back
  in the caller while one starts (either, at that moment, would otherwise make the new worker
  print a traceback): they are the caller's, which stops the workers. On Linux a worker
  dies with the calling thread's process (``PR_SET_PDEATHSIG``). A worker that dies without
  answering (``kill -9``, a crash in native code) has its episode run again on a new worker, once
  (``on_retry`` says so); if that one dies too the episode's record is an ``error`` saying so and
  the others go on.
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
import ctypes
import multiprocessing as mp
import re
import signal
import sys
import threading
from collections import deque
from collections.abc import Callable, Iterator, Sequence
from multiprocessing.connection import Connection, wait
from typing import Any

from pfctl.bench.episode import Episode, error_record, one_blas_thread, run_episode_task
from pfctl.bench.plan import EpisodeSpec
from pfctl.errors import UserError

__all__ = [
    "RAY_ADDRESS",
    "RAY_INSTALL",
    "connect_ray",
    "disconnect_ray",
    "ray_address_issue",
    "ray_available",
    "run_in_processes",
    "run_on_ray",
]

OnRecord = Callable[[dict[str, Any]], None]
OnRetry = Callable[[EpisodeSpec, str], None]
#: How to get Ray (the ``ray`` extra of pfctl).
RAY_INSTALL = "pip install 'pfctl[ray]' (or pip install ray)"
#: Runs of an episode whose worker died before the episode is recorded as an error.
ATTEMPTS = 2
#: Seconds a worker has to end after it answered, or after it was told to stop, before it is
#: killed.
GRACE_S = 5.0


def _worker(spec: EpisodeSpec, episode: Episode, answer: Connection, tied: bool) -> None:
    """A worker process: Ctrl-C is the campaign's (ignored, then unblocked: it was blocked from
    birth), one BLAS thread; run the episode and send its record back."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})
    if tied and sys.platform.startswith("linux"):
        with contextlib.suppress(OSError, AttributeError):
            ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGTERM, 0, 0, 0)  # PDEATHSIG
    one_blas_thread()
    record = run_episode_task(spec, episode)
    try:
        answer.send(record)
    except (TypeError, ValueError, AttributeError) as err:  # the record would not pickle
        answer.send(error_record(spec, f"{type(err).__name__}: {err}"))
    answer.close()


@contextlib.contextmanager
def _signals_held() -> Iterator[None]:
    """SIGINT and SIGTERM held back while a worker starts, then handled as they would have been.

    A KeyboardInterrupt raised by a handler halfway through ``Process.start`` leaves a child
    that never gets its start-up data (it prints an ``EOFError`` traceback). And the child is
    born with SIGINT blocked, so a Ctrl-C on the terminal (sent to the whole process group)
    cannot interrupt its start-up either (:func:`_worker` ignores it, then unblocks it).
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    caught: list[int] = []
    held = (signal.SIGINT, signal.SIGTERM)
    previous = {s: signal.signal(s, lambda signum, frame: caught.append(signum)) for s in held}
    signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})
        for signum, handler in previous.items():
            signal.signal(signum, handler)
        for signum in dict.fromkeys(caught):
            signal.raise_signal(signum)


def _how(process: mp.process.BaseProcess) -> str:
    code = process.exitcode
    if code is not None and code < 0:
        with contextlib.suppress(ValueError):
            return f"killed by {signal.Signals(-code).name}"
        return f"killed by signal {-code}"
    return f"exit status {code}"


def _stop(process: mp.process.BaseProcess, *, now: bool) -> None:
    """End ``process`` (``now``: terminate it first) and reap it; killed after :data:`GRACE_S`."""
    if now and process.is_alive():
        process.terminate()
    process.join(GRACE_S)
    if process.is_alive():
        process.kill()
        process.join()


class _Running:
    """The worker processes out at once: each one's pipe, process, episode and attempt."""

    def __init__(self, episode: Episode) -> None:
        self.episode = episode
        self.context = mp.get_context("spawn")
        self.by_pipe: dict[Connection, tuple[mp.process.BaseProcess, EpisodeSpec, int]] = {}
        self.ending: list[mp.process.BaseProcess] = []
        """Workers that answered or died, not yet reaped."""

    def start(self, spec: EpisodeSpec, attempt: int) -> None:
        answer, child_end = self.context.Pipe(duplex=False)
        tied = threading.current_thread() is threading.main_thread()
        process = self.context.Process(
            target=_worker,
            args=(spec, self.episode, child_end, tied),
            name=f"pfctl-bench-{spec.seed}",
            daemon=False,
        )
        with _signals_held():
            try:
                process.start()
            finally:
                child_end.close()  # the worker holds the only write end: EOF when it dies
            self.by_pipe[answer] = (process, spec, attempt)

    def receive(
        self, pipe: Connection
    ) -> tuple[EpisodeSpec, int, dict[str, Any] | None, mp.process.BaseProcess]:
        """The episode of ``pipe``, its attempt, its record (None: the worker died without
        answering) and its worker (to :meth:`reap`)."""
        process, spec, attempt = self.by_pipe.pop(pipe)
        self.ending.append(process)
        try:
            record: dict[str, Any] | None = pipe.recv()
        except (EOFError, OSError):
            record = None
        except Exception as err:  # a record that would not unpickle here
            record = error_record(spec, f"{type(err).__name__}: {err}")
        pipe.close()
        return spec, attempt, record, process

    def reap(self, process: mp.process.BaseProcess) -> str:
        """Wait for ``process`` to end (killed after :data:`GRACE_S`); how it ended."""
        _stop(process, now=False)
        how = _how(process)
        self.ending.remove(process)
        process.close()
        return how

    def stop_all(self) -> None:
        """Terminate every worker, then reap them."""
        processes = [p for p, _, _ in self.by_pipe.values()] + self.ending
        for process in processes:
            if process.is_alive():
                process.terminate()
        for process in processes:
            _stop(process, now=True)
            process.close()
        for pipe in self.by_pipe:
            pipe.close()
        self.by_pipe.clear()
        self.ending.clear()


def run_in_processes(
    specs: Sequence[EpisodeSpec],
    workers: int,
    on_record: OnRecord,
    episode: Episode,
    on_retry: OnRetry | None = None,
) -> None:
    """Run ``specs`` with ``episode`` in at most ``workers`` spawned processes, a fresh one each
    (module docstring); ``on_retry(spec, how)`` when a worker died and its episode runs again.

    Raises:
        KeyboardInterrupt: after the workers were stopped.
    """
    queue = deque((spec, 1) for spec in specs)
    running = _Running(episode)
    try:
        while queue or running.by_pipe:
            while queue and len(running.by_pipe) < max(1, workers):
                running.start(*queue.popleft())
            for pipe in wait(list(running.by_pipe)):
                spec, attempt, record, process = running.receive(pipe)  # type: ignore[arg-type]
                if record is not None:
                    on_record(record)  # before the worker is reaped: handed over at once
                how = running.reap(process)
                if record is not None:
                    continue
                if attempt < ATTEMPTS:
                    if on_retry is not None:
                        on_retry(spec, how)
                    queue.appendleft((spec, attempt + 1))
                else:
                    on_record(
                        error_record(
                            spec, f"the worker process died ({how}) {attempt} times; not run again"
                        )
                    )
    except BaseException:
        running.stop_all()
        raise


def ray_available() -> bool:
    """Whether ``import ray`` would work (without importing it)."""
    import importlib.util

    return importlib.util.find_spec("ray") is not None


#: What ``--ray`` takes (module docstring), checked before Ray is imported: Ray's own message for
#: anything else ("Invalid address format") came only after the campaign's files were written.
RAY_ADDRESS = re.compile(r"auto|local|(ray://)?(\[[0-9A-Fa-f:.]+\]|[A-Za-z0-9._-]+):\d{1,5}")


def ray_address_issue(address: str) -> str | None:
    """What is wrong with ``address`` as a ``--ray`` value, or None if it has the form of one."""
    if RAY_ADDRESS.fullmatch(address) is None:
        return "expected auto, local, HOST:PORT or ray://HOST:PORT"
    return None


def connect_ray(address: str, workers: int) -> bool:
    """Start (``local``, with ``workers`` CPUs) or reach the Ray cluster at ``address``, unless
    this process is connected already; True when connected here (then :func:`run_on_ray` with
    ``owned`` shuts Ray down at the end). Done before a campaign writes anything.

    Raises:
        UserError: Ray is not installed, or the cluster cannot be started or reached.
    """
    try:
        import ray
    except ImportError:
        raise UserError(f"--ray {address}: Ray is not installed; {RAY_INSTALL}") from None
    if ray.is_initialized():
        return False
    options: dict[str, Any] = {"include_dashboard": False, "log_to_driver": False}
    if address == "local":
        options["num_cpus"] = max(1, workers)
    try:
        ray.init(address=address, **options)
    except (ConnectionError, RuntimeError, ValueError) as err:
        message = str(err).strip().splitlines()[0] if str(err).strip() else type(err).__name__
        raise UserError(f"--ray {address}: cannot start or reach Ray: {message}") from None
    return True


def disconnect_ray() -> None:
    """Shut down the Ray connection :func:`connect_ray` made."""
    import ray

    ray.shutdown()


def run_on_ray(
    specs: Sequence[EpisodeSpec],
    address: str,
    workers: int,
    on_record: OnRecord,
    episode: Episode,
    *,
    owned: bool = False,
) -> None:
    """Run ``specs`` as Ray tasks on the cluster at ``address`` (module docstring), connecting
    first unless connected already; Ray is shut down at the end when connected here or ``owned``
    (the caller's :func:`connect_ray` connected for this run).

    Raises:
        UserError: Ray is not installed, or the cluster cannot be reached.
        KeyboardInterrupt: after the unfinished tasks were cancelled.
    """
    if not specs:
        if owned:
            disconnect_ray()
        return
    started_here = connect_ray(address, workers) or owned
    import ray

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
            disconnect_ray()
