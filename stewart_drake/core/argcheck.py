"""Argument checks for arrays of poses, lengths and vectors: one shape checker, one finiteness checker
and one "first offending sample" finder, so that every function reports bad input the same way.

Shape errors read like scipy's (``Expected poses to have shape (..., 6), got (5,)``); a bad sample is
named by its batch index counted from 1 (``pose 3 is not finite: [...]``). Messages are the templates
in ``stewart_drake.errors``. Plain numpy.
"""

from __future__ import annotations

import numpy as np

from stewart_drake.errors import NOT_FINITE_SAMPLE, SHAPE, NotFiniteError, ShapeError, counted


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
    a = np.asarray(value, dtype=float)
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
