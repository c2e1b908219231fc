"""Generated homes as mission files: ``pfctl mission generate`` and ``pfctl bench --homes``.

Wires :func:`pfctl.core.homes.generate_home` to a base mission (its grid resolution, wall
thickness and robot radius; the simulator's person radius) and to the mission writer
(:func:`pfctl.mission.homes.home_mission_text`). The text is validated as a mission before it
is returned, so no invalid home is ever written; a home the options cannot give is one
:class:`~pfctl.errors.UserError` naming the option.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

from pfctl.core.homes import Home, HomeOptions, ImpossibleHomeError, generate_home
from pfctl.errors import MissionError, UserError
from pfctl.files import write_output
from pfctl.mission import Mission, load_mission, loads_mission
from pfctl.mission.homes import home_mission_text

__all__ = [
    "HOUSE_MISSION",
    "GeneratedHome",
    "command_line",
    "home_file_name",
    "make_home",
    "write_homes",
]

#: The base mission of generated homes: the shipped house (every section but map and scenario).
HOUSE_MISSION = Path(__file__).resolve().parents[2] / "missions" / "house.yaml"
_OPTIONS = {"rooms": "--rooms", "size": "--size", "layout": "--layout"}


@dataclass(frozen=True)
class GeneratedHome:
    """A generated home, its mission text, and that text loaded."""

    home: Home
    text: str
    mission: Mission


def command_line(options: HomeOptions) -> str:
    """The ``pfctl mission generate`` options that give ``options``' home (no ``--out``)."""
    parts = ["pfctl mission generate", f"--seed {options.seed}"]
    if options.rooms is not None:
        parts.append(f"--rooms {options.rooms}")
    if options.size is not None:
        parts.append(f"--size {options.size[0]:g}x{options.size[1]:g}")
    if options.layout is not None:
        parts.append(f"--layout {options.layout}")
    if options.crowd:
        parts.append(f"--crowd {options.crowd}")
    if options.look_alikes:
        parts.append(f"--look-alikes {options.look_alikes}")
    return " ".join(parts)


def _given(options: HomeOptions, option: str) -> str:
    value = getattr(options, option)
    if option == "size" and value is not None:
        return f" {value[0]:g}x{value[1]:g}"
    return f" {value}" if value is not None else ""


def make_home(
    options: HomeOptions, base_file: str | os.PathLike[str] = HOUSE_MISSION
) -> GeneratedHome:
    """The home of ``options`` as a validated, self-contained mission text.

    Raises:
        UserError: the options cannot give a home (``--rooms 40: expected ...``), or the base
            mission is bad (its own one-line error).
    """
    base = load_mission(base_file)
    from pfctl.backends.pybullet.walkers import PERSON_RADIUS

    try:
        home = generate_home(
            options,
            resolution=base.map.resolution,
            wall_thickness=base.map.wall_thickness,
            robot_radius=base.robot.radius,
            person_radius=PERSON_RADIUS,
        )
    except ImpossibleHomeError as err:
        option = _OPTIONS.get(err.option, f"--{err.option}")
        raise UserError(f"{option}{_given(options, err.option)}: {err}") from None
    name = os.path.relpath(base_file) if Path(base_file).is_absolute() else os.fspath(base_file)
    if Path(base_file).resolve() == HOUSE_MISSION:
        name = "missions/house.yaml"
    text = home_mission_text(home, base, command=command_line(options), base_name=name)
    try:
        mission = loads_mission(text, source=f"generated home (seed {options.seed})")
    except MissionError as err:  # a generator bug, not the user's: say so plainly
        raise RuntimeError(f"the generated home is not a valid mission: {err}") from None
    return GeneratedHome(home, text, mission)


def home_file_name(seed: int) -> str:
    """The file a campaign writes the home of ``seed`` to: ``home-0007.yaml``."""
    return f"home-{seed:04d}.yaml"


def write_homes(
    folder: Path, seeds: list[int], *, crowd: int = 0, look_alikes: int = 0
) -> list[Path]:
    """Generate the homes of ``seeds`` (default options) into ``folder``; the files, in order.

    A file already there with the same text is kept as it is (a resumed campaign)."""
    folder.mkdir(parents=True, exist_ok=True)
    paths = []
    for seed in seeds:
        made = make_home(HomeOptions(seed=seed, crowd=crowd, look_alikes=look_alikes))
        path = folder / home_file_name(seed)
        if not (path.is_file() and path.read_text(encoding="utf-8") == made.text):
            write_output(path, made.text)
        paths.append(path)
    return paths
