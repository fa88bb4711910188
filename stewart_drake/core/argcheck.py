"""Argument checks for arrays of poses, lengths and vectors: one shape checker, one finiteness checker
and one "first offending sample" finder, so that every function reports bad input the same way.

Shape errors read like scipy's (``Expected poses to have shape (..., 6), got (5,)``); a bad sample is
named by its batch index counted from 1 (``pose 3 is not finite: [...]``). Messages are the templates
in ``stewart_drake.errors``. Plain numpy.
"""

from __future__ import annotations

import contextlib
import contextvars
import math
import os

import numpy as np

from stewart_drake.errors import NOT_FINITE_SAMPLE, SHAPE, ArgumentError, NotFiniteError, ShapeError, counted


def first_index(mask) -> tuple[int, ...] | None:
    """The index of the first True element of ``mask`` in C order, as a tuple of ints (``()`` for a 0-d
    mask); None when no element is True."""
    m = np.asarray(mask, dtype=bool)
    if not m.any():
        return None
    return tuple(int(i) for i in np.unravel_index(int(np.argmax(m)), m.shape))


def shape_text(shape) -> str:
    """A shape as in messages: ``(..., 6)`` for a trailing shape, ``(5,)`` for a concrete one."""
    return str(tuple(shape)).replace("Ellipsis", "...")


def check_shape(value, name: str, shape, error: type[Exception] = ShapeError) -> np.ndarray:
    """``value`` as a float array whose shape matches ``shape``; a leading ``...`` in ``shape`` stands
    for any batch dimensions (``(..., 6)``: poses; ``(..., 6, 3)``: anchor vectors). Raises ``error``
    with ``SHAPE`` (``Expected poses to have shape (..., 6), got (5,)``) otherwise."""
    a = as_real_array(value, name)
    shape = tuple(shape)
    if shape[:1] == (...,):
        tail = shape[1:]
        ok = a.shape[a.ndim - len(tail) :] == tail if a.ndim >= len(tail) else False
    else:
        ok = a.shape == shape
    if not ok:
        raise error(SHAPE.format(name=name, shape=shape_text(shape), got=shape_text(a.shape)))
    return a


def check_finite_samples(value, what: str, sample_ndim: int = 1, error: type[Exception] = NotFiniteError):
    """``value`` unchanged when every element is finite; else ``error`` naming the first sample (the
    last ``sample_ndim`` axes form one sample) with a non-finite element: ``{what} 3 is not finite: [...]``."""
    a = np.asarray(value)
    finite = np.isfinite(a)
    if finite.all():
        return value
    if sample_ndim:
        finite = finite.reshape(a.shape[: a.ndim - sample_ndim] + (-1,)).all(axis=-1)
    idx = first_index(~finite)
    raise error(NOT_FINITE_SAMPLE.format(what=what, index=counted(idx), values=a[idx].tolist()))


def as_poses(poses, name: str = "poses", what: str = "pose") -> np.ndarray:
    """``(..., 6)`` finite float poses [px, py, pz (m), a_x, a_y, a_z (rad)]; ``ShapeError`` or
    ``NotFiniteError`` naming the first bad pose otherwise."""
    q = check_shape(poses, name, (..., 6))
    check_finite_samples(q, what)
    return q


# ----------------------------------------------------------------------------------------------
# Scalar and typed arguments of the public API. Messages name the parameter as the API spells it
# (``max_iter``); while the command line runs (``cli_names``) the same checks name its flag (``--max-iter``).

_CLI_NAMES: contextvars.ContextVar[dict[str, str] | None] = contextvars.ContextVar("cli_names", default=None)


@contextlib.contextmanager
def cli_names(table: dict[str, str] | None = None):
    """Within this block, ``param(name)`` is the command line's flag for ``name``: ``table[name]``, else
    ``--`` + ``name`` with ``_`` written ``-``. The CLI's edge: the API's messages stay free of flags."""
    token = _CLI_NAMES.set(dict(table or {}))
    try:
        yield
    finally:
        _CLI_NAMES.reset(token)


def param(name: str) -> str:
    """How a message names the parameter ``name``: ``name`` itself, or its flag inside ``cli_names``."""
    table = _CLI_NAMES.get()
    if table is None:
        return name
    return table.get(name, "--" + name.replace("_", "-"))


def setting(name: str, value: str) -> str:
    """How a message tells the user to set ``name`` to ``value``: ``name='mm'`` in Python, ``--name mm`` on the
    command line."""
    shown = param(name)
    return f"{shown} {value}" if shown.startswith("--") else f"{shown}={value!r}"


def switch(name: str) -> str:
    """How a message tells the user to turn the option ``name`` on: ``name=True`` in Python, ``--name`` on the
    command line."""
    shown = param(name)
    return shown if shown.startswith("--") else f"{shown}=True"


def _shown(value) -> str:
    text = repr(value)
    return text if len(text) <= 80 else text[:77] + "..."


def as_real_array(value, name: str) -> np.ndarray:
    """``value`` as a float array. ``ArgumentError`` naming ``name`` for what is not real numbers: text,
    ``None``, objects, complex values (never cast silently), ragged lists."""
    if isinstance(value, (str, bytes)) or value is None:
        raise ArgumentError(ArgumentError.NOT_NUMBERS.format(name=name, value=_shown(value)))
    try:
        raw = np.asarray(value)
    except (TypeError, ValueError):
        raise ArgumentError(ArgumentError.NOT_NUMBERS.format(name=name, value=_shown(value))) from None
    if np.iscomplexobj(raw):
        raise ArgumentError(ArgumentError.COMPLEX.format(name=name, value=_shown(value)))
    if raw.dtype.kind not in "biuf":
        if raw.dtype.kind == "O":  # a list of numbers and arrays: numpy's float conversion decides
            try:
                return as_real_array(np.asarray(value, dtype=float), name)
            except (TypeError, ValueError):
                pass
        raise ArgumentError(ArgumentError.NOT_NUMBERS.format(name=name, value=_shown(value)))
    return raw.astype(float)


def as_real(value, name: str) -> float:
    """One real number (a Python or numpy scalar, or a 0-d array): ``ArgumentError`` naming ``name`` otherwise
    (text, ``None``, complex, an array of several values). Not checked for being finite. A Python or numpy
    real number is returned as it is (a value that prints as the user typed it keeps doing so)."""
    if isinstance(value, (bool, np.bool_, str, bytes)) or value is None:
        raise ArgumentError(ArgumentError.NOT_NUMBER.format(name=name, value=_shown(value)))
    if isinstance(value, (float, np.floating)) or (isinstance(value, (int, np.integer)) and abs(value) < 2**63):
        return value
    if isinstance(value, int):  # beyond int64: numpy's isfinite cannot take it
        try:
            return float(value)
        except OverflowError:
            return math.inf if value > 0 else -math.inf
    a = as_real_array(value, name)
    if a.shape != ():
        raise ArgumentError(ArgumentError.NOT_NUMBER.format(name=name, value=_shown(value)))
    return float(a)


def as_int(value, name: str, low: int | None = None, high: int | None = None) -> int:
    """A whole number in ``[low, high]`` (either bound may be None): Python or numpy integers, or floats
    with no fractional part; ``ArgumentError`` naming ``name`` and the value as given otherwise."""
    ok = not isinstance(value, bool) and isinstance(value, (int, np.integer))
    if not ok and isinstance(value, (float, np.floating)) and math.isfinite(value) and float(value).is_integer():
        ok = True
    if not ok or (low is not None and value < low) or (high is not None and value > high):
        bounds = (
            f" in {low}..{high}"
            if low is not None and high is not None
            else f" >= {low}"
            if low is not None
            else f" <= {high}"
            if high is not None
            else ""
        )
        raise ArgumentError(ArgumentError.NOT_INT.format(name=name, bounds=bounds, value=_shown(value)))
    return int(value)


def as_choice(value, name: str, choices) -> str:
    """``value`` when it is one of ``choices`` (strings); ``ArgumentError`` listing them otherwise."""
    if not isinstance(value, str) or value not in choices:
        raise ArgumentError(
            ArgumentError.CHOICE.format(name=name, value=_shown(value), choices=", ".join(map(repr, choices)))
        )
    return value


def check_path(value, name: str) -> str:
    """``value`` as a path string: text or an ``os.PathLike`` (not a number, ``None`` or text with a NUL
    character); ``ArgumentError`` naming ``name`` otherwise."""
    if isinstance(value, os.PathLike):
        value = os.fspath(value)
    if not isinstance(value, str) or not value or "\0" in value:
        raise ArgumentError(ArgumentError.NOT_TEXT.format(name=name, what="a path", value=_shown(value)))
    return value


def as_flag(value, name: str) -> bool:
    """A ``bool`` (Python or numpy); ``ArgumentError`` for anything else (``"no"`` is not False)."""
    if not isinstance(value, (bool, np.bool_)):
        raise ArgumentError(ArgumentError.NOT_BOOL.format(name=name, value=_shown(value)))
    return bool(value)
