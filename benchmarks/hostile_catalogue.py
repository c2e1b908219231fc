"""The cases of ``hostile_inputs.py``: bad inputs and interruptions across every pfctl command.

Each :class:`Case` is a small declarative record: the argv (after ``python -m pfctl``), the files
it needs in its own empty working folder, and what "handled cleanly" means for it
(:class:`Expect`). The runner (``hostile_inputs.py``) makes the files, runs the command and
checks the outcome; nothing here runs pfctl.

Placeholders in an argv are filled by the runner: ``{ws}`` the case's working folder (also its
current directory), ``{repo}`` the repository root (for ``missions/``), and the shared fixtures
made once per run: ``{target}`` (a target profile learned with ``pfctl learn-target``), ``{bag}``
(a 3 s recording of ``pfctl sim run --record``) and ``{campaign}`` (a finished one-episode
``pfctl bench`` folder).
"""

from __future__ import annotations

import copy
import io
import random
import struct
import zipfile
import zlib
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

ROOT = Path(__file__).resolve().parents[1]
HOUSE = ROOT / "missions" / "house.yaml"

# What a fixture is: literal bytes/text, a mission dict (dumped as YAML), or bytes made from the
# shared fixtures (``Shared`` in hostile_inputs.py, with .target, .bag, .campaign paths).
Content = bytes | str | dict[str, Any] | Callable[[Any], bytes]


@dataclass(frozen=True)
class Expect:
    """What a clean outcome is.

    ``kind``:
      * ``error``: exit 2; stderr is one line ``pfctl: error: ...`` containing every string of
        ``names``; the working folder is unchanged (no partial output).
      * ``error_or_run``: as ``error``, or the command runs normally (exit 0) — for values such
        as a negative seed that a command may reasonably accept.
      * ``interrupt``: exit ``code`` (130 SIGINT, 143 SIGTERM) with one line on stderr saying so
        (other log lines allowed); every path of ``outputs`` exists and parses (JSON, JSON
        lines, CSV, PNG by extension).
      * ``warn``: exit 0; stderr names every string of ``names`` (a repaired input said aloud).
      * ``survive``: exit 0 although a worker was killed; ``outputs`` exist and parse, and
        ``results.jsonl`` holds ``records`` episodes.
    ``avoid``: words the error line must not say (a library's message that misleads the user).
    Every kind also requires: no ``Traceback``, finished within the case's timeout and memory
    limit, no process of the command left behind.
    """

    kind: str
    names: tuple[str, ...] = ()
    code: int = 2
    outputs: tuple[str, ...] = ()
    records: int = 0
    avoid: tuple[str, ...] = ()

    def describe(self) -> str:
        """A few words for the table: what the case expects."""
        if self.kind in ("error", "error_or_run"):
            alt = " or run" if self.kind == "error_or_run" else ""
            return f"exit 2{alt}, 1 line naming {', '.join(self.names) or '-'}"
        if self.kind == "interrupt":
            return f"exit {self.code}, 1 line, {len(self.outputs)} outputs"
        if self.kind == "warn":
            return f"exit 0, says {', '.join(self.names)}"
        return f"exit 0, {self.records} episodes, no orphan"


@dataclass(frozen=True)
class Interrupt:
    """Signals sent once the run has started: ``(seconds after start, signal name, to)``, where
    ``to`` is ``group`` (the terminal's Ctrl-C reaches the whole process group), ``main`` (what
    ``timeout``/``docker stop`` signal) or ``worker`` (SIGKILL of one bench worker).

    The run has started when stderr's progress bar shows ``progress`` simulated seconds (the
    bar is forced on with FORCE_COLOR) or, if ``lines_in`` is set, when that file of the working
    folder has ``progress`` lines."""

    signals: tuple[tuple[float, str, str], ...]
    progress: float = 1.0
    lines_in: str | None = None


@dataclass(frozen=True)
class Case:
    """One hostile input or interruption and what handling it cleanly means."""

    id: str
    command: str
    argv: tuple[str, ...]
    expect: Expect
    files: dict[str, Content] = field(default_factory=dict)
    interrupt: Interrupt | None = None
    needs: tuple[str, ...] = ()
    timeout: float = 90.0
    memory_mb: int = 4096
    setup: Callable[[Path], str | None] | None = None
    why: str = ""


# ---------------------------------------------------------------- mission fixtures


def house() -> dict[str, Any]:
    """missions/house.yaml as a dict (self-contained: no extends, no include)."""
    return copy.deepcopy(_HOUSE)


_HOUSE: dict[str, Any] = yaml.safe_load(HOUSE.read_text(encoding="utf-8"))


def edited(path: str, value: Any) -> dict[str, Any]:
    """house.yaml with the dotted ``path`` set to ``value`` (list indices as numbers)."""
    data = house()
    *parents, last = path.split(".")
    node: Any = data
    for key in parents:
        node = node[int(key)] if isinstance(node, list) else node[key]
    if isinstance(node, list):
        node[int(last)] = value
    else:
        node[last] = value
    return data


def without(path: str) -> dict[str, Any]:
    """house.yaml without the dotted ``path``."""
    data = house()
    *parents, last = path.split(".")
    node: Any = data
    for key in parents:
        node = node[int(key)] if isinstance(node, list) else node[key]
    del node[int(last) if isinstance(node, list) else last]
    return data


def dump(data: Any) -> str:
    """YAML text of a fixture dict."""
    return yaml.safe_dump(data, sort_keys=False)


def random_bytes(n: int, seed: int = 21) -> bytes:
    """``n`` seeded random bytes."""
    return random.Random(seed).randbytes(n)


def huge_map() -> dict[str, Any]:
    """A 1000 x 1000 m house at 0.05 m: 20000 x 20000 cells per grid (3.2 GB as float64)."""
    data = house()
    data["map"]["regions"] = [
        {"name": "hall", "polygon": [[0, 0], [1000, 0], [1000, 1000], [0, 1000]]}
    ]
    data["map"]["doors"] = []
    data["map"]["obstacles"] = []
    for person in data["scenario"]["people"]:
        person["route"] = [[10, 10], [20, 20]]
    return data


def route_in_furniture() -> dict[str, Any]:
    """Alice's route passes a point inside the dining table (1.2-2.4 x 2.0-2.8)."""
    data = house()
    data["scenario"]["people"][0]["route"] = [[3.8, 2.6], [1.8, 2.4], [1.0, 7.0]]
    return data


def extends_loop(other: str) -> str:
    """A mission that extends ``other`` (which extends it back)."""
    return f"extends: {other}\nname: loop\n"


def pgm(width: int, height: int, value: int = 254) -> bytes:
    """A binary PGM image."""
    return f"P5\n{width} {height}\n255\n".encode() + bytes([value]) * (width * height)


def map_server_yaml(image: str, resolution: float = 0.05) -> str:
    """A map_server YAML pointing at ``image``."""
    return (
        f"image: {image}\nresolution: {resolution}\norigin: [0.0, 0.0, 0.0]\n"
        "negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n"
    )


def with_occupancy(name: str) -> dict[str, Any]:
    """house.yaml using the map_server map ``name`` (relative to the mission)."""
    return edited("map.occupancy", name)


def npz(arrays: dict[str, Any]) -> bytes:
    """An .npz of plain arrays (numpy imported here only)."""
    import numpy as np

    buf = io.BytesIO()
    np.savez(buf, **{k: np.asarray(v) for k, v in arrays.items()})
    return buf.getvalue()


def pickled_npz() -> bytes:
    """An .npz whose one array is an object array (needs allow_pickle to load)."""
    import numpy as np

    buf = io.BytesIO()
    np.savez(buf, profile=np.array([{"a": 1}], dtype=object))
    return buf.getvalue()


def zip_of(name: str, data: bytes) -> bytes:
    """A zip (an .npz is one) with one member that is not an .npy."""
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as z:
        z.writestr(name, data)
    return buf.getvalue()


def png_bytes(width: int = 4, height: int = 4) -> bytes:
    """A tiny valid grey PNG."""

    def chunk(kind: bytes, data: bytes) -> bytes:
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body))

    raw = b"".join(b"\x00" + b"\x80" * width for _ in range(height))
    return (
        b"\x89PNG\r\n\x1a\n"
        + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 0, 0, 0, 0))
        + chunk(b"IDAT", zlib.compress(raw))
        + chunk(b"IEND", b"")
    )


def head(name: str, n: int) -> Callable[[Any], bytes]:
    """The first ``n`` bytes of a shared fixture file (``target``) or of the bag."""

    def make(shared: Any) -> bytes:
        return Path(getattr(shared, name)).read_bytes()[:n]

    return make


def readonly_dir(ws: Path) -> str | None:
    """Make ``ws/ro`` read-only; a skip reason when that does not stop writes (root)."""
    ro = ws / "ro"
    ro.mkdir()
    ro.chmod(0o555)
    probe = ro / ".probe"
    try:
        probe.write_bytes(b"")
    except OSError:
        return None
    probe.unlink()
    ro.chmod(0o755)
    return "running as root: chmod 555 does not stop writes (the 'under a file' cases cover it)"


def unreadable_file(ws: Path) -> str | None:
    """Make ``ws/m.yaml`` unreadable; a skip reason when that does not stop reads (root)."""
    path = ws / "m.yaml"
    path.chmod(0o000)
    try:
        path.read_bytes()
    except OSError:
        return None
    path.chmod(0o644)
    return "running as root: chmod 000 does not stop reads"


def track_csv(rows: int = 40, t0: float = 0.0, dt: float = 0.1) -> str:
    """A straight-walk track t,x,y."""
    return "t,x,y\n" + "".join(
        f"{t0 + i * dt:.3f},{1.0 + 0.09 * i:.3f},{2.0 + 0.02 * i:.3f}\n" for i in range(rows)
    )


def frames_txt(people: int = 4, steps: int = 30) -> str:
    """ETH/UCY-style frames: frame ped x y."""
    lines = []
    for p in range(people):
        for s in range(steps):
            lines.append(f"{s * 10}\t{p + 1}\t{0.4 * s + p:.2f}\t{0.1 * s * (p - 1.5):.2f}")
    return "\n".join(lines) + "\n"


def billion_laughs() -> str:
    """YAML aliases that expand to 10^9 items if anyone flattens them."""
    lines = ['a0: &a0 ["lol","lol","lol","lol","lol","lol","lol","lol","lol","lol"]']
    for i in range(1, 9):
        refs = ",".join([f"*a{i - 1}"] * 10)
        lines.append(f"a{i}: &a{i} [{refs}]")
    lines.append("name: bomb\ndescription: *a8\n")
    return "\n".join(lines)


# ---------------------------------------------------------------- the catalogue

M = "{repo}/missions/house.yaml"
HIDE = "{repo}/missions/house_hide.yaml"


def _err(
    cid: str,
    command: str,
    argv: tuple[str, ...] | list[str],
    names: tuple[str, ...] | list[str] = (),
    files: dict[str, Content] | None = None,
    **kw: Any,
) -> Case:
    kind = kw.pop("kind", "error")
    avoid = kw.pop("avoid", ())
    return Case(
        id=cid,
        command=command,
        argv=tuple(command.split()) + tuple(argv),
        expect=Expect(kind, tuple(names), avoid=tuple(avoid)),
        files=files or {},
        **kw,
    )


def _mission_cases() -> list[Case]:
    v = "mission validate"
    c = [
        _err("mv-yaml-syntax", v, ["m.yaml"], ["m.yaml"], {"m.yaml": "name: x\nmap: [\n"}),
        _err("mv-empty", v, ["m.yaml"], ["m.yaml"], {"m.yaml": ""}),
        _err("mv-list-top", v, ["m.yaml"], ["m.yaml"], {"m.yaml": "- a\n- b\n"}),
        _err("mv-scalar-top", v, ["m.yaml"], ["m.yaml"], {"m.yaml": "42\n"}),
        _err("mv-random-bytes", v, ["m.yaml"], ["m.yaml"], {"m.yaml": random_bytes(4000)}),
        _err(
            "mv-latin1",
            v,
            ["m.yaml"],
            ["m.yaml"],
            {"m.yaml": dump(house()).encode().replace(b"ahg-house", b"caf\xe9-house")},
        ),
        _err("mv-missing-file", v, ["nope.yaml"], ["nope.yaml"]),
        _err("mv-directory", v, ["d"], ["d"], {"d/x.txt": "x"}),
        _err("mv-no-name", v, ["m.yaml"], ["m.yaml", "name"], {"m.yaml": without("name")}),
        _err(
            "mv-no-route",
            v,
            ["m.yaml"],
            ["m.yaml", "route"],
            {"m.yaml": without("scenario.people.0.route")},
        ),
        _err("mv-no-map", v, ["m.yaml"], ["m.yaml", "map"], {"m.yaml": without("map")}),
        _err(
            "mv-no-regions",
            v,
            ["m.yaml"],
            ["m.yaml", "regions"],
            {"m.yaml": without("map.regions")},
        ),
        _err(
            "mv-radius-str",
            v,
            ["m.yaml"],
            ["m.yaml", "robot.radius"],
            {"m.yaml": edited("robot.radius", "big")},
        ),
        _err(
            "mv-radius-neg",
            v,
            ["m.yaml"],
            ["m.yaml", "robot.radius"],
            {"m.yaml": edited("robot.radius", -1)},
        ),
        _err(
            "mv-resolution-zero",
            v,
            ["m.yaml"],
            ["m.yaml", "map.resolution"],
            {"m.yaml": edited("map.resolution", 0)},
        ),
        _err(
            "mv-resolution-nan",
            v,
            ["m.yaml"],
            ["m.yaml", "map.resolution"],
            {"m.yaml": dump(house()).replace("resolution: 0.05", "resolution: .nan")},
        ),
        _err(
            "mv-speed-inf",
            v,
            ["m.yaml"],
            ["m.yaml", "max_linear_speed"],
            {"m.yaml": dump(house()).replace("max_linear_speed: 0.22", "max_linear_speed: .inf")},
        ),
        _err(
            "mv-unknown-top",
            v,
            ["m.yaml"],
            ["m.yaml", "colour"],
            {"m.yaml": {**house(), "colour": "blue"}},
        ),
        _err(
            "mv-unknown-nested",
            v,
            ["m.yaml"],
            ["m.yaml", "robot.wheels"],
            {"m.yaml": edited("robot.wheels", 3)},
        ),
        _err(
            "mv-extends-loop",
            v,
            ["a.yaml"],
            ["a.yaml", "b.yaml"],
            {"a.yaml": extends_loop("b.yaml"), "b.yaml": extends_loop("a.yaml")},
        ),
        _err(
            "mv-extends-self",
            v,
            ["a.yaml"],
            ["a.yaml"],
            {"a.yaml": extends_loop("a.yaml")},
        ),
        _err(
            "mv-extends-missing",
            v,
            ["a.yaml"],
            ["a.yaml", "gone.yaml"],
            {"a.yaml": extends_loop("gone.yaml")},
        ),
        _err(
            "mv-include-missing",
            v,
            ["m.yaml"],
            ["m.yaml", "tree.yaml"],
            {"m.yaml": edited("behavior.tree", {"include": "tree.yaml"})},
        ),
        _err(
            "mv-include-bad-yaml",
            v,
            ["m.yaml"],
            ["tree.yaml"],
            {"m.yaml": edited("behavior.tree", {"include": "tree.yaml"}), "tree.yaml": "a: [\n"},
        ),
        _err(
            "mv-include-loop",
            v,
            ["m.yaml"],
            ["tree.yaml"],
            {
                "m.yaml": edited("behavior.tree", {"include": "tree.yaml"}),
                "tree.yaml": "include: tree.yaml\n",
            },
        ),
        _err(
            "mv-polygon-two-points",
            v,
            ["m.yaml"],
            ["m.yaml", "polygon"],
            {"m.yaml": edited("map.regions.0.polygon", [[0, 0], [5, 0]])},
        ),
        _err(
            "mv-door-unknown-region",
            v,
            ["m.yaml"],
            ["m.yaml", "garage"],
            {"m.yaml": edited("map.doors.0.between", ["kitchen", "garage"])},
        ),
        _err(
            "mv-target-unknown",
            v,
            ["m.yaml"],
            ["m.yaml", "scenario.target"],
            {"m.yaml": edited("scenario.target", "mallory")},
        ),
        _err(
            "mv-route-unknown-region",
            v,
            ["m.yaml"],
            ["m.yaml", "garage"],
            {"m.yaml": edited("scenario.people.1.route", ["living_room", "garage"])},
        ),
        _err(
            "mv-route-in-furniture",
            v,
            ["m.yaml"],
            ["m.yaml", "route"],
            {"m.yaml": route_in_furniture()},
            why="issue 21 item 14: the person stalls in the table",
        ),
        _err(
            "mv-start-in-furniture",
            v,
            ["m.yaml"],
            ["m.yaml", "robot.start"],
            {"m.yaml": edited("robot.start", {"x": 1.8, "y": 2.4, "theta": 0.0})},
            why="issue 21 item 14",
        ),
        _err(
            "mv-start-outside",
            v,
            ["m.yaml"],
            ["m.yaml", "robot.start"],
            {"m.yaml": edited("robot.start", {"x": 40.0, "y": -3.0, "theta": 0.0})},
        ),
        _err(
            "mv-occupancy-missing",
            v,
            ["m.yaml"],
            ["m.yaml", "map.occupancy"],
            {"m.yaml": with_occupancy("gone.yaml")},
        ),
        _err(
            "mv-occupancy-image-missing",
            v,
            ["m.yaml"],
            ["gone.pgm"],
            {"m.yaml": with_occupancy("occ.yaml"), "occ.yaml": map_server_yaml("gone.pgm")},
        ),
        _err(
            "mv-occupancy-image-random",
            v,
            ["m.yaml"],
            ["occ.pgm"],
            {
                "m.yaml": with_occupancy("occ.yaml"),
                "occ.yaml": map_server_yaml("occ.pgm"),
                "occ.pgm": random_bytes(5000),
            },
            why="issue 21 item 14: unreadable occupancy image",
        ),
        _err(
            "mv-occupancy-image-empty",
            v,
            ["m.yaml"],
            ["occ.pgm"],
            {
                "m.yaml": with_occupancy("occ.yaml"),
                "occ.yaml": map_server_yaml("occ.pgm"),
                "occ.pgm": b"",
            },
        ),
        _err(
            "mv-occupancy-yaml-bad",
            v,
            ["m.yaml"],
            ["occ.yaml"],
            {"m.yaml": with_occupancy("occ.yaml"), "occ.yaml": "image: [\n"},
        ),
        _err(
            "mv-occupancy-resolution-neg",
            v,
            ["m.yaml"],
            ["occ.yaml", "resolution"],
            {
                "m.yaml": with_occupancy("occ.yaml"),
                "occ.yaml": map_server_yaml("occ.pgm", -0.05),
                "occ.pgm": pgm(40, 40),
            },
        ),
        _err(
            "mv-huge-map",
            v,
            ["m.yaml"],
            ["m.yaml"],
            {"m.yaml": huge_map()},
            memory_mb=3072,
            timeout=60,
            why="issue 21 item 5: must be refused by validation",
        ),
        _err(
            "mv-tick-zero",
            v,
            ["m.yaml"],
            ["m.yaml", "tick_hz"],
            {"m.yaml": edited("behavior.tick_hz", 0)},
        ),
        _err(
            "mv-laser-rate-neg",
            v,
            ["m.yaml"],
            ["m.yaml", "rate_hz"],
            {"m.yaml": edited("sensors.laser.rate_hz", -40)},
        ),
        _err(
            "mv-bins-short",
            v,
            ["m.yaml"],
            ["m.yaml", "bins"],
            {"m.yaml": edited("perception.identity.bins", [16, 4])},
        ),
        _err(
            "mv-speed-neg-person",
            v,
            ["m.yaml"],
            ["m.yaml", "speed"],
            {"m.yaml": edited("scenario.people.0.speed", -0.9)},
        ),
        _err(
            "mv-clothes-range",
            v,
            ["m.yaml"],
            ["m.yaml", "upper"],
            {
                "m.yaml": edited(
                    "scenario.people.0.clothes", {"upper": [300, 0, 0], "lower": [0, 0, 0]}
                )
            },
        ),
        _err(
            "mv-tree-unknown-leaf",
            v,
            ["m.yaml"],
            ["m.yaml", "fly"],
            {"m.yaml": edited("behavior.tree", {"action": "fly"})},
        ),
        _err(
            "mv-tree-empty-children",
            v,
            ["m.yaml"],
            ["m.yaml"],
            {"m.yaml": edited("behavior.tree", {"fallback": {"name": "root", "children": []}})},
        ),
        _err(
            "mv-billion-laughs",
            v,
            ["m.yaml"],
            ["m.yaml"],
            {"m.yaml": billion_laughs()},
            memory_mb=2048,
            timeout=60,
        ),
        _err(
            "mv-unreadable",
            v,
            ["m.yaml"],
            ["m.yaml"],
            {"m.yaml": dump(house())},
            setup=unreadable_file,
        ),
        _err(
            "ms-out-under-file", "mission schema", ["--out", "f/schema.json"], ["--out"], {"f": "x"}
        ),
        _err("ms-out-is-dir", "mission schema", ["--out", "d"], ["--out"], {"d/keep": "x"}),
        _err(
            "mg-impossible-home",
            "mission generate",
            ["--rooms", "40", "--size", "5x5", "--out", "o/home.yaml"],
            ["--rooms"],
        ),
        _err("mg-bad-size", "mission generate", ["--size", "5by5", "--out", "h.yaml"], ["--size"]),
        _err("mg-out-is-dir", "mission generate", ["--out", "d"], ["--out"], {"d/keep": "x"}),
        _err(
            "ms-out-readonly",
            "mission schema",
            ["--out", "ro/schema.json"],
            ["--out"],
            setup=readonly_dir,
        ),
    ]
    return c


NOOK_GARAGE = "nook,garage=1,0.2;1,0.8"


def _map_cases() -> list[Case]:
    ex, sx, rd, an = "map export", "sim export-map", "map render", "map annotate"
    bad = {"m.yaml": edited("robot.radius", -1)}
    c = [
        _err("mx-missing-mission", ex, ["nope.yaml", "--out", "o/map.yaml"], ["nope.yaml"]),
        _err("mx-bad-mission", ex, ["m.yaml", "--out", "o/map.yaml"], ["robot.radius"], bad),
        _err("mx-res-zero", ex, [M, "--out", "o/map.yaml", "--resolution", "0"], ["--resolution"]),
        _err(
            "mx-res-neg", ex, [M, "--out", "o/map.yaml", "--resolution", "-0.05"], ["--resolution"]
        ),
        _err("mx-res-nan", ex, [M, "--out", "o/map.yaml", "--resolution", "nan"], ["--resolution"]),
        _err(
            "mx-res-tiny",
            ex,
            [M, "--out", "o/map.yaml", "--resolution", "1e-6"],
            ["--resolution"],
            memory_mb=3072,
            timeout=60,
            why="12 m at 1 um: 10^13 cells",
        ),
        _err("mx-margin-neg", ex, [M, "--out", "o/map.yaml", "--margin", "-1"], ["--margin"]),
        _err("mx-margin-nan", ex, [M, "--out", "o/map.yaml", "--margin", "nan"], ["--margin"]),
        _err("mx-out-under-file", ex, [M, "--out", "f/map.yaml"], ["--out"], {"f": "x"}),
        _err("mx-out-is-dir", ex, [M, "--out", "d"], ["--out"], {"d/keep": "x"}),
        _err("mx-out-readonly", ex, [M, "--out", "ro/map.yaml"], ["--out"], setup=readonly_dir),
        _err(
            "mx-huge-map",
            ex,
            ["m.yaml", "--out", "o/map.yaml"],
            ["m.yaml"],
            {"m.yaml": huge_map()},
            memory_mb=3072,
            timeout=60,
            why="issue 21 item 5",
        ),
        _err("sx-missing-mission", sx, ["nope.yaml", "--out", "o/map.yaml"], ["nope.yaml"]),
        _err("sx-res-zero", sx, [M, "--out", "o/map.yaml", "--resolution", "0"], ["--resolution"]),
        _err("sx-res-nan", sx, [M, "--out", "o/map.yaml", "--resolution", "nan"], ["--resolution"]),
        _err("sx-out-under-file", sx, [M, "--out", "f/map.yaml"], ["--out"], {"f": "x"}),
        _err(
            "sx-huge-map",
            sx,
            ["m.yaml", "--out", "o/map.yaml"],
            ["m.yaml"],
            {"m.yaml": huge_map()},
            memory_mb=3072,
            timeout=60,
        ),
        _err("mr-missing-mission", rd, ["nope.yaml", "--png", "o.png"], ["nope.yaml"]),
        _err("mr-bad-mission", rd, ["m.yaml", "--png", "o.png"], ["robot.radius"], bad),
        _err("mr-png-under-file", rd, [M, "--png", "f/o.png"], ["--png"], {"f": "x"}),
        _err("mr-png-is-dir", rd, [M, "--png", "d"], ["--png"], {"d/keep": "x"}),
        _err("mr-res-zero", rd, [M, "--png", "o.png", "--resolution", "0"], ["--resolution"]),
        _err("mr-res-nan", rd, [M, "--png", "o.png", "--resolution", "nan"], ["--resolution"]),
        _err(
            "mr-occupancy-random",
            rd,
            ["m.yaml", "--png", "o.png"],
            ["occ.pgm"],
            {
                "m.yaml": with_occupancy("occ.yaml"),
                "occ.yaml": map_server_yaml("occ.pgm"),
                "occ.pgm": random_bytes(5000),
            },
        ),
        _err(
            "mr-mapserver-image-missing",
            rd,
            ["occ.yaml", "--png", "o.png"],
            ["gone.pgm"],
            {"occ.yaml": map_server_yaml("gone.pgm")},
        ),
        _err(
            "mr-mapserver-res-neg",
            rd,
            ["occ.yaml", "--png", "o.png"],
            ["occ.yaml", "resolution"],
            {"occ.yaml": map_server_yaml("occ.pgm", -1), "occ.pgm": pgm(40, 40)},
        ),
        _err(
            "mr-huge-map",
            rd,
            ["m.yaml", "--png", "o.png"],
            ["m.yaml"],
            {"m.yaml": huge_map()},
            memory_mb=3072,
            timeout=60,
        ),
        _err(
            "ma-region-syntax",
            an,
            [M, "--region", "kitchen=1,2", "--out", "o.yaml"],
            ["--region"],
        ),
        _err(
            "ma-region-two-points",
            an,
            [M, "--region", "nook=0,0;1,0", "--out", "o.yaml"],
            ["--region"],
        ),
        _err(
            "ma-region-nan",
            an,
            [M, "--region", "nook=0,0;nan,0;1,1", "--out", "o.yaml"],
            ["--region"],
        ),
        _err("ma-door-syntax", an, [M, "--door", "kitchen", "--out", "o.yaml"], ["--door"]),
        _err(
            "ma-door-unknown-region",
            an,
            [M, "--region", "nook=0,0;1,0;1,1;0,1", "--door", NOOK_GARAGE, "--out", "o.yaml"],
            ["garage"],
        ),
        _err(
            "ma-regions-missing",
            an,
            [M, "--regions", "gone.yaml", "--out", "o.yaml"],
            ["gone.yaml"],
        ),
        _err(
            "ma-regions-bad-yaml",
            an,
            [M, "--regions", "r.yaml", "--out", "o.yaml"],
            ["r.yaml"],
            {"r.yaml": "regions: [\n"},
        ),
        _err(
            "ma-regions-wrong-type",
            an,
            [M, "--regions", "r.yaml", "--out", "o.yaml"],
            ["r.yaml", "regions"],
            {"r.yaml": "regions: 5\n"},
        ),
        _err("ma-out-under-file", an, [M, "--auto", "--out", "f/o.yaml"], ["--out"], {"f": "x"}),
        _err("ma-png-under-file", an, [M, "--png", "f/o.png"], ["--png"], {"f": "x"}),
        _err(
            "ma-door-width-neg",
            an,
            [M, "--auto", "--door-width", "-1", "--out", "o.yaml"],
            ["--door-width"],
        ),
        _err(
            "ma-min-area-nan",
            an,
            [M, "--auto", "--min-room-area", "nan", "--out", "o.yaml"],
            ["--min-room-area"],
        ),
        _err(
            "ma-reference-missing",
            an,
            [M, "--auto", "--reference", "gone.yaml", "--out", "o.yaml"],
            ["gone.yaml"],
        ),
        _err("ma-source-png", an, ["p.png", "--out", "o.yaml"], ["p.png"], {"p.png": png_bytes()}),
        _err(
            "ma-res-zero",
            an,
            [M, "--auto", "--resolution", "0", "--out", "o.yaml"],
            ["--resolution"],
        ),
        _err(
            "ma-out-existing-unchanged",
            an,
            [M, "--door", "kitchen", "--out", "o.yaml"],
            ["--door"],
            {"o.yaml": dump(house())},
        ),
    ]
    return c


def _sim_cases() -> list[Case]:
    r, s = "sim run", "sim serve-hsr"
    short = ["--duration", "2", "--png", "o/p.png", "--no-camera"]
    c = [
        _err("sr-missing-mission", r, ["nope.yaml", *short], ["nope.yaml"]),
        _err(
            "sr-bad-mission",
            r,
            ["m.yaml", *short],
            ["robot.radius"],
            {"m.yaml": edited("robot.radius", -1)},
        ),
        _err("sr-duration-neg", r, [M, "--duration", "-5", "--png", "o/p.png"], ["--duration"]),
        _err("sr-duration-nan", r, [M, "--duration", "nan", "--png", "o/p.png"], ["--duration"]),
        _err("sr-duration-inf", r, [M, "--duration", "inf", "--png", "o/p.png"], ["--duration"]),
        _err(
            "sr-duration-zero",
            r,
            [M, "--duration", "0", "--png", "o/p.png", "--no-camera"],
            ["--duration"],
            kind="error_or_run",
        ),
        _err(
            "sr-seed-neg",
            r,
            [M, "--seed", "-1", *short],
            ["--seed"],
            kind="error_or_run",
            why="issue 21 item 8",
        ),
        _err("sr-seed-huge", r, [M, "--seed", str(2**70), *short], ["--seed"], kind="error_or_run"),
        _err("sr-script-missing", r, [M, "--script", "gone.csv", *short], ["gone.csv"]),
        _err(
            "sr-script-random",
            r,
            [M, "--script", "s.csv", *short],
            ["s.csv"],
            {"s.csv": random_bytes(3000)},
        ),
        _err("sr-script-empty", r, [M, "--script", "s.csv", *short], ["s.csv"], {"s.csv": ""}),
        _err(
            "sr-script-header",
            r,
            [M, "--script", "s.csv", *short],
            ["s.csv"],
            {"s.csv": "time,speed\n0,1\n"},
        ),
        _err(
            "sr-script-nan",
            r,
            [M, "--script", "s.csv", *short],
            ["s.csv"],
            {"s.csv": "t,vx,vy,wz\n0,0.1,0,0\n1,nan,0,0\n"},
        ),
        _err(
            "sr-script-text",
            r,
            [M, "--script", "s.csv", *short],
            ["s.csv"],
            {"s.csv": "t,vx,vy,wz\n0,fast,0,0\n"},
        ),
        _err(
            "sr-png-under-file",
            r,
            [M, "--duration", "30", "--png", "f/p.png"],
            ["--png"],
            {"f": "x"},
            timeout=60,
        ),
        _err("sr-record-under-file", r, [M, "--record", "f/rec", *short], ["--record"], {"f": "x"}),
        _err("sr-laser-bogus", r, [M, "--laser", "warp", *short], ["--laser"]),
        _err(
            "sr-huge-map",
            r,
            ["m.yaml", *short],
            ["m.yaml"],
            {"m.yaml": huge_map()},
            memory_mb=3072,
            timeout=60,
            why="issue 21 item 5",
        ),
        _err(
            "sr-start-in-furniture",
            r,
            ["m.yaml", *short],
            ["robot.start"],
            {"m.yaml": edited("robot.start", {"x": 1.8, "y": 2.4, "theta": 0.0})},
            why="issue 21 item 14",
        ),
        _err("sh-missing-mission", s, ["nope.yaml"], ["nope.yaml"]),
        _err(
            "sh-bad-mission",
            s,
            ["m.yaml"],
            ["robot.radius"],
            {"m.yaml": edited("robot.radius", -1)},
        ),
        _err("sh-rate-neg", s, [M, "--rate", "-1"], ["--rate"]),
        _err("sh-depth-bogus", s, [M, "--depth-encoding", "8UC3"], ["--depth-encoding"]),
        _err("sh-hide-unknown", s, [M, "--hide", "garage"], ["garage"]),
        _err("sh-duration-neg", s, [M, "--duration", "-1"], ["--duration"]),
    ]
    return c


def _follow_search_cases() -> list[Case]:
    f, s = "follow", "search"
    fo = ["--duration", "3", "--out", "o"]
    c: list[Case] = []
    for cmd, mission in ((f, M), (s, HIDE)):
        p = "fo" if cmd == f else "se"
        tgt = ["--target", "{target}"]
        c += [
            _err(f"{p}-missing-mission", cmd, ["nope.yaml", *fo], ["nope.yaml"]),
            _err(
                f"{p}-bad-mission",
                cmd,
                ["m.yaml", *fo],
                ["robot.radius"],
                {"m.yaml": edited("robot.radius", -1)},
            ),
            _err(f"{p}-backend-bogus", cmd, [mission, "--backend", "gazebo", *fo], ["--backend"]),
            _err(f"{p}-target-missing", cmd, [mission, "--target", "gone.npz", *fo], ["gone.npz"]),
            _err(
                f"{p}-target-truncated",
                cmd,
                [mission, "--target", "t.npz", *fo],
                ["t.npz"],
                {"t.npz": head("target", 3000)},
                needs=("target",),
                why="issue 21 item 7",
            ),
            _err(
                f"{p}-target-random",
                cmd,
                [mission, "--target", "t.npz", *fo],
                ["t.npz"],
                {"t.npz": random_bytes(4000)},
                avoid=("pickle",),
                why="issue 21 item 11",
            ),
            _err(
                f"{p}-target-empty",
                cmd,
                [mission, "--target", "t.npz", *fo],
                ["t.npz"],
                {"t.npz": b""},
            ),
            _err(
                f"{p}-target-other-npz",
                cmd,
                [mission, "--target", "t.npz", *fo],
                ["t.npz"],
                {"t.npz": npz({"weights": [1.0, 2.0]})},
            ),
            _err(
                f"{p}-target-pickled",
                cmd,
                [mission, "--target", "t.npz", *fo],
                ["t.npz"],
                {"t.npz": pickled_npz()},
                avoid=("allow_pickle", "Object arrays"),
            ),
            _err(f"{p}-target-dir", cmd, [mission, "--target", "d", *fo], ["d"], {"d/keep": "x"}),
            _err(
                f"{p}-seed-neg",
                cmd,
                [mission, "--seed", "-1", *tgt, *fo],
                ["--seed"],
                needs=("target",),
                kind="error_or_run",
                why="issue 21 item 8",
            ),
            _err(
                f"{p}-seed-huge",
                cmd,
                [mission, "--seed", str(2**64), *tgt, *fo],
                ["--seed"],
                needs=("target",),
                kind="error_or_run",
            ),
            _err(
                f"{p}-duration-neg",
                cmd,
                [mission, "--duration", "-1", "--out", "o"],
                ["--duration"],
            ),
            _err(
                f"{p}-duration-nan",
                cmd,
                [mission, "--duration", "nan", "--out", "o"],
                ["--duration"],
            ),
            _err(
                f"{p}-duration-inf",
                cmd,
                [mission, "--duration", "inf", "--out", "o"],
                ["--duration"],
            ),
            _err(
                f"{p}-out-under-file",
                cmd,
                [mission, *tgt, "--duration", "120", "--out", "f/o"],
                ["--out"],
                {"f": "x"},
                needs=("target",),
                timeout=60,
                why="issue 21 item 2: refused before the episode runs",
            ),
            _err(
                f"{p}-out-is-file",
                cmd,
                [mission, *tgt, "--duration", "120", "--out", "f"],
                ["--out"],
                {"f": "x"},
                needs=("target",),
                timeout=60,
                why="issue 21 item 2",
            ),
            _err(
                f"{p}-out-readonly",
                cmd,
                [mission, *tgt, "--duration", "120", "--out", "ro/o"],
                ["--out"],
                needs=("target",),
                setup=readonly_dir,
                timeout=60,
            ),
            _err(
                f"{p}-huge-map",
                cmd,
                ["m.yaml", *tgt, *fo],
                ["m.yaml"],
                {"m.yaml": huge_map()},
                needs=("target",),
                memory_mb=3072,
                timeout=60,
            ),
        ]
    c += [
        _err(
            "fo-record-under-file",
            f,
            [M, "--target", "{target}", "--duration", "120", "--out", "o", "--record", "f/rec"],
            ["--record"],
            {"f": "x"},
            needs=("target",),
            timeout=60,
        ),
        _err(
            "se-region-unknown",
            s,
            [HIDE, "--region", "garage", "--duration", "3", "--out", "o"],
            ["garage"],
        ),
        _err(
            "se-no-target-person",
            s,
            ["m.yaml", "--duration", "3", "--out", "o"],
            ["m.yaml", "scenario.target"],
            {"m.yaml": without("scenario.target")},
        ),
    ]
    return c


def _learn_replay_cases() -> list[Case]:
    lt, rp = "learn-target", "replay"
    c = [
        _err("lt-missing-mission", lt, ["nope.yaml", "--out", "t.npz"], ["nope.yaml"]),
        _err("lt-out-under-file", lt, [M, "--out", "f/t.npz"], ["--out"], {"f": "x"}),
        _err("lt-out-is-dir", lt, [M, "--out", "d"], ["--out"], {"d/keep": "x"}),
        _err(
            "lt-plot-under-file",
            lt,
            [M, "--out", "t.npz", "--plot", "f/p.png"],
            ["--plot"],
            {"f": "x"},
        ),
        _err("lt-from-missing", lt, [M, "--out", "t.npz", "--from", "gone"], ["gone"]),
        _err("lt-from-empty-dir", lt, [M, "--out", "t.npz", "--from", "d"], ["d"], {"d/.keep": ""}),
        _err(
            "lt-from-random-image",
            lt,
            [M, "--out", "t.npz", "--from", "i.png"],
            ["i.png"],
            {"i.png": random_bytes(3000)},
        ),
        _err(
            "lt-from-no-person",
            lt,
            [M, "--out", "t.npz", "--from", "i.png"],
            ["i.png"],
            {"i.png": png_bytes(64, 48)},
        ),
        _err(
            "lt-pick-zero",
            lt,
            [M, "--out", "t.npz", "--from", "i.png", "--pick", "0"],
            ["--pick"],
            {"i.png": png_bytes(64, 48)},
        ),
        _err("lt-seconds-neg", lt, [M, "--out", "t.npz", "--seconds", "-1"], ["--seconds"]),
        _err("lt-seconds-nan", lt, [M, "--out", "t.npz", "--seconds", "nan"], ["--seconds"]),
        _err("lt-backend-bogus", lt, [M, "--out", "t.npz", "--backend", "gazebo"], ["--backend"]),
        _err(
            "lt-seed-neg",
            lt,
            [M, "--out", "t.npz", "--seed", "-1", "--seconds", "1"],
            ["--seed"],
            kind="error_or_run",
        ),
        _err(
            "rp-directory",
            rp,
            ["d", "--out", "o"],
            ["d"],
            {"d/notes.txt": "x"},
            avoid=("expected metadata file",),  # rosbags' words (the issue's item 12)
            why="issue 21 item 12",
        ),
        _err(
            "rp-empty-dir",
            rp,
            ["d", "--out", "o"],
            ["d"],
            {"d/.keep": ""},
            avoid=("expected metadata file",),  # rosbags' words (the issue's item 12)
            why="issue 21 item 12",
        ),
        _err("rp-missing", rp, ["gone.bag", "--out", "o"], ["gone.bag"]),
        _err(
            "rp-random-bag", rp, ["r.bag", "--out", "o"], ["r.bag"], {"r.bag": random_bytes(20000)}
        ),
        _err("rp-empty-bag", rp, ["r.bag", "--out", "o"], ["r.bag"], {"r.bag": b""}),
        _err(
            "rp-truncated-bag",
            rp,
            ["r.bag", "--out", "o"],
            ["r.bag"],
            {"r.bag": head("bag", 20000)},
            needs=("bag",),
            kind="error_or_run",
            why="a bag cut short may still replay what it holds",
        ),
        _err("rp-text-file", rp, ["r.txt", "--out", "o"], ["r.txt"], {"r.txt": "hello\n"}),
        _err(
            "rp-scan-topic-missing",
            rp,
            ["{bag}", "--scan-topic", "/nope", "--out", "o"],
            ["/nope"],
            needs=("bag",),
        ),
        _err(
            "rp-target-truncated",
            rp,
            ["{bag}", "--target", "t.npz", "--out", "o"],
            ["t.npz"],
            {"t.npz": head("target", 3000)},
            needs=("bag", "target"),
            why="issue 21 item 7",
        ),
        _err(
            "rp-mission-bad",
            rp,
            ["{bag}", "--mission", "m.yaml", "--out", "o"],
            ["robot.radius"],
            {"m.yaml": edited("robot.radius", -1)},
            needs=("bag",),
        ),
        _err(
            "rp-out-under-file",
            rp,
            ["{bag}", "--out", "f/o"],
            ["--out"],
            {"f": "x"},
            needs=("bag",),
        ),
    ]
    te, gt = "track evaluate", "/ground_truth_people_tracks"
    c += [
        _err("te-missing", te, ["gone.bag", "--ground-truth", gt, "--out", "o"], ["gone.bag"]),
        _err(
            "te-random-bag",
            te,
            ["r.bag", "--ground-truth", gt, "--out", "o"],
            ["r.bag"],
            {"r.bag": random_bytes(20000)},
        ),
        _err("te-no-ground-truth", te, ["{bag}", "--out", "o"], ["--ground-truth"], needs=("bag",)),
        _err(
            "te-ground-truth-missing",
            te,
            ["{bag}", "--ground-truth", gt, "--out", "o"],
            [gt],
            needs=("bag",),
        ),
        _err(
            "te-ground-truth-wrong-type",
            te,
            ["{bag}", "--ground-truth", "/hsrb/base_scan", "--out", "o"],
            ["/hsrb/base_scan", "leg_tracker/Person"],
            needs=("bag",),
        ),
        _err(
            "te-radius-zero",
            te,
            ["{bag}", "--ground-truth", gt, "--radius", "0", "--out", "o"],
            ["--radius"],
            needs=("bag",),
        ),
        _err(
            "te-radius-nan",
            te,
            ["{bag}", "--ground-truth", gt, "--radius", "nan", "--out", "o"],
            ["--radius"],
            needs=("bag",),
        ),
        _err(
            "te-decimate-zero",
            te,
            ["{bag}", "--ground-truth", gt, "--decimate", "0", "--out", "o"],
            ["--decimate"],
            needs=("bag",),
        ),
    ]
    return c


def campaign_files(kind: str) -> dict[str, Content]:
    """The shared campaign's files copied into ``c/``, its results torn (``torn``), with a
    garbage line in the middle (``garbage``) or as they are (``same``)."""

    def results(shared: Any) -> bytes:
        raw = (Path(shared.campaign) / "results.jsonl").read_bytes()
        if kind == "torn":
            return raw + raw[: len(raw) // 2].rstrip(b"\n")
        if kind == "garbage":
            return b"this is not json\n" + raw
        return raw

    def config(shared: Any) -> bytes:
        return (Path(shared.campaign) / "campaign.json").read_bytes()

    return {"c/results.jsonl": results, "c/campaign.json": config}


BENCH_ARGS = ("--episodes", "1", "--seed", "1", "--duration", "2", "--workers", "1")


def _bench_cases() -> list[Case]:
    b = "bench"
    o = ["--out", "o"]
    c = [
        _err("be-missing-mission", b, ["nope.yaml", *BENCH_ARGS, *o], ["nope.yaml"]),
        _err("be-no-homes", b, ["--homes", "0", *BENCH_ARGS, *o], ["--homes"]),
        _err(
            "be-bad-mission",
            b,
            ["m.yaml", *BENCH_ARGS, *o],
            ["robot.radius"],
            {"m.yaml": edited("robot.radius", -1)},
        ),
        _err(
            "be-bad-second-mission",
            b,
            [M, "m.yaml", *BENCH_ARGS, *o],
            ["m.yaml"],
            {"m.yaml": "name: [\n"},
        ),
        _err("be-same-mission-twice", b, [M, M, *BENCH_ARGS, *o], ["MISSION"]),
        _err("be-episodes-zero", b, [M, "--episodes", "0", *o], ["--episodes"]),
        _err("be-workers-zero", b, [M, "--workers", "0", *o], ["--workers"]),
        _err("be-duration-nan", b, [M, "--duration", "nan", *o], ["--duration"]),
        _err("be-duration-neg", b, [M, "--duration", "-2", *o], ["--duration"]),
        _err("be-timeout-neg", b, [M, "--timeout", "-1", *o], ["--timeout"]),
        _err(
            "be-seed-neg",
            b,
            [M, "--episodes", "1", "--seed", "-1", "--duration", "2", "--workers", "1", *o],
            ["--seed"],
            why="issue 21 item 8: all episodes failed and exit 0",
        ),
        _err("be-task-bogus", b, [M, "--task", "dance", *o], ["--task"]),
        _err("be-vary-syntax", b, [M, "--vary", "nonsense", *BENCH_ARGS, *o], ["--vary"]),
        _err(
            "be-vary-unknown-key",
            b,
            [M, "--vary", "robot.wheels=3,4", *BENCH_ARGS, *o],
            ["robot.wheels"],
        ),
        _err(
            "be-vary-bad-value",
            b,
            [M, "--vary", "robot.radius=-1,0.2", *BENCH_ARGS, *o],
            ["robot.radius"],
        ),
        _err(
            "be-vary-file-missing",
            b,
            [M, "--vary", "search.alpha=@gone.yaml", *BENCH_ARGS, *o],
            ["gone.yaml"],
        ),
        _err(
            "be-vary-file-empty",
            b,
            [M, "--vary", "search.alpha=@v.yaml", *BENCH_ARGS, *o],
            ["v.yaml"],
            {"v.yaml": ""},
        ),
        _err(
            "be-vary-file-bad",
            b,
            [M, "--vary", "search.alpha=@v.yaml", *BENCH_ARGS, *o],
            ["v.yaml"],
            {"v.yaml": "a: [\n"},
        ),
        _err("be-out-is-file", b, [M, *BENCH_ARGS, "--out", "f"], ["--out"], {"f": "x"}),
        _err("be-out-under-file", b, [M, *BENCH_ARGS, "--out", "f/o"], ["--out"], {"f": "x"}),
        _err("be-ray-bogus", b, [M, *BENCH_ARGS, "--ray", "carrier-pigeon", *o], ["--ray"]),
        _err(
            "be-search-no-target",
            b,
            ["m.yaml", "--task", "search", *BENCH_ARGS, *o],
            ["scenario.target"],
            {"m.yaml": without("scenario.target")},
        ),
        _err(
            "be-resume-garbage",
            b,
            [M, *BENCH_ARGS, "--out", "c", "--resume"],
            ["results.jsonl"],
            campaign_files("garbage"),
            needs=("campaign",),
        ),
        _err(
            "be-resume-other-campaign",
            b,
            [
                M,
                "--episodes",
                "1",
                "--seed",
                "5",
                "--duration",
                "2",
                "--workers",
                "1",
                "--out",
                "c",
                "--resume",
            ],
            ["--resume"],
            campaign_files("same"),
            needs=("campaign",),
        ),
        _err(
            "be-no-resume-existing",
            b,
            [M, *BENCH_ARGS, "--out", "c"],
            ["--resume"],
            campaign_files("same"),
            needs=("campaign",),
        ),
        Case(
            id="be-resume-torn",
            command=b,
            argv=(b, M, *BENCH_ARGS, "--out", "c", "--resume"),
            expect=Expect("warn", ("results.jsonl",)),
            files=campaign_files("torn"),
            needs=("campaign",),
            why="issue 21 item 15: a torn last line is dropped without a word",
        ),
    ]
    return c


def _predict_cases() -> list[Case]:
    t, e, s, d = "predict", "predict evaluate", "predict search", "predict experiment door"
    ok = {"k.csv": track_csv()}
    c = [
        _err("pt-missing", t, ["gone.csv"], ["gone.csv"]),
        _err("pt-empty", t, ["k.csv"], ["k.csv"], {"k.csv": ""}),
        _err("pt-header-only", t, ["k.csv"], ["k.csv"], {"k.csv": "t,x,y\n"}),
        _err("pt-wrong-header", t, ["k.csv"], ["k.csv"], {"k.csv": "a,b,c\n1,2,3\n2,3,4\n"}),
        _err("pt-random", t, ["k.csv"], ["k.csv"], {"k.csv": random_bytes(3000)}),
        _err("pt-text-values", t, ["k.csv"], ["k.csv"], {"k.csv": "t,x,y\n0,1,1\n0.1,a,b\n"}),
        _err("pt-nan-values", t, ["k.csv"], ["k.csv"], {"k.csv": track_csv(10) + "1.0,nan,2\n"}),
        _err(
            "pt-time-backwards",
            t,
            ["k.csv"],
            ["k.csv"],
            {"k.csv": "t,x,y\n0,1,1\n0.2,1.1,1\n0.1,1.2,1\n0.3,1.3,1\n"},
        ),
        _err("pt-one-row", t, ["k.csv"], ["k.csv"], {"k.csv": "t,x,y\n0,1,1\n"}),
        _err("pt-short-row", t, ["k.csv"], ["k.csv"], {"k.csv": "t,x,y\n0,1,1\n0.1,1\n"}),
        _err("pt-horizon-neg", t, ["k.csv", "--horizon", "-1"], ["--horizon"], ok),
        _err("pt-horizon-nan", t, ["k.csv", "--horizon", "nan"], ["--horizon"], ok),
        _err("pt-horizon-zero", t, ["k.csv", "--horizon", "0"], ["--horizon"], ok),
        _err(
            "pt-horizon-huge",
            t,
            ["k.csv", "--horizon", "1e9", "--step", "0.001"],
            ["--horizon"],
            ok,
            memory_mb=2048,
            timeout=60,
            why="10^12 points",
        ),
        _err("pt-model-bogus", t, ["k.csv", "--model", "oracle"], ["--model"], ok),
        _err("pt-format-bogus", t, ["k.csv", "--format", "xml"], ["--format"], ok),
        _err("pt-step-zero", t, ["k.csv", "--step", "0"], ["--step"], ok),
        _err("pt-history-neg", t, ["k.csv", "--history", "-1"], ["--history"], ok),
        _err(
            "pt-mission-bad",
            t,
            ["k.csv", "--mission", "m.yaml"],
            ["robot.radius"],
            {**ok, "m.yaml": edited("robot.radius", -1)},
        ),
        _err("pt-out-under-file", t, ["k.csv", "--out", "f/p.csv"], ["--out"], {**ok, "f": "x"}),
        _err("pt-plot-under-file", t, ["k.csv", "--plot", "f/p.png"], ["--plot"], {**ok, "f": "x"}),
        _err(
            "pt-huge-map-mission",
            t,
            ["k.csv", "--mission", "m.yaml"],
            ["m.yaml"],
            {**ok, "m.yaml": huge_map()},
            memory_mb=3072,
            timeout=60,
            why="issue 21 item 5",
        ),
        _err("pe-missing", e, ["gone", "--fps", "2.5"], ["gone"]),
        _err("pe-empty-dir", e, ["d", "--fps", "2.5"], ["d"], {"d/.keep": ""}),
        _err(
            "pe-jobs-zero",
            e,
            ["f.txt", "--fps", "2.5", "--jobs", "0"],
            ["--jobs"],
            {"f.txt": frames_txt()},
            why="issue 21 item 13",
        ),
        _err(
            "pe-obs-one",
            e,
            ["f.txt", "--fps", "2.5", "--obs", "1"],
            ["--obs"],
            {"f.txt": frames_txt()},
        ),
        _err(
            "pe-pred-zero",
            e,
            ["f.txt", "--fps", "2.5", "--pred", "0"],
            ["--pred"],
            {"f.txt": frames_txt()},
        ),
        _err("pe-no-fps", e, ["f.txt"], ["--fps"], {"f.txt": frames_txt()}),
        _err("pe-fps-zero", e, ["f.txt", "--fps", "0"], ["--fps"], {"f.txt": frames_txt()}),
        _err("pe-fps-nan", e, ["f.txt", "--fps", "nan"], ["--fps"], {"f.txt": frames_txt()}),
        _err(
            "pe-frame-step-zero",
            e,
            ["f.txt", "--fps", "2.5", "--frame-step", "0"],
            ["--frame-step"],
            {"f.txt": frames_txt()},
        ),
        _err(
            "pe-random-file", e, ["f.txt", "--fps", "2.5"], ["f.txt"], {"f.txt": random_bytes(3000)}
        ),
        _err("pe-csv-as-frames", e, ["k.csv", "--fps", "2.5"], ["k.csv"], ok),
        _err(
            "pe-models-bogus",
            e,
            ["f.txt", "--fps", "2.5", "--models", "oracle"],
            ["oracle"],
            {"f.txt": frames_txt()},
        ),
        _err(
            "pe-json-under-file",
            e,
            ["f.txt", "--fps", "2.5", "--json", "x/s.json"],
            ["--json"],
            {"f.txt": frames_txt(), "x": "x"},
        ),
        _err(
            "pe-format-bogus",
            e,
            ["f.txt", "--format", "parquet"],
            ["--format"],
            {"f.txt": frames_txt()},
        ),
        _err(
            "ps-grid-syntax",
            s,
            ["f.txt", "--fps", "2.5", "--grid", "C"],
            ["--grid"],
            {"f.txt": frames_txt()},
        ),
        _err(
            "ps-grid-unknown",
            s,
            ["f.txt", "--fps", "2.5", "--grid", "zeta=1,2"],
            ["zeta"],
            {"f.txt": frames_txt()},
        ),
        _err(
            "ps-test-fraction-big",
            s,
            ["f.txt", "--fps", "2.5", "--test-fraction", "1.5"],
            ["--test-fraction"],
            {"f.txt": frames_txt()},
        ),
        _err(
            "ps-test-fraction-nan",
            s,
            ["f.txt", "--fps", "2.5", "--test-fraction", "nan"],
            ["--test-fraction"],
            {"f.txt": frames_txt()},
        ),
        _err(
            "ps-model-bogus",
            s,
            ["f.txt", "--fps", "2.5", "--model", "oracle"],
            ["--model"],
            {"f.txt": frames_txt()},
        ),
        _err(
            "ps-metric-bogus",
            s,
            ["f.txt", "--fps", "2.5", "--metric", "rmse"],
            ["--metric"],
            {"f.txt": frames_txt()},
        ),
        _err(
            "ps-top-zero",
            s,
            ["f.txt", "--fps", "2.5", "--top", "0"],
            ["--top"],
            {"f.txt": frames_txt()},
        ),
        _err(
            "ps-jobs-zero",
            s,
            ["f.txt", "--fps", "2.5", "--jobs", "0"],
            ["--jobs"],
            {"f.txt": frames_txt()},
        ),
        _err("ps-missing", s, ["gone", "--fps", "2.5"], ["gone"]),
        _err("pd-walks-zero", d, ["--walks", "0"], ["--walks"]),
        _err("pd-history-neg", d, ["--history", "-1", "--walks", "2"], ["--history"]),
        _err("pd-history-nan", d, ["--history", "nan", "--walks", "2"], ["--history"]),
        _err(
            "pd-plot-under-file", d, ["--walks", "2", "--plot", "f/p.png"], ["--plot"], {"f": "x"}
        ),
        _err(
            "pd-json-under-file", d, ["--walks", "2", "--json", "f/p.json"], ["--json"], {"f": "x"}
        ),
    ]
    return c


def _legs_bt_cases() -> list[Case]:
    tr, ev, sh = "legs train", "legs evaluate", "bt show"
    c = [
        _err("lg-train-scans-zero", tr, ["--sim-scans", "0", "--out", "l.npz"], ["--sim-scans"]),
        _err("lg-train-scans-neg", tr, ["--sim-scans", "-5", "--out", "l.npz"], ["--sim-scans"]),
        _err(
            "lg-train-real-missing",
            tr,
            ["--sim-scans", "50", "--real", "gone", "--out", "l.npz"],
            ["gone"],
        ),
        _err(
            "lg-train-real-empty",
            tr,
            ["--sim-scans", "50", "--real", "d", "--out", "l.npz"],
            ["d"],
            {"d/.keep": ""},
        ),
        _err(
            "lg-train-out-under-file",
            tr,
            ["--sim-scans", "50", "--out", "f/l.npz"],
            ["--out"],
            {"f": "x"},
        ),
        _err(
            "lg-train-mission-bad",
            tr,
            ["--sim-scans", "50", "--mission", "m.yaml", "--out", "l.npz"],
            ["robot.radius"],
            {"m.yaml": edited("robot.radius", -1)},
        ),
        _err(
            "lg-eval-model-missing", ev, ["--model", "gone.npz", "--sim-scans", "50"], ["gone.npz"]
        ),
        _err(
            "lg-eval-model-random",
            ev,
            ["--model", "l.npz", "--sim-scans", "50"],
            ["l.npz"],
            {"l.npz": random_bytes(4000)},
        ),
        _err(
            "lg-eval-model-truncated",
            ev,
            ["--model", "l.npz", "--sim-scans", "50"],
            ["l.npz"],
            {"l.npz": (ROOT / "pfctl" / "data" / "legs_model.npz").read_bytes()[:3000]},
        ),
        _err(
            "lg-eval-model-target",
            ev,
            ["--model", "{target}", "--sim-scans", "50"],
            ["npz"],
            needs=("target",),
        ),
        _err("lg-eval-scans-zero", ev, ["--sim-scans", "0"], ["--sim-scans"]),
        _err("lg-eval-history-zero", ev, ["--sim-scans", "50", "--history", "0"], ["--history"]),
        _err(
            "lg-eval-json-under-file",
            ev,
            ["--sim-scans", "50", "--json", "f/l.json"],
            ["--json"],
            {"f": "x"},
        ),
        _err("lg-eval-real-missing", ev, ["--sim-scans", "50", "--real", "gone"], ["gone"]),
        _err("bt-missing-mission", sh, ["nope.yaml"], ["nope.yaml"]),
        _err(
            "bt-bad-tree",
            sh,
            ["m.yaml"],
            ["m.yaml", "fly"],
            {"m.yaml": edited("behavior.tree", {"action": "fly"})},
        ),
        _err("bt-format-bogus", sh, [M, "--format", "svg"], ["--format"]),
        _err("bt-out-under-file", sh, [M, "--out", "f/t.txt"], ["--out"], {"f": "x"}),
        _err(
            "bt-png-out-dir", sh, [M, "--format", "png", "--out", "d"], ["--out"], {"d/keep": "x"}
        ),
        _err(
            "bt-include-loop",
            sh,
            ["m.yaml"],
            ["tree.yaml"],
            {
                "m.yaml": edited("behavior.tree", {"include": "tree.yaml"}),
                "tree.yaml": "include: tree.yaml\n",
            },
        ),
        _err("bt-leaves-extra-arg", "bt leaves", ["extra"], ["extra"]),
    ]
    return c


def _usage_cases() -> list[Case]:
    return [
        _err("cli-unknown-command", "", ["fly"], ["fly"]),
        _err("cli-unknown-option", "", ["--bogus"], ["--bogus"]),
        _err("cli-follow-no-mission", "follow", [], ["MISSION"]),
        _err("cli-follow-unknown-option", "follow", [M, "--speed", "9"], ["--speed"]),
        _err("cli-duration-not-number", "follow", [M, "--duration", "soon"], ["--duration"]),
        _err("cli-seed-not-int", "sim run", [M, "--seed", "1.5"], ["--seed"]),
        _err("cli-map-unknown-sub", "map", ["paint"], ["paint"]),
        _err("cli-predict-no-args", "predict evaluate", [], ["DATA"]),
    ]


# ---------------------------------------------------------------- interruptions

SIGNAL_PLANS: dict[str, tuple[tuple[float, str, str], ...]] = {
    "int1": ((0.0, "SIGINT", "group"),),
    "int2-0.3s": ((0.0, "SIGINT", "group"), (0.3, "SIGINT", "group")),
    "int2-1.5s": ((0.0, "SIGINT", "group"), (1.5, "SIGINT", "group")),
    "term": ((0.0, "SIGTERM", "main"),),
    "term-int": ((0.0, "SIGTERM", "main"), (0.5, "SIGINT", "group")),
}


def _interrupt_cases() -> list[Case]:
    runs = {
        "follow": (
            ("follow", M, "--target", "{target}", "--seed", "1", "--duration", "40", "--out", "o"),
            ("o/metrics.json", "o/tracks.csv", "o/trajectory.png", "o/timeline.png"),
            ("target",),
        ),
        "search": (
            (
                "search",
                HIDE,
                "--target",
                "{target}",
                "--seed",
                "2",
                "--duration",
                "40",
                "--out",
                "o",
            ),
            ("o/metrics.json", "o/search.png"),
            ("target",),
        ),
        "sim run": (
            (
                "sim",
                "run",
                M,
                "--seed",
                "1",
                "--duration",
                "60",
                "--png",
                "o/paths.png",
                "--no-camera",
            ),
            ("o/paths.png",),
            (),
        ),
    }
    cases = []
    for command, (argv, outputs, needs) in runs.items():
        for plan, signals in SIGNAL_PLANS.items():
            code = 143 if signals[0][1] == "SIGTERM" else 130
            cases.append(
                Case(
                    id=f"sig-{command.replace(' ', '-')}-{plan}",
                    command=command,
                    argv=argv,
                    expect=Expect("interrupt", code=code, outputs=outputs),
                    interrupt=Interrupt(signals, progress=1.5),
                    needs=needs,
                    timeout=150,
                    memory_mb=8192,
                )
            )
    bench = (
        "bench",
        M,
        "--episodes",
        "3",
        "--seed",
        "1",
        "--duration",
        "4",
        "--workers",
        "2",
        "--out",
        "o",
    )
    for plan in ("int1", "int2-0.3s", "term", "term-int"):
        signals = SIGNAL_PLANS[plan]
        cases.append(
            Case(
                id=f"sig-bench-{plan}",
                command="bench",
                argv=bench,
                expect=Expect(
                    "interrupt",
                    code=143 if plan.startswith("term") else 130,
                    outputs=("o/results.jsonl", "o/campaign.json"),
                ),
                interrupt=Interrupt(signals, progress=1, lines_in="o/results.jsonl"),
                timeout=180,
                memory_mb=8192,
            )
        )
    cases.append(
        Case(
            id="sig-bench-kill9-worker",
            command="bench",
            argv=bench,
            expect=Expect("survive", outputs=("o/results.jsonl",), records=3),
            interrupt=Interrupt(
                ((0.0, "SIGKILL", "worker"),), progress=0, lines_in="o/campaign.json"
            ),
            timeout=240,
            memory_mb=8192,
            why="issue 21 item 9: the episode is retried on a new worker",
        )
    )
    return cases


def catalogue() -> list[Case]:
    """Every case, bad inputs first, then interruptions."""
    return [
        *_mission_cases(),
        *_map_cases(),
        *_sim_cases(),
        *_follow_search_cases(),
        *_learn_replay_cases(),
        *_bench_cases(),
        *_predict_cases(),
        *_legs_bt_cases(),
        *_usage_cases(),
        *_interrupt_cases(),
    ]


# Every command a case must exercise (the catalogue test checks the coverage).
COMMANDS = (
    "",
    "mission validate",
    "mission schema",
    "mission generate",
    "map export",
    "map render",
    "map annotate",
    "sim run",
    "sim export-map",
    "sim serve-hsr",
    "follow",
    "search",
    "learn-target",
    "replay",
    "track evaluate",
    "bench",
    "predict",
    "predict evaluate",
    "predict search",
    "predict experiment door",
    "legs train",
    "legs evaluate",
    "bt show",
    "bt leaves",
)

__all__ = [
    "COMMANDS",
    "Case",
    "Content",
    "Expect",
    "Interrupt",
    "catalogue",
]
