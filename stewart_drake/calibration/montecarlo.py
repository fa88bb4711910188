"""Monte Carlo of the calibration itself: one machine, one pose set, many noise draws, each identified; the
spread of the identified parameters against the σ the identification reports (a sample, not a proof)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from stewart_drake.calibration.identify import identify
from stewart_drake.calibration.model import Noise, make_problem, pose_blocks, reduced_blocks
from stewart_drake.calibration.simulate import simulate_measurements
from stewart_drake.core.geometry import Platform


@dataclass
class SigmaCheck:
    """``draws`` identifications: per free parameter the ratio of the sample σ to the reported σ
    (``ratio``), the relative standard error of a sample σ from that many draws (1/√(2(N−1))), and the mean
    Mahalanobis distance of the draws from their mean over its expectation p (N−1)/N (``mahalanobis_ratio``)."""

    names: list
    ratio: np.ndarray
    draws: int
    mahalanobis_ratio: float
    converged: int

    @property
    def standard_error(self) -> float:
        return 1.0 / np.sqrt(2 * (self.draws - 1))

    def to_dict(self) -> dict:
        return {
            "draws": self.draws,
            "converged": self.converged,
            "mean_ratio": float(self.ratio.mean()),
            "max_abs_deviation": float(np.abs(self.ratio - 1).max()),
            "standard_error": float(self.standard_error),
            "mahalanobis_ratio": self.mahalanobis_ratio,
            "mahalanobis_standard_error": float(np.sqrt(2 / (len(self.ratio) * self.draws))),
            "ratio": {n: float(r) for n, r in zip(self.names, self.ratio)},
        }


def sigma_monte_carlo(
    nominal: Platform,
    truth: Platform,
    poses,
    kind: str = "pose",
    noise: Noise = Noise(),
    draws: int = 40,
    seed: int = 100,
    convention: str = "utn",
) -> SigmaCheck:
    """Identify ``truth`` measured at ``poses`` with ``draws`` noise draws (seeds ``seed`` …); compare the
    spread of θ over the free parameters with the first fit's σ and covariance."""
    thetas, sigma, result, data = [], None, None, None
    ok = 0
    for k in range(draws):
        data, _ = simulate_measurements(nominal, {}, poses, kind, noise, seed + k, convention, truth=truth)
        r = identify(nominal, data, noise, convention)
        ok += r.converged
        thetas.append(r.theta)
        if result is None:
            result, sigma = r, r.sigma
    T = np.array(thetas)
    free = result.identifiability.free
    T = T[:, free]
    ratio = T.std(axis=0, ddof=1) / sigma[free]
    problem = make_problem(result.layout, data, noise, convention)
    theta_mean = result.theta.copy()
    theta_mean[free] = T.mean(0)
    A = reduced_blocks(*pose_blocks(problem, theta_mean))[:, :, free].reshape(-1, int(free.sum()))
    D = T - T.mean(0)
    m = float(np.einsum("ki,ij,kj->k", D, A.T @ A, D).mean())
    p = int(free.sum())
    names = [n for n, f in zip(result.layout.names, free) if f]
    return SigmaCheck(names, ratio, draws, m / (p * (draws - 1) / draws), ok)
