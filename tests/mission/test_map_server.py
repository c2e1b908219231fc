"""Tests of pfctl.mission.map_server: ROS map_server maps (YAML + PGM) written and read as
map_saver and map_server do, with one-line errors naming the file."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

from pfctl.core.mapping.grid import FREE, OCCUPIED, UNKNOWN, OccupancyGrid
from pfctl.mission.map_server import GridFileError, load_map_server, save_map_server


def asymmetric_grid() -> OccupancyGrid:
    """8 × 6 cells: free lower half, an occupied cell in the top row (highest y) at column 2."""
    p = np.full((6, 8), 0.5)
    p[:3, :] = 0.0
    p[5, 2] = 1.0
    p[0, 7] = 0.9
    return OccupancyGrid.from_probabilities(p, 0.05, origin=(-1.5, 2.25))


def read_pgm_bytes(path: Path) -> tuple[int, int, np.ndarray]:
    data = path.read_bytes()
    lines = data.split(b"\n", 4)  # P5, comment, "w h", "255", pixels
    assert lines[0] == b"P5" and lines[1].startswith(b"#") and lines[3] == b"255"
    width, height = map(int, lines[2].split())
    return width, height, np.frombuffer(lines[4], dtype=np.uint8).reshape(height, width)


def test_save_map_server_writes_map_saver_files(tmp_path: Path) -> None:
    yaml_path, pgm_path = save_map_server(asymmetric_grid(), tmp_path / "house.yaml")
    assert (yaml_path, pgm_path) == (tmp_path / "house.yaml", tmp_path / "house.pgm")
    meta = yaml.safe_load(yaml_path.read_text())
    assert meta == {
        "image": "house.pgm",
        "resolution": 0.05,
        "origin": [-1.5, 2.25, 0.0],
        "negate": 0,
        "occupied_thresh": 0.65,
        "free_thresh": 0.196,
        "mode": "trinary",
    }
    width, height, pixels = read_pgm_bytes(pgm_path)
    assert (width, height) == (8, 6)
    # First PGM row = top of the map = grid row 5: the occupied cell (0) at column 2.
    assert pixels[0].tolist() == [205, 205, 0, 205, 205, 205, 205, 205]
    # Grid row 0 (lowest y) is the last PGM row: free (254) with the occupied cell at column 7.
    assert pixels[5].tolist() == [254] * 7 + [0]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["house.pgm", "house.yaml"]


def test_map_server_round_trip(tmp_path: Path) -> None:
    grid = asymmetric_grid()
    save_map_server(grid, tmp_path / "maps_house")  # ".yaml" is appended
    back = load_map_server(tmp_path / "maps_house.yaml")
    assert back.geometry == grid.geometry
    assert np.array_equal(back.states(), grid.states())
    # Trinary load: occupied → p ≈ 1, free → p ≈ 0, unknown → exactly 0.5.
    assert back.prob()[5, 2] > 0.999999
    assert back.prob()[0, 0] < 1e-6
    assert back.prob()[4, 4] == 0.5


def test_save_map_server_leaves_no_partial_files(tmp_path: Path, monkeypatch) -> None:
    with pytest.raises(GridFileError, match="missing_dir"):
        save_map_server(asymmetric_grid(), tmp_path / "missing_dir" / "map.yaml")

    def broken_replace(src, dst):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr("pfctl.files.os.replace", broken_replace)
    with pytest.raises(GridFileError, match=r"map\.yaml"):
        save_map_server(asymmetric_grid(), tmp_path / "map.yaml")
    assert list(tmp_path.iterdir()) == []


def write_map(tmp_path: Path, pixels: bytes, **meta) -> Path:
    (tmp_path / "img.pgm").write_bytes(pixels)
    doc = {"image": "img.pgm", "resolution": 0.1, "origin": [0.0, 0.0, 0.0], **meta}
    path = tmp_path / "map.yaml"
    path.write_text(yaml.safe_dump(doc))
    return path


def test_load_ascii_p2_with_comments_and_modes(tmp_path: Path) -> None:
    # One row of 4 pixels: 0, 254, 205, 100 (the image's only row is grid row 0).
    p2 = b"P2\n# a comment\n4 1\n# another\n255\n0 254\n205 100\n"
    path = write_map(tmp_path, p2)
    # trinary: p = (255 − x)/255 = 1.0, 0.0039, 0.19608, 0.60784
    #          → occupied, free, unknown (0.19608 ≥ 0.196), unknown (≤ 0.65).
    grid = load_map_server(path)
    assert grid.states().tolist() == [[OCCUPIED, FREE, UNKNOWN, UNKNOWN]]
    assert grid.to_occupancy_values().tolist() == [100, 0, -1, -1]
    # scale: the in-between values become 99·(p − 0.196)/(0.65 − 0.196):
    #   x = 205: 99 · 0.000078/0.454 = 0.017 → 0; x = 100: 99 · 0.411843/0.454 = 89.81 → 90.
    grid = load_map_server(write_map(tmp_path, p2, mode="scale"))
    assert grid.prob()[0].tolist() == pytest.approx([1.0, 0.0, 0.0, 0.9], abs=1e-6)
    # negate: p = x/255 = 0, 0.996, 0.804, 0.392 → free, occupied, occupied, unknown.
    grid = load_map_server(write_map(tmp_path, p2, negate=1))
    assert grid.states().tolist() == [[FREE, OCCUPIED, OCCUPIED, UNKNOWN]]


def test_load_raw_mode_and_16_bit_p5(tmp_path: Path) -> None:
    # raw: the pixel is the occupancy value: 0 → 0, 42 → 0.42, 100 → 1, 255 → unknown.
    p5 = b"P5\n2 2\n255\n" + bytes([0, 42, 100, 255])
    grid = load_map_server(write_map(tmp_path, p5, mode="raw"))
    # The first image row [0, 42] is the top of the map = grid row 1.
    assert grid.prob()[1].tolist() == pytest.approx([0.0, 0.42], abs=1e-6)
    assert grid.prob()[0].tolist() == pytest.approx([1.0, 0.5], abs=1e-6)
    # 16-bit: maxval 65535, values scaled to 0..255: 65535 → 255 → free; 0 → occupied.
    p5_16 = b"P5\n2 1\n65535\n" + np.array([65535, 0], dtype=">u2").tobytes()
    grid = load_map_server(write_map(tmp_path, p5_16))
    assert grid.states().tolist() == [[FREE, OCCUPIED]]


@pytest.mark.parametrize(
    ("image", "meta", "message"),
    [
        (b"P5\n1 1\n255\n\x00", {"image": None}, "missing required key 'image'"),
        (b"P5\nabc\n", {}, "bad PGM header"),
        (b"P6\n1 1\n255\n\x00\x00\x00", {}, "unsupported image"),
        (b"P5\n4 4\n255\n\x00", {}, "truncated"),
        (b"P5\n1 1\n255\n\x00", {"image": "nowhere.pgm"}, "not found"),
        (b"P5\n1 1\n255\n\x00", {"origin": [0.0, 0.0, 0.5]}, "yaw"),
        (b"P5\n1 1\n255\n\x00", {"resolution": "fine"}, "resolution"),
        (b"P5\n1 1\n255\n\x00", {"mode": "fancy"}, "mode"),
    ],
)
def test_bad_map_files_raise_grid_file_error(
    tmp_path: Path, image: bytes, meta: dict, message: str
) -> None:
    path = write_map(tmp_path, image, **meta)
    if meta.get("image", "") is None:
        doc = yaml.safe_load(path.read_text())
        del doc["image"]
        path.write_text(yaml.safe_dump(doc))
    with pytest.raises(GridFileError, match=message) as info:
        load_map_server(path)
    text = str(info.value)
    assert "\n" not in text
    assert "map.yaml" in text or ".pgm" in text
    assert isinstance(info.value, ValueError)


def test_bad_yaml_and_missing_yaml(tmp_path: Path) -> None:
    path = tmp_path / "broken.yaml"
    path.write_text("image: [unclosed\n")
    with pytest.raises(GridFileError, match=r"broken\.yaml: invalid YAML"):
        load_map_server(path)
    path.write_text("- just\n- a list\n")
    with pytest.raises(GridFileError, match="mapping"):
        load_map_server(path)
    with pytest.raises(GridFileError, match="not found"):
        load_map_server(tmp_path / "absent.yaml")
