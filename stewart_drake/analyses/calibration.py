"""Kinematic calibration, the whole loop on the presets: plan 30 poses → simulate the measurements of a
machine built with ±1 mm joint errors and ±0.5 mm sensor offsets → identify → validate against the true
machine → regenerate the firmware from the calibrated file → the true machine held by the nominal vs the
calibrated firmware: the static plate error, the floors that bound it, and the word format that removes them."""

from __future__ import annotations

import numpy as np

from stewart_drake.calibration.identifiability import analyse, stacked
from stewart_drake.calibration.identify import identify
from stewart_drake.calibration.measurements import Measurements
from stewart_drake.calibration.model import Layout, Noise, make_problem, measure, pose_blocks, reduced_blocks
from stewart_drake.calibration.montecarlo import sigma_monte_carlo
from stewart_drake.calibration.plan import candidate_poses, plan_measurements
from stewart_drake.calibration.simulate import simulate_measurements
from stewart_drake.calibration.validate import truth_errors
from stewart_drake.control.gains import ControllerConfig
from stewart_drake.core.geometry import Platform, load_preset
from stewart_drake.core.newton_fk import forward_kinematics
from stewart_drake.firmware.generate import generate, offset_counts
from stewart_drake.fixedpoint.generic import QFormat, fixed_point_leg_lengths
from stewart_drake.montecarlo.spec import parse_spec
from stewart_drake.report import run_standalone

TITLE = "Calibration: measured poses → calibrated platform file → regenerated firmware"
ORDER = 97
COST = 3.7  # CPU seconds (full report, measured): the report's workers start the costliest first
PRESETS = ("utn-dynamic", "gonzalez-dutra-2009")
ERRORS = ["anchor=±1mm", "leg_offset=±0.5mm"]
NOISE = Noise(length=1e-6, position=10e-6, angle=20e-6)
POSES = 30
TARGET_RMS = 15e-6  # m, the target for leg length and plate position on validation poses
REDUCTION = 0.98
NEEDS = ()  # a user's machine: the calibration loop on its platform (and its firmware format, when given)


def static_hold(truth: Platform, firmware: Platform, poses, fmt: QFormat, resolution: float, convention: str = "utn"):
    """``(n,)`` plate position errors (m) of the true machine held at ``(n, 6)`` poses by a firmware built for
    ``firmware`` in the word format ``fmt`` with a sensor of ``resolution`` m per count.

    The controller's integral action drives each leg's error (set-point word × counts per LSB − measured
    counts) to zero, so at rest the sensors read the firmware's set-point minus its offset table: reading =
    (sp · cpl − offset_counts) · resolution (to within half a count, the sensor's own floor, not added here).
    The true machine's legs are then reading + its true offsets, and its plate sits where its forward
    kinematics puts it."""
    cpl = int(round(fmt.length_lsb / resolution))
    sp = fixed_point_leg_lengths(firmware, poses, fmt, convention, return_words=True)
    off = np.round(firmware.length_offset / resolution).astype(np.int64)
    reading = (sp * cpl - off) * resolution
    r = forward_kinematics(truth, truth.lengths_from_readings(reading), poses, convention, check_singularity=False)
    r.raise_if_failed()
    return np.linalg.norm(r.iterate[:, :3] - np.asarray(poses)[:, :3], axis=-1)


def _rms(x) -> float:
    return float(np.sqrt(np.mean(np.square(x))))


def build(section) -> None:
    import matplotlib.pyplot as plt

    laws = parse_spec(ERRORS).laws
    section.text(
        f"For each {'preset' if section.subject is None else 'platform'}: `stewart-drake plan-measurements --poses {POSES}` (D-optimal in the default box), "
        f"`simulate-measurements --errors {' '.join(ERRORS)} --noise length=1um position=10um angle=20urad --seed 1` "
        "(a laser tracker measuring the plate pose, 1 µm leg sensors), `calibrate`, then the identified platform "
        "against the true machine on 50 other poses of the workspace (noise-free: the model's own error). "
        "Unidentifiable parameters are computed from the data (SVD of the identification Jacobian), not assumed."
    )
    rows, fw_rows = [], []
    bars = {}
    subject = section.subject
    for nominal in [load_preset(name) for name in PRESETS] if subject is None else [subject.platform]:
        name = nominal.name
        plan = plan_measurements(nominal, POSES, "pose", noise=NOISE, seed=0, candidates=600 if section.quick else 1000)
        data, truth = simulate_measurements(nominal, laws, plan.poses, "pose", NOISE, seed=1)
        data_r, _ = simulate_measurements(nominal, laws, plan.random, "pose", NOISE, seed=1, truth=truth.platform)
        res = identify(nominal, data, NOISE)
        res_r = identify(nominal, data_r, NOISE)
        val = candidate_poses(nominal, plan.box, 200, seed=99)[:50]
        e0 = truth_errors(truth.platform, nominal, val)
        e1 = truth_errors(truth.platform, res.calibrated, val)
        er = truth_errors(truth.platform, res_r.calibrated, val)
        section.check(f"{name}: identification converged", 0 if res.converged else 1, 0)
        for key in ("leg_length", "position"):
            section.check(
                f"{name}: validation {key} RMS, calibrated (µm)", e1[key]["rms"] * 1e6, TARGET_RMS * 1e6, "µm"
            )
            section.check(
                f"{name}: validation {key} RMS, fraction of the nominal's left",
                e1[key]["rms"] / e0[key]["rms"],
                1 - REDUCTION,
            )
        section.check(
            f"{name}: random poses' D-index over the planned poses' (planned beats random)",
            plan.baseline.d_index / plan.planned.d_index,
            1.0,
        )
        rows.append(
            [
                name,
                f"{plan.planned.d_index:.3g} / {plan.baseline.d_index:.3g}",
                f"{plan.planned.noise_amplification:.3g} / {plan.baseline.noise_amplification:.3g}",
                f"{plan.planned.condition:.3g} / {plan.baseline.condition:.3g}",
                f"{e0['leg_length']['rms'] * 1e6:.0f} → {e1['leg_length']['rms'] * 1e6:.2f} ({er['leg_length']['rms'] * 1e6:.2f})",
                f"{e0['position']['rms'] * 1e6:.0f} → {e1['position']['rms'] * 1e6:.2f} ({er['position']['rms'] * 1e6:.2f})",
                f"{res.rms_sigma_before:.3g} → {res.rms_sigma_after:.3g}",
            ]
        )
        # -- the firmware: regenerated from the calibrated platform, the true machine held at the validation poses
        config = ControllerConfig.for_platform(res.calibrated)
        g = generate(res.calibrated, config)
        text = g.files["sd_firmware.c"]
        section.check(
            f"{name}: the calibrated firmware's offset table equals legs.length_offset in counts (legs differing)",
            0 if f"{{{', '.join(str(int(v)) for v in offset_counts(res.calibrated, config))}}}" in text else 6,
            0,
        )
        hold = val[:20]
        res_m = config.timing.sensor_resolution
        lsb16 = float(np.ceil(nominal.L_max / 32767 / res_m) * res_m)  # the finest LSB whose 16-bit words hold L_max
        formats = [
            ("16-bit, 1 mm LSB (the DSP default)", QFormat(16, 1e-3, "exact"), res_m),
            (f"16-bit, {lsb16 * 1e6:.0f} µm LSB (finest 16-bit)", QFormat(16, lsb16, "exact"), res_m),
            ("24-bit, 1 µm LSB, 1 µm sensor (emulation)", QFormat(24, 1e-6, "exact"), 1e-6),
        ]
        if subject is not None and subject.ik_format is not None:
            f = subject.ik_format
            formats.append(
                (f"{f.word_bits}-bit, {f.length_lsb * 1e6:g} µm LSB, {f.trig} (the machine file's)", f, res_m)
            )
        for label, fmt, res_s in formats:
            en = static_hold(truth.platform, nominal, hold, fmt, res_s)
            ec = static_hold(truth.platform, res.calibrated, hold, fmt, res_s)
            fw_rows.append(
                [name, label, f"{_rms(en) * 1e6:.1f}", f"{_rms(ec) * 1e6:.2f}", f"{_rms(en) / _rms(ec):.1f}×"]
            )
            bars[(name, label)] = (_rms(en), _rms(ec))
        en, ec = bars[(name, formats[1][0])]
        section.check(
            f"{name}: static plate error, calibrated over nominal firmware, finest 16-bit LSB (≤ 1/5)", ec / en, 0.2
        )
        if name == "utn-dynamic":  # the calibration's own Monte Carlo: σ against the spread over noise draws
            draws = 8 if section.quick else 12
            mc = sigma_monte_carlo(nominal, truth.platform, plan.poses, "pose", NOISE, draws=draws, seed=100).to_dict()
            section.check(
                f"{name}: Monte Carlo of the identification ({draws} noise draws): mean σ_MC/σ − 1 over the "
                f"parameters (each ratio's standard error {mc['standard_error']:.0%})",
                abs(mc["mean_ratio"] - 1),
                0.2,
            )
            section.text(
                f"The reported σ against a Monte Carlo of the identification on {name} ({draws} noise draws, same "
                f"machine and poses): σ_MC/σ is {mc['mean_ratio']:.2f} on average over the {len(mc['ratio'])} "
                f"parameters, at most {mc['max_abs_deviation']:.0%} off for one (a sample σ from {draws} draws is "
                f"uncertain by {mc['standard_error']:.0%}); the Mahalanobis distances average "
                f"{mc['mahalanobis_ratio']:.2f} × their expectation. tests/calibration/test_identify.py runs 40 draws."
            )
        # identifiability: what inclinometer data and pure translations cannot see
        if name == "gonzalez-dutra-2009":
            _identifiability_demo(section, nominal, plan.poses)
    section.table(
        [
            "platform",
            "D-index planned / random",
            "noise ampl. planned / random",
            "condition planned / random",
            "leg length RMS µm: nominal → calibrated (random poses)",
            "plate position RMS µm: nominal → calibrated (random poses)",
            "residual RMS in σ",
        ],
        rows,
        caption=f"{POSES} planned pose measurements; validation on 50 other poses against the true machine",
    )
    section.table(
        ["platform", "firmware word format", "nominal firmware µm", "calibrated firmware µm", "ratio"],
        fw_rows,
        caption="Static plate position error (RMS over 20 held poses) of the true machine under each firmware",
    )
    section.text(
        "The firmware's floors. With the DSP's default 1 mm length LSB the set-points are rounded to ±0.5 mm per leg, "
        "which the inverse kinematics amplifies into millimetres at the plate: larger than the geometric errors, so the "
        "calibrated constants change nothing (ratio ≈ 1) — the LSB is the floor. The finest LSB whose 16-bit words "
        "still hold the longest leg (L_max / 2¹⁵, rounded up to a whole number of 10 µm sensor counts: 30 µm, "
        "`stewart-drake firmware generate --platform calibrated.yaml --length-lsb 3e-5`) gives the calibrated firmware "
        "the ≥ 5× gain; what remains is the 16-bit rotation entries and angle words (π/2¹⁵ rad ≈ 96 µrad) and the "
        "30 µm rounding. 24-bit words with a 1 µm LSB and a 1 µm sensor (the emulation; the generator emits 16-bit "
        "words) leave only the calibration's own error. The static error is the loop's equilibrium: the integral "
        "action holds each sensor at the firmware's set-point minus its offset table (to within one count), and the "
        "true machine's forward kinematics of those legs places the plate; tests/drake/test_calibration_closed_loop.py "
        "checks it against the Drake closed loop (the true machine as the plant, a 3 s hold: equal to 10 % + 20 µm)."
    )
    fig, ax = plt.subplots(figsize=(8, 3.6))
    labels = [f"{n}\n{lbl.split(' (')[0]}" for (n, lbl) in bars]
    x = np.arange(len(bars))
    ax.bar(x - 0.2, [v[0] * 1e6 for v in bars.values()], 0.4, label="nominal firmware", color="tab:red")
    ax.bar(x + 0.2, [v[1] * 1e6 for v in bars.values()], 0.4, label="calibrated firmware", color="tab:blue")
    ax.set_yscale("log")
    ax.set_xticks(x, labels, fontsize=6)
    ax.set_ylabel("static plate position error, RMS µm")
    ax.set_xlabel("platform and firmware word format")
    ax.legend(fontsize=8)
    fig.tight_layout()
    section.figure(fig, "calibration_firmware", "The true machine held by the nominal and the calibrated firmware")


def _identifiability_demo(section, nominal: Platform, poses) -> None:
    """Inclinometer data and pure-translation pose data on the 6-6: what the SVD says they cannot fix."""
    found = {}
    for kind, q in (("inclinometer", poses), ("pose", np.c_[poses[:, :3], np.zeros((len(poses), 3))])):
        m = measure(nominal, q)
        data = Measurements(
            kind,
            m["readings"],
            q if kind == "pose" else None,
            None,
            m["tilts"] if kind == "inclinometer" else None,
            np.ones(len(q)),
            np.arange(2, len(q) + 2),
        )
        layout = Layout(nominal, kind)
        problem = make_problem(layout, data, NOISE)
        theta = layout.theta(nominal)
        found[kind] = analyse(layout, stacked(reduced_blocks(*pose_blocks(problem, theta)), NOISE.length), theta)
    inc, tr = found["inclinometer"], found["pose"]
    section.check(
        "gonzalez-dutra-2009, inclinometer data: frame freedoms named (base x, y, z, yaw; plate x, y, z) (missing)",
        7 - len(inc.frame_freedoms),
        0,
    )
    section.check(
        "gonzalez-dutra-2009, pose data of pure translations: unidentifiable combinations (18 = 6 legs × 3: b_i − R t_i)",
        abs(len(tr.fixed) - 18),
        0,
    )
    section.text(
        f"Inclinometer data (two tilts, no external instrument) on gonzalez-dutra-2009: {len(inc.fixed)} combinations "
        f"cannot be identified: {', '.join(inc.frame_freedoms)}; held at nominal by fixing "
        f"{', '.join(inc.names[i] for i in inc.fixed)}. Pose data where every pose has the same orientation: "
        f"{len(tr.fixed)} combinations lost (each leg's base and plate joint move together: only b_i − R t_i is seen), "
        f"e.g. {tr.combinations[0]}."
    )


def main(argv=None):
    return run_standalone(__file__, argv)


if __name__ == "__main__":
    raise SystemExit(main())
