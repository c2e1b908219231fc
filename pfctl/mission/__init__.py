"""The mission YAML boundary (DESIGN.md): section models, tree-node models, loading (``extends``,
``include``), errors with file:line, round-trip editing (``map annotate``) and the JSON Schema."""

from pfctl.mission.sections import *  # noqa: F403
from pfctl.mission.sections import __all__ as __all__
