"""`pfctl bt show` and `pfctl bt leaves`, in-process as the console script runs them."""

from __future__ import annotations

import io
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import pydot
import pytest
from PIL import Image

from pfctl.core.behavior.registry import LEAF_SPECS
from tests.conftest import HOUSE_MISSION, run_cli


def test_show_ascii_is_the_default(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    code, out, err = run_cli(["bt", "show", str(HOUSE_MISSION)], capsys, monkeypatch)
    assert code == 0, err
    assert out.splitlines()[0] == "[?] root (fallback)"
    assert "(target_visible) max_age=0.5" in out and "[waypoint_search]" in out
    assert len(out.splitlines()) == 10


def test_show_dot_and_btcpp_print_to_stdout(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    code, out, err = run_cli(
        ["bt", "show", str(HOUSE_MISSION), "--format", "dot"], capsys, monkeypatch
    )
    assert code == 0, err
    (graph,) = pydot.graph_from_dot_data(out)
    assert len(graph.get_edges()) == 9
    code, out, err = run_cli(["bt", "show", str(HOUSE_MISSION), "-f", "btcpp"], capsys, monkeypatch)
    assert code == 0, err
    root = ET.fromstring(out)
    assert root.get("BTCPP_format") == "4"
    assert root.find("BehaviorTree/ReactiveFallback[@name='root']") is not None


def test_show_writes_text_to_out(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    target = tmp_path / "tree.xml"
    code, out, err = run_cli(
        ["bt", "show", str(HOUSE_MISSION), "--format", "btcpp", "--out", str(target)],
        capsys,
        monkeypatch,
    )
    assert code == 0, err
    assert out == f"wrote {target}\n"
    ET.parse(target)
    assert [p.name for p in tmp_path.iterdir()] == ["tree.xml"]  # no temporaries left


def test_show_png_writes_the_default_file_in_the_current_folder(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    code, out, err = run_cli(
        ["bt", "show", str(HOUSE_MISSION), "--format", "png"], capsys, monkeypatch
    )
    assert code == 0, err
    written = tmp_path / "house_tree.png"
    assert out == f"wrote {written}\n"
    data = written.read_bytes()
    assert data.startswith(b"\x89PNG")
    with Image.open(io.BytesIO(data)) as image:
        assert image.size[0] > 600 and image.size[1] > 300
    other = tmp_path / "sub" / "t.png"
    other.parent.mkdir()
    code, out, err = run_cli(
        ["bt", "show", str(HOUSE_MISSION), "--format", "png", "-o", str(other)],
        capsys,
        monkeypatch,
    )
    assert code == 0, err
    assert out == f"wrote {other}\n" and other.read_bytes().startswith(b"\x89PNG")


def test_leaves_lists_every_leaf_with_its_parameters(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    code, out, err = run_cli(["bt", "leaves"], capsys, monkeypatch)
    assert code == 0, err
    for name in LEAF_SPECS:
        assert f"\n  {name}\n" in out
    assert "- max_age (float, default 0.5, >= 0): seconds since" in out
    assert "- pan (float, default 1.4, 0 to 3)" in out
    assert "- seconds (float, required, >= 0)" in out
    assert "- distance (float, default: the mission's value, >= 0.3)" in out
    assert out.index("Conditions:") < out.index("Actions:")


def _mission_with(tmp_path: Path, old: str, new: str) -> Path:
    text = HOUSE_MISSION.read_text(encoding="utf-8")
    assert old in text
    path = tmp_path / "m.yaml"
    path.write_text(text.replace(old, new, 1), encoding="utf-8")
    return path


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--format", "svg"], "--format svg: expected one of ascii, dot, png, btcpp"),
        (["--out", "/no/such/dir/t.txt"], "--out /no/such/dir/t.txt: no such folder /no/such/dir"),
    ],
)
def test_bad_options_exit_2_with_one_line(
    args: list[str],
    message: str,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    code, out, err = run_cli(["bt", "show", str(HOUSE_MISSION), *args], capsys, monkeypatch)
    assert code == 2
    assert message in err and err.count("\n") == 1
    assert out == ""


def test_missing_mission_exits_2(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    code, _, err = run_cli(["bt", "show", str(tmp_path / "no.yaml")], capsys, monkeypatch)
    assert code == 2 and "no.yaml" in err and err.count("\n") == 1


@pytest.mark.parametrize(
    ("old", "new", "message"),
    [
        ("condition: target_visible", "condition: target_seen", "unknown condition 'target_seen'"),
        (
            "- condition: target_visible",
            "- {condition: target_visible, params: {max_age: -1}}",
            "max_age",
        ),
    ],
)
def test_a_mission_with_a_bad_leaf_exits_2_with_one_line(
    old: str,
    new: str,
    message: str,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    mission = _mission_with(tmp_path, old, new)
    for fmt in ("ascii", "png"):
        code, out, err = run_cli(["bt", "show", str(mission), "--format", fmt], capsys, monkeypatch)
        assert code == 2
        assert err.startswith(f"pfctl: error: {mission}:") and message in err
        assert err.count("\n") == 1 and out == ""
    assert [p.name for p in tmp_path.iterdir()] == ["m.yaml"]  # no PNG written


@pytest.mark.slow
def test_console_script_in_a_subprocess(tmp_path: Path) -> None:
    exe = shutil.which("pfctl", path=str(Path(sys.executable).parent))
    if exe is None:
        pytest.skip("the pfctl console script is not installed next to this Python")
    shown = subprocess.run(
        [exe, "bt", "show", str(HOUSE_MISSION), "--format", "png"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        check=False,
    )
    assert shown.returncode == 0, shown.stderr
    assert (tmp_path / "house_tree.png").read_bytes().startswith(b"\x89PNG")
    bad = subprocess.run(
        [exe, "bt", "show", str(HOUSE_MISSION), "--format", "gif"],
        capture_output=True,
        text=True,
        check=False,
    )
    assert bad.returncode == 2
    assert bad.stderr == "pfctl: error: --format gif: expected one of ascii, dot, png, btcpp\n"
