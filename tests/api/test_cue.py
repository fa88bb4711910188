"""``sd.cue``: the limits counted by an independent leg-length computation, the in-the-loop run's plant against the
commanded poses, and refusals of bad input."""

from dataclasses import replace

import numpy as np
import pytest

import stewart_drake as sd
from stewart_drake.api.cueing import limit_samples, resolve_drive
from stewart_drake.control.cueing.classical import HAND_SET
from stewart_drake.control.cueing.drive import Drive
from stewart_drake.control.cueing.generators import DRIVES
from stewart_drake.control.cueing.guard import WorkspaceGuard
from stewart_drake.control.cueing.tuning import save_params
from stewart_drake.core.kinematics import leg_vectors
from stewart_drake.core.rotations import rotation_matrix
from stewart_drake.errors import ArgumentError, UsageError

NEWCOMER = "examples/newcomer-210kg.yaml"


def hand_lengths(platform, poses):
    """Leg lengths of pure translations (zero orientation: the plate anchors move with the plate) straight
    from the anchors, without ``core.kinematics``: |p + top_i − base_i|."""
    p = np.asarray(poses)[:, None, :3]
    top = platform.top_anchors[platform.leg_top] - platform.rotation_centre
    return np.linalg.norm(p + top - platform.base_anchors, axis=-1)


def first_seconds(drive: Drive, seconds: float) -> Drive:
    """The drive's first ``seconds`` s (a short in-the-loop run)."""
    n = int(round(seconds / (drive.t[1] - drive.t[0]))) + 1
    cut = {k: getattr(drive, k)[:n] for k in ("t", "specific_force", "angular_velocity")}
    return replace(drive, attitude=None if drive.attitude is None else drive.attitude[:n], **cut)


def test_limit_samples_counts_what_the_anchors_say():
    """A vertical sweep through the top of the stroke: the samples counted outside are those whose hand-computed
    longest leg exceeds L_max; a 30 mm jump in one 10 ms sample moves the legs at ~1 m/s by central differences on
    either side of it, over utn-dynamic's 0.5 m/s: those two samples are counted over speed."""
    p = sd.load_platform("utn-dynamic")
    t = np.arange(200) * 0.01
    poses = np.tile(p.home_pose(), (200, 1))
    poses[:, 2] += np.linspace(0.0, 0.3, 200)  # home is mid-stroke: the legs pass L_max on the way up
    poses[100:, 2] += 0.03
    L = hand_lengths(p, poses)
    lim = limit_samples(WorkspaceGuard.for_platform(p), t, poses)
    expected = int(np.count_nonzero(L.max(axis=1) > p.L_max))
    assert 0 < expected < 200 and lim["outside_stroke"] == expected
    speed = np.abs(np.gradient(L, t, axis=0)).max(axis=1)
    assert np.flatnonzero(speed > 0.5).tolist() == [99, 100] and lim["over_speed"] == 2
    assert lim["peak_leg_speed_m_s"] == pytest.approx(speed.max())


def test_classical_cue_keeps_every_pose_in_stroke_on_the_newcomer_machine():
    """The 210 kg machine, hand-set classical washout of a car lane change: the guarded poses are all inside the
    stroke by the anchors' own lengths, not only by the result's count."""
    r = sd.cue(NEWCOMER, "car-lane-change")
    p = r.machine.platform
    assert r.poses.shape == (len(r.drive.t), 6) and np.all(np.isfinite(r.poses))
    L = sd.ik(p, r.poses).lengths  # raises if a pose is unreachable
    assert np.all((L >= p.L_min) & (L <= p.L_max))
    assert r.limits["outside_stroke"] == 0 and r.ok
    d = r.to_dict()
    assert d["algorithm"] == "classical" and d["drive"] == "car-lane-change" and d["simulated"] is False


def test_in_the_loop_plant_follows_the_commanded_poses():
    """Three seconds of the sea-state-4 ship drive on the 210 kg machine (30 µm words) through its fixed-point loop:
    the plant's leg lengths at the drive's samples stay within the run's own tracking bound (``control.verdict``)
    of the commanded poses' IK, although the machine file says ``run: {fit: true}`` (a fitted reference would be
    moved and scaled to the stroke), no plant sample leaves the stroke, and the plant's perceived motion is
    scored."""
    drive = first_seconds(resolve_drive("ship-ss4"), 3.0)
    r = sd.cue(NEWCOMER, drive, simulate=True)
    assert r.machine.run.fit and r.simulation is not None and r.plant_poses.shape == r.poses.shape
    bound = r.simulation.verdict["tracking_bound_mm"] * 1e-3
    p = r.machine.platform
    assert np.abs(sd.ik(p, r.plant_poses).lengths - sd.ik(p, r.poses).lengths).max() < bound
    assert r.plant_limits["outside_stroke"] == 0
    assert "plant" in r.perceived and r.plant_scores is not None
    assert r.to_dict()["simulated"] is True and r.ok


def test_a_parameter_file_cues_as_its_parameters(tmp_path):
    """``params=FILE`` (as the tuning writes it) gives the poses of the same parameters given as an object."""
    params = replace(HAND_SET, scale_xy=0.4, hp_xy=0.8)
    save_params(params, tmp_path / "p.yaml")
    drive = first_seconds(resolve_drive("car-lane-change"), 4.0)
    from_file = sd.cue(NEWCOMER, drive, algorithm="tuned", params=tmp_path / "p.yaml")
    given = sd.cue(NEWCOMER, drive, algorithm="classical", params=params)
    hand = sd.cue(NEWCOMER, drive, algorithm="classical")
    assert np.array_equal(from_file.poses, given.poses) and not np.array_equal(given.poses, hand.poses)


def test_mpc_reports_its_solves_and_keeps_the_limits():
    """Three seconds of the car lane change by MPC on the 210 kg machine: every solve re-checked with the exact IK
    (largest stroke excess ≤ 0), the guarded poses inside the stroke, the solve times reported."""
    r = sd.cue(NEWCOMER, first_seconds(resolve_drive("car-lane-change"), 3.0), algorithm="mpc")
    assert r.mpc["max_stroke_violation_m"] <= 0 and r.limits["outside_stroke"] == r.limits["over_speed"] == 0
    assert 0 < r.mpc["mean_solve_s"] <= r.mpc["worst_solve_s"] and r.to_dict()["mpc"] == r.mpc


def joint_angles(platform, poses) -> np.ndarray:
    """``(N,)`` the largest angle (rad) between a leg and its base joint's axis (the base normal) or its plate
    joint's axis (the plate normal), from the leg vectors: the cones of ``workspace.limits`` by hand."""
    legs = leg_vectors(platform, poses)
    unit = legs / np.linalg.norm(legs, axis=-1, keepdims=True)
    plate_normal = rotation_matrix(poses[:, 3:])[:, :, 2]
    base = np.arccos(unit[..., 2])
    top = np.arccos(np.einsum("nij,nj->ni", unit, plate_normal))
    return np.maximum(base, top).max(axis=1)


def test_a_joint_cone_binds_and_is_kept():
    """The 210 kg machine's joints reach 58° from their axes in the lane change (37° at home): with a 45° cone the
    guard keeps every sample within it, by the leg vectors' own angles."""
    drive = first_seconds(resolve_drive("car-lane-change"), 6.0)
    free = sd.cue(NEWCOMER, drive)
    coned = sd.cue(NEWCOMER, drive, joint_cone=np.radians(45))
    p = free.machine.platform
    assert joint_angles(p, free.poses).max() > np.radians(46)
    assert joint_angles(p, coned.poses).max() <= np.radians(45) + 1e-9
    assert coned.limits["outside_joints"] == 0 and coned.ok


@pytest.mark.slow
@pytest.mark.parametrize("name", list(DRIVES))
def test_every_shipped_drive_in_the_loop_stays_within_the_limits(name):
    """The issue's acceptance: every shipped drive on seed 001's ship simulator, 0 samples outside the stroke or
    over the leg speed in the commanded poses and in the simulated plant, and the loop tracking."""
    r = sd.cue("gonzalez-dutra-2009", name, simulate=True)
    assert r.limits["outside_stroke"] == r.limits["over_speed"] == 0
    assert r.plant_limits["outside_stroke"] == r.plant_limits["over_speed"] == 0
    assert r.failures == []


def test_bad_input_is_named():
    with pytest.raises(ArgumentError, match=r"^drive 'no-such-drive': neither a shipped drive \(ship-ss"):
        sd.cue("utn-dynamic", "no-such-drive")
    with pytest.raises(ArgumentError, match=r"Expected algorithm to be one of .*got 'washout'"):
        sd.cue("utn-dynamic", "car-lane-change", algorithm="washout")
    with pytest.raises(UsageError, match=r"^params 'p.yaml': a parameter file holds classical"):
        sd.cue("utn-dynamic", "car-lane-change", algorithm="mpc", params="p.yaml")
    with pytest.raises(
        ArgumentError, match=r"^Expected params to be MpcParams for algorithm 'mpc', got ClassicalParams"
    ):
        sd.cue("utn-dynamic", "car-lane-change", algorithm="mpc", params=HAND_SET)
