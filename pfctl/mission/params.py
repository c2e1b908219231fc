"""Mission keys that the core declares: their YAML fields derived, and core parameters built.

A core parameter is declared once, on its dataclass field (:func:`pfctl.core.params.param`):
default, meaning, unit, bounds. A mission section names such a key with the annotation
:data:`FromCore` and the dataclass it comes from as ``core``; the key's type, default, bounds and
description (what ``pfctl mission schema`` shows) are taken from the declaration::

    class TrackingConfig(CoreSection, core=TrackerParams):
        \"""Noise of the constant-velocity Kalman filters and the association gate (§II-E).\"""

        process_noise: FromCore
        laser_noise: FromCore

Keys keep their order in the section, with the section's own keys (declared as usual) among
them; ``core`` may be several dataclasses (the first that has the key's field wins) and
``core_names`` names a core field that the mission calls otherwise (``{"kind": "weighting"}``).
The other way, :func:`core_params` builds a dataclass from validated sections, by name
(:func:`core_values`).

The types are those the mission's hand-written fields had: YAML booleans are no numbers; a
number bounded by 0 alone, or not at all, is finite (:data:`~pfctl.mission.types.Positive`,
:data:`~pfctl.mission.types.NonNegative`, :data:`~pfctl.mission.types.Number`); bounds on a tuple
bound each item; an ``ordered`` pair is :data:`~pfctl.mission.types.Limits`.
"""

from __future__ import annotations

import dataclasses
import inspect
import typing
from collections.abc import Mapping
from typing import TYPE_CHECKING, Annotated, Any, ClassVar, Literal, TypeVar, get_args, get_origin

from pydantic import Field

from pfctl.core.params import ParamInfo, param_info
from pfctl.mission.types import (
    NO_BOOL,
    Count,
    Integer,
    Limits,
    MissionModel,
    NonNegative,
    Number,
    Positive,
)

__all__ = ["CoreSection", "FromCore", "core_params", "core_values"]

if TYPE_CHECKING:
    FromCore = Any
else:

    class FromCore:
        """The annotation of a section key that the core declares (module docstring)."""


P = TypeVar("P")

#: Floats of these bounds are the mission's finite types; other bounds give a plain float.
_FINITE_FLOATS: dict[tuple[tuple[str, float], ...], Any] = {
    (): Number,
    (("gt", 0),): Positive,
    (("ge", 0),): NonNegative,
}
_NAMED_INTS: dict[tuple[tuple[str, float], ...], Any] = {(): Integer, (("ge", 1),): Count}


class CoreSection(MissionModel):
    """A mission section with keys that the core declares (the module docstring).

    Subclass it with ``core=`` (a dataclass, or a tuple of them) and, where a key is not named as
    its core field, ``core_names={key: field}``.
    """

    core_fields: ClassVar[Mapping[str, tuple[type, str]]] = {}
    """Key → (core dataclass, field name), for the keys annotated :data:`FromCore`."""

    def __init_subclass__(
        cls,
        *,
        core: type | tuple[type, ...] = (),
        core_names: Mapping[str, str] | None = None,
        **kwargs: Any,
    ) -> None:
        # runs before pydantic collects the fields (ModelMetaclass), so the derived annotations
        # and defaults are the section's fields
        super().__init_subclass__(**kwargs)
        sources = core if isinstance(core, tuple) else (core,)
        names = dict(core_names or {})
        annotations = inspect.get_annotations(cls)
        derived: dict[str, tuple[type, str]] = {}
        for key, annotation in list(annotations.items()):
            if annotation not in ("FromCore", FromCore):
                continue
            name = names.pop(key, key)
            source = next((s for s in sources if name in _field_names(s)), None)
            if source is None:
                known = ", ".join(s.__name__ for s in sources) or "no core=..."
                raise TypeError(f"{cls.__name__}.{key}: no field {name!r} in {known}")
            annotations[key], default = _field(source, name)
            setattr(cls, key, default)
            derived[key] = (source, name)
        if names:
            raise TypeError(f"{cls.__name__}: core_names for keys it lacks: {sorted(names)}")
        cls.__annotations__ = annotations
        cls.core_fields = {**cls.core_fields, **derived}


def core_values(params: type, *sections: CoreSection) -> dict[str, Any]:
    """The values of the keys of ``sections`` that dataclass ``params`` declares, by its field
    names."""
    return {
        name: getattr(section, key)
        for section in sections
        for key, (source, name) in type(section).core_fields.items()
        if source is params
    }


def core_params(params: type[P], /, *sections: CoreSection, **given: Any) -> P:
    """The dataclass ``params`` built from the keys of ``sections`` that it declares
    (:func:`core_values`) and from ``given`` (fields by name, over the sections' values, e.g. a
    setting resolved for the robot); fields in neither keep their defaults."""
    return params(**{**core_values(params, *sections), **given})


def _field_names(params: type) -> set[str]:
    return {f.name for f in dataclasses.fields(params)}


def _field(params: type, name: str) -> tuple[Any, Any]:
    """The pydantic annotation and default (a ``Field`` with the description) of field ``name``
    of the core dataclass ``params``."""
    info = param_info(params, name)
    field = next(f for f in dataclasses.fields(params) if f.name == name)
    annotation = _annotation(typing.get_type_hints(params)[name], info, f"{params.__name__}.{name}")
    return annotation, Field(default=field.default, description=info.describe())


def _annotation(tp: Any, info: ParamInfo, where: str) -> Any:
    """The mission type of a core field of type ``tp`` declared by ``info``."""
    if get_origin(tp) is tuple:
        items = get_args(tp)
        if info.ordered:
            if items != (float, float) or info.bounds:
                raise TypeError(f"{where}: an ordered pair is a tuple[float, float] without bounds")
            return Limits
        return tuple[tuple(_scalar(item, info, where) for item in items)]  # type: ignore[misc]
    if info.ordered:
        raise TypeError(f"{where}: only a pair can be ordered")
    return _scalar(tp, info, where)


def _scalar(tp: Any, info: ParamInfo, where: str) -> Any:
    bounds = tuple(info.bounds.items())
    if tp is float:
        named = _FINITE_FLOATS.get(bounds)
        return named if named is not None else Annotated[float, Field(**info.bounds), NO_BOOL]
    if tp is int:
        named = _NAMED_INTS.get(bounds)
        return named if named is not None else Annotated[int, Field(**info.bounds), NO_BOOL]
    if (tp is bool or get_origin(tp) is Literal) and not bounds:
        return tp
    raise TypeError(f"{where}: no mission type for {tp!r} with bounds {info.bounds}")
