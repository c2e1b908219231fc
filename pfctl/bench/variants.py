"""``--vary KEY=V1,V2,...``: mission variants run side by side in a campaign.

A *vary* names a mission key by its dotted path (``search.alpha``, ``prediction.svr.C``,
``behavior.tree``) and the values it takes. Each value is read as a YAML scalar or flow
collection (``2``, ``1e3``, ``true``, ``[0.5, 2.5]``, ``{x: 1, y: 2}``); ``@PATH`` reads a YAML
file (relative to the current directory) as the value:
``behavior.tree=@missions/trees/no_prediction.yaml``. Commas inside brackets, braces or quotes do
not separate values.

Several varies give their cross product; a :class:`Variant` is one combination, named by its
``KEY=LABEL`` parts (the label of ``@PATH`` is the file's stem): ``behavior.tree=no_prediction
search.alpha=2``. Without any vary there is one variant, :data:`BASE`.

Overrides are applied to the mission file's YAML data before it is validated (so the mission's
own checks and one-line errors apply to the result): the keys of the path are mapping keys,
missing sections are created, and the value replaces whatever was there (lists and trees are
replaced whole). A mission that ``extends`` another gets the override over its own data, which is
then merged over the base as any key of the file would be.
"""

from __future__ import annotations

import copy
import itertools
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml

from pfctl.errors import UserError

__all__ = [
    "BASE",
    "Variant",
    "Vary",
    "apply_overrides",
    "parse_vary",
    "split_values",
    "variants",
]

#: The name of the variant without overrides.
BASE = "base"
_KEY_PART = re.compile(r"[A-Za-z_][A-Za-z0-9_-]*")
_CLOSING = {"[": "]", "{": "}"}


@dataclass(frozen=True)
class Vary:
    """One ``--vary``: a dotted mission key and the values it takes, with their labels."""

    key: str
    values: tuple[Any, ...]
    labels: tuple[str, ...]
    """How each value reads in a variant's name (the text given, or the stem of ``@PATH``)."""


@dataclass(frozen=True)
class Variant:
    """One combination of the varies' values: ``(key, value)`` overrides and their labels."""

    overrides: tuple[tuple[str, Any], ...] = ()
    labels: tuple[str, ...] = ()
    """``KEY=LABEL`` per override, in the order the varies were given."""

    @property
    def name(self) -> str:
        """``KEY=LABEL`` parts separated by spaces; :data:`BASE` without overrides."""
        return " ".join(self.labels) if self.labels else BASE


def split_values(text: str) -> list[str]:
    """``text`` split at the commas outside brackets, braces and quotes, items stripped."""
    items: list[str] = []
    depth: list[str] = []
    quote: str | None = None
    start = 0
    for i, ch in enumerate(text):
        if quote is not None:
            if ch == quote:
                quote = None
        elif ch in "'\"":
            quote = ch
        elif ch in _CLOSING:
            depth.append(_CLOSING[ch])
        elif depth and ch == depth[-1]:
            depth.pop()
        elif ch == "," and not depth:
            items.append(text[start:i].strip())
            start = i + 1
    items.append(text[start:].strip())
    return items


def parse_vary(text: str) -> Vary:
    """Parse one ``--vary KEY=V1,V2,...``.

    Raises:
        UserError: a malformed key, an empty or unreadable value, a missing ``@PATH`` file, or
            the same value twice — one line naming the ``--vary``.
    """
    key, sep, rest = text.partition("=")
    key = key.strip()
    where = f"--vary {text}"
    if not sep or not key:
        raise UserError(f"{where}: expected KEY=V1,V2,... with a dotted mission key (search.alpha)")
    parts = key.split(".")
    bad = next((p for p in parts if not _KEY_PART.fullmatch(p)), None)
    if bad is not None:
        raise UserError(
            f"{where}: expected a dotted path of mission keys such as prediction.svr.C, "
            f"got {bad!r} in {key!r}"
        )
    values: list[Any] = []
    labels: list[str] = []
    for item in split_values(rest):
        if not item:
            raise UserError(f"{where}: empty value (expected KEY=V1,V2,...)")
        if item.startswith("@"):
            value, label = _read_value_file(item[1:], where)
        else:
            try:
                value = yaml.safe_load(item)
            except yaml.YAMLError as err:
                problem = getattr(err, "problem", None) or str(err).splitlines()[0]
                raise UserError(f"{where}: value {item!r} is not YAML: {problem}") from None
            label = item
        if label in labels:
            raise UserError(f"{where}: value {label!r} is given twice")
        values.append(value)
        labels.append(label)
    return Vary(key, tuple(values), tuple(labels))


def _read_value_file(name: str, where: str) -> tuple[Any, str]:
    """The YAML data of ``@PATH`` (relative to the current directory) and its label."""
    path = Path(name)
    if not name:
        raise UserError(f"{where}: expected a file name after @")
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise UserError(f"{where}: @{name}: no such file") from None
    except (OSError, UnicodeDecodeError) as err:
        reason = getattr(err, "strerror", None) or err
        raise UserError(f"{where}: @{name}: cannot read: {reason}") from None
    try:
        value = yaml.safe_load(text)
    except yaml.YAMLError as err:
        mark = getattr(err, "problem_mark", None)
        line = f":{mark.line + 1}" if mark is not None else ""
        problem = getattr(err, "problem", None) or "not YAML"
        raise UserError(f"{where}: @{name}{line}: {problem}") from None
    if value is None:
        raise UserError(f"{where}: @{name}: the file is empty")
    return value, path.stem


def variants(varies: list[Vary]) -> list[Variant]:
    """The cross product of ``varies`` (the first varies slowest), or ``[Variant()]``.

    Raises:
        UserError: the same key twice, or a key inside another one's value (``behavior`` and
            ``behavior.tree``).
    """
    keys = [v.key for v in varies]
    for i, a in enumerate(keys):
        for b in keys[i + 1 :]:
            if a == b:
                raise UserError(f"--vary {a}: the key is varied twice; give all its values once")
            if b.startswith(a + ".") or a.startswith(b + "."):
                outer, inner = (a, b) if b.startswith(a + ".") else (b, a)
                raise UserError(
                    f"--vary {inner}: inside --vary {outer}, which replaces it; vary one of them"
                )
    if not varies:
        return [Variant()]
    out = []
    for combo in itertools.product(*(range(len(v.values)) for v in varies)):
        out.append(
            Variant(
                overrides=tuple((v.key, v.values[i]) for v, i in zip(varies, combo, strict=True)),
                labels=tuple(f"{v.key}={v.labels[i]}" for v, i in zip(varies, combo, strict=True)),
            )
        )
    return out


def apply_overrides(data: dict[str, Any], overrides: tuple[tuple[str, Any], ...]) -> dict[str, Any]:
    """A deep copy of the mission's YAML ``data`` with each ``(dotted key, value)`` set.

    Missing sections on the way are created (a null one too); the value replaces what was there.

    Raises:
        UserError: a key that runs through a value that is not a section (a list, a number).
    """
    out = copy.deepcopy(data)
    for key, value in overrides:
        node: dict[str, Any] = out
        parts = key.split(".")
        for depth, part in enumerate(parts[:-1]):
            child = node.get(part)
            if child is None:
                child = node[part] = {}
            elif not isinstance(child, dict):
                prefix = ".".join(parts[: depth + 1])
                raise UserError(
                    f"--vary {key}: {prefix} is {_kind(child)}, not a section with keys; "
                    f"vary {prefix} as a whole"
                )
            node = child
        node[parts[-1]] = copy.deepcopy(value)
    return out


def _kind(value: Any) -> str:
    if isinstance(value, list):
        return "a list"
    if isinstance(value, str):
        return "a string"
    if isinstance(value, bool):
        return "a boolean"
    return f"a {type(value).__name__}"
