"""The simulated house behind the Robot port (PyBullet).

PyBullet prints its build time when it is first imported, which would end up in the output of
every command; it is imported here once with the process's stdout and stderr pointed at
/dev/null.
"""

from __future__ import annotations

import contextlib
import os
import sys


def _import_pybullet_quietly() -> None:
    try:
        fds = [sys.stdout.fileno(), sys.stderr.fileno()]
    except (AttributeError, OSError, ValueError):  # no real file descriptors (captured)
        fds = []
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(AttributeError, OSError, ValueError):
            stream.flush()
    saved = [os.dup(fd) for fd in fds]
    try:
        with open(os.devnull, "w") as null:
            for fd in fds:
                os.dup2(null.fileno(), fd)
            import pybullet  # noqa: F401
    finally:
        for fd, copy in zip(fds, saved, strict=True):
            os.dup2(copy, fd)
            os.close(copy)


_import_pybullet_quietly()
