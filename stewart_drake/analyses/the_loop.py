"""The loop as a control engineer sees it: the actuators as the machine states them, the margins of the closed leg
loop at a grid of poses over the workspace box (``sd.loop_response``, the gains the machine runs its motion with),
Bode plots at the worst pose with points measured on the nonlinear Drake loop (float law and fixed-point law at a
fine format), the simulated force ripple against the length LSB with the chatter limit, and the chosen gains and
format confirmed on the motion with the real firmware in the loop. On the presets: margins on each, the rest on
utn-dynamic; on a user's machine (``report.subject``) all of it on that machine.

The actuators' rows (``actuator_rows``) list a screw's or a cylinder's parameters; the ripple figure shows the
linear loop's prediction (``predicted_ripple``, ``control.ripple``) beside the simulated ripple.
"""

from __future__ import annotations

import math
from dataclasses import fields, replace

import numpy as np

from stewart_drake.api.response import loop_response
from stewart_drake.api.simulation import plan_run
from stewart_drake.api.tune import loop_spec
from stewart_drake.control.chatter import CHATTER_RANGE_FRACTION, chatter_measure
from stewart_drake.control.frequency import MIN_GAIN_MARGIN_DB, MIN_PHASE_MARGIN_DEG, effective_gains
from stewart_drake.control.ripple import quantisation_ripple
from stewart_drake.control.verdict import run_verdict
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.core.trajectory import SEED, fit_trajectory
from stewart_drake.drake.simulation import build_simulation
from stewart_drake.firmware.certify.box import workspace_box
from stewart_drake.report import parallel_map, run_standalone
from stewart_drake.report.subject import machine_of, subject_trajectories
from stewart_drake.spec import Gains, Machine, load_machine

TITLE = "The loop: actuators, margins across the workspace, frequency response and quantisation"
ORDER = 91
COST = 22  # CPU seconds (full report, measured): the report's workers start the costliest first
NEEDS = ("plate", "legs.max_force")  # a user's machine: its plate is the plant, legs.max_force the command range

PLATFORM = "utn-dynamic"  # the preset studied in full
PRESETS = ("utn-dynamic", "utn-kinematic", "gonzalez-dutra-2009")  # the margins across the workspace of each
AXES = ("x", "y", "z", "α", "β", "γ")
LAWS = ("float", "fixed")  # the measured responses: the float law and the fixed-point firmware at the fine format
# the measured points: log-spaced from MEASURE_LOW Hz to MEASURE_HIGH of the Nyquist frequency (where the
# response has fallen far enough that the sine's command limit leaves a measurable amplitude)
MEASURE_LOW, MEASURE_HIGH = 1.0, 0.4
WORD_BITS = 16  # the fine format's words: the generated C's (wider words would run the slow Python engine)
# the length LSBs of the ripple sweep besides the machine's own and the fine one (m)
RIPPLE_LSBS = (1e-4, 3e-4, 1e-3)


def _sizes(quick: bool) -> dict:
    """The section's bounded work: measured frequencies per law, ripple runs' and confirmation run's seconds,
    whether the grid has all 13 poses (quick: the box's centre and its z faces)."""
    if quick:
        return {"measured": 3, "ripple_s": 0.2, "confirm_s": 0.3, "full_grid": False}
    return {"measured": 10, "ripple_s": 1.0, "confirm_s": 4.0, "full_grid": True}


def pose_grid(platform, full: bool = True) -> tuple[list[str], np.ndarray]:
    """``(names, (n, 6) poses)``: the centre of the workspace box (``firmware.certify.box.workspace_box``: the
    preset's stated box, else home ± 10 % of the stroke range and ±15°) and, with ``full``, the centres of its 12
    faces (one coordinate at an end of its range, the others at the centre; without: z only), keeping the poses whose
    legs are within the stroke."""
    box = workspace_box(platform)
    centre, half = (box.lo + box.hi) / 2, (box.hi - box.lo) / 2
    names, poses = ["centre"], [centre]
    for k in range(6) if full else (2,):
        for sign, mark in ((-1, "−"), (1, "+")):
            names.append(f"{AXES[k]}{mark}")
            poses.append(centre + sign * half[k] * np.eye(6)[k])
    L = leg_lengths(platform, np.array(poses))
    keep = np.all((L >= platform.L_min) & (L <= platform.L_max), axis=1)
    return [n for n, k in zip(names, keep) if k], np.array(poses)[keep]


def motion(machine: Machine, subject=None):
    """The motion whose gains the loop runs with: the subject's first motion, or the seed trajectory fitted to the
    preset."""
    if subject is not None:
        return subject_trajectories(subject)[0]
    return fit_trajectory(SEED, machine.loaded_platform)


def chosen_machine(machine: Machine, traj) -> Machine:
    """``machine`` with explicit gains: those designed for it over ``traj``'s poses (what a run of that motion
    uses), so that every pose of the grid is studied with the same controller; ``run.fit`` off (``traj`` is fitted
    already, and a held pose of the grid is not to be moved).

    The section judges these, the gains the machine runs with; ``stewart-drake tune`` designs gains for the whole
    box (``api.tune``), and a machine file that holds them is studied with them."""
    machine = replace(machine, run=replace(machine.run, fit=False))
    g = plan_run(machine, traj, checks=False, command="report").config.gains
    return replace(machine, controller=replace(machine.controller, gains=Gains(g.kp, g.ki, g.kd, g.kv)))


def fine_lsb(machine: Machine) -> float:
    """The finest length LSB (m) whose ``WORD_BITS`` words hold the stroke's end, a whole number of sensor counts."""
    r = machine.sensors.resolution
    return r * math.ceil(machine.loaded_platform.L_max / (2 ** (WORD_BITS - 1) - 1) / r * (1 - 1e-12))


def with_lsb(machine: Machine, lsb: float) -> Machine:
    """``machine``'s fixed-point IK in ``WORD_BITS`` words of length LSB ``lsb`` (m)."""
    return replace(machine, firmware=replace(machine.firmware, word_bits=WORD_BITS, length_lsb=lsb))


def workspace_margins(machine: Machine, full: bool = True) -> list[dict]:
    """The loop's margins at each pose of ``pose_grid``: ``{"pose": name, "q": (6,), "gm": dB, "pm": deg,
    "bandwidth": Hz or None, "peak": sensitivity peak, "rho": spectral radius}`` (``sd.loop_response``: the
    smallest margins over the six legs)."""
    names, poses = pose_grid(machine.loaded_platform, full)
    rows = []
    for name, q in zip(names, poses):
        r = loop_response(machine, q)
        rows.append(
            {
                "pose": name,
                "q": q,
                "gm": min(m["gain_margin_db"] for m in r.margins),
                "pm": min(m["phase_margin_deg"] for m in r.margins),
                "bandwidth": r.bandwidth_hz,
                "peak": r.sensitivity_peak,
                "rho": r.spectral_radius,
            }
        )
    return rows


def worst(rows: list[dict]) -> dict | None:
    """The grid's worst pose where the loop is stable (an unstable loop has no steady response to measure): the
    largest sensitivity peak (the loop's least distance from instability); None when it is stable nowhere."""
    stable = [r for r in rows if r["rho"] < 1]
    return max(stable, key=lambda r: r["peak"]) if stable else None


def measured_response(machine: Machine, pose, law: str, count: int):
    """``sd.loop_response`` at ``pose`` with ``count`` points measured on the nonlinear Drake loop (leg 1) under
    ``law`` (``float``, or ``fixed`` at the fine format)."""
    m = with_lsb(machine, fine_lsb(machine)) if law == "fixed" else machine
    m = replace(m, controller=replace(m.controller, law=law))
    nyquist = 0.5 / m.controller.period
    freqs = np.logspace(math.log10(MEASURE_LOW), math.log10(MEASURE_HIGH * nyquist), count)
    return loop_response(m, pose, measure=freqs)


def ripple_lsbs(machine: Machine) -> list[float]:
    """The ripple sweep's length LSBs (m): the fine one, ``RIPPLE_LSBS`` and the machine's own, ascending, each one
    whose ``WORD_BITS`` words hold the stroke."""
    fine = fine_lsb(machine)
    return sorted({fine, *(x for x in (*RIPPLE_LSBS, machine.firmware.length_lsb) if x >= fine)})


def fixed_run(machine: Machine, traj, duration: float, lsb: float | None = None) -> dict:
    """The fixed-point loop (the firmware) of ``machine`` along ``traj`` for ``duration`` s, its IK in
    ``WORD_BITS`` words of length LSB ``lsb`` (m; None: the machine's own format): ``{"lsb", "ripple" N (largest
    leg's RMS force about the quasi-static force), "ratio" (ripple / working force), "error" m (max |leg length −
    IK(reference)|), "failures"}`` (``control.verdict.run_verdict``)."""
    m = machine if lsb is None else with_lsb(machine, lsb)
    m = replace(m, controller=replace(m.controller, law="fixed"))
    plan = plan_run(m, traj, duration=duration, checks=False, command="report")
    sc = plan.scenario
    log = build_simulation(sc).run(duration)
    e = log.length_error(sc.trajectory, sc.platform)
    verdict, _ = run_verdict(sc.platform, sc.platform, sc.trajectory, log, sc.config, e, log.pose_error(sc.trajectory))
    chat = chatter_measure(sc.platform, sc.trajectory, log, sc.config)
    return {
        "lsb": m.firmware.length_lsb,
        "ripple": max(chat["force_ripple_N"]),
        "ratio": chat["chatter_ratio"],
        "error": float(np.abs(e).max()),
        "failures": list(verdict["failures"]),
    }


def predicted_ripple(machine: Machine, traj, lsbs) -> np.ndarray:
    """The ripple (N, the largest leg's RMS) the linear loop predicts at each length LSB of ``lsbs`` (m): the
    white-noise estimate of ``control.ripple`` (its three quantisers through the loop at ``traj``'s first pose,
    with the gains the fixed law applies), beside the simulated ripple."""
    out = []
    for lsb in lsbs:
        m = with_lsb(machine, lsb)
        plan = plan_run(replace(m, controller=replace(m.controller, law="fixed")), traj, checks=False, command="report")
        sc = plan.scenario
        model = loop_spec(plan).model(sc.platform, sc.trajectory.pose(0.0), effective_gains("fixed", sc.config))
        out.append(quantisation_ripple(model, lsb, plan.timing.sensor_resolution, plan.timing.command_range).rms_N)
    return np.array(out)


# the units of the screw's and the cylinder's parameters (``design.screw``, ``design.hydraulic``: SI)
PARAMETER_UNITS = {
    "lead": "m/rev",
    "torque_constant": "N·m/A",
    "rotor_inertia": "kg·m²",
    "coulomb_friction": "N",
    "viscous_friction": "N·s/m",
    "max_current": "A",
    "rated_current": "A",
    "max_motor_speed": "rad/s",
    "current_time_constant": "s",
    "winding_resistance": "Ω",
    "encoder_counts": "/rev",
    "piston_area": "m²",
    "rod_area": "m²",
    "dead_volume": "m³",
    "stroke": "m",
    "bulk_modulus": "Pa",
    "supply_pressure": "Pa",
    "return_pressure": "Pa",
    "valve_flow_gain": "m³/(s·√Pa)",
    "valve_time_constant": "s",
    "leakage": "m³/(s·Pa)",
    "force_gain": "1/N",
}


def actuator_rows(machine: Machine) -> list[list]:
    """The actuators as the machine states them: ``[[quantity, value, unit, where it is set]]``; for a screw or
    hydraulic model one row per parameter (SI), set in the file or its stated default (``design.screw``,
    ``design.hydraulic``)."""
    a = machine.actuators
    full_scale = machine.loaded_platform.legs.max_force
    command = ["the command's full scale (Q15)", full_scale, "N", "legs.max_force"]
    if a.model in ("screw", "hydraulic"):
        params = a.screw(full_scale) if a.model == "screw" else a.hydraulic(machine.platform)
        title = "servo motor on a screw" if a.model == "screw" else "servo valve and differential cylinder"
        rows = [["model", title, "", "actuators.model"]]
        for f in fields(params):
            given = getattr(a, f.name, None) is not None
            rows.append(
                [f.name.replace("_", " "), getattr(params, f.name), "SI", f"actuators.{f.name}" if given else "default"]
            )
        return [*rows, command]
    limit, where = (a.max_force, "actuators.max_force") if a.max_force is not None else (full_scale, "legs.max_force")
    return [
        ["model", "first-order lag with a force limit", "", "the default"],
        ["time constant τ", a.time_constant * 1e3, "ms", "actuators.time_constant"],
        ["force limit", limit, "N", where],
        command,
    ]


# --- the heavy cases (``report.parts``) ----------------------------------------------------------------------


def _study_machine(name: str) -> tuple[Machine, object]:
    """A preset's machine with the gains of its motion, and the motion."""
    m = load_machine(name)
    traj = motion(m)
    return chosen_machine(m, traj), traj


_MARGINS: dict = {}  # a preset's grid per process: the measured parts need its worst pose (computed once)


def _margins_part(item):
    if item not in _MARGINS:
        name, full = item
        _MARGINS[item] = workspace_margins(_study_machine(name)[0], full)
    return _MARGINS[item]


def _measure_part(item):
    name, full, law, count = item
    w = worst(_margins_part((name, full)))
    return None if w is None else measured_response(_study_machine(name)[0], w["q"], law, count)


def _measure_items(quick: bool) -> list[tuple]:
    s = _sizes(quick)
    return [(PLATFORM, s["full_grid"], law, s["measured"]) for law in LAWS]


def _run_part(item):
    name, duration, lsb = item
    m, traj = _study_machine(name)
    return fixed_run(m, traj, duration, lsb)


def _run_items(name: str, quick: bool) -> list[tuple]:
    s = _sizes(quick)
    items = [(name, s["ripple_s"], lsb) for lsb in ripple_lsbs(load_machine(name))]
    return items + [(name, s["confirm_s"], None)]


def parts(quick: bool) -> list[tuple[str, tuple]]:
    """The independent heavy cases: each preset's margins over the grid, utn-dynamic's measured responses and its
    fixed-point runs."""
    full = _sizes(quick)["full_grid"]
    out = [("_margins_part", (n, full)) for n in PRESETS]
    out += [("_measure_part", it) for it in _measure_items(quick)]
    return out + [("_run_part", it) for it in _run_items(PLATFORM, quick)]


# --- the section ---------------------------------------------------------------------------------------------


def _fmt(x, digits: str = ".1f") -> str:
    return "—" if x is None else ("∞" if math.isinf(x) else format(x, digits))


def margin_checks(section, label: str, rows: list[dict]) -> None:
    """The 6 dB / 30° rule over the grid (checks of the shortfall: minimum − margin ≤ 0), and stability."""
    g, p = min(rows, key=lambda r: r["gm"]), min(rows, key=lambda r: r["pm"])
    rho = max(rows, key=lambda r: r["rho"])
    n = len(rows)
    section.check(
        f"{label}: loop stable at the grid's {n} poses (largest closed-loop pole |z|, at {rho['pose']})",
        rho["rho"],
        1.0,
    )
    section.check(
        f"{label}: gain margin ≥ {MIN_GAIN_MARGIN_DB:g} dB at the grid's {n} poses (shown: the minimum − the "
        f"smallest margin, {_fmt(g['gm'], '.2f')} dB at {g['pose']})",
        MIN_GAIN_MARGIN_DB - g["gm"],
        0.0,
        "dB",
    )
    section.check(
        f"{label}: phase margin ≥ {MIN_PHASE_MARGIN_DEG:g}° at the grid's {n} poses (shown: the minimum − the "
        f"smallest margin, {_fmt(p['pm'])}° at {p['pose']})",
        MIN_PHASE_MARGIN_DEG - p["pm"],
        0.0,
        "deg",
    )


def margins_figure(results: dict):
    """Gain and phase margin at each grid pose, per machine (``{name: workspace_margins rows}``), with the minimums."""
    import matplotlib.pyplot as plt  # deferred: pyplot is loaded when a figure is drawn

    fig, (ax_g, ax_p) = plt.subplots(1, 2, figsize=(11, 3.6), layout="constrained")
    names = list(dict.fromkeys(r["pose"] for rows in results.values() for r in rows))  # a machine may lack a pose
    label = "unstable there (its margins say nothing)"
    for name, rows in results.items():
        x = [names.index(r["pose"]) for r in rows]
        gm, pm = [min(r["gm"], 40.0) for r in rows], [min(r["pm"], 120.0) for r in rows]
        ax_g.plot(x, gm, "o-", label=name)
        ax_p.plot(x, pm, "o-", label=name)
        bad = [k for k, r in enumerate(rows) if not r["rho"] < 1]
        if bad:
            ax_g.plot([x[k] for k in bad], [gm[k] for k in bad], "rx", ms=10, mew=2, label=label)
            ax_p.plot([x[k] for k in bad], [pm[k] for k in bad], "rx", ms=10, mew=2)
            label = None  # once in the legend
    for ax, level, unit in ((ax_g, MIN_GAIN_MARGIN_DB, "dB"), (ax_p, MIN_PHASE_MARGIN_DEG, "deg")):
        ax.axhline(level, color="r", ls="--", lw=1, label=f"minimum {level:g} {unit}")
        ax.set_xticks(range(len(names)), names, fontsize=8)
        ax.set_xlabel("pose of the workspace box (centre, face centres)")
        ax.grid(True, alpha=0.3)
    ax_g.set_ylabel("gain margin [dB]")
    ax_p.set_ylabel("phase margin [deg]")
    ax_g.legend(fontsize=7)
    return fig


def bode_figure(responses: dict, pose_name: str):
    """Bode plots at the worst pose (``{law: LoopResponse}``): leg 1's set-point response (left) and the Cartesian
    response's diagonal (right), the linear model as lines and the nonlinear loop's measured points as dots."""
    import matplotlib.pyplot as plt  # deferred: pyplot is loaded when a figure is drawn

    fig, axes = plt.subplots(2, 2, figsize=(11, 6), sharex=True, layout="constrained")
    for k, (law, r) in enumerate(responses.items()):
        f, style = r.frequencies, ("-", "--")[k % 2]
        h = r.setpoint[:, 0, 0]
        phase = np.degrees(np.unwrap(np.angle(h)))
        axes[0, 0].semilogx(f, 20 * np.log10(np.abs(h)), style, color=f"C{k}", label=f"{law} law, linear model")
        axes[1, 0].semilogx(f, phase, style, color=f"C{k}")
        for p in r.measured:
            m = p.response[p.leg]
            ph = np.degrees(np.angle(m))
            ph += 360.0 * np.round((np.interp(np.log(p.freq), np.log(f), phase) - ph) / 360.0)  # the line's branch
            axes[0, 0].semilogx([p.freq], [20 * np.log10(abs(m))], "o", color=f"C{k}", mfc="none", ms=6)
            axes[1, 0].semilogx([p.freq], [ph], "o", color=f"C{k}", mfc="none", ms=6)
        if k == 0:
            for i in range(6):
                c = r.cartesian[:, i, i]
                axes[0, 1].semilogx(f, 20 * np.log10(np.abs(c)), lw=1, label=AXES[i])
                axes[1, 1].semilogx(f, np.degrees(np.unwrap(np.angle(c))), lw=1)
            axes[0, 1].set_title(f"Cartesian, pose per pose reference ({law} law)", fontsize=9)
    axes[0, 0].plot([], [], "ko", mfc="none", label="measured, nonlinear Drake loop")
    axes[0, 0].set_title(f"leg 1 per leg-1 set-point, pose {pose_name}", fontsize=9)
    axes[0, 0].legend(fontsize=7)
    axes[0, 1].legend(fontsize=7, ncol=3)
    for ax in axes[0]:
        ax.set_ylabel("magnitude [dB]")
    for ax in axes[1]:
        ax.set_ylabel("phase [deg]")
        ax.set_xlabel("frequency [Hz]")
    for ax in axes.flat:
        ax.grid(True, which="both", alpha=0.3)
    return fig


def ripple_figure(runs: list[dict], limit: float, predicted=None):
    """Simulated force ripple against the length LSB, the chatter limit, and the predicted ripple where given."""
    import matplotlib.pyplot as plt  # deferred: pyplot is loaded when a figure is drawn

    fig, ax = plt.subplots(figsize=(6.5, 3.8), layout="constrained")
    lsb = np.array([r["lsb"] for r in runs]) * 1e6
    ax.loglog(lsb, [r["ripple"] for r in runs], "o-", label="simulated (fixed-point firmware, Drake plant)")
    if predicted is not None:
        ax.loglog(lsb, predicted, "s--", label="predicted (control/ripple.py)")
    ax.axhline(limit, color="r", ls="--", lw=1, label=f"chatter limit {CHATTER_RANGE_FRACTION:g} × command range")
    ax.set_xlabel("length LSB [µm]")
    ax.set_ylabel("force ripple, largest leg [N RMS]")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    return fig


def _actuators(section, machine: Machine) -> None:
    section.table(
        ["quantity", "value", "unit", "set by"],
        actuator_rows(machine),
        caption=f"{machine.loaded_platform.name}: the actuators as the machine states them",
    )


def _margins(section, results: dict, studied: str, full: bool) -> None:
    """The margins table of the studied machine, one summary row per machine, their checks and figure."""
    rows = results[studied]
    section.table(
        ["pose", "pose (mm, deg)", "gain margin dB", "phase margin deg", "bandwidth Hz", "sensitivity peak", "|z| max"],
        [
            [
                r["pose"],
                " ".join(f"{v:.0f}" for v in np.r_[r["q"][:3] * 1e3, np.degrees(r["q"][3:])]),
                r["gm"],
                r["pm"],
                np.nan if r["bandwidth"] is None else r["bandwidth"],
                r["peak"],
                r["rho"],
            ]
            for r in rows
        ],
        caption=f"{studied}: the loop at each pose of the grid (smallest margin over the six legs, each broken at "
        "its command with the others closed; bandwidth: the legs' own −3 dB; sensitivity peak: the largest singular "
        "value of S; |z| max: the largest closed-loop pole, ≥ 1 unstable, where the margins say nothing)",
        nan_reason="above the Nyquist frequency",
    )
    summary = []
    for name, rs in results.items():
        g, p = min(rs, key=lambda r: r["gm"]), min(rs, key=lambda r: r["pm"])
        bws = [r["bandwidth"] for r in rs if r["bandwidth"] is not None]
        peak = max(r["peak"] for r in rs)
        summary.append([name, len(rs), g["gm"], g["pose"], p["pm"], p["pose"], min(bws) if bws else np.nan, peak])
        margin_checks(section, name, rs)
    section.table(
        ["machine", "poses", "least GM dB", "at", "least PM deg", "at", "least bandwidth Hz", "worst peak"],
        summary,
        caption=f"Margins across the workspace box (minimums {MIN_GAIN_MARGIN_DB:g} dB, {MIN_PHASE_MARGIN_DEG:g}°)",
        nan_reason="above the Nyquist frequency",
    )
    grid = "the centre of the workspace box and the centres of its 12 faces" if full else "the box's centre and z faces"
    section.figure(
        margins_figure(results),
        "loop_margins",
        f"Gain and phase margins at {grid} (poses outside the stroke dropped; margins above the plot are clipped).",
    )


def bode_responses(machine: Machine, row: dict, count: int) -> dict:
    """``{law: measured_response}`` at the grid row ``row``'s pose, the float law and the fine fixed-point law."""
    return {law: measured_response(machine, row["q"], law, count) for law in LAWS}


def _bode(section, machine: Machine, row: dict, responses: dict) -> None:
    """The measured Bode plots at the worst stable pose (``bode_responses``) and their agreement checks."""
    for law, r in responses.items():
        if not r.measured:
            section.text(f"{law} law at {row['pose']}: the loop is unstable there, no steady response to measure.")
            continue
        ratio = max(float(abs(p.response[p.leg] - p.linear[p.leg]) / p.tolerance[p.leg]) for p in r.measured)
        fmt = f" at the fine format ({fine_lsb(machine) * 1e6:g} µm, {WORD_BITS}-bit)" if law == "fixed" else ""
        section.check(
            f"{machine.loaded_platform.name}, {law} law{fmt}: nonlinear Drake loop against the linear model at "
            f"{len(r.measured)} frequencies, pose {row['pose']} (|measured − linear| / stated tolerance, worst)",
            ratio,
            1.0,
        )
    section.figure(
        bode_figure(responses, row["pose"]),
        "loop_bode",
        f"Bode plots at the worst stable pose ({row['pose']}, sensitivity peak {row['peak']:.2f}): lines the linear model, "
        "circles the response measured on the nonlinear Drake loop with a set-point sine on leg 1 (float law; "
        f"fixed-point firmware at {fine_lsb(machine) * 1e6:g} µm).",
    )


def _ripple(section, machine: Machine, traj, runs: list[dict]) -> None:
    limit = CHATTER_RANGE_FRACTION * machine.loaded_platform.legs.max_force
    lsbs = [r["lsb"] for r in runs]
    predicted = predicted_ripple(machine, traj, lsbs)
    section.table(
        [
            "length LSB µm",
            "force ripple N RMS",
            "predicted N RMS",
            "ripple / working force",
            "max |leg error| mm",
            "verdict",
        ],
        [
            [r["lsb"] * 1e6, r["ripple"], p, r["ratio"], r["error"] * 1e3, "; ".join(r["failures"]) or "passes"]
            for r, p in zip(runs, predicted)
        ],
        caption=f"The fixed-point firmware at each length LSB ({WORD_BITS}-bit words, the same gains), chatter limit "
        f"{limit:g} N",
    )
    section.figure(
        ripple_figure(runs, limit, predicted),
        "loop_ripple",
        "Force ripple (RMS of the actuator force about the quasi-static force, the largest leg) against the IK's "
        "length LSB, with the chatter limit and the linear loop's prediction (control.ripple's white-noise estimate).",
    )


def _confirm(section, machine: Machine, run: dict, duration: float) -> None:
    g, fw = machine.controller.gains, machine.firmware
    limit = CHATTER_RANGE_FRACTION * machine.loaded_platform.legs.max_force
    section.table(
        ["kp N/m", "ki N/(m·s)", "kd N·s/m", "kv N·s/m", "word bits", "length LSB µm", "trig"],
        [[g.kp, g.ki, g.kd, g.kv, fw.word_bits, fw.length_lsb * 1e6, fw.trig]],
        caption="The chosen gains (designed over the motion's poses) and the machine's format",
    )
    name = machine.loaded_platform.name
    section.check(
        f"{name}: time-domain confirmation, force ripple ≤ chatter limit ({duration:g} s of the motion, the "
        f"firmware at {fw.length_lsb * 1e6:g} µm; max |leg error| {run['error'] * 1e3:.3f} mm)",
        run["ripple"],
        limit,
        "N",
    )
    section.check(
        f"{name}: time-domain confirmation, the run's verdict failures ({'; '.join(run['failures']) or 'none'})",
        len(run["failures"]),
        0,
    )


def _study(section, machine: Machine, traj, margins: dict, runs: list[dict], quick: bool, responses=None) -> None:
    """The full study of one machine (its margins in ``margins``, its fixed-point runs ``runs``: the ripple sweep
    then the confirmation run; ``responses``: its ``bode_responses`` if computed already)."""
    s = _sizes(quick)
    name = machine.loaded_platform.name
    _actuators(section, machine)
    section.text(
        f"Margins across the workspace: the gains {name} runs its {traj.name} motion with (designed over the "
        "motion's poses) at every pose of a grid over the workspace box, the loop linearised about each held pose "
        "(control.frequency, the same as sd.loop_response and stewart-drake response). The rule: a gain margin of "
        f"at least {MIN_GAIN_MARGIN_DB:g} dB and a phase margin of at least {MIN_PHASE_MARGIN_DEG:g}° per leg. A "
        "failed check here is a finding about the loop, not an error of the report."
    )
    _margins(section, margins, name, s["full_grid"])
    w = worst(margins[name])
    if w is None:
        section.text(f"{name}: the loop is unstable at every pose of the grid: no steady response to measure.")
    else:
        _bode(section, machine, w, responses or bode_responses(machine, w, s["measured"]))
    section.text(
        "Quantisation: the same gains with the fixed-point IK at coarser length LSBs. Each set-point step of one "
        "LSB reaches the actuator as kp·LSB, and on its first tick as kv·LSB/T through the set-point-rate "
        f"feed-forward; runs of {s['ripple_s']:g} s of the motion."
    )
    _ripple(section, machine, traj, runs[:-1])
    _confirm(section, machine, runs[-1], s["confirm_s"])
    section.headline(
        f"{name}: least GM {min(r['gm'] for r in margins[name]):.1f} dB, PM {min(r['pm'] for r in margins[name]):.0f}°"
        f" over {len(margins[name])} poses; ripple {runs[-1]['ripple']:.3g} N"
    )


def machine_study(subject, quick: bool) -> tuple:
    """``(machine with its chosen gains, motion, {name: margins rows}, runs)`` of a user's machine (``_study``'s
    inputs: the ripple sweep's runs then the confirmation run)."""
    s = _sizes(quick)
    base = machine_of(subject)
    traj = motion(base, subject)
    machine = chosen_machine(base, traj)
    margins = {machine.loaded_platform.name: workspace_margins(machine, s["full_grid"])}
    runs = [fixed_run(machine, traj, s["ripple_s"], lsb) for lsb in ripple_lsbs(machine)]
    runs.append(fixed_run(machine, traj, s["confirm_s"]))
    return machine, traj, margins, runs


def docs_figures(subject) -> dict:
    """The section's figures for a user's machine (``report.subject.Subject``), ``{"margins" | "bode" | "ripple":
    Figure}``: the documentation's ``loop-*.png`` (``scripts/docs_hooks.py``)."""
    machine, traj, margins, runs = machine_study(subject, quick=False)
    rows = margins[machine.loaded_platform.name]
    w = worst(rows)
    limit = CHATTER_RANGE_FRACTION * machine.loaded_platform.legs.max_force
    predicted = predicted_ripple(machine, traj, [r["lsb"] for r in runs[:-1]])
    out = {"margins": margins_figure(margins), "ripple": ripple_figure(runs[:-1], limit, predicted)}
    if w is not None:
        out["bode"] = bode_figure(bode_responses(machine, w, _sizes(False)["measured"]), w["pose"])
    return out


def _user_machine(section, subject) -> None:
    _study(section, *machine_study(subject, section.quick), section.quick)


def build(section) -> None:
    if section.subject is not None:
        _user_machine(section, section.subject)
        return
    quick = section.quick
    full = _sizes(quick)["full_grid"]
    section.text(
        "The loop as a control engineer sees it, on utn-dynamic (margins on every preset): the actuators, the "
        "closed leg loop's margins over the workspace, its frequency response checked against the nonlinear Drake "
        "loop, the ripple the fixed-point format's length LSB causes, and the chosen gains and format confirmed in "
        "the time domain with the firmware in the loop."
    )
    margins = dict(zip(PRESETS, parallel_map(__file__, "_margins_part", [(n, full) for n in PRESETS])))
    measured = parallel_map(__file__, "_measure_part", _measure_items(quick))
    runs = parallel_map(__file__, "_run_part", _run_items(PLATFORM, quick))
    machine, traj = _study_machine(PLATFORM)
    responses = dict(zip(LAWS, measured)) if all(r is not None for r in measured) else None
    _study(section, machine, traj, margins, runs, quick, responses)


def main(argv=None):
    return run_standalone(__file__, argv)


if __name__ == "__main__":
    raise SystemExit(main())
