"""A parameter declared once: default, meaning, unit and bounds, on the core field that holds it.

The core's parameter classes are frozen dataclasses. Each field a mission may set is declared
with :func:`param`, the scikit-learn way (parameters declared once, in the class)::

    @dataclass(frozen=True)
    class TrackerParams:
        gate: float = param(9.21, "Squared Mahalanobis gate (χ², 2 dof, 99 %).", gt=0)

Everything else is derived from that declaration: the mission's YAML field (its type, default and
bounds, and the meaning and unit users read in ``pfctl mission schema``) and the building of the
dataclass from a validated mission section (``pfctl.mission.params``). The bounds are the values
a mission may give; a class that needs more checks makes them itself (``__post_init__``).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

__all__ = ["ParamInfo", "param", "param_info"]

_KEY = "pfctl.param"
"""Where :func:`param` keeps its :class:`ParamInfo` in a field's metadata."""


@dataclass(frozen=True)
class ParamInfo:
    """What a parameter means and which values it takes (:func:`param`)."""

    doc: str
    """What the parameter is and what it does, in a sentence or two."""
    unit: str | None = None
    """SI unit (``m``, ``s``, ``rad/s``, ...); None for a count, a ratio or a choice."""
    ge: float | None = None
    """Inclusive lower bound (of each item, for a tuple)."""
    gt: float | None = None
    """Exclusive lower bound (of each item, for a tuple)."""
    le: float | None = None
    """Inclusive upper bound (of each item, for a tuple)."""
    lt: float | None = None
    """Exclusive upper bound (of each item, for a tuple)."""
    ordered: bool = False
    """A ``(low, high)`` pair with ``low < high``."""

    @property
    def bounds(self) -> dict[str, float]:
        """The bounds that are set, by name (``{"gt": 0}``)."""
        named = {"ge": self.ge, "gt": self.gt, "le": self.le, "lt": self.lt}
        return {k: v for k, v in named.items() if v is not None}

    def describe(self) -> str:
        """The meaning with its unit, as users read it: ``"Std of a laser position. Unit: m."``."""
        return f"{self.doc} Unit: {self.unit}." if self.unit else self.doc


def param(
    default: Any,
    doc: str,
    *,
    unit: str | None = None,
    ge: float | None = None,
    gt: float | None = None,
    le: float | None = None,
    lt: float | None = None,
    ordered: bool = False,
) -> Any:
    """A dataclass field with ``default`` that declares a parameter (:class:`ParamInfo`).

    ``doc`` says what the parameter means (no measured figures or history: it is what users read),
    ``unit`` its SI unit, ``ge``/``gt``/``le``/``lt`` the values it may take, ``ordered`` that a
    pair is ``(low, high)`` with ``low < high``.
    """
    info = ParamInfo(doc, unit, ge, gt, le, lt, ordered)
    return dataclasses.field(default=default, metadata={_KEY: info})


def param_info(params: type, name: str) -> ParamInfo:
    """The declaration of field ``name`` of dataclass ``params``; KeyError when it has none."""
    for f in dataclasses.fields(params):
        if f.name == name and _KEY in f.metadata:
            return f.metadata[_KEY]  # type: ignore[no-any-return]
    raise KeyError(f"{params.__name__}.{name} is not declared with param()")
