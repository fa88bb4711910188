"""``sd.tune`` on the user's 210 kg machine: the margins it claims recomputed at every grid pose by a fresh
linear model, the verify step is the nonlinear loop's run, the tuned machine file reads back; and the ripple
estimate and bound of ``control.ripple`` against the ripple ``sd.simulate`` measures at several LSBs."""

import math
from pathlib import Path

import numpy as np
import pytest

import stewart_drake as sd
from stewart_drake.api.simulation import plan_run
from stewart_drake.api.tune import loop_spec
from stewart_drake.control.chatter import CHATTER_RANGE_FRACTION
from stewart_drake.control.feedforward import feedforward_forces
from stewart_drake.control.frequency import LoopModel, default_frequencies, effective_gains, margins
from stewart_drake.control.ripple import quantisation_ripple

NEWCOMER = str(Path(__file__).parents[2] / "examples" / "newcomer-210kg.yaml")


@pytest.fixture(scope="module")
def tuned():
    return sd.tune(NEWCOMER)


def test_claimed_margins_hold_at_every_grid_pose(tuned):
    assert tuned.ok, tuned.failures
    claim = tuned.after["linear"]
    # the tuned machine planned afresh: the gains its fixed law applies (Q15 words), its timing and lag
    plan = plan_run(tuned.machine)
    sc, t = plan.scenario, plan.timing
    gains = effective_gains(sc.controller, sc.config)
    for k, v in claim["gains"].items():  # the claim is about the gains the law applies, word for word
        assert getattr(gains, k) == pytest.approx(v, rel=1e-12)
    f = default_frequencies(t.sample_period, 400)  # another grid than the tuner's 200 frequencies
    spec = loop_spec(plan)
    gm = pm = math.inf
    for pose in tuned.grid:
        model = LoopModel.build(sc.platform, pose, gains, t.sample_period, t.output_delay, spec.lag, spec.step, None)
        assert model.spectral_radius < 1
        L, _ = model.loops(f)
        for leg in range(6):
            m = margins(f, L[:, leg])
            gm, pm = min(gm, m["gain_margin_db"]), min(pm, m["phase_margin_deg"])
    # the crossings are interpolated in log frequency on either grid: within 0.05 dB and 0.5° of each other
    assert gm == pytest.approx(claim["gain_margin_db"], abs=0.05) and gm >= 6.0 - 0.05
    assert pm == pytest.approx(claim["phase_margin_deg"], abs=0.5) and pm >= 30.0 - 0.5
    # today's design misses the margins on the same grid (the reason to tune)
    assert tuned.before["linear"]["gain_margin_db"] < 6.0


def test_verify_is_the_nonlinear_run_of_the_tuned_machine(tuned, tmp_path):
    # the file the command writes reads back as the same machine, and its run is the one the tuner reported
    path = tmp_path / "tuned.yaml"
    path.write_text(tuned.machine.to_yaml())
    run = sd.simulate(str(path))
    assert max(run.summary["force_ripple_N"]) == tuned.after["run"]["force_ripple_N"]
    assert run.summary["max_leg_error_mm"] == tuned.after["run"]["max_leg_error_mm"]
    assert run.ok and tuned.after["run"]["force_ripple_N"] < CHATTER_RANGE_FRACTION * 4000.0
    assert run.summary["firmware_format"]["length_lsb_m"] == tuned.format["length_lsb_m"]
    assert tuned.format["error_m"] <= tuned.targets["error_budget_m"]


@pytest.mark.parametrize(
    "machine, lsbs",
    [("utn-dynamic", ("0.5mm", "2mm")), (NEWCOMER, ("30um", "300um", "1mm"))],
)
def test_ripple_bound_and_estimate_against_the_nonlinear_loop(machine, lsbs):
    for lsb in lsbs:
        plan = plan_run(machine, **{"firmware.length_lsb": lsb})
        sc = plan.scenario
        model = loop_spec(plan).model(sc.platform, sc.platform.home_pose(), effective_gains(sc.controller, sc.config))
        rip = quantisation_ripple(
            model, sc.config.ik_format.length_lsb, plan.timing.sensor_resolution, plan.timing.command_range
        )
        res = sd.simulate(machine, **{"firmware.length_lsb": lsb})
        log = res.log.raw
        F_qs = feedforward_forces(sc.platform, sc.trajectory, log.t, 0.0, plan.timing.sample_period)
        peak = float(np.abs(np.asarray(log.force) - F_qs).max())
        rms = max(res.summary["force_ripple_N"])
        # the bound is a peak bound on any bounded quantisation error: at least the run's largest deviation
        assert rip.bound_N >= peak, (lsb, rip.bound_N, peak)
        # the white-noise estimate assumes an error uncorrelated from tick to tick; a slow reference (fewer steps
        # than ticks) or a limit cycle (a correlated error) moves the truth either way: within a factor 2
        assert 0.5 <= rip.rms_N / rms <= 2.0, (lsb, rip.rms_N, rms)


def test_gains_tune_in_the_machine_file_runs_the_tuner_at_plan_time(tuned):
    # controller.gains: tune plans the run with the gains sd.tune chose (the same grid, margins and candidates;
    # the newcomer's widest-bandwidth feasible set also fits the ripple limit, so sd.tune keeps it)
    plan = plan_run(NEWCOMER, **{"controller.gains": "tune"})
    sc = plan.scenario
    g = effective_gains(sc.controller, sc.config)
    assert {k: getattr(g, k) for k in ("kp", "ki", "kd", "kv")} == pytest.approx(tuned.after["linear"]["gains"])
    # and "design" (the default) is today's design, untouched
    assert plan_run(NEWCOMER).scenario.config.gains.kp == pytest.approx(tuned.before["linear"]["gains"]["kp"], 1e-4)
