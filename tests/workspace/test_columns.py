"""The stroke columns' exact z-lengths (``workspace/columns``): the per-leg test gives the numbers of the
one-array test it replaced, bit for bit."""

import numpy as np
import pytest

from stewart_drake.core.geometry import load_preset
from stewart_drake.core.kinematics import leg_vectors
from stewart_drake.workspace.columns import _column_lengths


def _column_lengths_one_array(platform, rho2, l0, z_bounds):
    """The former form: every leg's test in one (..., 25, 6) array."""
    a = np.sqrt(np.maximum(platform.L_min**2 - rho2, 0.0))
    b = np.sqrt(np.maximum(platform.L_max**2 - rho2, 0.0))
    cz = -l0[:, 2]
    z0, z1 = z_bounds
    ends = np.concatenate(
        [cz - b, cz - a, cz + a, cz + b, np.broadcast_to([z0, min(z1, 1e9)], rho2.shape[:-1] + (2,))], -1
    )
    ends = np.sort(np.clip(ends, z0, min(z1, 1e9)), axis=-1)
    mid = 0.5 * (ends[..., 1:] + ends[..., :-1])
    dz = np.abs(mid[..., None] - cz)
    ok = np.all((dz >= a[..., None, :]) & (dz <= b[..., None, :]), axis=-1)
    return np.sum(np.where(ok, ends[..., 1:] - ends[..., :-1], 0.0), axis=-1)


@pytest.mark.parametrize(
    "name, angles, z_bounds",
    [
        ("gonzalez-dutra-2009", (0.0, 0.0, 0.0), (0.0, np.inf)),
        ("gonzalez-dutra-2009", (0.1, -0.2, 0.3), (0.5, 0.8)),  # a clipped column: ends collapse on both bounds
        ("utn-dynamic", (0.0, 0.05, 0.0), (-np.inf, np.inf)),
    ],
)
def test_column_lengths_as_the_one_array_test(name, angles, z_bounds):
    """Columns over the whole reach of the legs (full, partial, clipped, rim, empty), and exactly tangent ones
    (rho² = L_min², L_max²): the same lengths, bit for bit."""
    p = load_preset(name)
    l0 = leg_vectors(p, np.r_[0.0, 0.0, 0.0, angles])
    x, y = np.meshgrid(np.linspace(-1.2, 1.2, 97), np.linspace(-1.2, 1.2, 89), indexing="ij")
    rho2 = (x[..., None] + l0[:, 0]) ** 2 + (y[..., None] + l0[:, 1]) ** 2
    rho2 = rho2[np.all(rho2 <= p.L_max**2, axis=-1)]
    rho2[:3, 0] = [p.L_min**2, p.L_max**2, 0.0]
    got = _column_lengths(p, rho2, l0, z_bounds)
    np.testing.assert_array_equal(got, _column_lengths_one_array(p, rho2, l0, z_bounds))
    assert (got > 0).sum() > 100 and (got == 0).any()
