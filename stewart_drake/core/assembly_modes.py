"""Every real assembly mode of a Stewart platform for one leg-length set: a seeded multi-start Newton
search, numpy only, with an optional polish (a callable; ``drake/program_fk`` passes Drake's
MathematicalProgram) that confirms each mode.

``assembly_modes`` finds the real solutions ("assembly modes") for one set of lengths:

1. **Generate** — seeded multi-start: random orientations R (uniform on SO(3)) each paired with the
   position that best fits the six leg equations for that R (they are linear in p once the first is
   subtracted from the others), then the batched Newton of ``newton_fk.newton_core`` from every start.
   For a platform whose base anchors and plate anchors are both planar (z = 0), the mirror image of
   every solution about the base plane is also a solution; with ``use_symmetry`` it is added directly.
2. **Deduplicate** — solutions closer than ``dedupe_tol`` (position and rotation matrix) are one.
3. **Polish and confirm** (when a ``polish`` callable is given) — each distinct solution is re-solved
   from that point by an independent method (``drake/program_fk.program_polish``: a MathematicalProgram
   with SNOPT or IPOPT); it is ``certified`` when that solve reports success, its leg residual is below
   1e-9 m and it lands on the same solution. A final Newton step brings the residual to the rounding floor.
4. Rounds of starts continue until the theoretical maximum number of solutions is found (then the set
   is provably complete), or ``patience`` rounds in a row find nothing new, or ``max_rounds``.

What this guarantees, and what not:
- Every returned mode satisfies the six leg equations to its reported ``residual`` (< 1e-12 m), and its
  Jacobian is non-singular (``sigma_min`` > 0), so an exact solution lies within about
  residual / sigma_min of it. This is a numerical, not an interval-arithmetic, proof.
- ``complete`` is True only when the number of distinct modes found equals the known upper bound on
  the number of isolated (complex) solutions: 40 for a general 6-6 platform (Dietmaier 1998 shows all
  40 can be real), 16 when the legs share three plate (or base) joints in pairs (3-6). Then no
  solution was missed. Otherwise the search is probabilistic: a mode whose basin of attraction is tiny may be
  missed; more starts (``n_starts``, ``max_rounds``) lower that risk but never to zero. The complete
  solver is ``stewart_drake.homotopy`` (parameter homotopy, every path classified, certified modes);
  this search remains as an independent second method.
- A platform whose solution set is not finite (an architecturally singular design, self-motions)
  returns finitely many sample points of it.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from stewart_drake.core.geometry import Platform
from stewart_drake.core.joints import coincident_groups
from stewart_drake.core.kinematics import check_stroke, plate_anchors
from stewart_drake.core.newton_fk import (
    CONVERGED,
    analyse_inverse_jacobian,
    anchor_scale,
    legs_and_jacobian,
    newton_core,
    validate_lengths,
)
from stewart_drake.core.rotations import angles_from_matrix, check_convention, quaternion_to_matrix, rotation_matrix
from stewart_drake.errors import FkInputError, ForwardKinematicsError, short_number

# m: base anchors this close are one point to the polynomial system. The 16-solution family needs exact
# coincidence, so this is rounding level, not the platform's MIN_ANCHOR_SEPARATION: a pair 1e-7 m apart
# is one joint to the model, but a generic such system has the 6-6 count of 40 roots.
EXACT_COINCIDENCE = 1e-12
CERTIFY_RESIDUAL = 1e-9  # m: a polished solution with a larger leg residual is not a confirmation
# polish(lengths (6,), p_BC (3,), R_BT (3, 3)) -> (p_BC, R_BT, success, residual m): an independent solve
# started at a Newton solution.
Polish = Callable[[np.ndarray, np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray, bool, float]]


# ----------------------------------------------------------------------------------------------
# Solution counts


def max_solutions(platform: Platform) -> int:
    """Upper bound on the number of isolated complex forward-kinematics solutions: 16 when the plate
    or the base has only three distinct joints each shared by two legs (3-6 / 6-3), else 40."""
    n_base = len(coincident_groups(platform.base_anchors, EXACT_COINCIDENCE)[0])
    if len(platform.top_anchors) == 3 or n_base == 3:
        return 16
    return 40


def is_planar(platform: Platform, tol: float = 1e-12) -> bool:
    """True when all base anchors have z = 0 in B and all plate anchors have z = p_TC,z in T: then
    the mirror image of a solution about the base plane is a solution too."""
    return bool(
        np.all(np.abs(platform.base_anchors[:, 2]) <= tol)
        and np.all(np.abs(platform.top_anchors[:, 2] - platform.rotation_centre[2]) <= tol)
    )


# ----------------------------------------------------------------------------------------------
# All assembly modes


@dataclass(frozen=True)
class AssemblyMode:
    """One real solution of the forward kinematics.

    pose (6,) m/rad in ``convention``; position (3,) p_BC; rotation (3, 3) R_BT; residual (m) max leg
    error; det_sign: sign of det J⁻¹ (the singularity-free region the mode lies in); condition: 2-norm
    condition number of the scaled J⁻¹; sigma_min: its smallest singular value (singularity distance);
    above_base: every plate anchor has z > 0 in B; within_stroke: the lengths are within the stroke (a
    property of the input, the same for every mode); certified: the polish confirmed it;
    distance_to_home: |Δp| / anchor radius + rotation angle (rad) from the home pose.
    """

    pose: np.ndarray
    position: np.ndarray
    rotation: np.ndarray
    residual: float
    det_sign: int
    condition: float
    sigma_min: float
    above_base: bool
    within_stroke: bool
    certified: bool
    distance_to_home: float

    def to_dict(self) -> dict:
        return {
            "pose": self.pose.tolist(),
            "residual_m": self.residual,
            "det_sign": self.det_sign,
            "condition": self.condition,
            "sigma_min": self.sigma_min,
            "above_base": self.above_base,
            "within_stroke": self.within_stroke,
            "certified": self.certified,
            "distance_to_home": self.distance_to_home,
        }


@dataclass(frozen=True)
class AssemblyModes:
    """All modes found, sorted by distance to the home pose (the first is the nearest)."""

    modes: list[AssemblyMode]
    lengths: np.ndarray
    max_solutions: int
    starts: int
    rounds: int
    elapsed_s: float
    timings_s: dict = field(default_factory=dict)

    @property
    def complete(self) -> bool:
        """True when the number found equals the theoretical maximum: no solution can be missing."""
        return len(self.modes) == self.max_solutions

    def poses(self) -> np.ndarray:
        """``(k, 6)`` poses of the modes."""
        return np.array([m.pose for m in self.modes]).reshape(-1, 6)

    def __len__(self) -> int:
        return len(self.modes)


def random_rotations(n: int, rng: np.random.Generator) -> np.ndarray:
    """``(n, 3, 3)`` rotation matrices uniform on SO(3) (normalised Gaussian quaternions)."""
    return quaternion_to_matrix(rng.normal(size=(n, 4)))


def best_position(platform: Platform, R: np.ndarray, lengths: np.ndarray) -> np.ndarray:
    """``(n, 3)`` least-squares p_BC for orientations ``(n, 3, 3)``: |p + c_i|² = L_i² with
    c_i = R r_i − p_BBi is linear in p after subtracting leg 1's equation from the others."""
    c = np.swapaxes(R @ (platform.top_anchors_per_leg - platform.rotation_centre).T, -1, -2) - platform.base_anchors
    A = 2 * (c[:, 1:] - c[:, :1])
    cc = np.sum(c * c, axis=-1)
    y = lengths[1:] ** 2 - lengths[0] ** 2 - cc[:, 1:] + cc[:, :1]
    return (np.linalg.pinv(A) @ y[..., None])[..., 0]


def _mirror(p: np.ndarray, R: np.ndarray):
    """Mirror image about the base plane of a planar platform: p -> M p, R -> M R M, M = diag(1, 1, -1)."""
    M = np.array([1.0, 1.0, -1.0])
    return p * M, R * M[:, None] * M[None, :]


def _dedupe(p: np.ndarray, R: np.ndarray, scale: float, tol: float) -> np.ndarray:
    """Indices of distinct solutions (keeps the first of each cluster): solution i is kept when its key
    (p / scale, R) is farther than ``tol`` (largest coordinate difference) from every solution kept before it.
    One pass per kept solution, over all later candidates at once (thousands of starts reach a few dozen
    modes): the first candidate still standing is kept and those within ``tol`` of it drop out, which keeps
    and drops exactly what testing each solution in turn against the kept ones does (a NaN distance is not
    farther, as there)."""
    key = np.concatenate([p / scale, R.reshape(len(R), 9)], axis=-1)
    keep = []
    cand = np.arange(len(key))
    while len(cand):
        i = cand[0]
        keep.append(i)
        rest = cand[1:]
        cand = rest[np.max(np.abs(key[rest] - key[i]), axis=-1) > tol]
    return np.array(keep, dtype=np.intp)


def assembly_modes(
    platform: Platform,
    lengths,
    convention: str = "utn",
    *,
    n_starts: int = 2000,
    max_rounds: int = 10,
    patience: int = 2,
    seed: int = 0,
    polish: Polish | None = None,
    use_symmetry: bool = True,
    dedupe_tol: float = 1e-6,
    tol: float = 1e-13,
) -> AssemblyModes:
    """Every real assembly mode found for one ``(6,)`` leg-length set (metres); see the module
    docstring for the method and what it guarantees. ``polish``: the independent solve that confirms
    each mode (``Polish``; ``drake.program_fk.program_polish``), or None (``certified`` is then False).
    Raises ``ForwardKinematicsError`` if no mode at all is found."""
    check_convention(convention)
    L = validate_lengths(lengths)
    if L.shape != (6,):
        raise FkInputError(FkInputError.ONE_SET.format(what="assembly_modes", shape=L.shape))
    if polish is not None and not callable(polish):
        raise TypeError(
            f"polish must be a callable (lengths, p, R) -> (p, R, success, residual) or None, got {polish!r}"
        )
    t_start = time.perf_counter()
    rng = np.random.default_rng(seed)
    scale = anchor_scale(platform)
    size = max(np.abs(platform.base_anchors).max(), scale, L.max())
    n_max = max_solutions(platform)
    mirror = use_symmetry and is_planar(platform)
    P = np.zeros((0, 3))
    RR = np.zeros((0, 3, 3))
    starts = rounds = idle = 0
    t_newton = 0.0
    while rounds < max_rounds and len(P) < n_max and idle < patience:
        rounds += 1
        t0 = time.perf_counter()
        R0 = random_rotations(n_starts, rng)
        p0 = best_position(platform, R0, L)
        if rounds == 1:  # also start from home, so that the mode nearest home is always tried
            h = platform.home_pose()
            R0 = np.concatenate([rotation_matrix(h[3:], "utn")[None], R0])
            p0 = np.concatenate([h[None, :3], p0])
        starts += len(p0)
        p, R, _, _, status = newton_core(platform, p0, R0, np.broadcast_to(L, (len(p0), 6)), tol, 40, 0.25 * size, 0.5)
        ok = status == CONVERGED
        p, R = p[ok], R[ok]
        if mirror and len(p):
            pm, Rm = _mirror(p, R)
            p, R = np.concatenate([p, pm]), np.concatenate([R, Rm])
        before = len(P)
        P, RR = np.concatenate([P, p]), np.concatenate([RR, R])
        keep = _dedupe(P, RR, size, dedupe_tol)
        P, RR = P[keep], RR[keep]
        idle = idle + 1 if len(P) == before else 0
        t_newton += time.perf_counter() - t0
    if len(P) == 0:
        raise ForwardKinematicsError(
            f"forward kinematics: no assembly found for lengths ({', '.join(short_number(v * 1e3) for v in L)}) mm "
            f"from {starts} starts — the legs probably cannot be assembled on platform {platform.name!r}"
        )
    t0 = time.perf_counter()
    certified = np.zeros(len(P), bool)
    if polish is not None:
        for k in range(len(P)):
            p_k, R_k, success, residual = polish(L, P[k], RR[k])
            same = np.max(np.abs(np.concatenate([(p_k - P[k]) / size, (R_k - RR[k]).ravel()]))) < 1e-6
            certified[k] = success and residual <= CERTIFY_RESIDUAL and same
            if certified[k]:
                P[k], RR[k] = p_k, R_k
        # Final Newton polish from the program's point (quadratic convergence: one or two steps).
        P, RR, _, _, _ = newton_core(platform, P, RR, np.broadcast_to(L, (len(P), 6)), 1e-15, 3, 0.25 * size, 0.5)
    t_polish = time.perf_counter() - t0
    modes = modes_from_solutions(platform, P, RR, L, certified, convention)
    return AssemblyModes(
        modes, L, n_max, starts, rounds, time.perf_counter() - t_start, {"newton": t_newton, "polish": t_polish}
    )


def modes_from_solutions(platform, P, RR, L, certified, convention) -> list[AssemblyMode]:
    """``AssemblyMode``s (sorted nearest home first) for solutions p_BC ``(k, 3)``, R_BT ``(k, 3, 3)`` of
    lengths ``L (6,)``; ``certified`` ``(k,)`` says which the polish confirmed."""
    Lp, Jinv = legs_and_jacobian(platform, P, RR)
    res = np.abs(Lp - L).max(axis=-1)
    an = analyse_inverse_jacobian(Jinv, anchor_scale(platform))
    poses = np.concatenate([P, angles_from_matrix(RR, convention)], axis=-1)
    above = np.all(plate_anchors(platform, poses, convention)[..., 2] > 0, axis=-1)
    within = bool(check_stroke(platform, L).within)
    home = platform.home_pose()
    R_home = rotation_matrix(home[3:], "utn")
    cos_angle = np.clip((np.einsum("nij,ij->n", RR, R_home) - 1) / 2, -1, 1)
    dist = np.linalg.norm(P - home[:3], axis=-1) / anchor_scale(platform) + np.arccos(cos_angle)
    modes = [
        AssemblyMode(
            pose=poses[k],
            position=P[k],
            rotation=RR[k],
            residual=float(res[k]),
            det_sign=int(an.det_sign[k]),
            condition=float(an.condition[k]),
            sigma_min=float(an.sigma_min[k]),
            above_base=bool(above[k]),
            within_stroke=within,
            certified=bool(certified[k]),
            distance_to_home=float(dist[k]),
        )
        for k in range(len(P))
    ]
    return sorted(modes, key=lambda m: m.distance_to_home)
