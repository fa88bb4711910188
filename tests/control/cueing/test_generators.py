"""The generated drives checked by what they must satisfy: the sea-state spectrum recovered from the series,
the single-track model's steady turn against its closed form, a stop that loses exactly its speed, a coordinated
turn whose ball stays centred at constant airspeed."""

import math

import numpy as np
import pytest
from scipy import signal
from scipy.integrate import cumulative_trapezoid

from stewart_drake.control.cueing.drive import GRAVITY
from stewart_drake.control.cueing.generators import (
    CAR,
    DRIVES,
    SEA_STATES,
    SHIP,
    aircraft_drive,
    car_drive,
    jonswap,
    ship_drive,
    shipped_drive,
    single_track,
    wave_elevation,
)
from stewart_drake.core.rotations import rotation_matrix
from stewart_drake.errors import DriveError


def test_jonswap_has_its_significant_height_and_peak():
    for hs, tp in SEA_STATES.values():
        w = np.geomspace(0.05, 30, 200_001)  # another grid than the normalisation's
        s = jonswap(w, hs, tp)
        assert 4 * math.sqrt(np.trapezoid(s, w)) == pytest.approx(hs, rel=1e-3)
        assert w[np.argmax(s)] == pytest.approx(2 * math.pi / tp, rel=1e-3)


def _band_energies(x, rate, edges, nperseg):
    f, p = signal.welch(x, fs=rate, nperseg=nperseg)
    w = 2 * math.pi * f
    return np.array([np.sum(p[(w >= a) & (w < b)]) * (f[1] - f[0]) for a, b in zip(edges[:-1], edges[1:])])


@pytest.mark.parametrize("sea_state", [3, 4, 5, 6])
def test_welch_recovers_the_sea_spectrum_and_the_roll_response(sea_state):
    # two hours at 4 Hz, Welch on 4096-sample segments (Hann, half overlap: ~7 independent averages); the
    # narrowest band holds 16 lines, so a band's energy has a relative standard error of at most 1/√(7·16) ≈ 9.5 %
    # (less: the synthesis draws only phases, its amplitudes are exact); 20 % is 2σ of that bound, twice the
    # largest error over 16 draws (4 seeds × 4 sea states: 10 %)
    rate, duration, nperseg = 4.0, 7200.0, 4096
    hs, tp = SEA_STATES[sea_state]
    wp = 2 * math.pi / tp
    edges = wp * np.array([0.7, 0.9, 1.1, 1.4, 2.0, 3.0])
    eta = wave_elevation(sea_state, duration, rate, seed=7)
    assert 4 * np.std(eta) == pytest.approx(hs, rel=1e-3)  # Parseval: the lines' Σ S Δω is the spectrum's m0
    w = np.linspace(edges[0], edges[-1], 20001)
    expected = [np.trapezoid(s, x) for s, x in _bands(jonswap(w, hs, tp), w, edges)]
    np.testing.assert_allclose(_band_energies(eta, rate, edges, nperseg), expected, rtol=0.2)
    roll = ship_drive(sea_state, duration, rate, seed=7).attitude[:, 0]
    s_roll = np.abs(SHIP.rao(w)[1]) ** 2 * jonswap(w, hs, tp)
    expected_roll = [np.trapezoid(s, x) for s, x in _bands(s_roll, w, edges)]
    np.testing.assert_allclose(_band_energies(roll, rate, edges, nperseg), expected_roll, rtol=0.2)


def _bands(s, w, edges):
    for a, b in zip(edges[:-1], edges[1:]):
        m = (w >= a) & (w <= b)
        yield s[m], w[m]


def test_single_track_steady_turn_matches_understeer_and_path_radius():
    u, delta = 20.0, 0.02
    t = np.arange(0, 20, 0.01)
    ay, r = single_track(CAR, u, np.full_like(t, delta), t)
    L = CAR.lf + CAR.lr
    assert r[-1] == pytest.approx(delta * u / (L + CAR.understeer * u**2), rel=1e-6)
    # the path's own radius (three points of the last 5 s of the integrated track): a_y = u²/R
    yaw = cumulative_trapezoid(r, t, initial=0)
    x = cumulative_trapezoid(u * np.cos(yaw), t, initial=0)
    y = cumulative_trapezoid(u * np.sin(yaw), t, initial=0)
    p = np.column_stack([x, y])[[-500, -250, -1]]
    a, b, c = (np.linalg.norm(p[i] - p[j]) for i, j in ((0, 1), (1, 2), (0, 2)))
    (ux, uy), (vx, vy) = p[1] - p[0], p[2] - p[0]
    area = abs(ux * vy - uy * vx) / 2
    radius = a * b * c / (4 * area)
    assert ay[-1] == pytest.approx(u**2 / radius, rel=1e-3)  # the lateral velocity's share of heading is steady


def test_lane_change_moves_one_lane_and_braking_loses_its_speed():
    d = car_drive("lane-change")
    R = rotation_matrix(d.attitude, "zyx")
    a = np.einsum("nij,nj->ni", R, d.specific_force) - [0, 0, GRAVITY]
    v = cumulative_trapezoid(a, d.t, axis=0, initial=0)
    lateral = cumulative_trapezoid(v[:, 1], d.t, initial=0)
    assert lateral[-1] == pytest.approx(3.5, rel=0.15)  # the steer is sized by the steady-state gain only
    assert abs(d.attitude[-1, 2]) < math.radians(3)
    b = car_drive("braking")
    dv = np.trapezoid(b.specific_force[:, 0], b.t)
    assert dv == pytest.approx(-25.0, rel=1e-3)
    np.testing.assert_allclose(b.specific_force[-1], [0, 0, GRAVITY], atol=1e-12)


@pytest.mark.parametrize("manoeuvre", ["turn-entry", "turn-reversal"])
def test_coordinated_turn_keeps_the_ball_centred_and_the_airspeed(manoeuvre):
    d = aircraft_drive(manoeuvre)
    phi = d.attitude[:, 0]
    np.testing.assert_allclose(d.specific_force[:, 1], 0, atol=1e-9)
    np.testing.assert_allclose(d.specific_force[:, 2], GRAVITY / np.cos(phi), rtol=1e-12)
    # integrate the world acceleration R f − g: level flight, speed 100 m/s all along (a turn changes only the
    # direction); the trapezoid's error over 15 s at 100 Hz is below 1e-3 m/s
    R = rotation_matrix(d.attitude, "zyx")
    a = np.einsum("nij,nj->ni", R, d.specific_force) - [0, 0, GRAVITY]
    v = cumulative_trapezoid(a, d.t, axis=0, initial=0) + [100.0, 0, 0]
    np.testing.assert_allclose(np.linalg.norm(v, axis=1), 100.0, atol=1e-3)
    np.testing.assert_allclose(v[:, 2], 0, atol=1e-9)


def test_every_shipped_drive_is_finite_and_starts_near_rest():
    for name, make in DRIVES.items():
        d = make()
        assert d.name == name
        assert np.all(np.isfinite(d.specific_force)) and np.all(np.isfinite(d.angular_velocity))
        if name.startswith(("car", "aircraft-turn-entry")):  # the reversal starts in a steady 30° turn
            np.testing.assert_allclose(d.specific_force[0], [0, 0, GRAVITY], atol=1e-6)


def test_bad_requests_are_named():
    with pytest.raises(DriveError, match="sea_state must be one of 3, 4, 5, 6, got 9"):
        ship_drive(9, 10.0)
    with pytest.raises(DriveError, match="unknown car manoeuvre 'drift'"):
        car_drive("drift")
    with pytest.raises(DriveError, match="duration must be a positive number of seconds"):
        car_drive("slalom", duration=-1.0)
    with pytest.raises(DriveError, match="unknown drive 'ship-ss9'; the shipped drives are ship-ss3, ship-ss4"):
        shipped_drive("ship-ss9")
