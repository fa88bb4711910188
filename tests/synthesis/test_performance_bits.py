"""The performance proof's per-cell bounds depend on the cell alone, bit for bit: computing what depends only on the
orientation once per distinct angle centre (and gathering it), and evaluating ``quad_box_max``'s faces only where
they can contribute, must not let one cell's numbers depend on the others in its batch. (One batch-wide switch is by
design: where some entry's 2 × 2 determinant sign is undecided, the face's determinants are recomputed exactly for
the whole batch; the tests compare batches on the same side of it.)"""

from __future__ import annotations

import dataclasses

import numpy as np

from stewart_drake.synthesis.performance import performance_bounds
from stewart_drake.synthesis.proof import Cells
from stewart_drake.synthesis.verified import quad_box_max


def _bits(b) -> list:
    return [np.asarray(v).tobytes() for v in dataclasses.astuple(b)]


def test_a_cells_bounds_do_not_depend_on_its_batch(req, design):
    # 60 cells on 5 angle centres (as cells split across positions share theirs), −0.0 and 0.0 among the angles
    rng = np.random.default_rng(11)
    home = design.home_pose()
    angles = home[3:] + rng.uniform(-1, 1, (5, 3)) * req.box_hi[3:] * 0.8
    angles[0, 2], angles[1, 2] = 0.0, -0.0
    c = np.concatenate([home[:3] + rng.uniform(-1, 1, (60, 3)) * req.box_hi[:3] * 0.8, angles[np.arange(60) % 5]], 1)
    h = rng.uniform(0.1, 1.0, (60, 6)) * np.r_[0.01, 0.01, 0.01, 0.03, 0.03, 0.03]
    args = (req.v_max, req.a_max, req.stiffness, req.convention)
    whole = performance_bounds(design, Cells(c, h), *args)
    order = rng.permutation(60)
    for part in np.array_split(order, 7):  # other batches: other companions, other orders, other distinct angles
        b = performance_bounds(design, Cells(c[part], h[part]), *args)
        for got, full in zip(
            _bits(b), [np.asarray(v)[part].tobytes() for v in dataclasses.astuple(whole)], strict=True
        ):
            assert got == full


def test_quad_box_max_per_entry_whatever_the_batch():
    # entries whose faces are evaluated (a < 0) mixed with entries where they are skipped, in every proportion: all
    # (0:100), none (100:200), most (0:133, a mask) and a minority (50:250, gathered indices) for Q_00
    rng = np.random.default_rng(5)
    Q = rng.normal(size=(400, 3, 3))
    Q[:100, 0, 0] = -np.abs(Q[:100, 0, 0])  # the first free coordinate's entry negative here, positive below
    Q[100:200, 0, 0] = np.abs(Q[100:200, 0, 0])
    b = np.array([0.3, 0.2, 0.5])
    ties = np.array([[-2.0, 1.0, 0.0], [1.0, -0.5, 0.0], [0.0, 0.0, -1.0]])  # a determinant exactly 0 on a face
    for Qb in (Q, np.concatenate([ties[None], Q[:150], ties[None], Q[150:]])):  # without and with the exact switch
        value, upper = quad_box_max(Qb, b)
        alone = [0, 150, 151, 399] if len(Qb) == len(Q) else []  # a 0-d batch holds no tie (no switch)
        for k in alone:
            v1, u1 = quad_box_max(Qb[k], b)
            assert v1.tobytes() == value[k].tobytes() and u1.tobytes() == upper[k].tobytes()
        for part in (
            (slice(0, 100), slice(100, 200), slice(0, 133), slice(50, 250), slice(0, 260))
            if len(Qb) == len(Q)
            else (slice(0, 1), slice(0, 260), slice(151, 402))
        ):
            v2, u2 = quad_box_max(Qb[part], b)
            assert v2.tobytes() == value[part].tobytes() and u2.tobytes() == upper[part].tobytes()
