"""Design maps over a workspace slice: each map node equals the single-pose computation."""

from __future__ import annotations

import numpy as np

from stewart_drake.core.geometry import load_platform
from stewart_drake.core.kinematics import condition_number
from stewart_drake.design.maps import slice_maps
from stewart_drake.design.modes import analytic_modes, spatial_inertia
from stewart_drake.design.stiffness import principal_stiffness, stiffness_matrix


def test_slice_maps_match_single_pose_computations():
    p = load_platform("utn-dynamic")
    o = np.radians([8.0, -5.0, 20.0])
    base = np.r_[0.0, 0.0, p.home_height, o]
    m = slice_maps(p, ranges=((-0.5, 0.5), (-0.5, 0.5)), n=21, base=base, k=1e5, modes=True)
    assert m.within.any() and not m.within.all()  # the slice reaches past the stroke
    assert np.all(np.isnan(m.condition[~m.within]))
    for i, j in [(10, 10), (3, 14), (16, 5)]:
        if not m.within[i, j]:
            continue
        q = np.r_[m.u[i], m.v[j], p.home_height, o]
        assert np.isclose(m.condition[i, j], condition_number(p, q), rtol=1e-10)
        K = stiffness_matrix(p, q, 1e5)
        pr = principal_stiffness(K)
        assert np.isclose(m.k_min[i, j], pr.translational[0], rtol=1e-10)
        assert abs(abs(m.softest[i, j] @ pr.translational_dirs[:, 0]) - 1) < 1e-8
        f = analytic_modes(K, spatial_inertia(p, q)).frequencies_hz
        assert np.isclose(m.f1[i, j], f[0], rtol=1e-9)
    assert m.safe[10, 10]  # home is safe
    assert np.all(m.safe <= (m.within & m.same_mode))


def test_assembly_mode_flips_across_a_singularity():
    """Turning the 3-6 plate about z far enough crosses a singularity: det J⁻¹ changes sign there and the
    far side is not in the home assembly's safe region."""
    p = load_platform("utn-dynamic")
    m = slice_maps(p, axes=(0, 5), ranges=((-0.05, 0.05), np.radians([-120.0, 120.0])), n=25)
    yaw = np.degrees(m.v)
    assert m.within.all()
    beyond = np.abs(yaw) > 90
    assert not m.same_mode[:, beyond].any() and m.same_mode[:, np.abs(yaw) < 90].all()  # at ±90° det J⁻¹ = 0
    assert not m.safe[:, np.abs(yaw) >= 80].any() and m.safe[:, np.abs(yaw) <= 30].all()


def test_cli_stiffness_map(tmp_path):
    from stewart_drake.cli import main

    out = tmp_path / "maps"
    assert (
        main(
            [
                "stiffness",
                "--pose",
                "0",
                "0",
                "700",
                "5",
                "0",
                "30",
                "--map",
                str(out),
                "--map-n",
                "9",
                "--map-half-width",
                "300",
            ]
        )
        == 0
    )
    assert (out / "maps.png").stat().st_size > 1000
    d = np.load(out / "maps.npz")
    p = load_platform("utn-dynamic")
    q = np.r_[d["x_m"][2], d["y_m"][6], 0.7, np.radians([5.0, 0.0, 30.0])]
    assert np.isclose(
        d["k_min_n_per_m"][2, 6], principal_stiffness(stiffness_matrix(p, q, 1e5)).translational[0], rtol=1e-10
    )
    assert main(["stiffness", "--pose", "0", "0", "700", "0", "0", "0", "--map", str(out), "--map-n", "5000"]) == 2
    assert (out / "maps.png").exists()  # a refused run leaves the earlier output alone
