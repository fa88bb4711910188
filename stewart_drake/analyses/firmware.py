"""Firmware equivalence: the C itself — the seed firmware tp17.C compiled against the host C intrinsics,
the firmware module generated for each preset (IK + controller tick), compared bit for bit with the
emulation and against the float IK, and run in the loop beside the Python engine."""

from __future__ import annotations

import dataclasses
import time
from collections import Counter

import numpy as np

from stewart_drake.api.simulation import plan_run
from stewart_drake.control import FEEDFORWARD_OPS_PER_LEG, PID_OPS_PER_LEG, ControllerConfig
from stewart_drake.core.geometry import PRESETS, load_preset
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.drake.simulation import build_simulation
from stewart_drake.firmware.check import workspace_poses
from stewart_drake.firmware.generate import generate
from stewart_drake.firmware.host import op_counts_tp17, tp17_leg_lengths_c
from stewart_drake.firmware.module import TickRunner, compile_generated
from stewart_drake.fixedpoint import QFormat, scalar
from stewart_drake.fixedpoint.generic import leg_length_words, pose_words
from stewart_drake.fixedpoint.tp17 import SEED_DSP_MM, SEED_DSP_POSES
from stewart_drake.report import run_standalone
from stewart_drake.report.subject import mark_not_applicable, subject_trajectories
from stewart_drake.system.c_build import compilers

TITLE = "Firmware equivalence: the C compiled, generated and run in the loop"
ORDER = 95
COST = 4.4  # CPU seconds (full report, measured): the report's workers start the costliest first
NEEDS = ("plate", "legs.max_force")  # a user's machine: its firmware generated for its plate and force range
C_WORD_BITS = 16  # the widest data word the generated C takes (firmware.generate)


def _seed_table(section) -> None:
    c = tp17_leg_lengths_c(SEED_DSP_POSES)
    rows = []
    for k, q in enumerate(SEED_DSP_POSES):
        rows.append(
            [f"{q[0]:g}, {q[1]:g}, {q[2]:g} mm; {q[3]:g}π, {q[4]:g}π, {q[5]:g}π", "seed DSP"]
            + [int(v) for v in SEED_DSP_MM[k]]
        )
        rows.append(["", "tp17.C compiled (host)"] + [int(v) for v in c[k]])
    section.table(
        ["pose", "row"] + [f"L{i}" for i in range(1, 7)],
        rows,
        caption="The seed table's DSP block from the compiled tp17.C (fixedpoint/c/tp17.c with dsp56800e.h)",
    )
    section.check("seed DSP block: 24 values vs compiled tp17.C", np.abs(c - SEED_DSP_MM).max(), 0.0, "mm")
    counts = op_counts_tp17()
    model = scalar.tp17_op_counts()
    diff = sum(abs(counts[k] - model[k]) for k in set(counts) | set(model))
    section.check(
        "tp17.C instrumented intrinsic calls per pass vs the cycle model's counts (sum of |Δ|)", diff, 0, "calls"
    )


def _workspace(section, n: int, platforms=None, ik_format=None) -> list:
    """Generated C vs emulation vs float IK for every preset (or ``platforms``, with the fixed-point format
    ``ik_format``, None: the DSP's); returns the generated modules."""
    rows, gens = [], []
    for p in [load_preset(name) for name in PRESETS] if platforms is None else platforms:
        name = p.name
        cfg = (
            ControllerConfig.for_platform(p)
            if ik_format is None
            else ControllerConfig.for_platform(p, ik_format=ik_format)
        )
        g = generate(p, cfg)
        gens.append((p, cfg, g))
        q = workspace_poses(p, n, seed=3)
        w = pose_words(q, cfg.ik_format)
        emu = leg_length_words(p, w, cfg.ik_format, cfg.convention)
        c, nsat = compile_generated(g).ik(w)
        d_ce = np.abs(c - emu).max()
        err = c * cfg.ik_format.length_lsb - leg_lengths(p, q)
        rows.append(
            [
                name,
                n,
                int(np.any(c != emu, axis=1).sum()),
                int(d_ce),
                f"{np.abs(err).max() * 1e3:.3f}",
                f"{np.sqrt(np.mean(err**2)) * 1e3:.3f}",
                int((nsat > 0).sum()),
            ]
        )
        section.check(f"{name}: generated sd_ik vs emulation, {n} workspace poses (worst LSB)", d_ce, 0, "LSB")
    fmt = gens[0][1].ik_format
    section.table(
        [
            "platform",
            "poses",
            "differing",
            "worst C − emulation (LSB)",
            "max |C − float| (mm)",
            "RMS C − float (mm)",
            "poses with saturation",
        ],
        rows,
        caption=f"The generated firmware's sd_ik ({fmt.word_bits}-bit words, {fmt.length_lsb * 1e3:g} mm LSB, {fmt.trig}) "
        "over random workspace poses "
        "(within stroke, ±10 % of the stroke, ±15°): bit-identical with the emulation; its error against the float IK",
    )
    return gens


def _saturation_map(section, quick: bool, gens) -> None:
    import matplotlib.pyplot as plt

    # utn-dynamic's designed configuration (its gains depend on the platform alone) in a finer word format
    p, designed, _ = next(x for x in gens if x[0].name == "utn-dynamic")
    fmt = QFormat(16, 1e-4, "tfr16")  # 0.1 mm LSB: the words reach ±3.28 m, so large poses saturate
    cfg = dataclasses.replace(designed, ik_format=fmt)
    m = compile_generated(generate(p, cfg))
    k = 81 if quick else 241
    x = np.linspace(-4.0, 4.0, k)
    z = np.linspace(-4.0, 4.0, k)
    X, Z = np.meshgrid(x, z)
    q = np.zeros(X.shape + (6,))
    q[..., 0], q[..., 2], q[..., 4] = X, Z, np.radians(20)
    w = pose_words(q, fmt)
    c, nsat = m.ik(w)
    emu = leg_length_words(p, w, fmt, cfg.convention)
    section.check(
        "saturation map: sd_ik vs emulation on the grid, saturating poses included (worst LSB)",
        np.abs(c - emu).max(),
        0,
        "LSB",
    )
    fig, ax = plt.subplots(figsize=(5.5, 4.2))
    im = ax.pcolormesh(X, Z, nsat, shading="auto", cmap="magma_r")
    fig.colorbar(im, ax=ax, label="saturations in one sd_ik")
    ax.set_xlabel("px [m]")
    ax.set_ylabel("pz [m]")
    ax.set_title("utn-dynamic, 16-bit words of 0.1 mm, pitch 20°")
    section.figure(
        fig,
        "firmware_saturation_map",
        "Where the generated sd_ik saturates (the count it returns): outside the "
        "circle the leg lengths exceed the word (32767 LSB = 3.28 m) and the square root clips; beyond ±3.28 m the position "
        "words are already clipped on the way in and the leg-vector sums clip too. The C equals the emulation everywhere",
    )


def _instrumented(section, gens) -> None:
    p, cfg, g = gens[0]
    m = compile_generated(g, counting=True)
    w = pose_words(p.home_pose(), cfg.ik_format)
    m.reset_op_counts()
    m.ik(w[None])
    ik = Counter(m.op_counts())
    m.reset_op_counts()
    TickRunner(m).tick(w, np.full(6, 70_000), np.zeros(6, dtype=np.int64))
    tick = Counter(m.op_counts()) - ik
    model = Counter()
    for ops in (PID_OPS_PER_LEG, FEEDFORWARD_OPS_PER_LEG):
        for k, v in ops.items():
            model[k] += 6 * v
    section.check(
        f"{p.name}: instrumented sd_ik operation counts vs the README's cycle model (sum of |Δ|)",
        sum(abs(ik[k] - g.ik_ops[k]) for k in set(ik) | set(g.ik_ops)),
        0,
        "calls",
    )
    section.check(
        f"{p.name}: instrumented sd_tick operations beyond the IK vs control.PID_OPS_PER_LEG + FEEDFORWARD_OPS_PER_LEG (sum of |Δ|)",
        sum(abs(tick[k] - model[k]) for k in set(tick) | set(model)),
        0,
        "calls",
    )


def _files(section, gens) -> None:
    rows = []
    for p, cfg, g in gens:
        ik = g.ik_cycles
        sizes = ", ".join(f"{k} {len(v.encode())} B" for k, v in g.files.items())
        rows.append(
            [
                p.name,
                sizes,
                f"{ik.cycles:.0f} ({ik.microseconds:.1f} µs)",
                f"{g.tick_cycles:.0f} ({g.tick_cycles / cfg.timing.clock_hz * 1e6:.1f} µs)",
                f"kp {cfg.gains.kp:.4g}, ki {cfg.gains.ki:.4g}, kd {cfg.gains.kd:.4g}",
            ]
        )
    section.table(
        ["preset", "generated files", "sd_ik cycles", "sd_tick cycles", "designed gains (SI)"],
        rows,
        caption="`stewart-drake firmware generate --platform NAME`: the files, and the cycle estimates (MC56F8367 at 60 MHz, "
        "fixedpoint.cycles table; the generated IK skips the firmware's run-time double conversions and dead anchors)",
    )
    section.text(
        "Each module compiles warning-free with -std=c99 -Wall -Wextra -Werror -pedantic under: "
        + ", ".join(f"{c.name} ({c.version})" for c in compilers())
        + "."
    )


def _sil(section, quick: bool, p=None, traj=None, ik_format=None) -> None:
    """The fixed-point loop with the Python law and with the generated C, bit for bit: utn-dynamic on the seed
    trajectory, or ``p`` along ``traj`` with the format ``ik_format``."""
    import matplotlib.pyplot as plt

    p = load_preset("utn-dynamic") if p is None else p
    traj = _traj() if traj is None else traj
    duration = 0.3 if quick else 4.0
    logs, wall = {}, {}
    for eng in ("python", "c"):
        plan = plan_run(p, traj, "fixed", duration, engine=eng, checks=False, command="report")
        if ik_format is not None:
            config = dataclasses.replace(plan.config, ik_format=ik_format)
            plan = dataclasses.replace(plan, scenario=dataclasses.replace(plan.scenario, config=config))
        sim = build_simulation(plan.scenario)
        t0 = time.perf_counter()
        logs[eng] = sim.run(duration)
        wall[eng] = time.perf_counter() - t0
    a, b = logs["python"], logs["c"]
    worst = max(
        float(np.abs(getattr(a, k) - getattr(b, k)).max()) for k in ("lengths", "command", "setpoint", "force", "pose")
    )
    section.check(
        f"closed loop, {traj.name} trajectory {duration:g} s: C engine logs vs Python engine logs (worst |Δ|)",
        worst,
        0.0,
    )
    section.table(
        ["engine", "wall time (s)", "real-time factor", "max leg error (mm)"],
        [
            [
                eng,
                f"{wall[eng]:.2f}",
                f"{duration / wall[eng]:.2f}",
                f"{np.abs(lg.length_error(traj, p)).max() * 1e3:.3f}",
            ]
            for eng, lg in logs.items()
        ],
        caption="The fixed-point controller at 1 kHz driving the Drake plant: the Python law vs the generated firmware's sd_tick "
        "(same LeafSystem ports, timing and logs); times from this run",
    )
    fig, ax = plt.subplots(figsize=(8, 3))
    ea, eb = a.length_error(traj, p), b.length_error(traj, p)
    ax.plot(a.t, ea * 1e3, lw=2.5, alpha=0.4)
    ax.set_prop_cycle(None)
    ax.plot(b.t, eb * 1e3, "--", lw=0.8)
    ax.set_xlabel("t [s]")
    ax.set_ylabel("leg error [mm]")
    section.figure(
        fig,
        "firmware_sil",
        "Leg-length errors with the Python engine (wide, faint) and the C engine (dashed): the same curves, bit for bit",
    )


def _traj():
    from stewart_drake.core.trajectory import get_trajectory

    return get_trajectory("seed")


def _user_machine(section, subject) -> None:
    """The firmware generated for the user's machine with its format: C vs emulation over its workspace, and the
    loop with the Python law vs the C, bit for bit, along its first motion."""
    fmt = subject.ik_format or ControllerConfig().ik_format
    if fmt.word_bits > C_WORD_BITS:
        mark_not_applicable(
            section,
            subject,
            f"the generated C takes words of at most {C_WORD_BITS} bits; the format has {fmt.word_bits}",
        )
        return
    section.text(
        f"{subject.name}: the firmware module generated for this machine (its gains, its command range "
        f"{subject.platform.legs.max_force:g} N) with the format {fmt.word_bits}-bit words, length LSB "
        f"{fmt.length_lsb * 1e6:g} µm, {fmt.trig}"
        + (" (from the machine file)" if subject.ik_format else " (the DSP default: the file gives no firmware format)")
        + ": its sd_ik against the emulation bit for bit, and its sd_tick in the loop against the Python law."
    )
    _workspace(section, 20_000 if section.quick else 200_000, [subject.platform], fmt)
    _sil(section, section.quick, subject.platform, subject_trajectories(subject)[0], fmt)


def build(section) -> None:
    if section.subject is not None:
        _user_machine(section, section.subject)
        return
    quick = section.quick
    section.text(
        "The toolkit verifies the firmware itself, not only a Python model of it. fixedpoint/c/dsp56800e.h and .c implement the "
        "DSP56800E intrinsics for the host (saturation on, two's-complement rounding, the tfr16.c polynomial and the rtlib "
        "mfr32Sqrt bit search); the seed's tp17.C compiles against them as a function (fixedpoint/c/tp17.c, the two garbled lines "
        "restored and commented). `firmware generate` emits a C99 module with no floating point for any platform: the fixed-point "
        "IK of fixedpoint.generic and the controller tick (PID, feed-forward word, saturation, anti-windup) with the designed gains; "
        "`simulate --engine c` runs its sd_tick inside the Drake diagram, and `firmware check` compares a user's C with the emulation."
    )
    _seed_table(section)
    gens = _workspace(section, 20_000 if quick else 200_000)
    _files(section, gens)
    _instrumented(section, gens)
    _saturation_map(section, quick, gens)
    _sil(section, quick)


def main(argv=None):
    return run_standalone(__file__, argv)


if __name__ == "__main__":
    raise SystemExit(main())
