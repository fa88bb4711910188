"""What a Monte Carlo study varies: the ``--vary`` SPEC (a YAML mapping or ``key=value`` words).

Every key takes one value written the same way in both forms (units allowed: ``m mm um µm nm``,
``s ms us µs``, ``N kN``, ``kg g``, ``%``; a bare number is SI):

    X          fixed at X
    ±T, +-T    uniform in nominal ± T (per component for the vector keys)
    ±P%        uniform in nominal × (1 ± P/100) (only keys whose nominal is not zero)
    A..B       uniform in [A, B]
    a|b|c      one of the listed values, equally likely

Keys (nominal in brackets: the machine's value at the spec path a key draws, ``KEYS``' ``path``; a drawn value
is checked as the machine checks that field):

    anchor             base and plate joint positions, per axis per physical joint [0 offset]
    leg_offset         the length sensor's zero, per leg [0]
    sensor_resolution  metres per count [sensors.resolution]
    sensor_noise       σ of white Gaussian noise on each reading, m [sensors.noise]
    latency            sample | computation | none [controller.latency]
    latency_jitter     the largest lag of a tick's sampling instant, s (per tick uniform in [0, J]) [0]
    actuator_lag       actuator time constant, s [actuators.time_constant]
    force_limit        actuator force limit, N [actuators.max_force, else the platform's legs.max_force]
    plate_mass         the plate's own total mass, kg [the platform's] (its inertia scales alike)
    plate_com          the plate's centre of mass offset, per axis, m [0]
    gain_scale         factor on every PID gain [controller.gain_scale]
    sample_period      controller sample period, s [controller.period] (the gains stay those designed for the
                       nominal)
    payload            a point mass on the plate, kg [payload.mass] (as ``size --payload``)
    payload_position   where that payload sits in the plate frame T, m [payload.position]; ``X,Y,Z`` fixes it
                       (as ``size --payload-com``), ±T draws each component in ±T

The keys ``payload_mass`` and ``payload_com`` of earlier versions set the plate's own mass and centre of
mass (not an added payload); they are refused with a message naming ``plate_mass``/``plate_com`` and
``payload``/``payload_position``.

``sensor_noise`` and ``latency_jitter`` set the size of per-tick random processes (drawn from the run's
seed); the other keys are drawn once per run.
"""

from __future__ import annotations

import difflib
from dataclasses import dataclass, field
from pathlib import Path
from typing import NamedTuple

from stewart_drake.core.yamlio import compose, read_yaml_text
from stewart_drake.errors import SpecError, YamlError, short_text
from stewart_drake.spec.quantity import parse_choice, parse_number, parse_quantity, parse_vector


class VaryKey(NamedTuple):
    """One ``--vary`` key: its quantity ``dimension`` (``mode``: a latency mode), ``length`` (0 for a scalar, 3 or 6
    components, ``anchors`` for one offset per physical joint), ``zero_nominal`` (±P% refused as read; a key with a ``path``
    is checked against the machine's value there, ``study.check_study``) and ``path``: the
    machine's spec path it draws (its nominal is the machine's value there, a drawn value is checked as the
    machine checks that field), or None for the plant's own geometry and the sensor's per-run processes."""

    dimension: str
    length: int | str
    zero_nominal: bool
    path: str | None = None


# The one table of what a study can vary, in draw order (a new key drawn from a machine field is one row here).
KEYS = {
    "anchor": VaryKey("length", "anchors", True),
    "leg_offset": VaryKey("length", 6, True),
    "sensor_resolution": VaryKey("length", 0, False, "sensors.resolution"),
    "sensor_noise": VaryKey("length", 0, True, "sensors.noise"),
    "latency": VaryKey("mode", 0, False, "controller.latency"),
    "latency_jitter": VaryKey("time", 0, True),
    "actuator_lag": VaryKey("time", 0, False, "actuators.time_constant"),
    "force_limit": VaryKey("force", 0, False, "actuators.max_force"),
    "plate_mass": VaryKey("mass", 0, False),
    "plate_com": VaryKey("length", 3, True),
    "gain_scale": VaryKey("ratio", 0, False, "controller.gain_scale"),
    "sample_period": VaryKey("time", 0, False, "controller.period"),
    "payload": VaryKey("mass", 0, True, "payload.mass"),
    "payload_position": VaryKey("length", 3, True, "payload.position"),
}
# Keys of earlier versions whose names said something else than what they varied: refused, naming the keys
# that replace them (a study written for the old names must not run with another meaning).
RENAMED = {
    "payload_mass": "it set the plate's own total mass: use plate_mass for that, or payload=KG (with "
    "payload_position=X,Y,Z) for a mass added to the plate",
    "payload_com": "it moved the plate's own centre of mass: use plate_com for that, or payload_position for "
    "where an added payload sits",
}
# Keys that configure a per-tick process: a fixed value only.
PROCESS_KEYS = ("sensor_noise", "latency_jitter")
LATENCY_MODES = ("sample", "computation", "none")


@dataclass(frozen=True)
class Distribution:
    """One key's law. ``kind``: ``fixed`` (value), ``plusminus`` (nominal ± half_width), ``relative``
    (nominal × (1 ± half_width)), ``uniform`` (low..high), ``choice`` (values)."""

    kind: str
    values: tuple = ()
    text: str = ""


@dataclass(frozen=True)
class VarySpec:
    """The parsed SPEC: ``{key: Distribution}`` for the keys given (others stay nominal)."""

    laws: dict = field(default_factory=dict)
    source: str = ""

    def to_dict(self) -> dict:
        """``{key: text as the user wrote it}``: the SPEC in a form that ``parse_spec`` reads back."""
        return {k: d.text for k, d in self.laws.items()}


def _where(source: str, line: int | None) -> str:
    return f"{source}:{line}" if line else source


def _number(text: str, key: str, where: str) -> float:
    return parse_number(text, KEYS[key][0], f"{where}: {key}", error=SpecError)


def parse_value(key: str, text: str, where: str = "--vary") -> Distribution:
    """The ``Distribution`` of ``key`` written ``text`` (see the module docstring)."""
    text = str(text).strip()
    dim, length, zero_nominal, _ = KEYS[key]
    at = f"{where}: {key}"
    if dim == "mode":
        modes = tuple(m.strip() for m in text.split("|"))
        for m in modes:
            parse_choice(m, LATENCY_MODES, f"{where}: latency", error=SpecError)
        return Distribution("choice" if len(modes) > 1 else "fixed", modes if len(modes) > 1 else (modes[0],), text)
    if key in PROCESS_KEYS:
        v = _number(text, key, where)
        if v < 0:
            raise SpecError(SpecError.NEGATIVE_PROCESS.format(where=where, key=key, text=text))
        return Distribution("fixed", (v,), text)
    # a key drawn about a machine field is checked against the machine's value (study.check_study)
    if zero_nominal and KEYS[key].path is None and text.startswith(("±", "+-")) and text.endswith("%"):
        raise SpecError(SpecError.PERCENT_OF_ZERO.format(where=where, key=key, text=text))
    if length == 3 and "," in text:  # X,Y,Z: a fixed vector
        if text.count(",") != 2:
            raise SpecError(SpecError.VECTOR_3.format(where=where, key=key, text=text))
        return Distribution("fixed", parse_vector(text, dim, 3, at, error=SpecError), text)
    q = parse_quantity(text, dim, at, error=SpecError, forms=_FORMS)
    return Distribution(_KIND[q.kind], q.values, text)


# the quantity grammar's forms a --vary value may take, and the Distribution kind of each
_FORMS = ("value", "plusminus", "relative", "range", "choice")
_KIND = {"value": "fixed", "plusminus": "plusminus", "relative": "relative", "range": "uniform", "choice": "choice"}


def check_key(key, where: str) -> None:
    """``SpecError`` unless ``key`` is one of ``KEYS``: a renamed key says what it meant and what to use, an
    unknown one the nearest key."""
    if not isinstance(key, str):
        raise SpecError(SpecError.KEY_NOT_TEXT.format(where=where, key=short_text(key)))
    if key in RENAMED:
        raise SpecError(SpecError.RENAMED.format(where=where, key=key, why=RENAMED[key]))
    if key not in KEYS:
        near = difflib.get_close_matches(key, KEYS, n=1)
        hint = f" (did you mean {near[0]!r}?)" if near else f" (keys: {', '.join(KEYS)})"
        raise SpecError(SpecError.UNKNOWN_KEY.format(where=where, key=key, hint=hint))


def _check_vector(key: str, d: Distribution, where: str) -> None:
    if KEYS[key][1] and d.kind not in ("plusminus", "fixed"):
        raise SpecError(SpecError.VECTOR_LAW.format(where=where, key=key, text=d.text))


def parse_spec(words, where: str = "--vary") -> VarySpec:
    """A ``VarySpec`` from ``key=value`` words (a list of strings, or one string split at whitespace)
    or, when the only word names an existing ``.yaml``/``.yml`` file, from that YAML mapping; messages name the
    words ``where`` (the option or parameter) and a file's line."""
    if isinstance(words, str):
        words = words.split()
    words = list(words)
    if len(words) == 1 and words[0].endswith((".yaml", ".yml")):
        return _parse_yaml(Path(words[0]), where)
    laws = {}
    for w in words:
        if "=" not in w:
            raise SpecError(SpecError.NOT_KEY_VALUE.format(where=where, value=w))
        key, value = w.split("=", 1)
        key = key.strip()
        check_key(key, where)
        d = parse_value(key, value, where)
        _check_vector(key, d, where)
        laws[key] = d
    return VarySpec(laws, " ".join(words))


MAX_SPEC_BYTES = 100_000


def _parse_yaml(path: Path, where: str) -> VarySpec:
    import yaml

    if not path.exists():
        raise SpecError(SpecError.MISSING_FILE.format(where=where, path=str(path)))
    # read once, bounded (a spec is a few lines), with the platform files' safe composer (nesting bounded)
    text, shown = read_yaml_text(path, f"{where} spec", limit=MAX_SPEC_BYTES)
    try:
        node = compose(text, shown)
    except YamlError as e:
        raise SpecError(str(e)) from None
    if node is None or not isinstance(node, yaml.MappingNode):
        raise SpecError(SpecError.NOT_MAPPING.format(path=path))
    laws, first = {}, {}
    for k, v in node.value:
        where = _where(str(path), k.start_mark.line + 1)
        if not isinstance(k, yaml.ScalarNode):  # a list or mapping as a key ([a, b]: 1)
            raise SpecError(
                SpecError.KEY_NOT_TEXT.format(
                    where=where, key=short_text(" ".join(text[k.start_mark.index : k.end_mark.index].split()))
                )
            )
        if k.value in first:  # YAML keeps the last silently: refused
            raise SpecError(SpecError.DUPLICATE.format(where=where, key=k.value, first=first[k.value]))
        first[k.value] = k.start_mark.line + 1
        if not isinstance(v, yaml.ScalarNode):
            raise SpecError(SpecError.NOT_SCALAR.format(where=where, key=k.value))
        check_key(k.value, where)
        d = parse_value(k.value, v.value, where)
        _check_vector(k.value, d, where)
        laws[k.value] = d
    return VarySpec(laws, str(path))


def spec_from_dict(d: dict, source: str = "study.json") -> VarySpec:
    """The ``VarySpec`` of ``VarySpec.to_dict()`` (as stored with a study)."""
    laws = {}
    for k, v in d.items():
        check_key(k, source)
        laws[k] = parse_value(k, v, source)
    return VarySpec(laws, source)
