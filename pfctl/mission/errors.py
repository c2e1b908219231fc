"""Mission errors: how the models' validators raise them, and how a failure becomes one line.

Every failure of a mission becomes a :class:`pfctl.errors.MissionError` whose message is one
line, ``<file>:<line>: <key.path[2].sub>: <what was expected>``. The line is found by composing
the YAML node graph and walking it along the error's key path to the deepest node that exists
(:func:`format_validation_error`). A mission merged with the one it extends has one node graph
merged the same way, each node marked with the file it came from, so the error names that file.

Validators raise :func:`value_error` (a message used verbatim) or, for a semantic check that
points below the model it runs on, :func:`field_error` / :func:`raise_first`.
"""

from __future__ import annotations

import re
from collections.abc import Iterator, Mapping, Sequence
from typing import Annotated, Any, Union, get_args, get_origin

import yaml
from pydantic import BaseModel, ValidationError
from pydantic_core import PydanticCustomError


def value_error(kind: str, message: str) -> PydanticCustomError:
    """A validation error whose message is ``message`` verbatim (no template expansion)."""
    return PydanticCustomError(kind, "{detail}", {"detail": message})


def field_error(loc: tuple[str | int, ...], message: str, more: int = 0) -> PydanticCustomError:
    """A semantic error at ``loc`` *relative to* the model that raises it.

    Pydantic gives model validators no way to point deeper than the model, so the relative key
    path travels in the error's context and :func:`_format_error` appends it. ``more`` counts
    further semantic errors found in the same pass.
    """
    return PydanticCustomError("mission", "{detail}", {"detail": message, "loc": loc, "more": more})


def raise_first(issues: list[tuple[tuple[str | int, ...], str]]) -> None:
    """Raise the first of ``issues`` (relative key path, message), counting the rest."""
    if issues:
        loc, message = issues[0]
        raise field_error(loc, message, more=len(issues) - 1)


def one_line(text: str) -> str:
    """``text`` with every run of white space (newlines too) made one space."""
    return " ".join(str(text).split())


def short(value: Any, limit: int = 40) -> str:
    """``repr(value)`` on one line, cut to ``limit`` characters (``...`` at the end)."""
    text = one_line(repr(value))
    return text if len(text) <= limit else text[: limit - 3] + "..."


def format_loc(loc: Sequence[str | int]) -> str:
    """``("map", "doors", 1, "between")`` -> ``map.doors[1].between``."""
    out = ""
    for part in loc:
        if isinstance(part, int):
            out += f"[{part}]"
        else:
            out += f".{part}" if out else str(part)
    return out


def _locate(root: yaml.Node, loc: Sequence[str | int]) -> tuple[tuple[str | int, ...], yaml.Mark]:
    """Walk the node graph along ``loc``; the cleaned key path and the mark of the deepest node.

    Union tags that pydantic inserts into the path (``route[0].point``) are dropped: a string
    step into a scalar or a list cannot be a key. Once a key is missing, the rest of the path is
    kept as is. The mark is the key's when the last step was into a mapping; its ``name`` is the
    file the node was read from (a mission merged with the one it extends has nodes of both).
    """
    node: yaml.Node | None = root
    mark = root.start_mark
    path: list[str | int] = []
    for part in loc:
        if node is None:
            path.append(str(part) if isinstance(part, str) else part)
        elif isinstance(node, yaml.MappingNode):
            match = next(
                (
                    (k, v)
                    for k, v in reversed(node.value)
                    if isinstance(k, yaml.ScalarNode) and k.value == str(part)
                ),
                None,
            )
            path.append(str(part))
            if match is None:
                node = None
            else:
                mark = match[0].start_mark
                node = match[1]
        elif isinstance(part, str):
            continue  # a union tag, not a key
        elif isinstance(node, yaml.SequenceNode) and 0 <= part < len(node.value):
            path.append(part)
            node = node.value[part]
            mark = node.start_mark
        else:
            path.append(part)
            node = None
    return tuple(path), mark


def _allowed_keys(model: type[BaseModel], loc: Sequence[str | int]) -> list[str] | None:
    """The keys the model at ``loc`` accepts, found by walking the model types along the path."""
    candidates: list[Any] = [model]
    for part in loc:
        following: list[Any] = []
        for tp in candidates:
            following.extend(_step_type(tp, part))
        candidates = following
    for tp in candidates:
        for model in models_in(tp):
            return [f.alias or name for name, f in model.model_fields.items()]
    return None


def models_in(tp: Any) -> Iterator[type[BaseModel]]:
    """The pydantic models ``tp`` may be (through Annotated, Optional and unions)."""
    if isinstance(tp, type) and issubclass(tp, BaseModel):
        yield tp
        return
    origin = get_origin(tp)
    if origin is Annotated:
        yield from models_in(get_args(tp)[0])
    elif origin is Union or type(tp).__name__ == "UnionType":
        for arg in get_args(tp):
            yield from models_in(arg)


def _step_type(tp: Any, part: str | int) -> list[Any]:
    """The types one key-path step below ``tp``."""
    origin = get_origin(tp)
    if origin is Annotated:
        return _step_type(get_args(tp)[0], part)
    if origin is Union or type(tp).__name__ == "UnionType":
        return [t for arg in get_args(tp) for t in _step_type(arg, part)]
    if isinstance(tp, type) and issubclass(tp, BaseModel):
        field = tp.model_fields.get(str(part))
        return [field.annotation] if field is not None else []
    if origin in (tuple, list) and isinstance(part, int):
        args = get_args(tp)
        if len(args) == 2 and args[1] is Ellipsis:
            return [args[0]]
        return [args[part]] if part < len(args) else []
    return []


_MODEL_TYPE = re.compile(r"a valid dictionary or instance of \w+")
_COUNT = re.compile(r"^\w+ should have at (least|most) (\d+) items? after validation, not (\d+)$")
_BOUND = re.compile(r"^expected (greater|less) than( or equal to)? (\S+)$")
_OPERATORS = {
    ("greater", False): ">",
    ("greater", True): ">=",
    ("less", False): "<",
    ("less", True): "<=",
}


def got(value: Any) -> str:
    """How an input reads in ``(got ...)``: short values verbatim, containers by their kind."""
    if isinstance(value, (list, tuple)):
        return f"a list of {len(value)}"
    if isinstance(value, Mapping):
        return "a mapping"
    if value is None or isinstance(value, bool):
        return {None: "null", True: "true", False: "false"}[value]
    return short(value)


def _format_error(
    error: Mapping[str, Any], root: yaml.Node, model: type[BaseModel]
) -> tuple[yaml.Mark, str, int]:
    """One pydantic error as ``(mark, "key.path: message", further errors it stands for)``."""
    loc = tuple(error["loc"])
    ctx = error.get("ctx") or {}
    kind = error["type"]
    message = one_line(error["msg"])
    if kind == "mission":
        loc = (*loc, *ctx.get("loc", ()))
    path, mark = _locate(root, loc)
    more = int(ctx.get("more", 0)) if kind == "mission" else 0
    if kind == "missing":
        message = "required key is missing"
    elif kind == "extra_forbidden":
        allowed = _allowed_keys(model, loc[:-1])
        message = "unknown key"
        if allowed:
            message += f" (expected one of: {', '.join(allowed)})"
    elif kind == "invalid_key":
        message = f"expected a string key, got {short(error.get('input'))}"
    else:
        message = re.sub(r"^(Value error|Assertion failed), ", "", message)
        message = _MODEL_TYPE.sub("a mapping", message)
        message = message.replace("a valid tuple", "a list").replace(
            "a valid dictionary", "a mapping"
        )
        if message.startswith("Input should be "):
            message = "expected " + message[len("Input should be ") :]
        count = _COUNT.match(message)
        if count:
            unit = "item" if count.group(2) == "1" else "items"
            message = f"expected at {count.group(1)} {count.group(2)} {unit}, got {count.group(3)}"
        bound = _BOUND.match(message)
        if bound:
            operator = _OPERATORS[(bound.group(1), bool(bound.group(2)))]
            message = f"expected a value {operator} {bound.group(3)}"
        if "detail" not in ctx and kind != "route_stop" and not count:
            message += f" (got {got(error.get('input'))})"
    where = format_loc(path)
    return mark, f"{where}: {message}" if where else message, more


def format_validation_error(
    err: ValidationError, root: yaml.Node, sources: list[str], model: type[BaseModel]
) -> str:
    """The first error of validating ``model`` in file order — the files in ``sources`` order
    (the mission, then what it includes and extends), then by line — as one line naming its
    file, with ``(+N more)`` when there are others."""
    errors = err.errors()
    # A list with a bad item is also "too short after validation": that one is noise.
    errors = [
        e
        for e in errors
        if e["type"] not in ("too_short", "too_long")
        or not any(
            len(o["loc"]) > len(e["loc"]) and o["loc"][: len(e["loc"])] == e["loc"] for o in errors
        )
    ]
    formatted = [_format_error(e, root, model) for e in errors]
    order = {name: i for i, name in reversed(list(enumerate(sources)))}

    def position(item: tuple[yaml.Mark, str, int]) -> tuple[int, int]:
        return (order.get(item[0].name, len(sources)), item[0].line)

    formatted.sort(key=position)  # stable: equal lines keep pydantic's order
    mark, message, _ = formatted[0]
    more = len(formatted) - 1 + sum(m for _, _, m in formatted)
    suffix = f" (+{more} more)" if more else ""
    return f"{mark.name}:{mark.line + 1}: {message}{suffix}"
