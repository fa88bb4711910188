"""Loading YAML configuration files safely into typed dataclasses.

PyYAML's safe composer builds the node tree (no tags beyond plain YAML values, so nothing is ever
executed); the tree is checked against hard limits before anything is built from it — file size,
nesting depth, and the number of values after alias expansion (counted without expanding, so a
"billion laughs" file is refused at once) — and is then converted field by field into the schema
dataclass. Errors are ``YamlError`` with ``file:line:`` and the field's dotted name and the value as
written in the file; an unknown key suggests the nearest valid one.
"""

from __future__ import annotations

import dataclasses
import math
import types
import typing
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import yaml

from stewart_drake.errors import InputError, YamlError
from stewart_drake.system.input_stream import read_input

MAX_BYTES = 1_000_000  # a platform file is a few hundred bytes
MAX_DEPTH = 32  # nesting levels of mappings/sequences
MAX_NODES = 100_000  # values after alias expansion
MAX_INT_DIGITS = 30  # a longer integer is no dimension
_CONSTRUCTOR = yaml.constructor.SafeConstructor()
_SAFE_TAGS = {f"tag:yaml.org,2002:{t}" for t in ("str", "int", "float", "bool", "null", "seq", "map")}


@dataclass(frozen=True)
class Where:
    """Where a value stands in the file: 1-based line and the text as written."""

    line: int
    text: str


class _Loader(yaml.SafeLoader):
    """PyYAML's safe loader, refusing nesting deeper than ``MAX_DEPTH`` while it composes."""

    def __init__(self, stream):
        super().__init__(stream)
        self.depth = 0
        self.path = ""

    def compose_node(self, parent, index):
        self.depth += 1
        try:
            if self.depth > MAX_DEPTH:
                mark = self.peek_event().start_mark
                raise YamlError(YamlError.TOO_DEEP.format(path=self.path, line=mark.line + 1, limit=MAX_DEPTH))
            return super().compose_node(parent, index)
        finally:
            self.depth -= 1


def field_name(path: tuple) -> str:
    """``("plate", "inertia", 3)`` -> ``"plate.inertia item 4"`` (items counted from 1)."""
    out = ""
    for p in path:
        out += f" item {p + 1}" if isinstance(p, int) else (f".{p}" if out else p)
    return out or "(top level)"


def load_yaml_typed(path, schema, kind: str, check: Callable[[Any, dict], None] | None = None):
    """Parse the YAML file ``path`` into a new ``schema`` dataclass (missing keys keep their defaults).

    ``kind`` names what the file should hold ("platform"), for messages. ``check(cfg, where)`` may
    validate values further; ``where`` maps field paths (tuples of keys and 0-based indices) to their
    ``Where``. Raises ``YamlError``."""
    text, shown = read_yaml_text(path, kind)
    return load_node_typed(compose(text, shown), schema, kind, shown, check)


def load_node_typed(root, schema, kind: str, shown: str, check: Callable[[Any, dict], None] | None = None):
    """``load_yaml_typed`` on a composed node ``root`` (a mapping of a larger file; ``shown``: the file as
    messages name it, line numbers are the file's)."""
    if root is None:
        raise YamlError(YamlError.TOP.format(path=shown, kind=kind, got="an empty file"))
    _check_tag(root, shown)
    if not isinstance(root, yaml.MappingNode):
        raise YamlError(YamlError.TOP.format(path=shown, kind=kind, got=_describe(root)))
    _check_size(root, shown)
    where: dict = {}
    cfg = _convert(root, schema, (), shown, where)
    if check is not None:
        check(cfg, where)
    return cfg


def read_yaml_text(path, kind: str, limit: int = MAX_BYTES) -> tuple[str, str]:
    """``(text, path as shown)`` of a YAML input, read once as a stream of at most ``limit`` bytes
    (``input_stream``: a FIFO works, ``/dev/zero`` is refused by the budget); ``YamlError`` naming it."""
    shown = str(path)
    try:
        data = read_input(
            path,
            kind=kind,
            limit=limit,
            missing=YamlError.MISSING.format(kind=kind, path=shown),
            folder=YamlError.NOT_A_FILE.format(kind=kind, path=shown),
            too_large=YamlError.TOO_LARGE.format(path=shown, limit=limit, kind=kind),
        )
    except InputError as e:
        raise YamlError(str(e)) from None
    try:
        return data.decode("utf-8-sig"), shown
    except UnicodeDecodeError as e:
        raise YamlError(YamlError.NOT_TEXT.format(path=shown, offset=e.start)) from None


def compose(text: str, shown: str):
    """The YAML node tree of ``text`` (None for an empty document); syntax errors as ``YamlError``."""
    try:
        loader = _Loader(text)
    except yaml.reader.ReaderError as e:
        line = text[: max(e.position, 0)].count("\n") + 1
        raise YamlError(
            YamlError.SYNTAX.format(path=shown, line=line, problem=f"{e.reason} (character #x{e.character:04x})")
        ) from None
    loader.path = shown
    try:
        return loader.get_single_node()
    except yaml.MarkedYAMLError as e:
        mark = e.problem_mark or e.context_mark
        line = mark.line + 1 if mark else "?"
        problem = (e.problem or e.context or "malformed").strip()
        raise YamlError(YamlError.SYNTAX.format(path=shown, line=line, problem=problem)) from None
    except yaml.YAMLError as e:
        raise YamlError(YamlError.SYNTAX.format(path=shown, line="?", problem=str(e).splitlines()[0])) from None
    finally:
        loader.dispose()


def _check_size(root, shown: str) -> None:
    """Refuse a tree with more than ``MAX_NODES`` values once aliases are expanded, or a recursive
    alias; sizes are memoised per node, so this costs one pass over the distinct nodes."""
    sizes: dict[int, int] = {}
    busy: set[int] = set()

    def size(node) -> int:
        key = id(node)
        if key in sizes:
            return sizes[key]
        if key in busy:
            raise YamlError(YamlError.RECURSIVE_ALIAS.format(path=shown, line=node.start_mark.line + 1))
        busy.add(key)
        if isinstance(node, yaml.SequenceNode):
            n = 1 + sum(size(c) for c in node.value)
        elif isinstance(node, yaml.MappingNode):
            n = 1 + sum(size(k) + size(v) for k, v in node.value)
        else:
            n = 1
        busy.discard(key)
        if n > MAX_NODES:
            raise YamlError(YamlError.TOO_MANY_NODES.format(path=shown, limit=MAX_NODES))
        sizes[key] = n
        return n

    size(root)


def _describe(node) -> str:
    """A node as the user wrote it, for messages."""
    if isinstance(node, yaml.ScalarNode):
        text = node.value if len(node.value) <= 60 else node.value[:57] + "..."
        return repr(text) if node.style in ("'", '"') or not text else text
    return "a list" if isinstance(node, yaml.SequenceNode) else "a mapping"


def _line(node) -> int:
    return node.start_mark.line + 1


def _check_tag(node, shown: str) -> None:
    if node.tag not in _SAFE_TAGS:
        raise YamlError(
            YamlError.TAG.format(path=shown, line=_line(node), tag=node.tag.replace("tag:yaml.org,2002:", "!!"))
        )


def _wrong(node, path, shown, expected: str) -> YamlError:
    return YamlError(
        YamlError.WRONG_TYPE.format(
            path=shown, line=_line(node), field=field_name(path), expected=expected, value=_describe(node)
        )
    )


def _convert(node, tp, path: tuple, shown: str, where: dict):
    """The value of ``node`` as type ``tp`` (a dataclass, list[...], Optional[...], float, int, str, bool)."""
    _check_tag(node, shown)
    origin, args = typing.get_origin(tp), typing.get_args(tp)
    if origin in (typing.Union, types.UnionType):
        inner = [a for a in args if a is not type(None)]
        if isinstance(node, yaml.ScalarNode) and node.tag.endswith(":null"):
            return None
        return _convert(node, inner[0], path, shown, where)
    if dataclasses.is_dataclass(tp):
        return _dataclass(node, tp, path, shown, where)
    if origin is list:
        if not isinstance(node, yaml.SequenceNode):
            raise _wrong(node, path, shown, "a list [...]")
        return [_convert(c, args[0], path + (i,), shown, where) for i, c in enumerate(node.value)]
    if not isinstance(node, yaml.ScalarNode):
        raise _wrong(node, path, shown, _type_words(tp))
    where[path] = Where(_line(node), node.value)
    if tp is str:
        if node.tag.endswith(":str") or node.tag.endswith(":int") or node.tag.endswith(":float"):
            return node.value
        raise _wrong(node, path, shown, "text")
    if tp is bool:
        if node.tag.endswith(":bool"):
            return node.value.lower() in ("true", "yes", "on", "y")
        raise _wrong(node, path, shown, "true or false")
    if tp is int:
        return _integer(node, path, shown)
    if tp is float:
        return _number(node, path, shown)
    raise _wrong(node, path, shown, _type_words(tp))


def _type_words(tp) -> str:
    return {float: "a number", int: "a whole number", str: "text", bool: "true or false"}.get(tp, "a value")


def _integer(node, path, shown) -> int:
    if node.tag.endswith(":int") and node.style is None:
        digits = node.value.lstrip("+-").replace("_", "")
        if len(digits) > MAX_INT_DIGITS:
            raise _bad(node, path, shown, f"has more than {MAX_INT_DIGITS} digits")
        return int(_CONSTRUCTOR.construct_yaml_int(node))
    raise _wrong(node, path, shown, "a whole number")


def _number(node, path, shown) -> float:
    """A finite float from a plain scalar: YAML ints and floats, and also ``1e3`` (a string to YAML 1.1)."""
    if node.style is not None or node.tag.endswith(":bool") or node.tag.endswith(":null"):
        raise _wrong(node, path, shown, "a number")
    text = node.value.replace("_", "")
    if node.tag.endswith(":int"):
        if len(text.lstrip("+-")) > MAX_INT_DIGITS:
            raise _bad(node, path, shown, f"has more than {MAX_INT_DIGITS} digits")
        value = float(_integer(node, path, shown))
    else:
        try:
            value = float(
                text.replace(".inf", "inf")
                .replace(".Inf", "inf")
                .replace(".INF", "inf")
                .replace(".nan", "nan")
                .replace(".NaN", "nan")
                .replace(".NAN", "nan")
            )
        except ValueError:
            raise _wrong(node, path, shown, "a number") from None
    if not math.isfinite(value):
        raise _bad(node, path, shown, "is not a finite number")
    return value


def _bad(node, path, shown, problem: str) -> YamlError:
    return YamlError(
        YamlError.BAD_VALUE.format(
            path=shown, line=_line(node), field=field_name(path), value=_describe(node), problem=problem
        )
    )


def _dataclass(node, tp, path, shown, where):
    if not isinstance(node, yaml.MappingNode):
        if not path:
            raise YamlError(YamlError.TOP.format(path=shown, kind=tp.__name__, got=_describe(node)))
        raise _wrong(node, path, shown, "a mapping of keys to values")
    hints = typing.get_type_hints(tp)
    fields = [f.name for f in dataclasses.fields(tp)]
    values = {}
    seen = set()
    for knode, vnode in node.value:
        _check_tag(knode, shown)
        if not isinstance(knode, yaml.ScalarNode):
            raise YamlError(
                YamlError.UNKNOWN_KEY.format(
                    path=shown, line=_line(knode), field=field_name(path), hint="", valid=", ".join(fields)
                )
            )
        key = knode.value
        if key not in hints:
            import difflib  # deferred: only a misspelt key needs it, and every command reads a file at start

            close = difflib.get_close_matches(key, fields, n=1, cutoff=0.6)
            hint = f" {key!r}" + (f" (did you mean {close[0]!r}?)" if close else "")
            raise YamlError(
                YamlError.UNKNOWN_KEY.format(
                    path=shown,
                    line=_line(knode),
                    field=field_name(path) if path else key,
                    hint=hint if path else (f" (did you mean {close[0]!r}?)" if close else ""),
                    valid=", ".join(fields),
                )
            )
        if key in seen:
            raise YamlError(
                YamlError.DUPLICATE_KEY.format(path=shown, line=_line(knode), field=field_name(path + (key,)))
            )
        seen.add(key)
        values[key] = _convert(vnode, hints[key], path + (key,), shown, where)
        where.setdefault(path + (key,), Where(_line(vnode), _describe(vnode)))
    return tp(**values)  # built once from every key: a frozen schema dataclass (LegConfig) is read as any other


# ----------------------------------------------------------------------------------------------
# Field rules: sign, range and shape of the values, checked with the file's line numbers.


@dataclass(frozen=True)
class Rule:
    """A numeric field's constraint. ``sign``: "pos" (> 0), "nonneg" (>= 0) or "any"; ``unit``:
    "length" (scaled by the file's length unit, bounded by ``MAX_LENGTH_M``), or a unit name;
    ``max``: the largest accepted magnitude in that unit (SI)."""

    sign: str = "any"
    unit: str = ""
    max: float = math.inf


MAX_LENGTH_M = 100.0  # no Stewart platform spans 100 m: a bigger number is a unit mistake


def _pattern(path: tuple) -> str:
    out = ""
    for p in path:
        out += "[*]" if isinstance(p, int) else (f".{p}" if out else p)
    return out


def check_rules(where: dict, rules: dict, shapes: dict, cfg, shown: str, length_scale: float, unit_name: str) -> None:
    """Apply ``rules`` (field pattern -> ``Rule``) to every number in ``where`` and ``shapes``
    (field pattern -> (min items, max items)) to the lists of ``cfg``; raise ``YamlError``."""
    for path, w in where.items():
        rule = rules.get(_pattern(path))
        if rule is None:
            continue
        value = _get(cfg, path)
        if not isinstance(value, (int, float)) or isinstance(value, bool):
            continue
        name = field_name(path)
        if rule.sign == "pos" and not value > 0:
            raise YamlError(
                YamlError.BAD_VALUE.format(path=shown, line=w.line, field=name, value=w.text, problem="must be > 0")
            )
        if rule.sign == "nonneg" and not value >= 0:
            raise YamlError(
                YamlError.BAD_VALUE.format(path=shown, line=w.line, field=name, value=w.text, problem="must be >= 0")
            )
        scale, limit, unit = (length_scale, MAX_LENGTH_M, "m") if rule.unit == "length" else (1.0, rule.max, rule.unit)
        if abs(value) * scale > limit:
            shown_limit = f"{limit / scale:g} {unit_name}" if rule.unit == "length" else f"{limit:g} {unit}"
            raise YamlError(
                YamlError.BAD_VALUE.format(
                    path=shown, line=w.line, field=name, value=w.text, problem=f"is too large (at most {shown_limit})"
                )
            )
    for pattern, (lo, hi) in shapes.items():
        for path, value in _lists(cfg, pattern):
            if value is None or (not value and lo > 0 and path not in where and not _given(where, path)):
                continue
            if not lo <= len(value) <= hi:
                w = where.get(path)
                count = f"{lo}" if lo == hi else f"{lo} to {hi}"
                line = f"{w.line}" if w else "?"
                raise YamlError(
                    YamlError.BAD_VALUE.format(
                        path=shown,
                        line=line,
                        field=field_name(path),
                        value=f"({len(value)} items)",
                        problem=f"must have {count} items",
                    )
                )


def _given(where: dict, path: tuple) -> bool:
    n = len(path)
    return any(k[:n] == path for k in where)


def _get(obj, path: tuple):
    for p in path:
        obj = obj[p] if isinstance(p, int) else getattr(obj, p)
    return obj


def _lists(cfg, pattern: str):
    """(path, value) of every list matching ``pattern`` ("base_anchors[*]" -> each anchor)."""
    parts = []
    for seg in pattern.split("."):
        name, _, rest = seg.partition("[")
        parts.append(name)
        parts += ["*"] * seg.count("[*]")
    results = [((), cfg)]
    for part in parts:
        nxt = []
        for path, obj in results:
            if obj is None:
                continue
            if part == "*":
                if isinstance(obj, list):
                    nxt += [(path + (i,), v) for i, v in enumerate(obj)]
            elif hasattr(obj, part):
                nxt.append((path + (part,), getattr(obj, part)))
        results = nxt
    return [(p, v) for p, v in results if isinstance(v, list) or v is None]
