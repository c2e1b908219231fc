"""The face worker process (Algorithm 2's face search off the control loop) and the identifier
with it: real photographs, the real dlib models in a real child process, no mocks."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import time
from collections.abc import Iterator
from pathlib import Path

import cv2
import numpy as np
import pytest
from skimage.data import astronaut, lfw_subset

from pfctl.core.perception.face_worker import FaceWorker, FaceWorkerError
from pfctl.core.perception.faces import FaceEncoder, FaceParams
from pfctl.core.perception.identity.identifier import Decision, TargetIdentifier
from pfctl.core.perception.identity.params import IdentityParams
from pfctl.core.perception.identity.profile import (
    TargetProfile,
    describe,
    face_region,
    learn_profile,
)
from pfctl.core.perception.vision import PersonDetection
from tests.processes import process_gone, processes_end

ROOT = Path(__file__).resolve().parents[3]
RED, NAVY, GREY = (200, 30, 40), (40, 40, 120), (90, 90, 90)
TARGET_FACE, OTHER_FACE = 20, 77  # two LFW faces far apart in dlib's embedding space
#: The astronaut's face and a head region around it (as a person detector would give).
HEAD = (150, 50, 290, 190)
#: How long a child may take to load dlib's models: seconds when idle, minutes on a busy machine.
LOADING_S = 300.0


@pytest.fixture(scope="module")
def worker() -> Iterator[FaceWorker]:
    with FaceWorker(FaceParams()) as w:
        w.wait_ready(LOADING_S)
        yield w


# -- the worker -----------------------------------------------------------------------------------


@pytest.mark.slow
@pytest.mark.skipif(not hasattr(os, "SCHED_IDLE"), reason="Linux's SCHED_IDLE")
def test_an_idle_worker_gets_ready_while_every_cpu_is_busy() -> None:
    """A busy process on every CPU: the worker still loads its models (it takes SCHED_IDLE only
    after; before, it starved, and ``pfctl search`` over ROS failed with "face worker: not ready
    after 60 s")."""
    spinners = [
        subprocess.Popen([sys.executable, "-c", "while True: pass"])
        for _ in range(len(os.sched_getaffinity(0)))
    ]
    try:
        with FaceWorker(FaceParams(), idle=True) as w:
            assert w.wait_ready(timeout=120.0) > 0
    finally:
        for spinner in spinners:
            spinner.kill()
            spinner.wait()


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_an_idle_child_waits_for_a_sleeping_parent_only() -> None:
    """The child starts a job once its parent sleeps: a sleeping process is not running, this
    one (reading the state) is, one that has ended is not; the wait for a sleeper ends."""
    from pfctl.core.perception.face_worker import _running, wait_while_running

    sleeper = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])
    try:
        for _ in range(200):  # until it has started and gone to sleep
            if not _running(sleeper.pid):
                break
            time.sleep(0.05)
        assert not _running(sleeper.pid)
        wait_while_running(sleeper.pid, 60.0)  # returns at once (no timing asserted)
    finally:
        sleeper.kill()
        sleeper.wait()
    assert _running(os.getpid())
    assert not _running(sleeper.pid)  # reaped: no such process


def test_the_worker_finds_the_same_faces_as_the_inline_encoder(worker: FaceWorker) -> None:
    img = astronaut()
    encoder = FaceEncoder(FaceParams())
    small = np.ascontiguousarray(img[::4, ::4])  # the face ~23 px: found only in a head region
    cases = [("head", img, HEAD), ("small head", small, (30, 5, 80, 55))]
    for key, rgb, region in cases:
        assert worker.submit(key, rgb, region)
    for key, rgb, region in cases:
        got = worker.wait(key)
        want = encoder.detect(rgb, region)
        assert len(got.faces) == len(want) == 1, key
        assert got.faces[0].box == want[0].box
        assert np.array_equal(got.faces[0].embedding, want[0].embedding)
        assert got.faces[0].score == want[0].score
        assert got.seconds > 0 and got.cpu_seconds > 0
    # a region without a face, and one too small to search, come back empty
    assert worker.submit("sky", img, (0, 0, 60, 60)) and worker.submit("tiny", img, (5, 5, 7, 7))
    assert worker.wait("sky").faces == () and worker.wait("tiny").faces == ()
    assert worker.poll() == []


def test_a_full_worker_refuses_a_job_and_takes_it_later(worker: FaceWorker) -> None:
    img = astronaut()
    refused = worker.stats.refused
    assert worker.submit("a", img, HEAD) and worker.submit("b", img, HEAD)
    assert worker.in_flight == 2
    assert not worker.submit("c", img, HEAD)  # two out: ~0.1 s each, nothing is back yet
    assert worker.stats.refused == refused + 1
    with pytest.raises(ValueError, match="already submitted"):
        worker.submit("a", img, HEAD)
    worker.wait_slot()
    assert worker.submit("c", img, HEAD)
    done = {r.job for r in worker.poll()}
    for key in ("a", "b", "c"):
        if key not in done:
            worker.wait(key)
    assert worker.in_flight == 0
    with pytest.raises(KeyError):
        worker.wait("never")


def test_close_stops_the_child_and_the_worker_says_so_after() -> None:
    w = FaceWorker(FaceParams(), max_in_flight=1)
    assert w.submit(1, astronaut(), HEAD)  # closing with a job out is fine
    pid = w.pid
    # the child finishes loading dlib and the job at hand first: on a busy machine that takes
    # longer than close's default wait, after which it would be terminated (exit code -15)
    w.close(timeout=60.0)
    assert w.closed and w._process.exitcode == 0
    assert pid is not None and process_gone(pid)
    w.close()  # twice is fine
    with pytest.raises(FaceWorkerError, match="after close"):
        w.poll()


def test_a_killed_child_is_one_clear_error() -> None:
    w = FaceWorker(FaceParams())
    try:
        w.wait_ready(LOADING_S)
        assert w.submit(1, astronaut(), HEAD)
        assert w.pid is not None
        os.kill(w.pid, signal.SIGKILL)
        with pytest.raises(FaceWorkerError) as err:
            w.wait(1)
        message = str(err.value)
        assert "died" in message and "signal 9" in message and "\n" not in message
        with pytest.raises(FaceWorkerError, match="died"):  # and so says every later call
            w.submit(2, astronaut(), HEAD)
    finally:
        w.close()


@pytest.mark.parametrize("ending", ["exit", "killed", "killed while loading"])
def test_the_child_ends_with_its_parent(ending: str) -> None:
    """A parent that exits without closing the worker does not hang; one that is killed
    (kill -9 of a bench worker), even while the child still loads the models, leaves no
    worker behind and no traceback on stderr (issue 21, item 9)."""
    script = textwrap.dedent(
        f"""
        import os, signal, sys
        from skimage.data import astronaut
        from pfctl.core.perception.face_worker import FaceWorker

        if __name__ == "__main__":
            w = FaceWorker()
            if {ending!r} != "killed while loading":
                w.wait_ready({LOADING_S})
                w.submit(1, astronaut(), {HEAD})
            print(w.pid, flush=True)
            if {ending!r} != "exit":
                os.kill(os.getpid(), signal.SIGKILL)
        """
    )
    # the child inherits stderr: run() returns once every process holding it has ended
    done = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, timeout=LOADING_S, cwd=ROOT
    )
    assert done.returncode == (0 if ending == "exit" else -signal.SIGKILL), done.stderr
    assert processes_end([int(done.stdout.split()[0])], 20.0)
    assert done.stderr == ""


# -- the identifier with a worker -----------------------------------------------------------------


def _picture(face: int | None) -> tuple[np.ndarray, PersonDetection]:
    """A 240x160 picture of a person in a red shirt: head 60x72 px (an LFW face, or the back of
    the head when ``face`` is None); the detection an OpenPose source would give."""
    img = np.full((240, 160, 3), GREY, np.uint8)
    if face is None:
        img[4:76, 50:110] = (60, 40, 30)  # hair
    else:
        gray = (lfw_subset()[face] * 255).astype(np.uint8)
        img[4:76, 50:110] = np.dstack([cv2.resize(gray, (60, 72), cv2.INTER_CUBIC)] * 3)
    img[80:150, 30:130] = RED
    img[150:236, 40:120] = NAVY
    kp = {"neck": (80.0, 80.0), "mid_hip": (80.0, 150.0), "ankles": (80.0, 236.0)}
    det = PersonDetection(
        (30, 4, 130, 236), (2.0, 0.0, 1.0), keypoints=kp, head_box=(50, 4, 110, 76)
    )
    return img, det


def _two(left: int | None, right: int | None) -> tuple[np.ndarray, list[PersonDetection]]:
    """Two people side by side in one 240x320 frame."""
    a, da = _picture(left)
    b, db = _picture(right)
    shift = lambda box: (box[0] + 160, box[1], box[2] + 160, box[3])  # noqa: E731
    moved = PersonDetection(
        shift(db.box),
        db.position,
        keypoints={k: (x + 160, y) for k, (x, y) in (db.keypoints or {}).items()},
        head_box=shift(db.head_box),
    )
    return np.hstack([a, b]), [da, moved]


@pytest.fixture(scope="module")
def profile() -> TargetProfile:
    params = IdentityParams()
    encoder = FaceEncoder(params.face)
    views = [_picture(TARGET_FACE), _picture(None)]
    return learn_profile([describe(img, det, params, encoder) for img, det in views], params)


def _episode(
    profile: TargetProfile, worker: FaceWorker, timing: str = "deterministic"
) -> tuple[list[tuple], TargetIdentifier]:
    """Two people in red at 10 Hz: track 1 shows the target's face from 0.2 s on, track 2
    (a look-alike) shows another face from 0.5 s on; track 3 is deleted while its search is
    out. The identities after every frame."""
    ident = TargetIdentifier(profile, IdentityParams(face_timing=timing), worker=worker)  # type: ignore[arg-type]
    out = []
    for k in range(10):
        t = round(0.1 * k, 10)
        frame, (d1, d2) = _two(TARGET_FACE if k >= 2 else None, OTHER_FACE if k >= 5 else None)
        seen = [(1, True, d1), (2, True, d2)]
        if k == 0:
            seen.insert(0, (3, True, d1))
        ids = ident.observe_frame(t, frame, seen)
        if k == 0:
            ident.forget(3)
        out.append(tuple((i.track_id, i.decision, i.basis, i.face_samples) for i in ids))
    return out, ident


def test_deterministic_timing_gives_the_same_identities_every_run(
    profile: TargetProfile, worker: FaceWorker
) -> None:
    first, ident = _episode(profile, worker)
    second, _ = _episode(profile, worker)
    assert first == second
    assert ident.face_stats.discarded == 1  # track 3's search came back after it was deleted
    assert ident.face_stats.inline == 0 and ident.face_stats.submitted >= 4


def test_a_face_found_later_decides_when_its_result_is_due(
    profile: TargetProfile, worker: FaceWorker
) -> None:
    frames, ident = _episode(profile, worker)
    basis = [{tid: (d, b) for tid, d, b, _ in f} for f in frames]
    # both wear the target's clothes: with a look-alike about clothes are no evidence, neither is
    # anyone until a face result is folded in (issue 23)
    assert basis[2][1] == (Decision.UNKNOWN, "clothes")  # face submitted at 0.2 s ...
    assert basis[3][1] == (Decision.TARGET, "face")  # ... counts from 0.3 s
    # the look-alike's back was searched at 0.1, 0.2, 0.3 s (three misses), so it is searched
    # again only at 0.8 s: its face (shown from 0.5 s) counts from 0.9 s
    assert basis[8][2] == (Decision.UNKNOWN, "clothes")
    assert basis[9][2] == (Decision.NOT_TARGET, "face")
    assert ident.face_stats.backed_off > 0
    assert ident.target_track() == 1
    one = ident.identity(1)
    assert one is not None and one.face_distance is not None and one.face_distance < 0.3


def test_the_deterministic_latency_is_the_frames_not_the_machines(
    profile: TargetProfile, worker: FaceWorker
) -> None:
    params = IdentityParams(face_latency_s=0.25)
    ident = TargetIdentifier(profile, params, worker=worker)
    img, det = _picture(TARGET_FACE)
    assert ident.observe(1, 0.0, True, det, img).basis == "clothes"
    worker.wait_idle()  # however fast the worker was ...
    assert ident.observe(1, 0.1, True, det, img).basis == "clothes"  # ... not due yet
    assert ident.observe(1, 0.2, True, det, img).basis == "clothes"
    due = ident.observe(1, 0.25, True, det, img)  # due: waits for it if need be
    assert due.basis == "face" and due.face_samples == 1
    inline = FaceEncoder().detect(img, face_region(det, img.shape))
    assert due.face_box == inline[0].box  # in the frame's pixels
    ident.update(10.0)
    assert ident.pending == 0


def test_realtime_timing_folds_in_what_has_come_back_and_never_waits(
    profile: TargetProfile, worker: FaceWorker
) -> None:
    ident = TargetIdentifier(profile, IdentityParams(face_timing="realtime"), worker=worker)
    img, det = _picture(TARGET_FACE)
    first = ident.observe(1, 0.0, True, det, img)
    assert first.basis == "clothes" and ident.pending == 1
    t, now = 0.0, first
    deadline = time.monotonic() + 30
    while now.basis != "face" and time.monotonic() < deadline:
        time.sleep(0.02)
        t += 0.02
        ident.update(t)
        now = ident.identity(1)  # type: ignore[assignment]
    assert now.basis == "face" and now.decision is Decision.TARGET
    assert ident.face_stats.submitted == 1 and ident.face_stats.folded == 1


def test_a_back_of_the_head_is_searched_less_often() -> None:
    """Inline: after face_miss_limit searches without a face, one search per backoff."""
    params = IdentityParams(face_miss_limit=3, face_miss_backoff_s=0.5)
    profile = TargetProfile(
        np.full(256, 1 / 256), np.full(256, 1 / 256), np.random.default_rng(0).normal(size=(1, 128))
    )
    ident = TargetIdentifier(profile, params)
    img, det = _picture(None)
    for k in range(11):
        ident.observe(1, round(0.1 * k, 10), True, det, img)
    # searched at 0.0, 0.1, 0.2 (three misses), then at 0.7 only
    assert ident.face_stats.inline == 4
    assert ident.face_stats.backed_off == 7
