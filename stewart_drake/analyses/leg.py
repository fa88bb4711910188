"""The 3R planar leg of seed 003: DH forward kinematics against Drake, the corrected geometric inverse
kinematics (both branches) against Drake's InverseKinematics, the seed's errors, and the workspace."""

from __future__ import annotations

import numpy as np

from stewart_drake.core.rotations import wrap_angle
from stewart_drake.drake.leg_model import drake_fk_errors, drake_ik
from stewart_drake.mechanisms.leg3r import (
    SEED_FIX_TEXT,
    SEED_FIXES,
    Leg3R,
    foot,
    foot_jacobian,
    inverse_kinematics,
    inverse_kinematics_3r,
    joint_points,
    random_configurations,
    seed_inverse_kinematics,
)
from stewart_drake.report import run_standalone

TITLE = "3R planar leg (seed 003): DH kinematics"
ORDER = 70
COST = 2  # CPU seconds (full report, measured): the report's workers start the costliest first
PRESET_ONLY = "it studies the 3R planar leg of seed 003, another mechanism"


def build(section) -> None:
    import matplotlib.pyplot as plt

    leg = Leg3R()
    n = 100 if section.quick else 1000
    section.text(
        f"Default leg (our choice; the seed gives no numbers): l1 = {leg.l1 * 1e3:.0f} mm, l2 = {leg.l2 * 1e3:.0f} mm, "
        f"l3 = {leg.l3 * 1e3:.0f} mm, fixed ankle alpha = 134.6° − 180° = −45.4°, hip q1 ∈ [−90°, 90°], knee q2 ∈ [−135°, 135°]. "
        "The SDF sdf/leg-3r.sdf is generated row by row from the DH table."
    )
    q = random_configurations(leg, n, seed=11)
    section.check(f"DH frames T_0^i vs Drake X_dh0,dhi ({n} configurations)", drake_fk_errors(leg, q).max(), 1e-14)
    p = foot(leg, q)[:, :2]
    rows = []
    for b in "ab":
        qn = inverse_kinematics(leg, p, b)
        rt = np.abs(foot(leg, qn)[:, :2] - p).max()
        qd, gap = drake_ik(leg, p, b)
        d = np.abs(wrap_angle(qd - qn)).max(1)
        bound = np.linalg.norm(np.linalg.inv(foot_jacobian(leg, qn)), 2, axis=(-2, -1)) * gap
        section.check(f"branch {b}: IK → FK round trip ({n} targets)", rt, 1e-12, "m")
        section.check(
            f"branch {b}: Drake IK angles minus 2·||J⁻¹||·(Drake's foot gap)",
            float(np.max(d - 2 * bound)),
            1e-12,
            "rad",
        )
        rows.append([b, rt, d.max(), gap.max()])
    section.table(
        ["branch", "IK→FK (m)", "|q_Drake − q_ours| (rad)", "Drake foot gap (m)"],
        rows,
        caption="Geometric IK vs Drake's InverseKinematics (SNOPT, knee boxed to the branch)",
        fmt="{:.3g}",
    )

    # The seed's inverse kinematics, fix by fix.
    f = foot(leg, q)
    rows = []
    for k in range(len(SEED_FIXES) + 1):
        s = seed_inverse_kinematics(leg, f, "a", SEED_FIXES[:k])
        ok = np.all(np.isfinite(s), axis=1)
        err = np.hypot(*(foot(leg, s[ok]) - f[ok])[:, :2].T)
        rows.append(
            [
                "as printed" if k == 0 else "+ " + SEED_FIX_TEXT[SEED_FIXES[k - 1]],
                f"{ok.mean() * 100:.0f}%",
                float(err.max() * 1e3) if ok.any() else float("nan"),
                float(np.median(err) * 1e3) if ok.any() else float("nan"),
            ]
        )
    section.table(
        ["seed eqs. 13-20", "targets with a real solution", "worst foot error (mm)", "median (mm)"],
        rows,
        caption="Branch a, targets from random configurations: each correction is needed",
        fmt="{:.3g}",
    )
    full = seed_inverse_kinematics(leg, f, "a", SEED_FIXES)
    section.check(
        "seed IK with every fix = inverse_kinematics_3r",
        float(np.abs(wrap_angle(full - inverse_kinematics_3r(leg, f, "a"))).max()),
        1e-12,
        "rad",
    )

    # Workspace.
    m = 60 if section.quick else 200
    g1, g2 = np.meshgrid(np.linspace(*leg.q1_limits, m), np.linspace(*leg.q2_limits, m))
    qq = np.stack([g1.ravel(), g2.ravel()], -1)
    P = foot(leg, qq)
    _, phi = leg.shank
    a = wrap_angle(qq[:, 1] + phi) >= 0
    fig, ax = plt.subplots(figsize=(6, 6))
    ax.scatter(P[a, 0] * 1e3, P[a, 1] * 1e3, s=1, alpha=0.3, label="branch a (knee ≥ 0)")
    ax.scatter(P[~a, 0] * 1e3, P[~a, 1] * 1e3, s=1, alpha=0.3, label="branch b (knee ≤ 0)")
    for r in leg.reach:
        th = np.linspace(0, 2 * np.pi, 200)
        ax.plot(r * 1e3 * np.cos(th), r * 1e3 * np.sin(th), "k:", lw=0.8)
    pts = joint_points(leg, np.radians([20.0, 50.0]))
    ax.plot(pts[:, 0] * 1e3, pts[:, 1] * 1e3, "k-o", label="q = (20°, 50°)")
    ax.set_aspect("equal")
    ax.set_xlabel("Px (mm)")
    ax.set_ylabel("Py (mm)")
    ax.legend(fontsize=8, markerscale=6)
    section.figure(
        fig, "leg_workspace", "Foot workspace within the joint limits; dotted: the reach annulus without limits"
    )


def main(argv=None):
    return run_standalone(__file__, argv)


if __name__ == "__main__":
    raise SystemExit(main())
