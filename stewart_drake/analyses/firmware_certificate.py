"""Firmware certificate: the generated ``sd_ik``'s word ranges, saturation and error bound proven over each
preset's workspace box (``firmware.certify``), against the worst sampled error, with the saturation
region of a finer length LSB mapped over workspace slices."""

from __future__ import annotations

import numpy as np

from stewart_drake.control.gains import ControllerConfig
from stewart_drake.core.geometry import PRESETS, load_preset
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.firmware.certify.box import KEYS, workspace_box
from stewart_drake.firmware.certify.certificate import certify
from stewart_drake.firmware.certify.recipe import BENIGN, Model, evaluate, word_names
from stewart_drake.firmware.certify.sampling import sample_box
from stewart_drake.firmware.certify.search import MAX_CELLS
from stewart_drake.firmware.certify.tick import certify_tick
from stewart_drake.firmware.certify.tp17_recipe import tp17_model
from stewart_drake.fixedpoint.generic import QFormat
from stewart_drake.fixedpoint.tp17 import dsp_poses_to_si, tp17_leg_lengths
from stewart_drake.report import run_standalone

TITLE = "Firmware certificate (proven word ranges, saturation and error bound over the workspace)"
ORDER = 96
COST = 3.8  # CPU seconds (full report, measured): the report's workers start the costliest first

DEFAULT = QFormat(16, 1e-3, "tfr16")
NEEDS = ()  # a user's machine: its platform's workspace box, in its format (default the DSP's)
# the formats compared on utn-kinematic: the default, 20 µm and 100 µm LSBs, and the formats
# `firmware optimize --error-budget 0.5mm` chose there (proven: 15-bit exact, 50 µm) and simulation alone
# would choose (14-bit exact, 90 µm: it overflows); each is certified afresh here
COMPARED = (
    ("default", DEFAULT),
    ("20 µm LSB", QFormat(16, 2e-5, "tfr16")),
    ("100 µm LSB", QFormat(16, 1e-4, "tfr16")),
    ("optimize, proven (0.5 mm budget)", QFormat(15, 5e-5, "exact")),
    ("simulation-only choice", QFormat(14, 9e-5, "exact")),
)


def _slice_map(model, box_words, ax_x: int, ax_y: int, n: int):
    """Proven clamp status over an n x n grid of cells spanning two pose coordinates of the box, the others
    held at the words ``fixed``: 0 impossible, 1 possible, 2 certain (an arithmetic word)."""
    lo, hi = box_words
    ex = np.linspace(lo[ax_x], hi[ax_x] + 1, n + 1).astype(np.int64)
    ey = np.linspace(lo[ax_y], hi[ax_y] + 1, n + 1).astype(np.int64)
    fixed = lo.copy()
    X, Y = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    c_lo = np.tile(fixed, (n * n, 1))
    c_hi = c_lo.copy()
    c_lo[:, ax_x], c_hi[:, ax_x] = ex[X.ravel()], np.maximum(ex[X.ravel() + 1] - 1, ex[X.ravel()])
    c_lo[:, ax_y], c_hi[:, ax_y] = ey[Y.ravel()], np.maximum(ey[Y.ravel() + 1] - 1, ey[Y.ravel()])
    ev = evaluate(model, c_lo, c_hi)
    arith = np.array([w not in BENIGN for w in word_names()])
    status = np.where((ev.certain & arith).any(axis=1), 2, np.where((ev.possible & arith).any(axis=1), 1, 0))
    return ex, ey, status.reshape(n, n).T


def _certified(section, p, fmt, cells: int, samples: int, tightness: bool = True):
    """The certificate of ``p``'s generated sd_ik in the format ``fmt`` over its workspace box, its checks against
    sampled poses through the emulation, and its table row: ``(row, certificate)``. ``tightness``: also check the
    bound within twice the sampled worst (how tight this cell budget makes it on the presets)."""
    name = p.name
    box = workspace_box(p)
    cert = certify(p, fmt, box, max_cells=cells)
    model = Model.build(p, fmt)
    s = sample_box(model, *box.words(fmt), samples, seed=0, adversarial=4)
    worst = s.worst_err * fmt.length_lsb * 1e3
    bound = np.array([np.nan if e is None else e for e in cert.error_bound_mm])
    inside = all(w.min <= s.word_min[k] and s.word_max[k] <= w.max for k, w in enumerate(cert.words))
    b = box.to_units()
    row = [
        name,
        "; ".join(f"{k} {b[k][0]:g}..{b[k][1]:g}" for k in KEYS),
        "possible" if cert.saturation_possible else "impossible",
        float(np.nanmax(bound)),
        float(worst.max()),
        float(np.nanmax(bound) / worst.max()),
        "yes" if inside else "NO",
    ]
    section.check(
        f"{name}: sampled worst error within the proven bound (worst − bound)", float(np.max(worst - bound)), 0.0, "mm"
    )
    if tightness:
        section.check(
            f"{name}: proven bound at most twice the sampled worst (bound / worst)",
            float(np.nanmax(bound) / worst.max()),
            2.0,
            "",
        )
    section.check(f"{name}: sampled words outside their proven ranges", 0 if inside else 1, 0, "")
    return row, cert


def _user_machine(section, subject, samples: int) -> None:
    """The certificate of the firmware generated for the user's machine, in its format, over its workspace box:
    the checks above, and that no word can saturate over the box."""
    fmt = subject.ik_format or DEFAULT
    # the command's budget (firmware certify): a smaller one can leave a word's range unresolved, which reads as
    # "saturation possible" where more cells exclude it; the bound's tightness is the budget's, not the machine's:
    # shown in the table, not checked
    row, cert = _certified(section, subject.platform, fmt, MAX_CELLS, samples, tightness=False)
    section.check(
        f"{subject.name}: a word may saturate over the workspace box, not excluded in {MAX_CELLS} cells (1: may)",
        int(cert.saturation_possible),
        0,
        "",
    )
    section.table(
        [
            "platform",
            "workspace box (mm, π)",
            "saturation",
            "proven bound (mm)",
            "sampled worst (mm)",
            "bound / worst",
            "samples in ranges",
        ],
        [row],
        caption=f"{subject.name}: format {fmt.word_bits}-bit words, {fmt.length_lsb * 1e6:g} µm LSB, {fmt.trig}"
        + (" (from the machine file)" if subject.ik_format else " (the DSP default: the file gives no firmware format)")
        + f"; {samples} random poses, corners and 4 adversarial rounds",
    )
    section.table(
        ["word", "proven min", "proven max", "headroom (bits)", "saturation"],
        [[w.name, w.min, w.max, w.headroom_bits, w.saturation] for w in cert.words if not w.name.startswith("pose")],
        caption=f"{subject.name}: the proven range of every intermediate word (LSB; Q15 for sin, cos, R)",
    )


def build(section) -> None:
    import matplotlib.pyplot as plt

    cells = 15_000 if section.quick else 25_000
    samples = 2_000 if section.quick else 10_000
    if section.subject is not None:
        cells = MAX_CELLS  # see _user_machine
    section.text(
        "Every intermediate word of the generated sd_ik gets a proven range over the whole pose box by interval "
        "arithmetic on the integer words themselves (the emulation's truncations, shifts and saturations), with the "
        "sine/cosine words bounded exactly over each cell's angle words and branch and bound on the box; each leg gets "
        "a proven bound on |L_firmware − L_float| (rigorous float enclosures). Samples (uniform + corners + an "
        "adversarial local search) through the bit-exact emulation check the bounds: a sample is not a proof, a bound "
        f"below a sample would be a bug. Budget here: {cells} cells per certificate"
        + (" (the command's default is 200,000: tighter bounds)." if cells < MAX_CELLS else " (the command's default).")
    )
    rows = []
    if section.subject is not None:
        _user_machine(section, section.subject, samples)
        return
    for name in PRESETS:
        p = load_preset(name)
        row, cert = _certified(section, p, DEFAULT, cells, samples)
        rows.append(row)
        if name == "utn-kinematic":
            table, default_cert = cert.words, cert  # the formats' table below starts with this one
    section.table(
        [
            "preset",
            "workspace box (mm, π)",
            "saturation",
            "proven bound (mm)",
            "sampled worst (mm)",
            "bound / worst",
            "samples in ranges",
        ],
        rows,
        caption=f"Default format (16-bit words, 1 mm LSB, tfr16) over each preset's workspace box; {samples} random poses, corners and 4 adversarial rounds",
    )
    section.table(
        ["word", "proven min", "proven max", "headroom (bits)", "saturation"],
        [[w.name, w.min, w.max, w.headroom_bits, w.saturation] for w in table if not w.name.startswith("pose")],
        caption="utn-kinematic, default format: the proven range of every intermediate word (LSB; Q15 for sin, cos, R)",
    )

    p = load_preset("utn-kinematic")
    box = workspace_box(p)
    # the seed's own firmware (tp17.C) over the same box, against the float IK of a = 612.5 mm
    tp = certify(p, DEFAULT, box, max_cells=cells, implementation="tp17")
    tm = tp17_model(p)
    lo, hi = tp.box.words(DEFAULT)
    w = lo + np.floor(np.random.default_rng(5).random((samples, 6)) * (hi - lo + 1)).astype(np.int64)
    q = np.c_[w[:, :3].astype(float), w[:, 3:] / 32768.0]
    tp_worst = np.abs(tp17_leg_lengths(q) - leg_lengths(tm.platform, dsp_poses_to_si(q)) * 1e3).max(axis=0)
    tp_bound = np.array(tp.error_bound_mm, dtype=float)
    section.text(
        f"The seed's hand-written firmware (tp17.C, --implementation tp17) over the same box: saturation "
        f"{'possible' if tp.saturation_possible else 'impossible'}; proven bound {tp_bound.max():.2f} mm against a "
        f"sampled worst of {tp_worst.max():.2f} mm over {samples} random poses (its integer geometry, a = 612 mm, is "
        "part of the error)."
    )
    section.check(
        "tp17: sampled worst error within the proven bound (worst − bound)",
        float(np.max(tp_worst - tp_bound)),
        0.0,
        "mm",
    )

    # the controller tick: utn-dynamic's designed gains
    pd = load_preset("utn-dynamic")
    cfg = ControllerConfig.for_platform(pd)
    trows = []
    for label, speed, ff in (
        ("legs still, no feed-forward", 0.0, 0.0),
        ("legs at 0.1 m/s", 0.1, 0.0),
        ("feed-forward ±50 N", 0.0, 50.0),
    ):
        tc = certify_tick(cfg, 5e-3, speed, ff)
        words = {x.name: x for x in tc.words}
        trows.append(
            [
                label,
                f"{words['derivative filter'].min}..{words['derivative filter'].max}",
                f"{words['integrator (Q31)'].min}..{words['integrator (Q31)'].max}",
                f"{words['command (Q15)'].min}..{words['command (Q15)'].max}",
                "proven" if tc.anti_windup else "not proven: the integrator may reach its rail (no wrap)",
            ]
        )
        if speed == 0 and ff == 0:
            section.check(
                "utn-dynamic tick, legs still: integrator proven off its rails (1 = not proven)",
                int(not tc.anti_windup),
                0,
                "",
            )
    section.table(
        ["inputs (|error| ≤ 5 mm)", "derivative filter", "integrator (Q31)", "command (Q15)", "anti-windup"],
        trows,
        caption="utn-dynamic's sd_tick: proven ranges of the PID words (exact endpoint maps; filters and integrator as invariants)",
    )

    rows = []
    for label, fmt in COMPARED:
        # the default format on this box was certified above (same platform, box and budget): not again
        cert = default_cert if fmt == DEFAULT else certify(p, fmt, box, max_cells=cells)
        bound = None if cert.saturation_possible else max(cert.error_bound_mm)
        wt = cert.witness
        rows.append(
            [
                label,
                f"{fmt.word_bits}-bit, {fmt.length_lsb * 1e6:g} µm, {fmt.trig}",
                "possible" if cert.saturation_possible else "impossible",
                np.nan if bound is None else bound,
                "—"
                if wt is None
                else ", ".join(f"{k} {v:.4g}" for k, v in wt["pose"].items()) + f" → {', '.join(wt['saturates'])}",
            ]
        )
        if label == "20 µm LSB":
            witness = None if wt is None else np.array(wt["pose_words"])
            section.check(
                "utn-kinematic at 20 µm: a witness saturates the emulation (1 = none found)", 0 if wt else 1, 0, ""
            )
            fine = fmt
        if label == "100 µm LSB":
            section.check(
                "utn-kinematic at 100 µm: saturation proven impossible (1 = not proven)",
                int(cert.saturation_possible),
                0,
                "",
            )
    section.table(
        ["format", "words, LSB, trig", "saturation", "proven bound (mm)", "witness (mm, π) → saturated words"],
        rows,
        caption="utn-kinematic workspace box: formats certified (the optimiser's choice meets 0.5 mm with a proof; the simulation-only choice overflows at the witness)",
        nan_reason="unbounded: saturation possible",
    )

    model = Model.build(p, fine)
    bw = box.words(fine)
    n = 24 if section.quick else 48
    fig, axes = plt.subplots(1, 2, figsize=(11, 4))
    cmap = plt.get_cmap("RdYlGn_r", 3)
    for ax, (ix, iy) in zip(axes, ((0, 2), (3, 2))):
        ex, ey, st = _slice_map(model, bw, ix, iy, n)
        sx = fine.length_lsb * 1e3 if ix < 3 else 1.0 / (1 << fine.frac_bits)
        sy = fine.length_lsb * 1e3
        im = ax.pcolormesh(ex * sx, ey * sy, st, cmap=cmap, vmin=-0.5, vmax=2.5, shading="flat")
        if witness is not None and np.all(np.delete(witness, [ix, iy]) == np.delete(bw[0], [ix, iy])):
            ax.plot(
                witness[ix] * sx, witness[iy] * sy, "k*", ms=14, clip_on=False, label="witness (emulation saturates)"
            )
            ax.legend(loc="upper right")
        ax.set_xlabel(f"{KEYS[ix]} ({'mm' if ix < 3 else 'π'})")
        ax.set_ylabel("pz (mm)")
        ax.set_title("others at the box's low corner")
    cb = fig.colorbar(im, ax=axes, ticks=[0, 1, 2])
    cb.ax.set_yticklabels(["impossible", "possible", "certain"])
    cb.set_label("proven saturation")
    section.figure(
        fig,
        "firmware_certificate_saturation",
        "utn-kinematic at a 20 µm LSB: proven saturation status of the arithmetic words over two workspace slices "
        "(each cell a box of pose words; certain = every pose of the cell saturates)",
    )


def main(argv=None):
    return run_standalone(__file__, argv)


if __name__ == "__main__":
    raise SystemExit(main())
