"""The rooms of DESIGN.md (v2) and which way imports may point between them, read from the code.

DESIGN.md: ``cli → commands → app → {backends, bags, plots, bench, mission, core}``;
``backends → {bags, core}``; ``bags → core``; ``plots → core``; ``mission → core``; ``core → core``
only (and third-party numerical libraries). Arrows compose: a room may import every room it
reaches. ``bench`` (campaigns and their statistics) uses ``mission`` and ``core``; the episodes
it runs are given to it by ``app``. The small shared modules at the top of the package
(``errors``, ``files``, ``progress``, ``interrupts``) may be imported by every room but ``core``.
Besides: no command imports another command, and of the HSR backend only ``sim_bridge`` (the
simulated house served as an HSR) may import the PyBullet backend.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "pfctl"

#: Each room and the rooms it may import (itself included).
ARROWS: dict[str, set[str]] = {
    "core": set(),
    "mission": {"core"},
    "bags": {"core"},
    "plots": {"core"},
    "backends.pybullet": {"bags", "core"},
    "backends.hsr": {"bags", "core"},
    "bench": {"mission", "core"},
    "app": {"backends.pybullet", "backends.hsr", "bags", "plots", "bench", "mission", "core"},
    "commands": {"app", "backends.pybullet", "backends.hsr", "bags", "plots", "bench", "mission"}
    | {"core"},
    "cli": {"commands"},
    "__main__": {"cli"},
}
SHARED = {"errors", "files", "progress", "interrupts", "__init__"}
"""Top-level modules every room but core may import (``pfctl`` itself: its version)."""

#: Third-party libraries core may import (DESIGN.md: numerical libraries and py_trees; OpenCV
#: and dlib for images and faces).
CORE_LIBRARIES = {
    "numpy",
    "scipy",
    "sklearn",
    "filterpy",
    "shapely",
    "networkx",
    "py_trees",
    "cv2",
    "dlib",
    "face_recognition_models",
}

#: Core's loose modules (the rest live in its packages), and the package's.
MAX_LOOSE = 8


def room_of(module: str) -> str:
    """``pfctl.core.mapping.grid`` → ``core``; ``pfctl.backends.hsr.robot`` → ``backends.hsr``;
    ``pfctl.errors`` → ``errors`` (a shared module)."""
    parts = module.split(".")[1:] or ["__init__"]
    if parts[0].startswith("__") and parts[0] != "__main__":
        return "__init__"  # pfctl itself (``from pfctl import __version__``)
    if parts[0] == "backends" and len(parts) > 1:
        return f"backends.{parts[1]}"
    return parts[0]


def imports_of(path: Path, root: Path = ROOT) -> list[tuple[int, str]]:
    """``(line, module)`` of every import in a file (relative imports resolved; ``from pfctl
    import x`` counts as importing ``pfctl.x``)."""
    module_parts = path.relative_to(root).with_suffix("").parts
    out: list[tuple[int, str]] = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            out += [(node.lineno, alias.name) for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = module_parts[: len(module_parts) - node.level]
                name = ".".join((*base, node.module) if node.module else base)
            else:
                name = node.module or ""
            if name == "pfctl":
                out += [(node.lineno, f"pfctl.{alias.name}") for alias in node.names]
            else:
                out.append((node.lineno, name))
    return out


def violations(root: Path = ROOT) -> list[str]:
    """Every import under ``root/pfctl`` that points the wrong way, as ``file:line: reason``."""
    bad: list[str] = []
    paths = sorted(p for p in (root / "pfctl").rglob("*.py") if "__pycache__" not in p.parts)
    for path in paths:
        rel = path.relative_to(root).as_posix()
        here = ".".join(path.relative_to(root).with_suffix("").parts)
        room = room_of(here)
        for line, name in imports_of(path, root):
            where = f"{rel}:{line}"
            top = name.split(".")[0]
            if top != "pfctl":
                if room == "core" and top not in CORE_LIBRARIES and not _is_stdlib(top):
                    bad.append(f"{where}: core imports the library {name}")
                continue
            target = room_of(name)
            if target == room or (room in SHARED and target in SHARED):
                if room == "commands" and name != here and name.startswith("pfctl.commands."):
                    bad.append(f"{where}: a command imports another command ({name})")
                continue
            if target in SHARED:
                if room == "core":
                    bad.append(f"{where}: core imports {name}")
                continue
            allowed = ARROWS.get(room, set())
            if room == "backends.hsr" and target == "backends.pybullet":
                if not rel.endswith("backends/hsr/sim_bridge.py"):
                    bad.append(f"{where}: only sim_bridge may import the PyBullet backend")
                continue
            if target not in allowed:
                bad.append(f"{where}: {room} imports {target} ({name})")
    return bad


def _is_stdlib(name: str) -> bool:
    import sys

    return name in sys.stdlib_module_names or name == "__future__"


def test_imports_point_the_way_design_md_says() -> None:
    assert violations() == []


def test_core_and_the_package_keep_few_loose_modules() -> None:
    """Families live in packages (DESIGN.md's rooms), not side by side at the top."""
    for folder in (PACKAGE, PACKAGE / "core"):
        loose = sorted(p.name for p in folder.glob("*.py") if p.name != "__init__.py")
        assert len(loose) <= MAX_LOOSE, f"{folder.relative_to(ROOT)}: {loose}"


@pytest.mark.parametrize(
    "room",
    ["app", "mission", "bags", "plots", "core/mapping", "core/perception", "core/prediction"],
)
def test_the_rooms_exist(room: str) -> None:
    assert (PACKAGE / room / "__init__.py").exists()


def test_the_check_catches_each_kind_of_wrong_arrow(tmp_path: Path) -> None:
    """The rules themselves, on a small package with one wrong arrow of each kind (a check
    that cannot fail proves nothing) and right ones beside them."""
    files = {
        "core/grid.py": "import yaml\nfrom pfctl.errors import UserError\nimport numpy\n",
        "core/mapping/regions.py": "from pfctl.core.grid import Grid\nfrom ..grid import Grid\n",
        "backends/pybullet/world.py": "from pfctl.mission import Mission\n",
        "backends/hsr/robot.py": "from pfctl.backends.pybullet.simulation import SimRobot\n",
        "backends/hsr/sim_bridge.py": "from pfctl.backends.pybullet.simulation import SimRobot\n",
        "commands/follow.py": "from pfctl.commands.sim import check\nfrom pfctl.app import x\n",
        "bags/replay.py": "from pfctl.backends.hsr.robot import HsrRobot\n",
        "app/episodes.py": "from pfctl import errors\nfrom pfctl.core.robot import Pose2D\n",
    }
    for name, text in files.items():
        path = tmp_path / "pfctl" / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text)
    assert violations(tmp_path) == [
        "pfctl/backends/hsr/robot.py:1: only sim_bridge may import the PyBullet backend",
        "pfctl/backends/pybullet/world.py:1: backends.pybullet imports mission (pfctl.mission)",
        "pfctl/bags/replay.py:1: bags imports backends.hsr (pfctl.backends.hsr.robot)",
        "pfctl/commands/follow.py:1: a command imports another command (pfctl.commands.sim)",
        "pfctl/core/grid.py:1: core imports the library yaml",
        "pfctl/core/grid.py:2: core imports pfctl.errors",
    ]
