"""Fixed-point vs float leg-length error over the workspace: the DSP firmware (tp17.C, bit-exact) and
the generic fixed-point IK at other word lengths."""

from __future__ import annotations

import numpy as np

from stewart_drake.core.geometry import load_preset
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.core.sampling import random_poses
from stewart_drake.fixedpoint import (
    ERROR_STAGES,
    QFormat,
    SaturationCounter,
    dsp_poses_from_si,
    dsp_poses_to_si,
    fixed_point_leg_lengths,
    tp17_error_stages,
    tp17_leg_lengths,
)
from stewart_drake.report import run_standalone

TITLE = "Fixed-point error over the workspace (DSP56800E firmware and word-length study)"
ORDER = 25
COST = 2.2  # CPU seconds (full report, measured): the report's workers start the costliest first
PRESET_ONLY = "it studies the seed DSP firmware's (tp17.C) own errors on utn-kinematic; your machine's format is certified in the firmware certificate section"

SEED = 20
BUDGET_MM = 6.3  # a 0.4 + anchor words 1.7 + R·anchor 2·sqrt(3) + sqrt 0.5 + trig/matrix 0.3 (see tests)


def workspace_sample(n: int, seed: int = SEED) -> np.ndarray:
    """``(n, 6)`` firmware poses (whole mm, pi-fractions) spread over the utn-kinematic workspace:
    ±100 mm in x, y and z about the home pose, ±25° about each axis, every leg in stroke."""
    p = load_preset("utn-kinematic")
    q = random_poses(p, n, seed=seed, translation=0.1, rotation=np.radians(25))
    d = dsp_poses_from_si(q)
    d[:, :3] = np.trunc(d[:, :3])
    return d


def build(section) -> None:
    import matplotlib.pyplot as plt

    n = 20_000 if section.quick else 200_000
    p = load_preset("utn-kinematic")
    q = workspace_sample(n)
    with SaturationCounter(shape=(n,)) as sat:
        dsp = tp17_leg_lengths(q)
    ref = leg_lengths(p, dsp_poses_to_si(q)) * 1e3
    err = dsp - ref
    k, leg = np.unravel_index(np.abs(err).argmax(), err.shape)
    worst = q[k]
    m = min(n, 20_000)
    st = tp17_error_stages(q[:m])["stages"]
    rms = {name: float(np.sqrt(np.mean(v**2))) for name, v in st.items()}
    mean = {name: float(np.mean(v)) for name, v in st.items()}
    dominant = max(rms, key=rms.get)

    section.text(
        f"{n} poses of the utn-kinematic workspace (±100 mm in x, y; ±100 mm in z about pz = 100 mm; ±25° about each "
        "axis; every leg within the 300–700 mm stroke), positions in whole millimetres as the firmware stores them. "
        "The DSP lengths come from the bit-exact emulation of tp17.C; the reference is the float IK of the exact "
        "platform (a = 612.5 mm) at the same pose."
    )
    section.table(
        ["quantity", "value"],
        [
            ["mean error (DSP − float)", f"{err.mean():+.3f} mm"],
            ["RMS error", f"{np.sqrt(np.mean(err**2)):.3f} mm"],
            ["99th percentile of |error|", f"{np.percentile(np.abs(err), 99):.3f} mm"],
            ["worst |error|", f"{abs(err[k, leg]):.3f} mm (leg {leg + 1})"],
            [
                "worst pose (px, py, pz mm; α, β, γ °)",
                f"{worst[0]:.0f}, {worst[1]:.0f}, {worst[2]:.0f}; {worst[3] * 180:.1f}, {worst[4] * 180:.1f}, {worst[5] * 180:.1f}",
            ],
            ["saturations in the firmware arithmetic", f"{sat.total}"],
        ],
        caption="DSP − float IK over the workspace sample",
    )
    section.check(
        f"DSP − float IK over {n} workspace poses, worst |error| vs the error budget",
        np.abs(err).max(),
        BUDGET_MM,
        "mm",
    )
    section.check("saturations in the firmware arithmetic within the workspace sample", sat.total, 0, "events")

    section.table(
        ["stage", "what changes", "mean (mm)", "RMS (mm)", "max |Δ| (mm)"],
        [
            [name, desc, f"{mean[name]:+.3f}", f"{rms[name]:.3f}", f"{np.abs(st[name]).max():.3f}"]
            for name, desc in ERROR_STAGES
        ],
        caption=f"The error split by operation on {m} of the poses (telescoping models; the stages sum to DSP − float)",
    )
    section.text(
        f"Dominant operation: {dominant} (RMS {rms[dominant]:.2f} mm). The truncations toward −∞ (extract_h) bias the "
        f"error: mean {err.mean():+.2f} mm overall. The trigonometric library contributes an RMS of "
        f"{rms['sin/cos library']:.3f} mm — the seed's explanation (sine/cosine precision) does not hold."
    )

    fig, axes = plt.subplots(1, 2, figsize=(11, 3.6))
    axes[0].hist(err.ravel(), bins=80, color="tab:blue")
    axes[0].set_xlabel("DSP − float leg length (mm)")
    axes[0].set_ylabel("legs")
    axes[0].set_title(f"{n} poses × 6 legs")
    names = [name for name, _ in ERROR_STAGES]
    axes[1].barh(names, [rms[x] for x in names], color="tab:orange")
    axes[1].invert_yaxis()
    axes[1].set_xlabel("RMS contribution (mm)")
    axes[1].set_title("by operation")
    axes[1].set_ylabel("firmware operation")
    section.figure(
        fig, "fixedpoint_error_hist", "Histogram of the DSP's leg-length error and its RMS contribution per operation"
    )

    # Saturation map: where does the firmware clip? Sweep px and pz across the 16-bit range.
    g = 41 if section.quick else 121
    PX, PZ = np.meshgrid(np.linspace(-32000, 32000, g), np.linspace(0, 32000, g))
    grid = np.zeros(PX.shape + (6,))
    grid[..., 0], grid[..., 2] = np.trunc(PX), np.trunc(PZ)
    with SaturationCounter(shape=PX.shape) as gsat:
        tp17_leg_lengths(grid)
    first = np.hypot(PX, PZ)[gsat.mask].min() if gsat.mask.any() else np.inf
    fig, ax = plt.subplots(figsize=(5.5, 3.8))
    ax.pcolormesh(PX / 1e3, PZ / 1e3, gsat.mask, cmap="Reds", shading="auto", vmin=0, vmax=1.5)
    ax.set_xlabel("px (m)")
    ax.set_ylabel("pz (m)")
    ax.set_title("red: some firmware operation saturates")
    section.figure(fig, "fixedpoint_saturation_map", "Saturation map of tp17.C over (px, pz), no rotation")
    section.text(
        f"Saturation: none of the {n} workspace poses saturates any operation. Over the sweep the firmware first clips "
        f"about {first / 1e3:.1f} m from the base centre ({', '.join(f'{a}: {c}' for a, c in gsat.counts.most_common(3))}): "
        "the sum of squares 2(x² + y² + z²) exceeds 2³¹ once a leg passes 32767 mm, and the position words overflow "
        "beyond that. Within any realistic pose the 16-bit words have ~50× headroom — which is why 1 mm is a poor use of them."
    )

    # Q-format study with the generic fixed-point IK
    qs = q[: (2_000 if section.quick else 20_000)]
    qsi = dsp_poses_to_si(qs)
    ref_s = leg_lengths(p, qsi)
    rows, bits, worst_w, rms_w = [], list(range(10, 26, 2)), [], []
    reach = 2.0  # m: a power of two above every anchor coordinate and length of this platform
    for w in bits:
        fmt = QFormat(w, reach / 2 ** (w - 1))
        e = fixed_point_leg_lengths(p, qsi, fmt) - ref_s
        worst_w.append(np.abs(e).max() * 1e3)
        rms_w.append(np.sqrt(np.mean(e**2)) * 1e3)
        rows.append([f"{w}", f"{fmt.length_lsb * 1e3:.4g}", f"{rms_w[-1]:.4g}", f"{worst_w[-1]:.4g}"])
    section.table(
        ["word bits", "length LSB (mm)", "RMS error (mm)", "worst (mm)"],
        rows,
        caption="Generic fixed-point IK (exact trig words, truncated products), range ±2 m, vs word length",
    )
    lsb_rows = []
    for lsb_mm in (1.0, 0.5, 0.25, 1 / 16, 1 / 32, 1 / 64):
        fmt = QFormat(16, lsb_mm * 1e-3, "tfr16")
        try:
            with SaturationCounter() as s16:
                e = fixed_point_leg_lengths(p, qsi, fmt) - ref_s
            lsb_rows.append(
                [
                    f"{lsb_mm:.4g}",
                    f"{fmt.range_m:.3f}",
                    f"{np.sqrt(np.mean(e**2)) * 1e3:.4g}",
                    f"{np.abs(e).max() * 1e3:.4g}",
                    f"{s16.total}",
                ]
            )
        except ValueError as ex:  # an anchor does not fit the word: say so
            lsb_rows.append([f"{lsb_mm:.4g}", f"{fmt.range_m:.3f}", "—", "—", f"does not fit: {ex}"])
    section.table(
        ["LSB (mm)", "range (m)", "RMS (mm)", "worst (mm)", "saturations"],
        lsb_rows,
        caption="16-bit words with the DSP's sin/cos library: choosing the length unit",
    )
    fig, ax = plt.subplots(figsize=(5.5, 3.6))
    ax.semilogy(bits, worst_w, "o-", label="worst")
    ax.semilogy(bits, rms_w, "s-", label="RMS")
    ax.semilogy(bits, [reach / 2 ** (w - 1) * 1e3 for w in bits], "k--", lw=0.8, label="1 LSB")
    ax.set_xlabel("word length (bits)")
    ax.set_ylabel("leg-length error (mm)")
    ax.legend()
    section.figure(
        fig, "fixedpoint_qformat", "Leg-length error of the generic fixed-point IK vs word length (range ±2 m)"
    )
    slope = np.polyfit(bits, np.log2(rms_w), 1)[0]
    section.text(
        f"The error falls by a factor 2^{-slope:.2f} per added bit (one LSB halves per bit) and stays within a few LSB: the "
        "arithmetic, not the trig, sets it. With 16-bit words, 1/32 mm LSBs (range ±1.02 m) would already cut the "
        "firmware's millimetre-level error by more than an order of magnitude on this platform."
    )
    section.check(
        "word-length study: RMS error halves per added bit (|slope of log2 RMS + 1|)", abs(slope + 1.0), 0.3, "bits/bit"
    )


def main(argv=None):
    return run_standalone(__file__, argv)


if __name__ == "__main__":
    raise SystemExit(main())
