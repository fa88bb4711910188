"""Three engines: the presets' kinematics, inverse dynamics, task-space inertia and forward simulation in Pinocchio
and MuJoCo against the closed forms, the passive fall against Drake's closed-loop plant and the float-law loop against
``sd.simulate``'s."""

from __future__ import annotations

import numpy as np

from stewart_drake.api.cross_check import drake_loop_check
from stewart_drake.core.dynamics import leg_forces_with_legs
from stewart_drake.core.geometry import PRESETS, load_preset
from stewart_drake.drake.verify_dynamics import constrained_leg_forces, simulate_open_loop
from stewart_drake.engines import cross_check as X
from stewart_drake.report import run_standalone

TITLE = "Three engines"
ORDER = 42
COST = 7  # CPU seconds (full report, measured): the report's workers start the costliest first
DRAKE_STEPS = (1e-3, 5e-4)
LOOP_SOLREF = (
    0.02,
    0.002,
)  # s: MuJoCo's default connect time constant and a stiff one  # s: Drake's discrete plant at two steps, for its first-order error


def drake_fall(platform, dt: float) -> np.ndarray:
    """The plate's distance from home (m) every 0.05 s of Drake's passive fall (no leg force) at step ``dt``."""
    t = np.arange(0.0, X.RELEASE_DURATION + dt / 2, dt)
    q = np.tile(platform.home_pose(), (len(t), 1))
    zero = np.zeros_like(q)
    return simulate_open_loop(platform, t, q, zero, zero, dt, record_every=int(round(X.RECORD / dt)))["position_error"]


def build(section) -> None:
    status = X.engine_status()
    missing = [reason for reason in status.values() if reason is not None]
    if len(missing) == len(status):
        section.text("Skipped: " + "; ".join(missing) + ".")
        return
    n = 100 if section.quick else 1000
    kin_rows, dyn_rows, sim_rows, fall_rows, loop_rows = [], [], [], [], []
    for name in PRESETS:
        p = load_preset(name)
        res = X.cross_check(p, poses=n, samples=7 if section.quick else 13)
        releases = {}
        # Drake's closed-loop plant on the same trajectories: the third engine's leg forces (its own [B Gᵀ] solve)
        for traj, (q, qd, qdd) in X.trajectories(p, 7 if section.quick else 13).items():
            F_ref = leg_forces_with_legs(p, q, qd, qdd)
            scale = float(np.abs(F_ref).max())
            rel = float(np.abs(constrained_leg_forces(p, q, qd, qdd) - F_ref).max()) / scale
            kappa = (
                res["pinocchio"]["dynamics"][traj]["condition"] if res.get("pinocchio", {}).get("available") else 1e3
            )
            dyn_rows.append([name, "drake", traj, scale, rel, kappa])
            section.check(
                f"{name}: drake leg forces along the {traj} trajectory, relative",
                rel,
                X.DYNAMIC_ROUNDING * kappa * X.EPS,
            )
        for engine, r in res.items():
            if not r["available"]:
                continue
            k, m = r["kinematics"], r["modes"]
            kin_rows.append(
                [name, engine, k["closure_residual_m"], k["leg_length_error_m"], m["mass_matrix_relative_error"]]
            )
            section.check(
                f"{name}: {engine} closure residual ({n} poses)", k["closure_residual_m"], k["tolerance_m"], "m"
            )
            section.check(f"{name}: {engine} leg lengths ({n} poses)", k["leg_length_error_m"], k["tolerance_m"], "m")
            section.check(
                f"{name}: {engine} task-space inertia, relative",
                m["mass_matrix_relative_error"],
                m["tolerance_relative"],
            )
            for traj, d in r["dynamics"].items():
                dyn_rows.append([name, engine, traj, d["max_force_n"], d["relative_error"], d["condition"]])
                section.check(
                    f"{name}: {engine} leg forces along the {traj} trajectory, relative",
                    d["relative_error"],
                    d["tolerance_relative"],
                )
            ol = r["open_loop"]
            if engine == "pinocchio":
                sim_rows.append([name, engine, "rigid", ol["position_error_m"], ol["constraint_m"]])
                section.check(f"{name}: pinocchio open loop, plate error", ol["position_error_m"], ol["bound_m"], "m")
            else:
                for tau, gap, err in zip(ol["solref_s"], ol["constraint_m"], ol["position_error_m"]):
                    sim_rows.append([name, engine, f"solref {tau * 1e3:g} ms", err, gap])
                # a spring of stiffness ∝ 1/τ²: from τ = 20 to 2 ms the stretch falls faster than τ (× 0.1)
                ratio = ol["constraint_m"][-1] / ol["constraint_m"][0]
                section.check(f"{name}: mujoco closure stretch, τ = 2 ms / τ = 20 ms", ratio, 0.1)
            releases[engine] = X.passive_release(engine, p)
        if "pinocchio" not in releases:
            continue
        if "mujoco" in releases:
            loop = X.float_loop("pinocchio", p)
            row = [name, loop["tracking_m"]]
            for tau in LOOP_SOLREF:
                other = X.float_loop("mujoco", p, solref=(tau, 1.0))
                row += [other["tracking_m"], float(np.linalg.norm(other["p"] - loop["p"], axis=-1).max())]
            loop_rows.append(row)
            section.check(
                f"{name}: float-law loop, MuJoCo − Pinocchio plate at solref 2 ms / at 20 ms (≤ a tenth)",
                row[-1] / row[3],
                0.1,
            )
        ref = releases["pinocchio"]
        falls = [drake_fall(p, dt) for dt in DRAKE_STEPS]
        # Drake's discrete plant is first order in its step: fall(dt) = fall + c·dt + O(dt²); two steps cancel c
        extrapolated = 2 * falls[1] - falls[0]
        T, dt = X.RELEASE_DURATION, DRAKE_STEPS[0]
        second_order = ref["drop"].max() * (dt / T) ** 2
        worst = float(np.abs(extrapolated - ref["drop"]).max())
        section.check(f"{name}: Drake's passive fall (extrapolated to dt → 0) vs Pinocchio's", worst, second_order, "m")
        row = [name, ref["drop"].max(), float(np.abs(falls[0] - ref["drop"]).max()), worst]
        row.append(float(np.abs(releases["mujoco"]["drop"] - ref["drop"]).max()) if "mujoco" in releases else np.nan)
        row += [ref["energy_drift_j"], releases["mujoco"]["energy_drift_j"] if "mujoco" in releases else np.nan]
        fall_rows.append(row)
    section.text(
        "Every preset's model is written for Pinocchio (URDF of the open tree, the six ball closures as "
        "RigidConstraintModel) and MuJoCo (MJCF, the closures as connect equalities) from the same Platform. "
        "Kinematics: the legs are set to the closed-form joint positions at seeded poses and each engine's forward "
        "kinematics closes the loops to rounding. Inverse dynamics: the engines have no constraint-aware inverse "
        "dynamics either; the legs' rates come from the closures and [B Gᵀ][u; λ] = τ_ID gives the leg forces, "
        "equal to the closed form with the legs' inertia to rounding (tolerance 1000 κ ε, κ the system's condition "
        "number). MuJoCo's soft constraints do not enter that number; they show in simulation."
    )
    if missing:
        section.text("Not run: " + "; ".join(missing) + ".")
    section.table(
        ["preset", "engine", "closure residual (m)", "leg length error (m)", "task-space inertia (rel.)"],
        kin_rows,
        caption=f"Kinematics at {n} poses and the inertia at home and nine poses, worst",
        fmt="{:.3g}",
    )
    section.table(
        ["preset", "engine", "trajectory", "max force (N)", "error (rel.)", "κ"],
        dyn_rows,
        caption="Leg forces (legs' inertia included) against the closed form",
        fmt="{:.3g}",
    )
    section.text(
        "Forward simulation: the closed-form forces of the seed sway applied open loop for 0.5 s. Pinocchio "
        "(constraintDynamics, RK4, forces linear over each 1 ms step) follows the plan to the forces' interpolation "
        "error. MuJoCo's connect is a spring–damper: it stretches under load by about τ² (less where its impedance "
        "rises with the stretch) and the plate's error shrinks with it; with MuJoCo's default Euler integrator its "
        "own first-order error (≈ 0.3 mm here) hides the softness, so it runs with RK4."
    )
    section.table(
        ["preset", "engine", "closures", "plate error (m)", "closure gap (m)"],
        sim_rows,
        caption="Open loop along the seed sway, 0.5 s",
        fmt="{:.3g}",
    )
    section.text(
        f"Passive fall: the platform released at rest from home for {X.RELEASE_DURATION:g} s (no leg force; every "
        "leg stays in stroke: the engines' models carry no stroke limits, Drake's SDF does, and a longer fall of "
        "utn-dynamic reaches L_min in Drake alone). Drake's discrete plant is first order in its step: its fall at "
        "1 ms differs from Pinocchio's by drop × dt / T, and extrapolated from 1 and 0.5 ms it agrees to the second "
        "order. Pinocchio keeps the energy to RK4's error; MuJoCo's damped closures lose some."
    )
    section.table(
        [
            "preset",
            "drop (m)",
            "Drake 1 ms − Pinocchio (m)",
            "Drake extrapolated − Pinocchio (m)",
            "MuJoCo − Pinocchio (m)",
            "Pinocchio energy drift (J)",
            "MuJoCo energy drift (J)",
        ],
        fall_rows,
        caption="Passive fall from home",
        fmt="{:.3g}",
    )
    _loop_table(section, loop_rows)
    if status["pinocchio"] is None:
        drake_loop(section, ["utn-dynamic"] if section.quick else list(PRESETS))


def drake_loop(section, presets) -> None:
    """The float-law loop of ``sd.simulate`` beside the same loop on Pinocchio (``api.cross_check.drake_loop_check``)
    for each preset name in ``presets``: a row each, two checks each (first order in the step, within the bound)."""
    rows = []
    for name in presets:
        r = drake_loop_check(load_preset(name))
        if r["ok"] is None:
            section.text(f"{name}: the float-law loop against Drake's not run ({r['reason']}).")
            continue
        f = r["fine"]
        rows.append(
            [
                name,
                r["position_m"],
                r["length_m"],
                f["position_m"][0],
                f["position_m"][1],
                r["step_ratio"],
                r["bound_m"],
            ]
        )
        section.check(
            f"{name}: float-law loop, Pinocchio − Drake plate with a 1 nm sensor, |ratio at h/2 − ½|",
            abs(r["step_ratio"] - 0.5),
            0.25,
        )
        section.check(
            f"{name}: float-law loop, Pinocchio − Drake plate with a 1 nm sensor (≤ ½ h T max|a|)",
            f["position_m"][0],
            r["bound_m"],
            "m",
        )
    section.text(
        f"The float-law loop of sd.simulate (the seed fitted to the stroke, {X.LOOP_DURATION:g} s, the machine's "
        "defaults) run again on Pinocchio with the same law, tick, output delay, actuators, start and feed-forward: "
        "only the plant differs. Drake's CENIC step is first order, Pinocchio's RK4 fourth: with a 1 nm sensor (no "
        "count flips between plants micrometres apart) the plates part by Drake's step error alone, which halves "
        "with the plant step and stays below ½ h T max|a|, its local error ½ h² |a| summed over the run. With the "
        "machine's sensor a count flipped in one run and not the other adds about a count."
    )
    section.table(
        [
            "preset",
            "plate, machine's sensor (m)",
            "legs, machine's sensor (m)",
            "plate, 1 nm sensor, h (m)",
            "plate, 1 nm sensor, h/2 (m)",
            "ratio",
            "bound ½ h T max|a| (m)",
        ],
        rows,
        caption="Float-law loop, Pinocchio against Drake's sd.simulate: worst distances",
        fmt="{:.3g}",
    )


def _loop_table(section, rows) -> None:
    if not rows:
        return
    section.text(
        f"The float PID law (its gains and period designed for the platform) closing the loop along the seed sway "
        f"for {X.LOOP_DURATION:g} s with the closed-form feed-forward, the legs' true lengths read each tick and the "
        "command held over the next period. Pinocchio's rigid model tracks to the sensor's resolution. MuJoCo's "
        "closures enter the loop as a compliance in series with the legs, which the law (it reads leg lengths) "
        "cannot see: at its default solref (20 ms) the heavy utn-kinematic plate sinks through its closures and the "
        "loop loses it; the departure from Pinocchio shrinks as the closures stiffen (2 ms). A loop simulated on "
        "MuJoCo's defaults would take that compliance for the machine's."
    )
    section.table(
        [
            "preset",
            "Pinocchio tracking (m)",
            "MuJoCo 20 ms tracking (m)",
            "MuJoCo 20 ms − Pinocchio (m)",
            "MuJoCo 2 ms tracking (m)",
            "MuJoCo 2 ms − Pinocchio (m)",
        ],
        rows,
        caption="Float-law loop along the seed sway: worst plate-origin distances",
        fmt="{:.3g}",
    )


def main(argv=None):
    return run_standalone(__file__, argv)


if __name__ == "__main__":
    raise SystemExit(main())
