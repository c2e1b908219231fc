"""dlib's face search for Algorithm 2 (§II-E) in a worker process, off the control loop.

Algorithm 2 identifies the target by face first (:mod:`pfctl.core.perception.faces`: dlib's HOG
detector, the 5-point alignment and the ResNet embedding). The embedding takes most of a 10 Hz
tick's budget on one core and holds the GIL, and the HOG detector adds to it for every head, so
run inline they blow the tick's budget whenever a face is found (benchmarks/bench_identity.py).
:class:`FaceWorker` runs ``FaceEncoder(params).detect(crop, region)`` in a persistent child
process instead:

- the child is started with the ``spawn`` start method (the parent may hold PyBullet, which must
  not be forked), loads the three dlib models **once**, and serves jobs until it is closed;
- once the models are loaded (at normal priority: the parent waits for them), it lowers its own
  priority (``os.nice``, and Linux's ``SCHED_IDLE`` policy when ``idle``), so on
  one core the control loop preempts it at once and it runs in the loop's idle time; ``cpus``
  pins it (as a benchmark pins the loop);
- with ``idle``, a job that arrives while the parent is running (the loop submits mid-tick) is
  started only once the parent sleeps (Linux: its state in ``/proc``, looked at every
  millisecond, for at most :data:`PARENT_BUSY_WAIT_S`). SCHED_IDLE alone does not keep a freshly
  woken child off the CPU: at a scheduler tick it may be given a slice of the loop's tick
  (benchmarks/README.md, ``bench_follower.py``);
- only the **head crop** crosses the process boundary (the region of the frame to search, a few
  KB), never the frame; the boxes come back in the frame's pixels, and the embeddings are the
  ones the inline encoder gives for the same region (same code, same models);
- :meth:`submit` never blocks: at most ``max_in_flight`` jobs are out at once and a submit beyond
  that returns False (the caller tries again on a later frame); :meth:`poll` collects finished
  jobs without blocking; :meth:`wait` blocks for one job, with a timeout;
- jobs go down a plain pipe written by the caller's thread (no feeder thread competing for the
  GIL), widened on Linux so that a few crops never make :meth:`submit` wait for the child;
- :meth:`close` (or leaving the ``with`` block) stops the child and reaps it; a worker that is
  garbage-collected or still open at interpreter exit is stopped too. The child ignores Ctrl-C
  and SIGTERM (the parent decides when to stop) and ends quietly when its parent has died: on
  Linux the kernel kills it at once (``PR_SET_PDEATHSIG``, asked for when the worker is started
  from the parent's main thread, whose end is the process's), elsewhere the job pipe reaches its
  end (it finishes the job at hand first); a reply to a parent that is gone is dropped, never a
  traceback. A child that dies is reported as one line (:class:`FaceWorkerError`) by the next
  call.

One worker serves one :class:`~pfctl.core.perception.identity.identifier.TargetIdentifier` at a time
(its job keys are unique; an identifier ignores the results of jobs that are not its own).
"""

from __future__ import annotations

import contextlib
import ctypes
import math
import multiprocessing
import os
import signal
import sys
import threading
import time
import weakref
from collections.abc import Hashable, Iterable, Iterator
from dataclasses import dataclass, field, replace
from multiprocessing.connection import Connection, wait
from typing import Any

import numpy as np

try:
    import fcntl
except ImportError:  # pragma: no cover - not POSIX
    fcntl = None  # type: ignore[assignment]

from pfctl.core.perception.faces import Box, Face, FaceEncoder, FaceParams

#: How often (s) an idle child checks that its parent is still there.
PARENT_CHECK_S = 0.5
#: At most this long (s) an ``idle`` child waits for its running parent to sleep before a job.
PARENT_BUSY_WAIT_S = 0.1
#: Capacity asked for the jobs pipe (Linux ``F_SETPIPE_SZ``): room for a few head crops, so
#: :meth:`FaceWorker.submit` never waits for the child to read.
PIPE_BYTES = 1 << 20


class FaceWorkerError(RuntimeError):
    """The face worker failed (its process died, could not start, or a job raised); one line."""


@dataclass(frozen=True)
class FaceResult:
    """What the worker found for one job: the faces best first (boxes in the frame's pixels)."""

    job: Hashable
    faces: tuple[Face, ...]
    seconds: float
    """Wall time the child spent on the job (HOG detection, alignment and embeddings)."""
    cpu_seconds: float
    """CPU time of the child for the job (less than ``seconds`` when it was preempted)."""


@dataclass
class FaceWorkerStats:
    """Counters of one worker (parent side)."""

    submitted: int = 0
    refused: int = 0
    """Submits refused because ``max_in_flight`` jobs were out."""
    completed: int = 0
    faces: int = 0
    """Faces found (each one embedded) over the completed jobs."""
    job_seconds: list[float] = field(default_factory=list)
    job_cpu_seconds: list[float] = field(default_factory=list)
    load_seconds: float | None = None
    """How long the child took to load dlib and the models (None: not ready yet)."""


def crop_region(shape: tuple[int, ...], region: Box | None) -> Box | None:
    """``region`` clipped to an image of ``shape`` (the whole image when None); None when less
    than 4 px remain either way (:meth:`FaceEncoder.detect` finds nothing there)."""
    h, w = shape[:2]
    x0, y0, x1, y1 = (0, 0, w, h) if region is None else region
    x0, y0 = max(0, int(x0)), max(0, int(y0))
    x1, y1 = min(w, int(x1)), min(h, int(y1))
    if x1 - x0 < 4 or y1 - y0 < 4:
        return None
    return x0, y0, x1, y1


def _widen_pipe(conn: Connection, size: int) -> None:
    """Ask for a pipe buffer of ``size`` bytes (Linux; elsewhere, or when refused, the default
    stays and a large crop may make a send wait until the child reads)."""
    setsize = getattr(fcntl, "F_SETPIPE_SZ", 1031) if fcntl is not None else None
    if setsize is None or not sys.platform.startswith("linux"):
        return
    with contextlib.suppress(OSError):
        fcntl.fcntl(conn.fileno(), setsize, size)


def _shift(box: Box, dx: int, dy: int) -> Box:
    return box[0] + dx, box[1] + dy, box[2] + dx, box[3] + dy


def _lower_priority(nice: int, idle: bool, cpus: tuple[int, ...] | None) -> None:
    """Make this process yield to the control loop: nice, SCHED_IDLE, CPU affinity."""
    if nice > 0:
        with contextlib.suppress(OSError):
            os.nice(nice)
    if idle and hasattr(os, "SCHED_IDLE"):
        with contextlib.suppress(OSError):
            os.sched_setscheduler(0, os.SCHED_IDLE, os.sched_param(0))
    if cpus and hasattr(os, "sched_setaffinity"):
        with contextlib.suppress(OSError):
            os.sched_setaffinity(0, set(cpus))


def _running(pid: int) -> bool:
    """Whether process ``pid`` is running or runnable (Linux ``/proc/<pid>/stat`` state R);
    False when that cannot be read (not Linux, gone)."""
    try:
        with open(f"/proc/{pid}/stat", "rb") as f:
            stat = f.read()
    except OSError:
        return False
    end = stat.rfind(b")")  # the command name may hold spaces and parentheses
    return stat[end + 2 : end + 3] == b"R"


def wait_while_running(pid: int, limit_s: float, poll_s: float = 0.001) -> None:
    """Return once process ``pid`` is not running (it sleeps, e.g. between control ticks), or
    after ``limit_s`` seconds."""
    deadline = time.monotonic() + limit_s
    while _running(pid) and time.monotonic() < deadline:
        time.sleep(poll_s)


_PARENTS_SIGNALS = (signal.SIGINT, signal.SIGTERM)
"""Signals the child ignores: the parent handles them and then stops the child."""


@contextlib.contextmanager
def _started_ignoring(signals: tuple[int, ...]) -> Iterator[None]:
    """A child started inside ignores ``signals`` from its first instruction (an ignored signal
    stays ignored across exec, and Python then installs no handler): a Ctrl-C to the whole group
    while it imports must not kill it. This thread blocks them meanwhile, so that Linux keeps one
    that comes for this process pending for its own handler (blocked signals are never
    discarded as ignored)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    signal.pthread_sigmask(signal.SIG_BLOCK, signals)
    previous = {s: signal.signal(s, signal.SIG_IGN) for s in signals}
    try:
        yield
    finally:
        for s, handler in previous.items():
            signal.signal(s, handler)
        signal.pthread_sigmask(signal.SIG_UNBLOCK, signals)


def _die_with_parent() -> bool:
    """Have the kernel kill this process when its parent ends (Linux ``PR_SET_PDEATHSIG``; a
    no-op elsewhere); False when the parent has already gone."""
    parent = multiprocessing.parent_process()
    if sys.platform.startswith("linux"):
        with contextlib.suppress(OSError, AttributeError):
            ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGKILL, 0, 0, 0)  # PR_SET_PDEATHSIG
    return parent is None or parent.pid is None or os.getppid() == parent.pid


def _reply(results: Connection, message: tuple[str, Any, Any]) -> bool:
    """Send ``message`` to the parent; False when the parent is gone (the pipe is broken)."""
    try:
        results.send(message)
    except OSError:
        return False
    return True


def _serve(
    params: FaceParams,
    jobs: Connection,
    results: Connection,
    nice: int,
    idle: bool,
    cpus: tuple[int, ...] | None,
    tied: bool = False,
) -> None:
    """The child's main loop: load the models once, then answer jobs until told to stop (or
    the parent is gone). ``tied``: die with the parent (:func:`_die_with_parent`)."""
    # Ctrl-C and SIGTERM are the parent's to handle (a terminal, `timeout` and systemd signal
    # the whole group): it stops the run and then this child
    for signum in _PARENTS_SIGNALS:
        signal.signal(signum, signal.SIG_IGN)  # already from the start (_started_ignoring)
    if tied and not _die_with_parent():
        return
    t0 = time.perf_counter()
    try:
        from pfctl.core.perception.faces import _models

        _models()
        encoder = FaceEncoder(params)
    except BaseException as err:  # no dlib, no model files: tell the parent, then end
        _reply(results, ("error", None, f"{type(err).__name__}: {err}"))
        return
    # only now: under SCHED_IDLE, busy processes beside it would starve the models' loading,
    # which the parent waits for before the episode starts
    _lower_priority(nice, idle, cpus)
    if not _reply(results, ("ready", None, time.perf_counter() - t0)):
        return
    parent = multiprocessing.parent_process()
    while True:
        try:
            if not jobs.poll(PARENT_CHECK_S):
                if parent is not None and not parent.is_alive():
                    return
                continue
            msg = jobs.recv()
        except (EOFError, OSError):  # the parent closed the pipe or died
            return
        if msg is None:
            return
        job, crop, offset, scaled = msg
        if idle and parent is not None and parent.pid is not None:
            wait_while_running(parent.pid, PARENT_BUSY_WAIT_S)
        w0, c0 = time.perf_counter(), time.process_time()
        try:
            h, w = crop.shape[:2]
            found = encoder.detect(crop, (0, 0, w, h) if scaled else None)
            faces = tuple(replace(f, box=_shift(f.box, *offset)) for f in found)
            out: tuple[str, Any, Any] = (
                "done",
                job,
                (faces, time.perf_counter() - w0, time.process_time() - c0),
            )
        except Exception as err:  # a bad job is the parent's bug: report it, keep serving
            out = ("failed", job, f"{type(err).__name__}: {err}")
        if not _reply(results, out):  # the parent is gone
            return


def _shutdown(process: Any, jobs: Connection, results: Connection, timeout: float) -> None:
    """Stop the child (politely, then by force), reap it and close the channels."""
    if process.is_alive():
        with contextlib.suppress(OSError, ValueError):
            jobs.send(None)
        process.join(timeout)
    if process.is_alive():
        process.kill()  # it ignores SIGTERM
        process.join()
    jobs.close()
    results.close()


class FaceWorker:
    """``FaceEncoder(params).detect`` in a low-priority child process (module docstring).

    ``max_in_flight`` jobs may be out at once (submitted, not yet received back). ``nice`` and
    ``idle`` lower the child's priority; ``cpus`` pins it to those CPUs (default: the parent's
    affinity, inherited). The child starts at once; :meth:`wait_ready` waits until it has loaded
    the models (jobs submitted before that simply queue).
    """

    def __init__(
        self,
        params: FaceParams | None = None,
        *,
        max_in_flight: int = 2,
        nice: int = 10,
        idle: bool = True,
        cpus: Iterable[int] | None = None,
        start_method: str = "spawn",
    ) -> None:
        if max_in_flight < 1:
            raise ValueError(f"max_in_flight must be at least 1, got {max_in_flight}")
        self.params = params or FaceParams()
        self.max_in_flight = int(max_in_flight)
        self.stats = FaceWorkerStats()
        self._in_flight: set[Hashable] = set()
        self._done: dict[Hashable, FaceResult] = {}
        self._ready = False
        self._closed = False
        self._error: str | None = None
        ctx = multiprocessing.get_context(start_method)
        # jobs: a plain pipe written from this thread (no feeder thread to take the GIL),
        # widened so that a few head crops never block the writer
        job_end, self._jobs = ctx.Pipe(duplex=False)
        _widen_pipe(self._jobs, PIPE_BYTES)
        self._results, child_end = ctx.Pipe(duplex=False)
        self._process = ctx.Process(
            target=_serve,
            args=(
                self.params,
                job_end,
                child_end,
                int(nice),
                bool(idle),
                None if cpus is None else tuple(cpus),
                # the kernel's parent-death signal follows the starting thread, not the process
                threading.current_thread() is threading.main_thread(),
            ),
            name="pfctl-face-worker",
            daemon=True,
        )
        try:
            with _started_ignoring(_PARENTS_SIGNALS):
                self._process.start()
        except AssertionError as err:  # "daemonic processes are not allowed to have children"
            for conn in (self._jobs, self._results, child_end, job_end):
                conn.close()
            raise FaceWorkerError(f"face worker: cannot start it here: {err}") from None
        child_end.close()  # the child holds the only write end: EOF when it dies
        job_end.close()  # and the only read end of the jobs: EOF for it when this process dies
        self._finalizer = weakref.finalize(
            self, _shutdown, self._process, self._jobs, self._results, 2.0
        )

    # -- state --------------------------------------------------------------------------------

    @property
    def pid(self) -> int | None:
        """The child's process id."""
        return self._process.pid

    @property
    def in_flight(self) -> int:
        """Jobs submitted and not yet received back."""
        return len(self._in_flight)

    @property
    def ready(self) -> bool:
        """Whether the child has loaded the models (as far as the parent has heard)."""
        return self._ready

    @property
    def closed(self) -> bool:
        return self._closed

    # -- jobs ---------------------------------------------------------------------------------

    def submit(self, job: Hashable, rgb: np.ndarray, region: Box | None = None) -> bool:
        """Search ``region`` of ``rgb`` (as ``FaceEncoder.detect(rgb, region)``) under the key
        ``job``; only the region's pixels are sent. Never blocks: False when ``max_in_flight``
        jobs are out (try again later). A region of less than 4x4 pixels is answered at once
        with no face. ValueError if ``job`` is still out or unclaimed."""
        self._check_open()
        self._receive(0.0)
        if job in self._in_flight or job in self._done:
            raise ValueError(f"face worker: job {job!r} is already submitted")
        if len(self._in_flight) >= self.max_in_flight:
            self.stats.refused += 1
            return False
        self.stats.submitted += 1
        box = crop_region(rgb.shape, region)
        if box is None:
            self._done[job] = FaceResult(job, (), 0.0, 0.0)
            self.stats.completed += 1
            return True
        x0, y0, x1, y1 = box
        crop = np.ascontiguousarray(rgb[y0:y1, x0:x1, :3], dtype=np.uint8)
        self._in_flight.add(job)
        try:
            self._jobs.send((job, crop, (x0, y0), region is not None))
        except OSError:
            raise self._died() from None
        return True

    def poll(self) -> list[FaceResult]:
        """The jobs finished since the last call (never blocks), in the order they finished."""
        self._check_open()
        self._receive(0.0)
        done = list(self._done.values())
        self._done.clear()
        return done

    def wait(self, job: Hashable, timeout: float | None = 60.0) -> FaceResult:
        """Block until ``job`` is done (other jobs finishing meanwhile are kept for
        :meth:`poll`); TimeoutError after ``timeout`` seconds, KeyError for an unknown job."""
        self._check_open()
        deadline = None if timeout is None else time.monotonic() + timeout
        while job not in self._done:
            if job not in self._in_flight:
                raise KeyError(f"face worker: no job {job!r} was submitted")
            left = None if deadline is None else deadline - time.monotonic()
            if left is not None and left <= 0:
                raise TimeoutError(f"face worker: job {job!r} not done after {timeout:g} s")
            self._receive(left)
        return self._done.pop(job)

    def wait_slot(self, timeout: float | None = 60.0, *, most: int | None = None) -> None:
        """Block until fewer than ``max_in_flight`` jobs (or at most ``most``) are out;
        finished ones are kept for :meth:`poll`. TimeoutError after ``timeout`` seconds."""
        self._check_open()
        limit = self.max_in_flight - 1 if most is None else most
        deadline = None if timeout is None else time.monotonic() + timeout
        self._receive(0.0)
        while len(self._in_flight) > limit:
            left = None if deadline is None else deadline - time.monotonic()
            if left is not None and left <= 0:
                raise TimeoutError(f"face worker: still busy after {timeout:g} s")
            self._receive(left)

    def wait_idle(self, timeout: float | None = 60.0) -> None:
        """Block until no job is out (finished ones are kept for :meth:`poll`)."""
        self.wait_slot(timeout, most=0)

    def wait_ready(self, timeout: float | None = 60.0) -> float:
        """Block until the child has loaded the models; the seconds that took (in the child)."""
        self._check_open()
        deadline = None if timeout is None else time.monotonic() + timeout
        while not self._ready:
            left = None if deadline is None else deadline - time.monotonic()
            if left is not None and left <= 0:
                raise TimeoutError(f"face worker: not ready after {timeout:g} s")
            self._receive(left)
        assert self.stats.load_seconds is not None
        return self.stats.load_seconds

    # -- life cycle ---------------------------------------------------------------------------

    def close(self, timeout: float = 2.0) -> None:
        """Stop the child (it finishes the job at hand first, up to ``timeout`` s) and reap it;
        safe to call twice."""
        if self._closed:
            return
        self._closed = True
        self._finalizer.detach()
        _shutdown(self._process, self._jobs, self._results, timeout)

    def __enter__(self) -> FaceWorker:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # -- internals ----------------------------------------------------------------------------

    def _check_open(self) -> None:
        if self._closed:
            raise FaceWorkerError("face worker: used after close()")
        if self._error is not None:
            raise FaceWorkerError(self._error)

    def _died(self) -> FaceWorkerError:
        self._process.join(1.0)
        code = self._process.exitcode
        how = f"killed by signal {-code}" if code is not None and code < 0 else f"exit code {code}"
        self._error = (
            f"face worker: the child process (pid {self._process.pid}) died ({how}); "
            f"{len(self._in_flight)} face job(s) lost"
        )
        return FaceWorkerError(self._error)

    def _receive(self, timeout: float | None) -> None:
        """Take every message the child has sent, waiting up to ``timeout`` s for the first."""
        if timeout is None or timeout > 0:
            if timeout is not None and not math.isfinite(timeout):
                timeout = None
            wait([self._results, self._process.sentinel], timeout)
        while True:
            try:
                if not self._results.poll(0):
                    break
                kind, job, payload = self._results.recv()
            except (EOFError, OSError):
                raise self._died() from None
            if kind == "done":
                faces, seconds, cpu = payload
                self._in_flight.discard(job)
                self._done[job] = FaceResult(job, faces, seconds, cpu)
                self.stats.completed += 1
                self.stats.faces += len(faces)
                self.stats.job_seconds.append(seconds)
                self.stats.job_cpu_seconds.append(cpu)
            elif kind == "ready":
                self._ready = True
                self.stats.load_seconds = float(payload)
            elif kind == "failed":
                self._in_flight.discard(job)
                raise FaceWorkerError(f"face worker: job {job!r} failed in the child: {payload}")
            else:  # "error": the child could not start
                self._error = f"face worker: the child could not load dlib's models: {payload}"
                raise FaceWorkerError(self._error)
        if not self._process.is_alive():
            # it may have sent everything and exited: nothing more will come
            raise self._died()


__all__ = [
    "FaceResult",
    "FaceWorker",
    "FaceWorkerError",
    "FaceWorkerStats",
    "crop_region",
]
