"""Real-time forward kinematics: one Newton solve per length set from the previous pose, compiled
(``core/fk_kernel.c`` through ``system.c_build``, called with cffi), with a branch certificate.

Why: a viewer, an estimator or a trajectory check calls FK once per sample with the previous pose as the
guess; the numpy Newton (``newton_fk.forward_kinematics``) pays ~0.5 ms of numpy overhead per call, the C
Newton a few µs. The algorithm is the numpy reference's (``newton_fk.newton_core``) step for step, so both
give the same pose to rounding (the tests pin 1e-12 m); without a C compiler the numpy path runs, with a
one-line note on stderr.

The branch check. Newton from the previous pose y0 can converge to another assembly mode when the step is
large or a singularity is near: silently following it would hand a controller a pose on the wrong branch.
In the coordinates y = (p, a·w) around y0 (a the anchor radius, R = exp([w]×) R0, so |y − y0| is
sqrt(|Δp|² + (a θ)²), the distance ``homotopy.branches`` reports) and F(y) = L(y) − L*:

- β ≥ ‖J(y0)⁻¹‖₂, from the computed inverse X and its residual δ = ‖I − X J‖_F: β = ‖X‖_F / (1 − δ);
- γ(ρ), a Lipschitz constant of F′ on the ball B(y0, ρ): leg i's vector l_i = p + exp([w]×) t_i − b_i has
  ‖Dl_i‖ ≤ c_i = sqrt(1 + (|t_i| e^{ρ/a} / a)²) and ‖D²l_i‖ ≤ |t_i| e^{ρ/a} / a² (the exponential's series
  bounded term by term), so ‖D²|l_i|‖ ≤ M_i = c_i² / (|l_i(y0)| − c_i ρ) + |t_i| e^{ρ/a} / a², γ = sqrt(Σ M_i²);
- η ≥ ‖J(y0)⁻¹ F(y0)‖ = |X F| + β δ |F|.

Uniqueness: if β γ(ρ) ρ < 1, F has at most one zero in B(y0, ρ) (two zeros y1, y2 would give
0 = (J(y0) + E)(y1 − y2) with ‖J(y0)⁻¹E‖ ≤ β γ ρ < 1). ``radius`` is the largest such ρ found: a
certified uniqueness radius around the previous pose, whatever the lengths. Trials: ρ_s = min(a/5, |l|min/4)
gives c = 0.999 / (β γ(ρ_s)), and ρ = min(c, ρ_s) passes (γ grows with ρ); when c > ρ_s, c itself (capped
at |l|min/4) is tried; when the radius found is below 2η, ρ = 2η is tried (γ(2η) < γ(ρ_s) when 2η < ρ_s:
the branch test below then needs exactly β γ(2η) 2η < 1, i.e. Kantorovich's h = β γ η < 1/2 with γ taken on
the ball the zero path stays in; on utn-kinematic from 1 mm / 1 mrad off it certifies 88 % of workspace
solves instead of 82 %). Branch: if moreover 2η ≤ ρ,
Kantorovich's theorem gives, for every s ∈ [0, 1] and lengths L(s) = L(y0) + s (L* − L(y0)), a zero in
B(y0, 2 s η) ⊂ B(y0, ρ), unique there, so it moves continuously from y0 (s = 0) to s = 1: it is y0's
branch. The result is ``certified`` when Newton converged to a point of B(y0, ρ) (then it is that zero).
With ``max_substeps`` > 0 an uncertified step is split along L(s) (halving) and certified when every
sub-step is. The bounds are evaluated in double precision with a relative margin of 1e-9 on β, γ, η and δ
covering the rounding of the 6×6 products (not interval arithmetic); ``certified = False`` means "not
shown", not "wrong": the caller may retry with smaller steps, or run the complete solver
(``homotopy.solve``).
"""

from __future__ import annotations

import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from stewart_drake.core.argcheck import as_int, as_real, as_real_array
from stewart_drake.core.geometry import Platform, check_platform
from stewart_drake.core.kinematics import anchor_radius
from stewart_drake.core.newton_fk import CONVERGED, leg_geometry, newton_core, validate_lengths
from stewart_drake.core.rotations import CONVENTIONS, angles_from_matrix, check_convention, rotation_matrix
from stewart_drake.errors import FkInputError

SOURCE = Path(__file__).with_name("fk_kernel.c")
CDEF = """
void sd_rtfk(int64_t n, const double *g, int conv, const double *L, const double *q0, int64_t q0_stride, int track,
             double tol, int max_iter, int max_sub, double *q_out, double *info);
"""
OPT = "-O2"
# -funroll-loops: the 6x6 loops fully unrolled, a third fewer instructions per solve; -fno-math-errno: sqrt a single
# instruction (no errno branch; the same results), 3 % fewer (callgrind)
FLAGS = ("-funroll-loops", "-fno-math-errno")
INFO = ("residual", "iterations", "status", "certified", "radius", "eta", "step", "substeps")
# Newton converges in tens of iterations or not at all; the C kernel counts iterations and substeps in ints.
MAX_ITERATIONS = 10_000
MARGIN = 1e-9  # relative margin on the bounds (the C kernel's MARGIN)
NO_COMPILER_NOTE = "note: no C compiler: real-time FK runs the numpy Newton (~100x slower per call)"
_LIB: list = []


def library():
    """``(ffi, lib)`` of the compiled kernel, or None without a compiler or cache (noted once on stderr)."""
    if not _LIB:
        # deferred: the compiler glue (subprocess, tempfile, hashing, cffi) is needed only when the kernel first
        # runs, and the command line's fk and ik import this module at start
        from stewart_drake.system.c_build import UNAVAILABLE, load, source_keyed_library

        try:
            path = source_keyed_library(SOURCE, CDEF, "sd-realtime-fk", OPT, flags=FLAGS)
            _LIB.append(load(path, CDEF, cache_declarations=True))
        except UNAVAILABLE:
            print(NO_COMPILER_NOTE, file=sys.stderr)
            _LIB.append(None)
    return _LIB[0]


def geometry_vector(platform: Platform) -> np.ndarray:
    """``(44,)`` the kernel's geometry: base anchors, plate anchors relative to the rotation centre (per
    leg, in T), the anchor radius a, the numpy divergence test's size and |t_i| (metres)."""
    t = platform.top_anchors_per_leg - platform.rotation_centre
    size = max(np.abs(platform.base_anchors).max(), np.abs(platform.top_anchors).max())
    rt = np.linalg.norm(t, axis=-1)
    return np.concatenate([platform.base_anchors.ravel(), t.ravel(), [anchor_radius(platform), size], rt]).astype(float)


@dataclass(frozen=True)
class RealtimeResult:
    """Per length set ``(n,)`` (or scalars for one set): ``poses (n, 6)`` (m, rad; NaN where Newton did not
    converge), ``residual`` (m), ``iterations``, ``status`` (``newton_fk`` codes), ``certified`` (on the
    previous pose's branch, see the module docstring), ``radius`` (m, the certified uniqueness radius
    around the previous pose), ``eta`` (m, the Newton step bound), ``step`` (m, distance travelled),
    ``substeps`` and ``engine`` (``c`` or ``numpy``)."""

    poses: np.ndarray
    residual: np.ndarray
    iterations: np.ndarray
    status: np.ndarray
    certified: np.ndarray
    radius: np.ndarray
    eta: np.ndarray
    step: np.ndarray
    substeps: np.ndarray
    engine: str


class RealtimeFK:
    """Forward kinematics for one platform from the previous pose: ``solve`` (one set, the per-call path),
    ``solve_batch`` (``(n, 6)`` sets, each from its own or one common previous pose) and ``track`` (a
    sequence, each from the last result). ``engine``: ``auto`` (compiled when a compiler exists), ``c`` or
    ``numpy``. ``max_substeps`` > 0 splits an uncertified step along the straight length path."""

    def __init__(
        self,
        platform: Platform,
        convention: str = "utn",
        *,
        tol: float = 1e-13,
        max_iter: int = 30,
        max_substeps: int = 0,
        engine: str = "auto",
    ):
        check_platform(platform)
        check_convention(convention)
        tol = as_real(tol, "tol")
        if not (np.isfinite(tol) and tol > 0):
            raise FkInputError(FkInputError.POSITIVE.format(name="tol", value=tol))
        max_iter = as_int(max_iter, "max_iter", 1, MAX_ITERATIONS)
        max_substeps = as_int(max_substeps, "max_substeps", 0, MAX_ITERATIONS)
        if not isinstance(engine, str) or engine not in ("auto", "c", "numpy"):
            raise FkInputError(FkInputError.ENGINE.format(value=engine))
        self.platform, self.convention = platform, convention
        self.tol, self.max_iter, self.max_substeps = float(tol), int(max_iter), int(max_substeps)
        self.conv = CONVENTIONS.index(convention)
        self.g = geometry_vector(platform)
        lib = library() if engine != "numpy" else None
        if engine == "c" and lib is None:
            raise FkInputError(FkInputError.NO_COMPILER)
        self.engine = "c" if lib is not None else "numpy"
        if lib is not None:
            self._ffi, self._lib = lib
            self._gp = self._ffi.from_buffer("double[]", self.g)
            self._one = np.empty(6 + 6 + 6 + len(INFO))  # lengths, previous, pose, info
            v = self._ffi.from_buffer("double[]", self._one)
            self._ptrs = (v, v + 6, v + 12, v + 18)

    # ------------------------------------------------------------------------------------------
    def solve(self, lengths, previous) -> tuple[np.ndarray, bool, float]:
        """One length set ``(6,)`` (m) from the previous pose ``(6,)`` (m, rad): ``(pose (6,), certified,
        radius m)``; the pose is NaN where Newton did not converge. The per-call path (no validation
        beyond shapes: use ``solve_batch`` for checked input)."""
        if self.engine != "c":
            r = self.solve_batch(np.reshape(lengths, (1, 6)), np.reshape(previous, (1, 6)))
            return r.poses[0], bool(r.certified[0]), float(r.radius[0])
        buf = self._one
        buf[0:6] = lengths
        buf[6:12] = previous
        L, q0, q, info = self._ptrs
        self._lib.sd_rtfk(1, self._gp, self.conv, L, q0, 0, 0, self.tol, self.max_iter, self.max_substeps, q, info)
        pose = buf[12:18].copy()
        if buf[20] != CONVERGED:
            pose[:] = np.nan
        return pose, buf[21] == 1.0, float(buf[22])

    def solve_batch(self, lengths, previous) -> RealtimeResult:
        """``(n, 6)`` length sets, each from ``previous`` ``(n, 6)`` (its own) or ``(6,)`` (common)."""
        return self._run(lengths, previous, track=False)

    def track(self, lengths, initial) -> RealtimeResult:
        """A sequence of ``(n, 6)`` length sets: the first from ``initial`` ``(6,)``, each next from the last
        converged result (its rotation matrix, no angle round trip)."""
        return self._run(lengths, np.reshape(initial, 6), track=True)

    # ------------------------------------------------------------------------------------------
    def _run(self, lengths, previous, track: bool) -> RealtimeResult:
        L = np.ascontiguousarray(validate_lengths(as_real_array(lengths, "lengths")).reshape(-1, 6))
        q0 = np.ascontiguousarray(as_real_array(previous, "previous"))
        if q0.shape != (6,) and q0.shape != L.shape:
            raise FkInputError(FkInputError.INITIAL_BROADCAST.format(shape=q0.shape, lengths_shape=L.shape))
        if not np.all(np.isfinite(q0)):
            raise FkInputError(FkInputError.INITIAL_NOT_FINITE.format(value=q0.tolist()))
        n = len(L)
        if self.engine == "c":
            q = np.empty((n, 6))
            info = np.empty((n, len(INFO)))
            fb = self._ffi.from_buffer
            self._lib.sd_rtfk(
                n,
                self._gp,
                self.conv,
                fb("double[]", L),
                fb("double[]", q0),
                0 if q0.ndim == 1 else 6,
                int(track),
                self.tol,
                self.max_iter,
                self.max_substeps,
                fb("double[]", q, require_writable=True),
                fb("double[]", info, require_writable=True),
            )
        else:
            q, info = self._numpy(L, q0, track)
        ok = info[:, 2] == CONVERGED
        return RealtimeResult(
            poses=np.where(ok[:, None], q, np.nan),
            residual=info[:, 0],
            iterations=info[:, 1].astype(int),
            status=info[:, 2].astype(int),
            certified=info[:, 3] == 1.0,
            radius=info[:, 4],
            eta=info[:, 5],
            step=info[:, 6],
            substeps=info[:, 7].astype(int),
            engine=self.engine,
        )

    def _numpy(self, L, q0, track):
        """The numpy path: ``newton_core`` and ``certificate`` (vectorised when not tracking)."""
        n = len(L)
        q = np.empty((n, 6))
        info = np.zeros((n, len(INFO)))
        if not track:
            qi = np.broadcast_to(q0, L.shape)
            p0, R0 = qi[:, :3].copy(), rotation_matrix(qi[:, 3:], self.convention)
            self._steps(L, p0, R0, q, info)
            return q, info
        p0, R0 = q0[None, :3].copy(), rotation_matrix(q0[None, 3:], self.convention)
        for k in range(n):
            p, R = self._steps(L[k : k + 1], p0, R0, q[k : k + 1], info[k : k + 1])
            if info[k, 2] == CONVERGED:
                p0, R0 = p, R
        return q, info

    def _steps(self, L, p0, R0, q, info):
        rho, eta = certificate(self.platform, p0, R0, L)
        p, R, res, its, st = newton_core(self.platform, p0, R0, L, self.tol, self.max_iter)
        d = pose_distance(anchor_radius(self.platform), p0, R0, p, R)
        cert = (st == CONVERGED) & (2 * eta <= rho) & (d < rho)
        info[:] = np.c_[res, its, st, cert, rho, eta, d, np.ones(len(L))]
        for k in np.flatnonzero(~cert & (st == CONVERGED) if self.max_substeps > 0 else []):
            p[k], R[k], info[k] = self._subdivide(L[k], p0[k], R0[k], info[k])
        q[:] = np.c_[p, angles_from_matrix(R, self.convention)]
        return p, R

    def _subdivide(self, Lt, p0, R0, info):
        """The C kernel's halving along the straight length path, for one set (numpy path)."""
        _, _, L0 = leg_geometry(self.platform, p0[None], R0[None])
        s, ds, n, its, rho0, travelled = 0.0, 0.5, 0, int(info[1]), -1.0, 0.0
        pk, Rk = p0[None].copy(), R0[None].copy()
        while s < 1.0 and n < self.max_substeps and ds > 1e-6:
            sn = min(1.0, s + ds)
            Ls = Lt[None] if sn >= 1.0 else L0 + sn * (Lt - L0)
            rho, eta = certificate(self.platform, pk, Rk, Ls)
            p, R, res, it, st = newton_core(self.platform, pk, Rk, Ls, self.tol, self.max_iter)
            its += int(it[0])
            d = pose_distance(anchor_radius(self.platform), pk, Rk, p, R)
            if st[0] == CONVERGED and 2 * eta[0] <= rho[0] and d[0] < rho[0]:
                rho0 = rho[0] if rho0 < 0 else rho0
                travelled += d[0]
                s, n, pk, Rk, ds = sn, n + 1, p, R, ds * 2
            else:
                ds *= 0.5
        if s >= 1.0:
            info = np.array([res[0], its, CONVERGED, 1.0, rho0, info[5], travelled, n])
            return pk[0], Rk[0], info
        info = info.copy()
        info[1] = its
        return p0 * np.nan, R0, info


def pose_distance(a: float, p0, R0, p1, R1) -> np.ndarray:
    """``(n,)`` sqrt(|Δp|² + (a θ)²) between ``(n, 3)`` positions / ``(n, 3, 3)`` orientations (θ the angle of R1 R0ᵀ)."""
    M = R1 @ np.swapaxes(R0, -1, -2)
    v = np.stack([M[:, 2, 1] - M[:, 1, 2], M[:, 0, 2] - M[:, 2, 0], M[:, 1, 0] - M[:, 0, 1]], -1)
    th = np.arctan2(0.5 * np.linalg.norm(v, axis=-1), 0.5 * (np.trace(M, axis1=-2, axis2=-1) - 1))
    return np.sqrt(np.sum((p1 - p0) ** 2, axis=-1) + (a * th) ** 2)


def lipschitz(platform: Platform, L0, rho) -> np.ndarray:
    """``(n,)`` a Lipschitz constant γ(ρ) of F′ on B(y0, ρ) (1/m), from the leg lengths ``(n, 6)`` at y0
    and radii ``(n,)`` (see the module docstring); inf where the ball reaches a zero leg length."""
    a = anchor_radius(platform)
    rt = np.linalg.norm(platform.top_anchors_per_leg - platform.rotation_centre, axis=-1)
    E = np.exp(np.asarray(rho) / a)[:, None]
    c1sq = 1.0 + (rt * E / a) ** 2
    lmin = L0 - np.sqrt(c1sq) * np.asarray(rho)[:, None]
    with np.errstate(divide="ignore", invalid="ignore"):
        M = np.where(lmin > 0, c1sq / lmin + rt * E / a**2, np.inf)
    return np.sqrt(np.sum(M * M, axis=-1)) * (1 + MARGIN)


def certificate(platform: Platform, p0, R0, L_target) -> tuple[np.ndarray, np.ndarray]:
    """``(rho, eta)``, each ``(n,)`` metres, at previous poses ``p0 (n, 3)``, ``R0 (n, 3, 3)`` for lengths
    ``(n, 6)``: the certified uniqueness radius around y0 (0 where J(y0) is singular or badly
    conditioned) and the bound on the first Newton step (see the module docstring)."""
    a = anchor_radius(platform)
    r, l, L = leg_geometry(platform, np.asarray(p0, float), np.asarray(R0, float))
    u = l / L[..., None]
    J = np.concatenate([u, np.cross(r, u) / a], axis=-1)
    with np.errstate(all="ignore"):
        ok = np.abs(np.linalg.det(J)) > 0
        X = np.zeros_like(J)
        try:
            X[ok] = np.linalg.inv(J[ok])
        except np.linalg.LinAlgError:  # an exactly singular J (the C kernel's zero pivot): one by one
            for k in np.flatnonzero(ok):
                try:
                    X[k] = np.linalg.inv(J[k])
                except np.linalg.LinAlgError:
                    ok[k] = False
        delta = np.linalg.norm(np.eye(6) - X @ J, axis=(-2, -1)) * (1 + MARGIN) + 1e-15
        ok &= delta < 0.5
        beta = np.linalg.norm(X, axis=(-2, -1)) * (1 + MARGIN) / (1 - delta)
        F = L - L_target
        eta = np.where(
            ok,
            (np.linalg.norm(np.einsum("nij,nj->ni", X, F), axis=-1) + beta * delta * np.linalg.norm(F, axis=-1))
            * (1 + MARGIN),
            np.inf,
        )
        rho_max = 0.25 * L.min(axis=-1)
        rho_s = np.minimum(0.2 * a, rho_max)
        c = 0.999 / (beta * lipschitz(platform, L, rho_s))
        best = np.where(ok, np.minimum(c, rho_s), 0.0)
        c = np.minimum(c, rho_max)
        wider = ok & (c > rho_s) & (beta * lipschitz(platform, L, c) * c < 1.0)
        best = np.where(wider, c, best)
        r2 = 2 * eta  # the third trial, rho = 2 eta, where the radius found is below it (see the module docstring)
        third = ok & (best < r2) & (r2 <= rho_max) & (beta * lipschitz(platform, L, np.where(ok, r2, 0.0)) * r2 < 1.0)
        best = np.where(third, r2, best)
    return best, eta


def branch_check(
    platform: Platform, initial, lengths, position, rotation, convention: str = "utn", max_substeps: int = 64
) -> tuple[bool, float]:
    """``(certified, radius m)`` for a Newton solution (``position (3,)``, ``rotation (3, 3)``) of one
    length set ``(6,)`` reached from the pose ``initial (6,)``: certified when the solution is the
    continuation of the initial pose's branch along the straight length path (followed in at most
    ``max_substeps`` certified sub-steps; the solution must be the followed pose to 1e-9 m and rad);
    radius: the certified uniqueness radius around the initial pose."""
    r = RealtimeFK(platform, convention, max_substeps=max_substeps).solve_batch(
        np.asarray(lengths, dtype=float)[None], np.asarray(initial, dtype=float)
    )
    p, R = np.asarray(position, dtype=float), np.asarray(rotation, dtype=float)
    q = np.r_[p, angles_from_matrix(R, convention)]
    same = bool(np.all(np.abs(r.poses[0] - q) <= 1e-9))
    q0 = np.asarray(initial, dtype=float)
    rho, _ = certificate(platform, q0[None, :3], rotation_matrix(q0[None, 3:], convention), np.asarray(lengths)[None])
    return bool(r.certified[0]) and same, float(rho[0])
