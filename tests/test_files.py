"""Files are written all or nothing, with ordinary permissions; every command checks that its
outputs can be written before any work starts."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from pfctl.core.mapping.grid import OccupancyGrid
from pfctl.errors import UserError
from pfctl.files import (
    atomic_write,
    atomic_write_all,
    check_output_dir,
    check_output_file,
    write_output,
)
from pfctl.mission.map_server import save_map_server
from tests.conftest import run_cli

ROOT = Path(__file__).resolve().parents[1]
HOUSE = str(ROOT / "missions" / "house.yaml")


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


# ---------------------------------------------------------------- pre-flight check of outputs


def test_the_output_checks_create_nothing_and_name_the_option(tmp_path: Path) -> None:
    a_file = tmp_path / "a_file"
    a_file.write_text("x")
    check_output_dir(tmp_path / "new" / "deeper", "--out")  # can be created: fine
    check_output_file(tmp_path / "new" / "f.png", "--png")
    check_output_dir(None, "--out")
    check_output_file(None, "--png")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a_file"]  # no folder, no probe left
    cases = [
        (lambda: check_output_dir(a_file, "--out"), f"--out {a_file}: exists and is not a dir"),
        (
            lambda: check_output_dir(a_file / "out", "--out"),
            f"--out {a_file / 'out'}: cannot create it: {a_file} is not a directory",
        ),
        (
            lambda: check_output_file(a_file / "d" / "f.png", "--png"),
            f"--png {a_file / 'd' / 'f.png'}: cannot create it: {a_file} is not a directory",
        ),
        (lambda: check_output_file(tmp_path, "--png"), "is a directory, expected a file path"),
        (
            lambda: check_output_file(tmp_path / "no" / "t.npz", "--out", make_folder=False),
            f"--out {tmp_path / 'no' / 't.npz'}: no such folder {tmp_path / 'no'}",
        ),
        (
            lambda: check_output_file(a_file / "t.npz", "--out", make_folder=False),
            f"{a_file} is not a directory",
        ),
    ]
    for check, words in cases:
        with pytest.raises(UserError) as err:
            check()
        assert words in str(err.value) and "\n" not in str(err.value)


#: Every command that writes, its output option and file name, and what the command would start
#: with (patched to fail the test: the check must come first).
WRITERS = [
    pytest.param(["follow", HOUSE, "--duration", "40"], "--out", "out", "follow.load_mission"),
    pytest.param(["follow", HOUSE], "--record", "rec", "follow.load_mission", id="follow-record"),
    pytest.param(["search", HOUSE, "--duration", "40"], "--out", "out", "follow.load_mission"),
    pytest.param(["sim", "run", HOUSE], "--record", "rec", "sim.load_mission", id="sim-record"),
    pytest.param(["sim", "run", HOUSE], "--png", "p.png", "sim.load_mission", id="sim-png"),
    pytest.param(["sim", "export-map", HOUSE], "--out", "m.yaml", "sim.load_mission"),
    pytest.param(["bench", HOUSE, "--episodes", "2"], "--out", "out", "bench.build_campaign"),
    pytest.param(["replay", "x.bag"], "--out", "out", "replay.open_replay"),
    pytest.param(["learn-target", HOUSE], "--out", "t.npz", "learn_target.load_mission"),
    pytest.param(["legs", "train"], "--out", "m.npz", "legs._mission"),
    pytest.param(["legs", "evaluate"], "--json", "e.json", "legs._mission"),
    pytest.param(["map", "export", HOUSE], "--out", "m.yaml", "map.load_mission"),
    pytest.param(["map", "render", HOUSE], "--png", "m.png", "map.load_source"),
    pytest.param(["map", "annotate", HOUSE], "--png", "m.png", "map.load_source"),
    pytest.param(["mission", "schema"], "--out", "s.json", "mission.dump_json_schema"),
    pytest.param(["mission", "generate"], "--out", "h.yaml", "mission.make_home"),
    pytest.param(["bt", "show", HOUSE], "--out", "tree.txt", "bt.load_mission"),
    pytest.param(["predict", "t.csv"], "--out", "p.csv", "predict.read_csv_trajectory"),
    pytest.param(["predict", "evaluate", "d"], "--json", "e.json", "predict._load_tracks"),
    pytest.param(["predict", "search", "d"], "--json", "s.json", "predict._load_tracks"),
    pytest.param(
        ["predict", "experiment", "door"], "--plot", "d.png", "predict.run_door_experiment"
    ),
]


@pytest.mark.parametrize(("args", "option", "name", "work"), WRITERS)
def test_every_writer_refuses_an_output_under_a_file_before_any_work(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
    args: list[str],
    option: str,
    name: str,
    work: str,
) -> None:
    def started(*_: object, **__: object) -> None:
        raise AssertionError(f"{work} ran before the outputs were checked")

    monkeypatch.setattr(f"pfctl.commands.{work}", started)
    a_file = tmp_path / "a_file"
    a_file.write_text("x")
    target = a_file / name
    code, out, err = run_cli([*args, option, str(target)], capsys, monkeypatch)
    assert code == 2 and out == "", err
    assert err in (
        f"pfctl: error: {option} {target}: cannot create it: {a_file} is not a directory\n",
        f"pfctl: error: {option} {target}: {a_file} is not a directory\n",  # folder not created
    ), err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a_file"]


def _unshare_works() -> bool:
    unshare = shutil.which("unshare")
    if unshare is None:
        return False
    done = subprocess.run(
        [unshare, "-rm", "sh", "-c", "mount -t tmpfs -o ro tmpfs /mnt"],
        capture_output=True,
        timeout=30,
    )
    return done.returncode == 0


@pytest.mark.slow
@pytest.mark.skipif(not _unshare_works(), reason="cannot mount a read-only tmpfs (unshare -rm)")
@pytest.mark.parametrize(
    "args",
    [
        ["follow", HOUSE, "--backend", "sim", "--seed", "1", "--duration", "40", "--out"],
        ["sim", "run", HOUSE, "--duration", "40", "--record"],
    ],
    ids=["follow", "sim-run"],
)
def test_an_output_on_a_read_only_file_system_fails_at_once(
    tmp_path: Path, args: list[str]
) -> None:
    """A real read-only mount (a tmpfs in a private mount namespace): one line, exit 2, and no
    learning or episode first (a 40 s episode that ran would print its figures)."""
    mount = tmp_path / "ro"
    mount.mkdir()
    target = mount / "out"
    script = 'mount -t tmpfs -o ro tmpfs "$1" && shift && exec "$@"'
    pfctl = [sys.executable, "-m", "pfctl", *args, str(target)]
    done = subprocess.run(
        ["unshare", "-rm", "sh", "-c", script, "sh", str(mount), *pfctl],
        capture_output=True,
        text=True,
        timeout=300,
        cwd=ROOT,
    )
    assert done.returncode == 2 and done.stdout == "", done.stderr
    assert done.stderr == (
        f"pfctl: error: {args[-1]} {target}: cannot write in {mount}: Read-only file system\n"
    )
    assert list(mount.iterdir()) == []  # the mount point, seen from outside: nothing
