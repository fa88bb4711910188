"""Differentiated quantisation in a sampled trajectory, and the smoothing spline that removes it.

A motion written with a few decimals is rounded to a step δ (6 decimals in metres: 1 µm). Its accelerations
come from second differences (the spline's second derivative, the feed-forward's differences), where the
rounding is amplified by 1/h²: at 10 kHz a 1 µm step is 1e-6 / 1e-8 = 100 m/s² of noise on a motion whose
true acceleration is ~0.05 m/s² (442 N computed for a 4 N motion).

Detection: rounding is white noise of variance δ²/12 per sample; its second difference Δ² has variance
6·δ²/12 and its fourth difference Δ⁴ variance 70·δ²/12, so RMS(Δ⁴) / RMS(Δ²) = √(70/6) ≈ 3.4 where noise
dominates, while for a smooth motion sampled at h it is ~(ωh)² ≪ 1. A column is noise-dominated when that
ratio exceeds ``NOISE_RATIO`` and its second difference is non-zero at more than ``DENSE_FRACTION`` of the
samples (a piecewise-linear file of waypoints has Δ² only at its corners: not noise, and not flagged).

The remedy offered is a smoothing spline with a stated tolerance: per column, the quintic spline of least
curvature whose RMS deviation from the samples is at most ``tol`` (FITPACK's smoothing condition
Σ (y − s)² ≤ n·tol², ``scipy.interpolate.UnivariateSpline``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from stewart_drake.errors import TrajectoryError, short_number

NOISE_RATIO = 1.0
DENSE_FRACTION = 0.1
MIN_SAMPLES = 20


@dataclass(frozen=True)
class NoisyColumn:
    """A column whose second differences are rounding noise: its index (0-5: px py pz a b g), the ratio
    RMS(Δ⁴)/RMS(Δ²), and the acceleration noise it implies, RMS(Δ²)/h² in the column's SI unit per s²."""

    column: int
    ratio: float
    accel_noise: float


def noisy_columns(t, values) -> list[NoisyColumn]:
    """The columns of ``values`` (n, 6) SI sampled at ``t`` (n,) s whose second differences are rounding
    noise (see the module docstring); [] for fewer than ``MIN_SAMPLES`` or unevenly spaced samples."""
    t, v = np.asarray(t, dtype=float), np.asarray(values, dtype=float)
    if len(t) < MIN_SAMPLES:
        return []
    dt = np.diff(t)
    h = float(np.median(dt))
    if not np.allclose(dt, h, rtol=0.05, atol=0):  # nearly even (times written rounded): differences still apply
        return []
    d2 = np.diff(v, 2, axis=0)
    d4 = np.diff(v, 4, axis=0)
    out = []
    for j in range(v.shape[1]):
        r2 = float(np.sqrt(np.mean(d2[:, j] ** 2)))
        if r2 == 0:
            continue
        dense = float(np.mean(np.abs(d2[:, j]) > 1e-12 * max(float(np.abs(v[:, j]).max()), 1e-300)))
        ratio = float(np.sqrt(np.mean(d4[:, j] ** 2))) / r2
        if ratio > NOISE_RATIO and dense > DENSE_FRACTION:
            out.append(NoisyColumn(j, ratio, r2 / h**2))
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
    """``TrajectoryError`` naming ``path`` and the first noise-dominated column of ``values`` (n, 6) SI at
    ``t`` (n,) s (``noisy_columns``), with the acceleration noise it implies and the remedy ``option``."""
    noisy = noisy_columns(t, values)
    if noisy:
        c = noisy[0]
        unit = "m/s²" if c.column < 3 else "rad/s²"
        raise TrajectoryError(
            TrajectoryError.QUANTISED.format(
                path=path,
                column=COLUMNS[c.column],
                ratio=c.ratio,
                noise=c.accel_noise,
                unit=unit,
                option=option,
            )
        )


def smooth_tolerance(value, option: str = "--smooth") -> float:
    """``value`` (the file's units) as a finite positive float, or ``TrajectoryError`` naming ``option``."""
    v = float(value)
    if not (np.isfinite(v) and v > 0):
        raise TrajectoryError(TrajectoryError.SMOOTH_TOL.format(option=option, value=value))
    return v
