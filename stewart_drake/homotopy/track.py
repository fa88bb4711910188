"""Path tracking for the parameter homotopy of ``study`` (compiled, with a vectorised numpy reference).

Every path k follows H(x, t) = F(x; P_k(τ(t))) = 0 from t = 0 to t = 1. The parameters move on the
straight segment P(τ) = P0 + τ (P1 − P0): leg matrices B ``(6, 4, 4)`` shared by all paths (one
platform), squared lengths s ``(n, 6)`` per path. τ(t) = γ t / (γ t + 1 − t) with a random complex γ
per path (the "gamma trick": the real interval t ∈ [0, 1] becomes a complex arc from P0 to P1, which
meets the discriminant locus — where two solutions collide — with probability zero, so the paths stay
non-singular for t < 1 and never cross).

Each path has its own t and step h. One step:
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

Two implementations of the same algorithm: ``_track_numpy`` (all paths in lockstep, vectorised; the
reference) and the compiled ``track.c`` (``ctrack``; one path at a time, each for its own number of
steps). ``TrackOptions.engine`` picks one: "auto" (compiled when a C compiler is available), "c" or
"numpy". Why compiled: the lockstep loop costs (steps of the slowest path) × (≈ 20 numpy calls of
≈ 10 µs), ≈ 80 × 250 µs for a 6-6 length set whose paths average 30 steps; the C loop costs ≈ 1–2 µs
per step of each path.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from stewart_drake.homotopy import ctrack

ACTIVE, DONE, STALLED, FAILED = 0, 1, 2, 3
STATE_TEXT = {ACTIVE: "active", DONE: "reached t = 1", STALLED: "stalled at a singular end point", FAILED: "failed"}


@dataclass(frozen=True)
class TrackOptions:
    """Step control of the tracker (t is dimensionless; tolerances are relative to ‖x‖) and ``engine``,
    the implementation: "auto" (compiled when a C compiler is available, else numpy), "c", "numpy"."""

    h0: float = 0.02
    h_max: float = 0.5
    h_min: float = 1e-12
    max_steps: int = 600
    target: float = 1e-2
    tol: float = 1e-3
    max_jump: float = 0.1
    contraction: float = 0.3
    end_newton: int = 3
    endgame: float = 1e-2
    engine: str = "auto"

    def tighter(self) -> TrackOptions:
        """Options for re-tracking failed paths: smaller steps, more of them, a stricter corrector."""
        return replace(
            self,
            h0=self.h0 / 10,
            h_max=self.h_max / 5,
            h_min=self.h_min / 100,
            max_steps=self.max_steps * 10,
            target=self.target / 10,
            tol=self.tol / 10,
            max_jump=self.max_jump / 4,
        )


@dataclass
class Paths:
    """Tracked paths: x ``(n, 8)`` complex end points (last iterate), t ``(n,)`` where each stopped,
    state ``(n,)`` (DONE/STALLED/FAILED), steps ``(n,)`` accepted + rejected steps."""

    x: np.ndarray
    t: np.ndarray
    state: np.ndarray
    steps: np.ndarray


def _block_diagonal(B: np.ndarray) -> np.ndarray:
    """``(24, 24)`` block-diagonal matrix of the six ``(4, 4)`` blocks B_i: u_flat @ it = [u_iᵀ B_i]_i."""
    D = np.zeros((24, 24), complex)
    for i in range(6):
        D[4 * i : 4 * i + 4, 4 * i : 4 * i + 4] = B[i]
    return D


class Homotopy:
    """H(x, t) for shared leg matrices B0 → B1 ``(6, 4, 4)``, per-path s0 → s1 ``(n, 6)``, chart v ``(8,)``
    and γ ``(n,)``. ``bind(idx)`` selects the rows of a working set; ``system(x, t)`` then gives
    H_x ``(k, 8, 8)`` and [H | dH/dt] ``(k, 8, 2)`` for those rows. Products with the six B_i are
    single matmuls: e @ Br = [B_i e]_i and u_flat @ blockdiag(B_i) = [B_iᵀ u_i]_i."""

    def __init__(self, B0, B1, s0, s1, v, gamma):
        B0 = np.asarray(B0, dtype=complex)
        dB = np.asarray(B1, dtype=complex) - B0
        self.fixed = not np.any(dB)  # only the lengths move (the two-stage homotopy's second stage)
        self.B0r = B0.reshape(24, 4).T.copy()
        self.dBr = dB.reshape(24, 4).T.copy()
        self.B0d = _block_diagonal(B0)
        self.dBd = _block_diagonal(dB)
        self.S0 = np.asarray(s0, dtype=complex)
        self.DS = np.asarray(s1, dtype=complex) - self.S0
        self.v = np.asarray(v, dtype=complex)
        self.G = np.asarray(gamma, dtype=complex)
        self.bind(np.arange(len(self.S0)))

    def bind(self, idx) -> None:
        self.s0, self.ds, self.gamma = self.S0[idx], self.DS[idx], self.G[idx]

    def system(self, x, t):
        g_ = self.gamma
        d = g_ * t + (1 - t)
        tau = g_ * t / d
        dtau = g_ / (d * d)
        n = len(x)
        e, g = x[:, :4], x[:, 4:]
        ds = self.ds
        s = self.s0 + tau[:, None] * ds
        ee = np.einsum("nk,nk->n", e, e)
        if self.fixed:
            uf = e @ self.B0r
            u = uf.reshape(n, 6, 4)
            u += g[:, None, :]
            BTu = (uf @ self.B0d).reshape(n, 6, 4)
        else:
            dBe = e @ self.dBr
            uf = e @ self.B0r + tau[:, None] * dBe
            u = uf.reshape(n, 6, 4)
            u += g[:, None, :]
            BTu = (uf @ self.B0d + tau[:, None] * (uf @ self.dBd)).reshape(n, 6, 4)
        R = np.empty((n, 8, 2), complex)
        R[:, :6, 0] = np.einsum("nij,nij->ni", u, u) - s * ee[:, None]
        R[:, 6, 0] = np.einsum("nk,nk->n", g, e)
        R[:, 7, 0] = x @ self.v - 1
        Ht = ds * (-ee)[:, None]
        if not self.fixed:
            Ht += 2 * np.einsum("nij,nij->ni", u, dBe.reshape(n, 6, 4))
        R[:, :6, 1] = Ht * dtau[:, None]
        R[:, 6:, 1] = 0
        J = np.empty((n, 8, 8), complex)
        J[:, :6, :4] = 2 * (BTu - s[..., None] * e[:, None, :])
        J[:, :6, 4:] = 2 * u
        J[:, 6, :4] = g
        J[:, 6, 4:] = e
        J[:, 7, :] = self.v
        return J, R


def _newton_tangent(hom, x, t):
    """One Newton step at (x, t) and the tangent dx/dt there: (x − H_x⁻¹ H, −H_x⁻¹ H_t), for the rows
    ``hom`` is bound to."""
    J, R = hom.system(x, t)
    sol = np.linalg.solve(J, R)
    return x - sol[..., 0], -sol[..., 1]


def _norm(z):
    """``(n,)`` max-norm of complex rows (cheap; the tolerances are relative to it)."""
    return np.abs(z).max(axis=1)


ENGINES = ("auto", "c", "numpy")


def engine_used(options: TrackOptions) -> str:
    """ "c" or "numpy": the implementation ``track`` runs with these options ("c" raises
    CompilerUnavailable or CacheUnavailable when it cannot be built here; "auto" then falls back to numpy)."""
    if options.engine not in ENGINES:
        raise ValueError(
            f"TrackOptions.engine must be one of {ENGINES}, got {options.engine!r}"
        )  # internal: set in code
    if options.engine == "auto":
        return "c" if ctrack.available() else "numpy"
    if options.engine == "c":
        ctrack.library()
    return options.engine


def track(x0, B0, B1, s0, s1, v, gamma, options: TrackOptions = TrackOptions(), max_steps=None) -> Paths:
    """Track paths from solutions x0 ``(n, 8)`` of (B0 ``(6, 4, 4)``, s0 ``(n, 6)``) to (B1, s1); chart v
    ``(8,)``; gamma scalar or ``(n,)``. ``max_steps`` ``(n,)`` optionally caps each path's steps
    below ``options.max_steps``. Returns ``Paths``. ``options.engine`` chooses the implementation."""
    if engine_used(options) == "numpy":
        return _track_numpy(x0, B0, B1, s0, s1, v, gamma, options, max_steps)
    o = options
    n = len(x0)
    B0 = np.asarray(B0, dtype=complex)
    dB = np.asarray(B1, dtype=complex) - B0
    s0 = np.broadcast_to(np.asarray(s0, dtype=complex), (n, 6))
    ds = np.broadcast_to(np.asarray(s1, dtype=complex), (n, 6)) - s0
    gamma = np.broadcast_to(np.asarray(gamma, dtype=complex), (n,))
    cap = np.full(n, o.max_steps) if max_steps is None else np.minimum(np.asarray(max_steps), o.max_steps)
    opts = [o.h0, o.h_max, o.h_min, o.target, o.tol, o.max_jump, o.contraction, o.endgame]
    x, t, state, steps = ctrack.track_c(x0, B0, dB, not np.any(dB), s0, ds, v, gamma, cap, opts, o.end_newton)
    return Paths(x, t, state.astype(int), steps.astype(int))


def _track_numpy(x0, B0, B1, s0, s1, v, gamma, options: TrackOptions = TrackOptions(), max_steps=None) -> Paths:
    """``track`` in numpy, all paths advancing together (the reference implementation).

    The loop works on a compacted copy of the active paths, compacted again only when fewer than
    half of it are still active (gathering and scattering every step would cost more than the
    finished rows' wasted arithmetic)."""
    o = options
    n = len(x0)
    s0 = np.broadcast_to(s0, (n, 6))
    s1 = np.broadcast_to(s1, (n, 6))
    hom = Homotopy(B0, B1, s0, s1, v, np.broadcast_to(np.asarray(gamma, dtype=complex), (n,)))
    cap = np.full(n, o.max_steps) if max_steps is None else np.minimum(np.asarray(max_steps), o.max_steps)
    X = np.array(x0, dtype=complex)
    T = np.zeros(n)
    STATE = np.full(n, ACTIVE)
    STEPS = np.zeros(n, dtype=int)
    with np.errstate(all="ignore"):
        idx = np.arange(n)
        x, t = X.copy(), T.copy()
        _, xd = _newton_tangent(hom, x, t)
        h = np.full(n, o.h0)
        # A fictitious previous point on the tangent line: the first Hermite prediction is Euler's.
        xp, tp, xdp = x - h[:, None] * xd, t - h, xd.copy()
        steps = np.zeros(n, dtype=int)
        state = np.full(n, ACTIVE)
        capw = cap.copy()
        while True:
            live = state == ACTIVE
            n_live = int(live.sum())
            if n_live < len(idx) / 2 or n_live == 0:  # write back, compact
                X[idx], T[idx], STATE[idx], STEPS[idx] = x, t, state, steps
                if n_live == 0:
                    break
                k = np.flatnonzero(live)
                idx, x, t, xd, xp, tp, xdp, h, steps, state, capw = (
                    idx[k],
                    x[k],
                    t[k],
                    xd[k],
                    xp[k],
                    tp[k],
                    xdp[k],
                    h[k],
                    steps[k],
                    state[k],
                    capw[k],
                )
                live = np.ones(len(idx), bool)
                hom.bind(idx)
            ha = np.where(live, np.minimum(h, 1 - t), 0.0)
            tn = t + ha
            # Predictor: cubic Hermite through (tp, xp, xdp) and (t, x, xd), evaluated at tn.
            D = (t - tp)[:, None]
            sg = (ha[:, None] + D) / D
            sg2 = sg * sg
            sg3 = sg2 * sg
            xhat = (
                (2 * sg3 - 3 * sg2 + 1) * xp
                + (sg3 - 2 * sg2 + sg) * D * xdp
                + (3 * sg2 - 2 * sg3) * x
                + (sg3 - sg2) * D * xd
            )
            x1, _ = _newton_tangent(hom, xhat, tn)
            x2, xd2 = _newton_tangent(hom, x1, tn)
            norm = np.maximum(_norm(x), 1.0)
            d1 = _norm(x1 - xhat)
            d2 = _norm(x2 - x1)
            good = live & (d1 <= o.max_jump * norm) & (d2 <= o.contraction * d1 + 1e-14 * norm) & (d2 <= o.tol * norm)
            good &= np.isfinite(d2) & np.all(np.isfinite(xd2), axis=1)
            bad = live & ~good
            steps += live
            ratio = np.where(d1 > 0, (o.target * norm / d1) ** 0.25, 4.0)
            g2 = good[:, None]
            xp = np.where(g2, x, xp)
            xdp = np.where(g2, xd, xdp)
            tp = np.where(good, t, tp)
            x = np.where(g2, x2, x)
            xd = np.where(g2, xd2, xd)
            t = np.where(good, np.where(1 - tn <= 1e-14, 1.0, tn), t)
            h = np.where(
                good,
                np.minimum(ha * np.clip(0.8 * ratio, 0.5, 2.0), o.h_max),
                np.where(bad, ha * np.clip(0.8 * ratio, 0.1, 0.5), h),
            )
            state[good & (t >= 1.0)] = DONE
            small = bad & (h < o.h_min)
            state[small] = np.where(1 - t[small] <= o.endgame, STALLED, FAILED)
            state[(steps >= capw) & (state == ACTIVE)] = FAILED
        done = np.flatnonzero(STATE == DONE)
        if len(done):
            xe = X[done]
            hom.bind(done)
            for _ in range(o.end_newton):
                xe, _ = _newton_tangent(hom, xe, np.ones(len(done)))
            fin = np.all(np.isfinite(xe), axis=1)
            X[done[fin]] = xe[fin]
    return Paths(X, T, STATE, STEPS)
