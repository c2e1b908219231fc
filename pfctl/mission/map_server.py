"""ROS map_server maps (a YAML file and a PGM image): the files a mission's ``map.occupancy``
names, read and written as the map_server and map_saver nodes do.

The occupancy grid itself and its conversion to and from nav_msgs/OccupancyGrid values are
core's (:class:`~pfctl.core.mapping.grid.OccupancyGrid`); this module is the file format.
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Any

import numpy as np
import yaml
from numpy.typing import NDArray

from pfctl.core.mapping.grid import (
    FREE,
    FREE_THRESH,
    OCCUPIED,
    OCCUPIED_THRESH,
    InverseSensorModel,
    OccupancyGrid,
)
from pfctl.files import atomic_write_all

__all__ = ["GridFileError", "load_map_server", "map_server_size", "read_pgm", "save_map_server"]

#: Pixel values written by map_saver in trinary mode.
PGM_FREE = 254
PGM_OCCUPIED = 0
PGM_UNKNOWN = 205

_MAP_MODES = ("trinary", "scale", "raw")
#: A PGM header (magic, comments, width, height, maxval) is read from this many first bytes.
_HEADER_BYTES = 65536


class GridFileError(ValueError):
    """A map file (map_server YAML or PGM) that cannot be read or written.

    The message is one line that names the file and says what is wrong; the commands turn it
    into exit status 2 (DESIGN.md, "Conventions").
    """


def save_map_server(
    grid: OccupancyGrid,
    yaml_path: str | os.PathLike[str],
    free_thresh: float = FREE_THRESH,
    occupied_thresh: float = OCCUPIED_THRESH,
) -> tuple[Path, Path]:
    """Write ``grid`` as ``<name>.yaml`` and ``<name>.pgm``, as ROS map_saver does (trinary).

    ``yaml_path`` may end in ``.yaml``/``.yml``; otherwise ``.yaml`` is appended. Cells are
    classified with :meth:`OccupancyGrid.states` (``free_thresh`` / ``occupied_thresh``) and
    written as free 254, occupied 0, unknown 205 in a binary 8-bit PGM (P5) whose first row is
    the top of the map (highest y). The YAML always carries map_server's standard ``occupied_thresh:
    0.65`` and ``free_thresh: 0.196``, which decode 254/0/205 back to free/occupied/unknown.
    Both files are written to temporary files and moved into place (``os.replace``), so an
    error leaves no partial file. Returns (yaml path, pgm path).
    """
    yaml_file = Path(yaml_path)
    if yaml_file.suffix.lower() not in (".yaml", ".yml"):
        yaml_file = yaml_file.with_name(yaml_file.name + ".yaml")
    pgm_file = yaml_file.with_suffix(".pgm")
    states = grid.states(free_thresh, occupied_thresh)
    pixels = np.full(states.shape, PGM_UNKNOWN, dtype=np.uint8)
    pixels[states == FREE] = PGM_FREE
    pixels[states == OCCUPIED] = PGM_OCCUPIED
    pixels = pixels[::-1]  # first image row = top of the map
    header = (
        f"P5\n# CREATOR: pfctl {grid.resolution:.3f} m/pix\n{grid.width} {grid.height}\n255\n"
    ).encode("ascii")
    meta = {
        "image": pgm_file.name,
        "resolution": float(grid.resolution),
        "origin": [float(grid.origin[0]), float(grid.origin[1]), 0.0],
        "negate": 0,
        "occupied_thresh": OCCUPIED_THRESH,
        "free_thresh": FREE_THRESH,
        "mode": "trinary",
    }
    text = yaml.safe_dump(meta, sort_keys=False, default_flow_style=None)
    try:
        atomic_write_all(
            [(pgm_file, header + np.ascontiguousarray(pixels).tobytes()), (yaml_file, text)]
        )
    except OSError as err:
        raise GridFileError(f"{yaml_file}: cannot write map: {err.strerror or err}") from err
    return yaml_file, pgm_file


def _map_yaml(path: Path) -> tuple[dict[str, Any], Path, float]:
    """A map_server YAML's fields, its image's path (relative to the YAML) and its resolution,
    checked (> 0)."""
    meta = _read_yaml(path)
    image_name = _field(meta, "image", path, str)
    resolution = _number(meta, "resolution", path)
    if not resolution > 0:
        raise GridFileError(f"{path}: resolution must be > 0, got {resolution}")
    image_path = Path(image_name)
    if not image_path.is_absolute():
        image_path = path.parent / image_path
    return meta, image_path, resolution


def load_map_server(
    yaml_path: str | os.PathLike[str], sensor_model: InverseSensorModel | None = None
) -> OccupancyGrid:
    """Read a ROS map_server map (YAML + PGM image) as the map_server node would.

    The YAML needs ``image`` (absolute, or relative to the YAML's folder), ``resolution`` and
    ``origin`` [x, y, yaw]; ``negate`` (0), ``occupied_thresh`` (0.65), ``free_thresh``
    (0.196) and ``mode`` (trinary) are optional. Only yaw = 0 is supported. The image must be
    a PGM: binary P5 (8 or 16 bit) or ASCII P2; values are scaled to 0..255 and the first
    image row is the top of the map. Per pixel x, p = (255 − x)/255, or x/255 with negate;
    then, as map_server does:

    - trinary: p > occupied_thresh → occupied (stored as p = 1, saturated), p < free_thresh →
      free (p = 0, saturated), otherwise unknown (p = 0.5);
    - scale: as trinary for the extremes, otherwise the value 99·(p − free)/(occ − free),
      stored as p = value/100;
    - raw: the value x itself (after negate) is the occupancy 0..100, stored as p = x/100;
      x ≥ 101 (255 = −1 as int8) is unknown.

    Anything wrong with either file raises :class:`GridFileError` naming the file.
    """
    path = Path(yaml_path)
    meta, image_path, resolution = _map_yaml(path)
    origin = meta.get("origin")
    if origin is None:
        raise GridFileError(f"{path}: missing required key 'origin'")
    if not isinstance(origin, list) or len(origin) not in (2, 3):
        raise GridFileError(f"{path}: origin must be a list [x, y, yaw], got {origin!r}")
    if not all(_is_number(v) and math.isfinite(v) for v in origin):
        raise GridFileError(f"{path}: origin must hold finite numbers, got {origin!r}")
    if len(origin) == 3 and abs(float(origin[2])) > 1e-12:
        raise GridFileError(
            f"{path}: origin yaw {origin[2]} is not supported (only unrotated maps, yaw 0)"
        )
    negate = meta.get("negate", 0)
    if negate not in (0, 1) or not isinstance(negate, (int, bool)):
        raise GridFileError(f"{path}: negate must be 0 or 1, got {negate!r}")
    occ_th = _number(meta, "occupied_thresh", path, OCCUPIED_THRESH)
    free_th = _number(meta, "free_thresh", path, FREE_THRESH)
    if not 0.0 <= free_th < occ_th <= 1.0:
        raise GridFileError(
            f"{path}: need 0 ≤ free_thresh < occupied_thresh ≤ 1, got {free_th}, {occ_th}"
        )
    mode = meta.get("mode", "trinary")
    if mode not in _MAP_MODES:
        raise GridFileError(f"{path}: mode must be one of {', '.join(_MAP_MODES)}, got {mode!r}")

    color = read_pgm(image_path)  # float 0..255, first row = top
    if negate:
        color = 255.0 - color
    if mode == "raw":
        raw = np.rint(color)
        values = np.where(raw <= 100, raw, -1)
    else:
        p = (255.0 - color) / 255.0
        if mode == "trinary":
            middle = np.full(p.shape, -1.0)
        else:
            middle = np.rint(99.0 * (p - free_th) / (occ_th - free_th))
        values = np.where(p > occ_th, 100, np.where(p < free_th, 0, middle))
    values = values[::-1].astype(np.int64)  # row 0 = bottom of the map
    height, width = values.shape
    return OccupancyGrid.from_occupancy_values(
        values, width, height, resolution, (float(origin[0]), float(origin[1])), sensor_model
    )


def _is_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _field(meta: dict[str, Any], key: str, path: Path, kind: type) -> Any:
    if key not in meta:
        raise GridFileError(f"{path}: missing required key '{key}'")
    value = meta[key]
    if not isinstance(value, kind) or (kind is str and not value):
        raise GridFileError(f"{path}: {key} must be a {kind.__name__}, got {value!r}")
    return value


def _number(meta: dict[str, Any], key: str, path: Path, default: float | None = None) -> float:
    if key not in meta:
        if default is None:
            raise GridFileError(f"{path}: missing required key '{key}'")
        return default
    value = meta[key]
    if not _is_number(value) or not math.isfinite(value):
        raise GridFileError(f"{path}: {key} must be a finite number, got {value!r}")
    return float(value)


def _read_yaml(path: Path) -> dict[str, Any]:
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError as err:
        raise GridFileError(f"{path}: map YAML not found") from err
    except (OSError, UnicodeDecodeError) as err:
        raise GridFileError(f"{path}: cannot read map YAML: {err}") from err
    try:
        meta = yaml.safe_load(text)
    except yaml.YAMLError as err:
        where = getattr(err, "problem_mark", None)
        line = f" at line {where.line + 1}" if where is not None else ""
        problem = getattr(err, "problem", None) or "syntax error"
        raise GridFileError(f"{path}: invalid YAML{line}: {problem}") from err
    if not isinstance(meta, dict):
        raise GridFileError(f"{path}: map YAML must be a mapping of keys to values")
    return meta


def _pgm_header(data: bytes, path: Path) -> tuple[bytes, int, int, int, int]:
    """``(magic, width, height, maxval, offset after maxval)`` of a PGM's first bytes."""
    magic = data[:2]
    if magic not in (b"P5", b"P2"):
        shown = magic.decode("latin-1") if magic[:1] == b"P" else "not a PNM file"
        raise GridFileError(
            f"{path}: unsupported image ({shown}); only PGM (P5 binary or P2 ASCII) is read"
        )
    tokens: list[int] = []
    pos = 2
    while len(tokens) < 3:
        while pos < len(data) and data[pos : pos + 1].isspace():
            pos += 1
        if pos < len(data) and data[pos : pos + 1] == b"#":
            end = data.find(b"\n", pos)
            pos = len(data) if end < 0 else end + 1
            continue
        start = pos
        while pos < len(data) and not data[pos : pos + 1].isspace() and data[pos] != ord("#"):
            pos += 1
        token = data[start:pos]
        if not token.isdigit():
            raise GridFileError(f"{path}: bad PGM header (expected width, height and maxval)")
        tokens.append(int(token))
    width, height, maxval = tokens
    if width < 1 or height < 1 or not 0 < maxval < 65536:
        raise GridFileError(f"{path}: bad PGM header (size {width}×{height}, maxval {maxval})")
    return magic, width, height, maxval, pos


def map_server_size(yaml_path: str | os.PathLike[str]) -> tuple[int, int, float]:
    """``(width, height, resolution)`` of a map_server map without decoding its pixels: the
    YAML's ``image`` and ``resolution`` are checked as :func:`load_map_server` checks them, the
    image's PGM header is read, and a binary image must hold all its pixels. Raises
    :class:`GridFileError` naming the file, so a mission can refuse an unreadable or oversized
    map before anything loads it."""
    path = Path(yaml_path)
    _, image_path, resolution = _map_yaml(path)
    try:
        with image_path.open("rb") as handle:
            head = handle.read(_HEADER_BYTES)
            size = os.fstat(handle.fileno()).st_size
    except FileNotFoundError as err:
        raise GridFileError(f"{image_path}: map image not found") from err
    except OSError as err:
        raise GridFileError(f"{image_path}: cannot read map image: {err.strerror or err}") from err
    magic, width, height, maxval, pos = _pgm_header(head, image_path)
    if magic == b"P5":
        need = width * height * (2 if maxval > 255 else 1)
        if size - pos - 1 < need:
            raise GridFileError(
                f"{image_path}: PGM pixel data truncated ({max(size - pos - 1, 0)} bytes, "
                f"{need} expected)"
            )
    return width, height, resolution


def read_pgm(path: str | os.PathLike[str]) -> NDArray[np.float64]:
    """Pixels of a PGM image as floats scaled to 0..255, shape (rows, cols), first row = top.

    Reads binary P5 (maxval ≤ 255: 1 byte per pixel; up to 65535: 2 bytes, big-endian) and ASCII
    P2, with ``#`` comments in the header. Raises :class:`GridFileError` naming the file.
    """
    path = Path(path)
    try:
        data = path.read_bytes()
    except FileNotFoundError as err:
        raise GridFileError(f"{path}: map image not found") from err
    except OSError as err:
        raise GridFileError(f"{path}: cannot read map image: {err.strerror or err}") from err
    magic, width, height, maxval, pos = _pgm_header(data, path)
    count = width * height
    if magic == b"P5":
        if pos >= len(data) or not data[pos : pos + 1].isspace():
            raise GridFileError(f"{path}: bad PGM header (no whitespace after maxval)")
        pos += 1
        dtype = np.dtype(">u2") if maxval > 255 else np.dtype(np.uint8)
        if len(data) - pos < count * dtype.itemsize:
            raise GridFileError(
                f"{path}: PGM pixel data truncated ({len(data) - pos} bytes, "
                f"{count * dtype.itemsize} expected)"
            )
        pixels = np.frombuffer(data, dtype=dtype, count=count, offset=pos).astype(np.int64)
    else:
        body = b"\n".join(line.split(b"#", 1)[0] for line in data[pos:].splitlines())
        words = body.split()
        if len(words) != count or not all(w.isdigit() for w in words):
            raise GridFileError(f"{path}: P2 pixel data must be {count} non-negative integers")
        pixels = np.array([int(w) for w in words], dtype=np.int64)
    if pixels.size and int(pixels.max()) > maxval:
        raise GridFileError(f"{path}: PGM pixel value above maxval {maxval}")
    return pixels.reshape(height, width) * (255.0 / maxval)
