"""The oracle baseline's privileged input: the simulator's truth of where the target is.

DESIGN.md keeps ground truth apart from what the follower observes. The oracle baseline
(``oracle_search``, issue 22) is the one named exception, and this module is the one place that
hands the truth over: only when the mission's tree names a privileged leaf
(:data:`~pfctl.core.behavior.leaves.PRIVILEGED_LEAVES`), only in the simulator, and only as the
target's position (:func:`true_target_reader`), into the blackboard key that leaf alone reads. A
tree with such a leaf is refused on the real robot (:func:`refuse_on_real_robot`).
"""

from __future__ import annotations

from collections.abc import Callable

from pfctl.core.behavior.leaves import PRIVILEGED_LEAVES
from pfctl.core.robot import GroundTruth
from pfctl.errors import UserError
from pfctl.mission import Mission


def privileged_leaves(mission: Mission) -> list[str]:
    """The privileged leaves the mission's tree names (sorted; empty for every other tree)."""
    return sorted(mission.behavior.tree.leaf_names() & set(PRIVILEGED_LEAVES))


def refuse_on_real_robot(mission: Mission, source: str) -> None:
    """UserError (one line, exit 2) if the mission's tree names a privileged leaf: there is no
    ground truth on the real robot."""
    names = privileged_leaves(mission)
    if names:
        raise UserError(
            f"{source}: behavior.tree: {names[0]} reads the simulator's ground truth "
            "(privileged, the oracle baseline): it runs only with --backend sim"
        )


def true_target_reader(
    truth: Callable[[], GroundTruth],
) -> Callable[[], tuple[float, float] | None]:
    """A reader of the target's true position (None when the truth has no target)."""

    def read() -> tuple[float, float] | None:
        target = next((p for p in truth().people if p.is_target), None)
        return None if target is None else (target.x, target.y)

    return read


__all__ = ["privileged_leaves", "refuse_on_real_robot", "true_target_reader"]
