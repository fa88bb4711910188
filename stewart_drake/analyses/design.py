"""Design analysis: actuator sizing for a trajectory, a motion program and a duty envelope;
Cartesian stiffness and its ellipsoids; natural frequencies analytic vs Drake; maps of dexterity,
stiffness and lowest frequency over a workspace slice; a summary for each preset."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from stewart_drake.core.dynamics import seed_trajectory
from stewart_drake.core.geometry import PRESETS, load_platform, load_preset
from stewart_drake.core.kinematics import inverse_jacobian, leg_lengths
from stewart_drake.design.envelope import Envelope, cartesian_leg_forces_at, envelope_sizing
from stewart_drake.design.maps import SAFE_CONDITION, slice_maps
from stewart_drake.design.modes import analytic_modes, damping_matrix, spatial_inertia, subspace_mac
from stewart_drake.design.payload import with_payload
from stewart_drake.design.sizing import rotating_trajectory, size_trajectory
from stewart_drake.design.stiffness import principal_stiffness, static_wrench, stiffness_matrix
from stewart_drake.design.verify import newton_euler_fd, sample_box
from stewart_drake.drake.design_checks import drake_modes
from stewart_drake.report import run_standalone
from stewart_drake.report.subject import NEEDS as NEED_TEXT
from stewart_drake.report.subject import TRAJECTORY_NAMES, motion_rates, not_applicable_html, subject_trajectories

TITLE = "Design: actuator sizing, stiffness, natural frequencies"
ORDER = 85
COST = 3  # CPU seconds (full report, measured): the report's workers start the costliest first
PRESET = "utn-dynamic"
PROGRAM = Path(__file__).resolve().parents[1] / "examples" / "seed_004.stw"
PAYLOAD_KG, PAYLOAD_COM = 5.0, np.array([0.02, -0.01, 0.05])  # m, in T
DEFAULT_K = 1.0e5  # N/m, for presets whose file gives no legs.stiffness (stated in the table)
Q_TILT = np.r_[0.05, -0.03, 0.72, np.radians([6.0, -4.0, 15.0])]  # the preset's tilted pose (m, rad)
# a user's machine: its tilted pose, home moved by these (m, rad), halved until every leg is within its stroke
USER_TILT = np.r_[0.02, -0.01, 0.0, np.radians([3.0, -2.0, 6.0])]
# sizing along a user's smooth motions (its rates by five-point differences at 0.1 ms: report.subject.motion_rates)
# vs Newton–Euler by eighth-order differences of the pose at 1 ms (design.verify): both truncations are negligible
# on smooth motions of a few rad/s, so the difference is the rates' rounding, ~1e-16 |q| / h² ≈ 1e-8 m/s² on
# accelerations of ~0.1..1 m/s²; relative to the largest force, 1e-6 leaves two orders of margin
FD_REL_TOL = 1e-6
EDGE_S = 0.01  # s: the motions are sized from here to this before their end (the stencils stay inside them)
NEEDS = ("plate", "legs.max_force")  # a user's machine: sizing along its motions (stiffness: legs.stiffness)
SAMPLE_RATE, LOOP_DELAY = 1000.0, 1.5e-3  # the DSP's 1 kHz loop: one sample of output delay + half a sample of hold
ENVELOPE = Envelope(
    poses=np.stack(
        np.meshgrid(
            *[np.linspace(-0.05, 0.05, 3)] * 2,
            [0.68, 0.72],
            *[np.radians(np.linspace(-5, 5, 3))] * 2,
            [0.0],
            indexing="ij",
        ),
        -1,
    ).reshape(-1, 6),
    v_max=np.array([0.3, 0.3, 0.2, 0.5, 0.5, 1.0]),
    a_max=np.array([3.0, 3.0, 5.0, 10.0, 10.0, 20.0]),
    source="report envelope",
)
LEG_HEADER = [
    "leg",
    "peak |F| (N)",
    "RMS F (N)",
    "peak |L̇| (m/s)",
    "peak |L̈| (m/s²)",
    "peak |P| (W)",
    "L min (mm)",
    "L max (mm)",
]


def _rows(legs):
    return [
        [
            r["leg"],
            r["force"]["peak"],
            r["rms_force"],
            r["speed"]["peak"],
            r["accel"]["peak"],
            r["power"]["peak"],
            r["min_length"] * 1e3,
            r["max_length"] * 1e3,
        ]
        for r in legs
    ]


def sizing(section, p) -> None:
    # Seed trajectory and the check against Newton–Euler by finite differences (rotating trajectory).
    t = np.linspace(0, 4, 4001)
    s = size_trajectory(p, t, *seed_trajectory(t))
    section.table(
        LEG_HEADER, _rows(s.legs()), caption=f"{PRESET}, seed trajectory (4 s at 1 kHz), plate only", fmt="{:.4g}"
    )
    tr = np.linspace(0, 4, 401)
    pl = with_payload(p, PAYLOAD_KG, PAYLOAD_COM)
    sr = size_trajectory(pl, tr, *rotating_trajectory(tr))
    F, L, Ld, _ = newton_euler_fd(pl, lambda ts: rotating_trajectory(ts)[0], tr)
    section.check(
        "sizing forces vs Newton–Euler from finite differences of the pose (rotating, 5 kg offset payload)",
        float(np.abs(sr.force - F).max()),
        1e-6,
        "N",
    )
    section.check(
        "sizing leg speeds vs finite differences of the leg lengths (rotating)",
        float(np.abs(sr.speed - Ld).max()),
        1e-6,
        "m/s",
    )

    # The seed program on the kinematic preset (its z = 300 mm suits that platform).
    from stewart_drake.script import run_program

    pk = load_preset("utn-kinematic")
    res = run_program(PROGRAM.read_text(), str(PROGRAM), pk, rate=100.0)
    tj = res.trajectory
    sp = size_trajectory(pk, tj.t, tj.q, tj.qd, tj.qdd)
    section.table(
        LEG_HEADER,
        _rows(sp.legs()),
        caption=f"utn-kinematic, examples/seed_004.stw ({len(tj.t)} samples, {tj.duration:.2f} s)",
        fmt="{:.4g}",
    )
    section.check(
        "program sizing forces = the run command's inverse dynamics", float(np.abs(sp.force - res.F).max()), 1e-9, "N"
    )

    # Envelope, with the random-sample check.
    es = envelope_sizing(p, ENVELOPE)
    rows = [
        [
            i + 1,
            w["peak"],
            float(es.peak_speed[:, i].max()),
            float(es.peak_accel[:, i].max()),
            float(es.peak_power[:, i].max()),
        ]
        for i, w in enumerate(es.worst)
    ]
    section.text(
        f"Envelope: {len(ENVELOPE.poses)} poses (x, y ±50 mm, z 680/720 mm, roll and pitch ±5°), |v| <= {ENVELOPE.v_max[:3].tolist()} m/s, "
        f"|ω| <= {ENVELOPE.v_max[3:].tolist()} rad/s, |a| <= {ENVELOPE.a_max[:3].tolist()} m/s², |ω̇| <= {ENVELOPE.a_max[3:].tolist()} rad/s². "
        "Peak force: exact worst case (affine in acceleration: a vertex of the box; quadratic in velocity: maximised over every face "
        "of the velocity box). Speed exact; acceleration and power are upper bounds."
    )
    section.table(
        ["leg", "peak |F| (N)", "peak |L̇| (m/s)", "peak |L̈| bound (m/s²)", "peak |P| bound (W)"],
        rows,
        caption="Worst case over the envelope",
        fmt="{:.4g}",
    )
    n = 10_000 if section.quick else 100_000
    rng = np.random.default_rng(16)
    k = rng.integers(0, len(ENVELOPE.poses), n)
    V, A = sample_box(rng, n, ENVELOPE.v_max), sample_box(rng, n, ENVELOPE.a_max)
    Fs = cartesian_leg_forces_at(p, ENVELOPE.poses, k, V, A)  # = cartesian_leg_forces(p, poses[k], V, A)
    section.check(
        f"envelope: {n} random samples never exceed the worst case (largest excess)",
        float(max((Fs - es.force_max[k]).max(), (es.force_min[k] - Fs).max(), 0.0)),
        1e-9 * es.peak_force.max(),
        "N",
    )
    if not section.quick:
        section.check(
            "envelope: the worst case is attained by a sample (largest shortfall of the best sample)",
            float((1 - np.abs(Fs).max(0) / es.peak_force.max(0)).max()),
            0.01,
        )
    a = es.allowed_accel.min(axis=0)
    section.table(
        ["axis", "x (m/s²)", "y (m/s²)", "z (m/s²)", "roll (rad/s²)", "pitch (rad/s²)", "yaw (rad/s²)"],
        [["allowed"] + list(a)],
        caption=f"Largest acceleration per axis (alone, worst envelope velocity) within max_force = {p.legs.max_force:g} N at every envelope pose",
        fmt="{:.4g}",
    )


def _ellipsoid(ax, vals, dirs, color):
    u, v = np.meshgrid(np.linspace(0, 2 * np.pi, 30), np.linspace(0, np.pi, 15))
    sph = np.stack([np.cos(u) * np.sin(v), np.sin(u) * np.sin(v), np.cos(v)], -1)
    pts = sph * vals @ dirs.T
    ax.plot_surface(pts[..., 0], pts[..., 1], pts[..., 2], color=color, alpha=0.35, linewidth=0)
    m = np.max(vals)
    ax.set_xlim(-m, m)
    ax.set_ylim(-m, m)
    ax.set_zlim(-m, m)


def stiffness(section, p, k, pl=None, q_tilt=None, load: str = f"{PAYLOAD_KG:g} kg payload") -> None:
    """Stiffness checks and ellipsoids of ``p`` loaded as ``pl`` (default: the report's payload) at home and at
    ``q_tilt`` (default the preset's tilted pose)."""
    import matplotlib.pyplot as plt

    pl = with_payload(p, PAYLOAD_KG, PAYLOAD_COM) if pl is None else pl
    q_home = p.home_pose()
    q_tilt = Q_TILT if q_tilt is None else q_tilt
    K = stiffness_matrix(pl, q_tilt, k)
    r = inverse_jacobian(pl, q_tilt)
    section.check(
        "zero-load stiffness = Aᵀ diag(k) A (gravity 0)",
        float(np.abs(stiffness_matrix(pl, q_tilt, k, gravity=0.0) - r.T @ np.diag(k) @ r).max() / np.abs(K).max()),
        1e-9,
    )
    h = 1e-6
    Kfd = -np.stack(
        [(static_wrench(pl, q_tilt, h * e, k) - static_wrench(pl, q_tilt, -h * e, k)) / (2 * h) for e in np.eye(6)], -1
    )
    section.check(
        "loaded stiffness vs central differences of the static wrench (relative)",
        float(np.abs(K - Kfd).max() / np.abs(K).max()),
        1e-8,
    )
    section.check(
        "loaded stiffness symmetric at the equilibrium (relative)",
        float(np.abs(K - K.T).max() / np.abs(K).max()),
        1e-12,
    )
    rows = []
    fig = plt.figure(figsize=(10, 8))
    for j, (name, q) in enumerate((("home", q_home), ("tilted", q_tilt))):
        Kq = stiffness_matrix(pl, q, k)
        pr = principal_stiffness(Kq)
        rows.append([name, *pr.translational, *pr.rotational])
        ax = fig.add_subplot(2, 2, 1 + j, projection="3d")
        _ellipsoid(ax, pr.translational / 1e3, pr.translational_dirs, "tab:blue")
        ax.set_title(f"{name}: translational (kN/m)", fontsize=9)
        ax = fig.add_subplot(2, 2, 3 + j, projection="3d")
        _ellipsoid(ax, pr.rotational / 1e3, pr.rotational_dirs, "tab:orange")
        ax.set_title(f"{name}: rotational (kN·m/rad)", fontsize=9)
    section.table(
        ["pose", "k_t1 (N/m)", "k_t2", "k_t3", "k_r1 (N·m/rad)", "k_r2", "k_r3"],
        rows,
        caption=f"Principal stiffnesses (softest first; from the compliance's blocks), legs {k[0]:g} N/m, {load}",
        fmt="{:.4g}",
    )
    section.figure(
        fig,
        "stiffness_ellipsoids",
        "Stiffness ellipsoids: semi-axes = principal stiffnesses along their directions (base frame)",
    )


def frequencies(section, p, k, pl=None, q_tilt=None, name_shown: str = PRESET) -> None:
    """Natural frequencies analytic vs Drake of ``p`` loaded as ``pl`` (default: the report's payload) at home and
    at ``q_tilt`` (default the preset's tilted pose)."""
    pl = with_payload(p, PAYLOAD_KG, PAYLOAD_COM) if pl is None else pl
    q_tilt = Q_TILT if q_tilt is None else q_tilt
    rows = []
    for name, q in (("home", p.home_pose()), ("tilted", q_tilt)):
        for legs in (False, True):
            a = analytic_modes(stiffness_matrix(pl, q, k, legs=legs), spatial_inertia(pl, q, legs=legs))
            d = drake_modes(pl, q, k, legs=legs)["modes"]
            rel = np.abs(d.frequencies_hz / a.frequencies_hz - 1)
            m = subspace_mac(a.shapes, d.shapes, a.frequencies_hz)
            what = "plate + legs" if legs else "plate only"
            section.check(
                f"{name}, {what}: Drake frequencies vs the analytic eigenproblem (relative)", float(rel.max()), 1e-6
            )
            section.check(
                f"{name}, {what}: 1 − MAC of the mode shapes (clusters of repeated modes: subspace)",
                float(1 - m.min()),
                1e-3,
            )
            for i in range(6):
                rows.append([name, what, i + 1, a.frequencies_hz[i], d.frequencies_hz[i], rel[i], m[i]])
    section.table(
        ["pose", "model", "mode", "analytic (Hz)", "Drake (Hz)", "relative diff", "MAC"],
        rows,
        caption="Natural frequencies: plate only via Drake's Linearize of a spring-leg plant; plate + legs via the closed-loop plant reduced to the plate's motion",
        fmt="{:.6g}",
    )
    q = q_tilt
    damped = analytic_modes(stiffness_matrix(pl, q, k), spatial_inertia(pl, q), damping_matrix(pl, q, 300.0))
    dd = drake_modes(pl, q, k, 300.0)["modes"]
    section.check(
        "damped (300 N·s/m legs): Drake frequencies vs analytic (relative)",
        float(np.abs(dd.frequencies_hz / damped.frequencies_hz - 1).max()),
        1e-6,
    )
    f1 = float(rows[6][3])
    section.text(
        f"Lowest mode of {name_shown} at home with legs and payload: {f1:.3g} Hz. The DSP's loop at {SAMPLE_RATE:g} Hz samples it "
        f"{SAMPLE_RATE / f1:.0f} times per period; its delay (one sample of output delay + half a sample of hold, {LOOP_DELAY * 1e3:g} ms) "
        f"lags that mode by {360 * f1 * LOOP_DELAY:.2g}°. A loop bandwidth well below f1 (a rule of thumb: ≤ f1/3 ≈ {f1 / 3:.2g} Hz) keeps the "
        "controller from exciting the structure; the sample rate is then ample, and a slower loop down to ≈ 20 samples per "
        f"period of the lowest mode ({20 * f1:.0f} Hz) would still resolve it."
    )


def maps(section, p, k) -> None:
    import matplotlib.pyplot as plt

    n = 31 if section.quick else 81
    # constrained from the start: colorbars added before the layout engine is set leave it unsolvable (the
    # figure was then saved as drawn, the yaw axis label under the left colorbar's)
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.5), layout="constrained")
    xy = ((-0.45, 0.45), (-0.45, 0.45))
    for ax, axes_, ranges, scale, labels in (
        (axes[0], (0, 1), xy, (1e3, 1e3), ("x (mm)", "y (mm)")),
        (axes[1], (0, 5), ((-0.3, 0.3), np.radians([-150.0, 150.0])), (1e3, 180 / np.pi), ("x (mm)", "yaw (°)")),
    ):
        m = slice_maps(p, axes_, ranges, n)
        X, Y = np.meshgrid(m.u * scale[0], m.v * scale[1], indexing="ij")
        c = ax.pcolormesh(
            X, Y, np.log10(np.minimum(m.condition, 1e4)), shading="auto", cmap="viridis_r", vmin=0.5, vmax=3
        )
        ax.contour(X, Y, m.safe.astype(float), levels=[0.5], colors="w", linewidths=2)
        other = (~m.same_mode & m.within).astype(float)
        if other.any():
            ax.contourf(X, Y, other, levels=[0.5, 1.5], colors="none", hatches=["//"])
        ax.set_xlabel(labels[0])
        ax.set_ylabel(labels[1])
        fig.colorbar(c, ax=ax, label="log10 condition number")
    axes[0].set_aspect("equal")
    section.figure(
        fig,
        "dexterity_maps",
        f"{PRESET}, other coordinates at home: white line = edge of the safe region (κ ≤ {SAFE_CONDITION:g}, "
        "home assembly mode, connected to home); hatched = the other assembly mode (det J⁻¹ changed sign through the "
        "singularity at yaw ±90°); blank = outside the stroke",
    )

    m = slice_maps(with_payload(p, PAYLOAD_KG, PAYLOAD_COM), (0, 1), xy, n, k=k, modes=True)
    X, Y = np.meshgrid(m.u * 1e3, m.v * 1e3, indexing="ij")
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.5), layout="constrained")
    c = axes[0].pcolormesh(X, Y, m.k_min / 1e3, shading="auto", cmap="magma")
    s = slice(None, None, max(1, n // 15))
    axes[0].quiver(
        X[s, s],
        Y[s, s],
        m.softest[s, s, 0],
        m.softest[s, s, 1],
        color="c",
        pivot="mid",
        headwidth=1,
        headlength=0,
        scale=25,
    )
    axes[0].set_title("min translational stiffness (kN/m), softest direction", fontsize=9)
    fig.colorbar(c, ax=axes[0])
    c = axes[1].pcolormesh(X, Y, m.f1, shading="auto", cmap="cividis")
    axes[1].set_title("lowest natural frequency (Hz)", fontsize=9)
    fig.colorbar(c, ax=axes[1])
    for ax in axes:
        ax.set_aspect("equal")
        ax.set_xlabel("x (mm)")
        ax.set_ylabel("y (mm)")
    section.figure(
        fig, "stiffness_frequency_maps", f"{PRESET}, legs {k[0]:g} N/m, {PAYLOAD_KG:g} kg payload, zero orientation"
    )


def presets(section) -> None:
    rows = []
    for name in PRESETS:
        p = load_preset(name)
        k = np.full(6, p.legs.stiffness or DEFAULT_K)
        q = p.home_pose()
        K = stiffness_matrix(p, q, k)
        pr = principal_stiffness(K)
        a = analytic_modes(K, spatial_inertia(p, q))
        d = drake_modes(p, q, k)["modes"]
        rel = float(np.abs(d.frequencies_hz / a.frequencies_hz - 1).max())
        section.check(f"{name} at home: Drake vs analytic frequencies (relative)", rel, 1e-6)
        rows.append(
            [
                name,
                k[0],
                "file" if p.legs.stiffness else "assumed",
                pr.translational[0],
                pr.rotational[0],
                a.frequencies_hz[0],
                a.frequencies_hz[-1],
                rel,
            ]
        )
    section.table(
        [
            "preset",
            "leg k (N/m)",
            "k from",
            "min k_t (N/m)",
            "min k_r (N·m/rad)",
            "f1 (Hz)",
            "f6 (Hz)",
            "Drake rel. diff",
        ],
        rows,
        caption="Each preset at its home pose, plate only",
        fmt="{:.4g}",
    )


def _user_tilt(p):
    """A tilted pose of the user's platform: home + ``USER_TILT``, halved until every leg is within its stroke."""
    for k in range(8):
        q = p.home_pose() + USER_TILT / 2**k
        L = leg_lengths(p, q)
        if np.all((L >= p.stroke[0]) & (L <= p.stroke[1])):
            return q
    return p.home_pose()


def _user_machine(section, subject) -> None:
    """Sizing along the user's motions (against Newton–Euler and the actuators' limits), then its stiffness and
    natural frequencies against Drake where the file gives the legs' stiffness."""
    p = subject.platform
    lim = p.legs
    section.text(
        f"{subject.name}: plate with its payload {p.mass:g} kg; actuator limits from {subject.source}: max_force "
        f"{lim.max_force:g} N" + (f", max_speed {lim.max_speed:g} m/s" if lim.max_speed else "") + ". Sizing "
        "along each motion with the legs' own inertia and weight; on the smooth seed and rotating motions the "
        "plate-only forces are checked against Newton–Euler by central differences of the pose (a second method; "
        "a program's or a table's moves join with jumps in their higher derivatives, where differences of the "
        "pose do not converge: their forces are checked against Drake in the inverse dynamics section)."
    )
    for spec, traj in zip(subject.motions or TRAJECTORY_NAMES, subject_trajectories(subject), strict=True):
        t = np.arange(EDGE_S, traj.duration - EDGE_S, 1e-3)
        q, qd, qdd = motion_rates(traj, t)
        s_legs = size_trajectory(p, t, q, qd, qdd, legs=True)
        section.table(
            LEG_HEADER, _rows(s_legs.legs()), caption=f"{traj.name} ({traj.duration:g} s at 1 kHz), legs included"
        )
        if spec in TRAJECTORY_NAMES:  # smooth: both differentiations hold to their truncation (see FD_REL_TOL)
            s_plate = size_trajectory(p, t, q, qd, qdd)
            F = newton_euler_fd(p, traj.pose, t)[0]
            scale = float(np.abs(s_plate.force).max())
            section.check(
                f"{traj.name}: sizing forces vs Newton–Euler from finite differences of the pose (relative to "
                f"{scale:.4g} N)",
                float(np.abs(s_plate.force - F).max()) / scale,
                FD_REL_TOL,
            )
        section.check(
            f"{traj.name}: peak leg force <= legs.max_force", float(np.abs(s_legs.force).max()), lim.max_force, "N"
        )
        if lim.max_speed:
            section.check(
                f"{traj.name}: peak leg speed <= legs.max_speed",
                float(np.abs(s_legs.speed).max()),
                lim.max_speed,
                "m/s",
            )
        section.check(
            f"{traj.name}: leg lengths outside the stroke {p.stroke[0]:g}..{p.stroke[1]:g} m (by how much)",
            float(max(0.0, p.stroke[0] - s_legs.length.min(), s_legs.length.max() - p.stroke[1])),
            0.0,
            "m",
        )
    if lim.stiffness is None:
        section.html(
            not_applicable_html(
                subject,
                f"stiffness and natural frequencies need {NEED_TEXT['legs.stiffness']}, which {subject.source} does not give",
            )
        )
        return
    k = np.full(6, lim.stiffness)
    q_tilt = _user_tilt(p)
    stiffness(section, p, k, pl=p, q_tilt=q_tilt, load="payload as in the file")
    frequencies(section, p, k, pl=p, q_tilt=q_tilt, name_shown=subject.name)


def build(section) -> None:
    if section.subject is not None:
        _user_machine(section, section.subject)
        return
    p = load_platform(PRESET)
    k = np.full(6, p.legs.stiffness)
    section.text(
        f"{PRESET}: actuator limits from the file (max_force {p.legs.max_force:g} N, max_speed {p.legs.max_speed} m/s), leg stiffness "
        f"{k[0]:g} N/m (assumed in the preset). Payload where used: {PAYLOAD_KG:g} kg at {PAYLOAD_COM.tolist()} m in the plate frame. "
        "Stiffness is about the rotation centre in base coordinates, [δp (m); δθ (rad)] → restoring [f (N); m (N·m)]."
    )
    sizing(section, p)
    stiffness(section, p, k)
    frequencies(section, p, k)
    maps(section, p, k)
    presets(section)


def main(argv=None):
    return run_standalone(__file__, argv)


if __name__ == "__main__":
    raise SystemExit(main())
