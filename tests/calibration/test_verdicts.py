"""A calibration that cannot be fooled: copies are not evidence, a model that moved farther than a built machine
can is not one, a weak identification is said and named, a gross outlier is isolated, forward kinematics that has
no solution on the nominal does not refuse good data, and noise-free data (σ = 0) is accepted."""

from __future__ import annotations

import re

import numpy as np
import pytest

from stewart_drake.api.calibration import calibrate
from stewart_drake.calibration.identify import MAX_CHI2_RATIO, identify, plausible_correction, validation_failures
from stewart_drake.calibration.measurements import measurements_csv
from stewart_drake.calibration.model import NOISE_FLOOR, Layout, Noise
from stewart_drake.calibration.plan import Box, candidate_poses, plan_measurements
from stewart_drake.calibration.simulate import simulate_measurements
from stewart_drake.calibration.validate import truth_errors
from stewart_drake.core.geometry import load_preset
from stewart_drake.core.kinematics import leg_lengths, plate_anchors
from stewart_drake.errors import CalibrationError
from tests.calibration.conftest import ERRORS, NOISE


@pytest.fixture(scope="module")
def utn():
    """utn-dynamic: 30 planned poses, the machine of seed 1 measured there, 50 other poses to judge against."""
    nominal = load_preset("utn-dynamic")
    plan = plan_measurements(nominal, 30, "pose", noise=NOISE, seed=0, candidates=400)
    data, truth = simulate_measurements(nominal, ERRORS, plan.poses, "pose", NOISE, seed=1)
    val = candidate_poses(nominal, Box.default(nominal), 200, seed=99)[:50]
    return nominal, plan.poses, data, truth, val


def _write(tmp_path, data, name="m.csv"):
    f = tmp_path / name
    f.write_text(measurements_csv(data), encoding="utf-8")
    return f


def test_copied_rows_are_one_measurement(utn):
    """Every row twice: the same fit and the same σ as the rows once (a copy repeats the noise draw, so it is no
    second measurement; counting it shrank σ by √2), and a warning naming the first copy's line."""
    nominal, _, data, _, _ = utn
    once = identify(nominal, data, NOISE)
    twice = identify(nominal, data.subset(np.r_[np.arange(30), np.arange(30)]), NOISE)
    assert np.array_equal(twice.sigma, once.sigma) and np.array_equal(twice.theta, once.theta)
    assert len(twice.lines) == 30
    assert any("30 rows repeat an earlier row exactly" in w and "line 2 repeats line 2" in w for w in twice.warnings)
    assert not any("repeat" in w for w in once.warnings)


def test_one_pose_copied_or_measured_again_is_too_few(utn, tmp_path):
    """30 copies of one pose, or 30 noisy measurements of one pose: one distinct pose, refused (6 needed)."""
    nominal, poses, data, _, _ = utn
    copies = _write(tmp_path, data.subset(np.zeros(30, int)), "copies.csv")
    with pytest.raises(CalibrationError, match=r"30 rows hold only 1 distinct poses \(29 exact copies counted once"):
        calibrate(nominal, copies)
    again, _ = simulate_measurements(nominal, ERRORS, np.repeat(poses[:1], 30, axis=0), "pose", NOISE, seed=1)
    with pytest.raises(CalibrationError, match=r"30 rows hold only 1 distinct poses \(0 exact copies"):
        calibrate(nominal, _write(tmp_path, again, "again.csv"))


def test_measurements_of_another_platform_are_not_a_calibration(utn, tmp_path):
    """utn-dynamic (a 3-6) measured, calibrated as gonzalez-dutra-2009 (a 6-6): the 6-6 model can fit it to the
    noise, but only by moving joints by hundreds of mm; not ok, said why."""
    _, _, data, _, _ = utn
    cal = calibrate("gonzalez-dutra-2009", _write(tmp_path, data))
    assert cal.converged and not cal.ok
    assert any("this is not a built gonzalez-dutra-2009" in f for f in cal.identified.failures)
    assert np.abs(cal.identified.corrections).max() > 10 * plausible_correction(cal.nominal)


def test_poses_at_one_orientation_with_gains_do_not_make_a_platform(utn, tmp_path):
    """30 poses within ±0.1 mrad of one orientation, --gains: the leg-pair directions are fixed only by noise
    (condition ~1e5); the fitted model reads centimetres from the nominal and is worse than the nominal against
    the true machine, and so on 20 held-out poses: not ok, for both reasons."""
    nominal, _, _, truth, val = utn
    rng = np.random.default_rng(0)
    q = np.tile(nominal.home_pose(), (30, 1))
    q[:, :3] += rng.uniform(-0.02, 0.02, (30, 3))
    q[:, 3:] += rng.uniform(-1e-4, 1e-4, (30, 3))
    flat, _ = simulate_measurements(nominal, {}, q, "pose", NOISE, seed=1, truth=truth.platform)
    other, _ = simulate_measurements(nominal, {}, val[:20], "pose", NOISE, seed=2, truth=truth.platform)
    cal = calibrate(nominal, _write(tmp_path, flat), gains=True, validate=_write(tmp_path, other, "v.csv"))
    assert cal.converged and not cal.ok
    moved, *worse = cal.identified.failures
    assert "reads up to" in moved and "away from the nominal over the workspace" in moved
    assert worse and all("validation: the calibrated model is worse than the nominal on the 20" in f for f in worse)
    # the verdict is the physics: against the true machine the calibrated model is worse than the nominal
    worse = truth_errors(truth.platform, cal.platform, val)["leg_length"]["rms"]
    assert worse > truth_errors(truth.platform, nominal, val)["leg_length"]["rms"]


def test_a_small_box_is_weakly_identified_but_a_good_model(tmp_path):
    """30 poses planned in ±20 mm, ±4°: condition ~1e4, single parameters mm off the truth, yet the model is
    within 5 % of the nominal's error over the whole workspace: ok, with the condition warning naming the weakest
    combination and the σ along it (σ_l / s_min: rows are whitened, then times σ_l)."""
    nominal = load_preset("utn-dynamic")
    plan = plan_measurements(nominal, 30, "pose", Box(0.02, 0.02, 0.015, np.radians(4)), NOISE, seed=0, candidates=300)
    data, truth = simulate_measurements(nominal, ERRORS, plan.poses, "pose", NOISE, seed=3)
    cal = calibrate(nominal, _write(tmp_path, data))
    ident = cal.identified.identifiability
    assert cal.ok and ident.condition > 1e3
    val = candidate_poses(nominal, Box.default(nominal), 200, seed=99)[:50]
    assert (
        truth_errors(truth.platform, cal.platform, val)["leg_length"]["rms"]
        < 0.05 * truth_errors(truth.platform, nominal, val)["leg_length"]["rms"]
    )
    (warning,) = [w for w in cal.identified.warnings if w.startswith("condition number")]
    name, s = ident.weak[0]
    assert s == ident.singular_values[-1] and f"the weakest [{name}] to σ {NOISE.length / s * 1e6:.3g} µm" in warning
    assert "judge the model by its validation" in warning


def test_the_planned_poses_warn_about_their_condition(utn):
    """Thirty planned poses on utn-dynamic: condition ~850, above the rule of ~100: the leg offsets trade with
    their base joints' z; the warning says so while the fit is ok."""
    nominal, _, data, _, _ = utn
    res = identify(nominal, data, NOISE)
    assert res.ok and res.identifiability.condition > 100
    (warning,) = [w for w in res.warnings if w.startswith("condition number")]
    assert "offset" in res.identifiability.weak[0][0] and res.identifiability.weak[0][0] in warning


def test_a_gross_outlier_is_isolated(utn):
    """One reading 5 mm off (5000 σ): the fit converges, names that line alone, and meets the validation target
    (15 µm RMS against the true machine, as without the outlier)."""
    nominal, _, data, truth, val = utn
    bad = data.subset(np.arange(30))
    bad.readings[7, 5] += 5e-3
    res = identify(nominal, bad, NOISE)
    assert res.converged, res.message
    assert [o["line"] for o in res.outliers] == [9]
    assert truth_errors(truth.platform, res.calibrated, val)["leg_length"]["rms"] < 15e-6


def test_the_misfit_ratio_is_over_the_poses_not_over_none(utn):
    """Readings paired with the wrong poses: every pose outlying; the ratio printed is the residuals' over all the
    poses (above MAX_CHI2_RATIO), not 0 from an empty set of inliers."""
    nominal, _, data, _, _ = utn
    shuffled = data.subset(np.arange(30))
    shuffled.readings[:] = data.readings[np.roll(np.arange(30), 1)]
    res = identify(nominal, shuffled, NOISE)
    assert not res.converged and len(res.outliers) == 30
    ratio = float(re.match(r"residuals (\S+) times the stated noise", res.message).group(1))
    assert ratio > MAX_CHI2_RATIO and ratio >= res.rms_sigma_after


def test_overstated_noise_warns():
    """Data with 1 µm sensors and a 10 µm tracker, stated as ten times noisier: the residuals fall below the
    χ² distribution's 1e-3 quantile; a warning, not a failure."""
    nominal = load_preset("utn-dynamic")
    plan = plan_measurements(nominal, 30, "pose", noise=NOISE, seed=0, candidates=400)
    data, _ = simulate_measurements(nominal, ERRORS, plan.poses, "pose", NOISE, seed=1)
    res = identify(nominal, data, Noise(10 * NOISE.length, 10 * NOISE.position, 10 * NOISE.angle))
    assert res.ok and any("smaller than the stated noise can give" in w for w in res.warnings)
    assert not any("smaller than the stated noise" in w for w in identify(nominal, data, NOISE).warnings)


@pytest.mark.parametrize("kind", ["pose", "inclinometer"])
def test_poses_the_nominal_cannot_assemble_do_not_refuse_the_file(tmp_path, kind):
    """60 random poses within ±20° on utn-kinematic: at a few of them the nominal geometry admits no assembly
    for the readings of the built machine (Newton's residual stays at ~0.1 mm); they are counted in the nominal's
    statistics, and the calibration is made and is ok. Inclinometer data start their poses there from the
    least-squares fit of the legs."""
    nominal = load_preset("utn-kinematic")
    rng = np.random.default_rng(0)
    q = nominal.home_pose() + np.concatenate([np.zeros((3000, 3)), rng.uniform(-1, 1, (3000, 3)) * np.radians(20)], 1)
    L = leg_lengths(nominal, q)
    keep = np.all((L > nominal.L_min) & (L < nominal.L_max), 1) & np.all(plate_anchors(nominal, q)[..., 2] > 5e-3, -1)
    n = 60 if kind == "pose" else 30  # the inclinometer's fit has 6 more unknowns per pose: fewer, for time
    data, _ = simulate_measurements(nominal, ERRORS, q[keep][:n], kind, NOISE, seed=1)
    cal = calibrate(nominal, _write(tmp_path, data), holdout=0.2 if kind == "pose" else None)
    unsolved = cal.identified.fit_before["unsolved"]
    assert cal.ok and unsolved["count"] >= 1 and set(unsolved["lines"]) <= set(cal.identified.lines.tolist())
    assert "unsolved" not in cal.identified.fit_after


def test_noise_free_data_calibrates_to_the_floor(tmp_path):
    """σ = 0 everywhere: the measurements are the true machine's exactly, the fit weighs them at NOISE_FLOOR,
    and every parameter comes out within 4.5 of its σ (what 1e-9 noise would give) of the truth."""
    nominal = load_preset("utn-dynamic")
    plan = plan_measurements(nominal, 30, "pose", noise=Noise(0.0, 0.0, 0.0), seed=0, candidates=400)
    data, truth = simulate_measurements(nominal, ERRORS, plan.poses, "pose", Noise(0.0, 0.0, 0.0), seed=1)
    cal = calibrate(nominal, _write(tmp_path, data), noise="length=0 position=0 angle=0urad")
    r = cal.identified
    assert cal.ok and r.noise.length == 0.0
    assert any(f"weighed as {NOISE_FLOOR:g}" in w for w in r.warnings)
    z = (r.theta - Layout(nominal, "pose").theta(truth.platform)) / r.sigma
    assert np.abs(z).max() < 4.5, z


def test_a_validation_worse_than_the_nominal_fails():
    """The rule on its own: a quantity's calibrated RMS above the nominal's by more than two standard errors of
    an RMS of its count fails; within them it does not (6 poses × 6 legs: 2/√72 = 24 %)."""

    def v(cal):
        stats = {"rms": 1.0, "max": 2.0, "unit": "m", "count": 36}
        return {"poses": 6, "nominal": {"leg_length": stats}, "calibrated": {"leg_length": {**stats, "rms": cal}}}

    assert validation_failures(v(1.2)) == []
    (f,) = validation_failures(v(1.3))
    assert "worse than the nominal on the 6 held-out poses (leg_length RMS 1e+06 → 1.3e+06 µm)" in f
