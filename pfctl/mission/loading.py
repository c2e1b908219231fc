"""Reading a mission: the YAML with what it ``extends`` and ``include``s, validated, every
failure one line.

A mission is checked in three layers, and every failure becomes a :class:`pfctl.errors.MissionError`
whose message is one line, ``<file>:<line>: <key.path[2].sub>: <what was expected>``
(:mod:`pfctl.mission.errors`):

1. reading: missing file, a directory, not UTF-8, empty, YAML syntax, duplicate keys; the
   mission it ``extends`` (read first, this file merged over it: :func:`merge_mission_data`)
   and a tree file it includes (``behavior.tree: {include: PATH}``), missing or in a cycle;
2. shape: unknown keys, wrong types, ranges (pydantic, ``extra="forbid"`` everywhere);
3. meaning: polygons are simple with >= 3 distinct points, regions do not overlap, doors lie on
   the wall two existing regions share, the scenario's target and routes name existing things.

Example::

    mission = load_mission("missions/house.yaml")
    layout = mission.layout()          # HouseLayout: regions, doors, obstacles
    mission.behavior.tree.size()       # number of behavior-tree nodes
"""

from __future__ import annotations

import functools
import os
from pathlib import Path
from typing import Any, get_args

import yaml
from pydantic import BaseModel, ValidationError

from pfctl.errors import MissionError
from pfctl.mission.errors import (
    format_loc,
    format_validation_error,
    got,
    models_in,
    one_line,
    short,
)
from pfctl.mission.sections import Mission


def load_mission(path: str | os.PathLike[str]) -> Mission:
    """Read and validate the mission at ``path``.

    A mission may start from another: a top-level ``extends: PATH`` (relative to the file)
    loads that mission's YAML first — recursively, a cycle is an error — and merges this file
    over it (:func:`merge_mission_data`). ``behavior.tree: {include: PATH}`` reads the tree from
    a file holding exactly what ``behavior.tree`` would (``missions/trees/``). Relative paths in
    a file (``map.occupancy``, ``perception.legs.model``) stay relative to the file that has
    them, and errors name the file and line the failing value came from.

    Raises:
        MissionError: for anything wrong with the file, with a one-line message
            ``<file>:<line>: <key.path>: <what was expected>``.
    """
    source = os.fspath(path)
    file = Path(source)
    text = _read_text(file, source, "a mission YAML file")
    return _loads(text, source, file.parent, ((file.resolve(), source),))


def loads_mission(
    text: str, *, source: str = "<string>", base_dir: str | os.PathLike[str] | None = None
) -> Mission:
    """Validate the mission YAML in ``text``; ``source`` names it in errors.

    ``base_dir`` is where relative paths in the mission (``map.occupancy``, ``extends``,
    ``behavior.tree.include``) are resolved; the current directory if None.

    Raises:
        MissionError: as :func:`load_mission`.
    """
    return _loads(text, source, Path(base_dir) if base_dir is not None else Path("."), ())


def merge_mission_data(base: Any, child: Any, path: tuple[str, ...] = ()) -> Any:
    """``child`` deep-merged over ``base`` (the semantics of ``extends``).

    Mappings merge key by key (a key of ``child`` wins; keys only in ``base`` stay); lists and
    scalars replace. ``behavior.tree`` replaces as a whole: a tree node is one of several kinds,
    and merging two trees would mix them. ``path`` is the key path of ``base`` and ``child``.
    """
    if isinstance(base, dict) and isinstance(child, dict) and path != _TREE_PATH:
        merged = dict(base)
        for key, value in child.items():
            sub = (*path, str(key))
            merged[key] = merge_mission_data(base[key], value, sub) if key in base else value
        return merged
    return child


#: The top-level key naming the mission a file extends.
EXTENDS_KEY = "extends"
#: ``behavior.tree: {include: PATH}``: the tree is read from PATH.
INCLUDE_KEY = "include"
_TREE_PATH = ("behavior", "tree")
_Chain = tuple[tuple[Path, str], ...]
"""The files being extended, outermost first: (resolved path, name in messages)."""


def _read_text(file: Path, source: str, what: str) -> str:
    """The UTF-8 text of ``file``; one-line errors naming ``source``."""
    if file.is_dir():
        raise MissionError(f"{source}: is a directory, expected {what}")
    try:
        raw = file.read_bytes()
    except FileNotFoundError:
        raise MissionError(f"{source}: no such file") from None
    except OSError as err:
        raise MissionError(f"{source}: cannot read: {err.strerror or err}") from None
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError as err:
        line = raw[: err.start].count(b"\n") + 1
        raise MissionError(
            f"{source}:{line}: not UTF-8 text (byte 0x{raw[err.start]:02x}); "
            "save the mission as UTF-8"
        ) from None


def _loads(text: str, source: str, base_dir: Path, chain: _Chain) -> Mission:
    """Read ``text`` with what it extends and includes, then validate the merged mission."""
    root, data, sources = _read_layers(text, source, base_dir, chain)
    context = {"base_dir": base_dir}
    try:
        return Mission.model_validate(data, context=context)
    except ValidationError as err:
        raise MissionError(format_validation_error(err, root, sources, Mission)) from None
    except RecursionError:
        raise MissionError(f"{source}: the mission is nested too deeply") from None


def _read_layers(
    text: str, source: str, base_dir: Path, chain: _Chain
) -> tuple[yaml.MappingNode, dict[str, Any], list[str]]:
    """The mission in ``text`` merged over the one it extends: the YAML node graph (every node
    keeps the name of its file in its marks, for error lines), the data, and the files read,
    this one first."""
    root, data = _parse_yaml(text, source)
    if root is None or data is None:
        raise MissionError(
            f"{source}: the file is empty; expected a mission with at least 'name' and 'map'"
        )
    if not isinstance(data, dict) or not isinstance(root, yaml.MappingNode):
        raise MissionError(
            f"{source}:{root.start_mark.line + 1}: expected a mapping of mission sections "
            f"(name, map, ...) at the top level, got {_yaml_kind(data)}"
        )
    _check_duplicate_keys(root, source)
    sources = [source, *_include_tree(root, data, source, base_dir)]
    key = _key_node(root, EXTENDS_KEY)
    if key is None:
        return root, data, sources
    line = key.start_mark.line + 1
    where = f"{source}:{line}: {EXTENDS_KEY}"
    value = data.pop(EXTENDS_KEY)
    root = yaml.MappingNode(
        root.tag,
        [(k, v) for k, v in root.value if k is not key],
        root.start_mark,
        root.end_mark,
        root.flow_style,
    )
    base_file = _referenced_file(
        value, base_dir, where, "the path of the mission this one extends", "mission file"
    )
    resolved = base_file.resolve()
    names = [name for _, name in chain] or [source]
    if any(resolved == seen for seen, _ in chain):
        cycle = " -> ".join([*names, os.path.normpath(base_file)])
        raise MissionError(f"{where}: a mission cannot extend itself: {cycle}")
    base_name = os.path.normpath(base_file)  # for messages; the file is read as written
    base_text = _read_text(base_file, base_name, "a mission YAML file")
    base_chain = (*(chain or ((Path(source), source),)), (resolved, base_name))
    base_root, base_data, base_sources = _read_layers(
        base_text, base_name, base_file.parent, base_chain
    )
    _rebase_files(base_data, base_file.parent, base_dir)
    merged_root = _merge_nodes(base_root, root, ())
    assert isinstance(merged_root, yaml.MappingNode)
    return merged_root, merge_mission_data(base_data, data), [*sources, *base_sources]


def _referenced_file(value: object, base_dir: Path, where: str, expected: str, kind: str) -> Path:
    """The existing file a mission names at ``where`` (``extends``, a tree ``include``): an
    absolute path, or one relative to the naming file's folder ``base_dir``; else one line."""
    if not isinstance(value, str) or not value.strip():
        raise MissionError(
            f"{where}: expected {expected} (relative to this file), got {got(value)}"
        )
    file = Path(value) if Path(value).is_absolute() else base_dir / value
    if not file.is_file():
        raise MissionError(
            f"{where}: expected an existing {kind}, but {os.path.normpath(file)} "
            + ("is a directory" if file.is_dir() else "does not exist")
        )
    return file


def _key_node(node: yaml.Node, key: str) -> yaml.ScalarNode | None:
    """The key node ``key`` of mapping ``node`` (the last, as PyYAML keeps), else None."""
    if not isinstance(node, yaml.MappingNode):
        return None
    for k, _ in reversed(node.value):
        if isinstance(k, yaml.ScalarNode) and k.value == key:
            return k
    return None


def _include_tree(
    root: yaml.MappingNode, data: dict[str, Any], source: str, base_dir: Path
) -> list[str]:
    """Replace ``behavior.tree: {include: PATH}`` by the tree read from PATH (relative to the
    mission file), in the data and in the node graph; the file read, if any."""
    behavior, tree = data.get("behavior"), None
    if isinstance(behavior, dict):
        tree = behavior.get("tree")
    if not isinstance(tree, dict) or INCLUDE_KEY not in tree:
        return []
    behavior_value = next(v for k, v in root.value if k is _key_node(root, "behavior"))
    tree_key = _key_node(behavior_value, "tree")
    assert tree_key is not None and isinstance(behavior_value, yaml.MappingNode)
    tree_value = next(v for k, v in behavior_value.value if k is tree_key)
    include_key = _key_node(tree_value, INCLUDE_KEY)
    assert include_key is not None
    where = f"{source}:{include_key.start_mark.line + 1}: behavior.tree.{INCLUDE_KEY}"
    others = [str(k) for k in tree if k != INCLUDE_KEY]
    if others:
        raise MissionError(
            f"{where}: a tree read from a file takes no other keys, got {others[0]!r} beside it"
        )
    value = tree[INCLUDE_KEY]
    file = _referenced_file(value, base_dir, where, "the path of a tree file", "tree file")
    name = os.path.normpath(file)
    tree_root, tree_data = _parse_yaml(_read_text(file, name, "a behavior-tree YAML file"), name)
    if tree_root is None or tree_data is None:
        raise MissionError(
            f"{name}: the file is empty; expected a behavior tree (what behavior.tree holds)"
        )
    _check_duplicate_keys(tree_root, name, _TREE_PATH)
    behavior["tree"] = tree_data
    behavior_value.value = [(k, tree_root if k is tree_key else v) for k, v in behavior_value.value]
    return [name]


def _merge_nodes(base: yaml.Node, child: yaml.Node, path: tuple[str, ...]) -> yaml.Node:
    """:func:`merge_mission_data` on the YAML node graphs: a merged mapping takes the child's
    marks; every other node stays the one (and the file) its value came from."""
    if not (
        isinstance(base, yaml.MappingNode)
        and isinstance(child, yaml.MappingNode)
        and path != _TREE_PATH
    ):
        return child
    children = {k.value: (k, v) for k, v in child.value if isinstance(k, yaml.ScalarNode)}
    merged: list[tuple[yaml.Node, yaml.Node]] = []
    for k, v in base.value:
        name = k.value if isinstance(k, yaml.ScalarNode) else None
        if name in children:
            ck, cv = children.pop(name)
            merged.append((ck, _merge_nodes(v, cv, (*path, name))))
        else:
            merged.append((k, v))
    merged += [
        (k, v) for k, v in child.value if not isinstance(k, yaml.ScalarNode) or k.value in children
    ]
    return yaml.MappingNode(child.tag, merged, child.start_mark, child.end_mark, child.flow_style)


@functools.cache
def _file_fields() -> tuple[tuple[str, ...], ...]:
    """Key paths of the mission's file-valued fields (``map.occupancy``,
    ``perception.legs.model``): the ``Path`` fields of the models, through nested models."""

    def walk(model: type[BaseModel], seen: frozenset[type[BaseModel]]) -> list[tuple[str, ...]]:
        out: list[tuple[str, ...]] = []
        for name, info in model.model_fields.items():
            if Path in (info.annotation, *get_args(info.annotation)):
                out.append((name,))
            for sub in models_in(info.annotation):
                if sub not in seen:
                    out += [(name, *rest) for rest in walk(sub, seen | {sub})]
        return out

    return tuple(walk(Mission, frozenset({Mission})))


def _rebase_files(data: dict[str, Any], file_dir: Path, base_dir: Path) -> None:
    """Relative file paths of a base mission in ``file_dir``, made absolute so that they still
    name the same files when the extending mission in ``base_dir`` is validated."""
    if file_dir.resolve() == base_dir.resolve():
        return
    for keys in _file_fields():
        parent: Any = data
        for key in keys[:-1]:
            parent = parent.get(key) if isinstance(parent, dict) else None
        value = parent.get(keys[-1]) if isinstance(parent, dict) else None
        if isinstance(value, str) and value and not Path(value).is_absolute():
            parent[keys[-1]] = str((file_dir / value).absolute())


def _yaml_kind(value: Any) -> str:
    if isinstance(value, list):
        return "a list"
    if isinstance(value, str):
        return f"the string {short(value)}"
    return f"{type(value).__name__} {short(value)}"


def _parse_yaml(text: str, source: str) -> tuple[yaml.Node | None, Any]:
    """Compose the node graph (for line numbers) and construct the data from it, in one parse."""
    loader = yaml.SafeLoader(text)
    loader.name = source  # every node's marks name its file (errors of merged missions)
    try:
        root = loader.get_single_node()
        data = loader.construct_document(root) if root is not None else None
    except yaml.MarkedYAMLError as err:
        mark = err.problem_mark or err.context_mark
        where = f"{source}:{mark.line + 1}" if mark is not None else source
        parts = [p for p in (err.context, err.problem) if p]
        cmark, pmark = err.context_mark, err.problem_mark
        if cmark is not None and pmark is not None and err.context and cmark.line != pmark.line:
            parts[0] = f"{err.context} (line {cmark.line + 1})"
        detail = one_line(": ".join(parts) or "invalid YAML")
        label = (
            "YAML error"
            if isinstance(err, yaml.constructor.ConstructorError)
            else "YAML syntax error"
        )
        raise MissionError(f"{where}: {label}: {detail}") from None
    except yaml.YAMLError as err:
        raise MissionError(f"{source}: YAML syntax error: {one_line(str(err))}") from None
    except RecursionError:
        raise MissionError(f"{source}: the YAML is nested too deeply") from None
    finally:
        loader.dispose()
    return root, data


def _check_duplicate_keys(root: yaml.Node, source: str, prefix: tuple[str | int, ...] = ()) -> None:
    """PyYAML keeps the last of two equal keys silently; a mission must not repeat a key.
    ``prefix`` is the key path of ``root`` in the mission (a tree file's ``behavior.tree``)."""
    seen: set[int] = set()
    stack: list[tuple[yaml.Node, tuple[str | int, ...]]] = [(root, prefix)]
    while stack:
        node, loc = stack.pop()
        if id(node) in seen:
            continue
        seen.add(id(node))
        if isinstance(node, yaml.MappingNode):
            keys: dict[str, int] = {}
            for key, value in node.value:
                if isinstance(key, yaml.ScalarNode) and key.value != "<<":
                    if key.value in keys:
                        path = format_loc((*loc, key.value))
                        raise MissionError(
                            f"{source}:{key.start_mark.line + 1}: {path}: duplicate key "
                            f"(first on line {keys[key.value]})"
                        )
                    keys[key.value] = key.start_mark.line + 1
                    stack.append((value, (*loc, key.value)))
        elif isinstance(node, yaml.SequenceNode):
            stack.extend((item, (*loc, i)) for i, item in enumerate(node.value))
