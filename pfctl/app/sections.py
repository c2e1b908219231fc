"""Backend config objects filled from the mission's sections.

A backend receives plain frozen dataclasses of its own (``backends/*/config.py``) whose fields
carry the names of the mission's fields; :func:`from_section` copies the values across by name,
so a value is declared once, in the mission, and only carried by the backend's config.
"""

from __future__ import annotations

import dataclasses
from typing import Any, TypeVar, get_args, get_origin, get_type_hints

T = TypeVar("T")


def from_section(cls: type[T], section: object, **given: Any) -> T:
    """An instance of the dataclass ``cls``: the fields in ``given`` as given, every other one
    the attribute of ``section`` of the same name. A field whose type is a dataclass (or a tuple
    of one) is filled the same way from that attribute (or from each of its items)."""
    hints = get_type_hints(cls)
    values = dict(given)
    for f in dataclasses.fields(cls):  # type: ignore[arg-type]
        if f.name not in values:
            values[f.name] = _carried(hints[f.name], getattr(section, f.name))
    return cls(**values)


def _carried(hint: Any, value: Any) -> Any:
    if dataclasses.is_dataclass(hint) and isinstance(hint, type):
        return from_section(hint, value)
    args = get_args(hint)
    if get_origin(hint) is tuple and len(args) == 2 and args[1] is Ellipsis:
        item = args[0]
        if dataclasses.is_dataclass(item) and isinstance(item, type):
            return tuple(from_section(item, v) for v in value)
    return value


__all__ = ["from_section"]
