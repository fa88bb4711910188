"""A ``Machine`` from YAML, a mapping, a preset or a ``Platform``, with overrides by spec path.

A machine file is a platform file with sections beside the platform's keys (``controller``, ``firmware``,
``sensors``, ``actuators``, ``payload``, ``run``, ``motions``, ``requirements``), or holds the platform under
``platform:`` (an inline mapping, a preset name or a platform file's path, relative to the machine file). A
plain platform file is a machine with every other section at its defaults. Values follow the quantity
grammar (``period: 0.5ms``; a bare number is SI); errors name the file, line and spec path. Overrides are
``PATH=VALUE`` words or a ``{path: value}`` mapping (``controller.period=0.5ms``).
"""

from __future__ import annotations

import copy
import dataclasses
import difflib
from collections.abc import Iterable, Mapping
from pathlib import Path

import yaml

from stewart_drake.core.geometry import (
    PRESETS,
    Platform,
    PlatformConfig,
    check_platform_fields,
    load_platform,
    platform_from_file_config,
)
from stewart_drake.core.platform_file import platform_document
from stewart_drake.core.trajectory import Trajectory
from stewart_drake.core.yamlio import compose, load_node_typed, read_yaml_text
from stewart_drake.errors import MachineError, QuantityError, StewartError
from stewart_drake.spec.machine import FIELDS, GAIN_WORDS, SECTIONS, Gains, Machine, check_motion
from stewart_drake.spec.quantity import parse_choice, parse_number, parse_vector

MACHINE_KEYS = (*SECTIONS, "platform", "motions", "requirements", "calibration")
# the top-level keys that make a YAML file a machine file rather than a platform file
_MACHINE_ONLY = (*SECTIONS, "platform", "motions", "requirements")
PLATFORM_KEYS = tuple(f.name for f in dataclasses.fields(PlatformConfig))
_TRUE, _FALSE = ("true", "yes", "on"), ("false", "no", "off")


def parse_field(path: str, value, where: str | None = None):
    """The SI value of spec path ``path`` written ``value`` (text in the quantity grammar, a number in SI,
    a bool, None for an optional field, a mapping for ``controller.gains``); ``where`` prefixes messages
    (default the path). Raises ``MachineError`` or ``QuantityError``."""
    if path not in FIELDS:
        raise MachineError(MachineError.UNKNOWN_KEY.format(where="", path=path, hint=_hint(path, FIELDS)))
    kind = FIELDS[path]
    where = where or path
    optional = kind[0].endswith("?") if isinstance(kind, tuple) else kind.endswith("?")
    if value is None and not optional:
        raise QuantityError(QuantityError.NUMBER.format(where=where, text="null", allowed="a value"))
    if isinstance(kind, tuple):
        word, choices = kind
        if word.endswith("?") and _is_null(value):
            return None
        return parse_choice(value, choices, where)
    if kind.endswith("?"):
        if _is_null(value):
            return None
        kind = kind[:-1]
    if kind == "text":
        return str(value).strip()
    if kind == "bool":
        if isinstance(value, bool):
            return value
        s = str(value).strip().lower()
        if s in _TRUE + _FALSE:
            return s in _TRUE
        raise QuantityError(QuantityError.CHOICE.format(where=where, text=str(value), valid="true, false"))
    if kind == "int":
        s = str(value).strip()
        if isinstance(value, bool) or not s.lstrip("+-").isdigit():
            raise QuantityError(QuantityError.NUMBER.format(where=where, text=s, allowed="an integer"))
        return int(s)
    if kind == "length3":
        return parse_vector(value, "length", 3, where)
    if kind == "gains":
        if isinstance(value, Gains):
            return value
        if isinstance(value, Mapping):
            extra = set(value) - {"kp", "ki", "kd", "kv"}
            if extra or len(value) != 4:
                raise MachineError(
                    MachineError.RANGE.format(path=where, rule="design, tune or {kp, ki, kd, kv}", value=dict(value))
                )
            return Gains(**{k: parse_number(v, "ratio", f"{where}.{k}") for k, v in value.items()})
        return parse_choice(value, GAIN_WORDS, where)
    return parse_number(value, kind, where)


def apply_overrides(machine: Machine, overrides) -> Machine:
    """``machine`` with the fields of ``overrides`` replaced: ``PATH=VALUE`` words or a ``{path: value}``
    mapping (values as ``parse_field`` reads them; a path given twice takes its last value). The fields of a
    section are replaced together, so that they are checked as a whole (``firmware.word_bits=24`` with
    ``firmware.trig=exact``)."""
    values, texts = {}, {}
    for path, value in _override_items(overrides):
        values[path], texts[path] = parse_field(path, value), str(value)
    sections: dict = {}
    for path, value in values.items():
        section, name = path.split(".", 1)
        sections.setdefault(section, {})[name] = value
    for section, fields in sections.items():
        try:
            new = dataclasses.replace(getattr(machine, section), **fields)
        except MachineError as e:
            path = str(e).split(" ", 1)[0]
            raise MachineError(_as_written(e, texts[path]) if path in texts else str(e)) from None
        machine = dataclasses.replace(machine, **{section: new})
    return machine


def _override_items(overrides) -> list:
    if isinstance(overrides, Mapping):
        return list(overrides.items())
    if isinstance(overrides, str):
        overrides = (overrides,)
    out = []
    for w in overrides or ():
        if "=" not in str(w):
            raise MachineError(MachineError.OVERRIDE.format(text=str(w)))
        path, value = str(w).split("=", 1)
        out.append((path.strip(), value.strip()))
    return out


def _as_written(e: MachineError, text: str) -> str:
    """The range error's message with the value as the user wrote it."""
    head, sep, _ = str(e).rpartition(", got ")
    return f"{head}, got {text}" if sep else str(e)


def load_machine(source: Machine | Platform | Mapping | str | Path, overrides: Iterable[str] | Mapping = ()) -> Machine:
    """A ``Machine`` from a machine or platform file (path), a preset name, a mapping (a machine file's
    content), a ``Platform`` (every other section at its defaults) or a ``Machine``; then ``overrides``
    (``PATH=VALUE`` words or a ``{path: value}`` mapping) applied in order.

    Raises:
        MachineError, QuantityError, YamlError, GeometryError: naming the file, line and spec path.
    """
    if isinstance(source, Machine):
        machine = source
    elif isinstance(source, Platform):
        machine = Machine(source)
    elif isinstance(source, Mapping):  # a machine file's content; "platform" may hold a Platform
        rest = dict(source)
        given = rest.pop("platform") if isinstance(rest.get("platform"), Platform) else None
        text = yaml.safe_dump(_plain(rest), sort_keys=False, allow_unicode=True)
        machine = _from_text(text, "machine mapping", Path.cwd(), platform=given)
    elif isinstance(source, (str, Path)):
        s = str(source)
        if s in PRESETS:
            machine = Machine(load_platform(s), platform_source=s)
        elif not Path(s).exists():  # the platform loader's message: an unknown preset or a missing file
            machine = Machine(load_platform(s))
        else:
            text, shown = read_yaml_text(s, "machine")
            machine = _from_text(text, shown, Path(s).parent, stem=Path(s).stem)
    else:
        raise MachineError(MachineError.SOURCE.format(got=type(source).__name__))
    return apply_overrides(machine, overrides)


def is_machine_file(source) -> bool:
    """Whether ``source`` (a path, or a ``--platform`` value) names a file with machine sections beside the
    platform's (a plain platform file, a preset or an object: False)."""
    if not isinstance(source, (str, Path)) or str(source) in PRESETS or not Path(source).is_file():
        return False
    try:  # a peek at the top-level keys; a file that does not parse is left to the loader's message
        keys = yaml.safe_load(Path(source).read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, yaml.YAMLError):
        return False
    if not isinstance(keys, dict):
        return False
    # a platform file's calibration is its record (a mapping); a machine's names a measurements file
    return any(k in _MACHINE_ONLY or (k == "calibration" and not isinstance(v, dict)) for k, v in keys.items())


def _plain(value):
    if isinstance(value, Mapping):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if hasattr(value, "tolist"):
        return value.tolist()
    if isinstance(value, Path):
        return str(value)
    return value


def _line(node) -> int:
    return node.start_mark.line + 1


def _hint(key: str, valid) -> str:
    near = difflib.get_close_matches(key, list(valid), n=1)
    return f" (did you mean {near[0]!r}?)" if near else f" (keys: {', '.join(valid)})"


def _scalar(node):
    """A scalar node's value: None, a bool, else its text."""
    if node.tag.endswith(":null"):
        return None
    if node.tag.endswith(":bool"):
        return node.value.lower() in _TRUE + ("y",)
    return node.value


def _is_null(value) -> bool:
    return value is None or (isinstance(value, str) and value.strip().lower() in ("none", "null", "~", ""))


def _describe(node) -> str:
    return {yaml.MappingNode: "a mapping", yaml.SequenceNode: "a list"}.get(
        type(node), repr(getattr(node, "value", ""))
    )


def _from_text(text: str, shown: str, base: Path, stem: str = "", platform: Platform | None = None) -> Machine:
    root = compose(text, shown)
    if platform is not None and root is None:  # {"platform": Platform} alone
        return Machine(platform)
    if not isinstance(root, yaml.MappingNode):
        got = "an empty file" if root is None else _describe(root)
        raise MachineError(MachineError.NOT_MAPPING.format(where=f"{shown}: ", path="a machine file", got=got))
    fields, platform_pairs, seen = {}, [], {}
    platform_node = None
    for k, v in root.value:
        at = f"{shown}:{_line(k)}: "
        if not isinstance(k, yaml.ScalarNode):
            raise MachineError(MachineError.KEY.format(where=at, got=_describe(k)))
        key = k.value
        if key in seen:
            raise MachineError(
                MachineError.RANGE.format(path=at + key, rule=f"given once (first on line {seen[key]})", value="twice")
            )
        seen[key] = _line(k)
        if key in SECTIONS:
            fields[key] = _section(key, v, shown)
        elif key == "platform":
            platform_node = v
        elif key == "motions":
            items = v.value if isinstance(v, yaml.SequenceNode) else [v]
            for i, item in enumerate(items):
                if not isinstance(item, yaml.ScalarNode):
                    raise MachineError(
                        MachineError.MOTION.format(path=f"{at}motions item {i + 1}", value=_describe(item))
                    )
                check_motion(f"{shown}:{_line(item)}: motions item {i + 1}", item.value)
            fields["motions"] = tuple(_relative(item.value, base) for item in items)
        elif key == "calibration" and isinstance(v, yaml.MappingNode):  # a calibrated platform file's record
            platform_pairs.append((k, v))
        elif key in ("requirements", "calibration"):
            if not isinstance(v, yaml.ScalarNode):
                raise MachineError(
                    MachineError.RANGE.format(path=at + key, rule="a file path or null", value=_describe(v))
                )
            fields[key] = None if _scalar(v) is None else _relative(v.value, base)
        elif key in PLATFORM_KEYS:
            platform_pairs.append((k, v))
        else:
            raise MachineError(
                MachineError.UNKNOWN_KEY.format(
                    where=at, path=key, hint=_hint(key, dict.fromkeys(MACHINE_KEYS + PLATFORM_KEYS))
                )
            )
    if platform is not None:
        if platform_pairs:
            k = platform_pairs[0][0]
            raise MachineError(
                MachineError.UNKNOWN_KEY.format(
                    where=f"{shown}:{_line(k)}: ", path=k.value, hint=" (the platform is given as a Platform)"
                )
            )
        return Machine(platform, **fields)
    if platform_node is not None and platform_pairs:
        k = platform_pairs[0][0]
        raise MachineError(
            MachineError.UNKNOWN_KEY.format(
                where=f"{shown}:{_line(k)}: ",
                path=k.value,
                hint=" (the platform is given under platform:, its keys belong there)",
            )
        )
    if platform_node is None:
        if not platform_pairs:
            raise MachineError(MachineError.PLATFORM.format(where=f"{shown}: ", got="nothing"))
        platform_node = yaml.MappingNode("tag:yaml.org,2002:map", platform_pairs, root.start_mark, root.end_mark)
    if isinstance(platform_node, yaml.ScalarNode):
        src = platform_node.value
        src = src if src in PRESETS else _relative(src, base)
        try:
            platform, source = load_platform(src), src
        except StewartError as e:  # the same error, located in the machine file
            located = copy.copy(e)
            located.args = (f"{shown}:{_line(platform_node)}: platform: {e}",)
            raise located from None
    elif isinstance(platform_node, yaml.MappingNode):
        platform, source = _inline_platform(platform_node, shown, stem), None
    else:
        raise MachineError(MachineError.PLATFORM.format(where=f"{shown}:{_line(platform_node)}: ", got="a list"))
    return Machine(platform, platform_source=source, **fields)


def _relative(path: str, base: Path) -> str:
    if path in ("seed", "rotating") or Path(path).is_absolute():
        return path
    return str(base / path)


def _inline_platform(node, shown: str, stem: str) -> Platform:
    cfg = load_node_typed(node, PlatformConfig, "platform", shown, check_platform_fields(shown))
    if not cfg.name:
        cfg.name = stem or "machine"
    return platform_from_file_config(cfg, shown)


def _section(name: str, node, shown: str):
    if not isinstance(node, yaml.MappingNode):
        raise MachineError(
            MachineError.NOT_MAPPING.format(where=f"{shown}:{_line(node)}: ", path=name, got=_describe(node))
        )
    tp = SECTIONS[name]
    valid = [f.name for f in dataclasses.fields(tp)]
    values, lines, texts = {}, {}, {}
    for k, v in node.value:
        path = f"{name}.{k.value}"
        where = f"{shown}:{_line(k)}: {path}"
        if k.value not in valid:
            raise MachineError(
                MachineError.UNKNOWN_KEY.format(where=f"{shown}:{_line(k)}: ", path=path, hint=_hint(k.value, valid))
            )
        if isinstance(v, yaml.ScalarNode):
            raw = _scalar(v)
        elif isinstance(v, yaml.SequenceNode) and all(isinstance(c, yaml.ScalarNode) for c in v.value):
            raw = [c.value for c in v.value]
        elif isinstance(v, yaml.MappingNode) and all(isinstance(c, yaml.ScalarNode) for _, c in v.value):
            raw = {kk.value: vv.value for kk, vv in v.value}
        else:
            raise MachineError(MachineError.NOT_MAPPING.format(where=f"{shown}:{_line(v)}: ", path=path, got="nested"))
        values[k.value] = parse_field(path, raw, where)
        lines[path], texts[path] = _line(k), raw if isinstance(raw, str) else str(raw)
    try:
        return tp(**values)
    except MachineError as e:
        path = str(e).split(" ", 1)[0]
        at = f"{shown}:{lines[path]}: " if path in lines else f"{shown}: "
        raise MachineError(at + _as_written(e, texts.get(path, ""))) from None


def machine_document(machine: Machine) -> dict:
    """The machine as plain data (SI numbers): what ``machine_yaml`` writes and ``load_machine`` reads."""
    doc = {"platform": platform_document(machine.platform)}
    for name in SECTIONS:
        sec = getattr(machine, name)
        d = {}
        for f in dataclasses.fields(sec):
            v = getattr(sec, f.name)
            d[f.name] = dataclasses.asdict(v) if isinstance(v, Gains) else (list(v) if isinstance(v, tuple) else v)
        doc[name] = d
    for i, m in enumerate(machine.motions):
        if isinstance(m, Trajectory):
            raise MachineError(
                MachineError.RANGE.format(path=f"motions item {i + 1}", rule="a name or a path to write", value=m.name)
            )
    doc["motions"] = list(machine.motions)
    doc["requirements"] = machine.requirements
    doc["calibration"] = machine.calibration
    return _plain(doc)


def machine_yaml(machine: Machine) -> str:
    """The machine as a YAML document (``load_machine`` reads it back to an equal machine)."""
    return yaml.safe_dump(machine_document(machine), sort_keys=False, allow_unicode=True)


def machine_paths() -> Iterable[str]:
    """Every spec path an override may set."""
    return tuple(FIELDS)
