"""Branch safety of a trajectory: how close does another assembly mode, or a singularity, come?

At each sampled pose q_k of a trajectory the leg lengths L(q_k) have several real assembly modes; the
platform is on the one at q_k. If another mode comes close, the two meet at a singularity nearby and
the platform could flip to the other branch (or the controller's forward kinematics could). For each
sample the complete homotopy solver (``solve_batch``, all samples in one batch) gives every real mode
with a certificate; we report

- ``branch_distance`` (m): the distance from q_k to the nearest *other* real mode, measured as
  sqrt(|Δp|² + (r θ)²) with θ the rotation angle between the two orientations and r the plate's
  anchor radius (so the rotation counts as the arc its anchors sweep);
- ``sigma_min``: the smallest singular value of the scaled inverse Jacobian at q_k (``fk``'s
  singularity distance: 0 on a singularity).

The check is only as complete as the solver: a sample whose result is not ``complete`` is reported.

Between the checked samples, every sample of the trajectory is followed by the real-time FK
(``core.realtime_fk``: compiled Newton from the previous sample, split into certified sub-steps where
needed): ``fk_certified`` says, per sample, that the FK a controller would run from the leg lengths
stays on the trajectory's branch (a Kantorovich certificate), and ``fk_radius`` is the certified
uniqueness radius around each pose — a lower bound on the distance to any other mode at every sample,
where ``branch_distance`` is exact at the checked ones.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from stewart_drake.core.geometry import Platform
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.core.newton_fk import anchor_scale, jacobian_analysis
from stewart_drake.core.realtime_fk import RealtimeFK
from stewart_drake.core.rotations import rotation_matrix
from stewart_drake.errors import OPTION_BRANCH_SAMPLES, OptionError
from stewart_drake.homotopy.solve import solve_batch

MAX_SAMPLES = 5000  # bound on the samples checked (each is one homotopy solve)
SAME_MODE = 1e-6  # m: the mode the platform is on is found within this of the sampled pose
FK_SUBSTEPS = 64  # certified sub-steps the real-time FK may split one sample-to-sample step into


@dataclass(frozen=True)
class BranchReport:
    """Per checked sample ``(k,)``: ``index`` into the trajectory, ``t`` (s), ``branch_distance`` (m,
    inf when the pose is the only real mode), ``sigma_min``, ``modes`` (real modes), ``complete``,
    ``on_mode`` (the sampled pose is among the certified modes). Per trajectory sample ``(n,)``:
    ``fk_certified`` (the real-time FK followed the branch to this pose, certified) and ``fk_radius``
    (m, the certified uniqueness radius around the previous pose). Worst values and where."""

    index: np.ndarray
    t: np.ndarray
    branch_distance: np.ndarray
    sigma_min: np.ndarray
    modes: np.ndarray
    complete: np.ndarray
    on_mode: np.ndarray
    t_all: np.ndarray = None
    fk_certified: np.ndarray = None
    fk_radius: np.ndarray = None

    def summary(self, branch_margin: float, singularity_margin: float) -> dict:
        kb = int(np.argmin(self.branch_distance))
        ks = int(np.argmin(self.sigma_min))
        kr = int(np.argmin(self.fk_radius))
        uncertified = np.flatnonzero(~self.fk_certified)
        return {
            "samples_checked": len(self.index),
            "min_branch_distance_m": float(self.branch_distance[kb]),
            "min_branch_distance_t_s": float(self.t[kb]),
            "min_sigma_min": float(self.sigma_min[ks]),
            "min_sigma_min_t_s": float(self.t[ks]),
            "branch_margin_m": branch_margin,
            "singularity_margin": singularity_margin,
            "modes_min": int(self.modes.min()),
            "modes_max": int(self.modes.max()),
            "all_complete": bool(self.complete.all()),
            "incomplete_samples": [int(i) for i in self.index[~self.complete]],
            "pose_found_at_every_sample": bool(self.on_mode.all()),
            "fk_samples_followed": len(self.fk_certified),
            "fk_certified_every_sample": bool(self.fk_certified.all()),
            "fk_uncertified_t_s": [float(self.t_all[k]) for k in uncertified[:10]],
            "fk_min_uniqueness_radius_m": float(self.fk_radius[kr]),
            "fk_min_uniqueness_radius_t_s": float(self.t_all[kr]),
            "safe": bool(
                self.branch_distance[kb] >= branch_margin
                and self.sigma_min[ks] >= singularity_margin
                and self.complete.all()
                and self.on_mode.all()
                and self.fk_certified.all()
            ),
        }


def sample_indices(n: int, samples: int) -> np.ndarray:
    """``(≤ samples,)`` evenly spaced indices of a trajectory of n samples, first and last included."""
    if not 2 <= samples <= MAX_SAMPLES:
        raise OptionError(OPTION_BRANCH_SAMPLES.format(limit=MAX_SAMPLES, value=samples))
    return np.unique(np.round(np.linspace(0, n - 1, min(n, samples))).astype(int))


def branch_safety(
    platform: Platform, t: np.ndarray, poses: np.ndarray, convention: str, samples: int = 200, seed: int = 0
) -> BranchReport:
    """Check ``samples`` evenly spaced poses of a trajectory (t ``(n,)`` s, poses ``(n, 6)`` m/rad in
    ``convention``); see the module docstring."""
    idx = sample_indices(len(poses), samples)
    q = np.asarray(poses, dtype=float)[idx]
    L = leg_lengths(platform, q, convention)
    results = solve_batch(platform, L, seed=seed)
    r_a = anchor_scale(platform)
    R_q = rotation_matrix(q[:, 3:], convention)
    dist = np.full(len(idx), np.inf)
    on = np.zeros(len(idx), bool)
    for k, r in enumerate(results):
        if not r.modes:
            continue
        P = np.array([m.position for m in r.modes])
        R = np.array([m.rotation for m in r.modes])
        cos = np.clip((np.einsum("nij,ij->n", R, R_q[k]) - 1) / 2, -1, 1)
        d = np.sqrt(np.sum((P - q[k, :3]) ** 2, axis=1) + (r_a * np.arccos(cos)) ** 2)
        me = int(np.argmin(d))
        on[k] = d[me] <= SAME_MODE and r.modes[me].certified
        others = np.delete(d, me)
        dist[k] = others.min() if len(others) else np.inf
    sig = jacobian_analysis(platform, q, convention).sigma_min
    fk_cert, fk_radius = follow(platform, poses, convention)
    return BranchReport(
        idx,
        np.asarray(t)[idx],
        dist,
        sig,
        np.array([len(r.modes) for r in results]),
        np.array([r.complete for r in results]),
        on,
        np.asarray(t, dtype=float),
        fk_cert,
        fk_radius,
    )


def follow(platform: Platform, poses: np.ndarray, convention: str) -> tuple[np.ndarray, np.ndarray]:
    """The real-time FK along every ``(n, 6)`` pose of a trajectory, each from the previous: ``(certified,
    radius)``, each ``(n,)``; certified also requires the followed pose to be the trajectory's own (1e-9 m and
    rad: the FK tolerance 1e-13 m over the smallest singular value of a pose the certificate accepts)."""
    q = np.asarray(poses, dtype=float)
    r = RealtimeFK(platform, convention, max_substeps=FK_SUBSTEPS).track(leg_lengths(platform, q, convention), q[0])
    on = np.all(np.abs(r.poses - q) <= 1e-9, axis=-1)
    return r.certified & on, r.radius
