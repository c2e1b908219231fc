"""The leaves a mission's behavior tree may name, and their parameters (§II-A, Fig. 2).

Derived from the leaf classes of :mod:`pfctl.core.behavior.leaves`, each of which declares its
own :class:`~pfctl.core.behavior.spec.LeafSpec` (name, kind, what it does, parameters): the
mission loader checks a tree against it (unknown names, wrong kinds, bad parameters are mission
errors) and ``pfctl bt leaves`` lists it.
"""

from __future__ import annotations

from pfctl.core.behavior.leaves import LEAF_CLASSES
from pfctl.core.behavior.spec import LeafKind, LeafSpec, ParamSpec

#: Every leaf's spec by name, conditions first, in the order of :data:`LEAF_CLASSES`.
LEAF_SPECS: dict[str, LeafSpec] = {name: cls.spec for name, cls in LEAF_CLASSES.items()}


def leaf_spec(kind: str, name: str) -> LeafSpec:
    """The spec of leaf ``name`` of ``kind``; ValueError naming the known leaves otherwise."""
    spec = LEAF_SPECS.get(name)
    if spec is None or spec.kind != kind:
        names = ", ".join(n for n, s in LEAF_SPECS.items() if s.kind == kind)
        raise ValueError(f"unknown {kind} {name!r} (known: {names})")
    return spec


__all__ = ["LEAF_SPECS", "LeafKind", "LeafSpec", "ParamSpec", "leaf_spec"]
