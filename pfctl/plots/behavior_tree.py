"""Drawings of a behavior-tree layout (§II-A, Fig. 2): text, Graphviz DOT, PNG, BT.CPP XML.

Each function takes the layout as plain mappings in the mission's shape (see
:mod:`pfctl.core.behavior.tree`); no leaf behaviour is built, so a tree can be drawn without a
robot. The layout is checked first (:func:`pfctl.core.behavior.tree.parse_layout`), so a drawing
shows every leaf's resolved parameters, defaults included; a default of None ("the mission's
value", e.g. ``follow_target.distance`` is ``control.following_distance``) reads ``(mission)``.

The symbols are the usual ones of behaviour-tree figures such as the paper's Fig. 2: ``?``
fallback, ``→`` sequence, ``⇉`` parallel; decorators by name (``¬`` inverter, ``↻`` retry, ...);
conditions as ellipses and actions as boxes.

- :func:`ascii_tree`: an indented tree for the terminal;
- :func:`dot_tree`: Graphviz DOT text (``dot -Tsvg``);
- :func:`png_tree`: a PNG drawn by matplotlib (Agg), no Graphviz program needed;
- :func:`btcpp_xml`: BehaviorTree.CPP v4 XML that Groot2 opens, with a ``<TreeNodesModel>``
  declaring every leaf of the registry and its parameters as input ports.
"""

from __future__ import annotations

import io
import xml.etree.ElementTree as ET
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from pfctl.core.behavior.registry import LEAF_SPECS
from pfctl.core.behavior.tree import DECORATORS, LayoutNode, parse_layout

__all__ = ["SYMBOLS", "ascii_tree", "btcpp_xml", "dot_tree", "png_tree"]

#: The symbol of each composite and decorator kind.
SYMBOLS: dict[str, str] = {
    "fallback": "?",
    "sequence": "→",
    "parallel": "⇉",
    "inverter": "¬",
    "force_success": "✓",
    "force_failure": "✗",
    "retry": "↻",
    "timeout": "◷",
    "repeat": "⟳",
}

#: Fill colours of the PNG and DOT drawings.
COLORS: dict[str, str] = {
    "fallback": "#f6c85f",
    "sequence": "#8cc0eb",
    "parallel": "#a5d8a0",
    "decorator": "#d5c3ec",
    "condition": "#fff2b3",
    "action": "#f2f2f2",
}
EDGE_COLOR = "#4d4d4d"


def _value(value: Any) -> str:
    """A parameter value as it reads in a drawing: ``0.5``, ``true``, ``(mission)``."""
    if value is None:
        return "(mission)"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return f"{value:.12g}"
    return str(value)


def _params(node: LayoutNode) -> list[str]:
    return [f"{key}={_value(value)}" for key, value in node.params.items()]


def _option(node: LayoutNode) -> str:
    """What distinguishes a composite or decorator beyond its kind: memory, policy, count."""
    if node.kind in ("sequence", "fallback"):
        return "memory" if node.memory else ""
    if node.kind == "parallel":
        return "success on all" if node.policy == "success_on_all" else "success on one"
    if node.kind == "retry":
        return f"attempts={node.value}"
    if node.kind == "repeat":
        return f"count={node.value}"
    if node.kind == "timeout":
        return f"seconds={_value(node.value)}"
    return ""


def _kind_text(node: LayoutNode) -> str:
    """``fallback``, ``sequence, memory``, ``retry, attempts=3``."""
    option = _option(node)
    return f"{node.kind}, {option}" if option else node.kind


def _subtitle(node: LayoutNode) -> str:
    """What a composite or decorator's label does not say: its kind when it has a name (the
    label is then the name), and its option (``memory``, ``attempts=3``)."""
    return _kind_text(node) if node.name else _option(node)


# --------------------------------------------------------------------------------------------
# text


def _ascii_line(node: LayoutNode) -> str:
    if node.is_leaf:
        head = f"({node.label})" if node.kind == "condition" else f"[{node.label}]"
        params = _params(node)
        return f"{head} {' '.join(params)}" if params else head
    symbol = SYMBOLS[node.kind]
    head = f"<{symbol}> {node.label}" if node.kind in DECORATORS else f"[{symbol}] {node.label}"
    subtitle = _subtitle(node)
    return f"{head} ({subtitle})" if subtitle else head


def ascii_tree(layout: Mapping[str, Any]) -> str:
    """The tree as indented text, one node a line, ending in a newline::

        [?] root (fallback)
        ├── [→] follow (sequence)
        │   ├── (target_visible) max_age=0.5
        │   └── [follow_target] distance=(mission)
        └── ...

    ``[?]``/``[→]``/``[⇉]`` are composites and ``<¬>``, ``<↻>``... decorators, each with its
    name (or kind) and in parentheses its kind and options; ``(name)`` are conditions and
    ``[name]`` actions, with their parameters.
    """
    root = parse_layout(layout)
    lines = [_ascii_line(root)]

    def walk(node: LayoutNode, prefix: str) -> None:
        for i, child in enumerate(node.children):
            last = i == len(node.children) - 1
            lines.append(f"{prefix}{'└── ' if last else '├── '}{_ascii_line(child)}")
            walk(child, prefix + ("    " if last else "│   "))

    walk(root, "")
    return "\n".join(lines) + "\n"


# --------------------------------------------------------------------------------------------
# Graphviz


def _dot_quote(text: str) -> str:
    """A DOT double-quoted string; ``\\n`` in ``text`` (a real newline) becomes a line break."""
    escaped = text.replace("\\", "\\\\").replace('"', '\\"')
    return '"' + escaped.replace("\n", "\\n") + '"'


def _dot_attrs(node: LayoutNode) -> dict[str, str]:
    if node.is_leaf:
        label = "\n".join([node.label, *_params(node)])
        shape = "ellipse" if node.kind == "condition" else "box"
        style = "filled" if node.kind == "condition" else "filled,rounded"
        return {"label": label, "shape": shape, "style": style, "fillcolor": COLORS[node.kind]}
    label = f"{SYMBOLS[node.kind]} {node.label}"
    if _subtitle(node):
        label += f"\n{_subtitle(node)}"
    if node.kind in DECORATORS:
        shape, color = "hexagon", COLORS["decorator"]
    else:
        shape, color = "box", COLORS[node.kind]
    return {"label": label, "shape": shape, "style": "filled", "fillcolor": color}


def dot_tree(layout: Mapping[str, Any], graph_name: str = "behavior_tree") -> str:
    """The tree as Graphviz DOT text: one node statement per tree node (``n0`` is the root),
    edges parent → child in order; composites as boxes with their symbol, decorators as
    hexagons, conditions as ellipses, actions as rounded boxes, parameters under leaf names."""
    root = parse_layout(layout)
    lines = [
        f"digraph {graph_name} {{",
        "  graph [rankdir=TB, ordering=out, nodesep=0.25, ranksep=0.45];",
        '  node [fontname="DejaVu Sans", fontsize=11, penwidth=1.2];',
        f'  edge [color="{EDGE_COLOR}", arrowsize=0.7];',
    ]
    ids: dict[int, str] = {}
    for i, node in enumerate(root.walk()):
        ids[id(node)] = f"n{i}"
        attrs = ", ".join(f"{key}={_dot_quote(value)}" for key, value in _dot_attrs(node).items())
        lines.append(f"  n{i} [{attrs}];")
    for node in root.walk():
        for child in node.children:
            lines.append(f"  {ids[id(node)]} -> {ids[id(child)]};")
    lines.append("}")
    return "\n".join(lines) + "\n"


# --------------------------------------------------------------------------------------------
# PNG

_NAME_PT = 10.0
_SMALL_PT = 8.0
_CHAR_EM = 0.62
"""Average advance of a DejaVu Sans character, in ems (a little generous)."""
_PAD_X = 0.16
_PAD_Y = 0.09
_GAP_X = 0.3
_GAP_Y = 0.42
_LINE = 1.3


@dataclass
class _Box:
    """A node's drawing: its text lines (first one bold-ish, larger) and size in inches."""

    node: LayoutNode
    lines: list[tuple[str, float]]
    width: float
    height: float
    depth: int
    x: float = 0.0
    y: float = 0.0


def _text_width(text: str, points: float) -> float:
    return len(text) * _CHAR_EM * points / 72.0


def _png_lines(node: LayoutNode) -> list[tuple[str, float]]:
    if node.is_leaf:
        return [(node.label, _NAME_PT)] + [(p, _SMALL_PT) for p in _params(node)]
    gap = " " if node.kind in DECORATORS else "  "
    lines = [(f"{SYMBOLS[node.kind]}{gap}{node.label}", _NAME_PT)]
    if _subtitle(node):
        lines.append((_subtitle(node), _SMALL_PT))
    return lines


def _boxes(root: LayoutNode) -> list[_Box]:
    """Every node's box, laid out top-down: leaves side by side in order, each parent centred
    over its children, a subtree as wide as the wider of its children and its own box."""
    boxes: list[_Box] = []

    def make(node: LayoutNode, depth: int) -> _Box:
        lines = _png_lines(node)
        width = max(_text_width(text, pt) for text, pt in lines) + 2 * _PAD_X
        if node.kind == "condition":
            width *= 1.18  # an ellipse needs room at its ends
        elif node.kind in DECORATORS:
            width += 0.18  # the hexagon's points
        height = sum(pt * _LINE / 72.0 for _, pt in lines) + 2 * _PAD_Y
        box = _Box(node, lines, width, height, depth)
        boxes.append(box)
        return box

    def place(node: LayoutNode, depth: int, left: float) -> tuple[_Box, float]:
        """Lay out ``node``'s subtree from ``left``; its box and the subtree's right edge."""
        box = make(node, depth)
        if not node.children:
            box.x = left + box.width / 2
            return box, left + box.width
        # Lay the children out once to learn their width, then shift them to centre under a
        # parent wider than they are.
        start = len(boxes)
        right = left
        child_boxes = []
        for i, child in enumerate(node.children):
            child_box, right = place(child, depth + 1, right + (_GAP_X if i else 0.0))
            child_boxes.append(child_box)
        span = right - left
        if box.width > span:
            shift = (box.width - span) / 2
            for b in boxes[start:]:
                b.x += shift
            right = left + box.width
        box.x = (child_boxes[0].x + child_boxes[-1].x) / 2
        return box, right

    place(root, 0, 0.0)
    depth_height: dict[int, float] = {}
    for b in boxes:
        depth_height[b.depth] = max(depth_height.get(b.depth, 0.0), b.height)
    # Rows are top-aligned, so the edges from a parent to its children meet them at one height.
    top = 0.0
    row_top: dict[int, float] = {}
    for depth in sorted(depth_height):
        row_top[depth] = top
        top -= depth_height[depth] + _GAP_Y
    for b in boxes:
        b.y = row_top[b.depth] - b.height / 2
    return boxes


def _draw_box(ax: Any, b: _Box) -> None:
    from matplotlib.patches import Ellipse, FancyBboxPatch, Polygon

    node = b.node
    kw: dict[str, Any] = {"edgecolor": "#333333", "linewidth": 1.1, "zorder": 2}
    x0, y0 = b.x - b.width / 2, b.y - b.height / 2
    if node.kind == "condition":
        ax.add_patch(Ellipse((b.x, b.y), b.width, b.height, facecolor=COLORS["condition"], **kw))
    elif node.kind == "action":
        ax.add_patch(
            FancyBboxPatch(
                (x0, y0),
                b.width,
                b.height,
                boxstyle="round,pad=0,rounding_size=0.07",
                facecolor=COLORS["action"],
                **kw,
            )
        )
    elif node.kind in DECORATORS:
        tip = min(0.12, b.height / 2)
        points = [
            (x0, b.y),
            (x0 + tip, y0 + b.height),
            (x0 + b.width - tip, y0 + b.height),
            (x0 + b.width, b.y),
            (x0 + b.width - tip, y0),
            (x0 + tip, y0),
        ]
        ax.add_patch(Polygon(points, closed=True, facecolor=COLORS["decorator"], **kw))
    else:
        ax.add_patch(
            FancyBboxPatch(
                (x0, y0),
                b.width,
                b.height,
                boxstyle="square,pad=0",
                facecolor=COLORS[node.kind],
                **kw,
            )
        )
    total = sum(pt * _LINE / 72.0 for _, pt in b.lines)
    y = b.y + total / 2
    for i, (text, pt) in enumerate(b.lines):
        step = pt * _LINE / 72.0
        ax.text(
            b.x,
            y - step / 2,
            text,
            ha="center",
            va="center",
            fontsize=pt,
            fontweight="bold" if i == 0 and not node.is_leaf else "normal",
            color="#1a1a1a" if i == 0 else "#444444",
            zorder=3,
        )
        y -= step


def _legend_handles(root: LayoutNode) -> list[Any]:
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    kinds = {n.kind for n in root.walk()}
    handles: list[Any] = []
    for kind in ("fallback", "sequence", "parallel"):
        if kind in kinds:
            handles.append(
                Patch(facecolor=COLORS[kind], edgecolor="#333333", label=f"{SYMBOLS[kind]} {kind}")
            )
    decorators = [k for k in DECORATORS if k in kinds]
    if decorators:
        label = "decorator: " + ", ".join(f"{SYMBOLS[k]} {k}" for k in decorators)
        handles.append(Patch(facecolor=COLORS["decorator"], edgecolor="#333333", label=label))
    marker = {"linestyle": "none", "markeredgecolor": "#333333", "markersize": 13}
    if "condition" in kinds:
        handles.append(
            Line2D(
                [],
                [],
                marker="o",
                markerfacecolor=COLORS["condition"],
                label="condition",
                **marker,
            )
        )
    if "action" in kinds:
        handles.append(
            Line2D([], [], marker="s", markerfacecolor=COLORS["action"], label="action", **marker)
        )
    return handles


def png_tree(layout: Mapping[str, Any], title: str | None = None, dpi: int = 110) -> bytes:
    """The tree as a PNG (matplotlib, Agg; no Graphviz needed): top-down, leaves spread evenly,
    each parent centred over its children, orthogonal edges, parameters under leaf names, and a
    legend of the kinds that occur. ``title`` goes above the tree."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    root = parse_layout(layout)
    boxes = _boxes(root)
    by_node = {id(b.node): b for b in boxes}
    handles = _legend_handles(root)
    left = min(b.x - b.width / 2 for b in boxes)
    right = max(b.x + b.width / 2 for b in boxes)
    top = max(b.y + b.height / 2 for b in boxes)
    bottom = min(b.y - b.height / 2 for b in boxes)
    margin = 0.3
    title_h = 0.45 if title else 0.0
    tree_w = right - left
    ncol = len(handles) if tree_w >= 9.0 else min(3, len(handles))
    legend_rows = -(-len(handles) // ncol)
    legend_h = 0.3 * legend_rows + 0.25
    fig_w = max(tree_w + 2 * margin, 6.0)
    fig_h = (top - bottom) + 2 * margin + title_h + legend_h

    fig = Figure(figsize=(fig_w, fig_h), dpi=dpi, facecolor="white")
    FigureCanvasAgg(fig)
    # One data unit is one inch: the axes fill the figure below the title, above the legend.
    ax = fig.add_axes((0.0, legend_h / fig_h, 1.0, 1.0 - (legend_h + title_h) / fig_h))
    ax.set_axis_off()
    cx = (left + right) / 2
    half_w = fig_w / 2
    ax.set_xlim(cx - half_w, cx + half_w)
    ax.set_ylim(bottom - margin, top + margin)
    ax.set_aspect("equal", adjustable="box")
    for b in boxes:
        for child in b.node.children:
            c = by_node[id(child)]
            y_start = b.y - b.height / 2
            y_end = c.y + c.height / 2
            y_mid = y_end + _GAP_Y / 2
            ax.plot(
                [b.x, b.x, c.x, c.x],
                [y_start, y_mid, y_mid, y_end],
                color=EDGE_COLOR,
                linewidth=1.1,
                solid_joinstyle="miter",
                zorder=1,
            )
    for b in boxes:
        _draw_box(ax, b)
    if title:
        fig.text(
            0.5,
            1.0 - (title_h / 2) / fig_h,
            title,
            ha="center",
            va="center",
            fontsize=12,
            fontweight="bold",
        )
    fig.legend(
        handles=handles,
        loc="lower center",
        ncol=ncol,
        frameon=False,
        fontsize=9,
        bbox_to_anchor=(0.5, 0.02 / fig_h),
        handlelength=1.4,
        columnspacing=1.6,
    )
    out = io.BytesIO()
    fig.savefig(out, format="png", dpi=dpi, facecolor="white")
    return out.getvalue()


# --------------------------------------------------------------------------------------------
# BehaviorTree.CPP v4

_PORT_TYPES = {float: "double", int: "int", bool: "bool"}


def _xml_value(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return f"{value:.12g}"
    return str(value)


def _btcpp_element(node: LayoutNode) -> ET.Element:
    attrs: dict[str, str] = {}
    if node.is_leaf:
        # v4's compact form: the element is the registration ID, ports are attributes. A
        # parameter whose default is "the mission's value" is left out (the port's default).
        attrs = {k: _xml_value(v) for k, v in node.params.items() if v is not None}
        return ET.Element(node.label, attrs)
    if node.name:
        attrs["name"] = node.name
    if node.kind == "sequence":
        tag = "Sequence" if node.memory else "ReactiveSequence"
    elif node.kind == "fallback":
        tag = "Fallback" if node.memory else "ReactiveFallback"
    elif node.kind == "parallel":
        tag = "Parallel"
        attrs["success_count"] = "-1" if node.policy == "success_on_all" else "1"
        attrs["failure_count"] = "1"
    elif node.kind == "retry":
        tag = "RetryUntilSuccessful"
        attrs["num_attempts"] = str(node.value)
    elif node.kind == "repeat":
        tag = "Repeat"
        attrs["num_cycles"] = str(node.value)
    elif node.kind == "timeout":
        tag = "Timeout"
        attrs["msec"] = str(round(float(node.value or 0.0) * 1000))
    else:
        tag = {"inverter": "Inverter", "force_success": "ForceSuccess"}.get(
            node.kind, "ForceFailure"
        )
    element = ET.Element(tag, attrs)
    for child in node.children:
        element.append(_btcpp_element(child))
    return element


def _tree_nodes_model() -> ET.Element:
    """Every leaf of the registry as ``<Condition|Action ID=...>`` with its input ports."""
    model = ET.Element("TreeNodesModel")
    for spec in LEAF_SPECS.values():
        element = ET.SubElement(model, "Condition" if spec.kind == "condition" else "Action")
        element.set("ID", spec.name)
        for param in spec.params:
            port = ET.SubElement(element, "input_port", {"name": param.name})
            port.set("type", _PORT_TYPES.get(param.kind, "std::string"))
            text = param.doc
            if param.default is not None:
                port.set("default", _xml_value(param.default))
            elif param.required:
                text += " (required)"
            elif "default" not in text:
                text += " (default: the mission's value)"
            bounds = []
            if param.minimum is not None:
                bounds.append(f">= {param.minimum:g}")
            if param.maximum is not None:
                bounds.append(f"<= {param.maximum:g}")
            if bounds:
                text += f" [{', '.join(bounds)}]"
            port.text = text
        metadata = ET.SubElement(element, "MetadataFields")
        ET.SubElement(metadata, "Metadata", {"description": spec.doc})
    return model


def btcpp_xml(layout: Mapping[str, Any], tree_id: str = "MainTree") -> str:
    """The tree as BehaviorTree.CPP v4 XML (``BTCPP_format="4"``) that Groot2 opens.

    Mapping: sequence → ``ReactiveSequence`` (``Sequence`` with memory), fallback →
    ``ReactiveFallback`` (``Fallback`` with memory), parallel → ``Parallel success_count="-1"``
    (all) or ``"1"`` (one) with ``failure_count="1"``, inverter → ``Inverter``, force_success →
    ``ForceSuccess``, force_failure → ``ForceFailure``, retry → ``RetryUntilSuccessful
    num_attempts``, timeout → ``Timeout msec``, repeat → ``Repeat num_cycles``; a leaf is its own
    element, ``<target_visible max_age="0.5"/>``, parameters as ports. The
    ``<TreeNodesModel>`` declares every registered leaf with its ports, defaults and description.
    """
    root_node = parse_layout(layout)
    root = ET.Element("root", {"BTCPP_format": "4", "main_tree_to_execute": tree_id})
    tree = ET.SubElement(root, "BehaviorTree", {"ID": tree_id})
    tree.append(_btcpp_element(root_node))
    root.append(_tree_nodes_model())
    ET.indent(root, space="  ")
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, encoding="unicode") + "\n"
