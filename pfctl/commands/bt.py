"""`pfctl bt show|leaves`: draw a mission's behavior tree, list the leaves a tree may name.

- ``show MISSION``: the mission's tree (§II-A, Fig. 2) as indented text (``--format ascii``, the
  default), Graphviz DOT (``dot``), a PNG (``png``, drawn by matplotlib, no Graphviz needed) or
  BehaviorTree.CPP v4 XML for Groot2 (``btcpp``). Text goes to stdout unless ``--out``; the PNG is
  written to ``--out`` or ``<mission stem>_tree.png`` in the current folder.
- ``leaves``: every condition and action of the registry with what it does and its parameters
  (default, range).

Every bad input is a :class:`pfctl.errors.UserError` (one line, exit 2); files are written
atomically.
"""

from __future__ import annotations

import textwrap
from pathlib import Path
from typing import Annotated

import typer

from pfctl.core.behavior.registry import LEAF_SPECS, ParamSpec
from pfctl.errors import UserError
from pfctl.files import check_output_file, write_output
from pfctl.mission import load_mission
from pfctl.plots.behavior_tree import ascii_tree, btcpp_xml, dot_tree, png_tree

app = typer.Typer(
    help="Behavior trees: draw a mission's tree, list the leaves a tree may name.",
    no_args_is_help=True,
)

FORMATS = ("ascii", "dot", "png", "btcpp")
_WIDTH = 100


@app.command()
def show(
    mission: Annotated[Path, typer.Argument(help="Mission YAML file.", show_default=False)],
    fmt: Annotated[
        str,
        typer.Option(
            "--format",
            "-f",
            help="ascii (indented text), dot (Graphviz), png (picture) or btcpp "
            "(BehaviorTree.CPP v4 XML for Groot2).",
        ),
    ] = "ascii",
    out: Annotated[
        Path | None,
        typer.Option(
            "--out",
            "-o",
            help="Write to this file (atomically). Text formats print to stdout without it; "
            "png defaults to <mission stem>_tree.png in the current folder.",
        ),
    ] = None,
) -> None:
    """Draw the behavior tree of MISSION (§II-A, Fig. 2 of the paper)."""
    if fmt not in FORMATS:
        raise UserError(f"--format {fmt}: expected one of {', '.join(FORMATS)}")
    check_output_file(out, "--out", make_folder=False)
    loaded = load_mission(mission)
    layout = loaded.behavior.tree.model_dump(exclude_none=True)
    try:
        if fmt == "png":
            data: str | bytes = png_tree(layout, title=f"{loaded.name}: behavior tree")
        elif fmt == "dot":
            data = dot_tree(layout)
        elif fmt == "btcpp":
            data = btcpp_xml(layout)
        else:
            data = ascii_tree(layout)
    except ValueError as err:  # the mission loader checks the tree; this is a second guard
        raise UserError(f"{mission}: {err}") from None
    if fmt == "png" and out is None:
        out = Path.cwd() / f"{mission.stem}_tree.png"
    if out is None:
        typer.echo(data, nl=False)
        return
    write_output(out, data)
    typer.echo(f"wrote {out}")


def _range(param: ParamSpec) -> str:
    """``>= 0``, ``<= 3``, ``0 to 3``, or empty."""
    low, high = param.minimum, param.maximum
    if low is not None and high is not None:
        return f"{low:g} to {high:g}"
    if low is not None:
        return f">= {low:g}"
    if high is not None:
        return f"<= {high:g}"
    return ""


def _default(param: ParamSpec) -> str:
    if param.required:
        return "required"
    if param.default is None:
        return "default: the mission's value"
    if isinstance(param.default, bool):
        return f"default {str(param.default).lower()}"
    return f"default {param.default:g}"


@app.command()
def leaves() -> None:
    """List the conditions and actions a tree may name, with their parameters."""
    for kind, title in (("condition", "Conditions"), ("action", "Actions")):
        typer.echo(f"{title}:")
        for spec in LEAF_SPECS.values():
            if spec.kind != kind:
                continue
            typer.echo(f"  {spec.name}")
            typer.echo(
                textwrap.fill(spec.doc, _WIDTH, initial_indent="      ", subsequent_indent="      ")
            )
            for param in spec.params:
                facts = [param.kind.__name__, _default(param)]
                if _range(param):
                    facts.append(_range(param))
                line = f"{param.name} ({', '.join(facts)}): {param.doc}"
                typer.echo(
                    textwrap.fill(
                        line, _WIDTH, initial_indent="      - ", subsequent_indent="        "
                    )
                )
        if kind == "condition":
            typer.echo("")
