"""The RC-servo (6-RSS) hexapod of seed 002: arm angles and PWM pulses along a trajectory through the
50 Hz controller, Drake cross-checks, and the reachable set of the hobby-servo preset."""

from __future__ import annotations

import numpy as np

from stewart_drake.drake.servo_model import IK_GAP_TOL_M, compare_with_drake, run_closed_loop, run_controller
from stewart_drake.mechanisms.servo import load_servo_hexapod, solve
from stewart_drake.mechanisms.servo_loop import servo_gains, tracking_bounds
from stewart_drake.report import run_standalone

TITLE = "RC-servo hexapod (seed 002): arm angles and PWM"
ORDER = 60
COST = 3  # CPU seconds (full report, measured): the report's workers start the costliest first
PRESET_ONLY = "it studies the RC-servo hexapod of seed 002, another mechanism"
AXES = ["x (mm)", "y (mm)", "z (mm)", "phi (deg)", "theta (deg)", "psi (deg)"]


def axis_limits(h, directions, hi):
    """``(m,)`` largest steps along ``directions`` (m, 6) from home where every servo is reachable and in travel:
    a bisection in [0, ``hi`` (m,)], all directions at once (one ``solve`` of m poses per halving)."""
    lo, hi = np.zeros(len(directions)), np.array(hi, dtype=float)
    for _ in range(40):
        mid = (lo + hi) / 2
        ok = solve(h, h.home_pose() + mid[:, None] * directions).ok
        lo, hi = np.where(ok, mid, lo), np.where(ok, hi, mid)
    return lo


def build(section) -> None:
    import matplotlib.pyplot as plt

    h = load_servo_hexapod("hobby-servo")
    section.text(
        f"Preset hobby-servo (presets/servo-hobby.yaml, layout in servo.hobby_servo_hexapod): arm a = {h.arm_length * 1e3:.0f} mm, rod s = {h.rod_length * 1e3:.0f} mm, "
        f"pivots on three pairs at 60 mm, anchors at 50 mm. Eq. 10 gives h0 = {h.home_height * 1e3:.3f} mm and eq. 12 "
        f"alpha0 = {np.degrees(h.home_angles[0]):.3f}° for every servo. Pose R = Rz(psi)·Ry(theta)·Rx(phi). Pulses: "
        "W = W0 ± (alpha − alpha0)·400 µs/45°, + for even and − for odd servos; the sign comes out of the mounting "
        "(horns facing the centre, clockwise = longer pulse)."
    )
    rng = np.random.default_rng(8)
    n = 8 if section.quick else 60
    poses = h.home_pose() + np.c_[rng.uniform(-0.008, 0.008, (n, 3)), rng.uniform(-0.1, 0.1, (n, 3))]
    poses = poses[solve(h, poses).ok]
    r = compare_with_drake(h, poses)
    section.check("servo SDF frames read back (pivots, anchors, arm length)", r["frames"], 1e-15, "m")
    section.check("Drake IK home joint angles vs eq. 12 alpha0 through the mounting", r["home"], 1e-6, "rad")
    section.check(f"Drake FK rod length at eq. 13-14 pulses ({len(poses)} poses)", r["fk"], 1e-12, "m")
    section.check(
        f"Drake InverseKinematics servo angles vs eq. 9 ({len(poses)} poses)",
        r["ik"],
        2 * IK_GAP_TOL_M / (0.5 * h.arm_length),
        "rad",
    )
    section.table(
        ["check", "worst"],
        [
            ["frames (m)", r["frames"]],
            ["home angles (rad)", r["home"]],
            ["FK rod length (m)", r["fk"]],
            ["IK angles (rad)", r["ik"]],
            ["FK with the odd/even sign ignored (m)", r["mirror_fk"]],
        ],
        caption="Drake cross-checks; the last row shows the check can fail: without the mirroring the rods are off by millimetres",
        fmt="{:.3g}",
    )

    # A trajectory through the 50 Hz controller with 1 µs quantisation.
    T = 1.0 if section.quick else 4.0
    t = np.linspace(0, T, int(T * 200) + 1)
    traj = np.tile(h.home_pose(), (len(t), 1))
    traj[:, 2] += 0.006 * np.sin(2 * np.pi * 0.5 * t)
    traj[:, 3] = np.radians(8) * np.sin(2 * np.pi * 1.0 * t)
    traj[:, 5] = np.radians(15) * np.sin(2 * np.pi * 0.25 * t)
    log = run_controller(h, t, traj)
    exact = solve(h, traj)
    fig, ax = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
    for i in range(6):
        ax[0].plot(t, np.degrees(exact.angles[:, i]), label=f"servo {i + 1}")
        ax[1].step(log["t"], log["pulse_us"][:, i], where="post")
    ax[0].set_ylabel("arm angle alpha (deg)")
    ax[0].legend(ncol=3, fontsize=8)
    ax[1].set_ylabel("pulse (µs), 50 Hz, 1 µs")
    ax[1].set_xlabel("t (s)")
    section.figure(
        fig,
        "servo_trajectory",
        "Heave ±6 mm, roll ±8°, yaw ±15°: eq. 9 arm angles (top) and the controller's latched pulses (bottom)",
    )
    sat = int(np.sum(log["status"] > 0))
    section.text(
        f"{len(log['t'])} frames logged, {sat} servo-frames clamped or unreachable; pulses span "
        f"{log['pulse_us'].min():.0f}–{log['pulse_us'].max():.0f} µs."
    )

    # The same trajectory with the loop closed: controller → servos (PD, speed limit) → closed-loop plant.
    closed_loop(section, h, t, traj)

    # Reachable set: single-axis limits and an x-y slice at h0.
    rows = []
    hi = np.where(np.arange(6) < 3, 0.1, np.pi / 2)
    plus, minus = np.split(axis_limits(h, np.vstack([np.eye(6), -np.eye(6)]), np.r_[hi, hi]), 2)
    for k in range(6):
        s = 1e3 if k < 3 else np.degrees(1.0)
        rows.append([AXES[k], -minus[k] * s, plus[k] * s])
    section.table(
        ["axis", "min", "max"],
        rows,
        caption="Reachable range along each axis from home (all servos reachable and within ±45°)",
        fmt="{:.2f}",
    )
    m = 41 if section.quick else 121
    xs = np.linspace(-0.04, 0.04, m)
    X, Y = np.meshgrid(xs, xs)
    fig, ax = plt.subplots(figsize=(5, 5))
    for dz, c in ((-0.01, "tab:blue"), (0.0, "tab:green"), (0.01, "tab:orange")):
        P = np.zeros(X.shape + (6,))
        P[..., 0], P[..., 1], P[..., 2] = X, Y, h.home_height + dz
        ok = solve(h, P).ok
        ax.contour(X * 1e3, Y * 1e3, ok.astype(float), levels=[0.5], colors=c)
        ax.plot([], [], color=c, label=f"z = h0 {dz * 1e3:+.0f} mm ({ok.mean() * 100:.0f}% of the square)")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.set_aspect("equal")
    ax.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.12))  # below the axes, off the contours
    section.figure(fig, "servo_reachable_xy", "Reachable platform positions (no rotation) at three heights")


def closed_loop(section, h, t, traj) -> None:
    """The 50 Hz controller driving the Drake servo plant: tracking error vs its bound, rod gaps."""
    import matplotlib.pyplot as plt

    kp, kd = servo_gains(h)
    log = run_closed_loop(h, t, traj)
    b = tracking_bounds(h, log)
    arm = np.abs(log["arm_angle"] - log["arm_angle_ref"])
    err = log["pose"] - log["reference"]
    settled = log["t"] >= 0.1
    section.text(
        f"Closed loop (servo_model.run_closed_loop): the controller's pulses drive six servo models in one Diagram with the "
        f"ball-constrained plant (1 ms SAP steps). Servo: a DC motor behind a proportional loop, Drake's implicit PD "
        f"clamped to the {h.servo_torque:g} N·m stall torque, kp = stall torque / {np.degrees(h.servo_band):g}° = {kp:.1f} N·m/rad, "
        f"kd = stall torque / no-load speed ({np.degrees(h.servo_speed) / 60:.3g}⁻¹ s per 60° → {kd:.3f} N·m·s/rad), "
        f"set-point slewed at the no-load speed. Bound on each arm's error: the reference's change over the loop latency "
        f"{b['lag'] * 1e3:.1f} ms (20 ms frame + 2 steps + kd/kp) + half a pulse step ({np.degrees(b['quantisation']):.3f}°) + "
        f"sag under load (≤ {np.degrees(b['sag'].max()):.3f}°); on the pose: its Jacobian image."
    )
    rows = [
        [
            AXES[k],
            abs(err[:, k]).max() * (1e3 if k < 3 else np.degrees(1)),
            b["pose"][:, k].max() * (1e3 if k < 3 else np.degrees(1)),
        ]
        for k in range(6)
    ]
    rows.append(["arm angle (deg)", np.degrees(arm.max()), np.degrees(b["arm"].max())])
    section.table(
        ["quantity", "worst error", "worst bound"],
        rows,
        caption="Closed-loop tracking, worst over the run",
        fmt="{:.3f}",
    )
    section.check(
        "closed-loop arm angle error / its bound (per servo, worst over the run)",
        (arm.max(0) / b["arm"].max(0)).max(),
        1.0,
        "ratio",
    )
    section.check(
        "closed-loop pose error / its bound (per axis, worst over the run)",
        (np.abs(err).max(0) / b["pose"].max(0)).max(),
        1.0,
        "ratio",
    )
    section.check("closed-loop rod constraint violation (t >= 0.1 s)", log["rod_gap"][settled].max(), 1e-5, "m")
    fig, ax = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
    for k, lab in ((0, "x"), (1, "y"), (2, "z")):
        ax[0].plot(log["t"], err[:, k] * 1e3, label=lab)
    ax[0].set_ylabel("position error (mm)")
    ax[0].legend(fontsize=8)
    for k, lab in ((3, "phi"), (4, "theta"), (5, "psi")):
        ax[1].plot(log["t"], np.degrees(err[:, k]), label=lab)
        ax[1].plot(log["t"], np.degrees(b["pose"][:, k]), ls=":", color=ax[1].lines[-1].get_color())
    ax[1].set_ylabel("angle error (deg); dotted: bound")
    ax[1].set_xlabel("t (s)")
    ax[1].legend(fontsize=8)
    section.figure(
        fig,
        "servo_closed_loop",
        "Closed loop: platform pose (Drake) minus the reference; the 20 ms frame latency dominates",
    )
    section.text(
        f"Rod constraint violation: ≤ {log['rod_gap'][settled].max():.2g} m after 0.1 s (start-up kick "
        f"{log['rod_gap'].max():.2g} m in the first steps); no servo clamped ({int(np.sum(log['status'] > 0))} servo-samples)."
    )


def main(argv=None):
    return run_standalone(__file__, argv)


if __name__ == "__main__":
    raise SystemExit(main())
