"""The closed loop: trajectory source → DSP controller → actuators → closed-loop MultibodyPlant.

Short runs (1 s simulated, ~1 s wall each) of the seed trajectory on ``utn-dynamic``.
"""

import numpy as np
import pytest

from stewart_drake.control import ControllerConfig, DspTiming, TimingError
from stewart_drake.control.feedforward import feedforward_forces
from stewart_drake.core.geometry import load_preset
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.core.trajectory import SEED, fit_trajectory, get_trajectory, load_trajectory_csv
from stewart_drake.drake.simulation import ActuatorModel, Scenario, SimulationLog, build_simulation
from stewart_drake.drake.systems import Actuators
from stewart_drake.fixedpoint import fixed_point_leg_lengths

PLATFORM = load_preset("utn-dynamic")
DURATION = 1.0


@pytest.fixture(scope="module")
def runs():
    """One float and one fixed run of the seed trajectory with the default (DSP) configuration."""
    return {kind: build_simulation(Scenario(PLATFORM, SEED, kind)).run(DURATION) for kind in ("float", "fixed")}


def test_run_starts_on_the_reference(runs):
    """The plant starts at the reference pose (the logged pose goes through Drake's quaternion state and
    back) with the leg lengths of the exact IK; the first samples move with the reference's velocity."""
    for log in runs.values():
        np.testing.assert_allclose(log.pose[0], SEED.pose(0.0), atol=1e-12)
        np.testing.assert_allclose(log.lengths[0], leg_lengths(PLATFORM, SEED.pose(0.0)), atol=1e-12)
        # after one plant step py has moved by ≈ 0.2 m/s · 1 ms (not 0: the run did not start at rest)
        assert log.pose[1, 1] == pytest.approx(0.2e-3, rel=0.05)


def test_closed_loop_ticks_are_k_T(runs):
    for log in runs.values():
        ticks = log.tick_times()
        n = len(ticks)
        assert n == round(DURATION / 1e-3)  # ticks at 0 … (N−1)·T have been seen by the last sample at N·T
        np.testing.assert_array_equal(ticks, np.arange(n) * 1e-3)


def test_fixed_closed_loop_setpoints_are_the_fixed_point_ik_of_the_reference(runs):
    """In the loop too: the set-point held at (k+2)·T (sample latency, logged before the update) is the
    fixed-point IK of the reference read at tick k."""
    log = runs["fixed"]
    words = fixed_point_leg_lengths(PLATFORM, log.reference, ControllerConfig().ik_format, return_words=True)
    k = np.round(log.t / 1e-3).astype(int)
    held = log.setpoint[k >= 2]
    np.testing.assert_array_equal(held, words[k[k >= 2] - 2] * 1e-3)


def test_seed_trajectory_tracks_within_the_quantisation_and_timing_bound(runs):
    """Bound, leg by leg, on |L − IK(reference)|:

    - the float twin has the same timing (one sample of output delay, 1 kHz, the same sensor and
      actuators) and no arithmetic quantisation; its error E_float is the servo + timing error;
    - the fixed-point controller tracks set-points that differ from the exact IK by at most Δ_IK
      (the fixed-point IK's own error over the run, computed from the IK alone), moves in steps of one
      set-point LSB (1 mm) that the loop can over- or undershoot by at most that step, and reads the
      sensor to ±r/2. So |e_fixed| <= E_float + Δ_IK + LSB + r.
    - E_float itself is bounded by the timing: the reference reaches the actuators, along the
      feed-forward path, late by the output delay (T) + the measurement's age (T) + the actuator lag (τ)
      + the feed-forward filter's time constant ((1 − α)/α · T); the error is at most the distance the
      legs travel in that time, v_max · t_delay (the feedback only reduces it).
    """
    t = runs["float"].t
    L_ref = leg_lengths(PLATFORM, SEED.pose(t))
    v_max = np.abs(np.gradient(L_ref, t, axis=0)).max()
    e_float = np.abs(runs["float"].length_error(SEED, PLATFORM)).max()
    e_fixed = np.abs(runs["fixed"].length_error(SEED, PLATFORM)).max()
    ticks = SEED.pose(np.arange(round(DURATION / 1e-3)) * 1e-3)
    fmt = ControllerConfig().ik_format
    d_ik = np.abs(fixed_point_leg_lengths(PLATFORM, ticks, fmt) - leg_lengths(PLATFORM, ticks)).max()
    r = DspTiming().sensor_resolution
    cfg, T = ControllerConfig(), 1e-3
    alpha = cfg.gains.feedforward_filter
    t_delay = cfg.timing.output_delay + T + ActuatorModel().time_constant + (1 - alpha) / alpha * T
    assert e_float <= v_max * t_delay, (e_float, v_max, t_delay)
    assert e_fixed <= e_float + d_ik + fmt.length_lsb + r, (e_fixed, e_float, d_ik)
    # and the loop does something: without a controller the plate would fall to the stroke end
    assert e_fixed < 3e-3 and e_float < 1e-3
    assert runs["fixed"].saturations().sum() == 0


def test_two_identical_runs_give_identical_logs(runs):
    again = build_simulation(Scenario(PLATFORM, SEED, "fixed")).run(DURATION)
    first = runs["fixed"]
    for name in SimulationLog.ARRAYS:
        np.testing.assert_array_equal(getattr(again, name), getattr(first, name), err_msg=name)


@pytest.mark.parametrize("kind", ["float", "fixed"])
def test_tick_tables_hold_the_values_of_one_time_at_a_time(kind):
    """The reference and feed-forward tables the loop reads by tick index are filled in one batch before
    the run: a speed-up only. Each tick's row equals the pose / forces computed for that time alone, bit
    for bit (the logged reference; the feed-forward row of each tick), and the IK cache changes no bit (a
    run with it emptied gives the same logs)."""
    traj = fit_trajectory(get_trajectory("rotating"), PLATFORM)
    primed_sim = build_simulation(Scenario(PLATFORM, traj, kind))
    primed = primed_sim.run(0.1)
    for t, q in zip(primed.t_ref, primed.reference):
        np.testing.assert_array_equal(q, traj.pose(np.array([t]))[0])
    rows, table = primed_sim.controller.feedforward, primed_sim.feedforward
    assert len(rows) == len(primed.t_ref)
    for row, t in zip(rows, primed.t_ref):
        np.testing.assert_array_equal(
            row, feedforward_forces(PLATFORM, traj, [t], table.lead, table.h, table.engine)[0]
        )
    sim = build_simulation(Scenario(PLATFORM, traj, kind))
    sim.controller.law.prime = lambda poses: None
    bare = sim.run(0.1)
    assert sim.controller.law._cache == {}
    for name in SimulationLog.ARRAYS:
        np.testing.assert_array_equal(getattr(bare, name), getattr(primed, name), err_msg=name)


def test_infeasible_timing_is_refused_by_the_diagram():
    with pytest.raises(TimingError, match=r"longer than the sample period 40\.000 µs"):
        build_simulation(Scenario(PLATFORM, SEED, "fixed", ControllerConfig(timing=DspTiming(sample_period=40e-6))))


def test_saturation_is_counted_in_the_loop():
    """A command range of 3 N cannot hold the plate (≈13 N of weight on six legs, 2–5 N each): the
    controller saturates and says so; the command never exceeds the range."""
    cfg = ControllerConfig(timing=DspTiming(command_range=3.0))
    log = build_simulation(Scenario(PLATFORM, SEED, "fixed", cfg)).run(0.2)
    assert log.saturations().sum() > 0
    assert np.all(np.abs(log.command) <= 3.0)


@pytest.mark.parametrize("kind", ["fixed", "float"])
def test_anti_windup_stops_the_integrator_at_saturation(kind):
    """One tick computed directly: with an error that drives the output past the positive rail the
    integrator does not grow; with the output inside the range it does."""
    from stewart_drake.drake.systems import make_law

    ctrl = make_law(kind, PLATFORM)
    pose = SEED.pose(0.0)
    L = leg_lengths(PLATFORM, pose)
    pid = ctrl.initial_pid_state(L, np.full(6, 5.0))
    # legs 0.3 m short of their set-points: the P term alone is 900 N > 200 N
    u, _, pid_new, sat = ctrl.step(pid, pose, L - 0.3)
    assert np.all(sat == 1) and np.allclose(u, 200.0, rtol=1e-3)
    np.testing.assert_array_equal(pid_new[:6], pid[:6])
    # 1 mm short: unsaturated, the integrator grows by ki·T·e (float) or its Q31 word (fixed)
    u, _, pid_new, sat = ctrl.step(pid, pose, L - 1e-3)
    assert np.all(sat == 0) and np.all(pid_new[:6] > pid[:6])


def test_log_save_writes_npz_and_csv(runs, tmp_path):
    paths = runs["fixed"].save(tmp_path)
    data = np.load(paths[0])
    np.testing.assert_array_equal(data["setpoint"], runs["fixed"].setpoint)
    lines = paths[1].read_text().splitlines()
    assert lines[0].startswith("t,pose_px") and len(lines) == len(runs["fixed"].t) + 1


# ----------------------------------------------------------------------------------------------
# Trajectories and actuators (no plant)


def test_csv_trajectory_interpolates_and_names_bad_lines(tmp_path):
    f = tmp_path / "traj.csv"
    f.write_text("t,px,py,pz,ax,ay,az\n0,0,0,700,0,0,0\n1,10,0,700,0,0,90\n")
    traj = load_trajectory_csv(f, length_unit="mm", angle_unit="deg")
    np.testing.assert_allclose(traj.pose(0.5), [0.005, 0, 0.7, 0, 0, np.pi / 4])
    np.testing.assert_allclose(traj.pose(5.0), [0.01, 0, 0.7, 0, 0, np.pi / 2])  # held after the end
    assert traj.duration == 1.0
    bad = tmp_path / "bad.csv"
    bad.write_text("0,0,0,0.7,0,0,0\n0,0,0,0.7,0,0,0\n")
    with pytest.raises(ValueError, match=r"bad.csv:2: time 0.0 s is not after the previous sample's 0.0 s"):
        load_trajectory_csv(bad)
    bad.write_text("0,0,0,0.7,0,0\n")
    with pytest.raises(ValueError, match=r"bad.csv:1: expected 7 values"):
        load_trajectory_csv(bad)
    with pytest.raises(ValueError, match="unknown trajectory 'spiral'"):
        get_trajectory("spiral")


def test_actuator_saturates_and_lags():
    """Force limit, then a first-order lag exact at its period: the step response after n steps is
    F_max·(1 − exp(−n·dt/τ))."""
    from pydrake.systems.analysis import Simulator

    dt, tau = 1e-3, 4e-3
    act = Actuators(50.0, tau, dt)
    sim = Simulator(act)
    ctx = sim.get_mutable_context()
    act.get_input_port().FixValue(ctx, np.full(6, 500.0))  # beyond the 50 N limit
    sim.AdvanceTo(10 * dt)
    F = act.get_output_port().Eval(ctx)
    np.testing.assert_allclose(F, 50.0 * (1 - np.exp(-10 * dt / tau)), rtol=1e-12)
    with pytest.raises(ValueError, match="ActuatorModel.time_constant must be >= 0 s, got -1"):
        ActuatorModel(time_constant=-1)


@pytest.mark.parametrize("tau", [2e-3, 0.0])
def test_actuator_is_the_numpy_recurrence_bit_for_bit(tau):
    """Drake's Saturation + LinearSystem compute exactly F ← a·F + (1−a)·clip(u): one rounding per
    product and one per sum, as numpy does (random commands, half of them beyond the limit)."""
    from pydrake.systems.analysis import Simulator

    dt, F_max = 1e-3, 80.0
    u = np.random.default_rng(3).normal(0.0, 100.0, (40, 6))
    act = Actuators(F_max, tau, dt)
    sim = Simulator(act)
    ctx = sim.get_mutable_context()
    F0 = np.linspace(-100.0, 100.0, 6)
    act.set_force(ctx, F0)
    a = np.exp(-dt / tau) if tau > 0 else 0.0
    F = np.clip(F0, -F_max, F_max)
    for k, uk in enumerate(u):
        act.get_input_port().FixValue(ctx, uk)
        sat = np.clip(uk, -F_max, F_max)
        np.testing.assert_array_equal(act.get_output_port().Eval(ctx), F if tau > 0 else sat)
        sim.AdvanceTo((k + 1) * dt)
        if tau > 0:
            F = a * F + (1 - a) * sat


# ----------------------------------------------------------------------------------------------
# Any platform: gains designed from the platform, model-based force feed-forward


def _timing_bound(platform, traj, log, cfg, actuators=ActuatorModel()):
    """The bound terms of ``test_seed_trajectory_tracks_within_the_quantisation_and_timing_bound`` for
    any platform and trajectory: v_max · t_delay (m), Δ_IK over the ticks (m)."""
    t = log.t
    v_max = np.abs(np.gradient(leg_lengths(platform, traj.pose(t)), t, axis=0)).max()
    T = cfg.timing.sample_period
    a = cfg.gains.feedforward_filter
    t_delay = cfg.timing.output_delay + T + actuators.time_constant + (1 - a) / a * T
    ticks = traj.pose(np.arange(round(t[-1] / T)) * T)
    d_ik = np.abs(fixed_point_leg_lengths(platform, ticks, cfg.ik_format) - leg_lengths(platform, ticks)).max()
    return v_max * t_delay, d_ik


@pytest.mark.parametrize("name", ["utn-kinematic", "gonzalez-dutra-2009"])
@pytest.mark.parametrize("base", ["seed", "rotating"])
def test_other_platforms_track_out_of_the_box(name, base):
    """The seed-like and rotating trajectories moved to each platform's home height and scaled to its
    stroke (``fit_trajectory``), run with the defaults only (gains designed from the platform, command
    range its actuator force, force feed-forward). The same bounds as on utn-dynamic, for the same
    reasons: the float twin within the timing bound v_max · t_delay, the fixed-point controller within
    float + Δ_IK + LSB + r; no saturation. (Before the design: 40–76 mm on utn-kinematic.)"""
    from stewart_drake.core.trajectory import fit_trajectory

    platform = load_preset(name)
    traj = fit_trajectory(get_trajectory(base), platform)
    logs = {kind: build_simulation(Scenario(platform, traj, kind)).run(0.5) for kind in ("float", "fixed")}
    cfg = ControllerConfig.for_platform(platform)
    e_float = np.abs(logs["float"].length_error(traj, platform)).max()
    e_fixed = np.abs(logs["fixed"].length_error(traj, platform)).max()
    timing, d_ik = _timing_bound(platform, traj, logs["float"], cfg)
    assert e_float <= timing, (e_float, timing)
    assert e_fixed <= e_float + d_ik + cfg.ik_format.length_lsb + cfg.timing.sensor_resolution, (e_fixed, e_float, d_ik)
    assert e_float < 1e-3 and e_fixed < 5e-3
    assert logs["fixed"].saturations().sum() == 0 and logs["float"].saturations().sum() == 0


def test_stiffness_floor_is_what_keeps_the_heavy_platform_up():
    """utn-kinematic (12.8 kg on almost flat legs): its struts' negative stiffness reaches ~10 kN/m along
    the rotating trajectory. Gains without the stiffness floor (kp = 4.6 kN/m from the inertia rules
    alone, here 0.9 × the home value) let an unstable mode grow (~10 mm after 1 s, growing); the designed
    kp (3 × the home value) holds the plate within a millimetre."""
    from dataclasses import replace

    from stewart_drake.control import strut_stiffness
    from stewart_drake.core.trajectory import ROTATING, fit_trajectory

    platform = load_preset("utn-kinematic")
    traj = fit_trajectory(ROTATING, platform)
    cfg = ControllerConfig.for_platform(platform)
    weak = replace(cfg, gains=replace(cfg.gains, kp=0.9 * strut_stiffness(platform)))
    e_weak = np.abs(
        build_simulation(Scenario(platform, traj, "float", weak)).run(1.0).length_error(traj, platform)
    ).max()
    e_design = np.abs(
        build_simulation(Scenario(platform, traj, "float", cfg)).run(1.0).length_error(traj, platform)
    ).max()
    assert e_weak > 5e-3 and e_design < 1e-3, (e_weak, e_design)


@pytest.mark.parametrize("kind", ["float", "fixed"])
def test_utn_kinematic_rotating_error_does_not_grow(kind):
    """A stable loop driven by a smooth reference and a bounded quantisation repeats its error; a growing
    mode shows as a larger error late in the run. On utn-kinematic's rotating trajectory (strut stiffness
    up to 14.6 kN/m) the max error in the last 0.25 s of a 1.5 s run stays within the first 0.5 s's max
    plus one set-point LSB (1 mm: the fixed point's set-point steps can land differently) — the float twin
    plus 0.1 × that. With the home-only design of 6b (kp 15.3 kN/m, ki 66 kN/(m·s)) the fixed-point error
    went 2.3 mm → 30 mm here (the heaviest mode, ~2 Hz, Routh-unstable where kp − K is small)."""
    from stewart_drake.core.trajectory import ROTATING, fit_trajectory

    platform = load_preset("utn-kinematic")
    traj = fit_trajectory(ROTATING, platform)
    log = build_simulation(Scenario(platform, traj, kind)).run(1.5)
    e = np.abs(log.length_error(traj, platform)).max(axis=1)
    first, last = e[log.t < 0.5].max(), e[log.t >= 1.25].max()
    slack = 1e-3 if kind == "fixed" else 1e-4
    assert last <= first + slack, (first, last)


def test_feedforward_table_is_the_inverse_dynamics_ahead_of_time_and_helps():
    """The table holds ``leg_forces_with_legs`` of the reference at t + lead (lead = output delay + T/2 +
    actuator lag, checked against a direct evaluation), and on utn-dynamic it cuts the float twin's error
    several-fold compared with the PID alone."""
    from stewart_drake.control import feedforward_lead
    from stewart_drake.core.dynamics import leg_forces_with_legs

    cfg = ControllerConfig.for_platform(PLATFORM)
    lead = feedforward_lead(cfg, 2e-3)
    assert lead == pytest.approx(1e-3 + 0.5e-3 + 2e-3)
    sim = build_simulation(Scenario(PLATFORM, SEED, "float"))
    t = 0.25
    q = SEED.pose(t + lead)  # analytic rates of the seed trajectory: py = 0.1 sin 2t
    qd = np.array([0, 0.2 * np.cos(2 * (t + lead)), 0, 0, 0, 0])
    qdd = np.array([0, -0.4 * np.sin(2 * (t + lead)), 0, 0, 0, 0])
    # central differences of step T: error h²/6 · |d⁴q/dt⁴| on the rates, tiny here
    np.testing.assert_allclose(sim.feedforward.force(t), leg_forces_with_legs(PLATFORM, q, qd, qdd), atol=1e-5)
    log = sim.run(0.6)
    e_ff = np.abs(log.length_error(SEED, PLATFORM)).max()
    e_pid = np.abs(
        build_simulation(Scenario(PLATFORM, SEED, "float", feedforward=False)).run(0.6).length_error(SEED, PLATFORM)
    ).max()
    assert e_ff < e_pid / 4, (e_ff, e_pid)


def test_setpoint_l1_gain_bounds_the_fixed_point_excess_on_gonzalez():
    """The fixed-point set-points are the float twin's plus an error of amplitude A = Δ_IK + LSB + r; the
    loop passes it to the legs with the ℓ1 gain ‖h‖₁ of its impulse response (set-point → lengths), not
    with gain 1: gonzalez-dutra-2009's stiff loop overshoots a 1 mm set-point step, and its fixed-point
    error exceeded float + A over 4 s. Measured from the float twin's step response at home
    (``setpoint_step_gain``): the stepped leg's ‖h_ii‖₁ ≥ 1 (total variation from 0 to the DC gain 1, which
    the integrator restores), > 1 with the overshoot; the six legs' sum is at least that; and the bound
    float + ‖h‖₁·A holds on a 1 s run (both trajectories)."""
    from stewart_drake.core.trajectory import ROTATING, design_poses, fit_trajectory
    from stewart_drake.drake.simulation import setpoint_step_gain

    platform = load_preset("gonzalez-dutra-2009")
    for base in (SEED, ROTATING):
        traj = fit_trajectory(base, platform)
        cfg = ControllerConfig.for_platform(platform, poses=design_poses(traj, 4.0))
        g = setpoint_step_gain(platform, cfg, duration=1.0)
        s = g["s"][:, 0]
        assert abs(s[-1] - 1.0) < 0.02, s[-1]  # DC gain 1: the integrator removes the static error
        assert g["peak"] > 1.1 and g["diagonal"] >= 2 * g["peak"] - 1 - 1e-9, g  # overshoot: up, back down
        assert g["coupled"] >= g["diagonal"] >= 1.0
        logs = {kind: build_simulation(Scenario(platform, traj, kind, cfg)).run(1.0) for kind in ("float", "fixed")}
        e_float, e_fixed = (np.abs(logs[k].length_error(traj, platform)).max() for k in ("float", "fixed"))
        ticks = traj.pose(np.arange(1000) * 1e-3)
        d_ik = np.abs(fixed_point_leg_lengths(platform, ticks, cfg.ik_format) - leg_lengths(platform, ticks)).max()
        amplitude = d_ik + cfg.ik_format.length_lsb + cfg.timing.sensor_resolution
        assert e_fixed <= e_float + g["coupled"] * amplitude, (base.name, e_fixed, e_float, g["coupled"], amplitude)


def test_setpoint_step_response_is_refused_for_a_bad_leg_or_step():
    from stewart_drake.drake.simulation import setpoint_step_response

    with pytest.raises(ValueError, match="leg must be 0 … 5, got 6"):
        setpoint_step_response(PLATFORM, leg=6)
    with pytest.raises(ValueError, match="step must be a non-zero number of metres, got 0.0"):
        setpoint_step_response(PLATFORM, step=0.0)


def test_l1_gain_reports_how_far_it_has_settled():
    """‖h‖₁ is a sum over the run, so a short run underestimates it: utn-dynamic's loop rings down over
    seconds. ``settled`` (the share of ‖h‖₁ the run's last quarter added) says so — large at 1.5 s, where
    the sum is still > 5 % short of the 6 s one, and under the report's 1 % at 6 s — and it is the 6 s
    response's own prefix that gives the 1.5 s figures (the sums are over the same samples)."""
    from stewart_drake.drake.simulation import _l1_sums, setpoint_step_gain

    platform = load_preset("utn-dynamic")
    long = setpoint_step_gain(platform, duration=6.0)
    short = setpoint_step_gain(platform, duration=1.5)
    n = len(short["s"])
    np.testing.assert_array_equal(short["s"], long["s"][:n])  # the same loop, the same samples
    assert _l1_sums(long["s"][:n], 0)[1] == short["coupled"]
    assert short["coupled"] < 0.95 * long["coupled"], (short["coupled"], long["coupled"])
    assert short["settled"] > 0.05 > 0.01 > long["settled"], (short["settled"], long["settled"])


def test_l1_gain_continues_its_runs_until_settled():
    """``setpoint_step_gain`` with ``settle``: a run not settled is continued to twice as long
    (``Simulation.extend``) up to ``max_duration``, and gives what fresh runs that long give, bit for bit;
    a settled one stops at its first duration."""
    from stewart_drake.drake.simulation import setpoint_step_gain

    platform = load_preset("utn-dynamic")
    doubled = setpoint_step_gain(platform, duration=0.25, settle=0.0, max_duration=1.0)  # 0.25, 0.5, 1 s
    fresh = setpoint_step_gain(platform, duration=1.0)
    assert doubled["t"][-1] == 1.0 and doubled["settled"] > 0.0
    for k in fresh:
        np.testing.assert_array_equal(doubled[k], fresh[k], err_msg=k)
    assert setpoint_step_gain(platform, duration=0.25, settle=1.0, max_duration=1.0)["t"][-1] == 0.25
