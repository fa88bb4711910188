"""``homotopy.branches`` with the real-time FK following every trajectory sample (``core.realtime_fk``)."""

import numpy as np

from stewart_drake.core.geometry import load_preset
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.core.rotations import angles_from_matrix
from stewart_drake.homotopy import solve
from stewart_drake.homotopy.branches import branch_safety, follow


def test_certified_radius_is_a_lower_bound_of_the_exact_branch_distance():
    """Along a 1 kHz tilt every sample is certified on the branch, and at the samples the homotopy
    checks, the certified uniqueness radius is below the exact distance to the nearest other mode."""
    p = load_preset("utn-dynamic")
    t = np.linspace(0, 1, 1001)
    q = p.home_pose() + np.outer(np.sin(np.pi * t), [0.03, -0.02, 0.02, 0.15, 0.1, 0.2])
    rep = branch_safety(p, t, q, "utn", samples=3)
    s = rep.summary(0.0, 0.0)
    assert s["fk_certified_every_sample"] and s["fk_samples_followed"] == 1001 and s["safe"]
    radius_at_checked = follow(p, q[rep.index], "utn")[1]
    assert np.all(radius_at_checked > 0) and np.all(radius_at_checked < rep.branch_distance)


def test_a_trajectory_that_jumps_to_another_mode_is_not_branch_safe():
    """A trajectory whose second sample is another assembly mode of the same leg lengths: the leg
    lengths cannot tell the two apart, the FK stays on the first branch, so the sample is not certified
    and the trajectory is not branch-safe (whatever the margins)."""
    p = load_preset("gonzalez-dutra-2009")
    modes = solve(p, leg_lengths(p, p.home_pose())).modes
    home = min(modes, key=lambda m: np.linalg.norm(m.position - p.home_pose()[:3]))
    other = next(m for m in modes if m is not home and m.position[2] > 0)
    q = np.array([p.home_pose(), np.r_[other.position, angles_from_matrix(other.rotation)]])
    cert, _ = follow(p, q, "utn")
    assert cert[0] and not cert[1]
    rep = branch_safety(p, np.array([0.0, 0.001]), q, "utn", samples=2)
    s = rep.summary(0.0, 0.0)
    assert not s["fk_certified_every_sample"] and s["fk_uncertified_t_s"] == [0.001] and not s["safe"]
