"""The behavior tree of a mission (``behavior.tree``, §II-A, Fig. 2): one model per node kind.

A node is a mapping with exactly one kind key: a composite (``sequence``, ``fallback``,
``parallel``), a decorator (``inverter``, ``retry``, ``timeout``, ``repeat``, ``force_success``,
``force_failure``) or a leaf (``condition``/``action`` naming a registered leaf, with its
``params`` checked against :mod:`pfctl.core.behavior.registry`). :func:`paper_tree` is Fig. 2.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from typing import Annotated, Any, Literal

from pydantic import Field, model_validator

from pfctl.core.behavior.registry import leaf_spec
from pfctl.mission.errors import field_error, value_error
from pfctl.mission.types import Count, Identifier, MissionModel, Positive

COMPOSITES = ("sequence", "fallback", "parallel")
DECORATORS = ("inverter", "retry", "timeout", "repeat", "force_success", "force_failure")
LEAVES = ("condition", "action")
NODE_KINDS = COMPOSITES + DECORATORS + LEAVES


class Composite(MissionModel):
    """A sequence or fallback: an optional name and a non-empty list of children."""

    name: str | None = None
    children: Annotated[tuple[TreeNode, ...], Field(min_length=1)]
    memory: bool = False
    """False (reactive): every tick starts again at the first child, so a condition is checked
    again while a later action runs; True: a tick resumes at the child that was running."""


class Parallel(Composite):
    """Ticks every child each tick; succeeds when all (or one) succeed."""

    policy: Literal["success_on_all", "success_on_one"] = "success_on_all"


class Decorator(MissionModel):
    """A decorator (inverter, force_success, force_failure): one child."""

    name: str | None = None
    child: TreeNode


class Retry(Decorator):
    """Re-run the child after a failure, up to ``attempts`` times in all."""

    attempts: Count


class Timeout(Decorator):
    """Fail the child if it is still running after ``seconds``."""

    seconds: Positive


class Repeat(Decorator):
    """Run the child ``count`` times while it succeeds."""

    count: Count


class TreeNode(MissionModel):
    """One behavior-tree node (Fig. 2): exactly one of the keys below, plus ``params`` on leaves.

    Composites ``sequence`` / ``fallback`` / ``parallel`` hold ``{name?, children: [...]}``;
    decorators ``inverter`` / ``retry`` / ``timeout`` / ``repeat`` / ``force_success`` /
    ``force_failure`` hold ``{name?, child, ...}``; leaves are ``{condition: NAME, params?}`` or
    ``{action: NAME, params?}`` with NAME a snake_case identifier.
    """

    sequence: Composite | None = None
    fallback: Composite | None = None
    parallel: Parallel | None = None
    inverter: Decorator | None = None
    retry: Retry | None = None
    timeout: Timeout | None = None
    repeat: Repeat | None = None
    force_success: Decorator | None = None
    force_failure: Decorator | None = None
    condition: Identifier | None = None
    action: Identifier | None = None
    params: dict[str, Any] = Field(default_factory=dict)

    @model_validator(mode="before")
    @classmethod
    def _exactly_one_kind(cls, data: Any) -> Any:
        """A node is a mapping with exactly one kind key; ``params`` only on leaves."""
        kinds_text = ", ".join(NODE_KINDS)
        if not isinstance(data, Mapping):
            got = repr(data) if isinstance(data, (str, int, float)) else type(data).__name__
            raise value_error(
                "tree_node", f"expected a tree node, a mapping with one of {kinds_text}, got {got}"
            )
        if any(key not in NODE_KINDS and key != "params" for key in data):
            return data  # pydantic reports the unknown key, with the allowed ones
        kinds = [key for key in data if key in NODE_KINDS]
        if len(kinds) != 1:
            got = " and ".join(repr(k) for k in kinds) if kinds else "none"
            raise value_error(
                "tree_node", f"expected exactly one of {kinds_text} in a tree node, got {got}"
            )
        if "params" in data and kinds[0] not in LEAVES:
            raise field_error(
                ("params",), f"params belong to a condition or action leaf, not {kinds[0]}"
            )
        return data

    @model_validator(mode="after")
    def _known_leaf(self) -> TreeNode:
        """A leaf names a registered condition or action, with valid parameters."""
        if self.condition is None and self.action is None:
            return self
        kind = "condition" if self.condition is not None else "action"
        try:
            spec = leaf_spec(kind, str(self.body))
        except ValueError as err:
            raise field_error((kind,), str(err)) from None
        try:
            spec.resolve(self.params)
        except ValueError as err:
            key, _, reason = str(err).partition(": ")
            raise field_error(("params", key), reason) from None
        return self

    @property
    def kind(self) -> str:
        """Which node this is: one of :data:`NODE_KINDS`."""
        for kind in NODE_KINDS:
            if getattr(self, kind) is not None:
                return kind
        raise AssertionError("a validated TreeNode always has a kind")  # pragma: no cover

    @property
    def body(self) -> Composite | Decorator | str:
        """The value under the kind key: the composite/decorator model, or the leaf's name."""
        return getattr(self, self.kind)  # type: ignore[no-any-return]

    @property
    def is_leaf(self) -> bool:
        """True for condition and action leaves."""
        return self.kind in LEAVES

    @property
    def label(self) -> str:
        """A short human name: the leaf's name, else the node's ``name``, else its kind."""
        body = self.body
        if isinstance(body, str):
            return body
        return body.name or self.kind

    @property
    def children(self) -> tuple[TreeNode, ...]:
        """The child nodes: a composite's children, a decorator's child, none for a leaf."""
        body = self.body
        if isinstance(body, Composite):
            return body.children
        if isinstance(body, Decorator):
            return (body.child,)
        return ()

    def walk(self) -> Iterator[TreeNode]:
        """This node and all below it, depth first, in order."""
        yield self
        for child in self.children:
            yield from child.walk()

    def leaf_names(self) -> set[str]:
        """The names of the condition and action leaves in this subtree."""
        return {str(node.body) for node in self.walk() if node.is_leaf}

    def size(self) -> int:
        """The number of nodes in this subtree, this one included."""
        return sum(1 for _ in self.walk())


Composite.model_rebuild()
Parallel.model_rebuild()
Decorator.model_rebuild()
Retry.model_rebuild()
Timeout.model_rebuild()
Repeat.model_rebuild()
TreeNode.model_rebuild()


def paper_tree() -> TreeNode:
    """Fig. 2 of the paper: follow while visible, else predict and look, else way-point search."""
    return TreeNode.model_validate(
        {
            "fallback": {
                "name": "root",
                "children": [
                    {
                        "sequence": {
                            "name": "follow",
                            "children": [
                                {"condition": "target_visible"},
                                {"action": "follow_target"},
                            ],
                        }
                    },
                    {
                        "fallback": {
                            "name": "find",
                            "children": [
                                {
                                    "sequence": {
                                        "name": "predict_and_look",
                                        "children": [
                                            {"condition": "prediction_available"},
                                            {"action": "go_to_prediction"},
                                            {"action": "look_around"},
                                        ],
                                    }
                                },
                                {"action": "waypoint_search"},
                            ],
                        }
                    },
                ],
            }
        }
    )
