"""Where the linear stiffness and modal results stop meaning something: an unstable loaded platform, a
deflection beyond the linear range, damping or masses the double-precision eigen-solve cannot resolve.

- **Stability.** The loaded stiffness K (legs plus the load's geometric stiffness) must be positive definite
  at an equilibrium: an eigenvalue of sym(K) at or below zero means the plate, under its load, falls away
  from the pose (the load's geometric stiffness exceeds the legs'). A result outside limits, not a number
  to print as a deflection.
- **Linear range.** δx = K⁻¹ w is a first-order answer: it holds while the deflection changes the geometry
  little. The bound used: every leg's length change (the legs at the displaced pose) at most ``MAX_LEG_STRAIN`` of its length (small
  strain; the second-order terms are then ~``MAX_LEG_STRAIN``² relative) and every rotation at most
  ``MAX_ROTATION`` rad (sin θ − θ is then < 2e-5 θ).
- **Resolvable damping.** With leg damping c, leg stiffness k and leg-space mass m, a mode's damping ratio
  is ~c / (2√(k m)); beyond ``MAX_DAMPING_RATIO`` the two roots of each mode differ by more than 1e12 and
  double precision cannot resolve the slow one (1e300 N·s/m printed 1e283 Hz).
- **Rigid-body range.** The modes treat the plate as rigid on massless springs; that holds below the legs'
  own first axial resonance, c / (2 L) with c = ``SOUND_SPEED_STEEL`` m/s (a steel rod of the leg's length;
  ~3.6 kHz for a 0.7 m leg). A mode above it (a 1e-30 kg plate printed 1e18 Hz) says the masses are not
  those of a platform, not a frequency.
"""

from __future__ import annotations

import numpy as np

MAX_LEG_STRAIN = 0.01
MAX_ROTATION = 0.01
MAX_DAMPING_RATIO = 1e6
SOUND_SPEED_STEEL = 5000.0  # m/s, √(E/ρ) of steel (aluminium 5100, so one figure serves both)


def rigid_body_limit_hz(lengths) -> float:
    """The legs' first axial resonance c / (2 L_max) (Hz) for leg lengths ``lengths`` (6,) m: above it the
    rigid-plate, massless-leg modes do not hold."""
    return SOUND_SPEED_STEEL / (2.0 * float(np.max(lengths)))


def unstable_direction(K) -> np.ndarray | None:
    """None when sym(K) is positive definite (``K`` (6, 6) about the rotation centre: the loaded platform
    returns to the pose), else the direction δx (6,) [m; rad], largest component 1, along which it falls
    away. Rows and columns are scaled to a unit diagonal first, so translations (N/m) and rotations
    (N·m/rad) weigh alike; the scaling is a congruence, which keeps the signs of the eigenvalues
    (Sylvester's law of inertia)."""
    S = 0.5 * (np.asarray(K, dtype=float) + np.asarray(K, dtype=float).T)
    d = np.sqrt(np.abs(np.diag(S)))
    d[d == 0] = 1.0
    ev, vec = np.linalg.eigh(S / np.outer(d, d))
    if ev[0] > 0:
        return None
    v = vec[:, 0] / d
    return v / v[np.argmax(np.abs(v))]


def beyond_linear_range(lengths, displaced_lengths, dx) -> str | None:
    """Why the deflection ``dx`` (6,) [m; rad] is beyond the linear range, or None: a leg's length change
    (``displaced_lengths`` − ``lengths``, (6,) m, the legs at the pose and at the pose moved by ``dx``)
    above ``MAX_LEG_STRAIN`` × its length, or a rotation above ``MAX_ROTATION`` rad."""
    dx = np.asarray(dx, dtype=float)
    L0, L1 = np.asarray(lengths, dtype=float), np.asarray(displaced_lengths, dtype=float)
    if not (np.all(np.isfinite(dx)) and np.all(np.isfinite(L1))):
        return "the deflection is not finite"
    strain = np.abs(L1 - L0) / L0
    j = int(np.argmax(strain))
    if strain[j] > MAX_LEG_STRAIN:
        return f"leg {j + 1} would change length by {strain[j] * 100:.3g} % (the linear range ends at {MAX_LEG_STRAIN * 100:g} %)"
    rot = float(np.abs(dx[3:]).max())
    if rot > MAX_ROTATION:
        return f"the plate would turn by {rot:.3g} rad (the linear range ends at {MAX_ROTATION:g} rad)"
    return None


def damping_ratio_scale(K, M, C) -> float:
    """~The largest modal damping ratio, ρ(M⁻¹C) / (2 √ρ(M⁻¹K)) from spectral radii, or 0 without C; used
    before the eigen-solve to refuse damping it cannot resolve (``MAX_DAMPING_RATIO``)."""
    if C is None:
        return 0.0
    MinvC = np.linalg.solve(M, C)
    MinvK = np.linalg.solve(M, K)
    rc = float(np.abs(np.linalg.eigvals(MinvC)).max())
    rk = float(np.abs(np.linalg.eigvals(MinvK)).max())
    return rc / (2.0 * np.sqrt(rk)) if rk > 0 else np.inf
