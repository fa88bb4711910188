"""The motion language: the seed's example, arithmetic, control flow, trajectory and forces."""

import math

import numpy as np
import pytest

from stewart_drake.core.geometry import load_preset
from stewart_drake.core.kinematics import leg_lengths, leg_unit_vectors
from stewart_drake.core.rotations import pose_to_si
from stewart_drake.script import Motion, check, execute, parse, run_program
from stewart_drake.script.runtime import for_range, quintic

SEED_PROGRAM = "x=100\ny=120\nz=300\nalpha=25\nbeta=10\ngama=0\nmover(x,y,z,alpha,beta,gama)\n"
HOME = np.array([0.0, 0.0, 0.1, 0.0, 0.0, 0.0])


@pytest.fixture(scope="module")
def utn():
    return load_preset("utn-kinematic")


def run_env(src):
    """Parse, check and execute ``src``; return (variables, motion)."""
    program = parse(src, "t.stw")
    check(program)
    motion = Motion(HOME)
    return execute(program, motion), motion


def value(expr):
    return run_env(f"v = {expr}")[0]["v"]


# ---- the seed's example ------------------------------------------------------------------------


def test_seed_example_lengths(utn):
    """The seed's program moves to (100, 120, 300 mm; 25, 10, 0 deg): the final lengths are the closed-form
    IK of that pose (an independent call), and the start is the home pose (every leg 473.19 mm, the
    seed table's 473)."""
    r = run_program(SEED_PROGRAM, "seed.stw", utn)
    expected = leg_lengths(utn, pose_to_si([100, 120, 300, 25, 10, 0], "mm", "deg"))
    np.testing.assert_allclose(r.L[-1], expected, rtol=0, atol=1e-12)
    np.testing.assert_allclose(r.L[-1] * 1e3, [583.334, 669.133, 508.944, 693.559, 624.865, 364.708], atol=1e-3)
    assert np.all(np.floor(r.L[0] * 1e3) == 473)
    # The pose is within the preset's assumed 300..700 mm stroke, leg 4 only 6.44 mm from its end.
    assert utn.L_max - r.L.max() == pytest.approx(6.44e-3, abs=1e-5)
    assert r.L.min() > utn.L_min


def test_seed_example_second_mover_uses_its_own_arguments(utn):
    """The seed's compiler read mover arguments from a global counter (a second mover repeated the first
    one's values); here each mover gets its own."""
    _, m = run_env(SEED_PROGRAM + "z = 250\nmover(x, y, z, alpha, beta, gama)\nmover(0, 0, 200, 0, 0, 0)")
    assert [s.values for s in m.segments] == [
        (100, 120, 300, 25, 10, 0),
        (100, 120, 250, 25, 10, 0),
        (0, 0, 200, 0, 0, 0),
    ]


# ---- expressions ---------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "expr, expected",
    [
        ("2+3*4", 14),  # the seed gave 20 (one precedence level)
        ("(2+3)*4", 20),
        ("2-3-4", -5),  # left associative
        ("8/2/2", 2),
        ("-2*3", -6),
        ("2*-3", -6),
        ("1+-1", 0),
        ("- -2", 2),
        ("7 DIV 2", 3),
        ("-7 DIV 2", -4),  # floor division
        ("-7 MOD 3", 2),  # remainder with the divisor's sign
        ("7 mod 3 * 2", 2),  # MOD at the level of *, left to right
        ("1.5e2 + .5", 150.5),
        ("10 / 4", 2.5),  # real numbers, not the seed's integers
        ("sqrt(16) + abs(-1) + max(2, 3) + min(2, 3)", 10),
        ("atan2(1, 1) * 4", math.pi),
        ("2 * pi", 2 * math.pi),
    ],
)
def test_arithmetic(expr, expected):
    assert value(expr) == pytest.approx(expected, rel=1e-15, abs=0)


def test_comments_separators_and_assignment_forms():
    env, _ = run_env("a = 1 // line comment\n(* block\n comment *) b := 2; c = a + b;; d = c")
    assert env == {"a": 1, "b": 2, "c": 3, "d": 3}


# ---- control flow ----------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "loop, visited",
    [
        ("FOR i := 1 TO 5 DO", [1, 2, 3, 4, 5]),
        ("FOR i := 1 TO 6 BY 2 DO", [1, 3, 5]),
        ("FOR i := 3 TO 1 BY -1 DO", [3, 2, 1]),
        ("FOR i := 3 TO 1 DO", []),
        ("for i = 0 to 1 by 0.25 do", [0, 0.25, 0.5, 0.75, 1.0]),
    ],
)
def test_for_loops(loop, visited):
    env, m = run_env(f"{loop} wait i + 1 END")
    assert [s.duration - 1 for s in m.segments] == pytest.approx(visited)


def test_for_bounds_are_evaluated_once_and_step_accumulates_without_drift():
    env, m = run_env("n = 3\nFOR i := 1 TO n DO n = n + 1; i = 100; wait 1 END")
    assert len(m.segments) == 3 and env["n"] == 6
    assert len(list(for_range(0, 1, 0.1))) == 11  # 0.1 steps reach 1 despite rounding


def test_nested_loops_and_conditionals():
    src = """
    s = 0
    FOR i := 1 TO 4 DO
        FOR j := 1 TO i DO
            IF (i + j) MOD 2 = 0 AND NOT j = 1 THEN s = s + 100
            ELSIF i = j OR j > 3 THEN s = s + 10
            ELSE s = s + 1
            END
        END
    END
    """
    expected = 0
    for i in range(1, 5):
        for j in range(1, i + 1):
            if (i + j) % 2 == 0 and not j == 1:
                expected += 100
            elif i == j or j > 3:
                expected += 10
            else:
                expected += 1
    assert run_env(src)[0]["s"] == expected


@pytest.mark.parametrize(
    "cond, taken",
    [
        ("1 < 2", True),
        ("2 <= 2", True),
        ("1 > 2", False),
        ("2 >= 3", False),
        ("1 = 1", True),
        ("1 == 1", True),
        ("1 <> 1", False),
        ("1 # 2", True),
        ("1 != 2", True),
        ("NOT (1 < 2 OR 2 < 1)", False),
    ],
)
def test_comparisons(cond, taken):
    assert run_env(f"v = 0; IF {cond} THEN v = 1 ELSE v = 2 END")[0]["v"] == (1 if taken else 2)


def test_while_loop():
    env, m = run_env("n = 0\nWHILE n < 5 DO n = n + 2; wait 0.5 END")
    assert env["n"] == 6 and len(m.segments) == 3


# ---- moves, units, trajectory ---------------------------------------------------------------------


def test_keyword_arguments_keep_unnamed_coordinates_and_units_convert():
    _, m = run_env("mover(z = 150) en 2\nunits m, rad\nmove(0.01, 0, 0.2, 0.1, 0, 0)\nmove(gamma = 0.5) in 3")
    np.testing.assert_allclose(m.segments[0].q1, [0, 0, 0.15, 0, 0, 0])
    assert m.segments[0].duration == 2 and m.segments[1].duration == 1.0  # default 1 s
    np.testing.assert_allclose(m.segments[1].q1, [0.01, 0, 0.2, 0.1, 0, 0])
    np.testing.assert_allclose(m.segments[2].q1, [0.01, 0, 0.2, 0.1, 0, 0.5])
    assert m.segments[2].units == ("m", "rad")


def test_degrees_default():
    _, m = run_env("mover(0, 0, 100, 90, 0, 0)")
    assert m.segments[0].q1[3] == pytest.approx(math.pi / 2, abs=1e-15)


def test_quintic_derivatives_against_finite_differences():
    """s', s'' of the blend match central differences (truncation errors h²/6·max|s⁽³⁾| = 1e-7 and
    h²/6·max|s⁽⁴⁾| = 6e-7 with h = 1e-4), and vanish at both ends (rest to rest)."""
    tau = np.linspace(0.05, 0.95, 19)
    h = 1e-4
    s, ds, dds = quintic(tau)
    np.testing.assert_allclose(ds, (quintic(tau + h)[0] - quintic(tau - h)[0]) / (2 * h), atol=2e-7)
    np.testing.assert_allclose(dds, (quintic(tau + h)[1] - quintic(tau - h)[1]) / (2 * h), atol=1e-6)
    np.testing.assert_array_equal(quintic(np.array([0.0, 1.0]))[0], [0, 1])
    assert np.all(np.array(quintic(np.array([0.0, 1.0]))[1:]) == 0)


def test_trajectory_velocity_and_acceleration_are_consistent(utn):
    """Sampled q̇, q̈ match central differences of the sampled q, q̇ at 1 kHz away from waypoints (error
    h²/6·max|q⁽⁴⁾| < 1e-3 of the peak). Across waypoints q̈ is continuous but the jerk jumps, so there
    consecutive samples of q̈ differ by at most h·max|jerk| (max|s⁽³⁾| = 60)."""
    _, m = run_env(
        "mover(20, 0, 150, 5, 0, 0) en 0.5\nmover(x = -20, gama = 10) in 0.7\nwait 0.2\nmover(0, 0, 100, 0, 0, 0)"
    )
    tr = m.trajectory(rate=1000.0)
    dt = np.diff(tr.t)
    np.testing.assert_allclose(dt, 1e-3, atol=1e-12)
    inner = (tr.segment[1:-1] == tr.segment[2:]) & (tr.segment[1:-1] == tr.segment[:-2])
    fd_v = (tr.q[2:] - tr.q[:-2]) / 2e-3
    fd_a = (tr.qd[2:] - tr.qd[:-2]) / 2e-3
    assert np.abs(fd_v - tr.qd[1:-1])[inner].max() < 1e-3 * np.abs(tr.qd).max()
    assert np.abs(fd_a - tr.qdd[1:-1])[inner].max() < 1e-3 * np.abs(tr.qdd).max()
    jerk = max(60 * np.abs(s.q1 - s.q0).max() / s.duration**3 for s in tr.segments)
    assert np.abs(np.diff(tr.qdd, axis=0)).max() <= 1e-3 * jerk * (1 + 1e-9)
    assert np.all(tr.qd[[0, -1]] == 0) and np.all(tr.qdd[[0, -1]] == 0)
    np.testing.assert_allclose(tr.pose_at(tr.t), tr.q, atol=1e-15)


def test_forces_balance_gravity_at_rest(utn):
    """At rest (start and end of a move) the leg forces along the legs add up to the plate's weight,
    Σ F_i u_i = m g e_z (an independent statics check of the inverse dynamics)."""
    pytest.importorskip("stewart_drake.core.dynamics")
    r = run_program(SEED_PROGRAM, "seed.stw", utn)
    for n in (0, -1):
        u = leg_unit_vectors(utn, r.trajectory.q[n])
        total = (r.F[n][:, None] * u).sum(axis=0)
        np.testing.assert_allclose(total, [0, 0, utn.mass * 9.81], atol=1e-9 * utn.mass * 9.81)
    assert r.notes == ()


def test_coriolis_switch_changes_only_moving_samples(utn):
    pytest.importorskip("stewart_drake.core.dynamics")
    on = run_program(SEED_PROGRAM, "s.stw", utn)
    off = run_program(SEED_PROGRAM, "s.stw", utn, coriolis=False)
    np.testing.assert_allclose(on.F[[0, -1]], off.F[[0, -1]], atol=1e-9)
    assert np.abs(on.F - off.F).max() > 1e-6
