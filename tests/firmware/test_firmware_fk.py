"""``sd_fk`` of the generated firmware (``firmware.fk_gen``): the pose from the leg sensors in fixed point
(Newton on the firmware's IK), against the float FK over the workspace on every preset and a platform of our
own, and its operation count (the cycle estimate's)."""

import numpy as np
import pytest

from stewart_drake.control.gains import ControllerConfig
from stewart_drake.core.geometry import load_preset
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.core.sampling import random_poses
from stewart_drake.firmware.fk_gen import FK_ITERATIONS, pose_jacobian, word_scales
from stewart_drake.firmware.generate import generate
from stewart_drake.firmware.module import compile_generated
from stewart_drake.fixedpoint.generic import pose_words
from tests._own_platform import own_radial

# a tick of fast motion (±3 length LSB, ±30 angle words) and ten times that in position, three in angle
STARTS = {"tick": np.r_[3, 3, 3, 30, 30, 30], "far": np.r_[30, 30, 30, 100, 100, 100]}


def run_fk(m, measured, start):
    out = np.empty_like(start)
    nsat = np.empty(len(start), dtype=int)
    for k in range(len(start)):
        w = m.ffi.new("sd_word[6]", start[k].tolist())
        nsat[k] = m.lib.sd_fk(m.ffi.new("sd_count[6]", measured[k].tolist()), w)
        out[k] = list(w)
    return out, nsat


def platform(name, tmp_path):
    if name != "own":
        return load_preset(name)
    return own_radial(tmp_path)


def fk_over_workspace(p, start_offset):
    """300 workspace poses, the sensors' counts of their exact lengths, sd_fk from a start offset by up to
    ``start_offset`` words: ``(q, q_w, residual r (m), IK error ε (m), bound (m, rad), word-scaled κ)``. The
    fixed-point estimate q_w explains the sensors as well as the firmware's IK can when r ≤ max ε + 1 LSB
    (the update's rounding); its error against the float FK (the sampled pose itself) is then the
    first-order propagation |∂L/∂q⁻¹| (ε + r + res/2)."""
    cfg = ControllerConfig.for_platform(p)
    m = compile_generated(generate(p, cfg))
    q = random_poses(p, 300, seed=0, region="workspace")
    res, lsb, sc = cfg.timing.sensor_resolution, cfg.ik_format.length_lsb, word_scales(cfg)
    measured = np.round(leg_lengths(p, q) / res).astype(np.int32)
    step = np.random.default_rng(0).integers(-1, 2, (len(q), 6)) * start_offset
    out, nsat = run_fk(m, measured, (pose_words(q, cfg.ik_format) + step).astype(np.int16))
    assert not nsat.any()
    q_w = out * sc
    L_fx, _ = m.ik(out)
    r = np.abs(measured * res - L_fx * lsb)
    eps = np.abs(leg_lengths(p, q_w) - L_fx * lsb)
    bound = np.array(
        [np.abs(np.linalg.inv(pose_jacobian(p, x, "utn"))) @ (e + d + res / 2) for x, e, d in zip(q_w, eps, r)]
    )
    s = np.linalg.svd(pose_jacobian(p, q, "utn") * sc, compute_uv=False)
    converged = r.max(axis=1) <= eps.max() + lsb
    return q, q_w, converged, bound, s[:, 0] / s[:, -1], lsb


@pytest.mark.parametrize("start", STARTS)
@pytest.mark.parametrize("name", ["utn-dynamic", "gonzalez-dutra-2009", "own"])
def test_sd_fk_error_against_the_float_fk_over_the_workspace(name, start, tmp_path):
    """Every estimate explains the sensors as well as the IK can, and is within the first-order bound of the
    float FK (10 % for the second-order term: a few mm on legs of ~0.5 m, ~1 %): millimetres on the default
    format, the IK's resolution (below 5 LSB on the presets, as the first version's chord; our own platform's
    Jacobian is worse conditioned, its bound reaches 6 mm)."""
    q, q_w, converged, bound, _, lsb = fk_over_workspace(platform(name, tmp_path), STARTS[start])
    assert converged.all()
    assert np.all(np.abs(q_w - q) <= 1.1 * bound)
    if name != "own":
        assert np.abs(q_w - q)[:, :3].max() < 5 * lsb


def test_sd_fk_converges_on_utn_kinematic():
    """utn-kinematic (0.1 m home height, ±0.35 rad), where a chord with the home gain diverges (spectral
    radius 1.8): from a tick's offset the estimate sd_fk returns (the iterate that explains the sensors best)
    explains them as well as the IK can at every pose, the ill-conditioned ones too (κ above 1000, where the
    IK's 1-LSB resolution leaves the step's near-null direction undetermined and the later iterates wander).
    The error against the float FK is not pinned to the first-order bound here: on legs of ~0.1–0.3 m the
    second-order term of a few-mm residual is not small (up to 1.3× that bound)."""
    q, q_w, converged, _, kappa, _ = fk_over_workspace(load_preset("utn-kinematic"), STARTS["tick"])
    assert converged.all() and (kappa > 1000).any()


def test_sd_fk_operation_count_is_the_cycle_estimates():
    """The instrumented build counts, per sd_fk call, exactly the operations the cycle estimate costs, and
    the README states that estimate."""
    p = load_preset("utn-dynamic")
    cfg = ControllerConfig.for_platform(p)
    g = generate(p, cfg)
    m = compile_generated(g, counting=True)
    m.reset_op_counts()
    run_fk(
        m,
        np.round(leg_lengths(p, p.home_pose()[None]) / cfg.timing.sensor_resolution).astype(np.int32),
        pose_words(p.home_pose()[None], cfg.ik_format).astype(np.int16),
    )
    counted = {k: v for k, v in m.op_counts().items() if v}
    assert counted == dict(g.fk_ops)
    assert g.fk_cycles.cycles > FK_ITERATIONS * g.ik_cycles.cycles
    assert f"Cycle estimate: {g.fk_cycles.cycles:.0f} cycles" in g.files["README.md"]
