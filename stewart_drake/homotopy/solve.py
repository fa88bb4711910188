"""All assembly modes of a Stewart–Gough platform by parameter homotopy, every path accounted for.

Method: the Study-coordinate system of ``study`` (40 isolated solutions for a general 6-6 platform,
16 for 3-6 / 6-3) is continued from the shipped generic start system of the platform's class
(``start``) to the platform's own parameters, all paths together (``track``), with a random γ per
length set (seeded). By default in two stages (``platform_start``): once per platform, the shipped
start system is tracked to this platform's anchors at random complex squared lengths s*; then each
length set tracks only the finite solutions found there (the platform's generic root count) over the
six squared lengths. Each path's end point is classified:

  real       finite, real (pose recovered, Newton-polished on the real system, certified)
  complex    finite, not real
  infinity   |e·e| / ‖x‖² < INFINITY_TOL: the pose's translation is unbounded (no assembly). A real
             assembly has |p| of the order of the leg lengths, so |e·e| / ‖x‖² ~ 1 / (1 + |p|²) in
             scaled units — far above the tolerance; no real mode can be misfiled as infinite.
  singular   the end point is a singular root (Jacobian rank-deficient: a multiple root, a root on a
             positive-dimensional set)
  failed     the tracker gave up; failed paths are re-tracked with tighter steps
             (``TrackOptions.tighter``), then the whole set with a new γ, before they are reported

Guarantee (``COMPLETE_TEXT``): by the parameter-homotopy theorem (Morgan & Sommese 1989), for all
parameters outside a proper algebraic subset of the family — which the random complex start point
and γ avoid with probability one — the end points of the paths from all solutions of the start point
include every isolated solution of the target. So when no path failed and the finite end points are
distinct (two paths ending together would reveal a path jump), the real end points are all the
isolated real assembly modes. ``complete`` is False otherwise and ``failed_paths`` names the paths.
What it does not cover: a positive-dimensional solution set (a self-motion of an architecturally
singular platform); numerical path tracking itself is not interval-verified (the certificate is
per returned solution, not per path).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from stewart_drake.core.geometry import Platform
from stewart_drake.core.newton_fk import leg_geometry, validate_lengths
from stewart_drake.errors import SHAPE, FkInputError, ShapeError
from stewart_drake.homotopy.certify import certify, newton_real, pose_bounds, real_forms
from stewart_drake.homotopy.singular import resolve as resolve_singular
from stewart_drake.homotopy.start import load_start_system
from stewart_drake.homotopy.study import (
    SIX_THREE,
    architecture,
    evaluate,
    hessian_forms,
    leg_matrices,
    pose_from_study,
    study_parameters,
)
from stewart_drake.homotopy.track import DONE, FAILED, STALLED, TrackOptions, engine_used, track

REAL, COMPLEX, INFINITY, SINGULAR, FAIL = "real", "complex", "infinity", "singular", "failed"
CLASSES = (REAL, COMPLEX, INFINITY, SINGULAR, FAIL)
INFINITY_TOL = 1e-7  # |e·e| / ‖x‖² below this: the translation is unbounded
SINGULAR_COND = 1e9  # end-point Jacobian condition number above this: a singular root
SINGULAR_END = 1e-6  # a path stalled (not at infinity) closer than this to t = 1 ends at a singular root
REAL_TOL = 1e-7  # max |Im| of the normalised end point below this: a real solution
DISTINCT_TOL = 1e-6  # relative distance of two finite end points below this: the same root
COMPLETE_TEXT = (
    "parameter homotopy from a generic start system of the {kind} family ({what}; Morgan–Sommese): with "
    "probability one over the random start point and gamma, the path end points include every isolated complex "
    "solution; every path reached t = 1 and the finite end points are distinct, so every isolated real assembly "
    "mode is listed (a positive-dimensional solution set, a self-motion, would not be)"
)


@dataclass(frozen=True)
class CertifiedMode:
    """One real solution: pose p_BC ``(3,)`` m, R_BT ``(3, 3)``; ``residual`` max leg-length error (m);
    ``certified`` (the Krawczyk/Kantorovich test of ``certify`` passed); ``radius`` (an exact solution
    lies within it, Study coordinates), ``uniqueness`` (no other within it), ``position_bound`` (m)
    and ``angle_bound`` (rad) derived from ``radius``; ``path`` the path index that reached it."""

    position: np.ndarray
    rotation: np.ndarray
    residual: float
    certified: bool
    radius: float
    uniqueness: float
    position_bound: float
    angle_bound: float
    path: int
    singular: bool = False  # a singular root resolved from a singular end point (``singular``): not certified


@dataclass(frozen=True)
class HomotopyResult:
    """Outcome for one length set. ``classes`` ``(n_paths,)`` per-path class (``CLASSES``); ``modes``
    the real solutions; ``complete`` and ``guarantee`` as in the module docstring; ``failed_paths``
    path indices that failed even after re-tracking; ``retracked`` those re-tracked; ``steps``
    ``(n_paths,)`` tracker steps; ``attempts`` how many random γ were used; ``engine`` the tracker
    implementation that ran ("c" or "numpy", ``track.TrackOptions.engine``)."""

    kind: str
    architecture: str
    lengths: np.ndarray
    classes: tuple
    modes: list
    complete: bool
    guarantee: str
    failed_paths: list
    retracked: list
    duplicate_paths: list
    steps: np.ndarray
    attempts: int = 1
    stage: str = "direct"
    dropped: int = 0
    time_s: float = 0.0
    timing: dict = field(default_factory=dict)
    engine: str = ""

    @property
    def n_paths(self) -> int:
        return len(self.classes)

    def counts(self) -> dict:
        """Paths per class, over all the class's paths: in two-stage mode the ``dropped`` first-stage
        paths (at infinity for this platform's anchors at every length) count as infinity."""
        out = {c: int(sum(k == c for k in self.classes)) for c in CLASSES}
        out[INFINITY] += self.dropped
        return out

    @property
    def max_solutions(self) -> int:
        """Paths of the class's start system: the generic root count (40 for 6-6, 16 for 3-6 / 6-3)."""
        return self.n_paths + self.dropped


def _normalise(x: np.ndarray) -> np.ndarray:
    """Scale Study points ``(k, 8)`` so that e·e = 1, with the sign making the largest |e_j| real part
    positive (x and −x are the same pose)."""
    ee = np.einsum("kj,kj->k", x[:, :4], x[:, :4])
    y = x / np.sqrt(ee)[:, None]
    j = np.argmax(np.abs(y[:, :4]), axis=1)
    sign = np.sign(y[np.arange(len(y)), j].real)
    return y * np.where(sign == 0, 1, sign)[:, None]


def _classify(paths, B1, s1, v):
    """Per-path class ``(n,)`` (object array of CLASSES) and normalised end points ``(n, 8)``."""
    x = paths.x
    n = len(x)
    with np.errstate(all="ignore"):
        F, J = evaluate(x, np.broadcast_to(B1, (n, 6, 4, 4)), s1, v)
        sv = np.linalg.svd(J, compute_uv=False)
        cond = sv[:, 0] / sv[:, -1]
        ee = np.abs(np.einsum("kj,kj->k", x[:, :4], x[:, :4])) / np.einsum("kj,kj->k", np.abs(x), np.abs(x))
        y = _normalise(x)
    done = paths.state == DONE
    stalled = paths.state == STALLED
    cls = np.full(n, FAIL, dtype=object)
    at_inf = (done | stalled) & ~(ee > INFINITY_TOL)
    cls[at_inf] = INFINITY
    sing = ~at_inf & ((done & ~(cond < SINGULAR_COND)) | (stalled & (1 - paths.t <= SINGULAR_END)))
    cls[sing] = SINGULAR
    fin = done & ~at_inf & ~sing
    is_real = fin & (np.max(np.abs(y.imag), axis=1) <= REAL_TOL * np.linalg.norm(y, axis=1))
    cls[fin] = COMPLEX
    cls[is_real] = REAL
    return cls, y


def _duplicates(y: np.ndarray, idx: np.ndarray) -> list[int]:
    """Indices among ``idx`` whose normalised end points coincide (as poses: y ~ −y) with another's."""
    z = y[idx]
    if len(z) < 2:
        return []
    tol = DISTINCT_TOL * np.maximum(1.0, np.abs(z).max(-1))
    # Exact prefilter: |Σ_k (z_ik ∓ z_jk)| <= 8 max_k |z_ik ∓ z_jk|, so a pair within tol (max-norm) has
    # its coordinate sums within 8 tol; only such pairs (few) get the full comparison.
    w = z.sum(-1)
    near = np.minimum(np.abs(w[:, None] - w[None]), np.abs(w[:, None] + w[None])) <= 8 * tol[:, None] * (1 + 1e-9)
    near[np.diag_indices(len(z))] = False
    out = set()
    for i, j in zip(*np.nonzero(near)):
        if min(np.abs(z[i] - z[j]).max(), np.abs(z[i] + z[j]).max()) <= tol[i]:
            out.add(int(idx[i]))
    return sorted(out)


@dataclass(frozen=True)
class Start:
    """Start points of the per-length-set homotopy: x ``(N, 8)`` solutions of (B ``(6, 4, 4)``,
    s ``(6,)``) on chart v. ``stage`` "direct" (the shipped generic start system of the class) or
    "platform" (this platform's own anchors at random complex lengths, computed from the shipped one);
    ``dropped`` counts the first-stage paths that went to infinity for this platform's anchors (a
    platform property, the same for every length set); ``total`` = N + dropped."""

    stage: str
    B: np.ndarray
    s: np.ndarray
    x: np.ndarray
    v: np.ndarray
    dropped: int
    total: int


_PLATFORM_STARTS: dict = {}
MAX_CACHED_PLATFORMS = 32  # stage-one results kept (oldest dropped first)


def platform_start(
    platform: Platform, arch, scale: float, B1: np.ndarray, seed: int = 0, options: TrackOptions = TrackOptions()
) -> Start | None:
    """Stage one of the two-stage homotopy, cached per platform: track the shipped start system of the
    class to this platform's anchors at random complex squared lengths s* (mid-stroke ± 30 %, complex).
    Every path must end at infinity or at a finite non-singular root, the finite ones distinct; then
    these finite roots are all the isolated solutions at the generic point s* of this platform's
    length space, and tracking them to any real lengths (stage two) reaches every isolated solution
    there (parameter homotopy over the six squared lengths). Returns None when stage one is not
    clean after three random s*."""
    key = (
        platform.base_anchors.tobytes(),
        platform.top_anchors_per_leg.tobytes(),
        platform.rotation_centre.tobytes(),
        platform.stroke.tobytes(),
        seed,
        options,
    )
    if key in _PLATFORM_STARTS:
        return _PLATFORM_STARTS[key]
    S = load_start_system(arch.kind)
    rng = np.random.default_rng(seed + 1)
    ref = (platform.stroke.mean() / scale) ** 2
    out = None
    for _ in range(3):
        s_star = ref * (1 + 0.3 * (rng.normal(size=6) + 1j * rng.normal(size=6)))
        paths = track(S.x, S.B, B1, S.s, s_star[None], S.v, np.exp(2j * np.pi * rng.uniform()), options)
        cls, y = _classify(paths, B1, np.broadcast_to(s_star, (len(S.x), 6)), S.v)
        finite = np.flatnonzero((cls == REAL) | (cls == COMPLEX))
        if np.all((cls == INFINITY) | (cls == REAL) | (cls == COMPLEX)) and not _duplicates(y, finite):
            out = Start("platform", B1, s_star, paths.x[finite], S.v, len(S.x) - len(finite), len(S.x))
            break
    if len(_PLATFORM_STARTS) >= MAX_CACHED_PLATFORMS:
        _PLATFORM_STARTS.pop(next(iter(_PLATFORM_STARTS)))
    _PLATFORM_STARTS[key] = out
    return out


def solve_batch(
    platform: Platform,
    lengths,
    *,
    seed: int = 0,
    options: TrackOptions = TrackOptions(),
    retrack: bool = True,
    gamma_retries: int = 2,
    path_max_steps: dict | None = None,
    two_stage: bool = True,
) -> list[HomotopyResult]:
    """All assembly modes for each of the ``(m, 6)`` (or ``(6,)``) leg-length sets (m), every path
    classified; one ``HomotopyResult`` per set. The paths of all sets are tracked together.

    ``two_stage`` (default): the start points are this platform's own solutions at random complex
    lengths (``platform_start``, computed once per platform and cached), so each length set tracks
    only the platform's generic root count of paths (40 for a general 6-6, 28 for the 3-fold
    symmetric gonzalez-dutra-2009 whose other 12 go to infinity at every length, 16 for 3-6) over
    a short segment in length space; falls back to the direct homotopy from the shipped start system
    when stage one is not clean. A failed path is re-tracked with ``options.tighter()``; a set that
    still has one is re-solved whole with a new random γ, up to ``gamma_retries`` times
    (``retrack=False`` disables both). ``path_max_steps`` {path index: steps} caps the steps of those
    paths of every set in every attempt — a deliberate failure, to check that the result then says
    incomplete."""
    t_start = time.perf_counter()
    L = np.atleast_2d(validate_lengths(lengths))
    if L.ndim != 2 or L.shape[1] != 6:
        raise ShapeError(SHAPE.format(name="lengths", shape="(6,) or (m, 6)", got=np.shape(lengths)))
    m = len(L)
    arch = architecture(platform)
    a, b, s, scale = study_parameters(platform, L, arch)
    B1 = leg_matrices(a, b)
    st = platform_start(platform, arch, scale, B1, seed, options) if two_stage else None
    if st is None:
        S = load_start_system(arch.kind)
        st = Start("direct", S.B, S.s, S.x, S.v, 0, len(S.x))
    t_stage1 = time.perf_counter() - t_start
    N = len(st.x)
    rng = np.random.default_rng(seed)
    n = m * N
    s0 = np.broadcast_to(st.s, (n, 6))
    s1 = np.repeat(s, N, axis=0)
    x0 = np.tile(st.x, (m, 1))
    cap = np.full(N, np.iinfo(np.int64).max)  # track() takes the smaller of this and the options' limit
    for k, v in (path_max_steps or {}).items():
        if 0 <= int(k) < N:
            cap[int(k)] = v
    cap = np.tile(cap, m)

    def run(rows, g_rows):
        """Track rows (path indices into the batch) with γ per row; failed rows re-tracked tighter."""
        paths = track(x0[rows], st.B, B1, s0[rows], s1[rows], st.v, g_rows, options, cap[rows])
        bad = np.flatnonzero(paths.state == FAILED)
        if retrack and len(bad):
            again = track(
                x0[rows][bad],
                st.B,
                B1,
                s0[rows][bad],
                s1[rows][bad],
                st.v,
                g_rows[bad],
                options.tighter(),
                cap[rows][bad],
            )
            paths.x[bad], paths.state[bad], paths.t[bad] = again.x, again.state, again.t
            paths.steps[bad] += again.steps
        return paths, rows[bad] if retrack else np.zeros(0, int)

    t0 = time.perf_counter()
    gamma = np.exp(2j * np.pi * rng.uniform(size=m))
    paths, retracked = run(np.arange(n), np.repeat(gamma, N))
    attempts = np.ones(m, int)
    # A set with a path that still failed is tracked again, all its paths, with a new random γ (a new
    # arc of the same homotopy: the path correspondence changes, so all paths are redone together).
    for _ in range(gamma_retries if retrack else 0):
        # the sets with a failed path, ascending (row r is path r % N of set r // N); not np.unique, whose
        # first call imports numpy.ma, a large share of `fk --all`'s start-up
        sets = np.flatnonzero((paths.state == FAILED).reshape(-1, N).any(axis=1))
        if len(sets) == 0:
            break
        rows = (sets[:, None] * N + np.arange(N)).ravel()
        g_new = np.exp(2j * np.pi * rng.uniform(size=len(sets)))
        again, rt = run(rows, np.repeat(g_new, N))
        for j, sj in enumerate(sets):
            r = slice(j * N, (j + 1) * N)
            sl = slice(sj * N, (sj + 1) * N)
            if np.sum(again.state[r] == FAILED) < np.sum(paths.state[sl] == FAILED):
                paths.x[sl], paths.state[sl], paths.t[sl] = again.x[r], again.state[r], again.t[r]
                paths.steps[sl] += again.steps[r]
                attempts[sj] += 1
        retracked = np.union1d(retracked, rt)
    t_track = time.perf_counter() - t0
    cls, y = _classify(paths, B1, s1, st.v)
    t_class = time.perf_counter() - t0 - t_track
    results = []
    for j in range(m):
        sl = slice(j * N, (j + 1) * N)
        cj = cls[sl]
        Q, c = real_forms(hessian_forms(B1.real, s[j]))
        ridx = np.flatnonzero(cj == REAL)
        xr = newton_real(y[sl][ridx].real, Q, c)
        # singular end points (several paths meeting at a multiple root): resolved, not dropped
        sidx = np.flatnonzero(cj == SINGULAR)
        rs = resolve_singular(y[sl][sidx], sidx, Q, c)
        nonsing = ~np.isin(np.arange(len(rs.real)), np.flatnonzero(rs.singular))
        if len(rs.real):  # a regular root the end game reached poorly is certified as any other
            xr = np.concatenate([xr, rs.real])
            ridx = np.concatenate([ridx, rs.paths])
        singular_flag = np.r_[np.zeros(len(xr) - len(rs.real), bool), ~nonsing]
        cert = certify(xr, Q, c)
        # coinciding end points reveal a path jump, except singular ones (a multiple root is several paths' end)
        dup = _duplicates(y[sl], np.flatnonzero((cj == REAL) | (cj == COMPLEX)))
        failed = [int(k) for k in np.flatnonzero(cj == FAIL)]
        p_BC, R_BT = pose_from_study(xr, scale, arch.kind)
        _, _, Lp = leg_geometry(platform, p_BC, R_BT)
        res = np.abs(Lp - L[j]).max(axis=-1) if len(xr) else np.zeros(0)
        dp, da = pose_bounds(xr, cert.radius)
        if arch.kind == SIX_THREE:  # bounds hold for the inverse motion (R', p'), p = −R'ᵀ p', |p'| = |p|:
            dp = dp + (np.linalg.norm(p_BC, axis=1) / scale + dp) * da  # |δp| <= |δp'| + (|p'| + |δp'|) θ
        modes = [
            CertifiedMode(
                p_BC[k],
                R_BT[k],
                float(res[k]),
                bool(cert.certified[k]),
                float(cert.radius[k]),
                float(cert.uniqueness[k]),
                float(dp[k] * scale),
                float(da[k]),
                int(ridx[k]),
                bool(singular_flag[k]),
            )
            for k in range(len(ridx))
        ]
        complete = not failed and not dup and not rs.unresolved_paths
        what = (
            f"{st.total} paths"
            if st.stage == "direct"
            else (
                f"two stages: {st.total} paths once to this platform at random complex lengths ({st.dropped} went to "
                f"infinity), then {N} paths per length set"
            )
        )
        n_sing = len(sidx)
        if n_sing:
            what += (
                f"; {n_sing} path(s) ended at singular roots, resolved by Gauss–Newton on the real system: "
                f"{int((~nonsing).sum())} singular real mode(s) (rank-deficient, listed uncertified), "
                f"{int(nonsing.sum())} regular real, {len(rs.complex_paths)} complex"
            )
        guarantee = (
            COMPLETE_TEXT.format(kind=arch.kind, what=what)
            if complete
            else (
                "not complete: "
                + "; ".join(
                    (
                        [
                            f"path(s) {', '.join(map(str, failed))} failed even after re-tracking with tighter steps and new gamma"
                        ]
                        if failed
                        else []
                    )
                    + ([f"paths {', '.join(map(str, dup))} reached the same finite end point"] if dup else [])
                    + (
                        [
                            f"path(s) {', '.join(map(str, rs.unresolved_paths))} end at a singular point neither "
                            "real (Gauss–Newton found no real root) nor clearly complex"
                        ]
                        if rs.unresolved_paths
                        else []
                    )
                )
                + " — an isolated solution may be missing"
            )
        )
        rt = [int(k - j * N) for k in retracked if j * N <= k < (j + 1) * N]
        results.append(
            HomotopyResult(
                arch.kind,
                arch.describe(),
                L[j],
                tuple(cj.tolist()),
                modes,
                complete,
                guarantee,
                failed,
                rt,
                dup,
                paths.steps[sl].copy(),
                int(attempts[j]),
                st.stage,
                st.dropped,
            )
        )
    total = time.perf_counter() - t_start
    timing = {
        "stage1": t_stage1,
        "track": t_track,
        "classify": t_class,
        "certify": total - t_stage1 - t_track - t_class,
    }
    engine = engine_used(options)
    return [HomotopyResult(**{**r.__dict__, "time_s": total / m, "timing": timing, "engine": engine}) for r in results]


def solve(platform: Platform, lengths, **kwargs) -> HomotopyResult:
    """All assembly modes for one ``(6,)`` leg-length set (m); keywords as ``solve_batch``."""
    L = validate_lengths(lengths)
    if L.shape != (6,):
        raise FkInputError(FkInputError.ONE_SET.format(what="solve", shape=L.shape))
    return solve_batch(platform, L, **kwargs)[0]
