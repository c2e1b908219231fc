"""Writing files all or nothing: a temporary file beside the target, then ``os.replace``.

Nothing partial is ever left behind (house rule): on any error the temporaries are removed and
the targets keep their old content. An existing target keeps its permission bits; a new one gets
the usual ``0o666 & ~umask`` (not ``mkstemp``'s private 0o600). :func:`write_output` is the same
for the files a command produces, with a one-line error for the user.

:func:`check_output_file` and :func:`check_output_dir` are the pre-flight check every command runs
on its outputs before any work starts (a run that cannot write its outputs fails before it starts):
they create nothing, but write and remove a probe file where the output will go, so a read-only
file system, a missing permission or a folder under a regular file is one line at once.
"""

from __future__ import annotations

import contextlib
import os
import tempfile
from collections.abc import Sequence
from pathlib import Path

from pfctl.errors import UserError

__all__ = [
    "atomic_write",
    "atomic_write_all",
    "check_episode_dir",
    "check_output_dir",
    "check_output_file",
    "write_output",
]


def atomic_write(path: str | os.PathLike[str], data: str | bytes) -> Path:
    """Write ``data`` (str as UTF-8) to ``path`` atomically; return the path. Raises OSError."""
    atomic_write_all([(path, data)])
    return Path(path)


def write_output(path: str | os.PathLike[str], data: str | bytes) -> Path:
    """Write ``data`` to ``path`` all or nothing; an OSError becomes a :class:`UserError` naming
    the file (exit 2, nothing partial left behind)."""
    try:
        return atomic_write(path, data)
    except OSError as err:
        raise UserError(f"{path}: cannot write: {err.strerror or err}") from None


def atomic_write_all(files: Sequence[tuple[str | os.PathLike[str], str | bytes]]) -> None:
    """Write several files so that none is replaced unless all were written (e.g. a map's YAML
    and its PGM). The final renames run in order; each one is atomic. Raises OSError."""
    temporaries: list[tuple[str, Path]] = []
    try:
        for path, data in files:
            target = Path(path)
            temporaries.append((_write_temporary(target, data), target))
        while temporaries:
            tmp, target = temporaries[0]
            os.replace(tmp, target)
            temporaries.pop(0)
    finally:
        for tmp, _ in temporaries:
            with contextlib.suppress(OSError):
                os.unlink(tmp)


def _write_temporary(target: Path, data: str | bytes) -> str:
    payload = data.encode("utf-8") if isinstance(data, str) else data
    try:
        mode = target.stat().st_mode & 0o7777
    except OSError:
        umask = os.umask(0)
        os.umask(umask)
        mode = 0o666 & ~umask
    fd, tmp = tempfile.mkstemp(dir=target.parent, prefix=f".{target.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as handle:
            handle.write(payload)
            handle.flush()
            os.fsync(handle.fileno())
        os.chmod(tmp, mode)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise
    return tmp


def check_episode_dir(path: Path) -> None:
    """Refuse to write an episode (``--record``) over a file or over a folder that holds
    something else."""
    if path.exists() and not path.is_dir():
        raise UserError(f"--record {path}: exists and is not a directory")
    if path.is_dir() and any(path.iterdir()) and not (path / "episode.json").is_file():
        raise UserError(
            f"--record {path}: a folder that is neither empty nor an episode; choose another"
        )


def check_output_file(
    path: str | os.PathLike[str] | None, option: str, *, make_folder: bool = True
) -> None:
    """Before any work: a :class:`UserError` (``OPTION PATH: why``) unless a file can be written
    at ``path``: its folder is writable, or (``make_folder``: the command creates it) can be
    created. None: no output."""
    if path is None:
        return
    target = Path(path)
    if target.is_dir():
        raise UserError(f"{option} {target}: is a directory, expected a file path")
    if not make_folder and not target.parent.is_dir():
        why = (
            f"{target.parent} is not a directory"
            if target.parent.exists()
            else f"no such folder {target.parent}"
        )
        raise UserError(f"{option} {target}: {why}")
    _check_writable_folder(target.parent, option, target)


def check_output_dir(path: str | os.PathLike[str] | None, option: str) -> None:
    """Before any work: a :class:`UserError` (``OPTION PATH: why``) unless files can be written
    into the folder ``path`` (it exists or can be created, and is writable). None: no output."""
    if path is None:
        return
    target = Path(path)
    if target.exists() and not target.is_dir():
        raise UserError(f"{option} {target}: exists and is not a directory")
    _check_writable_folder(target, option, target)


def _check_writable_folder(folder: Path, option: str, shown: Path) -> None:
    """``folder`` is writable, or the nearest folder above it that exists is, so it can be made."""
    existing = folder
    while not existing.exists() and existing != existing.parent:
        existing = existing.parent
    if not existing.is_dir():
        raise UserError(f"{option} {shown}: cannot create it: {existing} is not a directory")
    try:
        fd, probe = tempfile.mkstemp(dir=existing, prefix=".pfctl-probe.", suffix=".tmp")
    except OSError as err:
        raise UserError(
            f"{option} {shown}: cannot write in {existing}: {err.strerror or err}"
        ) from None
    os.close(fd)
    with contextlib.suppress(OSError):
        os.unlink(probe)
