"""Design maps over a workspace slice (issue 16): each map node equals the single-pose computation."""

from __future__ import annotations

import numpy as np

from stewart_drake.design.maps import slice_maps
from stewart_drake.design.modes import analytic_modes, spatial_inertia
from stewart_drake.design.stiffness import principal_stiffness, stiffness_matrix
from stewart_drake.geometry import load_platform
from stewart_drake.kinematics import condition_number


def test_slice_maps_match_single_pose_computations():
    p = load_platform("utn-dynamic")
    o = np.radians([8.0, -5.0, 20.0])
    m = slice_maps(p, half_width=0.5, n=21, orientation=o, k=1e5, modes=True)
    assert m.within.any() and not m.within.all()  # the slice reaches past the stroke
    assert np.all(np.isnan(m.condition[~m.within]))
    for i, j in [(10, 10), (3, 14), (16, 5)]:
        if not m.within[i, j]:
            continue
        q = np.r_[m.x[i], m.y[j], m.z, o]
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
    m = slice_maps(p, half_width=0.05, n=5, orientation=np.radians([0.0, 0.0, 100.0]))
    m0 = slice_maps(p, half_width=0.05, n=5)
    assert m0.same_mode.all()
    assert not m.same_mode[m.within].all() or np.nanmax(m.condition) > 1e3
    assert not m.safe.any()
