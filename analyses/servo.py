"""The RC-servo (6-RSS) hexapod of seed 002: arm angles and PWM pulses along a trajectory through the
50 Hz controller, Drake cross-checks, and the reachable set of the hobby-servo preset."""

from __future__ import annotations

import numpy as np

from stewart_drake.report import run_standalone
from stewart_drake.servo import hobby_servo_hexapod, solve
from stewart_drake.servo_model import IK_GAP_TOL_M, compare_with_drake, run_controller

TITLE = "RC-servo hexapod (seed 002): arm angles and PWM"
ORDER = 60
AXES = ["x (mm)", "y (mm)", "z (mm)", "phi (deg)", "theta (deg)", "psi (deg)"]


def axis_limits(h, direction, hi):
    """Largest step along ``direction`` (bisection) from home where every servo is reachable and in travel."""
    lo = 0.0
    for _ in range(40):
        mid = (lo + hi) / 2
        lo, hi = (mid, hi) if solve(h, h.home_pose() + mid * direction).ok else (lo, mid)
    return lo


def build(section) -> None:
    import matplotlib.pyplot as plt

    h = hobby_servo_hexapod()
    section.text(
        f"Preset hobby-servo (servo.hobby_servo_hexapod): arm a = {h.arm_length * 1e3:.0f} mm, rod s = {h.rod_length * 1e3:.0f} mm, "
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
    section.check(f"Drake InverseKinematics servo angles vs eq. 9 ({len(poses)} poses)", r["ik"], 2 * IK_GAP_TOL_M / (0.5 * h.arm_length), "rad")
    section.table(["check", "worst"], [["frames (m)", r["frames"]], ["home angles (rad)", r["home"]], ["FK rod length (m)", r["fk"]],
                                       ["IK angles (rad)", r["ik"]], ["FK with the odd/even sign ignored (m)", r["mirror_fk"]]],
                  caption="Drake cross-checks; the last row shows the check can fail: without the mirroring the rods are off by millimetres",
                  fmt="{:.3g}")

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
    section.figure(fig, "servo_trajectory", "Heave ±6 mm, roll ±8°, yaw ±15°: eq. 9 arm angles (top) and the controller's latched pulses (bottom)")
    sat = int(np.sum(log["status"] > 0))
    section.text(f"{len(log['t'])} frames logged, {sat} servo-frames clamped or unreachable; pulses span "
                 f"{log['pulse_us'].min():.0f}–{log['pulse_us'].max():.0f} µs.")

    # Reachable set: single-axis limits and an x-y slice at h0.
    rows = []
    for k in range(6):
        d = np.zeros(6)
        d[k] = 1.0
        hi = 0.1 if k < 3 else np.pi / 2
        plus, minus = axis_limits(h, d, hi), axis_limits(h, -d, hi)
        s = 1e3 if k < 3 else np.degrees(1.0)
        rows.append([AXES[k], -minus * s, plus * s])
    section.table(["axis", "min", "max"], rows, caption="Reachable range along each axis from home (all servos reachable and within ±45°)", fmt="{:.2f}")
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
    ax.legend(fontsize=8)
    section.figure(fig, "servo_reachable_xy", "Reachable platform positions (no rotation) at three heights")


def main(argv=None):
    return run_standalone(__file__, argv)


if __name__ == "__main__":
    raise SystemExit(main())
