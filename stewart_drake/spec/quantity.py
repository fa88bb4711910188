"""The one grammar of quantities in files and options.

A value is written as one of:

    X          a number with its unit (``0.5mm``, ``30um``, ``2ms``, ``8Hz``, ``45deg``, ``4kN``, ``150kg``);
               a bare number is SI (metres, seconds, radians, newtons, kilograms, hertz)
    ±T, +-T    nominal ± T
    ±P%        nominal × (1 ± P/100)
    A..B       the interval [A, B]
    a|b|c      one of the listed values (numbers with units, or words of a closed set)
    X,Y,Z      a vector (or a YAML list of numbers)

Decimal units scale exactly (``10um`` is 1e-05, the float nearest to the decimal, not 10 × 1e-06);
degrees scale by π/180. Every parser takes ``where`` (the field's spec path or the option as the user
wrote it) and names it with the text as written when the text cannot be read; ``error`` is the
``StewartError`` subclass raised (a caller keeps its own class), the message templates are
``QuantityError``'s.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from decimal import Decimal, DecimalException

from stewart_drake.errors import QuantityError

# unit -> (power of ten, extra factor) of the SI unit of each dimension; "" is a bare number (SI)
_DEG = math.pi / 180
UNITS = {
    "length": {"": (0, 1), "m": (0, 1), "mm": (-3, 1), "um": (-6, 1), "µm": (-6, 1), "nm": (-9, 1)},
    "time": {"": (0, 1), "s": (0, 1), "ms": (-3, 1), "us": (-6, 1), "µs": (-6, 1)},
    "angle": {"": (0, 1), "rad": (0, 1), "mrad": (-3, 1), "urad": (-6, 1), "µrad": (-6, 1), "deg": (0, _DEG)},
    "force": {"": (0, 1), "N": (0, 1), "kN": (3, 1)},
    "mass": {"": (0, 1), "kg": (0, 1), "g": (-3, 1)},
    "frequency": {"": (0, 1), "Hz": (0, 1), "kHz": (3, 1)},
    "speed": {"": (0, 1), "m/s": (0, 1), "mm/s": (-3, 1)},
    "stiffness": {"": (0, 1), "N/m": (0, 1), "kN/m": (3, 1), "N/mm": (3, 1)},
    "pressure": {"": (0, 1), "Pa": (0, 1), "kPa": (3, 1), "MPa": (6, 1), "GPa": (9, 1), "bar": (5, 1)},
    "ratio": {"": (0, 1)},
    "count": {"": (0, 1)},
}
DIMENSIONS = tuple(UNITS)
NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
_VALUE = re.compile(rf"\s*({NUMBER})\s*([a-zA-Zµ/%]*)\s*")


@dataclass(frozen=True)
class Quantity:
    """One parsed value. ``kind``: ``value`` (``values`` = (x,)), ``plusminus`` ((half_width,)), ``relative``
    ((fraction,)), ``range`` ((low, high)), ``choice`` (the values), ``vector`` (the components); values in
    SI; ``text``: as written."""

    kind: str
    values: tuple
    text: str


def _error(error, template: str, **fields):
    """``error`` with ``template`` filled in; ``template`` is kept on it (callers that keep their own
    messages tell the failures apart by it)."""
    e = error(template.format(**fields))
    e.template = template
    return e


def allowed_units(dimension: str) -> str:
    """The units of ``dimension`` as a message lists them (``"none"`` for a plain number)."""
    return ", ".join(u for u in UNITS[dimension] if u) or "none"


def _split(text, dimension: str, where: str, error, bare: float) -> float:
    units = UNITS[dimension]
    m = _VALUE.fullmatch(text)
    if not m or m.group(2) not in units:
        raise _error(error, QuantityError.NUMBER, where=where, text=text, allowed=allowed_units(dimension))
    power, factor = units[m.group(2)]
    if not m.group(2):
        factor = bare
    try:
        d = Decimal(m.group(1)).scaleb(power)
        v = float(d) if factor == 1 else float(d) * factor
    except (DecimalException, OverflowError):  # an exponent beyond Decimal's context (1e999999999999999999)
        v = math.inf
    if not math.isfinite(v):
        raise _error(error, QuantityError.NOT_FINITE, where=where, text=text)
    return v + 0.0  # -0 is 0


def parse_number(text, dimension: str, where: str, *, error=QuantityError, bare: float = 1.0) -> float:
    """The SI value of one number with an optional unit of ``dimension`` (``bare``: the factor of a number
    written without a unit, 1 for SI); a YAML or Python number is taken as SI. Raises ``error``."""
    if isinstance(text, bool):
        raise _error(error, QuantityError.NUMBER, where=where, text=str(text), allowed=allowed_units(dimension))
    if isinstance(text, (int, float)):
        v = float(text) * bare
        if not math.isfinite(v):
            raise _error(error, QuantityError.NOT_FINITE, where=where, text=str(text))
        return v + 0.0
    return _split(str(text), dimension, where, error, bare)


def parse_choice(text, choices, where: str, *, error=QuantityError) -> str:
    """One word of ``choices``, or ``error`` naming ``where``, the text and the choices."""
    word = str(text).strip()
    if word not in choices:
        raise _error(error, QuantityError.CHOICE, where=where, text=str(text), valid=", ".join(choices))
    return word


def parse_vector(value, dimension: str, n: int, where: str, *, error=QuantityError, bare: float = 1.0) -> tuple:
    """``n`` numbers of ``dimension`` written ``X,Y,Z`` or as a list; SI floats."""
    parts = value if isinstance(value, (list, tuple)) else str(value).split(",")
    if len(parts) != n:
        raise _error(error, QuantityError.VECTOR, where=where, text=_shown(value), n=n)
    return tuple(parse_number(p, dimension, where, error=error, bare=bare) for p in parts)


def parse_quantity(
    text,
    dimension: str,
    where: str,
    *,
    forms=("value", "plusminus", "relative", "range", "choice"),
    error=QuantityError,
    bare: float = 1.0,
) -> Quantity:
    """The ``Quantity`` written ``text`` (see the module docstring), limited to the ``forms`` given.

    Raises:
        ``error``: unreadable text, a form not allowed here, a negative half-width, a percentage outside
        [0, 100) or a range whose low end is above its high end; the message names ``where`` and the text.
    """
    if isinstance(text, (int, float)) and not isinstance(text, bool):
        return Quantity("value", (parse_number(text, dimension, where, error=error, bare=bare),), str(text))
    if isinstance(text, (list, tuple)):
        return Quantity("vector", parse_vector(text, dimension, len(text), where, error=error, bare=bare), str(text))
    s = str(text).strip()

    def allowed(form):
        if form not in forms:
            raise _error(error, QuantityError.FORM, where=where, text=s, form=_FORMS[form])

    if s.startswith(("±", "+-")):
        body = (s[1:] if s.startswith("±") else s[2:]).strip()
        if body.endswith("%"):
            allowed("relative")
            p = parse_number(body[:-1], "ratio", where, error=error) / 100
            if not 0 <= p < 1:
                raise _error(error, QuantityError.PERCENT_RANGE, where=where, text=s)
            return Quantity("relative", (p,), s)
        allowed("plusminus")
        w = parse_number(body, dimension, where, error=error, bare=bare)
        if w < 0:
            raise _error(error, QuantityError.HALF_WIDTH, where=where, text=s)
        return Quantity("plusminus", (w,), s)
    if ".." in s:
        allowed("range")
        lo, hi = (parse_number(p, dimension, where, error=error, bare=bare) for p in s.split("..", 1))
        if not lo <= hi:
            raise _error(error, QuantityError.RANGE_ORDER, where=where, text=s)
        return Quantity("range", (lo, hi), s)
    if "|" in s:
        allowed("choice")
        return Quantity(
            "choice", tuple(parse_number(p, dimension, where, error=error, bare=bare) for p in s.split("|")), s
        )
    if "," in s:
        allowed("vector")
        return Quantity("vector", parse_vector(s, dimension, s.count(",") + 1, where, error=error, bare=bare), s)
    return Quantity("value", (parse_number(s, dimension, where, error=error, bare=bare),), s)


_FORMS = {
    "plusminus": "a tolerance ±T",
    "relative": "a percentage ±P%",
    "range": "a range A..B",
    "choice": "a choice a|b",
    "vector": "a vector X,Y,Z",
    "value": "a single value",
}


def _shown(value) -> str:
    return ",".join(str(v) for v in value) if isinstance(value, (list, tuple)) else str(value)
