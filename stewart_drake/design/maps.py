"""Design maps over a horizontal slice of the workspace (fixed height and orientation): Jacobian
condition number and distance to singularity with the assembly mode tracked, minimum stiffness and
softest direction, lowest natural frequency. All vectorised over the slice.

Assembly mode: the sign of det J⁻¹ (J⁻¹ = A, rows [u_i; r_i × u_i]) changes only through a singularity,
so the poses sharing the home pose's sign and connected to it without crossing a singular or
out-of-stroke node form the region the platform reaches in its home assembly. ``safe`` is that region
with the condition number below ``max_condition``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from stewart_drake.core.dynamics import G_EARTH
from stewart_drake.core.geometry import Platform
from stewart_drake.core.kinematics import inverse_jacobian, leg_lengths
from stewart_drake.core.rotations import rotation_matrix
from stewart_drake.design.envelope import spatial_inertia_about_C
from stewart_drake.design.modes import spatial_inertia
from stewart_drake.design.stiffness import principal_stiffness, stiffness_matrix
from stewart_drake.errors import SLICE_NODES, StewartError

MAX_POINTS = 4_000_000  # slice nodes (work bounded before allocating)
SAFE_CONDITION = 20.0  # default condition-number limit of the safe region


AXIS_NAMES = ("x", "y", "z", "roll", "pitch", "yaw")


@dataclass(frozen=True)
class SliceMaps:
    """Maps on an (n, n) grid over two pose coordinates ``axes`` (indices into the pose), values ``u``
    and ``v`` (n,) in SI (m or rad), the other coordinates at ``base`` (6,). NaN outside the stroke.
    ``condition`` (scaled 2-norm condition of J⁻¹), ``distance`` = 1/condition (0 at a singularity),
    ``same_mode`` (sign of det J⁻¹ equals home's), ``safe``; when stiffness is given: ``k_min`` (N/m,
    softest principal translational stiffness), ``softest`` (n, n, 3) its direction; with modes:
    ``f1`` (Hz) the lowest natural frequency."""

    u: np.ndarray
    v: np.ndarray
    axes: tuple
    base: np.ndarray
    within: np.ndarray
    condition: np.ndarray
    distance: np.ndarray
    same_mode: np.ndarray
    safe: np.ndarray
    k_min: np.ndarray | None = None
    softest: np.ndarray | None = None
    f1: np.ndarray | None = None


def slice_poses(
    platform: Platform, axes=(0, 1), ranges=((-0.15, 0.15), (-0.15, 0.15)), n: int = 61, base=None
) -> tuple:
    """``(u (n,), v (n,), poses (n, n, 6))``: pose coordinates ``axes`` over ``ranges`` (SI), the others
    at ``base`` (default the home pose)."""
    if not (isinstance(n, (int, np.integer)) and 2 <= n and n * n <= MAX_POINTS):
        raise StewartError(SLICE_NODES.format(n=n, limit=MAX_POINTS))
    base = platform.home_pose() if base is None else np.asarray(base, dtype=float).reshape(6)
    u = np.linspace(*ranges[0], n)
    v = np.linspace(*ranges[1], n)
    q = np.broadcast_to(base, (n, n, 6)).copy()
    q[..., axes[0]], q[..., axes[1]] = np.meshgrid(u, v, indexing="ij")
    return u, v, q


def lowest_frequency(K, M) -> np.ndarray:
    """``(...)`` lowest natural frequency (Hz) of batched (..., 6, 6) K, M: eigenvalues of
    L⁻¹ K L⁻ᵀ with M = L Lᵀ (Cholesky), symmetrised."""
    Lc = np.linalg.cholesky(M)
    X = np.linalg.solve(Lc, 0.5 * (K + np.swapaxes(K, -1, -2)))
    S = np.linalg.solve(Lc, np.swapaxes(X, -1, -2))
    w2 = np.linalg.eigvalsh(0.5 * (S + np.swapaxes(S, -1, -2)))[..., 0]
    return np.sqrt(np.maximum(w2, 0.0)) / (2 * np.pi)


def slice_maps(
    platform: Platform,
    axes=(0, 1),
    ranges=((-0.15, 0.15), (-0.15, 0.15)),
    n: int = 61,
    base=None,
    k=None,
    gravity: float = G_EARTH,
    modes: bool = False,
    max_condition: float = SAFE_CONDITION,
    convention: str = "utn",
) -> SliceMaps:
    """Maps over the slice (see ``SliceMaps``, ``slice_poses``); stiffness maps when leg stiffness ``k``
    (N/m) is given, and the lowest frequency too with ``modes`` (plate only). The safe region is the
    connected part holding the node nearest to the home pose's coordinates, of the nodes within
    the stroke, in the home assembly mode and with condition <= ``max_condition``."""
    x, y, q = slice_poses(platform, axes, ranges, n, base)
    L = leg_lengths(platform, q, convention)
    within = np.all((L >= platform.L_min) & (L <= platform.L_max), axis=-1)
    A = inverse_jacobian(platform, q, convention)
    scale = np.max(np.linalg.norm(platform.top_anchors - platform.rotation_centre, axis=1))
    An = np.concatenate([A[..., :3], A[..., 3:] / scale], -1)
    s = np.linalg.svd(An, compute_uv=False)
    with np.errstate(divide="ignore", invalid="ignore"):
        cond = np.where(s[..., -1] > 0, s[..., 0] / s[..., -1], np.inf)
    sign_home = np.sign(np.linalg.det(inverse_jacobian(platform, platform.home_pose(), convention)))
    same = np.sign(np.linalg.det(A)) == sign_home
    ok = within & same & (cond <= max_condition)
    from scipy import ndimage  # here: its import costs ~0.3 s CPU, and most users of this module never label

    labels, _ = ndimage.label(ok)
    home = platform.home_pose()[list(axes)]
    i0 = (int(np.argmin(np.abs(x - home[0]))), int(np.argmin(np.abs(y - home[1]))))
    safe = ok & (labels == labels[i0]) if ok[i0] else np.zeros_like(ok)
    nan = np.where(within, 1.0, np.nan)
    out = dict(
        u=x,
        v=y,
        axes=tuple(axes),
        base=q[0, 0].copy(),
        within=within,
        condition=cond * nan,
        distance=np.where(np.isfinite(cond), 1 / cond, 0.0) * nan,
        same_mode=same,
        safe=safe,
    )
    if k is not None:
        kmin = np.full(within.shape, np.nan)
        soft = np.full(within.shape + (3,), np.nan)
        good = within & np.isfinite(cond) & (cond < 1e8)
        K = stiffness_matrix(platform, q[good], k, convention, gravity)
        pr = principal_stiffness(K)
        kmin[good] = pr.translational[..., 0]
        soft[good] = pr.translational_dirs[..., :, 0]
        out.update(k_min=kmin, softest=soft)
        if modes:
            f1 = np.full(within.shape, np.nan)
            M = (
                np.stack([spatial_inertia(platform, qq, convention) for qq in q[good]])
                if good.sum() < 64
                else _inertia_batch(platform, q[good], convention)
            )
            f1[good] = lowest_frequency(K, M)
            out["f1"] = f1
    return SliceMaps(**out)


def _inertia_batch(platform: Platform, q, convention):
    return spatial_inertia_about_C(platform, rotation_matrix(q[..., 3:], convention))
