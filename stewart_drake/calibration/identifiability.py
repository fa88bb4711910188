"""Identifiability, computed from the data: the SVD of the identification Jacobian of θ (the poses' own
unknowns eliminated, ``model.reduced_blocks``), the parameter combinations it cannot separate, the
convention that fixes them, and the observability indices.

The Jacobian is *scaled*: rows whitened by the stated noise (unit variance) then multiplied by the leg
sensor's σ, so that a leg row is in metres; columns are all metres (θ holds lengths only), so no column
scaling is needed. Its singular values s_1 ≥ … ≥ s_P give:

- the rank: s_i ≤ ``RANK_TOL`` · s_1 marks a null direction (the central-difference Jacobian puts exact
  null directions at ~1e-10 · s_1 and identifiable ones above ~1e-5 · s_1 on the presets);
- the condition number s_1 / s_r of the identifiable part (Schroer: keep it below ~100 for a well-posed
  identification);
- the noise-amplification index s_r² / s_1 (Nahvi & Hollerbach's O5: large when the smallest singular value
  is large and the spread small);
- the D-index (∏ s_i²)^(1/r): the geometric mean of the information's eigenvalues (D-optimal design
  maximises it; it is invariant to how θ is parametrised up to a constant factor).

Convention for what the data cannot fix: each null direction is fixed by holding one parameter at its
nominal value, chosen greedily in the order of θ (base joints, plate joints, offsets, targets) as the first
parameter that still lowers the remaining freedom. So a frame freedom of the base is fixed by base joint 1
(translation) and the next base joint coordinates (rotation), the usual choice of the literature.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from stewart_drake.calibration.model import Layout

RANK_TOL = 1e-7
FRAME_TOL = 1e-6  # a frame motion this invisible (relative to s_1) is a freedom of the data
PIVOT_TOL = 1e-3  # a parameter that moves a null direction less than this (relative) is not fixed for it
NAME_TOL = 0.05  # a coefficient below this (of the combination's largest) is not named
CONDITION_RULE = 100.0  # Schroer's rule of thumb: above it, the weakest combinations are poorly fixed
WEAK_SHOWN = 3  # the weakest combinations named
WEAK_TERMS = 4  # the parameters named in each


@dataclass
class Identifiability:
    """What the data can identify. ``singular_values`` (r,) of the free part; ``null`` ``(P, d)`` basis of
    the unidentifiable combinations (each column 1 at its fixed parameter, 0 at the other fixed ones);
    ``fixed`` (d,) indices held at their nominal value; ``free`` (P,) mask; ``frame_freedoms`` the rigid
    motions of the base or plate frame the data cannot see; ``combinations`` each null direction named;
    ``weak`` ``(name, s_i)`` for the identifiable directions with s_i < s_1 / ``CONDITION_RULE``, weakest first
    (at most ``WEAK_SHOWN``): σ along one is the leg sensor's σ / s_i."""

    names: tuple[str, ...]
    singular_values: np.ndarray
    null: np.ndarray
    fixed: list[int]
    free: np.ndarray
    frame_freedoms: list[str] = field(default_factory=list)
    combinations: list[str] = field(default_factory=list)
    weak: list[tuple[str, float]] = field(default_factory=list)

    @property
    def condition(self) -> float:
        s = self.singular_values
        return float(s[0] / s[-1]) if s.size and s[-1] > 0 else float("inf")

    @property
    def noise_amplification(self) -> float:
        s = self.singular_values
        return float(s[-1] ** 2 / s[0]) if s.size else 0.0

    @property
    def d_index(self) -> float:
        s = self.singular_values
        return float(np.exp(np.mean(2 * np.log(s)))) if s.size and s[-1] > 0 else 0.0

    def to_dict(self) -> dict:
        return {
            "parameters": len(self.names),
            "identifiable": int(self.free.sum()),
            "unidentifiable": len(self.fixed),
            "condition_number": self.condition,
            "noise_amplification_index": self.noise_amplification,
            "d_index": self.d_index,
            "frame_freedoms": self.frame_freedoms,
            "unidentifiable_combinations": self.combinations,
            "weakly_identified": [{"combination": c, "singular_value": v} for c, v in self.weak],
            "fixed_by_convention": [self.names[i] for i in self.fixed],
            "convention": "each unidentifiable combination is fixed by holding one parameter at its nominal value, "
            "chosen in the order base joints, plate joints, offsets, gains, targets",
        }


def stacked(A: np.ndarray, noise_length: float) -> np.ndarray:
    """``(n·rows, P)`` the scaled identification Jacobian from reduced pose blocks ``(n, rows, P)``."""
    return A.reshape(-1, A.shape[-1]) * noise_length


def analyse(layout: Layout, J: np.ndarray, theta, fixed: list[int] | None = None) -> Identifiability:
    """Identifiability of θ from the scaled Jacobian ``J`` ``(m, P)`` at ``theta`` (see the module docstring).
    ``fixed``: keep these parameters fixed (the convention chosen at the start of a fit) instead of choosing
    again, when they still fix every null direction."""
    names = layout.names
    s_full, N, fixed, free = _null_space(J, fixed)
    if fixed:
        N = N @ np.linalg.inv(N[fixed])  # 1 at its own fixed parameter, 0 at the others
    sf, weak = np.zeros(0), []
    if free.any():
        _, sf, Vt = np.linalg.svd(J[:, free], full_matrices=False)
        v = np.zeros((len(sf), len(names)))
        v[:, free] = Vt
        weak = [
            (_name(v[i], names, WEAK_TERMS), float(sf[i])) for i in np.flatnonzero(sf * CONDITION_RULE < sf[0])[::-1]
        ]
    ident = Identifiability(names, sf, N, fixed, free, weak=weak[:WEAK_SHOWN])
    ident.frame_freedoms = _frame_freedoms(layout, J, s_full[0], theta)
    ident.combinations = [_name(N[:, j], names) for j in range(N.shape[1])]
    return ident


def free_parameters(J: np.ndarray, fixed: list[int] | None = None) -> tuple[list[int], np.ndarray]:
    """``(fixed, free)`` of ``analyse(layout, J, theta, fixed)`` alone: the parameters held by the convention
    and the ``(P,)`` mask of the others, without the free part's singular values, the frame freedoms and the
    names, for a caller that needs only which parameters to fit (one SVD instead of two)."""
    _, _, fixed, free = _null_space(J, fixed)
    return fixed, free


def _null_space(J: np.ndarray, fixed: list[int] | None):
    """``(s_full (P,), N (P, d), fixed, free (P,))``: the singular values, the null basis of the scaled
    Jacobian ``J`` (m, P), the parameters that fix it (``fixed`` kept where it still does) and the free mask."""
    P = J.shape[1]
    _, s, Vt = np.linalg.svd(J, full_matrices=J.shape[0] < P)
    s_full = np.zeros(P)
    s_full[: s.size] = s
    null_mask = s_full <= RANK_TOL * s_full[0]
    N = Vt[null_mask].T  # (P, d)
    if fixed is None or len(fixed) != N.shape[1] or np.linalg.matrix_rank(N[fixed]) < N.shape[1]:
        fixed = _pivots(N)
    free = np.ones(P, bool)
    free[fixed] = False
    return s_full, N, fixed, free


def _pivots(N: np.ndarray) -> list[int]:
    """Rows of the null basis ``N`` ``(P, d)`` to fix: greedily in θ order, a row whose part outside the span
    of the rows already chosen is at least ``PIVOT_TOL`` of the largest such part (Gram–Schmidt on the rows);
    if the order leaves directions uncovered, the rows with the largest remaining parts complete the set."""
    d = N.shape[1]
    R = N.astype(float).copy()
    chosen: list[int] = []

    def take(i):
        q = R[i] / np.linalg.norm(R[i])
        R[:] -= np.outer(R @ q, q)
        chosen.append(i)

    for i in range(N.shape[0]):
        if len(chosen) == d:
            break
        norms = np.linalg.norm(R, axis=1)
        if norms[i] > PIVOT_TOL * norms.max():
            take(i)
    while len(chosen) < d:
        norms = np.linalg.norm(R, axis=1)
        norms[chosen] = -1.0
        take(int(np.argmax(norms)))
    return chosen


def _name(v: np.ndarray, names, terms: int = 8) -> str:
    """A direction of θ as words: ``base joint 1 x +1, plate joint 1 x -0.99 ...`` (largest first, ``terms``
    of them)."""
    big = np.abs(v).max()
    order = [i for i in np.argsort(-np.abs(v)) if abs(v[i]) >= NAME_TOL * big]
    shown = ", ".join(f"{names[i]} {v[i]:+.2f}" for i in order[:terms])
    return shown + (f", … ({len(order) - terms} more)" if len(order) > terms else "")


def frame_generators(layout: Layout, theta) -> dict[str, np.ndarray]:
    """``{"base frame translation along x": (P,) δθ, ...}``: the change of θ (at ``theta``) when the base
    frame (or the plate frame) moves rigidly by a unit translation along, or a unit rotation about, one of
    its axes (through its origin, the plate's at the rotation centre); the poses absorb the rest when they
    are unknowns."""
    B, T, _, S = layout.split(theta)
    c = layout.nominal.rotation_centre
    out = {}
    for frame in ("base", "plate"):
        for motion in ("translation", "rotation"):
            for k, axis in enumerate("xyz"):
                e = np.eye(3)[k]
                dB, dT, dS = np.zeros_like(B), np.zeros_like(T), np.zeros_like(S)
                if frame == "base":
                    dB[:] = e if motion == "translation" else np.cross(e, B)
                else:
                    dT[:] = e if motion == "translation" else np.cross(e, T - c)
                    dS[:] = e if motion == "translation" else np.cross(e, S - c)
                word = "along" if motion == "translation" else "about"
                out[f"{frame} frame {motion} {word} {axis}"] = np.concatenate(
                    [dB.ravel(), dT.ravel(), np.zeros(6 + 6 * layout.gains), dS.ravel()]
                )
    return out


def _frame_freedoms(layout: Layout, J: np.ndarray, s1: float, theta) -> list[str]:
    """The frame motions (``frame_generators``) that the scaled Jacobian ``J`` cannot see."""
    return [
        name
        for name, g in frame_generators(layout, theta).items()
        if np.linalg.norm(J @ g) <= FRAME_TOL * s1 * np.linalg.norm(g)
    ]
