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

The engines are optional (``pip install .[engines]``): ``engine_status`` says which are importable and why not.
"""

from __future__ import annotations

import importlib

import numpy as np

from stewart_drake.core.dynamics import harmonic_trajectory, leg_forces_with_legs
from stewart_drake.core.geometry import Platform
from stewart_drake.core.kinematics import leg_lengths, stroke_within
from stewart_drake.core.sampling import random_poses
from stewart_drake.engines.plate import plate_state

ENGINES = ("pinocchio", "mujoco")
_MODULES = {"pinocchio": "stewart_drake.engines.pinocchio_engine", "mujoco": "stewart_drake.engines.mujoco_engine"}
_CLASSES = {"pinocchio": "PinocchioPlatform", "mujoco": "MujocoPlatform"}
KINEMATIC_TOL_REL = 1e-12  # of the longest leg, m/m (see the module docstring)
# Rounding of a 24-unknown elimination and of the closed form's ~100 operations per force: a bound of
# (24 + 100) × κ × ε on the relative error; 1000 leaves it a factor eight.
DYNAMIC_ROUNDING = 1000.0
EPS = float(np.finfo(float).eps)
TRAJECTORIES = ("seed", "rotating")


def engine_status() -> dict:
    """engine name -> None when importable, else the one-line reason it is not."""
    out = {}
    for name in ENGINES:
        try:
            # deferred: each engine is an optional extra; a missing one is reported, not raised at import
            importlib.import_module(_MODULES[name])
            out[name] = None
        except ImportError as e:
            out[name] = f"{name} is not installed ({e}); pip install 'stewart-drake[engines]'"
    return out


def engine_model(name: str, platform: Platform, **texts):
    """The platform in engine ``name`` ("pinocchio" | "mujoco"); ``texts`` replace the generated model text
    (``urdf=``, ``closure_list=`` for Pinocchio, ``mjcf=`` for MuJoCo). Raises ImportError when it is missing."""
    module = importlib.import_module(_MODULES[name])  # deferred: the engine is an optional extra
    return getattr(module, _CLASSES[name])(platform, **texts)


def trajectories(platform: Platform, n: int = 13, duration: float = 3.0) -> dict:
    """name -> ``(q, qd, qdd)`` ``(n, 6)`` each: ``seed`` the seed's sideways sway about home (y = A sin 2t, A a
    quarter of the stroke range), ``rotating`` all six coordinates about home (translations a twentieth of the
    stroke range, rotations 0.2 rad, incommensurate frequencies 1.3–3.5 rad/s)."""
    t = np.linspace(0.0, duration, n)
    home = platform.home_pose()
    s = platform.L_max - platform.L_min
    seed = harmonic_trajectory(t, home, [0, s / 4, 0, 0, 0, 0], 2.0)
    rot = harmonic_trajectory(
        t, home, [s / 20] * 3 + [0.2] * 3, [1.3, 2.1, 1.7, 3.0, 2.5, 3.5], [0.1, 0.2, 0.3, 0.4, 0.5, 0.6]
    )
    return {"seed": seed, "rotating": rot}


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
    platform: Platform, engines=None, poses: int = 1000, samples: int = 13, seed: int = 0, convention: str = "utn"
) -> dict:
    """Every check of every engine in ``engines`` (default: all) on ``platform``.

    Returns engine name -> ``{"available": bool, "reason": str | None, "version": str, "kinematics": dict,
    "dynamics": {trajectory name: dict}, "ok": bool}`` (a missing engine: available False and its reason)."""
    status = engine_status()
    P = random_poses(platform, poses, seed, convention=convention)
    trajs = trajectories(platform, samples)
    for name, (q, _, _) in trajs.items():
        if not stroke_within(platform, leg_lengths(platform, q, convention)).all():
            # internal: the trajectories are sized from the stroke; one outside it is a bug here
            raise ValueError(f"the {name} cross-check trajectory leaves the stroke of {platform.name!r}")
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
        out[name] = {
            "available": True,
            "reason": None,
            "version": importlib.import_module(_MODULES[name]).VERSION,
            "kinematics": kin,
            "dynamics": dyn,
            "ok": bool(kin["ok"] and all(d["ok"] for d in dyn.values())),
        }
    return out


def engine_condition(engine, platform: Platform, q, qd, qdd, convention: str = "utn") -> float:
    """The worst condition number of the engine's [B Gᵀ] along the samples."""
    st = plate_state(platform, q, qd, qdd, convention)
    return max(engine.condition(st, k) for k in range(len(st.lengths)))
