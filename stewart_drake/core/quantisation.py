"""Rounding in a sampled trajectory, judged against the motion it must represent, and the smoothing spline
that removes it.

A motion written with a few decimals is rounded to a step q (its quantum: 4 decimals in metres, 0.1 mm).
Its accelerations come from second differences (the spline's second derivative, the feed-forward's
differences), where the rounding is amplified by 1/h² at the sample interval h.

The noise: a value rounded to q carries an error e uniform in ±q/2, of variance q²/12. The second difference
e[k+1] − 2·e[k] + e[k−1] of independent errors has variance (1 + 4 + 1)·q²/12, so the acceleration noise the
rounding implies is σ_a = √6·q / (√12·h²) = q / (√2·h²) RMS. (Where the motion moves less than q per sample
the errors are not independent: the file is a staircase whose second differences are spikes of ±q/h² at each
step; the noise taken is then the smaller of σ_a and what the file's second differences show, RMS(Δ²)/h², counted
in whole quanta: an exact ramp shows none.)

The motion: its accelerations are read at the smallest stride m (a power of two) where the rounding can
no longer hide them: the second difference over m samples has an error of at most 2q/(m·h)² (|e| ≤ q/2), and
at that stride it must be at most ``RESOLVED`` of the peak |Δ²_m|/(m·h)² seen. Strides shorter than the
motion's features keep its accelerations; the noise falls as 1/m².

A column is refused when its acceleration noise is more than ``NOISE_FRACTION`` of the peak acceleration of
the motion of its kind (the largest over the translations, or over the rotations) — also when the motion is
not resolved at any stride. A column with fewer than ``MIN_STEPS`` changes of value is not judged (a few
waypoints carry no evidence of their resolution), nor one whose quantum is at the floats' own resolution.

The remedy offered is a smoothing spline with a stated tolerance: per column, the quintic spline of least
curvature whose RMS deviation from the samples is at most ``tol`` (FITPACK's smoothing condition
Σ (y − s)² ≤ n·tol², ``scipy.interpolate.UnivariateSpline``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from stewart_drake.errors import TrajectoryError, short_number

NOISE_FRACTION = 0.1
RESOLVED = 0.1
MIN_SAMPLES = 20
MIN_STEPS = 10
QUANTUM_CANDIDATES = 256  # the smallest distinct steps the quantum is computed from (then checked on all)


@dataclass(frozen=True)
class NoisyColumn:
    """A column rounded too coarsely for its motion: its index (0-5: px py pz a b g), its quantum (the
    rounding step, SI), the acceleration noise the rounding implies at the sample interval (RMS, SI per s²)
    and the peak acceleration of the motion it is judged against (SI per s²; 0: not resolved)."""

    column: int
    quantum: float
    accel_noise: float
    motion_accel: float


def quantum(values) -> float:
    """The rounding step of ``values`` (n,): the largest q of which every difference between them is a
    whole multiple (a float gcd of the distinct steps), or 0 when there is none above the floats' own
    resolution (values written with all their digits)."""
    v = np.asarray(values, dtype=float)
    d = np.abs(np.diff(v))
    d = d[d > 0]
    if d.size == 0:
        return 0.0
    floor = 64 * np.finfo(float).eps * float(np.abs(v).max())  # a difference's error from parsing and scaling
    steps = np.unique(d)[:QUANTUM_CANDIDATES]
    g = float(steps[0])
    for x in steps[1:]:
        a, b = float(x), g
        while b > 8 * floor:
            r = math.fmod(a, b)
            a, b = b, min(r, b - r)
        g = a
        if g <= 8 * floor:
            return 0.0
    ratio = d / g
    if np.abs(ratio - np.rint(ratio)).max() > 0.01:
        return 0.0
    return g


def _peak_accel(v, h: float, m: int) -> float:
    """The peak |second difference over ``m`` samples| / (m·h)² of ``v`` (n,)."""
    d2 = v[2 * m :] - 2 * v[m:-m] + v[: -2 * m]
    return float(np.abs(d2).max()) / (m * h) ** 2 if d2.size else 0.0


def motion_accel(v, h: float, q: float) -> float:
    """The peak acceleration of the motion sampled as ``v`` (n,) every ``h`` s with rounding step ``q``
    (see the module docstring): read at the smallest power-of-two stride where the rounding's error bound
    2q/(m·h)² is at most ``RESOLVED`` of it; 0 when no stride up to n/4 resolves it."""
    m = 1
    while 4 * m <= len(v):
        a = _peak_accel(v, h, m)
        if 2 * q / (m * h) ** 2 <= RESOLVED * a:
            return a
        m *= 2
    return 0.0


def noisy_columns(t, values) -> list[NoisyColumn]:
    """The columns of ``values`` (n, 6) SI sampled at ``t`` (n,) s whose rounding noise is not small against
    the accelerations of the motion (see the module docstring); [] for fewer than ``MIN_SAMPLES`` or unevenly
    spaced samples."""
    t, v = np.asarray(t, dtype=float), np.asarray(values, dtype=float)
    if len(t) < MIN_SAMPLES:
        return []
    dt = np.diff(t)
    h = float(np.median(dt))
    if not np.allclose(dt, h, rtol=0.05, atol=0):  # nearly even (times written rounded): differences still apply
        return []
    judged = {}
    motion = np.zeros(v.shape[1])
    for j in range(v.shape[1]):
        col = v[:, j]
        if np.count_nonzero(np.diff(col)) < MIN_STEPS:
            continue
        q = quantum(col)
        motion[j] = motion_accel(col, h, q)
        if q > 0:
            seen = q * float(np.sqrt(np.mean(np.rint(np.diff(col, 2) / q) ** 2))) / h**2  # whole quanta
            judged[j] = (q, min(q / (math.sqrt(2) * h**2), seen))
    out = []
    for j, (q, noise) in judged.items():
        kind = slice(0, 3) if j < 3 else slice(3, 6)
        if noise > NOISE_FRACTION * float(motion[kind].max()):
            out.append(NoisyColumn(j, q, noise, float(motion[kind].max())))
    return out


def _spline(t, y, k: int, tol: float):
    """The degree-``k`` smoothing spline of ``y`` (n,) at ``t`` (n,) with RMS deviation at most ``tol``."""
    # deferred: scipy.interpolate takes ~0.5 s to import and only a smoothed CSV needs it, while every closed-loop
    # run imports this module (through core.trajectory)
    from scipy.interpolate import UnivariateSpline

    return UnivariateSpline(t, y, k=k, s=len(t) * tol**2)


def smooth_columns(t, values, tol) -> np.ndarray:
    """``(n, 6)`` the samples of the quintic smoothing spline through each column of ``values`` (n, 6) at
    ``t`` (n,), RMS deviation at most ``tol`` (6,) (or a scalar) in the values' units."""
    t, v = np.asarray(t, dtype=float), np.asarray(values, dtype=float)
    tol = np.broadcast_to(np.asarray(tol, dtype=float), (v.shape[1],))
    k = 5 if len(t) > 5 else max(1, len(t) - 1)
    out = np.empty_like(v)
    for j in range(v.shape[1]):
        if np.ptp(v[:, j]) == 0:
            out[:, j] = v[:, j]
            continue
        out[:, j] = _spline(t, v[:, j], k, float(tol[j]))(t)
    return out


def smoothing_spline(t, values, tol):
    """The per-column quintic smoothing splines (``smooth_columns``), as a callable ``f(t, nu)`` returning
    the ``nu``-th derivative ``(m, 6)`` at times ``t`` (m,)."""
    t, v = np.asarray(t, dtype=float), np.asarray(values, dtype=float)
    tol = np.broadcast_to(np.asarray(tol, dtype=float), (v.shape[1],))
    k = 5 if len(t) > 5 else max(1, len(t) - 1)
    splines = [None if np.ptp(v[:, j]) == 0 else _spline(t, v[:, j], k, float(tol[j])) for j in range(v.shape[1])]

    def f(x, nu: int = 0) -> np.ndarray:
        x = np.asarray(x, dtype=float)
        cols = [
            (np.full(x.shape, v[0, j]) if nu == 0 else np.zeros(x.shape)) if s is None else s(x, nu)
            for j, s in enumerate(splines)
        ]
        return np.stack(cols, axis=-1)

    return f


COLUMNS = ("px", "py", "pz", "a_x", "a_y", "a_z")


def check_finite_rates(path, t, values) -> None:
    """``TrajectoryError`` naming ``path``, the column and the two samples when a rate (difference over the
    time step) of ``values`` (n, 6) at ``t`` (n,) s is not finite: a 1e308 cell passes as a number but its
    rate overflows (scipy's "`dydx` must contain only finite values" before)."""
    t, v = np.asarray(t, dtype=float), np.asarray(values, dtype=float)
    with np.errstate(over="ignore", invalid="ignore"):
        rate = np.diff(v, axis=0) / np.diff(t)[:, None]
    bad = ~np.isfinite(rate)
    if bad.any():
        k, j = np.unravel_index(int(np.argmax(bad)), bad.shape)
        raise TrajectoryError(
            TrajectoryError.RATE.format(
                path=path,
                column=COLUMNS[j],
                a=short_number(v[k, j], 6),
                b=short_number(v[k + 1, j], 6),
                t0=short_number(t[k], 6),
                t1=short_number(t[k + 1], 6),
            )
        )


def check_quantisation(path, t, values, option: str = "--smooth") -> None:
    """``TrajectoryError`` naming ``path`` and the first column of ``values`` (n, 6) SI at ``t`` (n,) s rounded
    too coarsely for its motion (``noisy_columns``): its step, the acceleration noise it implies, the motion's
    peak acceleration and the remedy ``option``."""
    noisy = noisy_columns(t, values)
    if noisy:
        c = noisy[0]
        qunit, unit = ("m", "m/s²") if c.column < 3 else ("rad", "rad/s²")
        h = float(np.median(np.diff(np.asarray(t, dtype=float))))
        motion = (
            f"a motion whose accelerations peak at {c.motion_accel:.3g} {unit}"
            if c.motion_accel > 0
            else "a motion whose accelerations the rounding hides at every stride"
        )
        raise TrajectoryError(
            TrajectoryError.QUANTISED.format(
                path=path,
                column=COLUMNS[c.column],
                quantum=f"{c.quantum:.3g}",
                qunit=qunit,
                rate=f"{1 / h:.6g}",
                noise=c.accel_noise,
                unit=unit,
                motion=motion,
                option=option,
            )
        )


def smooth_tolerance(value, option: str = "--smooth") -> float:
    """``value`` (the file's units) as a finite positive float, or ``TrajectoryError`` naming ``option``."""
    v = float(value)
    if not (np.isfinite(v) and v > 0):
        raise TrajectoryError(TrajectoryError.SMOOTH_TOL.format(option=option, value=value))
    return v
