"""Exact maximum of a quadratic form over a symmetric box, vectorised.

max f(x) = xᵀ Q x over |x_j| <= b_j. The maximum of a continuous function over a box is attained in the
relative interior of one of its 3^d faces (each coordinate at −b_j, at +b_j, or free), at a point that
is a local maximum of f restricted to that face. On a face with free set F and fixed values x_C:

- if Q_FF is not negative definite, f has a direction of non-negative curvature along which it does
  not decrease from a stationary point, so the face's maximum is also attained on its boundary (a
  smaller face, also enumerated): the face is skipped;
- otherwise its only candidate is the stationary point x_F = −Q_FF⁻¹ Q_FC x_C, kept if inside the box.

Enumerating every face therefore gives the global maximum whatever the signs of Q's eigenvalues. f is
even, so faces come in ± pairs of equal value and only one of each pair is visited; the interior's
candidate is x = 0 (value 0). Faces with up to two free coordinates are solved in closed form.
"""

from __future__ import annotations

import itertools

import numpy as np


def _value(Qf, iu, x):
    """xᵀ Q x from the packed upper triangle Qf (..., m) (off-diagonal entries doubled)."""
    return np.sum(Qf * (x[..., iu[0]] * x[..., iu[1]]), axis=-1)


def _patterns(d: int):
    """One representative of each ± pair of faces (first non-zero entry +1), without the interior."""
    for p in itertools.product((-1, 0, 1), repeat=d):
        nz = [v for v in p if v]
        if nz and nz[0] == 1:
            yield np.array(p)


def box_quadratic_max(Q, b) -> tuple[np.ndarray, np.ndarray]:
    """``(value (...), argmax (..., d))``: max of xᵀ Q x over |x_j| <= b_j for ``(..., d, d)`` Q (made
    symmetric) and ``(d,)`` half-widths b >= 0."""
    Q = np.asarray(Q, dtype=float)
    Q = 0.5 * (Q + np.swapaxes(Q, -1, -2))
    b = np.asarray(b, dtype=float)
    d = b.shape[0]
    batch = Q.shape[:-2]
    if d == 0:
        return np.zeros(batch), np.zeros(batch + (0,))
    iu = np.triu_indices(d)
    Qf = Q[..., iu[0], iu[1]] * np.where(iu[0] == iu[1], 1.0, 2.0)
    pats = list(_patterns(d))
    # Vertices at once: one matrix product.
    verts = np.array([p * b for p in pats if np.all(p != 0)], dtype=float)
    vals = Qf @ (verts[:, iu[0]] * verts[:, iu[1]]).T  # (..., n_vertices)
    k = np.argmax(vals, axis=-1)
    best = np.maximum(np.take_along_axis(vals, k[..., None], -1)[..., 0], 0.0)  # 0: the interior's x = 0
    arg = np.where((best > 0)[..., None], verts[k], 0.0)
    for p in pats:
        free = np.flatnonzero(p == 0)
        fixed = np.flatnonzero(p != 0)
        nf = len(free)
        if nf == 0 or np.any(b[free] == 0):
            continue  # vertices done; a zero-width coordinate is never free (the same points are a smaller face)
        g = np.sum(Q[..., free, :][..., :, fixed] * (p[fixed] * b[fixed]), axis=-1)  # (..., nf): Q_FC x_C
        if nf == 1:
            a = Q[..., free[0], free[0]]
            ok = a < 0
            xf = (-g[..., 0] / np.where(ok, a, -1.0))[..., None]
        elif nf == 2:
            a, c, e = Q[..., free[0], free[0]], Q[..., free[0], free[1]], Q[..., free[1], free[1]]
            det = a * e - c * c
            ok = (a < 0) & (det > 0)
            det = np.where(ok, det, 1.0)
            xf = np.stack([(-e * g[..., 0] + c * g[..., 1]) / det, (-a * g[..., 1] + c * g[..., 0]) / det], -1)
        else:
            Qff = Q[..., free, :][..., :, free]
            ok = np.linalg.eigvalsh(Qff)[..., -1] < 0
            Qs = np.where(ok[..., None, None], Qff, -np.eye(nf))
            xf = np.linalg.solve(Qs, -g[..., None])[..., 0]
        ok &= np.all(np.abs(xf) <= b[free] * (1 + 1e-12), axis=-1)
        if not ok.any():
            continue
        if batch:  # the face's point and value only where it is a candidate (the same arithmetic per entry)
            sel = np.flatnonzero(ok)
            x = np.broadcast_to((p * b).astype(float), (len(sel), d)).copy()
            x[:, free] = np.clip(xf.reshape(-1, nf)[sel], -b[free], b[free])
            val = _value(Qf.reshape(-1, Qf.shape[-1])[sel], iu, x)
            better = val > best.reshape(-1)[sel]
            # best and arg are C-contiguous arrays made here (np.maximum, np.where): reshape is a view
            best.reshape(-1)[sel[better]] = val[better]
            arg.reshape(-1, d)[sel[better]] = x[better]
            continue
        x = np.broadcast_to((p * b).astype(float), batch + (d,)).copy()
        x[..., free] = np.clip(xf, -b[free], b[free])
        val = _value(Qf, iu, x)
        better = ok & (val > best)
        best = np.where(better, val, best)
        arg = np.where(better[..., None], x, arg)
    return best, arg
