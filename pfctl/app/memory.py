"""Keep freed memory in the process for the control loop's next tick (glibc ``mallopt``).

Every tick allocates the same large numpy temporaries again: a person filling the camera image
is ~50 000 pixels, so ~1.2 MB per ``(n, 3)`` float array of their 3-D points, and the laser, the
grid and the belief add more of a few hundred kB. glibc serves blocks above its mmap threshold
(128 kB at start, adjusted upwards as blocks are freed, at most 32 MiB) with a fresh ``mmap`` and
hands them back with ``munmap`` when freed, and trims the top of its heap beyond 128 kB: the next
tick's arrays then touch new pages, one page fault per 4 kB, and on a virtual machine a fault is
expensive (benchmarks/README.md, ``replay_tick_stages.py``, has the figures).

:func:`retain_freed_memory` sets the mmap threshold to glibc's maximum (32 MiB on 64 bits: larger
blocks are still mapped) and the trim threshold high, so freed blocks stay in the heap and the
next tick reuses pages that are already mapped. It changes where memory comes from, never what
is computed. The price is that the process keeps its peak heap (tens of MB for the follower).
Call it once at the start of a control loop; elsewhere than glibc it does nothing.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import sys

#: glibc's ``mallopt`` parameters (malloc.h).
M_TRIM_THRESHOLD = -1
M_TOP_PAD = -2
M_MMAP_THRESHOLD = -3
#: glibc's largest mmap threshold on 64-bit systems (``DEFAULT_MMAP_THRESHOLD_MAX``).
MMAP_THRESHOLD = 32 * 1024 * 1024
#: Free memory at the top of the heap kept rather than returned to the system.
TRIM_THRESHOLD = 512 * 1024 * 1024
#: Extra memory asked for when the heap grows (fewer, larger ``brk`` calls).
TOP_PAD = 16 * 1024 * 1024


def retain_freed_memory() -> bool:
    """Make glibc keep freed blocks up to :data:`MMAP_THRESHOLD` in the heap (module
    docstring); True if it accepted the settings, False where there is no glibc ``mallopt``."""
    if not sys.platform.startswith("linux"):
        return False
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6")
        mallopt = libc.mallopt
    except (OSError, AttributeError):
        return False
    mallopt.argtypes = (ctypes.c_int, ctypes.c_int)
    mallopt.restype = ctypes.c_int
    settings = (
        (M_MMAP_THRESHOLD, MMAP_THRESHOLD),
        (M_TRIM_THRESHOLD, TRIM_THRESHOLD),
        (M_TOP_PAD, TOP_PAD),
    )
    return all(mallopt(param, value) == 1 for param, value in settings)


__all__ = ["retain_freed_memory"]
