"""Files are written all or nothing, with ordinary permissions."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from pfctl.core.mapping.grid import OccupancyGrid
from pfctl.errors import UserError
from pfctl.files import atomic_write, atomic_write_all, write_output
from pfctl.mission.map_server import save_map_server


def test_a_new_file_gets_the_umask_permissions_and_an_old_one_keeps_its_own(
    tmp_path: Path,
) -> None:
    umask = os.umask(0o022)
    try:
        new = atomic_write(tmp_path / "new.txt", "hello")
        assert new.read_text() == "hello"
        assert new.stat().st_mode & 0o777 == 0o644
        old = tmp_path / "old.txt"
        old.write_text("old")
        old.chmod(0o600)
        atomic_write(old, b"new")
        assert old.read_bytes() == b"new" and old.stat().st_mode & 0o777 == 0o600
    finally:
        os.umask(umask)


def test_when_one_file_cannot_be_written_none_is_replaced(tmp_path: Path) -> None:
    first = tmp_path / "map.pgm"
    first.write_bytes(b"before")
    with pytest.raises(OSError):
        atomic_write_all([(first, b"after"), (tmp_path / "missing" / "map.yaml", "x")])
    assert first.read_bytes() == b"before"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["map.pgm"]  # no temporaries left


def test_saved_maps_are_readable_by_others(tmp_path: Path) -> None:
    umask = os.umask(0o022)
    try:
        yaml_file, pgm_file = save_map_server(OccupancyGrid.empty(1.0, 1.0, 0.1), tmp_path / "m")
    finally:
        os.umask(umask)
    assert yaml_file.stat().st_mode & 0o777 == 0o644
    assert pgm_file.stat().st_mode & 0o777 == 0o644


def test_write_output_turns_an_os_error_into_one_line_for_the_user(tmp_path: Path) -> None:
    target = tmp_path / "no" / "such" / "dir.png"
    with pytest.raises(UserError, match=r"dir\.png: cannot write: No such file or directory$"):
        write_output(target, b"png")
    assert not (tmp_path / "no").exists()
