"""The leaves a mission's behavior tree may name, and their parameters (§II-A, Fig. 2).

This is pure data: the mission loader checks a tree against it (unknown names, wrong kinds, bad
parameters are mission errors), ``pfctl bt show`` lists it, and
:mod:`pfctl.core.behavior.leaves` gives each name its py_trees behaviour. A leaf's parameter
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


def _p(name: str, default: float | None, doc: str, **kw: Any) -> ParamSpec:
    return ParamSpec(name, kw.pop("kind", float), default, doc, **kw)


LEAF_SPECS: dict[str, LeafSpec] = {
    spec.name: spec
    for spec in (
        # -- conditions ---------------------------------------------------------------------
        LeafSpec(
            "target_visible",
            "condition",
            "The identified target's track was detected (laser legs or camera) within max_age s.",
            (_p("max_age", 0.5, "seconds since the target's last detection", minimum=0.0),),
        ),
        LeafSpec(
            "target_tracked",
            "condition",
            "The tracker still holds the identified target's track (detected or coasting).",
        ),
        LeafSpec(
            "target_lost_for",
            "condition",
            "The target has not been visible for at least `seconds` (or was never seen).",
            (
                _p(
                    "seconds",
                    None,
                    "how long the target has been out of sight",
                    minimum=0.0,
                    required=True,
                ),
            ),
        ),
        LeafSpec(
            "prediction_available",
            "condition",
            "A prediction of where the lost target went exists and has not been looked at yet.",
        ),
        LeafSpec(
            "near_target",
            "condition",
            "The robot is within `distance` metres of the target's estimated position.",
            (_p("distance", 1.0, "metres", minimum=0.0),),
        ),
        # -- actions --------------------------------------------------------------------------
        LeafSpec(
            "follow_target",
            "action",
            "Drive after the target (TURN + GO_STRAIGHT when the line of sight is free, else "
            "MOVE_BASE), keeping the following distance; running while there is a target.",
            (
                _p(
                    "distance",
                    None,
                    "following distance, m (default control.following_distance)",
                    minimum=0.3,
                ),
            ),
        ),
        LeafSpec(
            "gaze_at_target",
            "action",
            "Point the head at the target; running while there is one, failure otherwise.",
        ),
        LeafSpec(
            "go_to_prediction",
            "action",
            "Navigate to where the prediction says the target went; success on arrival, failure "
            "when there is no prediction or no way there.",
            (_p("tolerance", 0.5, "arrival distance, m", minimum=0.05),),
        ),
        LeafSpec(
            "look_around",
            "action",
            "Sweep the head (and turn the base) to look for the target; success when the target "
            "is seen, failure when the sweep ends without it (the prediction is used up).",
            (
                _p("seconds", 8.0, "length of the sweep, s", minimum=0.5),
                _p("pan", 1.4, "head pan to either side, rad", minimum=0.0, maximum=3.0),
                _p("turn", True, "also turn the base once around", kind=bool),
            ),
        ),
        LeafSpec(
            "waypoint_search",
            "action",
            "Algorithm 1: go to the best frontier toward the heading region, look, repeat; "
            "running until the target is found, failure when nothing is left to search.",
            (_p("tolerance", 0.4, "arrival distance at a way-point, m", minimum=0.05),),
        ),
        LeafSpec(
            "go_to_last_seen",
            "action",
            "Navigate to where the target was last seen; success on arrival (and from then on "
            "for that sighting), failure when it was never seen or there is no way there.",
            (_p("tolerance", 0.5, "arrival distance, m", minimum=0.05),),
        ),
        LeafSpec("stop", "action", "Stop the base; success."),
    )
}


def leaf_spec(kind: str, name: str) -> LeafSpec:
    """The spec of leaf ``name`` of ``kind``; ValueError naming the known leaves otherwise."""
    spec = LEAF_SPECS.get(name)
    if spec is None or spec.kind != kind:
        names = ", ".join(n for n, s in LEAF_SPECS.items() if s.kind == kind)
        raise ValueError(f"unknown {kind} {name!r} (known: {names})")
    return spec


__all__ = ["LEAF_SPECS", "LeafKind", "LeafSpec", "ParamSpec", "leaf_spec"]
