"""The behavior tree built from the mission's layout (§II-A, Fig. 2 of Kim et al.).

A behavior tree is ticked at a fixed rate from its root; every node answers each tick with
RUNNING, SUCCESS or FAILURE (§II-A). Control-flow nodes decide which children are ticked:

- a **fallback** (``?``) ticks its children in order until one does not fail: it succeeds or runs
  with the first child that succeeds or runs, and fails only when every child failed;
- a **sequence** (``→``) ticks its children in order until one does not succeed: it fails or runs
  with the first child that fails or runs, and succeeds only when every child succeeded;
- a **parallel** (``⇉``) ticks every child each tick; it fails as soon as one child fails and
  succeeds when all children (``success_on_all``) or one child (``success_on_one``) succeeded;
- a **decorator** has one child and changes its status or how often it runs (inverter,
  force_success, force_failure, retry, timeout, repeat);
- **leaves** are conditions (answer SUCCESS or FAILURE at once: "is the target visible?") and
  actions (RUNNING while they work: "follow the target").

Fig. 2 is two fallbacks and two sequences: *follow* while the target is visible, else *find* it:
predict where it went, go there and look around, else search way-points (Algorithm 1).

The layout is data (as in Nav2): plain nested mappings in the mission's shape, e.g.
``mission.behavior.tree.model_dump(exclude_none=True)``::

    {"fallback": {"name": "root", "children": [
        {"sequence": {"name": "follow", "memory": False, "children": [
            {"condition": "target_visible", "params": {"max_age": 0.5}},
            {"action": "follow_target"}]}},
        {"action": "waypoint_search"}]}}

:func:`parse_layout` checks such a layout against the leaf registry
(:mod:`pfctl.core.behavior.registry`) and gives a :class:`LayoutNode` tree with every leaf's
parameters resolved; :func:`build_tree` turns it into py_trees behaviours, asking a *factory* for
each leaf. Composites without ``memory`` are *reactive*: they start from their first child on
every tick, so a condition is re-checked each tick and a running lower-priority action is stopped
(``terminate(INVALID)``) when a higher-priority branch takes over — the paper's robot stops
searching the moment the target is visible again.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import py_trees
from py_trees.common import ParallelPolicy, Status

from pfctl.core.behavior.registry import leaf_spec

__all__ = [
    "COMPOSITES",
    "DECORATORS",
    "LEAVES",
    "NODE_KINDS",
    "Clock",
    "EpisodeTimeout",
    "LayoutNode",
    "LeafFactory",
    "build_tree",
    "parse_layout",
]

COMPOSITES = ("sequence", "fallback", "parallel")
DECORATORS = ("inverter", "force_success", "force_failure", "retry", "timeout", "repeat")
LEAVES = ("condition", "action")
NODE_KINDS = COMPOSITES + DECORATORS + LEAVES
POLICIES = ("success_on_all", "success_on_one")

#: The one numeric option of each parametrised decorator, and its type.
_DECORATOR_OPTIONS: dict[str, tuple[str, type]] = {
    "retry": ("attempts", int),
    "timeout": ("seconds", float),
    "repeat": ("count", int),
}

Clock = Callable[[], float]
"""The time in seconds (simulated or wall), as :func:`time.monotonic` gives it."""

LeafFactory = Callable[[str, str, dict[str, Any]], py_trees.behaviour.Behaviour]
"""``factory(kind, name, params)``: the behaviour of a condition or action leaf; ``params`` are
resolved (every parameter present, defaults filled in; None means "the mission's value")."""


@dataclass(frozen=True)
class LayoutNode:
    """One checked node of a layout: what :func:`build_tree` and the drawings work from."""

    kind: str
    """One of :data:`NODE_KINDS`."""
    label: str
    """The leaf's name for leaves; else the node's ``name``, or its kind when it has none."""
    path: str
    """Where the node is, e.g. ``behavior.tree.fallback.children[1]``."""
    children: tuple[LayoutNode, ...] = ()
    name: str | None = None
    """The ``name`` given in the layout (composites and decorators), if any."""
    memory: bool = False
    """Sequence and fallback: resume at the running child instead of starting over each tick."""
    policy: str = "success_on_all"
    """Parallel: ``success_on_all`` or ``success_on_one``."""
    value: float | int | None = None
    """retry: attempts; timeout: seconds; repeat: count."""
    params: dict[str, Any] = field(default_factory=dict)
    """Leaves: every parameter, resolved against the registry (None: the mission's value)."""

    @property
    def is_leaf(self) -> bool:
        """True for conditions and actions."""
        return self.kind in LEAVES

    def walk(self) -> list[LayoutNode]:
        """This node and every node below it, depth first, in order."""
        nodes = [self]
        for child in self.children:
            nodes.extend(child.walk())
        return nodes


def _kind_of(node: Any, path: str) -> str:
    """The single kind key of a node mapping; ValueError naming ``path`` otherwise."""
    if not isinstance(node, Mapping):
        raise ValueError(f"{path}: expected a tree node (a mapping), got {type(node).__name__}")
    kinds = [key for key in node if key in NODE_KINDS]
    unknown = [key for key in node if key not in NODE_KINDS and key != "params"]
    if unknown:
        raise ValueError(
            f"{path}.{unknown[0]}: unknown key (expected one of: {', '.join(NODE_KINDS)}, params)"
        )
    if len(kinds) != 1:
        got = " and ".join(repr(k) for k in kinds) if kinds else "none"
        raise ValueError(f"{path}: expected exactly one of {', '.join(NODE_KINDS)}, got {got}")
    kind = kinds[0]
    if kind not in LEAVES and node.get("params"):
        raise ValueError(f"{path}.params: params belong to a condition or action, not {kind}")
    return kind


def _body(node: Mapping[str, Any], kind: str, path: str, allowed: Sequence[str]) -> dict[str, Any]:
    """The mapping under a composite's or decorator's kind key, with only ``allowed`` keys."""
    body = node[kind]
    if not isinstance(body, Mapping):
        raise ValueError(f"{path}: expected a mapping, got {type(body).__name__}")
    for key in body:
        if key not in allowed:
            raise ValueError(f"{path}.{key}: unknown key (expected one of: {', '.join(allowed)})")
    name = body.get("name")
    if name is not None and not isinstance(name, str):
        raise ValueError(f"{path}.name: expected a string, got {name!r}")
    return dict(body)


def _number(body: Mapping[str, Any], key: str, kind: type, path: str) -> float | int:
    """A decorator's positive count (``int``) or duration (``float``)."""
    if key not in body:
        raise ValueError(f"{path}.{key}: required key is missing")
    value = body[key]
    ok = isinstance(value, (int, float)) and not isinstance(value, bool)
    if ok and kind is int:
        ok = float(value).is_integer() and value >= 1
    elif ok:
        ok = value > 0 and value != float("inf")
    if not ok:
        what = "a whole number >= 1" if kind is int else "a finite number > 0"
        raise ValueError(f"{path}.{key}: expected {what}, got {value!r}")
    return int(value) if kind is int else float(value)


def parse_layout(layout: Mapping[str, Any], where: str = "behavior.tree") -> LayoutNode:
    """Check a layout and resolve its leaves' parameters; ValueError ``"<path>: <reason>"``.

    ``where`` is the path of the root in messages, e.g. an unknown condition deep in the tree
    reads ``behavior.tree.fallback.children[1].sequence.children[0]: unknown condition 'foo'
    (known: ...)`` and a bad parameter ``...children[0].params.max_age: expected at least 0,
    got -1``. A missing ``memory`` is False; ``params`` may be absent or empty.
    """
    kind = _kind_of(layout, where)
    if kind in LEAVES:
        name = layout[kind]
        if not isinstance(name, str):
            raise ValueError(f"{where}.{kind}: expected a leaf name, got {name!r}")
        params = layout.get("params") or {}
        if not isinstance(params, Mapping):
            raise ValueError(f"{where}.params: expected a mapping, got {type(params).__name__}")
        try:
            spec = leaf_spec(kind, name)
        except ValueError as err:
            raise ValueError(f"{where}: {err}") from None
        try:
            resolved = spec.resolve(params)
        except ValueError as err:
            key, _, reason = str(err).partition(": ")
            raise ValueError(f"{where}.params.{key}: {reason}") from None
        return LayoutNode(kind=kind, label=name, path=where, params=resolved)

    here = f"{where}.{kind}"
    if kind in COMPOSITES:
        extra = ("policy",) if kind == "parallel" else ("memory",)
        body = _body(layout, kind, here, ("name", "children", *extra))
        children = body.get("children")
        if not isinstance(children, Sequence) or isinstance(children, str) or not children:
            raise ValueError(f"{here}.children: expected a non-empty list of tree nodes")
        memory = body.get("memory", False)
        if not isinstance(memory, bool):
            raise ValueError(f"{here}.memory: expected true or false, got {memory!r}")
        policy = body.get("policy", "success_on_all")
        if policy not in POLICIES:
            allowed = ", ".join(POLICIES)
            raise ValueError(f"{here}.policy: expected one of {allowed}, got {policy!r}")
        return LayoutNode(
            kind=kind,
            label=body.get("name") or kind,
            path=where,
            children=tuple(
                parse_layout(child, f"{here}.children[{i}]") for i, child in enumerate(children)
            ),
            name=body.get("name"),
            memory=memory,
            policy=policy,
        )

    option = _DECORATOR_OPTIONS.get(kind)
    body = _body(layout, kind, here, ("name", "child", *((option[0],) if option else ())))
    if "child" not in body:
        raise ValueError(f"{here}.child: required key is missing")
    return LayoutNode(
        kind=kind,
        label=body.get("name") or kind,
        path=where,
        children=(parse_layout(body["child"], f"{here}.child"),),
        name=body.get("name"),
        value=_number(body, option[0], option[1], here) if option else None,
    )


class EpisodeTimeout(py_trees.decorators.Decorator):
    """Fail the child when it has been RUNNING for ``seconds`` on ``clock`` (a decorator, §II-A).

    py_trees' own ``Timeout`` reads the wall clock; this one reads the episode's clock (the
    simulated time in the simulator, which runs faster or slower than real time; ROS time on the
    robot). The time is measured from the tick on
    which the child (re)starts, i.e. the decorator's ``initialise``. On the first tick the child
    is still RUNNING at ``clock() - start >= seconds`` the child is stopped (its ``terminate``
    sees INVALID, so an action cancels its goal) and the decorator returns FAILURE. A child that
    finishes in time passes its SUCCESS or FAILURE through. After a timeout, the next tick starts
    the child afresh with a new deadline.
    """

    def __init__(
        self, name: str, child: py_trees.behaviour.Behaviour, seconds: float, clock: Clock
    ) -> None:
        super().__init__(name=name, child=child)
        self.seconds = float(seconds)
        self.clock = clock
        self.started = 0.0

    def initialise(self) -> None:
        """Start the deadline: the child is being (re)started on this tick."""
        self.started = self.clock()
        self.feedback_message = ""

    def update(self) -> Status:
        """The child's status, or FAILURE (child stopped) once its time is up."""
        status = self.decorated.status
        if status == Status.RUNNING:
            elapsed = self.clock() - self.started
            if elapsed >= self.seconds:
                self.feedback_message = f"timed out after {elapsed:g} s (limit {self.seconds:g} s)"
                self.decorated.stop(Status.INVALID)
                return Status.FAILURE
            self.feedback_message = f"{self.seconds - elapsed:g} s left"
        else:
            self.feedback_message = "child finished before the timeout"
        return status


def _display_name(node: LayoutNode) -> str:
    """A readable py_trees name: the node's name, or its kind with its option."""
    if node.name:
        return node.name
    if node.kind == "retry":
        return f"retry ×{node.value}"
    if node.kind == "repeat":
        return f"repeat ×{node.value}"
    if node.kind == "timeout":
        return f"timeout {node.value:g} s"
    return node.kind


def _build(node: LayoutNode, factory: LeafFactory, clock: Clock) -> py_trees.behaviour.Behaviour:
    if node.is_leaf:
        try:
            leaf = factory(node.kind, node.label, dict(node.params))
        except ValueError as err:
            raise ValueError(f"{node.path}: {err}") from None
        if not isinstance(leaf, py_trees.behaviour.Behaviour):
            raise TypeError(
                f"{node.path}: the leaf factory returned {type(leaf).__name__}, not a Behaviour"
            )
        return leaf
    children = [_build(child, factory, clock) for child in node.children]
    name = _display_name(node)
    if node.kind == "sequence":
        return py_trees.composites.Sequence(name, memory=node.memory, children=children)
    if node.kind == "fallback":
        return py_trees.composites.Selector(name, memory=node.memory, children=children)
    if node.kind == "parallel":
        policy: ParallelPolicy.Base = (
            ParallelPolicy.SuccessOnOne()
            if node.policy == "success_on_one"
            else ParallelPolicy.SuccessOnAll()
        )
        return py_trees.composites.Parallel(name, policy=policy, children=children)
    (child,) = children
    if node.kind == "inverter":
        return py_trees.decorators.Inverter(name=name, child=child)
    if node.kind == "force_success":
        return py_trees.decorators.FailureIsSuccess(name=name, child=child)
    if node.kind == "force_failure":
        return py_trees.decorators.SuccessIsFailure(name=name, child=child)
    if node.kind == "retry":
        # py_trees' Retry fails on the num_failures-th failure: at most that many runs in all.
        return py_trees.decorators.Retry(name=name, child=child, num_failures=int(node.value or 1))
    if node.kind == "repeat":
        # py_trees' Repeat succeeds on the num_success-th success and fails on any failure.
        return py_trees.decorators.Repeat(name=name, child=child, num_success=int(node.value or 1))
    if node.kind == "timeout":
        return EpisodeTimeout(name=name, child=child, seconds=float(node.value or 0.0), clock=clock)
    raise AssertionError(f"unhandled node kind {node.kind!r}")  # pragma: no cover


def build_tree(
    layout: Mapping[str, Any],
    factory: LeafFactory,
    clock: Clock,
    *,
    where: str = "behavior.tree",
) -> py_trees.behaviour.Behaviour:
    """The root behaviour of the tree ``layout`` describes (§II-A, Fig. 2).

    ``layout`` is the tree as plain mappings in the mission's shape (see the module docstring);
    ``factory(kind, name, params)`` makes each condition/action leaf from its resolved
    parameters; ``clock()`` is the (simulated) time that ``timeout`` decorators measure.

    The mapping to py_trees: sequence → ``Sequence(memory=...)``, fallback →
    ``Selector(memory=...)`` (``memory`` False unless given: reactive), parallel →
    ``Parallel(SuccessOnAll() | SuccessOnOne())``, inverter → ``Inverter``, force_success →
    ``FailureIsSuccess``, force_failure → ``SuccessIsFailure`` (RUNNING stays RUNNING in both),
    retry → ``Retry(num_failures=attempts)`` (a failed run is retried on the next tick, at most
    ``attempts`` runs in all), repeat → ``Repeat(num_success=count)`` (one run per tick while it
    succeeds), timeout → :class:`EpisodeTimeout`.

    Raises ValueError ``"<path>: <reason>"`` for a malformed layout, an unknown leaf or a bad
    parameter (see :func:`parse_layout`), and for a ValueError the factory raises.
    """
    return _build(parse_layout(layout, where), factory, clock)
