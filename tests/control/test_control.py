"""The DSP controller without Drake: timing and cycle model, gain design and Q15 encoding, and single
ticks of the float and fixed-point laws against independent computations (plain Python integers). The
controller as a Drake system is tested in ``test_controller_system.py``."""

import numpy as np
import pytest

from stewart_drake.control import (
    ControllerConfig,
    DspTiming,
    FixedGains,
    FixedPointLaw,
    FloatLaw,
    PidGains,
    TimingError,
    q15_gain,
    tick_cycles,
)
from stewart_drake.core.geometry import load_preset
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.core.trajectory import ROTATING, SEED
from stewart_drake.fixedpoint import fixed_point_leg_lengths, tp17_cycles

PLATFORM = load_preset("utn-dynamic")
T = 1e-3


# ----------------------------------------------------------------------------------------------
# Configuration


def test_cycle_model_is_ik_plus_pid_plus_isr():
    n = tick_cycles()
    ik = tp17_cycles().cycles
    assert ik < n < ik + 1000  # the PID and ISR add a few hundred cycles to the ~3.3 k of the IK
    timing = DspTiming()
    assert timing.computation_time == pytest.approx(n / 60e6)
    assert timing.output_delay == T  # the conservative default: one full sample
    assert DspTiming(latency="computation").output_delay == pytest.approx(n / 60e6)


def test_infeasible_timing_is_refused_with_both_numbers():
    n = tick_cycles()
    with pytest.raises(
        TimingError, match=rf"{n} cycles = {n / 60:.3f} µs at 60 MHz, longer than the sample period 50\.000 µs"
    ):
        DspTiming(sample_period=50e-6).check()
    with pytest.raises(TimingError, match=r"5000 cycles = 500\.000 µs at 10 MHz.*400\.000 µs"):
        FixedPointLaw(
            PLATFORM, ControllerConfig(timing=DspTiming(clock_hz=10e6, sample_period=400e-6, computation_cycles=5000))
        )
    DspTiming(sample_period=n / 60e6).check()  # exactly fits: accepted


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (
            dict(sample_period=0.0),
            r"sample period \(controller.period, vary sample_period; s\) must be a positive number, got 0.0",
        ),
        (dict(latency="late"), "latency must be one of sample, computation, none, got 'late'"),
        (dict(computation_cycles=-3), "computation_cycles must be a positive integer, got -3"),
        (
            dict(sensor_resolution=float("nan")),
            r"sensor resolution \(sensors.resolution, vary sensor_resolution; m per count\) must be a positive number",
        ),
    ],
)
def test_bad_timing_values_are_named(kwargs, match):
    with pytest.raises(ValueError, match=match):
        DspTiming(**kwargs)


def test_bad_gains_and_sensor_resolution_are_named():
    with pytest.raises(ValueError, match="the controller.s kd gain must be a finite number >= 0, got -1"):
        PidGains(kd=-1)
    with pytest.raises(ValueError, match=r"the controller.s feedforward filter must be in \(0, 1\], got 0"):
        PidGains(feedforward_filter=0)
    with pytest.raises(ValueError, match="sensor_resolution 0.0003 m must divide the IK's length LSB 0.001 m"):
        FixedPointLaw(PLATFORM, ControllerConfig(timing=DspTiming(sensor_resolution=3e-4)))


def test_q15_gains_are_within_half_an_lsb():
    for x in (0.0, 1e-4, 0.3, 0.99999, 1.0, 7.2, 1234.5):
        g = q15_gain(x)
        assert 0 <= g.mantissa <= 32767 and g.shift >= 0
        # rounding to the nearest mantissa: error at most half an LSB of the scaled word
        assert abs(g.value - x) <= 0.5 / 32768 * 2.0**g.shift
    fg = FixedGains.from_si(PidGains(), DspTiming())
    # the default gains need shifts (kp·2^15 counts·10 µm/200 N = 4.9): a left shift keeps the precision
    assert fg.kp.shift == 3 and fg.kp.value == pytest.approx(3000 * 32768 * 1e-5 / 200, rel=1e-4)


# ----------------------------------------------------------------------------------------------
# Timing in a Diagram


def test_primed_ik_cache_gives_the_same_words():
    config = ControllerConfig()
    ctrl = FixedPointLaw(PLATFORM, config)
    poses = ROTATING.pose(np.arange(200) * 0.01)
    ctrl.prime(poses)
    for q in poses[::17]:
        np.testing.assert_array_equal(ctrl.setpoint_words(q), ctrl.ik_words(q))
    assert ctrl.cache_misses == 0
    q = poses[3] + 1e-9  # not primed: computed, same function
    np.testing.assert_array_equal(
        ctrl.setpoint_words(q), fixed_point_leg_lengths(PLATFORM, q, config.ik_format, return_words=True)
    )
    assert ctrl.cache_misses == 1


def test_fixed_pid_tick_matches_a_plain_integer_reimplementation():
    """One tick of the fixed-point law recomputed with Python integers (independent of the numpy
    intrinsics): ETSI semantics sat16/sat32, L_mult = sat32(2ab), mult_r = (ab + 2^14) >> 15, shifts
    saturating. Random state and inputs (fixed seed), including saturating ones."""
    rng = np.random.default_rng(6)
    ctrl = FixedPointLaw(PLATFORM)
    g, cpl = ctrl.gains, 100  # 1 mm IK LSB / 10 µm sensor counts

    def s16(x):
        return max(-32768, min(32767, x))

    def s32(x):
        return max(-(2**31), min(2**31 - 1, x))

    def lshl(x, n):
        return s32(x << n)

    rails = 0
    for trial in range(200):
        pose = SEED.pose(rng.uniform(0, 4))
        scale = 1e-3 if trial % 2 else 0.3  # small errors, or saturating ones
        L = leg_lengths(PLATFORM, pose) + rng.normal(0, scale, 6)
        pid = np.concatenate(
            [
                rng.integers(-(2**31), 2**31 - 1, 6),
                np.round(L / 1e-5) + rng.integers(-300, 300, 6),
                rng.integers(-5000, 5000, 6),
                ctrl.setpoint_words(pose) + rng.integers(-3, 3, 6),
                rng.integers(-5000, 5000, 6),
            ]
        ).astype(float)
        cmd, sp, new, sat = ctrl.step(pid, pose, L)
        words = ctrl.setpoint_words(pose)
        for i in range(6):
            integ, prev, df, sprev, vf = (int(pid[6 * j + i]) for j in range(5))
            m = int(round(L[i] / 1e-5))
            e = s16(int(words[i]) * cpl - m)
            dm = s16(s16(m - prev) << 6)
            df = s16(df + ((g.alpha * s16(dm - df) + 2**14) >> 15))
            ds = s16(s16((int(words[i]) - sprev) * cpl) << 6)
            vf = s16(vf + ((g.alpha_ff * s16(ds - vf) + 2**14) >> 15))
            P = lshl(s32(2 * g.kp.mantissa * e), g.kp.shift)
            D = lshl(s32(2 * g.kd.mantissa * df), g.kd.shift)
            V = lshl(s32(2 * g.kv.mantissa * vf), g.kv.shift)
            u = s32(s32(s32(P + integ) - D) + V)
            rail = u in (2**31 - 1, -(2**31))
            rails += rail
            if not ((u == 2**31 - 1 and e > 0) or (u == -(2**31) and e < 0)):
                integ = s32(integ + lshl(s32(2 * g.ki.mantissa * e), g.ki.shift))
            assert cmd[i] == (u >> 16) / 32768 * 200.0
            assert sat[i] == rail
            assert [int(new[6 * j + i]) for j in range(5)] == [integ, m, df, int(words[i]), vf]
    assert 100 < rails < 1100  # both saturated and unsaturated ticks were exercised


# ----------------------------------------------------------------------------------------------
# Gains designed from the platform; the force feed-forward word


def test_leg_space_inertia_without_legs_is_the_plate_mass_matrix_in_leg_coordinates():
    """Independent check of ``leg_space_inertia``: with massless legs it must equal J⁻ᵀ M(q) J⁻¹ with
    M(q) from ``dynamics.mass_matrix`` (Lagrangian A(q)ᵀ diag(m, I) A(q), another code path than the
    Newton–Euler of ``leg_forces_with_legs``)."""
    from dataclasses import replace

    from stewart_drake.control import leg_space_inertia
    from stewart_drake.core.dynamics import mass_matrix
    from stewart_drake.core.kinematics import length_jacobian

    p = load_preset("utn-kinematic")
    bare = p.replace(legs=replace(p.legs, cylinder_mass=0.0, piston_mass=0.0))
    q = p.home_pose() + np.array([0.02, -0.01, 0.03, 0.05, -0.04, 0.1])
    Ji = np.linalg.inv(length_jacobian(bare, q))
    np.testing.assert_allclose(leg_space_inertia(bare, q), Ji.T @ mass_matrix(bare, q) @ Ji, rtol=1e-9, atol=1e-9)
    # the legs only add mass: every eigenvalue grows
    assert np.all(np.linalg.eigvalsh(leg_space_inertia(p, q)) > np.linalg.eigvalsh(leg_space_inertia(bare, q)))


@pytest.mark.parametrize("name", ["utn-dynamic", "utn-kinematic", "gonzalez-dutra-2009"])
def test_design_gains_follow_the_documented_rules(name):
    from stewart_drake.control import (
        HEAVY_MODE_DAMPING,
        PHASE_BUDGET,
        ROUTH_FRACTION,
        STIFFNESS_MARGIN,
        UNKNOWN_POSE_STIFFNESS_FACTOR,
        design_gains,
        leg_space_inertia,
        loop_delay,
        strut_stiffness,
    )

    p = load_preset(name)
    cfg = ControllerConfig.for_platform(p)
    assert cfg.timing.command_range == p.legs.max_force
    g = cfg.gains
    assert g == design_gains(p, cfg.timing)
    m = np.linalg.eigvalsh(leg_space_inertia(p))
    w_c = PHASE_BUDGET / loop_delay(cfg.timing)
    assert loop_delay(cfg.timing) == pytest.approx(1e-3 + 1e-3 + 2e-3)  # output delay + ZOH/difference + lag
    assert g.kd == pytest.approx(m[0] * w_c) and g.kv == g.kd
    K = UNKNOWN_POSE_STIFFNESS_FACTOR * strut_stiffness(p)  # home only: the visited poses are unknown
    kp = max(min(g.kd**2 / (4 * HEAVY_MODE_DAMPING**2 * m[-1]), g.kd * w_c / 3), STIFFNESS_MARGIN * K)
    assert g.kp == pytest.approx(kp)
    assert g.ki == pytest.approx(min(g.kp * np.sqrt(g.kp / m[-1]) / 4, ROUTH_FRACTION * g.kd * (g.kp - K) / m[-1]))
    # every gain fits the firmware's Q15 mantissa + shift
    fg = FixedGains.from_si(g, cfg.timing)
    for q in (fg.kp, fg.ki, fg.kd, fg.kv):
        assert 0 < q.mantissa <= 32767 and q.value > 0


@pytest.mark.parametrize("name", ["utn-dynamic", "utn-kinematic", "gonzalez-dutra-2009"])
@pytest.mark.parametrize("base", ["seed", "rotating"])
def test_designed_gains_keep_the_heaviest_mode_routh_stable_along_the_trajectory(name, base):
    """The PID on the heaviest leg-space mode m with the struts' negative stiffness K is
    m s³ + kd s² + (kp − K) s + ki: stable iff kp > K and ki < kd·(kp − K)/m (Routh). Checked at 300 poses
    over a full period (2π s) of each trajectory, more and other poses than the design's 64 over 4 s, with
    the pose's own K and heaviest mass. (The home-only design of 6b broke it on utn-kinematic: kp 15.3 kN/m
    against K up to 14.6 kN/m and ki 66 kN/(m·s), ~25 × the limit; the loop grew at ~2 Hz.)"""
    from stewart_drake.control import design_gains, leg_space_inertia, strut_stiffness
    from stewart_drake.core.trajectory import design_poses, fit_trajectory, get_trajectory

    p = load_preset(name)
    traj = fit_trajectory(get_trajectory(base), p)
    g = design_gains(p, poses=design_poses(traj))
    q = traj.pose(np.linspace(0, 2 * np.pi, 300))
    K = strut_stiffness(p, q)
    m_max = np.linalg.eigvalsh(leg_space_inertia(p, q))[:, -1]
    assert np.all(g.kp > 1.5 * K), (g.kp, K.max())
    limit = g.kd * (g.kp - K) / m_max
    assert np.all(g.ki < 0.8 * limit), (g.ki, limit.min())


def test_strut_stiffness_and_inertia_are_vectorised_over_poses():
    from stewart_drake.control import leg_space_inertia, strut_stiffness

    p = load_preset("utn-kinematic")
    q = p.home_pose() + np.array([[0, 0, 0, 0, 0, 0], [0.02, -0.01, 0.01, 0.05, 0.0, 0.2]])
    assert strut_stiffness(p, q) == pytest.approx([strut_stiffness(p, qi) for qi in q], rel=1e-12)
    np.testing.assert_allclose(leg_space_inertia(p, q), [leg_space_inertia(p, qi) for qi in q], rtol=1e-12)


def test_strut_stiffness_and_inertia_batched_equal_one_call_per_direction(tmp_path):
    """``strut_stiffness`` and ``leg_space_inertia`` run their twelve (six) inverse-dynamics poses as one batch:
    bit for bit the numbers of one ``leg_forces_with_legs`` call per direction (their former code, here as the
    reference), which the gains, and so the fixed-point firmware's words, depend on."""
    from stewart_drake.control import leg_space_inertia, strut_stiffness
    from stewart_drake.core.dynamics import leg_forces_with_legs
    from stewart_drake.core.kinematics import length_jacobian
    from tests._own_platform import own_radial

    def reference(p, q0, h=1e-6):
        z, Jinv = np.zeros_like(q0), np.linalg.inv(length_jacobian(p, q0))
        pairs = [
            (leg_forces_with_legs(p, q0 + h * e, z, z), leg_forces_with_legs(p, q0 - h * e, z, z)) for e in np.eye(6)
        ]
        K = np.stack([(a - b) / (2 * h) for a, b in pairs], -1) @ Jinv
        k = np.maximum(0.0, np.linalg.eigvalsh(-(K + np.swapaxes(K, -1, -2)) / 2)[..., -1])
        M_L = np.stack([leg_forces_with_legs(p, q0, z, z + e, gravity=0.0) for e in np.eye(6)], -1) @ Jinv
        return k, (M_L + np.swapaxes(M_L, -1, -2)) / 2

    rng = np.random.default_rng(11)
    for p in (load_preset("utn-dynamic"), load_preset("gonzalez-dutra-2009"), own_radial(tmp_path)):
        home = p.home_pose()
        poses = home + rng.uniform(-1, 1, (40, 6)) * [0.02, 0.02, 0.02, 0.05, 0.05, 0.05]
        for q in (home, poses, poses.reshape(2, 20, 6)):
            k, M_L = reference(p, q)
            assert np.array_equal(strut_stiffness(p, q), k)
            assert np.array_equal(leg_space_inertia(p, q), M_L)


def test_strut_stiffness_matches_the_open_loop_growth():
    """The negative stiffness K of the struts and the open-loop growth rate λ (``dynamics``) describe the
    same instability: the fastest growth needs λ² ≤ K / m_min (a stiffness K on the lightest mass), and
    the slowest unstable mode at least K / m_max — so λ_max² · m_min <= K <= λ_max² · m_max."""
    from stewart_drake.control import leg_space_inertia, strut_stiffness
    from stewart_drake.core.dynamics import open_loop_growth_rates

    for name in ("utn-dynamic", "utn-kinematic"):
        p = load_preset(name)
        K = strut_stiffness(p)
        lam = open_loop_growth_rates(p, p.home_pose())[0]
        m = np.linalg.eigvalsh(leg_space_inertia(p))
        assert lam**2 * m[0] <= K <= lam**2 * m[-1], (name, K, lam, m)


def test_fixed_feedforward_is_one_saturating_word_added_to_the_sum():
    """The feed-forward enters the fixed-point law as its Q15 table word deposited in the high half and
    added with a saturating L_add; everything else in the tick is unchanged (Python integers)."""
    rng = np.random.default_rng(7)
    ctrl = FixedPointLaw(PLATFORM)
    for _trial in range(60):
        pose = SEED.pose(rng.uniform(0, 4))
        L = leg_lengths(PLATFORM, pose) + rng.normal(0, 1e-3, 6)
        pid = ctrl.initial_pid_state(L, rng.uniform(-50, 50, 6))
        ff = rng.uniform(-300, 300, 6)  # beyond the 200 N range for some legs: the word saturates
        cmd0, sp0, st0, _ = ctrl.step(pid, pose, L)
        cmd, sp, st, sat = ctrl.step(pid, pose, L, ff)
        np.testing.assert_array_equal(sp, sp0)
        np.testing.assert_array_equal(st[6:], st0[6:])  # filters and memories do not see the feed-forward
        for i in range(6):
            w = max(-32768, min(32767, round(ff[i] / 200.0 * 32768)))
            u0 = int(round(cmd0[i] / 200.0 * 32768))  # the high word of the feed-forward-free sum
            # adding w·2^16 changes only the high word: floor(u / 2^16) + w, then the rails
            assert int(round(cmd[i] / 200.0 * 32768)) == max(-32768, min(32767, u0 + w))
        assert np.all(np.abs(cmd) <= 200.0)


def test_controller_without_a_feedforward_connection_is_unchanged():
    """Left unconnected, the feed-forward port is zero: the tick equals ``step`` without it."""
    ctrl = FloatLaw(PLATFORM)
    pose = SEED.pose(0.3)
    L = leg_lengths(PLATFORM, pose)
    pid = ctrl.initial_pid_state(L, np.full(6, 3.0))
    a = ctrl.step(pid, pose, L)
    b = ctrl.step(pid, pose, L, np.zeros(6))
    for x, y in zip(a, b):
        np.testing.assert_array_equal(x, y)


def test_laws_need_no_drake():
    """With pydrake unimportable, the control package imports and both laws tick (in a fresh interpreter,
    whatever this one has imported); the fixed-point tick equals this process's bit for bit."""
    import subprocess
    import sys
    from pathlib import Path

    import stewart_drake

    code = """
import sys
class Block:
    def find_spec(self, name, path=None, target=None):
        if name == "pydrake" or name.startswith("pydrake."):
            raise ImportError("pydrake blocked")
sys.meta_path.insert(0, Block())
import numpy as np
from stewart_drake.control import FixedPointLaw, FloatLaw
from stewart_drake.core.geometry import load_preset
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.core.trajectory import SEED
p = load_preset("utn-dynamic")
pose = SEED.pose(0.4)
L = leg_lengths(p, pose) + 2e-4
for law in (FixedPointLaw(p), FloatLaw(p)):
    cmd, sp, st, sat = law.step(law.initial_pid_state(L, np.full(6, 5.0)), pose, L, np.full(6, 3.0))
    print(repr(cmd.tolist()))
assert not any(m.startswith("pydrake") for m in sys.modules)
"""
    root = Path(stewart_drake.__file__).resolve().parents[1]  # the package importable from the checkout
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True, cwd=root
    ).stdout.splitlines()
    law = FixedPointLaw(PLATFORM)
    pose = SEED.pose(0.4)
    L = leg_lengths(PLATFORM, pose) + 2e-4
    cmd = law.step(law.initial_pid_state(L, np.full(6, 5.0)), pose, L, np.full(6, 3.0))[0]
    assert out[0] == repr(cmd.tolist())
    assert len(out) == 2


def test_design_gains_remembered_by_content_gives_the_computed_numbers():
    """``design_gains`` remembers its costly extremes by content (a study's runs share the nominal design):
    a repeat gives the gains computed afresh bit for bit, and a platform differing in one mass is a
    different design (no collision)."""
    from stewart_drake.control import gains as G
    from stewart_drake.core.trajectory import design_poses, get_trajectory

    p = load_preset("utn-dynamic")
    poses = design_poses(get_trajectory("seed"))
    G._EXTREMES.clear()
    fresh = G.design_gains(p, poses=poses)
    assert len(G._EXTREMES) == 1
    assert G.design_gains(p, poses=poses) == fresh and len(G._EXTREMES) == 1
    heavier = p.replace(mass=p.mass * 1.5)
    g2 = G.design_gains(heavier, poses=poses)
    assert len(G._EXTREMES) == 2 and g2 != fresh
    G._EXTREMES.clear()
    assert G.design_gains(heavier, poses=poses) == g2  # as computed with nothing remembered
