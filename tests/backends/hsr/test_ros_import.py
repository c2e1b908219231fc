"""The ROS import helper: pfctl never loads rospy unless the HSR backend asks, and a missing ROS 1
is one clear error. These run without ROS 1 too (fresh interpreters, no master)."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

pytestmark = pytest.mark.ros


def _python(code: str, **env: str) -> subprocess.CompletedProcess[str]:
    full = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"} | env
    return subprocess.run(
        [sys.executable, "-c", code], env=full, capture_output=True, text=True, timeout=120
    )


def test_pfctl_without_hsr_backend_never_imports_rospy():
    done = _python(
        "import sys; from pfctl import cli; import pfctl.backends.hsr.convert\n"
        "sys.argv = ['pfctl', '--help']\n"
        "try:\n    cli.main()\nexcept SystemExit:\n    pass\n"
        "ros = ('rospy', 'rosgraph', 'genpy', 'sensor_msgs', 'std_msgs')\n"
        "print('ROS', [m for m in sys.modules if m.split('.')[0] in ros])"
    )
    assert done.returncode == 0, done.stderr
    assert "ROS []" in done.stdout


def test_missing_ros_is_one_clear_error():
    done = _python(
        "from pfctl.backends.hsr.ros_import import import_ros_module\n"
        "try:\n    import_ros_module('no_such_ros_pkg.msg')\n"
        "except Exception as e:\n    print(type(e).__name__, '|', e)\n",
        PFCTL_ROS_PYTHONPATH="/nonexistent",
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.startswith("RosUnavailableError | the HSR backend needs ROS 1")
    assert "apt-get install --no-install-recommends ros-core python3-rospy" in done.stdout
    assert len(done.stdout.strip().splitlines()) == 1


def _pytest_without_ros(ci: bool) -> subprocess.CompletedProcess[str]:
    """Run one ROS test in a fresh pytest where ROS 1 cannot be found."""
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "CI")}
    env["PFCTL_ROS_PYTHONPATH"] = "/nonexistent"
    if ci:
        env["CI"] = "true"
    test = os.path.join(os.path.dirname(__file__), "test_convert.py") + "::test_twist_round_trip"
    return subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-rs", "-p", "no:cacheprovider", test],
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
    )


def test_ros_tests_skip_without_ros_but_fail_on_ci():
    local = _pytest_without_ros(ci=False)
    assert local.returncode == 0, local.stdout
    assert "SKIPPED [1]" in local.stdout and "ROS 1 is not importable" in local.stdout
    ci = _pytest_without_ros(ci=True)
    assert ci.returncode == 1, ci.stdout
    assert "SKIPPED" not in ci.stdout and "CI is set: .ci/run must have installed it" in ci.stdout
