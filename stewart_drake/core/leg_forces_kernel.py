"""The compiled inverse dynamics of plate and legs: ``dynamics.leg_forces_with_legs``'s forces for ``(n, 6)`` rows of
poses, rates and accelerations in one C loop (``core/leg_forces_kernel.c`` through ``system.c_build``, cached by
the hash of its source), with the numpy function as the reference and the fallback.

Why: a feed-forward table (``control.feedforward``) is this inverse dynamics once per tick; numpy spends it on
some hundred array operations over ``(n, 6, 3)`` temporaries, the C loop keeps a row in registers.

Not numpy's bits: the same formulas in the same order, but libm's sine and cosine, sums in written order and LU
solves without fused multiply-adds. ``RELATIVE_TOLERANCE`` bounds the difference, per row, relative to the row's
largest force: the forces solve Jᵀ F = Q, so a relative perturbation δ of J and Q moves F by at most
κ(J)·δ/(1 − κ(J)·δ) relative. Each entry of J and Q is a chain of at most ~100 roundings from the inputs (the
rotation, the legs' unit vectors and their two derivatives, the universal joint's 2 × 2 solves, the rods'
moments, the 3 × 3 tip solve, the sums over six legs): δ ≤ 100·ε ≈ 2.2e-14 for each side's computation, so
4.4e-14 for the difference of two, and with κ ≤ 20 (the scaled κ of the preset and user trajectories here is
3–12; ``tests/core/test_leg_forces_kernel.py`` measures it) the bound is ≈ 9e-13 < 1e-12. Rows where κ is
larger scale it: the tests check random references against 200·ε·κ (measured: at most 3·ε·κ).

A row the loop leaves to numpy (see the C file: an unproven condition bound, a zero pivot, a non-finite number)
makes the whole batch run numpy, which raises ``SingularPoseError`` naming its sample or answers as before.
Without a C compiler numpy runs, silently: ``engine()`` says which ran.
"""

from __future__ import annotations

import numpy as np

from stewart_drake.core.dynamics import G_EARTH, MAX_CONDITION, leg_forces_with_legs
from stewart_drake.core.geometry import Platform
from stewart_drake.core.kinematics import anchor_radius
from stewart_drake.core.leg_bodies import home_leg_frames, leg_dimensions
from stewart_drake.core.rotations import CONVENTIONS, check_convention

RELATIVE_TOLERANCE = 1e-12  # per row, of max |F|: see the module docstring
SOURCE_NAME = "leg_forces_kernel.c"
CDEF = (
    "int64_t sd_leg_forces(int64_t n, const double *g, int conv, const double *q, const double *qd,"
    " const double *qdd, double *F);"
)
_LIB: list = []


def library():
    """``(ffi, lib)`` of the compiled loop, or None without a compiler or cache (numpy then runs)."""
    if not _LIB:
        # deferred: the compiler glue (subprocess, tempfile, hashing, cffi) only where a table is first computed
        from pathlib import Path

        from stewart_drake.system.c_build import UNAVAILABLE, CompileError, load, source_keyed_library

        try:
            path = source_keyed_library(Path(__file__).with_name(SOURCE_NAME), CDEF, "sd-leg-forces", "-O3")
            _LIB.append(load(path, CDEF, cache_declarations=True))
        except (*UNAVAILABLE, CompileError, OSError, ImportError):
            _LIB.append(None)
    return _LIB[0]


def engine() -> str:
    """``"c"`` where the compiled loop runs here, else ``"numpy"``."""
    return "numpy" if library() is None else "c"


def platform_constants(platform: Platform, gravity: float = G_EARTH) -> np.ndarray:
    """``(76,)`` the constants the C loop reads (the layout of its ``G_…`` enumeration), SI units."""
    dims = leg_dimensions(platform)
    legs = platform.legs
    return np.concatenate(
        [
            [platform.mass],
            np.asarray(platform.inertia, dtype=float).ravel(),
            platform.com - platform.rotation_centre,
            (platform.top_anchors_per_leg - platform.rotation_centre).ravel(),
            np.asarray(platform.base_anchors, dtype=float).ravel(),
            home_leg_frames(platform)[:, :, 0].ravel(),
            [legs.cylinder_mass, dims["cylinder_radius"], dims["cylinder_length"]],
            [legs.piston_mass, dims["piston_radius"], dims["piston_length"]],
            [gravity, anchor_radius(platform), MAX_CONDITION],
        ]
    ).astype(float)


def leg_forces(platform: Platform, q, qd, qdd, convention: str = "utn", gravity: float = G_EARTH) -> np.ndarray:
    """``(n, 6)`` leg forces (N) of ``(n, 6)`` poses, rates and accelerations (m, rad, s): the C loop's, else
    ``dynamics.leg_forces_with_legs``'s (its numbers and errors) — within ``RELATIVE_TOLERANCE`` of each other."""
    check_convention(convention)
    c = library()
    rows = [np.ascontiguousarray(a, dtype=float) for a in (q, qd, qdd)]
    if c is None or any(a.ndim != 2 or a.shape[1] != 6 or a.shape != rows[0].shape for a in rows):
        return leg_forces_with_legs(platform, *rows, convention, gravity)
    ffi, lib = c
    fb = ffi.from_buffer
    g = platform_constants(platform, gravity)
    F = np.empty_like(rows[0])
    if lib.sd_leg_forces(len(F), fb("double[]", g), CONVENTIONS.index(convention), *(fb("double[]", a) for a in rows),
                         fb("double[]", F)):  # fmt: skip
        return leg_forces_with_legs(platform, *rows, convention, gravity)
    return F
