"""`pfctl map annotate|render|export` end to end, and round-trip mission editing."""

from __future__ import annotations

import os
import shutil
import struct
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from shapely.geometry import Polygon

from pfctl.cli import main
from pfctl.core.mapping.house import Door, Region
from pfctl.core.mapping.rooms import polygon_iou
from pfctl.core.mapping.walls import rasterize_house
from pfctl.mission import load_mission
from pfctl.mission.edit import write_regions
from pfctl.mission.map_server import load_map_server

ROOT = Path(__file__).resolve().parents[2]
HOUSE = ROOT / "missions" / "house.yaml"


def cli(monkeypatch, capsys, *args: str) -> tuple[int, str, str]:
    """Run `pfctl ARGS` in-process through the real entry point; (exit code, stdout, stderr)."""
    monkeypatch.setattr(sys, "argv", ["pfctl", *map(str, args)])
    code = 0
    try:
        main()
    except SystemExit as exc:
        code = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
    out, err = capsys.readouterr()
    return code, out, err


def png_size(path: Path) -> tuple[int, int]:
    """(width, height) of a PNG, checking its signature and IHDR chunk."""
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
    assert data[12:16] == b"IHDR"
    return struct.unpack(">II", data[16:24])


def assert_one_error_line(code: int, err: str, *words: str) -> None:
    assert code == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("pfctl: error: "), err
    for w in words:
        assert w in lines[0], (w, lines[0])


@pytest.fixture(scope="module")
def house_map(tmp_path_factory) -> Path:
    """The house rendered by `pfctl map export` into a map_server map (real CLI, subprocess)."""
    out = tmp_path_factory.mktemp("map") / "maps" / "house_map.yaml"
    run = subprocess.run(
        [sys.executable, "-m", "pfctl", "map", "export", str(HOUSE), "--out", str(out)],
        capture_output=True,
        text=True,
        cwd=ROOT,
    )
    assert run.returncode == 0, run.stderr
    assert out.is_file() and out.with_suffix(".pgm").is_file()
    return out


@pytest.mark.slow
def test_auto_annotation_of_the_exported_house_finds_every_room(house_map, tmp_path) -> None:
    """THE KEY TEST. IoU is of shapely polygons: proposed region vs. the house.yaml region."""
    mission_path, png = tmp_path / "m.yaml", tmp_path / "m.png"
    run = subprocess.run(
        [
            sys.executable,
            "-m",
            "pfctl",
            "map",
            "annotate",
            str(house_map),
            "--auto",
            "--out",
            str(mission_path),
            "--png",
            str(png),
        ],
        capture_output=True,
        text=True,
    )
    assert run.returncode == 0, run.stderr
    assert "room_1" in run.stdout  # the summary table

    written = load_mission(mission_path)
    proposed = written.layout().regions
    truth = load_mission(HOUSE).layout()
    for region in truth.regions:
        ious = [polygon_iou(Polygon(p.polygon), Polygon(region.polygon)) for p in proposed]
        matching = [iou for iou in ious if iou >= 0.8]
        assert len(matching) == 1, (region.name, ious)
    assert len(proposed) == len(truth.regions)
    assert len(written.layout().doors) == len(truth.doors)
    assert written.map.occupancy == house_map.resolve()

    width, height = png_size(png)
    assert 400 <= width <= 3000 and 300 <= height <= 3000


def test_export_writes_the_rasterised_house(house_map) -> None:
    loaded = load_map_server(house_map)
    expected = rasterize_house(load_mission(HOUSE).layout(), 0.05)
    assert loaded.geometry == expected.geometry
    assert np.array_equal(loaded.states(), expected.states())


def test_annotate_into_an_existing_mission_keeps_comments_and_sections(
    monkeypatch, capsys, tmp_path
) -> None:
    mission = tmp_path / "house.yaml"
    original = HOUSE.read_text().replace("  obstacles:", "  # my furniture, keep me\n  obstacles:")
    mission.write_text(original)
    code, _, err = cli(monkeypatch, capsys, "map", "annotate", mission, "--auto", "--out", mission)
    assert code == 0, err
    text = mission.read_text()
    for line in original.splitlines():
        if "#" in line:
            assert line in text, line  # every comment survives
    before = original.split("robot:", 1)[1]
    assert text.split("robot:", 1)[1] == before  # the sections after map are untouched
    assert "  # my furniture, keep me\n  obstacles:" in text
    updated = load_mission(mission)
    # named after the regions already there (the mission is its own reference)
    assert [r.name for r in updated.map.regions] == [
        "kitchen",
        "living_room",
        "hall",
        "office",
        "bedroom",
    ]
    assert updated.map.regions[0].polygon != load_mission(HOUSE).map.regions[0].polygon
    assert updated.scenario == load_mission(HOUSE).scenario


def test_manual_region_and_door_flags(monkeypatch, capsys, house_map, tmp_path) -> None:
    out = tmp_path / "sub" / "manual.yaml"
    code, stdout, err = cli(
        monkeypatch,
        capsys,
        "map",
        "annotate",
        house_map,
        "--region",
        "south=0,0;12,0;12,4;0,4",
        "--region",
        "north=0,4;12,4;12,9;0,9",
        "--door",
        "south,north=2,4;2.9,4",
        "--out",
        out,
        "--name",
        "manual",
    )
    assert code == 0, err
    assert "south" in stdout and "north" in stdout
    mission = load_mission(out)
    assert mission.name == "manual"
    layout = mission.layout()
    assert layout.regions == (
        Region("south", ((0, 0), (12, 0), (12, 4), (0, 4))),
        Region("north", ((0, 4), (12, 4), (12, 9), (0, 9))),
    )
    assert layout.doors == (Door(("south", "north"), ((2.0, 4.0), (2.9, 4.0))),)
    assert mission.map.occupancy == house_map.resolve()
    assert "occupancy: ../" in out.read_text()  # relative to the mission's folder


def test_regions_from_a_file_and_a_flag_override(monkeypatch, capsys, house_map, tmp_path):
    regions = tmp_path / "regions.yaml"
    regions.write_text(
        "regions:\n"
        "  - {name: south, polygon: [[0, 0], [12, 0], [12, 4], [0, 4]]}\n"
        "  - {name: north, polygon: [[0, 4], [12, 4], [12, 8], [0, 8]]}\n"
        "doors:\n"
        "  - {between: [south, north], segment: [[8.5, 4], [9.4, 4]]}\n"
    )
    out = tmp_path / "m.yaml"
    code, _, err = cli(
        monkeypatch,
        capsys,
        "map",
        "annotate",
        house_map,
        "--regions",
        regions,
        "--region",
        "north=0,4;12,4;12,9;0,9",
        "--out",
        out,
        "--png",
        tmp_path / "m.png",
    )
    assert code == 0, err
    layout = load_mission(out).layout()
    assert layout.region("north").polygon[2] == (12.0, 9.0)
    assert len(layout.doors) == 1
    png_size(tmp_path / "m.png")


def test_render_draws_a_mission(monkeypatch, capsys, tmp_path) -> None:
    png = tmp_path / "figs" / "house.png"
    code, out, err = cli(monkeypatch, capsys, "map", "render", HOUSE, "--png", png)
    assert code == 0, err
    assert "kitchen" in out
    width, height = png_size(png)
    assert width > 400 and height > 300


def test_render_draws_the_people_walking_their_routes(monkeypatch, capsys, tmp_path) -> None:
    """``--routes``: the scenario's walks as planned, e.g. on a generated home (issue 22)."""
    png, plain = tmp_path / "routes.png", tmp_path / "plain.png"
    code, _, err = cli(monkeypatch, capsys, "map", "render", HOUSE, "--routes", "--png", png)
    assert code == 0, err
    code, _, err = cli(monkeypatch, capsys, "map", "render", HOUSE, "--png", plain)
    assert code == 0, err
    assert png.read_bytes() != plain.read_bytes()
    assert png_size(png)[0] > png_size(plain)[0] * 0.9


@pytest.mark.parametrize(
    ("args", "words"),
    [
        (["{tmp}/missing.yaml", "--auto"], ["missing.yaml", "no such file"]),
        (["{map}", "--region", "kitchen=0,0;5,0"], ["--region", "at least 3 points"]),
        (["{map}", "--region", "kitchen:0,0;5,0;5,4"], ["--region", "NAME=x0,y0"]),
        (["{map}", "--region", "k=0,0;5,x;5,4"], ["--region", "'5,x'"]),
        (["{map}", "--auto", "--door", "a,b,c=0,0;1,0"], ["--door", "A,B="]),
        (
            ["{map}", "--region", "a=0,0;5,0;5,4;0,4", "--door", "a,zz=0,0;1,0"],
            ["unknown region 'zz'"],
        ),
        (
            [
                *("{map}", "--region", "a=0,0;5,0;5,4;0,4"),
                *("--region", "b=5,0;9,0;9,4;5,4", "--door", "a,b=5,5;5,6"),
            ],
            ["doors[0].segment", "shared"],
        ),
        (["{map}"], ["nothing to annotate"]),
        (["{tmp}/notamap.yaml", "--auto"], ["notamap.yaml", "expected a mission"]),
        (["{map}", "--auto", "--resolution", "0.1"], ["--resolution"]),
        (["{map}", "--regions", "{tmp}/nope.yaml"], ["nope.yaml", "no such file"]),
        (["{map}", "--auto", "--min-room-area", "nan"], ["'--min-room-area'", "finite", "nan"]),
        (["{map}", "--auto", "--door-width", "inf"], ["'--door-width'", "finite", "inf"]),
    ],
)
def test_bad_input_exits_2_with_one_line_and_writes_nothing(
    monkeypatch, capsys, house_map, tmp_path, args, words
) -> None:
    (tmp_path / "notamap.yaml").write_text("just: [a, mapping]\n")
    out, png = tmp_path / "out" / "m.yaml", tmp_path / "out" / "m.png"
    filled = [a.format(tmp=tmp_path, map=house_map) for a in args]
    code, _, err = cli(monkeypatch, capsys, "map", "annotate", *filled, "--out", out, "--png", png)
    assert_one_error_line(code, err, *words)
    assert not out.exists() and not png.exists()


def test_a_failed_update_leaves_the_mission_as_it_was(monkeypatch, capsys, tmp_path) -> None:
    mission = tmp_path / "house.yaml"
    shutil.copy(HOUSE, mission)
    before = mission.read_bytes()
    # one region instead of five orphans the scenario's routes → invalid mission, no write
    code, _, err = cli(
        monkeypatch,
        capsys,
        "map",
        "annotate",
        mission,
        "--region",
        "a=0,0;12,0;12,9;0,9",
        "--out",
        mission,
    )
    assert_one_error_line(code, err, str(mission))
    assert mission.read_bytes() == before
    assert [p.name for p in tmp_path.iterdir()] == ["house.yaml"]  # no temp file left


def test_export_bad_input(monkeypatch, capsys, tmp_path) -> None:
    code, _, err = cli(monkeypatch, capsys, "map", "export", tmp_path / "x.yaml", "--out", "m.yaml")
    assert_one_error_line(code, err, "x.yaml")
    code, _, err = cli(monkeypatch, capsys, "map", "export", HOUSE, "--out", tmp_path / "m.png")
    assert_one_error_line(code, err, "--out", ".yaml")
    assert list(tmp_path.iterdir()) == []


def test_export_refuses_a_resolution_whose_grids_exceed_the_memory_limit(
    monkeypatch, capsys, tmp_path
) -> None:
    """``--resolution 1e-6`` made grids of 10**13 cells (a MemoryError traceback): refused with
    the mission's grid memory limit before any grid is made."""
    out = tmp_path / "m.yaml"
    code, _, err = cli(
        monkeypatch, capsys, "map", "export", HOUSE, "--resolution", "1e-6", "--out", out
    )
    assert_one_error_line(code, err, "--resolution 1e-06", "over the limit of 2 GiB")
    assert list(tmp_path.iterdir()) == []


def test_write_regions_creates_a_minimal_mission(tmp_path) -> None:
    target = tmp_path / "new.yaml"
    regions = [Region("r", ((0, 0), (1.23456, 0), (1.23456, 2), (0, 2)))]
    write_regions(target, regions, [], name="tiny", resolution=0.05)
    text = target.read_text()
    assert text.startswith("name: tiny\nmap:\n  resolution: 0.05\n  occupancy: null\n")
    assert "- {name: r, polygon: [[0, 0], [1.23, 0], [1.23, 2], [0, 2]]}" in text
    assert "doors: []" in text
    assert load_mission(target).map.regions[0].name == "r"
    assert oct(os.stat(target).st_mode & 0o777) != "0o600"  # a normal file, not a temp file's mode


def test_auto_drops_a_door_off_the_shared_wall_with_one_warning(
    monkeypatch, capsys, house_map, tmp_path
) -> None:
    """A proposed door the mission rules reject is dropped with one warning; exit 0, written."""
    import pfctl.commands.map as map_command
    from pfctl.core.mapping.rooms import ProposedDoor

    real = map_command.segment_free_space

    def with_a_corner_cutting_door(states, geometry, params):
        seg = real(states, geometry, params)
        bad = ProposedDoor(between=seg.doors[0].between, segment=((0.5, 0.5), (1.5, 1.7)))
        return replace(seg, doors=(*seg.doors, bad))

    monkeypatch.setattr(map_command, "segment_free_space", with_a_corner_cutting_door)
    out = tmp_path / "m.yaml"
    code, stdout, err = cli(
        monkeypatch, capsys, "map", "annotate", house_map, "--auto", "--out", out
    )
    assert code == 0, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("pfctl: warning: "), err
    assert "dropped 1 proposed door" in lines[0]
    written = load_mission(out).layout()
    assert len(written.regions) == 5 and len(written.doors) == 5
    assert "wrote" in stdout


def _save_states(states: np.ndarray, geometry, path: Path) -> Path:
    """A trinary map written as map_server YAML + PGM, as a SLAM package's map_saver would."""
    from pfctl.core.mapping.grid import FREE, OCCUPIED, OccupancyGrid
    from pfctl.mission.map_server import save_map_server

    p = np.where(states == FREE, 0.0, np.where(states == OCCUPIED, 1.0, 0.5))
    grid = OccupancyGrid.from_probabilities(p, geometry.resolution, origin=geometry.origin)
    return save_map_server(grid, path)[0]


def test_auto_annotation_of_the_house_turned_by_17_degrees_finds_every_room(
    monkeypatch, capsys, house_map, tmp_path
) -> None:
    """A SLAM map is turned by wherever the mapping started: the exported house turned by 17°
    still gives its 5 rooms and 5 doors, turned with it, with no warning."""
    import math

    from pfctl.core.mapping.orientation import rotate_points, rotated_map

    angle = math.radians(17.0)
    loaded = load_map_server(house_map)
    states, geometry = rotated_map(loaded.states(), loaded.geometry, angle)
    turned_map = _save_states(states, geometry, tmp_path / "turned.yaml")
    out = tmp_path / "m.yaml"
    code, _, err = cli(monkeypatch, capsys, "map", "annotate", turned_map, "--auto", "--out", out)
    assert code == 0 and err == "", err
    written = load_mission(out).layout()
    truth = load_mission(HOUSE).layout()
    for region in truth.regions:
        turned = Polygon(rotate_points(np.asarray(region.polygon), angle))
        ious = [polygon_iou(Polygon(p.polygon), turned) for p in written.regions]
        assert sum(iou >= 0.8 for iou in ious) == 1, (region.name, ious)
    assert len(written.regions) == 5 and len(written.doors) == 5


def test_auto_on_walls_in_no_dominant_direction_warns_once_and_writes(
    monkeypatch, capsys, tmp_path
) -> None:
    """Two hexagonal rooms: no wall angle to segment at, so the distance transform does it, with
    one warning line; exit 0 and the mission written."""
    import math

    def hexagon(cx: float, cy: float) -> tuple[tuple[float, float], ...]:
        return tuple(
            (
                round(cx + 3 * math.cos(k * math.pi / 3), 6),
                round(cy + 3 * math.sin(k * math.pi / 3), 6),
            )
            for k in range(6)
        )

    from pfctl.core.mapping.house import HouseLayout

    door = ((2.5, round(math.sqrt(3) / 2, 6)), (2.0, round(math.sqrt(3), 6)))
    layout = HouseLayout(
        regions=(Region("a", hexagon(0, 0)), Region("b", hexagon(4.5, 1.5 * math.sqrt(3)))),
        doors=(Door(("a", "b"), door),),
    )
    grid = rasterize_house(layout, 0.05)
    hex_map = _save_states(grid.states(), grid.geometry, tmp_path / "hex.yaml")
    out = tmp_path / "m.yaml"
    code, stdout, err = cli(monkeypatch, capsys, "map", "annotate", hex_map, "--auto", "--out", out)
    assert code == 0, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("pfctl: warning: "), err
    assert "no dominant direction" in lines[0] and "distance transform" in lines[0]
    written = load_mission(out).layout()
    assert len(written.regions) == 2 and len(written.doors) == 1
    assert "wrote" in stdout
