"""The compiled real-time FK's batch path (core/fk_kernel.c) solves independent length sets two at a time
(``newton_pair``) and certifies with a third radius trial ρ = 2η: the pairs must give each set the bits it
gets alone, and the sets only the third trial certifies must be the previous pose's branch (checked by an
independent continuation)."""

import numpy as np

from stewart_drake.core.geometry import load_preset
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.core.realtime_fk import RealtimeFK
from stewart_drake.core.sampling import random_poses
from tests.core.test_realtime_fk import continuation

FIELDS = ("poses", "residual", "iterations", "status", "certified", "radius", "eta", "step", "substeps")


def mixed_sets(p, n=41):
    """``(n, 6)`` lengths and previous poses (n odd: the last set runs alone) mixing sets 1 mm / 1 mrad off,
    jumps between random workspace poses (some to another mode, some not certified) and lengths that admit
    no assembly (Newton does not converge), so that the two sets of a pair often part ways."""
    q = random_poses(p, n, seed=11, region="workspace")
    q0 = q + 1e-3
    q0[1::3] = random_poses(p, len(q0[1::3]), seed=12, region="workspace")
    L = leg_lengths(p, q)
    L[2::5] *= 3.0  # three times every leg: no assembly
    return L, q0


def test_pairs_give_each_set_the_bits_it_gets_alone():
    """Every field of every set of an odd batch (pairs, then one alone) equals, bit for bit (NaN where not
    converged), the set solved in a batch of one, with and without sub-steps: pairing changes the order
    of the work, never a set's operations."""
    for name in ("utn-kinematic", "gonzalez-dutra-2009"):
        p = load_preset(name)
        L, q0 = mixed_sets(p)
        for sub in (0, 16):
            fk = RealtimeFK(p, engine="c", max_substeps=sub)
            r = fk.solve_batch(L, q0)
            assert len({int(s) for s in r.status}) >= 2 and 0 < r.certified.sum() < len(L)
            for k in range(len(L)):
                one = fk.solve_batch(L[k : k + 1], q0[k : k + 1])
                for f in FIELDS:
                    assert np.array_equal(getattr(r, f)[k : k + 1], getattr(one, f), equal_nan=True), (name, sub, k, f)


def test_sets_certified_by_the_third_trial_are_on_the_branch():
    """On utn-kinematic from 2 mm / 2 mrad off, some sets are certified with radius exactly 2η (the third
    trial: the fixed trials' radius was below 2η); each of them is the continuation of the previous pose
    along the length path (400 numpy Newton steps, independent of the certificate) to 1e-9, and the numpy
    certificate certifies the same sets."""
    p = load_preset("utn-kinematic")
    q = random_poses(p, 600, seed=21, region="workspace")
    q0 = q + 2e-3
    L = leg_lengths(p, q)
    r = RealtimeFK(p, engine="c").solve_batch(L, q0)
    third = r.certified & (r.radius == 2 * r.eta)
    assert third.sum() >= 20  # 93 of 600 here
    cont, st = continuation(p, q0[third], L[third])
    assert np.all(st == 0) and np.abs(r.poses[third] - cont).max() <= 1e-9
    n = RealtimeFK(p, engine="numpy").solve_batch(L[third], q0[third])
    assert n.certified.all()
