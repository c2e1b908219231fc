"""Find ROS 1's Python modules from the project's venv, without ``PYTHONPATH`` or ``.pth`` files.

Debian's ROS 1 packages (README, "ROS 1 (HSR backend)") live in ``/usr/lib/python3/dist-packages``,
which the venv (built from another CPython 3.11) does not see. :func:`import_rospy` appends that
directory to ``sys.path`` only when a plain ``import rospy`` fails, and appends it *last*, so the
venv's own numpy/yaml/... keep winning. A plain append, not ``site.addsitedir``: that would run
Debian's ``.pth`` files inside the venv. ``PFCTL_ROS_PYTHONPATH`` names another directory (e.g.
``/opt/ros/noetic/lib/python3/dist-packages``).
"""

from __future__ import annotations

import importlib
import os
import sys
from types import ModuleType

from pfctl.errors import UserError

DEBIAN_DIST_PACKAGES = "/usr/lib/python3/dist-packages"
"""Where Debian's ``python3-rospy`` & co. install their modules."""

ROS_PYTHONPATH_ENV = "PFCTL_ROS_PYTHONPATH"

APT_INSTALL = (
    "apt-get install --no-install-recommends ros-core python3-rospy python3-rosgraph "
    "python3-std-msgs python3-sensor-msgs python3-geometry-msgs python3-nav-msgs "
    "python3-trajectory-msgs python3-rosgraph-msgs python3-tf2-ros python3-tf2-msgs "
    "python3-actionlib python3-actionlib-msgs python3-move-base-msgs python3-std-srvs "
    "python3-rosbag python3-visualization-msgs"
)
"""The apt line that installs ROS 1 for the HSR backend (the same list as ``.ci/run``)."""


class RosUnavailableError(UserError):
    """ROS 1 cannot be imported: its one-line message says how to install it."""


def ros_python_dir() -> str:
    """The directory appended to ``sys.path`` when ROS 1 is not importable as is."""
    return os.environ.get(ROS_PYTHONPATH_ENV) or DEBIAN_DIST_PACKAGES


def import_ros_module(name: str) -> ModuleType:
    """Import a ROS 1 module (``rospy``, ``sensor_msgs.msg``, ...), appending the ROS Python
    directory to ``sys.path`` first if the plain import fails.

    Raises :class:`RosUnavailableError` naming the apt line when it still cannot be imported.
    """
    try:
        return importlib.import_module(name)
    except ImportError as first:
        extra = ros_python_dir()
        if sys.version_info[:2] != (3, 11) and extra == DEBIAN_DIST_PACKAGES:
            raise RosUnavailableError(
                f"the HSR backend needs ROS 1 ({name}); Debian's ROS 1 in {extra} is built for "
                f"Python 3.11, this is {sys.version_info[0]}.{sys.version_info[1]}"
            ) from first
        if extra not in sys.path and os.path.isdir(extra):
            sys.path.append(extra)
            importlib.invalidate_caches()
        try:
            return importlib.import_module(name)
        except ImportError as err:
            raise RosUnavailableError(
                f"the HSR backend needs ROS 1 but {name} cannot be imported ({err}); "
                f"install it with: sudo {APT_INSTALL}"
            ) from err


def import_rospy() -> ModuleType:
    """``rospy``, found as :func:`import_ros_module` does."""
    return import_ros_module("rospy")
