"""The DSP controller LeafSystems on their own (no plant): timing, causality, bit-exact set-points.

The controller is driven by time functions (a pose reference, a leg-length "measurement"), and its
held outputs are logged finely between ticks, so what is checked is what the plant would see. Drake
publishes (logs) at time t *before* the discrete updates scheduled at t: a sample at t shows what every
other system reads at t; a tick's or release's effect appears in the samples after it.
"""

import numpy as np
import pytest

from stewart_drake.control import (
    STATUS,
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
from stewart_drake.fixedpoint import QFormat, fixed_point_leg_lengths, tp17_cycles
from stewart_drake.core.geometry import load_preset
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.core.trajectory import ROTATING, SEED, Trajectory
from stewart_drake.drake.systems import PoseSource, make_controller

PLATFORM = load_preset("utn-dynamic")
T = 1e-3


def run_open_loop(kind, config, reference, measurement, duration, log_period):
    """Controller alone: reference and measurement from time functions; returns the logs (times, command,
    setpoint, status, reference) sampled every ``log_period`` and the controller."""
    from pydrake.systems.analysis import Simulator
    from pydrake.systems.framework import DiagramBuilder
    from pydrake.systems.primitives import LogVectorOutput

    b = DiagramBuilder()
    ctrl = b.AddSystem(make_controller(kind, PLATFORM, config))
    ref = b.AddSystem(PoseSource(reference))
    meas = b.AddSystem(PoseSource(measurement))
    b.Connect(ref.get_output_port(), ctrl.GetInputPort("reference"))
    b.Connect(meas.get_output_port(), ctrl.GetInputPort("leg_lengths"))
    logs = {name: LogVectorOutput(ctrl.GetOutputPort(name), b, log_period) for name in ("command", "setpoint", "status")}
    logs["reference"] = LogVectorOutput(ref.get_output_port(), b, log_period)
    d = b.Build()
    sim = Simulator(d)
    ctx = sim.get_mutable_context()
    L0 = measurement.pose(0.0)
    ctrl.initialize(ctrl.GetMyMutableContextFromRoot(ctx), L0, np.full(6, 5.0))
    sim.Initialize()
    sim.AdvanceTo(duration)
    out = {k: v.FindLog(sim.get_context()) for k, v in logs.items()}
    t = out["command"].sample_times()
    return t, {k: v.data().T for k, v in out.items()}, ctrl


def _fast(t):
    """Every pose coordinate moving quickly, so that 60 ticks visit many set-points."""
    t = np.asarray(t, dtype=float)[..., None]
    amp = np.array([0.03, 0.03, 0.03, 0.15, 0.15, 0.3])
    return np.array([0.0, 0.0, 0.7, 0, 0, 0]) + amp * np.sin(np.array([31.0, 37, 41, 43, 47, 53]) * t)


FAST = Trajectory("fast", _fast, None)
HOME = Trajectory("home", lambda t: SEED.pose(np.zeros_like(t)), None)
L_HOME = leg_lengths(PLATFORM, SEED.pose(0.0))


def step_measurement(t_step, delta):
    """Leg lengths L_HOME, plus ``delta`` on every leg from ``t_step`` on."""

    def fn(t):
        t = np.asarray(t, dtype=float)
        return L_HOME + delta * (t >= t_step)[..., None]

    return Trajectory("step", fn, None)


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
    with pytest.raises(TimingError, match=rf"{n} cycles = {n / 60:.3f} µs at 60 MHz, longer than the sample period 50\.000 µs"):
        DspTiming(sample_period=50e-6).check()
    with pytest.raises(TimingError, match=r"5000 cycles = 500\.000 µs at 10 MHz.*400\.000 µs"):
        make_controller("fixed", PLATFORM, ControllerConfig(timing=DspTiming(clock_hz=10e6, sample_period=400e-6, computation_cycles=5000)))
    DspTiming(sample_period=n / 60e6).check()  # exactly fits: accepted


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(sample_period=0.0), "sample_period must be a positive number, got 0.0"),
        (dict(latency="late"), "latency must be one of sample, computation, none, got 'late'"),
        (dict(computation_cycles=-3), "computation_cycles must be a positive integer, got -3"),
        (dict(sensor_resolution=float("nan")), "sensor_resolution must be a positive number"),
    ],
)
def test_bad_timing_values_are_named(kwargs, match):
    with pytest.raises(ValueError, match=match):
        DspTiming(**kwargs)


def test_bad_gains_and_controller_kind_are_named():
    with pytest.raises(ValueError, match="PidGains.kd must be a finite number >= 0, got -1"):
        PidGains(kd=-1)
    with pytest.raises(ValueError, match=r"PidGains.feedforward_filter must be in \(0, 1\], got 0"):
        PidGains(feedforward_filter=0)
    with pytest.raises(ValueError, match="controller must be 'fixed' or 'float', got 'analog'"):
        make_controller("analog", PLATFORM)
    with pytest.raises(ValueError, match="sensor_resolution 0.0003 m must divide the IK's length LSB 0.001 m"):
        make_controller("fixed", PLATFORM, ControllerConfig(timing=DspTiming(sensor_resolution=3e-4)))


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


@pytest.mark.parametrize("kind", ["fixed", "float"])
def test_ticks_happen_exactly_at_k_T(kind):
    T2 = 2e-3  # a period other than the plant's usual step
    config = ControllerConfig(timing=DspTiming(sample_period=T2))
    t, logs, _ = run_open_loop(kind, config, HOME, step_measurement(0.01, 1e-3), 0.05, T2 / 4)
    st = logs["status"]
    ticks = st[:, STATUS.index("ticks")]
    tick_time = st[:, STATUS.index("last_tick_time")]
    # one tick per period: a sample at t has seen the ticks strictly before t
    k = np.ceil(t / T2 - 1e-9)
    np.testing.assert_array_equal(ticks, k)
    first = np.r_[False, np.diff(ticks) > 0]
    # the logged tick times are k·T exactly (bit for bit: Drake schedules offset + k·period)
    np.testing.assert_array_equal(tick_time[first], np.arange(first.sum()) * T2)


@pytest.mark.parametrize(
    "latency, cycles, delay",
    [("sample", None, T), ("computation", 15000, 15000 / 60e6), ("none", None, 0.0)],
)
@pytest.mark.parametrize("kind", ["fixed", "float"])
def test_output_depends_only_on_measurements_before_the_release(kind, latency, cycles, delay):
    """A measurement step at tick 5 changes the output first at 5T + delay: with the default latency
    ("sample") the output at tick k depends only on measurements up to tick k−1."""
    config = ControllerConfig(timing=DspTiming(latency=latency, computation_cycles=cycles))
    t_step, dt = 5 * T, T / 8
    t, base, _ = run_open_loop(kind, config, HOME, step_measurement(1.0, 0.0), 0.012, dt)
    t, step, _ = run_open_loop(kind, config, HOME, step_measurement(t_step, 1e-3), 0.012, dt)
    changed = np.any(step["command"] != base["command"], axis=1)
    assert changed.any()
    t_first = t[np.argmax(changed)]
    assert t_first == pytest.approx(t_step + delay + dt, abs=1e-12)  # the first sample after the release
    # held between releases (zero-order hold): the command changes only at release instants k·T + delay
    moves = t[1:][np.any(np.diff(step["command"], axis=0) != 0, axis=1)]
    phase = np.mod(moves - dt - delay + 1e-12, T)
    assert len(moves) > 3 and np.all(phase < 1e-9), moves


# ----------------------------------------------------------------------------------------------
# Bit-exact set-points


@pytest.mark.parametrize("latency, lag", [("none", 1), ("sample", 2)])
def test_fixed_setpoints_equal_the_standalone_fixed_point_ik(latency, lag):
    """The set-points the controller releases are, bit for bit, ``fixed_point_leg_lengths`` of the
    reference it read (16-bit words, integer mm, the tfr16 sine/cosine). Not primed: every tick
    computes the IK itself. Logged at k·T (before tick k), so the sample at k·T shows the set-point of
    tick k − 1 (latency none) or k − 2 (one full sample)."""
    config = ControllerConfig(timing=DspTiming(latency=latency))
    meas = Trajectory("L", lambda t: leg_lengths(PLATFORM, FAST.pose(t)), None)
    t, logs, ctrl = run_open_loop("fixed", config, FAST, meas, 0.06, T)
    ref = logs["reference"]  # the reference at each tick, as the controller read it
    np.testing.assert_array_equal(t, np.arange(len(t)) * T)
    words = fixed_point_leg_lengths(PLATFORM, ref, QFormat(16, 1e-3, "tfr16"), return_words=True)
    sp = logs["setpoint"]
    np.testing.assert_array_equal(sp[lag:], words[: len(words) - lag] * 1e-3)
    assert ctrl.law.cache_misses == len(t) - 1  # one IK per tick (the last sample's tick is not run)
    assert len(np.unique(words, axis=0)) > 40  # the reference moved through many set-points


def test_primed_ik_cache_gives_the_same_words():
    config = ControllerConfig()
    ctrl = FixedPointLaw(PLATFORM, config)
    poses = ROTATING.pose(np.arange(200) * 0.01)
    ctrl.prime(poses)
    for q in poses[::17]:
        np.testing.assert_array_equal(ctrl.setpoint_words(q), ctrl.ik_words(q))
    assert ctrl.cache_misses == 0
    q = poses[3] + 1e-9  # not primed: computed, same function
    np.testing.assert_array_equal(ctrl.setpoint_words(q), fixed_point_leg_lengths(PLATFORM, q, config.ik_format, return_words=True))
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
        pid = np.concatenate([rng.integers(-(2**31), 2**31 - 1, 6), np.round(L / 1e-5) + rng.integers(-300, 300, 6),
                              rng.integers(-5000, 5000, 6), ctrl.setpoint_words(pose) + rng.integers(-3, 3, 6),
                              rng.integers(-5000, 5000, 6)]).astype(float)
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
    from stewart_drake.control import (HEAVY_MODE_DAMPING, PHASE_BUDGET, ROUTH_FRACTION, STIFFNESS_MARGIN,
                                       UNKNOWN_POSE_STIFFNESS_FACTOR, design_gains, leg_space_inertia, loop_delay,
                                       strut_stiffness)

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
    for trial in range(60):
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
    """With pydrake unimportable, the control package imports and both laws tick (a fresh interpreter:
    this one has imported pydrake already); the fixed-point tick equals this process's bit for bit."""
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
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, cwd=root).stdout.splitlines()
    law = FixedPointLaw(PLATFORM)
    pose = SEED.pose(0.4)
    L = leg_lengths(PLATFORM, pose) + 2e-4
    cmd = law.step(law.initial_pid_state(L, np.full(6, 5.0)), pose, L, np.full(6, 3.0))[0]
    assert out[0] == repr(cmd.tolist())
    assert len(out) == 2
