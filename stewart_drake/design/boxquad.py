"""Exact extrema of a quadratic form over a symmetric box, vectorised.

max xᵀ Q x over |x_j| <= b_j: the maximum of a continuous function over a box is attained at a
Karush–Kuhn–Tucker point, i.e. at a point that is stationary within the relative interior of one of
the box's 3^d faces (each coordinate at −b_j, at +b_j, or free). On a face with free set F and fixed
values x_C the stationary point solves Q_FF x_F = −Q_FC x_C; it is a candidate if it lies in the box.
Enumerating all faces therefore gives the global maximum, whatever the sign pattern of Q (indefinite
forms included). When Q_FF is singular the form is constant along its null space, so the same value
is found again on a lower-dimensional face, which the enumeration also visits.
"""

from __future__ import annotations

import itertools

import numpy as np

REL_SINGULAR = 1e-13  # |det Q_FF| below this × (scale of Q)^|F|: the face's value is found on a smaller face


def box_quadratic_max(Q, b) -> tuple[np.ndarray, np.ndarray]:
    """``(value (...), argmax (..., d))``: max of xᵀ Q x over |x_j| <= b_j for ``(..., d, d)`` Q and
    ``(d,)`` non-negative half-widths b. Cost 3^d batched solves of size <= d."""
    Q = np.asarray(Q, dtype=float)
    Q = 0.5 * (Q + np.swapaxes(Q, -1, -2))
    b = np.asarray(b, dtype=float)
    d = b.shape[0]
    batch = Q.shape[:-2]
    best = np.full(batch, -np.inf)
    arg = np.zeros(batch + (d,))
    scale = np.max(np.abs(Q), axis=(-1, -2)) + 1e-300
    for pattern in itertools.product((-1, 0, 1), repeat=d):
        p = np.array(pattern)
        free = p == 0
        x = np.broadcast_to(p * b, batch + (d,)).copy()
        ok = np.ones(batch, bool)
        if free.any():
            if np.any(b[free] == 0):  # a zero-width coordinate is never free: its vertex value is the same point
                continue
            fixed = ~free
            Qff = Q[..., free, :][..., :, free]
            rhs = -(Q[..., free, :][..., :, fixed] @ (p[fixed] * b[fixed]))
            nf = int(free.sum())
            if nf == 1:
                den = Qff[..., 0, 0]
                ok = np.abs(den) > REL_SINGULAR * scale
                xf = (rhs[..., 0] / np.where(ok, den, 1.0))[..., None]
            else:
                det = np.linalg.det(Qff)
                ok = np.abs(det) > REL_SINGULAR * scale**nf
                Qs = np.where(ok[..., None, None], Qff, np.eye(nf))
                xf = np.linalg.solve(Qs, rhs[..., None])[..., 0]
            ok &= np.all(np.abs(xf) <= b[free] * (1 + 1e-12), axis=-1)
            x[..., free] = np.clip(xf, -b[free], b[free])
        val = np.einsum("...i,...ij,...j->...", x, Q, x)
        better = ok & (val > best)
        best = np.where(better, val, best)
        arg = np.where(better[..., None], x, arg)
    return best, arg
