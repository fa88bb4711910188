"""``geometric_load_term``: Σ_i F_i D_i contracted block by block equals the contraction of the full
``geometric_stiffness`` array bit for bit (the loaded stiffness of every caller is unchanged by the shortcut)."""

from __future__ import annotations

import numpy as np

from stewart_drake.design.stiffness import geometric_load_term, geometric_stiffness


def test_geometric_load_term_is_the_full_contraction_bit_for_bit():
    rng = np.random.default_rng(2)
    shape = (7, 13, 6)  # two batch axes, as the search's (designs, poses)
    u = rng.normal(size=shape + (3,))
    u /= np.linalg.norm(u, axis=-1)[..., None]
    r = rng.normal(size=shape + (3,)) * 0.4
    L = rng.uniform(0.5, 1.5, shape)
    F = rng.normal(size=shape) * 1e3
    F[0, 0] = 0.0  # zero forces: the sums' signs of zero as well
    full = np.einsum("...k,...kij->...ij", F, geometric_stiffness(u, r, L))
    assert geometric_load_term(F, u, r, L).tobytes() == full.tobytes()
