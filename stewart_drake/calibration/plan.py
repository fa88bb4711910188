"""Planning the measurement: N poses inside a workspace box that make the identification well-posed.

Criterion: **D-optimal** (maximise det Σ A_kᵀ A_k over the identifiable parameters, ``model.reduced_blocks``).
Chosen over the noise-amplification index (O5 = s_min²/s_max, reported for both sets) because it is
invariant to how θ is scaled or combined (only the parameters' units change it, by a constant), because it is
smooth in the poses' contributions (a pose's gain is log det(I + A_k M⁻¹ A_kᵀ), exact rank-one-block
updates: a greedy build and a Fedorov exchange are well-posed and cheap), and because it minimises the
volume of the parameters' confidence ellipsoid, which is what the validation error integrates over the
workspace; O5 depends on the single worst direction only and its maximiser jumps from pose to pose.

Candidates are drawn uniformly in the box about home (seeded) and kept when every leg is within the
stroke with a margin, every plate anchor is above the base and the Jacobian's condition number is at most
``MAX_CONDITION_RATIO`` × its value at home (away from singularities).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from stewart_drake.calibration.identifiability import Identifiability, analyse, free_parameters, stacked
from stewart_drake.calibration.measurements import Measurements
from stewart_drake.calibration.model import Layout, Noise, Problem, make_problem, measure, pose_blocks, reduced_blocks
from stewart_drake.calibration.simulate import default_targets
from stewart_drake.core.geometry import Platform
from stewart_drake.core.kinematics import check_stroke, condition_number, leg_lengths, plate_anchors
from stewart_drake.core.rotations import rotation_matrix
from stewart_drake.errors import CalibrationError

CANDIDATES = 1000
STROKE_MARGIN = 0.02  # of the stroke range, at each end
MAX_CONDITION_RATIO = 3.0
EXCHANGE_PASSES = 3
MAX_POSES = 500


@dataclass(frozen=True)
class Box:
    """The workspace to plan in: ±``x``, ±``y``, ±``z`` metres about home and ±``rotation`` rad per angle."""

    x: float
    y: float
    z: float
    rotation: float

    @classmethod
    def default(cls, platform: Platform) -> Box:
        span = platform.L_max - platform.L_min
        return cls(0.3 * span, 0.3 * span, 0.2 * span, np.radians(20.0))

    def to_dict(self) -> dict:
        return {"x_m": self.x, "y_m": self.y, "z_m": self.z, "rotation_rad": self.rotation}

    def describe(self) -> str:
        """The box in words: ``±0.12 m x, ±0.12 m y, ±0.08 m z, ±20° per angle about home``."""
        return (
            f"±{self.x:.4g} m x, ±{self.y:.4g} m y, ±{self.z:.4g} m z, ±{np.degrees(self.rotation):.4g}° per angle "
            "about home"
        )


@dataclass
class PlanResult:
    """``poses`` (n, 6) planned, ``random`` (n, 6) drawn from the same candidates, and the identifiability
    of each set (``planned``, ``baseline``)."""

    platform: str
    kind: str
    poses: np.ndarray
    random: np.ndarray
    planned: Identifiability
    baseline: Identifiability
    box: Box
    candidates: int
    seed: int

    def to_dict(self) -> dict:
        def idx(i: Identifiability) -> dict:
            d = i.to_dict()
            return {
                k: d[k]
                for k in ("d_index", "noise_amplification_index", "condition_number", "identifiable", "unidentifiable")
            }

        return {
            "platform": self.platform,
            "measurement_type": self.kind,
            "criterion": "D-optimal (det of the identification information, poses' unknowns eliminated)",
            "poses": len(self.poses),
            "candidates": self.candidates,
            "seed": self.seed,
            "workspace": self.box.to_dict(),
            "planned": idx(self.planned),
            "random": idx(self.baseline),
            "d_index_ratio": self.planned.d_index / self.baseline.d_index if self.baseline.d_index > 0 else None,
            "unidentifiable": self.planned.to_dict()["unidentifiable_combinations"],
            "frame_freedoms": self.planned.frame_freedoms,
            "fixed_by_convention": [self.planned.names[i] for i in self.planned.fixed],
        }


def candidate_poses(platform: Platform, box: Box, count: int, seed: int, convention: str = "utn") -> np.ndarray:
    """``(m, 6)`` acceptable poses (see the module docstring) among ``count`` drawn in ``box``; seeded."""
    rng = np.random.default_rng(seed)
    half = np.array([box.x, box.y, box.z, box.rotation, box.rotation, box.rotation])
    q = platform.home_pose() + rng.uniform(-1, 1, (count, 6)) * half
    margin = STROKE_MARGIN * (platform.L_max - platform.L_min)
    L = leg_lengths(platform, q, convention)
    ok = check_stroke(platform, L).within & np.all((L > platform.L_min + margin) & (L < platform.L_max - margin), -1)
    ok &= np.all(plate_anchors(platform, q, convention)[..., 2] > 0, axis=-1) | platform.plate_below_base_allowed
    home = float(condition_number(platform, platform.home_pose(), convention))
    ok[ok] &= condition_number(platform, q[ok], convention) <= MAX_CONDITION_RATIO * home
    return q[ok]


def design_problem(
    platform: Platform, poses, kind: str, noise: Noise, convention: str = "utn", n_targets: int = 3, gains: bool = False
):
    """``(layout, problem)`` of noise-free measurements of the nominal at ``poses`` (for the design)."""
    q = np.asarray(poses, dtype=float)
    K = n_targets if kind == "points" else 0
    targets = default_targets(platform, K) if K else None
    m = measure(platform, q, convention, targets)
    n = len(q)
    data = Measurements(
        kind,
        m["readings"],
        q if kind == "pose" else None,
        m.get("targets"),
        m["tilts"] if kind == "inclinometer" else None,
        np.ones(n),
        np.arange(2, n + 2),
    )
    layout = Layout(platform, kind, K, gains)
    if kind == "pose":
        problem = make_problem(layout, data, noise, convention)
    else:
        problem = Problem(layout, data, noise, convention, q[:, :3], rotation_matrix(q[:, 3:], convention))
    return layout, problem, layout.theta(platform, targets)


def _gains(F: np.ndarray, Minv: np.ndarray) -> np.ndarray:
    """``(m,)`` log det(I + F_k M⁻¹ F_kᵀ) for blocks ``F`` ``(m, rows, p)``."""
    G = np.eye(F.shape[1]) + F @ Minv @ np.swapaxes(F, -1, -2)
    return np.linalg.slogdet(G)[1]


def d_optimal(F: np.ndarray, n: int) -> np.ndarray:
    """Indices of ``n`` of the blocks ``F`` ``(m, rows, p)`` that (locally) maximise det Σ F_kᵀ F_k: a greedy
    build from a small ridge, then ``EXCHANGE_PASSES`` Fedorov exchange passes."""
    m, _, p = F.shape
    info = np.einsum("kri,krj->kij", F, F)
    ridge = 1e-9 * np.trace(info.sum(0)) / p * np.eye(p)
    M = ridge.copy()
    chosen: list[int] = []
    for _ in range(n):
        g = _gains(F, np.linalg.inv(M))
        g[chosen] = -np.inf
        k = int(np.argmax(g))
        chosen.append(k)
        M += info[k]
    for _ in range(EXCHANGE_PASSES):
        swapped = False
        for slot in range(n):
            i = chosen[slot]
            Mi = M - info[i]
            Minv = np.linalg.inv(Mi)
            g = _gains(F, Minv)
            g[chosen] = -np.inf
            j = int(np.argmax(g))
            if g[j] > _gains(F[i : i + 1], Minv)[0] + 1e-9:
                chosen[slot] = j
                M = Mi + info[j]
                swapped = True
        if not swapped:
            break
    return np.array(chosen)


def plan_measurements(
    platform: Platform,
    n: int,
    kind: str = "pose",
    box: Box | None = None,
    noise: Noise = Noise(),
    seed: int = 0,
    convention: str = "utn",
    candidates: int = CANDIDATES,
    n_targets: int = 3,
    gains: bool = False,
) -> PlanResult:
    """Plan ``n`` measurement poses (D-optimal, see the module docstring) and draw ``n`` random ones from
    the same candidates for comparison; both sets' identifiability is analysed. A σ below ``model.NOISE_FLOOR`` weighs
    as the floor (``Noise.floored``)."""
    noise = noise.floored()
    box = box or Box.default(platform)
    cand = candidate_poses(platform, box, candidates, seed, convention)
    if len(cand) < max(2 * n, 50):
        raise CalibrationError(
            CalibrationError.CANDIDATES.format(name=platform.name, got=len(cand), want=candidates, box=box.describe())
        )
    layout, problem, theta = design_problem(platform, cand, kind, noise, convention, n_targets, gains)
    A = reduced_blocks(*pose_blocks(problem, theta)) * noise.length
    _, free = free_parameters(A.reshape(-1, A.shape[-1]))  # what the whole candidate set can identify
    chosen = d_optimal(A[:, :, free], n)
    rand = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(1,))).choice(len(cand), n, replace=False)
    planned = analyse(layout, stacked(A[chosen], 1.0), theta)
    baseline = analyse(layout, stacked(A[rand], 1.0), theta)
    return PlanResult(platform.name, kind, cand[chosen], cand[rand], planned, baseline, box, len(cand), seed)


def stw_program(poses, platform: str, move_time: float = 2.0, settle: float = 1.0) -> str:
    """A motion program (.stw, SI units) that visits ``(n, 6)`` poses, waiting ``settle`` s at each for the
    measurement, and returns home."""
    lines = [
        f"// {len(poses)} calibration poses for platform {platform}, planned by stewart-drake plan-measurements.",
        "// At each pose: wait, then record the leg sensors and the measurement.",
        "units m, rad",
    ]
    for k, q in enumerate(np.asarray(poses, dtype=float), 1):
        lines.append(f"move({', '.join(repr(float(v)) for v in q)}) in {move_time:g}   // pose {k}")
        lines.append(f"wait {settle:g}")
    return "\n".join(lines) + "\n"
