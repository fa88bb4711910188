"""Singular end points of the homotopy resolved: a path that ends at a singular root (a multiple root, e.g. a
real pose on a singularity where several paths meet) is a solution to classify, not one to drop.

A multiple root is reached by the tracker only to ~(1 − t)^(1/m) (the path stalls short of t = 1), so its
end point is neither accurate nor certifiable (Krawczyk needs an invertible Jacobian). From the real part of
the end point, Gauss–Newton on the real Study system G(x) = 0 (the least-squares step of the pseudo-inverse,
which converges linearly to a rank-deficient root where Newton's solve breaks down) either reaches a real
root — G below ``RESIDUAL_TOL`` — or not. The rank test of the certificate then says what it is: the
smallest singular value of DG relative to the largest below ``RANK_TOL`` is a singular real mode (listed,
flagged singular, not certified); above it, a regular real root the end game reached poorly (certified as
any other). An end point whose imaginary part stays above ``IMAG_TOL`` and that Gauss–Newton does not take to
a real root is a complex (singular) root: no real assembly. Only end points neither real nor clearly complex
are unresolved, and then the result is not called complete.

(The utn-dynamic lengths of pose 0 0 0.7 m, 0 0 90°: 4 paths end there, the pose on a singularity of the 3-6
platform; they were dropped and "no real assembly mode, complete" printed.)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from stewart_drake.homotopy.certify import value_and_jacobian

IMAG_TOL = 1e-3  # |Im| of a normalised end point (e·e = 1) above this, if Gauss–Newton finds no real root: complex
RESIDUAL_TOL = 1e-12  # max |G| (e·e = 1, lengths in the study's scale) of a real root
RANK_TOL = 1e-8  # σ_min / σ_max of DG below this: rank-deficient (a singular root)
ITERATIONS = 100  # Gauss–Newton steps: linear convergence at a double root halves the error per step
SAME_TOL = 1e-7  # two resolved roots (x ~ −x) closer than this are one


@dataclass(frozen=True)
class Resolved:
    """The outcome for singular end points: ``real`` (k, 8) real roots (distinct), ``singular`` (k,) their
    rank test (True: rank-deficient), ``paths`` (k,) the first path index reaching each, ``complex_paths``
    and ``unresolved_paths`` (path indices)."""

    real: np.ndarray
    singular: np.ndarray
    paths: np.ndarray
    complex_paths: list
    unresolved_paths: list


def gauss_newton_real(x, Q, c, iterations: int = ITERATIONS) -> np.ndarray:
    """``(k, 8)`` Gauss–Newton iterates on G from real ``x`` (k, 8): the minimum-norm least-squares step
    (``lstsq``), well defined where DG is rank-deficient."""
    x = np.array(x, dtype=float)
    for _ in range(iterations):
        G, A = value_and_jacobian(x, Q, c)
        if np.abs(G).max(initial=0.0) <= RESIDUAL_TOL * 1e-3:
            break
        for k in range(len(x)):
            x[k] -= np.linalg.lstsq(A[k], G[k], rcond=1e-13)[0]
    return x


def resolve(y, paths, Q, c) -> Resolved:
    """Classify the normalised singular end points ``y`` (k, 8) complex (path indices ``paths`` (k,)) of the
    real system (forms ``Q`` (8, 8, 8), constants ``c`` (8,), ``certify.real_forms``)."""
    y = np.asarray(y)
    paths = np.asarray(paths, dtype=int)
    if len(y) == 0:
        return Resolved(np.zeros((0, 8)), np.zeros(0, bool), np.zeros(0, int), [], [])
    x = gauss_newton_real(y.real, Q, c)
    G, A = value_and_jacobian(x, Q, c)
    res = np.abs(G).max(axis=1)
    sv = np.linalg.svd(A, compute_uv=False)
    rank_low = sv[:, -1] <= RANK_TOL * sv[:, 0]
    imag = np.abs(y.imag).max(axis=1)
    real, sing, first, cplx, unresolved = [], [], [], [], []
    for k in range(len(y)):
        if res[k] <= RESIDUAL_TOL:
            if not any(min(np.abs(x[k] - r).max(), np.abs(x[k] + r).max()) <= SAME_TOL for r in real):
                real.append(x[k])
                sing.append(bool(rank_low[k]))
                first.append(int(paths[k]))
        elif imag[k] > IMAG_TOL:
            cplx.append(int(paths[k]))
        else:
            unresolved.append(int(paths[k]))
    return Resolved(np.array(real).reshape(-1, 8), np.array(sing, bool), np.array(first, int), cplx, unresolved)
