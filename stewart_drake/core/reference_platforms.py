"""Reference platforms for the forward-kinematics solvers (massless, geometry only): Dietmaier's 6-6 with
40 real assembly modes, and seeded random general and planar 6-6 platforms, each with the leg lengths
of a pose. The assembly-mode searches, the report's forward-kinematics analysis, the benchmarks and the
tests solve these.
"""

from __future__ import annotations

import numpy as np

from stewart_drake.core.geometry import Platform
from stewart_drake.core.kinematics import leg_lengths


def dietmaier_platform() -> tuple[Platform, np.ndarray]:
    """Dietmaier's (1998) general 6-6 Stewart–Gough platform with 40 real assembly modes, and its
    leg lengths ``(6,)``. Dimensionless units read as metres; the anchors are not planar.

    Source of the numbers: we could not read the paper itself; the coordinates below (base anchors,
    plate anchors, leg lengths) appear in a Stewart-platform example in Drake's C++ sources (a
    mixed-integer rotation-constraint demo, found by code search; the file does not name Dietmaier)
    and match the values usually quoted for Dietmaier's example. The result confirms them:
    ``assembly_modes.assembly_modes`` finds 40 real, distinct, non-singular solutions
    (``tests/drake/test_forward_drake.py``),
    which only a 40-real-solution geometry can give. The stroke [0.5, 1.6] m is our choice (it holds
    every leg); the home pose is a placeholder (the geometry has no natural one)."""
    base = np.array(
        [
            [0.0, 0.0, 0.0],
            [1.107915, 0.0, 0.0],
            [0.549094, 0.756063, 0.0],
            [0.735077, -0.223935, 0.525991],
            [0.514188, -0.526063, -0.368418],
            [0.590473, 0.094733, -0.205018],
        ]
    )
    top = np.array(
        [
            [0.0, 0.0, 0.0],
            [0.542805, 0.0, 0.0],
            [0.956919, -0.528915, 0.0],
            [0.665885, -0.353482, 1.402538],
            [0.478359, 1.158742, 0.107672],
            [-0.137087, -0.235121, 0.353913],
        ]
    )
    lengths = np.array([1.0, 0.645275, 1.086284, 1.503439, 1.281933, 0.771071])
    p = _kinematic_platform(
        "dietmaier-1998", "Dietmaier 1998: general 6-6 platform with 40 real assembly modes", base, top, (0.5, 1.6)
    )
    return p, lengths


def _kinematic_platform(name: str, description: str, p_BBi, p_TTj, stroke) -> Platform:
    """A massless 6-6 platform (anchors ``(6, 3)`` m, leg i on plate anchor i, stroke ``(2,)`` m, home
    height 1 m): geometry only, for the FK solvers' reference cases."""
    return Platform(
        name=name,
        description=description,
        base_anchors=p_BBi,
        top_anchors=p_TTj,
        leg_top=np.arange(6),
        stroke=np.asarray(stroke, dtype=float),
        mass=0.0,
        com=np.zeros(3),
        inertia=np.zeros((3, 3)),
        home_height=1.0,
    )


def _random_ring(rng, radius: float, dz: float | None, n: int = 6) -> np.ndarray:
    """``(n, 3)`` anchors at sorted random angles, radii in [0.6, 1] × ``radius``, z uniform in ±``dz``
    (``None``: z = 0, drawing nothing)."""
    ang = np.sort(rng.uniform(0, 2 * np.pi, n))
    r = radius * rng.uniform(0.6, 1.0, n)
    z = np.zeros(n) if dz is None else rng.uniform(-dz, dz, n)
    return np.stack([r * np.cos(ang), r * np.sin(ang), z], -1)


def _lengths_near_home(p: Platform, rng, angle: float) -> tuple[Platform, np.ndarray]:
    """``(p, lengths (6,))`` of a random pose within ±0.1 m and ±``angle`` rad of ``p``'s home."""
    q = p.home_pose() + np.r_[rng.uniform(-0.1, 0.1, 3), rng.uniform(-angle, angle, 3)]
    return p, leg_lengths(p, q)


def general_platform(seed: int = 0) -> tuple[Platform, np.ndarray]:
    """A seeded random general (non-planar, asymmetric) 6-6 platform and the leg lengths ``(6,)`` of a
    pose near its home: base anchors within 1 m of the axis (z within ±0.2 m), plate anchors within
    0.6 m (z within ±0.1 m), home height 1 m. For benchmarks and reports."""
    rng = np.random.default_rng(seed)
    p = _kinematic_platform(
        f"general-6-6-seed{seed}",
        "seeded random general 6-6 platform",
        _random_ring(rng, 1.0, 0.2),
        _random_ring(rng, 0.6, 0.1),
        (0.5, 2.0),
    )
    return _lengths_near_home(p, rng, 0.2)


def planar_platform(seed: int = 0) -> tuple[Platform, np.ndarray]:
    """A seeded random planar 6-6 platform (base anchors at z = 0 within 1 m of the axis, plate anchors
    at z = 0 within 0.6 m, at random angles: no symmetry) and the leg lengths ``(6,)`` of a random pose
    near its home (±0.1 m, ±0.3 rad). For tests and benchmarks of the complete solvers."""
    rng = np.random.default_rng(seed)
    p = _kinematic_platform(
        f"planar-6-6-seed{seed}",
        "seeded random planar 6-6 platform",
        _random_ring(rng, 1.0, None),
        _random_ring(rng, 0.6, None),
        (0.3, 2.5),
    )
    return _lengths_near_home(p, rng, 0.3)
