"""The JSON Schema of a mission file (``pfctl mission schema``)."""

from __future__ import annotations

from typing import Any

from pfctl.mission.sections import Mission


def dump_json_schema() -> dict[str, Any]:
    """The JSON Schema of a mission file (what ``pfctl mission schema`` prints)."""
    return Mission.model_json_schema()
