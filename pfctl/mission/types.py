"""The value types of mission fields, and the base of every mission model.

Numbers reject YAML booleans (``yes`` must not silently become 1); :data:`Number`,
:data:`Positive` and :data:`NonNegative` are finite; a :data:`Polygon` is simple with at least
three distinct points; :data:`Limits` are ``[low, high]`` pairs with ``low < high``. Every model
derives from :class:`MissionModel`: unknown keys are errors, values are immutable.
"""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Annotated, Any

import shapely
from pydantic import AfterValidator, BaseModel, BeforeValidator, ConfigDict, Field, ValidationInfo
from shapely.validation import explain_validity

from pfctl.mission.errors import value_error

#: Geometric tolerance of the semantic checks, metres (and m² for areas).
TOLERANCE = 1e-6


def _reject_bool(value: Any) -> Any:
    """YAML's ``yes``/``true`` must not silently become 1: numbers reject booleans."""
    if isinstance(value, bool):
        raise value_error(
            "bool_not_number", f"expected a number, got the boolean {str(value).lower()}"
        )
    return value


def _snake_case(value: str) -> str:
    """Behavior-tree leaf names are snake_case identifiers (``target_visible``)."""
    if not re.fullmatch(r"[a-z][a-z0-9_]*", value):
        raise value_error(
            "snake_case", f"expected a snake_case name such as 'target_visible', got {value!r}"
        )
    return value


NO_BOOL = BeforeValidator(_reject_bool)
# Constraints come before the validator so that pydantic folds them into the number schema
# (and the JSON Schema says exclusiveMinimum, not an unknown "gt").
Number = Annotated[float, Field(allow_inf_nan=False), NO_BOOL]
"""A finite float; booleans are rejected."""
Positive = Annotated[float, Field(gt=0, allow_inf_nan=False), NO_BOOL]
NonNegative = Annotated[float, Field(ge=0, allow_inf_nan=False), NO_BOOL]
Probability = Annotated[float, Field(gt=0, lt=1), NO_BOOL]
"""A probability in the open interval (0, 1)."""
UnitInterval = Annotated[float, Field(ge=0, le=1), NO_BOOL]
Integer = Annotated[int, NO_BOOL]
SEED_MAX = 2**32 - 1
"""The largest seed: numpy's and scikit-learn's seeds are 32-bit unsigned."""
Seed = Annotated[int, Field(ge=0, le=SEED_MAX), NO_BOOL]
"""A seed of the random streams: 0 to :data:`SEED_MAX`."""
Count = Annotated[int, Field(ge=1), NO_BOOL]
Name = Annotated[str, Field(min_length=1)]
Identifier = Annotated[
    str, AfterValidator(_snake_case), Field(json_schema_extra={"pattern": "^[a-z][a-z0-9_]*$"})
]
Point = tuple[Number, Number]
"""An ``[x, y]`` point in the map frame, metres."""
Channel = Annotated[int, Field(ge=0, le=255), NO_BOOL]
RGB = tuple[Channel, Channel, Channel]


def fmt_point(p: Sequence[float]) -> str:
    """``(x, y)`` as messages write a point: ``(4, 1.5)``."""
    return f"({p[0]:g}, {p[1]:g})"


def _check_polygon(points: tuple[Point, ...]) -> tuple[Point, ...]:
    """A simple polygon of >= 3 distinct points; a repeated closing point is dropped."""
    pts = list(points)
    if len(pts) >= 2 and pts[0] == pts[-1]:
        pts.pop()
    distinct = len(set(pts))
    if distinct < 3:
        raise value_error(
            "polygon_points",
            f"expected a polygon of at least 3 distinct [x, y] points, got {distinct}",
        )
    if shapely.LineString(pts).convex_hull.area <= TOLERANCE**2:
        raise value_error(
            "polygon_area", "expected a polygon with an area, but its points are collinear"
        )
    polygon = shapely.Polygon(pts)
    if not polygon.is_valid:
        reason = explain_validity(polygon)
        match = re.fullmatch(r"(.*?)\[\s*(\S+)\s+(\S+)\s*\]", reason)
        if match:
            where = fmt_point((float(match.group(2)), float(match.group(3))))
            reason = f"{match.group(1).lower()} at {where}"
        raise value_error(
            "polygon_invalid", f"expected a simple polygon (edges that do not cross), got {reason}"
        )
    return tuple(pts)


Polygon = Annotated[tuple[Point, ...], AfterValidator(_check_polygon)]
"""A simple polygon: >= 3 distinct points, not self-intersecting; closing point optional."""


def _check_limits(value: tuple[float, float]) -> tuple[float, float]:
    """A ``[low, high]`` pair must have ``low < high``."""
    if value[0] >= value[1]:
        raise value_error(
            "limits_order",
            f"expected [low, high] with low < high, got [{value[0]:g}, {value[1]:g}]",
        )
    return value


Limits = Annotated[tuple[Number, Number], AfterValidator(_check_limits)]
"""A ``[low, high]`` joint-limit pair in radians, ``low < high``."""


def existing_file(value: Path, info: ValidationInfo, what: str) -> Path:
    """``value`` resolved against the mission file's folder; an error when it is no file."""
    context = info.context if isinstance(info.context, Mapping) else {}
    base = Path(context.get("base_dir", "."))
    path = value if value.is_absolute() else base / value
    if not path.is_file():
        raise value_error("file_missing", f"expected {what}, but {path} does not exist")
    return path.resolve()


class MissionModel(BaseModel):
    """Base of every mission model: unknown keys are errors, values are immutable."""

    model_config = ConfigDict(extra="forbid", frozen=True, use_attribute_docstrings=True)
