"""Design-analysis throughput: envelope sizing over a 10⁶-pose grid and a stiffness map of 10⁵ poses,
against per-pose references measured in the same run.

Run by hand: ``.venv/bin/python benchmarks/bench_design.py [--poses N] [--map-poses M]``. Prints poses
per second and ratios: the vectorised envelope worst case vs one inverse-dynamics evaluation per
(pose, acceleration-vertex, velocity-vertex) sample; the vectorised stiffness map vs a per-pose loop
and vs Drake's linearisation per pose (frequencies).
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from stewart_drake.core.geometry import load_preset
from stewart_drake.design.envelope import Envelope, cartesian_leg_forces, envelope_sizing
from stewart_drake.design.maps import lowest_frequency
from stewart_drake.design.modes import analytic_modes, spatial_inertia
from stewart_drake.design.stiffness import principal_stiffness, stiffness_matrix
from stewart_drake.drake.design_checks import drake_modes


def grid(n_total: int) -> np.ndarray:
    """About ``n_total`` poses on a 6-D grid around home (±50 mm, 680–720 mm, ±5°)."""
    m = max(2, int(round(n_total ** (1 / 6))))
    axes = [np.linspace(-0.05, 0.05, m), np.linspace(-0.05, 0.05, m), np.linspace(0.68, 0.72, m)] + [
        np.radians(np.linspace(-5, 5, m))
    ] * 3
    return np.stack(np.meshgrid(*axes, indexing="ij"), -1).reshape(-1, 6)


def timed(fn):
    t0 = time.perf_counter()
    out = fn()
    return time.perf_counter() - t0, out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--poses", type=int, default=1_000_000, help="envelope poses (default 10⁶: a 10^6 grid)")
    ap.add_argument("--map-poses", type=int, default=100_000, help="stiffness-map poses (default 10⁵)")
    args = ap.parse_args(argv)
    p = load_preset("utn-dynamic")
    v_max = np.array([0.3, 0.3, 0.2, 0.5, 0.5, 1.0])
    a_max = np.array([3.0, 3.0, 5.0, 10.0, 10.0, 20.0])

    poses = grid(args.poses)
    env = Envelope(poses, v_max, a_max)
    t_env, es = timed(lambda: envelope_sizing(p, env))
    # Reference: brute force over the 2^6 acceleration vertices × 2^3 angular-velocity vertices (a lower
    # bound of the worst case, 512 inverse-dynamics samples per pose) on a subset.
    sub = poses[:: max(1, len(poses) // 200)]
    signs_a = np.array(np.meshgrid(*[[-1.0, 1.0]] * 6, indexing="ij")).reshape(6, -1).T
    signs_w = np.array(np.meshgrid(*[[-1.0, 1.0]] * 3, indexing="ij")).reshape(3, -1).T
    A = np.repeat(signs_a * a_max, len(signs_w), 0)
    V = np.zeros((len(A), 6))
    V[:, 3:] = np.tile(signs_w * v_max[3:], (len(signs_a), 1))

    def brute():
        out = []
        for q in sub:
            F = cartesian_leg_forces(p, np.broadcast_to(q, (len(A), 6)), V, A)
            out.append(np.abs(F).max(0))
        return np.array(out)

    t_brute, Fb = timed(brute)
    idx = np.arange(0, len(poses), max(1, len(poses) // 200))[: len(sub)]
    gap = float(np.max(Fb - es.peak_force[idx]))

    mp = grid(args.map_poses)
    k = np.full(6, 1e5)
    t_map, _ = timed(lambda: principal_stiffness(stiffness_matrix(p, mp, k)))
    t_f1, _ = timed(lambda: lowest_frequency(stiffness_matrix(p, mp, k), _inertia(p, mp)))
    n_loop = 300
    t_loop, _ = timed(lambda: [principal_stiffness(stiffness_matrix(p, q, k)) for q in mp[:n_loop]])
    n_dk = 30
    t_dk, _ = timed(lambda: [drake_modes(p, q, k) for q in mp[:n_dk]])
    t_an, _ = timed(lambda: [analytic_modes(stiffness_matrix(p, q, k), spatial_inertia(p, q)) for q in mp[:n_dk]])

    print(f"platform {p.name}")
    r_env = len(poses) / t_env
    r_brute = len(sub) / t_brute
    print(
        f"envelope sizing, {len(poses):,} poses (worst case per pose and leg, exact):  {t_env:7.2f} s  {r_env:12,.0f} poses/s"
    )
    print(
        f"  brute force over 512 vertex samples per pose ({len(sub)} poses):           {t_brute:7.2f} s  {r_brute:12,.0f} poses/s  -> {r_env / r_brute:,.0f}x"
    )
    print(f"  brute force never beats the worst case: max(brute - worst) = {gap:.2e} N (<= 0 expected)")
    r_map = len(mp) / t_map
    print(
        f"stiffness map, {len(mp):,} poses (K under load + principal stiffnesses):     {t_map:7.2f} s  {r_map:12,.0f} poses/s"
    )
    print(
        f"  per-pose loop ({n_loop} poses):                                          {t_loop:7.2f} s  {n_loop / t_loop:12,.0f} poses/s  -> {r_map / (n_loop / t_loop):,.0f}x"
    )
    print(
        f"lowest-frequency map, {len(mp):,} poses (K, M_C, batched Cholesky + eigvalsh): {t_f1:7.2f} s  {len(mp) / t_f1:12,.0f} poses/s"
    )
    print(
        f"  analytic modes per pose ({n_dk}):                                          {t_an:7.2f} s  {n_dk / t_an:12,.0f} poses/s"
    )
    print(
        f"  Drake Linearize per pose ({n_dk}):                                         {t_dk:7.2f} s  {n_dk / t_dk:12,.1f} poses/s  -> batched {len(mp) / t_f1 / (n_dk / t_dk):,.0f}x"
    )
    return 0


def _inertia(p, q):
    from stewart_drake.core.rotations import rotation_matrix
    from stewart_drake.design.envelope import spatial_inertia_about_C

    return spatial_inertia_about_C(p, rotation_matrix(q[..., 3:]))


if __name__ == "__main__":
    raise SystemExit(main())
