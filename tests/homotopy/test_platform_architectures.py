"""Platform files of every architecture the forward-kinematics solver knows, written in the explicit
YAML format: 6-3 (three base joints, each shared by two legs, declared with ``leg_base``) and a general
6-6 whose anchors are not in one plane. Each loads, classifies, solves completely with certified
modes equal to the multi-start's, round-trips through the inverse kinematics, and assembles in Drake.
A repeated base anchor without ``leg_base`` is still a one-line error (exit 2)."""

import json

import numpy as np
import pytest
import yaml

from stewart_drake.cli import main
from stewart_drake.core.assembly_modes import assembly_modes, modes_from_solutions
from stewart_drake.core.dynamics import harmonic_trajectory, leg_forces
from stewart_drake.core.geometry import load_platform_yaml
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.drake.platform_model import set_pose
from stewart_drake.drake.verify_dynamics import drake_leg_forces
from stewart_drake.drake.verify_kinematics import anchor_frames, drake_fk_tip_errors, make_plant
from stewart_drake.errors import GeometryError
from stewart_drake.homotopy import architecture, solve
from stewart_drake.homotopy.track import TrackOptions, engine_used
from stewart_drake.workspace.limits import leg_pairs

# Two solvers agree on a mode when positions and rotation matrices agree to this: both are
# Newton-polished to ~1e-15 m leg residual and the modes are well separated (min distance ~1e-2).
SAME_MODE = 1e-8
# Leg lengths recomputed from a returned pose: the pose is a Newton-polished root (leg residual below
# 1e-12 m, asserted by the solver's own residual) plus rounding of metre-scale numbers (~1e-15 m).
ROUND_TRIP = 1e-12
# The same through the CLI: the pose is printed in mm/deg (17 significant digits) and read back; the
# degree-radian conversions add a few ulps of angle (~1e-16 rad) times the leg lever (< 2 m).
CLI_ROUND_TRIP_MM = 1e-9
MASS = {"mass": 5.0, "com": [0, 0, 0.01], "inertia": [0.1, 0.1, 0.18, 0, 0, 0]}
POSE_OFFSETS = ([0.02, -0.01, 0.03, 0.1, 0.05, -0.1], [-0.03, 0.02, -0.05, -0.08, 0.12, 0.2])


def six_three_config(seed: int) -> dict:
    """A random 6-3 platform (seeded): three base joints near 90°, 210°, 330° on a 0.45–0.55 m circle,
    each shared by two legs whose plate anchors lie 40–55° either side of it on a 0.25–0.32 m circle;
    every anchor a few cm off the z = 0 plane."""
    rng = np.random.default_rng(seed)
    th = np.radians(90 + 120 * np.arange(3)) + rng.uniform(-0.15, 0.15, 3)
    rb = rng.uniform(0.45, 0.55, 3)
    base = np.stack([rb * np.cos(th), rb * np.sin(th), rng.uniform(-0.03, 0.03, 3)], -1)
    ph = np.repeat(th, 2) + np.tile([-1, 1], 3) * np.radians(rng.uniform(40, 55, 6))
    rt = rng.uniform(0.25, 0.32, 6)
    top = np.stack([rt * np.cos(ph), rt * np.sin(ph), rng.uniform(-0.03, 0.03, 6)], -1)
    return dict(
        name=f"random-6-3-seed{seed}",
        length_unit="m",
        base_anchors=np.round(base, 4).tolist(),
        top_anchors=np.round(top, 4).tolist(),
        leg_top=list(range(6)),
        leg_base=[0, 0, 1, 1, 2, 2],
        stroke=[0.5, 1.1],
        plate=MASS,
    )


def non_planar_config(seed: int) -> dict:
    """A random general 6-6 platform (seeded) with base and plate anchors up to 6 cm off z = 0: base
    pairs either side of 90°, 210°, 330°, plate pairs either side of 30°, 150°, 270°."""
    rng = np.random.default_rng(seed)
    tb = np.radians(np.repeat([90, 210, 330], 2) + np.tile([-1, 1], 3) * rng.uniform(10, 20, 6))
    tt = np.radians(np.repeat([90, 210, 330], 2) + np.tile([-1, 1], 3) * (60 - rng.uniform(10, 20, 6)))
    rb, rt = rng.uniform(0.45, 0.55, 6), rng.uniform(0.25, 0.32, 6)
    base = np.stack([rb * np.cos(tb), rb * np.sin(tb), rng.uniform(-0.06, 0.06, 6)], -1)
    top = np.stack([rt * np.cos(tt), rt * np.sin(tt), rng.uniform(-0.06, 0.06, 6)], -1)
    return dict(
        name=f"random-non-planar-seed{seed}",
        length_unit="m",
        base_anchors=np.round(base, 4).tolist(),
        top_anchors=np.round(top, 4).tolist(),
        leg_top=list(range(6)),
        stroke=[0.5, 1.1],
        plate=MASS,
    )


def _write(tmp_path, cfg: dict):
    f = tmp_path / f"{cfg['name']}.yaml"
    f.write_text(yaml.safe_dump(cfg, default_flow_style=None, sort_keys=False))
    return f


def _key(modes):
    return np.array([np.r_[m.position, m.rotation.ravel()] for m in modes]).reshape(-1, 12)


def _same_sets(a, b) -> bool:
    A, B = _key(a), _key(b)
    if len(A) != len(B):
        return False
    d = np.abs(A[:, None] - B[None]).max(-1)
    return bool(np.all(d.min(1) < SAME_MODE) and np.all(d.min(0) < SAME_MODE))


def _lengths_of(platform, position, rotation) -> np.ndarray:
    """``(6,)`` |p_BC + R_BT (p_TTi − p_TC) − p_BBi| (m), straight from the anchors."""
    a = platform.top_anchors_per_leg - platform.rotation_centre
    return np.linalg.norm(position + a @ rotation.T - platform.base_anchors, axis=-1)


CASES = [("6-3", six_three_config, 0), ("6-3", six_three_config, 1), ("6-6", non_planar_config, 0)]


@pytest.mark.parametrize("kind,make,seed", CASES)
def test_file_loads_and_solves_completely(tmp_path, kind, make, seed):
    """The file loads with the anchors it declares (leg_base expands the shared base joints), the
    solver picks the architecture from them, and at two poses: complete, every path classified, every
    real mode certified, the real set equal to the multi-start's, and each mode's legs have the lengths."""
    cfg = make(seed)
    p = load_platform_yaml(_write(tmp_path, cfg))
    leg_base = cfg.get("leg_base", range(6))
    np.testing.assert_array_equal(p.base_anchors, np.asarray(cfg["base_anchors"])[list(leg_base)])
    if kind == "6-6":  # really not planar: the anchors' smallest principal extent is centimetres
        for pts in (p.base_anchors, p.top_anchors):
            assert np.linalg.svd(pts - pts.mean(0), compute_uv=False)[-1] > 0.01
    arch = architecture(p)
    assert arch.kind == kind and arch.root_count == {"6-3": 16, "6-6": 40}[kind]
    for offset in POSE_OFFSETS:
        L = leg_lengths(p, p.home_pose() + offset)
        r = solve(p, L)
        assert r.kind == kind and r.complete, r.guarantee
        assert sum(r.counts().values()) == r.max_solutions == arch.root_count
        assert r.modes and all(m.certified for m in r.modes)
        ms = assembly_modes(p, L, polish=None)
        assert _same_sets(r.modes, ms.modes), (len(r.modes), len(ms))
        for m in r.modes:
            np.testing.assert_allclose(_lengths_of(p, m.position, m.rotation), L, rtol=0, atol=ROUND_TRIP)


def test_three_three_is_solved_in_the_general_family(tmp_path):
    """A 3-3 (octahedral) platform: shared plate joints (leg_top) and shared base joints (leg_base) in
    offset pairs. No class of its own: the general 40-path start system, described with its joint counts;
    its 16 finite solutions found (Nanua, Waldron & Murthy 1990), the other 24 paths at infinity; complete,
    certified, and the real set equal to the multi-start's."""
    cfg = dict(
        name="three-three",
        base_anchors=[[0.0, 0.5, 0.01], [-0.43, -0.25, 0.0], [0.43, -0.25, -0.01]],
        leg_base=[0, 0, 1, 1, 2, 2],
        top_anchors=[[0.0, -0.3, 0.0], [0.26, 0.15, 0.01], [-0.26, 0.15, 0.0]],
        leg_top=[2, 1, 1, 0, 0, 2],
        stroke=[0.5, 1.1],
    )
    p = load_platform_yaml(_write(tmp_path, cfg))
    arch = architecture(p)
    assert arch.kind == "6-6" and arch.joints == (3, 3) and "3 base, 3 plate joints" in arch.describe()
    L = leg_lengths(p, p.home_pose() + POSE_OFFSETS[0])
    r = solve(p, L)
    assert r.complete and r.counts()["infinity"] == 24 and r.counts()["real"] + r.counts()["complex"] == 16
    assert r.modes and all(m.certified for m in r.modes)
    assert _same_sets(r.modes, assembly_modes(p, L, polish=None).modes)


def test_six_three_cli_fk_all_names_architecture_and_engine_and_round_trips(tmp_path, capsys):
    """``fk --all --json`` on a 6-3 file: architecture 6-3, the engine the tracker runs with, complete
    with 16 paths; each listed pose fed back to ``ik`` gives the lengths asked for. The text output
    names the class and the engine too."""
    f = _write(tmp_path, six_three_config(0))
    p = load_platform_yaml(f)
    L_mm = leg_lengths(p, p.home_pose() + POSE_OFFSETS[0]) * 1e3
    args = ["fk", "--platform", str(f), "--lengths", *(repr(float(v)) for v in L_mm), "--all"]
    assert main(args + ["--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    engine = engine_used(TrackOptions())
    assert d["architecture"] == "6-3" and d["engine"] == engine and d["complete"] and d["max_solutions"] == 16
    assert "base joints shared" in d["architecture_text"]
    assert d["paths"]["real"] == len(d["solutions"]) >= 2
    checked = 0
    for s in d["solutions"]:
        if not (s["above_base"] and s["within_stroke"]):
            continue  # ik refuses poses below the base; these were checked in metres above
        assert main(["ik", "--platform", str(f), "--pose", *(repr(v) for v in s["pose"]), "--json"]) == 0
        back = json.loads(capsys.readouterr().out)["lengths"]
        np.testing.assert_allclose(back, L_mm, rtol=0, atol=CLI_ROUND_TRIP_MM)
        checked += 1
    assert checked >= 2
    assert main(args) == 0
    text = capsys.readouterr().out
    assert "architecture 6-3 (base joints shared by leg pairs" in text and f"tracking engine: {engine}" in text


def test_six_three_drake_model_assembles_at_fk_solutions(tmp_path):
    """The Drake model of a 6-3 file: its base anchor frames are the file's (two legs on each joint),
    and with the plate set at each certified FK solution every piston tip meets its plate anchor
    (ball-constraint gap ~0) with Drake's prismatic joints at the lengths FK was asked for."""
    p = load_platform_yaml(_write(tmp_path, six_three_config(1)))
    h = make_plant(p)
    base, top = anchor_frames(h)
    np.testing.assert_allclose(base, p.base_anchors, rtol=0, atol=1e-12)  # a few float operations
    np.testing.assert_allclose(top, p.top_anchors_per_leg, rtol=0, atol=1e-12)
    L = leg_lengths(p, p.home_pose() + POSE_OFFSETS[1])
    r = solve(p, L)
    assert r.complete and len(r.modes) >= 2
    P = np.array([m.position for m in r.modes])
    RR = np.array([m.rotation for m in r.modes])
    poses = np.array([m.pose for m in modes_from_solutions(p, P, RR, L, np.ones(len(P), bool), "utn")])
    assert drake_fk_tip_errors(h, poses).max() < 1e-12  # frames and FK: float operations on metre numbers
    for pose in poses:
        set_pose(h.plant, h.context, p, pose, "utn")
        drake_lengths = [h.plant.GetJointByName(f"prismatic_{i + 1}").get_translation(h.context) for i in range(6)]
        np.testing.assert_allclose(drake_lengths, L, rtol=0, atol=ROUND_TRIP)


def test_repeated_base_anchor_is_still_refused(tmp_path, capsys):
    """Typo protection: one base anchor written twice (no leg_base) is exit 2 with one line naming the
    file, line and field; so are three pairs written out without leg_base. leg_base errors name it."""
    cfg = non_planar_config(0)
    cfg["base_anchors"][4] = list(cfg["base_anchors"][1])
    f = _write(tmp_path, cfg)
    assert main(["ik", "--platform", str(f), "--pose", "0", "0", "700", "0", "0", "0"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and f"{f}:" in err[0] and "base_anchors item 5" in err[0] and "repeats item 2" in err[0]
    assert "leg_base" in err[0]
    written_out = six_three_config(0)
    written_out["base_anchors"] = [written_out["base_anchors"][j] for j in written_out.pop("leg_base")]
    with pytest.raises(GeometryError, match=r"base_anchors item 2: .* repeats item 1"):
        load_platform_yaml(_write(tmp_path, written_out))
    for leg_base, message in (
        ([0, 0, 1, 1, 2, 3], "leg_base: leg 6 refers to base anchor 3, but there are 3"),
        ([0, 0, 1, 1, 1, 1], "leg_base: base anchor 2 is used by no leg"),
        ([0, 0, 0, 1, 2, 2], "legs may share base joints only in three pairs"),
    ):
        bad = six_three_config(0) | {"leg_base": leg_base}
        with pytest.raises(GeometryError, match=message):
            load_platform_yaml(_write(tmp_path, bad))
    short = non_planar_config(0)
    short["base_anchors"] = short["base_anchors"][:5]
    with pytest.raises(GeometryError, match="base_anchors: 5 points given; give 6"):
        load_platform_yaml(_write(tmp_path, short))


def test_six_three_file_through_other_commands(tmp_path, capsys):
    """Commands other than fk on a 6-3 file: ``model --inspect`` builds the Drake plant with its frames
    on the file's anchors; ``workspace`` with the collision limit leaves the legs that share a base
    joint out of the collision pairs (they meet at the joint: counting them would empty the workspace),
    so the volume stays of the order of the stroke-only volume; the numpy inverse dynamics on the
    non-planar, shared-joint geometry equals Drake's free-body plant (``drake_leg_forces``)."""
    f = _write(tmp_path, six_three_config(0))
    p = load_platform_yaml(f)
    pairs = {tuple(q) for q in leg_pairs(p).tolist()}
    assert len(pairs) == 12 and not pairs & {(0, 1), (2, 3), (4, 5)}
    assert main(["model", "--platform", str(f), "--inspect", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["constraints"] == 6 and d["anchor_error_m"] < 1e-12  # frames: a few float operations
    volumes = {}
    for limits in ("stroke", "stroke,collision"):
        assert main(["workspace", "--platform", str(f), "--resolution", "0.05", "--limits", limits, "--json"]) == 0
        volumes[limits] = json.loads(capsys.readouterr().out)["volume_m3"]
    assert volumes["stroke"] > 0.1 and volumes["stroke,collision"] > 0.5 * volumes["stroke"]
    assert main(["dynamics", "--platform", str(f), "--json"]) == 0
    assert np.all(np.isfinite(json.loads(capsys.readouterr().out)["forces"]))
    # As tests/test_dynamics_drake.py: O(10) operations per term on forces of O(10 N), J well conditioned
    # (< 30 here): rounding gives ~1e-14 N; 1e-9 N is the bound asked of the dynamics everywhere.
    centre, amplitude = p.home_pose() + [0.01, -0.01, 0, 0.02, 0.01, 0.03], [0.02, 0.02, 0.01, 0.1, 0.1, 0.2]
    q, qd, qdd = harmonic_trajectory(
        np.linspace(0, 2, 7), centre, amplitude, [1.3, 2.1, 1.7, 3.0, 2.5, 3.5], [0.1, 0.2, 0.3, 0.4, 0.5, 0.6]
    )
    assert np.abs(leg_forces(p, q, qd, qdd, "utn") - drake_leg_forces(p, q, qd, qdd, "utn")).max() <= 1e-9
