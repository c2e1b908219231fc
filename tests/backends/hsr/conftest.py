"""Fixtures for the ROS 1 tests: ROS itself (required on CI) and a private ``rosmaster`` per test.

* ``ros``: skips the test with a reason when ROS 1 cannot be imported — but **fails** it when the
  environment variable ``CI`` is set (CI installs ROS 1 in ``.ci/run``; a silent skip there would
  hide a broken install).
* ``ros_master``: starts ``rosmaster --core -p PORT`` on a free loopback port with ``ROS_HOME`` and
  ``ROS_LOG_DIR`` in the test's tmp dir, waits until the master answering is *ours* (its XML-RPC
  ``getPid`` equals our process id: a master started on a taken port keeps running without
  serving), and always stops it (SIGTERM to its process group, then SIGKILL).

Nodes run in subprocesses (:func:`run_node`): rospy allows one ``init_node`` per process and its
interrupt exceptions subclass ``KeyboardInterrupt``, so pytest's own process never starts a node.
"""

from __future__ import annotations

import os
import shutil
import signal
import socket
import subprocess
import sys
import time
import xmlrpc.client
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType

import pytest

from pfctl.backends.hsr.master import master_proxy as _master_proxy
from pfctl.backends.hsr.ros_import import import_ros_module

ROS_MODULES = (
    "rospy",
    "rosgraph",
    "std_msgs.msg",
    "sensor_msgs.msg",
    "geometry_msgs.msg",
    "nav_msgs.msg",
    "trajectory_msgs.msg",
    "actionlib_msgs.msg",
)
READY_TIMEOUT = 20.0
"""Wall seconds a master may take to answer."""
NODE_TIMEOUT = 60.0
"""Wall seconds a test node process may run before it counts as hung."""


@pytest.fixture(scope="session")
def ros() -> dict[str, ModuleType]:
    """The ROS 1 modules the tests use; skip (fail when ``CI`` is set) if they are missing."""
    try:
        return {name: import_ros_module(name) for name in ROS_MODULES}
    except Exception as err:  # RosUnavailableError, or a broken install raising something else
        message = f"ROS 1 is not importable: {err}"
        if os.environ.get("CI"):
            pytest.fail(f"{message} (CI is set: .ci/run must have installed it)", pytrace=False)
        pytest.skip(message)


def master_proxy(uri: str) -> xmlrpc.client.ServerProxy:
    """An XML-RPC proxy to the master at ``uri`` with a 2 s socket timeout (a stuck listener
    must not hang the test)."""
    return _master_proxy(uri, timeout=2.0)


@dataclass(frozen=True)
class RosMaster:
    """A running private master: its URI, the environment for nodes that use it, its process."""

    uri: str
    port: int
    env: dict[str, str]
    process: subprocess.Popen[bytes]
    log: Path

    def proxy(self) -> xmlrpc.client.ServerProxy:
        return master_proxy(self.uri)


def _free_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def ros_env(port: int, home: Path) -> dict[str, str]:
    """The environment of the master and of every test node: loopback only, logs under ``home``,
    no ``ROS_IP``/``PYTHONPATH`` from the caller (nodes find ROS through the import helper)."""
    env = {k: v for k, v in os.environ.items() if k not in ("ROS_IP", "PYTHONPATH")}
    env.update(
        ROS_MASTER_URI=f"http://127.0.0.1:{port}/",
        ROS_HOSTNAME="127.0.0.1",
        ROS_HOME=str(home),
        ROS_LOG_DIR=str(home / "log"),
        PYTHONUNBUFFERED="1",
    )
    return env


def _stop(process: subprocess.Popen[bytes]) -> None:
    """SIGTERM to the process group, then SIGKILL if it is still there after 10 s."""
    if process.poll() is not None:
        return
    try:
        os.killpg(process.pid, signal.SIGTERM)
        process.wait(timeout=10)
    except subprocess.TimeoutExpired:
        os.killpg(process.pid, signal.SIGKILL)
        process.wait(timeout=10)
    except ProcessLookupError:
        process.wait(timeout=10)


def _ours(uri: str, pid: int) -> bool:
    """True when the master answering at ``uri`` is process ``pid`` and serves the graph."""
    try:
        proxy = master_proxy(uri)
        code, _, answered_pid = proxy.getPid("/pytest")
        state_code, _, _ = proxy.getSystemState("/pytest")
    except (OSError, xmlrpc.client.Error):
        return False
    return code == 1 and state_code == 1 and answered_pid == pid


def start_master(home: Path, attempts: int = 3) -> RosMaster:
    """Start ``rosmaster --core`` on a free port and wait until it answers as ours; a master that
    exits, or whose port answers for another process, is stopped and retried on a new port."""
    exe = shutil.which("rosmaster") or "/usr/bin/rosmaster"
    problems = []
    for attempt in range(attempts):
        port = _free_port()
        ros_home = home / f"ros{attempt}"
        (ros_home / "log").mkdir(parents=True)
        env = ros_env(port, ros_home)
        log = ros_home / "rosmaster.log"
        with log.open("wb") as out:
            process = subprocess.Popen(
                [exe, "--core", "-p", str(port)],
                env=env,
                stdin=subprocess.DEVNULL,
                stdout=out,
                stderr=subprocess.STDOUT,
                start_new_session=True,
            )
        try:
            deadline = time.monotonic() + READY_TIMEOUT
            while time.monotonic() < deadline and process.poll() is None:
                if _ours(env["ROS_MASTER_URI"], process.pid):
                    return RosMaster(env["ROS_MASTER_URI"], port, env, process, log)
                time.sleep(0.05)
        except BaseException:
            _stop(process)
            raise
        _stop(process)
        problems.append(f"port {port}: {log.read_text(errors='replace')[-300:]!r}")
    raise RuntimeError(f"rosmaster did not come up as ours in {attempts} attempts: {problems}")


@pytest.fixture
def ros_master(ros: dict[str, ModuleType], tmp_path: Path) -> Iterator[RosMaster]:
    """A private ``rosmaster`` for this test, stopped afterwards whatever happens."""
    master = start_master(tmp_path)
    try:
        yield master
    finally:
        _stop(master.process)


def start_node(
    master: RosMaster, script: str, *args: str, stdin: int | None = None
) -> subprocess.Popen[str]:
    """Run ``script`` (Python source) as a node process with the master's environment, in its own
    process group; stdout is a pipe (text), stderr goes to the test's output."""
    return subprocess.Popen(
        [sys.executable, "-c", script, *args],
        env=master.env,
        stdin=stdin if stdin is not None else subprocess.DEVNULL,
        stdout=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )


def stop_node(process: subprocess.Popen[str]) -> None:
    """Stop a node process (SIGTERM to its group, then SIGKILL), as for the master."""
    _stop(process)  # type: ignore[arg-type]


@pytest.fixture
def ros_nodes(ros_master: RosMaster) -> Iterator[Callable[..., subprocess.Popen[str]]]:
    """``start(script, *args, stdin=None)``: a node process on the test's master (see
    :func:`start_node`); every node started is stopped after the test."""
    started: list[subprocess.Popen[str]] = []

    def start(script: str, *args: str, stdin: int | None = None) -> subprocess.Popen[str]:
        process = start_node(ros_master, script, *args, stdin=stdin)
        started.append(process)
        return process

    try:
        yield start
    finally:
        for process in started:
            stop_node(process)
