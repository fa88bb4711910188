"""Inverse and forward kinematics: ``ik`` (closed form, vectorised) and ``fk`` (Newton from home, or every
assembly mode by the complete homotopy or the multi-start search)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from stewart_drake.api.result import Result
from stewart_drake.core.argcheck import as_choice, as_flag, as_int, as_real, as_real_array, check_shape, param
from stewart_drake.core.geometry import Platform, check_platform
from stewart_drake.core.kinematics import check_stroke, leg_lengths
from stewart_drake.core.rotations import check_convention
from stewart_drake.core.sanity import (
    below_base_message,
    check_finite,
    check_poses,
    check_positive,
    check_work,
    plate_anchor_heights,
)
from stewart_drake.errors import API_POSE_SHAPE, UsageError

# Newton converges quadratically from a good start (< 20 iterations); beyond this many it is not
# converging, and each iteration costs a Jacobian solve.
MAX_ITER = 1000
# The all-mode searches ``fk`` offers.
FK_METHODS = ("homotopy", "multi-start")
# numpy's seed sequences take any non-negative integer; the searches' seeds are stored as 64-bit words.
MAX_SEED = 2**63 - 1


@dataclass(repr=False)
class IKResult(Result):
    """Leg lengths for poses (``ik``). ``to_dict()`` is one pose's dict for a single pose ``(6,)``, else
    ``{"platform", "results": [one dict per pose]}`` (as ``stewart-drake ik --pose`` / ``--poses`` print).

    Attributes:
        poses: ``(..., 6)`` the poses asked for (m, rad).
        lengths: ``(..., 6)`` leg lengths, m.
        within_stroke: ``(...)`` every leg within ``[L_min, L_max]``.
        above_base: ``(...)`` every plate anchor above the base plane (or the platform allows it).
        violations: one list per pose (in C order of the leading dimensions) of the stroke violations
            ``{"leg", "side", "length", "limit", "excess"}`` (m).
        notes: flat pose index -> why the plate is below the base.
        platform: the platform's name.
        convention: the Euler convention of the poses.
        readings: ``(..., 6)`` what the leg sensors read at those lengths, m (``legs.length_offset`` and
            ``legs.length_gain`` of a calibrated platform), or None when every sensor reads the length itself.
    """

    poses: np.ndarray
    lengths: np.ndarray
    within_stroke: np.ndarray
    above_base: np.ndarray
    violations: list
    notes: dict
    platform: str
    convention: str
    readings: np.ndarray | None = None

    @property
    def ok(self) -> bool:
        """Every pose within the stroke and above the base."""
        return bool(np.all(self.within_stroke & self.above_base))

    def _fields(self) -> dict:
        flat = self.poses.reshape(-1, 6).tolist()
        lengths = self.lengths.reshape(-1, 6).tolist()
        readings = None if self.readings is None else self.readings.reshape(-1, 6).tolist()
        within, above = self.within_stroke.reshape(-1), self.above_base.reshape(-1)
        results = [
            {
                "pose": flat[i],
                "lengths": lengths[i],
                **({"readings": readings[i]} if readings is not None else {}),
                "length_unit": "m",
                "angle_unit": "rad",
                "within_stroke": bool(within[i]),
                "above_base": bool(above[i]),
                "violations": self.violations[i],
            }
            for i in range(len(flat))
        ]
        if self.poses.ndim == 1:
            return results[0]
        return {"platform": self.platform, "results": results}


def ik(platform: Platform, poses: ArrayLike, convention: str = "utn") -> IKResult:
    """Leg lengths for poses (closed-form inverse kinematics), with the stroke and base checks.

    Args:
        platform: the platform (see `load_platform`).
        poses: ``(..., 6)`` poses ``[px, py, pz, a, b, g]`` in metres and radians.
        convention: Euler convention of the angles (``"utn"``: Ry·Rx·Rz, or ``"zyx"``).

    Returns:
        The lengths and, per pose, whether it is within the stroke and above the base.

    Raises:
        StewartError: a pose that is not finite or far outside the platform (a unit mistake).
    """
    return solve_ik(platform, poses, convention)


def solve_ik(platform: Platform, poses, convention: str = "utn", what: str = "pose", lines=None) -> IKResult:
    """``ik`` with the name its errors give the poses (``what``, and the file ``lines`` they came from)."""
    check_platform(platform)
    check_convention(convention)
    q = as_real_array(poses, param("poses"))
    if q.shape[-1:] != (6,):
        raise UsageError(API_POSE_SHAPE.format(what=what, shape=q.shape))
    flat = q.reshape(-1, 6)
    check_poses(platform, flat, convention, what=what, lines=lines, base=False)
    L = leg_lengths(platform, flat, convention)
    check = check_stroke(platform, L)
    z = plate_anchor_heights(platform, flat, convention)  # (n, 6) m
    above = np.all(z > 0, axis=1) | platform.plate_below_base_allowed
    within = check.within
    bad = np.flatnonzero(~(within & above))  # per-pose details only for the poses that fail
    viol: list[list] = [[] for _ in range(len(flat))]
    for side, arr, lim in (("min", check.below, platform.L_min), ("max", check.above, platform.L_max)):
        for i, leg in np.argwhere(arr[bad] > 0):
            n = int(bad[i])
            viol[n].append(
                {
                    "leg": int(leg) + 1,
                    "side": side,
                    "length": float(L[n, leg]),
                    "limit": lim,
                    "excess": float(arr[n, leg]),
                }
            )
    for v in viol:
        v.sort(key=lambda d: d["leg"])
    notes = {int(i): below_base_message("pose", z[i]) for i in np.flatnonzero(~above)}
    lead = q.shape[:-1]
    offsets = np.any(platform.length_offset) or platform.has_sensor_gains
    return IKResult(
        q,
        L.reshape(q.shape),
        within.reshape(lead),
        above.reshape(lead),
        viol,
        notes,
        platform.name,
        convention,
        platform.readings(L).reshape(q.shape) if offsets else None,
    )


@dataclass(repr=False)
class FKSolution(Result):
    """One assembly mode found by ``fk``.

    Attributes:
        pose: ``(6,)`` the pose (m, rad).
        residual: leg-length residual, m.
        det_sign: sign of the Jacobian's determinant (which side of the singularity surface).
        condition: condition number of the Jacobian.
        sigma_min: smallest singular value of the scaled inverse Jacobian.
        above_base: every plate anchor above the base plane.
        within_stroke: every leg within the stroke.
        certified: an exact solution lies within ``extra["certified_radius"]`` (homotopy only).
        distance_to_home: distance of the pose from home (m and rad combined).
        method: ``"newton"``, ``"homotopy"`` or ``"multi-start"``.
        extra: method-specific numbers (iterations; path, certified_radius, uniqueness_radius,
            position_bound (m), angle_bound (rad), singular: a multiple root on a singularity, not certified).
    """

    pose: np.ndarray
    residual: float
    det_sign: int
    condition: float
    sigma_min: float
    above_base: bool
    within_stroke: bool
    certified: bool
    distance_to_home: float
    method: str
    extra: dict = field(default_factory=dict)

    def _fields(self) -> dict:
        return {
            "pose": self.pose,
            "residual": self.residual,
            "det_sign": self.det_sign,
            "condition": self.condition,
            "sigma_min": self.sigma_min,
            "above_base": self.above_base,
            "within_stroke": self.within_stroke,
            "certified": self.certified,
            "distance_to_home": self.distance_to_home,
            "converged": True,
            **({"iterations": self.extra["iterations"]} if "iterations" in self.extra else {}),
            "method": self.method,
            **{k: v for k, v in self.extra.items() if k != "iterations"},
        }


@dataclass(repr=False)
class FKResult(Result):
    """Poses for six leg lengths (``fk``).

    Attributes:
        solutions: the assembly modes found, nearest home first (one without ``all_modes``).
        method: how they were found (``"newton"``, ``"homotopy"``, ``"multi-start"``, or Newton's fallback).
        complete: every mode is known to be found (homotopy: certified; multi-start: all it can prove);
            None for a single Newton solution.
        lengths: ``(6,)`` the leg lengths, m.
        platform: the platform's name.
        convention: the Euler convention of the poses.
        info: the method's counts and guarantee (paths, max_solutions, guarantee, starts, ...).
    """

    solutions: list
    method: str
    complete: bool | None
    lengths: np.ndarray
    platform: str
    convention: str
    info: dict = field(default_factory=dict)
    below_base_allowed: bool = False

    @property
    def ok(self) -> bool:
        """What ``fk`` exits 0 for: a complete answer (homotopy: at least one mode), every mode within the
        stroke, and the plate above the base (one mode: in it; all modes: in at least one); no mode on a
        singularity (homotopy: a multiple root, ``extra["singular"]``)."""
        if self.method == "homotopy" and not (self.complete and self.solutions):
            return False
        if any(s.extra.get("singular") for s in self.solutions):  # a pose on a singularity: a physical limit
            return False
        above = [s.above_base or self.below_base_allowed for s in self.solutions]
        physical = any(above) if self.method in ("homotopy", "multi-start") else all(above)
        return all(s.within_stroke for s in self.solutions) and physical

    def _fields(self) -> dict:
        out = {
            "platform": self.platform,
            "lengths": self.lengths,
            "length_unit": "m",
            "angle_unit": "rad",
            "convention": self.convention,
            "solutions": [s.to_dict() for s in self.solutions],
            "method": self.method,
        }
        for k, v in self.info.items():  # the CLI's key order: complete after the counts
            out[k] = v
            if k == "max_solutions" and self.complete is not None:
                out["complete"] = self.complete
        return out


def fk(
    platform: Platform,
    lengths: ArrayLike,
    all_modes: bool = False,
    *,
    initial: ArrayLike | None = None,
    convention: str = "utn",
    method: str = "homotopy",
    tol: float = 1e-13,
    max_iter: int = 30,
    seed: int = 0,
) -> FKResult:
    """Forward kinematics: the pose(s) for six leg lengths.

    Without ``all_modes``: Newton-Raphson from the home pose (or ``initial``); if it does not converge, the
    multi-start search (which needs Drake) returns the mode nearest home. With ``all_modes``: every assembly
    mode, nearest home first, by the complete parameter homotopy (each real mode certified) or, with
    ``method="multi-start"``, the multi-start search confirmed by Drake's MathematicalProgram.

    Args:
        platform: the platform.
        lengths: ``(6,)`` leg lengths, m.
        all_modes: find every assembly mode.
        initial: ``(6,)`` Newton's initial pose (m, rad); default the home pose.
        convention: Euler convention of the returned poses.
        method: with ``all_modes``: ``"homotopy"`` or ``"multi-start"``.
        tol: Newton's tolerance on the leg lengths, m.
        max_iter: Newton's iteration limit (at most 1000).
        seed: random seed of the multi-start search and of the homotopy's gamma.

    Returns:
        The solutions and how complete they are.

    Raises:
        StewartError: lengths not positive and finite, a tolerance or iteration limit out of range.
    """
    return solve_fk(platform, lengths, all_modes, initial, convention, method, tol, max_iter, seed)


def solve_fk(
    platform,
    lengths,
    all_modes,
    initial,
    convention,
    method,
    tol,
    max_iter,
    seed,
    *,
    what="lengths",
    unit="m",
    given=None,
) -> FKResult:
    """``fk`` with the names its errors give the lengths: ``what``, and ``given`` (the values as the user wrote
    them, in ``unit``; default ``lengths`` in metres)."""
    # deferred: the FK solvers are for this function alone, and `ik` (this module's other command) starts without
    from stewart_drake.core.assembly_modes import modes_from_solutions
    from stewart_drake.core.newton_fk import forward_kinematics, multiple_root
    from stewart_drake.core.realtime_fk import branch_check

    check_platform(platform)
    L = check_shape(lengths, what, (6,))
    given = L if given is None else given
    for i, v in enumerate(given, 1):
        if not v > 0:
            raise UsageError(f"{what}: leg {i} length {v} {unit} must be a positive number")
    check_finite(given, what)
    all_modes = as_flag(all_modes, param("all_modes"))
    if initial is not None:
        initial = check_shape(initial, param("initial"), (6,))
        check_finite(initial, param("initial"))
    check_convention(convention)
    method = as_choice(method, param("method"), FK_METHODS)
    tol = check_positive(as_real(tol, param("tol")), param("tol"), "metres")
    max_iter = as_int(max_iter, param("max_iter"), 1)
    seed = as_int(seed, param("seed"), 0, MAX_SEED)
    check_work(
        param("max_iter"),
        str(max_iter),
        max_iter,
        "Newton iterations",
        max_count=MAX_ITER,
        hint="; Newton converges in a few tens of iterations or not at all",
    )
    common = (L, platform.name, convention)
    allowed = {"below_base_allowed": platform.plate_below_base_allowed}
    if not all_modes:
        r = forward_kinematics(platform, L, initial, convention, tol=tol, max_iter=max_iter, on_singular="warn")
        if r.converged:
            mode = modes_from_solutions(
                platform, r.iterate[None, :3], r.rotation[None], L, np.array([False]), convention
            )
            start = platform.home_pose() if initial is None else initial
            on_branch, radius = branch_check(platform, start, L, r.iterate[:3], r.rotation, convention)
            sol = _solution(
                mode[0],
                "newton",
                iterations=int(r.iterations),
                branch_certified=on_branch,
                uniqueness_radius_initial=radius,
                **(
                    {"singular": True}
                    if multiple_root(platform, mode[0].pose, mode[0].sigma_min, tol, convention)
                    else {}
                ),
            )
            return FKResult([sol], "newton", None, *common, **allowed)
    if all_modes and method == "homotopy":
        return _homotopy_all(platform, L, convention, seed, common, allowed)
    # Deferred: the multi-start search is confirmed by Drake's MathematicalProgram; Newton and the homotopy
    # run without pydrake.
    from stewart_drake.drake.program_fk import assembly_modes

    am = assembly_modes(platform, L, convention, seed=seed, tol=min(tol, 1e-13))
    sols = [_solution(m, "multi-start") for m in am.modes]
    return FKResult(
        sols if all_modes else sols[:1],
        "multi-start" if all_modes else "newton failed from the initial pose; multi-start, nearest home",
        am.complete,
        *common,
        info={"modes_found": len(am), "max_solutions": am.max_solutions, "starts": am.starts},
        **allowed,
    )


def _solution(mode, method: str, **extra) -> FKSolution:
    return FKSolution(
        mode.pose,
        mode.residual,
        mode.det_sign,
        mode.condition,
        mode.sigma_min,
        mode.above_base,
        mode.within_stroke,
        mode.certified,
        mode.distance_to_home,
        method,
        dict(extra),
    )


def _homotopy_all(platform, L, convention: str, seed: int, common, allowed) -> FKResult:
    """Every mode by the complete homotopy solver: nearest home first, each with its certificate."""
    # deferred: the homotopy solver and its compiled tracker (cffi) are for all-mode FK alone
    from stewart_drake.core.assembly_modes import modes_from_solutions
    from stewart_drake.homotopy import solve

    r = solve(platform, L, seed=seed)
    sols = []
    for hm in r.modes:
        mode = modes_from_solutions(
            platform, hm.position[None], hm.rotation[None], L, np.array([hm.certified]), convention
        )[0]
        sols.append(
            _solution(
                mode,
                "homotopy",
                path=hm.path,
                certified_radius=hm.radius,
                uniqueness_radius=hm.uniqueness,
                position_bound=hm.position_bound,
                angle_bound=hm.angle_bound,
                singular=hm.singular,
            )
        )
    sols.sort(key=lambda s: s.distance_to_home)
    info = dict(
        modes_found=len(sols),
        max_solutions=r.max_solutions,
        guarantee=r.guarantee,
        architecture=r.kind,
        architecture_text=r.architecture,
        paths=r.counts(),
        path_classes=list(r.classes),
        failed_paths=r.failed_paths,
        retracked_paths=r.retracked,
        stage=r.stage,
        engine=r.engine,
        certificate="Krawczyk/Kantorovich existence and uniqueness in Study coordinates (e·e = 1): an exact solution "
        "lies within certified_radius of the returned point, no other within uniqueness_radius; position_bound / "
        "angle_bound are the implied pose bounds",
    )
    return FKResult(sols, "homotopy", r.complete, *common, info=info, **allowed)
