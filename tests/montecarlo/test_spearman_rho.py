"""``summary.spearman_rho``: Spearman's ρ without ``scipy.stats`` (the robustness section's ranking), equal bit for
bit to ``scipy.stats.spearmanr``'s, ties included; and ``sensitivity(p_values=False)`` is the same ranking."""

import subprocess
import sys

import numpy as np
from scipy.stats import rankdata, spearmanr

from stewart_drake.montecarlo.summary import _average_ranks, sensitivity, spearman_rho


def test_rho_equals_scipy_bit_for_bit_with_and_without_ties():
    rng = np.random.default_rng(11)
    for k in range(300):
        n = int(rng.integers(3, 80))
        x = rng.normal(size=n)
        y = rng.normal(size=n) + rng.uniform(-2, 2) * x
        if k % 2:
            x = np.round(x, 1)  # ties in x
        if k % 3 == 0:
            y = rng.integers(0, 4, n).astype(float)  # many ties in y
        if np.ptp(x) == 0 or np.ptp(y) == 0:
            continue
        np.testing.assert_array_equal(_average_ranks(x), rankdata(x))
        assert spearman_rho(x, y) == spearmanr(x, y)[0]
    assert np.isnan(spearman_rho([1.0, np.nan, 3.0], [1.0, 2.0, 3.0]))


def _rows(seed: int) -> list[dict]:
    rng = np.random.default_rng(seed)
    a, b = rng.uniform(-1, 1, 40), rng.uniform(-1, 1, 40)
    lat = rng.integers(0, 2, 40)
    err = 3 * a + np.round(b, 1) + 0.1 * rng.normal(size=40)
    return [
        {
            "run": i,
            "seed": i,
            "a_m": float(a[i]),
            "b_m": float(np.round(b[i], 1)),
            "latency": ["sample", "computation"][lat[i]],
            "max_leg_error_m": float(err[i]),
        }
        for i in range(40)
    ]


def test_sensitivity_without_p_values_is_the_same_ranking():
    rows = _rows(3)
    full, rho_only = sensitivity(rows), sensitivity(rows, p_values=False)
    assert [d["parameter"] for d in full][:2] == ["a_m", "b_m"]  # the driving parameter first
    assert rho_only == [{k: v for k, v in d.items() if k != "p_value"} for d in full]


def test_rho_alone_does_not_import_scipy_stats():
    """What the option is for: a fresh process ranks without loading ``scipy.stats`` (~0.6 s of CPU)."""
    code = (
        "import sys\nfrom stewart_drake.montecarlo.summary import sensitivity\n"
        "rows = [{'run': i, 'seed': i, 'a_m': float(i % 7), 'max_leg_error_m': float(i * 37 % 11)} for i in range(20)]\n"
        "assert sensitivity(rows, 'max_leg_error_m', p_values=False)\n"
        "print('scipy.stats' in sys.modules)"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"
