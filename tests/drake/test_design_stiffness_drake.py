"""Vibration modes (``design/modes``, ``design/stiffness``) against the linearised Drake plant
(``drake/design_checks``): plate only, single modes, damped, and the closed loop with leg bodies."""

from __future__ import annotations

import numpy as np
import pytest

from stewart_drake.core.geometry import load_platform
from stewart_drake.design.modes import analytic_modes, damping_matrix, mac, spatial_inertia, subspace_mac
from stewart_drake.design.payload import with_payload
from stewart_drake.design.stiffness import stiffness_matrix
from stewart_drake.drake.design_checks import drake_modes

Q_OFF = np.array([0.05, -0.03, 0.72, 0.1, -0.05, 0.2])  # an asymmetric pose: no repeated frequencies
K_LEGS = np.array([1.0e5, 1.2e5, 0.9e5, 1.0e5, 1.1e5, 1.05e5])


@pytest.fixture(scope="module")
def loaded():
    return with_payload(load_platform("utn-dynamic"), 8.0, [0.03, -0.02, 0.06])


@pytest.mark.parametrize("pose", [Q_OFF, np.array([0.0, 0.0, 0.7, 0.0, 0.0, 0.0])])
def test_drake_linearisation_matches_analytic_plate_only(loaded, pose):
    K = stiffness_matrix(loaded, pose, K_LEGS)
    M = spatial_inertia(loaded, pose)
    a = analytic_modes(K, M)
    d = drake_modes(loaded, pose, K_LEGS)
    assert d["residual"] <= 1e-9  # the spring preloads hold the plate in equilibrium
    assert np.all(np.abs(d["modes"].frequencies_hz / a.frequencies_hz - 1) <= 1e-6)
    assert np.all(subspace_mac(a.shapes, d["modes"].shapes, a.frequencies_hz) >= 0.999)


def test_drake_single_modes_mac(loaded):
    a = analytic_modes(stiffness_matrix(loaded, Q_OFF, K_LEGS), spatial_inertia(loaded, Q_OFF))
    assert np.min(np.diff(a.frequencies_hz) / a.frequencies_hz[1:]) > 1e-3  # distinct: plain MAC applies
    d = drake_modes(loaded, Q_OFF, K_LEGS)
    assert np.all(mac(a.shapes, d["modes"].shapes) >= 0.999)
    # a mode against another mode is not a match: the check can fail
    assert mac(a.shapes[:, :1], d["modes"].shapes[:, 1:2])[0] < 0.5


def test_drake_damped(loaded):
    c = 300.0
    a = analytic_modes(
        stiffness_matrix(loaded, Q_OFF, K_LEGS), spatial_inertia(loaded, Q_OFF), damping_matrix(loaded, Q_OFF, c)
    )
    d = drake_modes(loaded, Q_OFF, K_LEGS, c)
    assert np.all(np.abs(d["modes"].frequencies_hz / a.frequencies_hz - 1) <= 1e-6)
    assert np.all(np.abs(d["modes"].damping_ratio - a.damping_ratio) <= 1e-6)
    assert a.damping_ratio.max() > 0.05


def test_drake_closed_loop_with_legs(loaded):
    """Plate + leg bodies: the analytic model (leg inertia from the numpy inverse dynamics) against the
    closed-loop Drake plant reduced to the plate's motion (its central differences: ~1e-9)."""
    K = stiffness_matrix(loaded, Q_OFF, K_LEGS, legs=True)
    M = spatial_inertia(loaded, Q_OFF, legs=True)
    a = analytic_modes(K, M)
    d = drake_modes(loaded, Q_OFF, K_LEGS, legs=True)
    assert np.all(np.abs(d["modes"].frequencies_hz / a.frequencies_hz - 1) <= 1e-6)
    assert np.all(mac(a.shapes, d["modes"].shapes) >= 0.999)
    plate = analytic_modes(stiffness_matrix(loaded, Q_OFF, K_LEGS), spatial_inertia(loaded, Q_OFF))
    assert np.all(a.frequencies_hz < plate.frequencies_hz)  # the legs' inertia lowers every mode
