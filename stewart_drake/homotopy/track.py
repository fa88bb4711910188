"""Vectorised path tracking for the parameter homotopy of ``study``.

Every path k follows H(x, t) = F(x; P_k(τ(t))) = 0 from t = 0 to t = 1. The parameters move on the
straight segment P(τ) = P0 + τ (P1 − P0): leg matrices B ``(6, 4, 4)`` shared by all paths (one
platform), squared lengths s ``(n, 6)`` per path. τ(t) = γ t / (γ t + 1 − t) with a random complex γ
per path (the "gamma trick": the real interval t ∈ [0, 1] becomes a complex arc from P0 to P1, which
meets the discriminant locus — where two solutions collide — with probability zero, so the paths stay
non-singular for t < 1 and never cross).

All paths advance together, each with its own t and step h. One step:
- predictor: cubic Hermite extrapolation through the last two accepted points and their tangents
  dx/dt = −H_x⁻¹ H_t (Euler on the first step), local error O(h⁴);
- corrector: two Newton iterations at the new t; each solve also returns the tangent there (one
  LAPACK call with two right-hand sides), so a step costs two Jacobian evaluations and two solves.
- accepted when the first correction is below ``max_jump`` ‖x‖ (the prediction stayed on this path),
  the second below ``contraction`` times the first (Newton's quadratic regime: the corrected point
  is then within about (second)² of the path) and below ``tol`` ‖x‖. The next h comes from the first
  correction d₁ ≈ C h⁴: h ← h · clip(0.8 (``target`` ‖x‖ / d₁)^¼, ...).

Paths end DONE (t reached 1; x Newton-refined at t = 1, ``end_newton`` iterations), STALLED (h fell
below ``h_min`` within ``endgame`` of t = 1: the path approaches a singular end point — a multiple
root, or a root on the exceptional set e = 0 —, where H_x is singular) or FAILED (h fell below
``h_min`` earlier, ``max_steps`` steps were taken, or the iterate became non-finite).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

ACTIVE, DONE, STALLED, FAILED = 0, 1, 2, 3
STATE_TEXT = {ACTIVE: "active", DONE: "reached t = 1", STALLED: "stalled at a singular end point", FAILED: "failed"}


@dataclass(frozen=True)
class TrackOptions:
    """Step control of the tracker (t is dimensionless; tolerances are relative to ‖x‖)."""

    h0: float = 0.02
    h_max: float = 0.5
    h_min: float = 1e-12
    max_steps: int = 600
    target: float = 1e-3
    tol: float = 1e-4
    max_jump: float = 0.02
    contraction: float = 0.1
    end_newton: int = 3
    endgame: float = 1e-2

    def tighter(self) -> "TrackOptions":
        """Options for re-tracking failed paths: smaller steps, more of them, a stricter corrector."""
        return replace(self, h0=self.h0 / 10, h_max=self.h_max / 5, h_min=self.h_min / 100, max_steps=self.max_steps * 10,
                       target=self.target / 10, tol=self.tol / 10, max_jump=self.max_jump / 4)


@dataclass
class Paths:
    """Tracked paths: x ``(n, 8)`` complex end points (last iterate), t ``(n,)`` where each stopped,
    state ``(n,)`` (DONE/STALLED/FAILED), steps ``(n,)`` accepted + rejected steps."""

    x: np.ndarray
    t: np.ndarray
    state: np.ndarray
    steps: np.ndarray


class Homotopy:
    """H(x, t) for shared leg matrices B0 → B1 ``(6, 4, 4)``, per-path s0 → s1 ``(n, 6)``, chart v ``(8,)``
    and γ ``(n,)``. ``system(x, t, idx)`` gives H ``(k, 8)``, H_x ``(k, 8, 8)`` and dH/dt ``(k, 8)``."""

    def __init__(self, B0, B1, s0, s1, v, gamma):
        B0 = np.asarray(B0, dtype=complex)
        dB = np.asarray(B1, dtype=complex) - B0
        self.Br = np.concatenate([B0, dB], axis=1).reshape(48, 4).T.copy()  # e @ Br -> [B0 e | dB e]
        self.Bt = np.concatenate([B0, dB], axis=1)  # (6, 8, 4): [u | τu] @ Bt = B(τ)ᵀ u
        self.s0 = np.asarray(s0, dtype=complex)
        self.ds = np.asarray(s1, dtype=complex) - self.s0
        self.v = np.asarray(v, dtype=complex)
        self.gamma = np.asarray(gamma, dtype=complex)

    def system(self, x, t, idx):
        g_ = self.gamma[idx]
        d = g_ * t + (1 - t)
        tau, dtau = g_ * t / d, g_ / d**2
        n = len(x)
        e, g = x[:, :4], x[:, 4:]
        BE = (e @ self.Br).reshape(n, 6, 2, 4)
        Be = BE[:, :, 0] + tau[:, None, None] * BE[:, :, 1]
        u = g[:, None, :] + Be
        ee = np.einsum("nk,nk->n", e, e)
        s = self.s0[idx] + tau[:, None] * self.ds[idx]
        H = np.empty((n, 8), complex)
        H[:, :6] = np.einsum("nij,nij->ni", u, u) - s * ee[:, None]
        H[:, 6] = np.einsum("nk,nk->n", g, e)
        H[:, 7] = x @ self.v - 1
        J = np.empty((n, 8, 8), complex)
        uu = np.concatenate([u, tau[:, None, None] * u], axis=2).transpose(1, 0, 2)  # (6, n, 8)
        J[:, :6, :4] = 2 * (np.matmul(uu, self.Bt).transpose(1, 0, 2) - s[..., None] * e[:, None, :])
        J[:, :6, 4:] = 2 * u
        J[:, 6, :4] = g
        J[:, 6, 4:] = e
        J[:, 7, :] = self.v
        Ht = np.zeros((n, 8), complex)
        Ht[:, :6] = (2 * np.einsum("nij,nij->ni", u, BE[:, :, 1]) - self.ds[idx] * ee[:, None]) * dtau[:, None]
        return H, J, Ht


def _newton_tangent(hom, x, t, idx):
    """One Newton step at (x, t) and the tangent dx/dt there: (x − H_x⁻¹ H, −H_x⁻¹ H_t)."""
    H, J, Ht = hom.system(x, t, idx)
    sol = np.linalg.solve(J, np.stack([H, Ht], -1))
    return x - sol[..., 0], -sol[..., 1]


def track(x0, B0, B1, s0, s1, v, gamma, options: TrackOptions = TrackOptions(), max_steps=None) -> Paths:
    """Track paths from solutions x0 ``(n, 8)`` of (B0 ``(6, 4, 4)``, s0 ``(n, 6)``) to (B1, s1); chart v
    ``(8,)``; gamma scalar or ``(n,)``. ``max_steps`` ``(n,)`` optionally caps each path's steps
    below ``options.max_steps``. Returns ``Paths``."""
    o = options
    n = len(x0)
    s0 = np.broadcast_to(s0, (n, 6))
    s1 = np.broadcast_to(s1, (n, 6))
    hom = Homotopy(B0, B1, s0, s1, v, np.broadcast_to(np.asarray(gamma, dtype=complex), (n,)))
    cap = np.full(n, o.max_steps) if max_steps is None else np.minimum(np.asarray(max_steps), o.max_steps)
    x = np.array(x0, dtype=complex)
    t = np.zeros(n)
    h = np.full(n, o.h0)
    steps = np.zeros(n, dtype=int)
    state = np.full(n, ACTIVE)
    all_idx = np.arange(n)
    with np.errstate(all="ignore"):
        _, xd = _newton_tangent(hom, x, t, all_idx)
        xp, tp, xdp = x.copy(), t.copy(), xd.copy()
        has_prev = np.zeros(n, bool)
        while True:
            act = np.flatnonzero(state == ACTIVE)
            if len(act) == 0:
                break
            xa, ta, xda = x[act], t[act], xd[act]
            ha = np.minimum(h[act], 1 - ta)
            tn = ta + ha
            # Predictor: cubic Hermite through the last two points, Euler on the first step.
            xhat = xa + ha[:, None] * xda
            hp = has_prev[act]
            if np.any(hp):
                k = act[hp]
                D = (ta[hp] - tp[k])[:, None]
                sgm = (tn[hp][:, None] - tp[k][:, None]) / D
                h00, h10 = 2 * sgm**3 - 3 * sgm**2 + 1, sgm**3 - 2 * sgm**2 + sgm
                h01, h11 = -2 * sgm**3 + 3 * sgm**2, sgm**3 - sgm**2
                xhat[hp] = h00 * xp[k] + h10 * D * xdp[k] + h01 * xa[hp] + h11 * D * xda[hp]
            x1, _ = _newton_tangent(hom, xhat, tn, act)
            x2, xd2 = _newton_tangent(hom, x1, tn, act)
            norm = np.maximum(np.linalg.norm(xa, axis=1), 1.0)
            d1 = np.linalg.norm(x1 - xhat, axis=1)
            d2 = np.linalg.norm(x2 - x1, axis=1)
            good = (d1 <= o.max_jump * norm) & (d2 <= o.contraction * d1 + 1e-14 * norm) & (d2 <= o.tol * norm)
            good &= np.all(np.isfinite(x2), axis=1) & np.all(np.isfinite(xd2), axis=1)
            steps[act] += 1
            with np.errstate(divide="ignore"):
                ratio = np.where(d1 > 0, (o.target * norm / d1) ** 0.25, 4.0)
            ia, ib = act[good], act[~good]
            xp[ia], tp[ia], xdp[ia], has_prev[ia] = xa[good], ta[good], xda[good], True
            x[ia], xd[ia] = x2[good], xd2[good]
            t[ia] = np.where(1 - tn[good] <= 1e-14, 1.0, tn[good])
            h[ia] = np.minimum(ha[good] * np.clip(0.8 * ratio[good], 0.5, 2.0), o.h_max)
            h[ib] = ha[~good] * np.clip(0.8 * ratio[~good], 0.1, 0.5)
            state[ia[t[ia] >= 1.0]] = DONE
            small = ib[h[ib] < o.h_min]
            state[small] = np.where(1 - t[small] <= o.endgame, STALLED, FAILED)
            state[act[(steps[act] >= cap[act]) & (state[act] == ACTIVE)]] = FAILED
        done = np.flatnonzero(state == DONE)
        if len(done):
            xd_ = x[done]
            for _ in range(o.end_newton):
                xd_, _ = _newton_tangent(hom, xd_, np.ones(len(done)), done)
            fin = np.all(np.isfinite(xd_), axis=1)
            x[done[fin]] = xd_[fin]
    return Paths(x, t, state, steps)
