"""Cross-checks of the closed forms of ``core`` against Pinocchio and MuJoCo.

- **Kinematics** (``kinematics_check``): at seeded poses, the legs are set to our closed-form joint positions
  (``leg_bodies.leg_joint_positions``) and the engine's forward kinematics places the piston tips and plate
  anchors: the closure residual |tip − anchor| and the engine's anchor-to-anchor distance against our
  ``leg_lengths``. Both are exact in exact arithmetic; the model text carries 15 significant digits (half a unit
  in the 15th digit: 5e-15 relative per number) and a forward-kinematics chain some 20 double-precision operations
  (≈ 20 × 1.1e-16): the worst error is ~1e-13 of the platform's size. ``KINEMATIC_TOL_REL`` = 1e-12 of the
  longest leg is a decade above that; a millimetre-sized model error is nine decades above it.
- **Inverse dynamics** (``dynamics_check``): leg forces along a trajectory from the engine's rigid-body algorithm
  with the closures (``PinocchioPlatform.leg_forces``, ``MujocoPlatform.leg_forces``) against
  ``dynamics.leg_forces_with_legs``. Each side is a double-precision evaluation of the same physics; the engines
  solve the 24 × 24 system [B Gᵀ], which amplifies rounding by its condition number κ. The tolerance is
  ``DYNAMIC_ROUNDING`` × κ × ε of the largest force (κ measured per run, ε the double precision epsilon).

- **Forward simulation** (``open_loop_check``, ``passive_release``): the closed-form forces along the seed sway
  applied open loop from the trajectory's first state, and the passive platform released at rest from home. Pinocchio
  (rigid closures, ``constraintDynamics``, RK4 with the forces linear over each step) should follow the plan to the
  forces' interpolation error: |F̈| dt²/8 per leg, six legs on the plate's mass, grown as ½ δa T²
  (``pinocchio_open_loop_bound``). MuJoCo's ``connect`` is a spring–damper (stiffness 1/(d_max² τ² ζ²) per unit
  effective mass for ``solref`` = (τ, ζ)): under load it stretches by ∝ τ², less where its impedance d rises with
  the stretch; the check runs it with RK4 at several τ and reports the stretch and the plate's error per τ.

- **Mass matrix and modes** (``modes_check``): the engine's inertia reduced to the plate's Cartesian coordinates
  (Sᵀ M S, the legs' rates from the closures) against ``design.modes.spatial_inertia(legs=True)``, and the natural
  frequencies of K φ = ω² M φ (K: ``design.stiffness``) with either; rounding bound as for the forces, with κ the
  condition number of the legs' closure block.

The engines are optional (``pip install .[engines]``): ``engine_status`` says which are importable and why not.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg

from stewart_drake.control.laws import FloatLaw
from stewart_drake.core.dynamics import G_EARTH, harmonic_trajectory, leg_forces_with_legs
from stewart_drake.core.geometry import Platform
from stewart_drake.core.kinematics import leg_lengths, length_jacobian, stroke_within
from stewart_drake.core.sampling import random_poses
from stewart_drake.design.modes import spatial_inertia
from stewart_drake.design.stiffness import stiffness_matrix
from stewart_drake.engines.models import MJCF_SOLREF, mjcf_text, modelled_platform
from stewart_drake.engines.plate import plate_state

# Each engine is an optional extra: a missing one is reported by ``engine_status``, not raised at import.
MISSING: dict = {}
try:
    from stewart_drake.engines import pinocchio_engine
except ImportError as e:
    pinocchio_engine, MISSING["pinocchio"] = None, str(e)
try:
    from stewart_drake.engines import mujoco_engine
except ImportError as e:
    mujoco_engine, MISSING["mujoco"] = None, str(e)

ENGINES = ("pinocchio", "mujoco")
_MODULES = {"pinocchio": pinocchio_engine, "mujoco": mujoco_engine}
_CLASSES = {"pinocchio": "PinocchioPlatform", "mujoco": "MujocoPlatform"}
KINEMATIC_TOL_REL = 1e-12  # of the longest leg, m/m (see the module docstring)
# Rounding of a 24-unknown elimination and of the closed form's ~100 operations per force: a bound of
# (24 + 100) × κ × ε on the relative error; 1000 leaves it a factor eight.
DYNAMIC_ROUNDING = 1000.0
EPS = float(np.finfo(float).eps)
TRAJECTORIES = ("seed", "rotating")
SIM_STEP = 1e-3  # s, both engines' step in the simulation checks
SIM_DURATION = 0.5  # s of open-loop tracking
# s of passive fall from home: the plate drops ~11 cm and every preset's legs stay in stroke (the engines' models
# carry no stroke limits; Drake's SDF stops a leg at L_min)
RELEASE_DURATION = 0.15
SOLREF_TIMES = (0.02, 0.01, 0.005, 0.002)  # s, MuJoCo's connect time constants swept (≥ 2 steps: its stability floor)
RECORD = 0.05  # s between recorded samples
MODE_POSES = 10  # home and the first nine kinematic poses


def engine_status() -> dict:
    """engine name -> None when importable, else the one-line reason it is not."""
    return {
        name: None
        if name not in MISSING
        else f"{name} is not installed ({MISSING[name]}); pip install 'stewart-drake[engines]'"
        for name in ENGINES
    }


def engine_model(name: str, platform: Platform, **texts):
    """The platform in engine ``name`` ("pinocchio" | "mujoco"); ``texts`` replace the generated model text
    (``urdf=``, ``closure_list=`` for Pinocchio, ``mjcf=`` for MuJoCo). Raises ImportError when it is missing."""
    if _MODULES[name] is None:
        raise ImportError(engine_status()[name])
    return getattr(_MODULES[name], _CLASSES[name])(platform, **texts)


SWAY = ([0, 1 / 4, 0, 0, 0, 0], 2.0)  # amplitudes (× stroke range), rad/s: the seed's sideways sway
ROTATING = ([1 / 20] * 3, 0.2, [1.3, 2.1, 1.7, 3.0, 2.5, 3.5], [0.1, 0.2, 0.3, 0.4, 0.5, 0.6])
MAX_HALVINGS = 20


def _in_stroke(platform: Platform, make, t) -> tuple:
    """``make(t, scale)`` at the largest scale 2⁻ᵏ (k ≤ ``MAX_HALVINGS``) whose poses keep every leg in stroke."""
    for k in range(MAX_HALVINGS + 1):
        out = make(t, 0.5**k)
        if stroke_within(platform, leg_lengths(platform, out[0])).all():
            return out
    # internal: a pose within 1e-6 of home is in stroke for any platform that loads (home is checked then)
    raise ValueError(f"no in-stroke cross-check trajectory about the home pose of {platform.name!r}")


def sway(platform: Platform, t) -> tuple:
    """``(q, qd, qdd)`` ``t.shape + (6,)``: the seed's sideways sway about home, y = A sin 2t with A a quarter of the
    stroke range (halved until every leg stays in stroke)."""
    home, s = platform.home_pose(), platform.L_max - platform.L_min
    amp, omega = SWAY
    return _in_stroke(platform, lambda t, c: harmonic_trajectory(t, home, np.multiply(amp, s * c), omega), t)


def trajectories(platform: Platform, n: int = 13, duration: float = 3.0) -> dict:
    """name -> ``(q, qd, qdd)`` ``(n, 6)`` each over ``duration`` s: ``seed`` (``sway``), ``rotating`` all six
    coordinates about home (translations a twentieth of the stroke range, rotations 0.2 rad, incommensurate
    frequencies 1.3–3.5 rad/s; halved until every leg stays in stroke)."""
    t = np.linspace(0.0, duration, n)
    home, s = platform.home_pose(), platform.L_max - platform.L_min
    trans, rot, omega, phase = ROTATING

    def rotating(t, c):
        return harmonic_trajectory(t, home, np.concatenate([np.multiply(trans, s * c), [rot * c] * 3]), omega, phase)

    return {"seed": sway(platform, t), "rotating": _in_stroke(platform, rotating, t)}


def kinematics_check(engine, platform: Platform, poses, convention: str = "utn") -> dict:
    """The engine's closure residuals and leg lengths at ``(n, 6)`` poses against ours (see the module docstring).

    Returns ``poses``, ``closure_residual_m`` (worst over poses and legs), ``leg_length_error_m``, ``tolerance_m``
    and ``ok``."""
    res = engine.closure_residuals(poses, convention)
    err = np.abs(engine.leg_lengths(poses, convention) - leg_lengths(platform, poses, convention))
    tol = KINEMATIC_TOL_REL * platform.L_max
    worst_res, worst_len = float(res.max()), float(err.max())
    return {
        "poses": len(res),
        "closure_residual_m": worst_res,
        "leg_length_error_m": worst_len,
        "tolerance_m": tol,
        "ok": bool(worst_res <= tol and worst_len <= tol),
    }


def dynamics_check(engine, platform: Platform, q, qd, qdd, convention: str = "utn", condition: float = 1.0) -> dict:
    """The engine's leg forces along ``(n, 6)`` q, q̇, q̈ against ``leg_forces_with_legs``; ``condition`` κ of the
    engine's [B Gᵀ] (see the module docstring).

    Returns ``samples``, ``max_force_n``, ``max_error_n``, ``relative_error``, ``tolerance_relative``, ``ok``."""
    F = engine.leg_forces(q, qd, qdd, convention)
    F_ref = leg_forces_with_legs(platform, q, qd, qdd, convention)
    scale = float(np.abs(F_ref).max())
    err = float(np.abs(F - F_ref).max())
    rel = err / scale if scale > 0 else err
    tol = DYNAMIC_ROUNDING * condition * EPS
    return {
        "samples": len(F),
        "max_force_n": scale,
        "max_error_n": err,
        "relative_error": rel,
        "tolerance_relative": tol,
        "condition": condition,
        "ok": bool(rel <= tol),
    }


def cross_check(
    platform: Platform,
    engines=None,
    poses: int = 1000,
    samples: int = 13,
    seed: int = 0,
    convention: str = "utn",
    simulate: bool = True,
) -> dict:
    """Every check of every engine in ``engines`` (default: all) on ``platform``; ``simulate``: with the forward
    simulations (``open_loop_check``, ``passive_release``).

    Returns engine name -> ``{"available": bool, "reason": str | None, "version": str, "kinematics": dict,
    "dynamics": {trajectory name: dict}, "modes": dict, "open_loop": dict, "passive_release": dict, "ok": bool}`` (a missing
    engine: available False and its reason)."""
    status = engine_status()
    platform = modelled_platform(platform)
    P = random_poses(platform, poses, seed, convention=convention)
    trajs = trajectories(platform, samples)
    out = {}
    for name in engines or ENGINES:
        if status[name] is not None:
            out[name] = {"available": False, "reason": status[name], "ok": None}
            continue
        eng = engine_model(name, platform)
        kin = kinematics_check(eng, platform, P, convention)
        dyn = {}
        for tname, (q, qd, qdd) in trajs.items():
            kappa = engine_condition(eng, platform, q, qd, qdd, convention)
            dyn[tname] = dynamics_check(eng, platform, q, qd, qdd, convention, kappa)
        mod = modes_check(eng, platform, np.vstack([platform.home_pose(), P[: MODE_POSES - 1]]), convention)
        out[name] = {
            "available": True,
            "reason": None,
            "version": _MODULES[name].VERSION,
            "kinematics": kin,
            "dynamics": dyn,
            "modes": mod,
            "ok": bool(kin["ok"] and all(d["ok"] for d in dyn.values()) and mod["ok"]),
        }
        if simulate:
            ol = open_loop_check(name, platform)
            rel = passive_release(name, platform)
            out[name].update(
                open_loop=ol, passive_release={k: v for k, v in rel.items() if k not in ("t", "z", "drop")}
            )
            out[name]["ok"] = bool(out[name]["ok"] and ol["ok"])
    return out


def engine_condition(engine, platform: Platform, q, qd, qdd, convention: str = "utn") -> float:
    """The worst condition number of the engine's [B Gᵀ] along the samples."""
    st = plate_state(platform, q, qd, qdd, convention)
    return max(engine.condition(st, k) for k in range(len(st.lengths)))


def _plate_errors(st, rec, idx) -> tuple[float, float]:
    """Worst plate-origin distance (m) and rotation angle (rad) between a recorded run and the plan at ``idx``."""
    dp = float(np.linalg.norm(rec["p"] - st.p[idx], axis=-1).max())
    c = (np.einsum("kij,kij->k", rec["R"], st.R[idx]) - 1) / 2
    return dp, float(np.arccos(np.clip(c, -1.0, 1.0)).max())


def pinocchio_open_loop_bound(platform: Platform, F, dt: float, duration: float) -> float:
    """The plate's drift (m) from the forces' linear interpolation over steps of ``dt``: δF = |F̈| dt²/8 per leg
    (|F̈| from second differences of ``(n, 6)`` F), six legs on the plate's mass, grown as ½ δa T²."""
    Fdd = np.abs(np.diff(F, 2, axis=0)).max() / dt**2
    return 0.5 * (6 * Fdd * dt**2 / 8 / max(platform.mass, 1e-6)) * duration**2


def open_loop_check(name: str, platform: Platform, duration: float = SIM_DURATION, dt: float = SIM_STEP) -> dict:
    """The closed-form forces of the seed sway (``trajectories``) applied open loop in engine ``name``.

    Returns for Pinocchio ``{"position_error_m", "angle_error_rad", "constraint_m", "bound_m", "ok"}``; for MuJoCo
    ``{"solref_s": [τ...], "position_error_m": [...], "angle_error_rad": [...], "constraint_m": [...], "ok"}`` (ok:
    both shrink as τ shrinks)."""
    t = np.arange(0.0, duration + dt / 2, dt)
    q, qd, qdd = sway(platform, t)
    F = leg_forces_with_legs(platform, q, qd, qdd)
    st = plate_state(platform, q, qd, qdd)
    every = int(round(RECORD / dt))
    idx = np.arange(0, len(t), every)
    if name == "pinocchio":
        eng = engine_model(name, platform)
        q0, v0 = eng.set_state(st, 0)
        rec = eng.simulate(q0, v0, F, dt, every)
        dp, da = _plate_errors(st, rec, idx)
        bound = pinocchio_open_loop_bound(platform, F, dt, duration)
        return {
            "position_error_m": dp,
            "angle_error_rad": da,
            "constraint_m": float(rec["constraint"].max()),
            "bound_m": bound,
            "ok": bool(dp <= bound),
        }
    out = {"solref_s": list(SOLREF_TIMES), "position_error_m": [], "angle_error_rad": [], "constraint_m": []}
    for tau in SOLREF_TIMES:
        eng = engine_model(name, platform, mjcf=mjcf_text(platform, (tau, MJCF_SOLREF[1]), dt, "RK4"))
        eng.set_state(st, 0)
        rec = eng.simulate(F, every)
        dp, da = _plate_errors(st, rec, idx)
        out["position_error_m"].append(dp)
        out["angle_error_rad"].append(da)
        out["constraint_m"].append(float(rec["constraint"].max()))
    shrinks = all(np.diff(out["constraint_m"]) < 0) and all(np.diff(out["position_error_m"]) < 0)
    out["ok"] = bool(shrinks)
    return out


def passive_release(name: str, platform: Platform, duration: float = RELEASE_DURATION, dt: float = SIM_STEP) -> dict:
    """The passive platform (no actuator force) released at rest from home in engine ``name``.

    Returns ``t`` (m,) s, ``z`` (m,) the plate origin's height (m), ``drop`` (m,) its distance from the start (m),
    ``energy_drift_j`` the largest |E − E(0)| (J), ``energy_exchanged_j`` the largest |potential energy − its start|
    (J), ``constraint_m`` the worst closure gap, ``in_stroke`` whether every leg stayed within its stroke."""
    st = plate_state(platform, platform.home_pose())
    n = int(round(duration / dt)) + 1
    zero = np.zeros((n, 6))
    every = int(round(RECORD / dt))
    if name == "pinocchio":
        eng = engine_model(name, platform)
        q0, v0 = eng.set_state(st, 0)
        rec = eng.simulate(q0, v0, zero, dt, every)
    else:
        eng = engine_model(name, platform, mjcf=mjcf_text(platform, MJCF_SOLREF, dt, "RK4"))
        eng.set_state(st, 0)
        rec = eng.simulate(zero, every)
    drop = rec["p"][0, 2] - rec["p"][:, 2]
    mass = platform.mass + 6 * (platform.legs.cylinder_mass + platform.legs.piston_mass)
    return {
        "t": np.arange(len(rec["p"])) * every * dt,
        "z": rec["p"][:, 2],
        "energy_drift_j": float(np.abs(rec["energy"] - rec["energy"][0]).max()),
        "energy_exchanged_j": float(mass * G_EARTH * drop.max()),
        "constraint_m": float(rec["constraint"].max()),
        "drop": np.linalg.norm(rec["p"] - rec["p"][0], axis=-1),
        "in_stroke": bool(rec["lengths"].min() >= platform.L_min and rec["lengths"].max() <= platform.L_max),
    }


NOMINAL_LEG_STIFFNESS = 1e6  # N/m, where the platform gives none: only the inertia differs between the sides


def modes_check(engine, platform: Platform, poses, convention: str = "utn") -> dict:
    """The engine's Cartesian inertia and the natural frequencies with it against ``spatial_inertia`` (legs) and
    ``design.stiffness`` at ``(n, 6)`` poses.

    Returns ``poses``, ``mass_matrix_relative_error`` (worst ‖ΔM‖/‖M‖), ``frequency_relative_error`` (worst),
    ``frequencies_hz`` (the first pose's, from the engine: home in ``cross_check``), ``tolerance_relative``, ``ok``."""
    poses = np.atleast_2d(poses)
    st = plate_state(platform, poses, convention=convention)
    k = platform.legs.stiffness or NOMINAL_LEG_STIFFNESS
    err_m, err_f, freqs, kappa = 0.0, 0.0, None, 1.0
    for i, q in enumerate(poses):
        M_eng = engine.task_mass_matrix(st, i)
        M_ref = spatial_inertia(platform, q, convention, legs=True)
        err_m = max(err_m, float(np.linalg.norm(M_eng - M_ref) / np.linalg.norm(M_ref)))
        K = stiffness_matrix(platform, q, k, convention, legs=True)
        K = 0.5 * (K + K.T)
        f_eng = np.sqrt(np.abs(scipy.linalg.eigh(K, 0.5 * (M_eng + M_eng.T), eigvals_only=True))) / (2 * np.pi)
        f_ref = np.sqrt(np.abs(scipy.linalg.eigh(K, M_ref, eigvals_only=True))) / (2 * np.pi)
        err_f = max(err_f, float(np.abs(f_eng - f_ref).max() / f_ref.max()))
        kappa = max(kappa, float(np.linalg.cond(M_ref)))
        freqs = f_eng if freqs is None else freqs
    tol = DYNAMIC_ROUNDING * kappa * EPS
    return {
        "poses": len(poses),
        "mass_matrix_relative_error": err_m,
        "frequency_relative_error": err_f,
        "frequencies_hz": freqs,
        "tolerance_relative": tol,
        "ok": bool(err_m <= tol and err_f <= tol),
    }


LOOP_DURATION = 1.0  # s of the float-law loop along the seed sway


def float_loop(name: str, platform: Platform, duration: float = LOOP_DURATION, solref=MJCF_SOLREF) -> dict:
    """The float PID law (``control.laws.FloatLaw``, its gains and period T designed for the platform) closing the
    loop on engine ``name`` along the seed sway (``sway``) with the closed-form feed-forward: at each tick the legs'
    true lengths are read, the law's command is held over the next period (no output delay: the engines' loop,
    not the DSP's; ``engines.dsp_loop`` runs the DSP's, as ``sd.simulate`` does), the engine advances one period
    (RK4, step T; MuJoCo with ``solref``).

    Returns ``t`` (m,) s, ``p`` (m, 3) the plate origin and ``R`` (m, 3, 3) every ``RECORD`` s, ``tracking_m``
    the worst plate-origin distance from the plan, ``constraint_m`` the worst closure gap (MuJoCo: over every
    step; Pinocchio: at the end), ``period_s``."""
    law = FloatLaw(platform)
    T = law.timing.sample_period
    t = np.arange(0.0, duration + T / 2, T)
    q, qd, qdd = sway(platform, t)
    F_ff = leg_forces_with_legs(platform, q, qd, qdd)
    st = plate_state(platform, q, qd, qdd)
    rates = np.einsum("ij,j->i", length_jacobian(platform, q[0]), qd[0])
    # holding F_ff[0] with the feed-forward F_ff[0]: the integrator holds their difference, nothing
    state = law.initial_pid_state(st.lengths[0], np.zeros(6), rates)
    every = max(1, int(round(RECORD / T)))
    out = {"p": [], "R": []}
    if name == "pinocchio":
        eng = engine_model(name, platform)
        x, v = eng.set_state(st, 0)
        step = eng.stepper()

        def lengths():
            return eng.lengths(x)

        def plate():
            return eng.plate(x)
    else:
        eng = engine_model(name, platform, mjcf=mjcf_text(platform, solref, T, "RK4"))
        eng.set_state(st, 0)
        lengths, plate = eng.lengths, eng.plate
    gap = 0.0
    for k in range(len(t)):
        if k % every == 0:
            R, p = plate()
            out["R"].append(R)
            out["p"].append(p)
        if k == len(t) - 1:
            break
        u, _, state, _ = law.step(state, q[k], lengths(), F_ff[k])
        if name == "pinocchio":
            x, v = step(x, v, u, u, T)
        else:
            eng.advance(u)
            gap = max(gap, eng.closure_gap())
    rec = {k: np.array(v) for k, v in out.items()}
    idx = np.arange(0, len(t), every)
    dp, _ = _plate_errors(st, rec, idx)
    if name == "pinocchio":
        gap = float(eng.closure_residuals_at(x).max())
    return {"t": t[idx], **rec, "tracking_m": dp, "constraint_m": gap, "period_s": T}
