"""How a leaf of the behavior tree declares itself: its name, kind, what it does and its
parameters (§II-A; Nav2's ``providedPorts()``).

Each leaf class of :mod:`pfctl.core.behavior.leaves` carries a :class:`LeafSpec` (its ``spec``);
the registry (:mod:`pfctl.core.behavior.registry`) is derived from those classes. A parameter's
``default`` of None means "the mission's value" (e.g. ``follow_target.distance`` falls back to
``control.following_distance``).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, Literal

LeafKind = Literal["condition", "action"]


@dataclass(frozen=True)
class ParamSpec:
    """One parameter of a leaf: a number (or flag) with a default and an allowed range."""

    name: str
    kind: type
    """``float``, ``int`` or ``bool``."""
    default: float | int | bool | None
    """None: required when ``required``, else the mission's value."""
    doc: str
    minimum: float | None = None
    """Inclusive lower bound."""
    maximum: float | None = None
    """Inclusive upper bound."""
    required: bool = False

    def check(self, value: Any) -> float | int | bool:
        """``value`` converted to the parameter's kind; ValueError with the reason otherwise."""
        if self.kind is bool:
            if not isinstance(value, bool):
                raise ValueError(f"expected true or false, got {value!r}")
            return value
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise ValueError(f"expected a number, got {value!r}")
        if self.kind is int and float(value) != int(value):
            raise ValueError(f"expected a whole number, got {value!r}")
        number: float | int = int(value) if self.kind is int else float(value)
        if number != number or number in (float("inf"), float("-inf")):
            raise ValueError(f"expected a finite number, got {value!r}")
        if self.minimum is not None and number < self.minimum:
            raise ValueError(f"expected at least {self.minimum:g}, got {value!r}")
        if self.maximum is not None and number > self.maximum:
            raise ValueError(f"expected at most {self.maximum:g}, got {value!r}")
        return number


def param(
    name: str,
    default: float | bool | None,
    doc: str,
    *,
    kind: type = float,
    minimum: float | None = None,
    maximum: float | None = None,
    required: bool = False,
) -> ParamSpec:
    """A leaf parameter, a ``float`` unless ``kind`` says otherwise."""
    return ParamSpec(name, kind, default, doc, minimum, maximum, required)


@dataclass(frozen=True)
class LeafSpec:
    """A condition or action leaf: its name, what it does and its parameters."""

    name: str
    kind: LeafKind
    doc: str
    params: tuple[ParamSpec, ...] = ()

    def resolve(self, params: Mapping[str, Any]) -> dict[str, Any]:
        """All parameters with defaults filled in; ValueError ``"<name>: <reason>"`` on an
        unknown, missing or bad one."""
        known = {p.name: p for p in self.params}
        for key in params:
            if key not in known:
                allowed = ", ".join(known) or "none"
                raise ValueError(f"{key}: unknown parameter of {self.name} (allowed: {allowed})")
        out: dict[str, Any] = {}
        for spec in self.params:
            if spec.name in params:
                try:
                    out[spec.name] = spec.check(params[spec.name])
                except ValueError as err:
                    raise ValueError(f"{spec.name}: {err}") from None
            elif spec.required:
                raise ValueError(f"{spec.name}: required parameter of {self.name} is missing")
            else:
                out[spec.name] = spec.default
        return out


__all__ = ["LeafKind", "LeafSpec", "ParamSpec", "param"]
