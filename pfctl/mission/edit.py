"""Round-trip editing of a mission YAML: replace ``map.regions`` and ``map.doors``, keep the rest.

``pfctl map annotate --out`` writes the regions and doors it proposes (or was given) into a
mission. A user's mission is theirs: comments, key order, indentation, the other sections and the
rest of ``map`` stay as they were (ruamel.yaml round-trip mode); only the two lists are replaced.
Regions and doors are written one per line in flow style, as in ``missions/house.yaml``::

    regions:
      - {name: kitchen, polygon: [[0, 0], [5, 0], [5, 4], [0, 4]]}
    doors:
      - {between: [kitchen, hall], segment: [[2, 4], [2.9, 4]]}

The result is validated as a mission (:func:`pfctl.mission.loads_mission`) before anything is
written, and written atomically (a temporary file in the same folder, then ``os.replace``), so a
failure leaves the old file, or no file, behind.
"""

from __future__ import annotations

import io
import math
import os
import re
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from ruamel.yaml import YAML
from ruamel.yaml.comments import CommentedMap, CommentedSeq
from ruamel.yaml.error import YAMLError
from ruamel.yaml.util import load_yaml_guess_indent

from pfctl.core.mapping.house import Door, Region
from pfctl.errors import UserError
from pfctl.files import write_output

#: Decimals of written coordinates (millimetres); fewer when the resolution allows.
MAX_DECIMALS = 3


def _decimals(resolution: float | None) -> int:
    """Decimals enough for multiples of ``resolution``, at most :data:`MAX_DECIMALS`."""
    if resolution is None or resolution <= 0:
        return MAX_DECIMALS
    for d in range(MAX_DECIMALS + 1):
        if abs(round(resolution, d) - resolution) < 1e-9:
            return d
    return MAX_DECIMALS


def _num(value: float, decimals: int) -> int | float:
    """``value`` rounded to ``decimals``; an int when it is whole (``5`` rather than ``5.0``)."""
    r = round(float(value), decimals) + 0.0
    return int(r) if r == math.floor(r) and abs(r) < 2**53 else r


def _point(p: Sequence[float], decimals: int) -> CommentedSeq:
    s = CommentedSeq([_num(p[0], decimals), _num(p[1], decimals)])
    s.fa.set_flow_style()
    return s


def _flow_map(**items: Any) -> CommentedMap:
    m = CommentedMap(items)
    m.fa.set_flow_style()
    return m


def _flow_seq(items: Sequence[Any]) -> CommentedSeq:
    s = CommentedSeq(items)
    s.fa.set_flow_style()
    return s


def regions_yaml(regions: Sequence[Region], decimals: int = MAX_DECIMALS) -> CommentedSeq:
    """The ``map.regions`` list as ruamel nodes: one flow mapping per region."""
    out = CommentedSeq()
    for r in regions:
        out.append(
            _flow_map(name=r.name, polygon=_flow_seq([_point(p, decimals) for p in r.polygon]))
        )
    return out


def doors_yaml(doors: Sequence[Door], decimals: int = MAX_DECIMALS) -> CommentedSeq:
    """The ``map.doors`` list as ruamel nodes: one flow mapping per door."""
    out = CommentedSeq()
    for d in doors:
        out.append(
            _flow_map(
                between=_flow_seq(list(d.between)),
                segment=_flow_seq([_point(p, decimals) for p in d.segment]),
            )
        )
    if not doors:
        out.fa.set_flow_style()  # `doors: []`
    return out


def _yaml(mapping_indent: int = 2, sequence_indent: int = 4, offset: int = 2) -> YAML:
    y = YAML()  # round-trip
    y.indent(mapping=mapping_indent, sequence=sequence_indent, offset=offset)
    y.width = 4096  # never fold a long polygon onto several lines
    y.preserve_quotes = True

    def _null(representer: Any, _data: None) -> Any:
        return representer.represent_scalar("tag:yaml.org,2002:null", "null")

    y.representer.add_representer(type(None), _null)
    return y


def _mapping_indent(text: str) -> int:
    """The indentation of the first nested ``key:`` line (2 if there is none)."""
    for line in text.splitlines():
        m = re.match(r"^( +)[^\s#-][^:#]*:", line)
        if m:
            return len(m.group(1))
    return 2


def _replace(mapping: CommentedMap, key: str, value: CommentedSeq, before: str | None) -> None:
    """Set ``mapping[key]`` in place, or insert it before key ``before`` (else at the end).

    Comment lines that trailed the old list (ruamel keeps them at the list's end or on its last
    item) move to the new list, so a comment above the next key survives.
    """
    old = mapping.get(key)
    if isinstance(old, CommentedSeq):
        end = getattr(old.ca, "end", None)
        if end and len(value):
            value.ca.end = end
            # the emitter only writes an end comment for a sequence that has comment slots
            value.ca.comment = old.ca.comment if old.ca.comment is not None else [None, None]
        elif end and key in mapping and list(mapping).index(key) + 1 < len(mapping):
            # an empty list is written `[]`, which carries no comment: put the lines above the
            # next key instead
            following = list(mapping)[list(mapping).index(key) + 1]
            lines = [
                line.strip()[1:].strip()
                for token in end
                if token is not None
                for line in token.value.splitlines()
                if line.strip().startswith("#")
            ]
            if lines:
                column = getattr(end[0], "column", 0) or 0
                mapping.yaml_set_comment_before_after_key(
                    following, before="\n".join(lines), indent=column
                )
        tail = old.ca.items.get(len(old) - 1) if len(old) else None
        if tail and len(value):
            value.ca.items[len(value) - 1] = tail
    if key in mapping:
        mapping[key] = value
    elif before is not None and before in mapping:
        mapping.insert(list(mapping).index(before), key, value)
    else:
        mapping[key] = value


def render_regions(
    mission_path: str | os.PathLike[str],
    regions: Sequence[Region],
    doors: Sequence[Door],
    *,
    name: str | None = None,
    resolution: float | None = None,
    occupancy: str | os.PathLike[str] | None = None,
) -> str:
    """The text :func:`write_regions` would write (nothing is written).

    Existing file: its ``map.regions`` and ``map.doors`` replaced, everything else as it was
    (``map`` is created if missing; ``name`` renames the mission only if given). New file: a
    minimal mission ``name`` (default: the file's stem), ``map: {resolution, occupancy, regions,
    doors}``, ``occupancy`` written relative to the mission's folder.
    """
    path = Path(mission_path)
    decimals = _decimals(resolution)
    if path.exists():
        try:
            text = path.read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError) as err:
            raise UserError(f"{path}: cannot read the mission to update: {err}") from None
        try:
            data, seq_indent, offset = load_yaml_guess_indent(text)
        except YAMLError as err:
            first = str(err).strip().splitlines()[0] if str(err).strip() else "syntax error"
            raise UserError(f"{path}: invalid YAML, cannot update it: {first}") from None
        if data is None:
            data = CommentedMap()
        if not isinstance(data, CommentedMap):
            raise UserError(f"{path}: expected a mission (a mapping with 'name' and 'map')")
        yaml = _yaml(_mapping_indent(text), seq_indent or 4, offset if offset is not None else 2)
        if name is not None:
            data["name"] = name
        elif "name" not in data:
            data.insert(0, "name", path.stem)
        section = data.get("map")
        if section is None:
            section = CommentedMap()
            if "map" in data:
                data["map"] = section
            else:
                keys = list(data)
                pos = keys.index("description") + 1 if "description" in keys else 1
                data.insert(min(pos, len(keys)), "map", section)
        if not isinstance(section, CommentedMap):
            raise UserError(f"{path}: map: expected a mapping, cannot write regions into it")
        if resolution is not None and "resolution" not in section:
            section.insert(0, "resolution", _num(resolution, MAX_DECIMALS))
        _replace(section, "regions", regions_yaml(regions, decimals), before="doors")
        _replace(section, "doors", doors_yaml(doors, decimals), before="obstacles")
    else:
        yaml = _yaml()
        occ: str | None = None
        if occupancy is not None:
            occ = os.path.relpath(Path(occupancy).resolve(), path.parent.resolve())
        section = CommentedMap()
        section["resolution"] = _num(resolution if resolution is not None else 0.05, MAX_DECIMALS)
        section["occupancy"] = occ
        section["regions"] = regions_yaml(regions, decimals)
        section["doors"] = doors_yaml(doors, decimals)
        data = CommentedMap()
        data["name"] = name or path.stem
        data["map"] = section
    out = io.StringIO()
    yaml.dump(data, out)
    return out.getvalue()


def write_regions(
    mission_path: str | os.PathLike[str],
    regions: Sequence[Region],
    doors: Sequence[Door],
    name: str | None = None,
    *,
    resolution: float | None = None,
    occupancy: str | os.PathLike[str] | None = None,
    validate: bool = True,
) -> Path:
    """Write ``regions`` and ``doors`` into the mission at ``mission_path`` (see module docstring).

    Args:
        mission_path: an existing mission to update, or the path of a new one.
        regions, doors: what to write; coordinates rounded to ``resolution`` (≤ 3 decimals).
        name: the mission's name (new file: default the file's stem; existing: unchanged if None).
        resolution: ``map.resolution`` of a new mission (default 0.05); for an existing one it is
            only added if the file has none.
        occupancy: the map_server YAML of a new mission (written relative to the mission).
        validate: check that the result loads as a mission before writing.

    Raises:
        UserError: the existing file cannot be read or parsed, or the result is not a valid
            mission (:class:`pfctl.errors.MissionError`); nothing is written then.
    """
    path = Path(mission_path)
    text = render_regions(
        path, regions, doors, name=name, resolution=resolution, occupancy=occupancy
    )
    if validate:
        from pfctl.mission import loads_mission

        loads_mission(text, source=str(path), base_dir=path.parent)
    return write_output(path, text)


__all__ = ["doors_yaml", "regions_yaml", "render_regions", "write_regions"]
