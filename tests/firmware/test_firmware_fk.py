"""``sd_fk`` of the generated firmware (``firmware.fk_gen``): the pose from the leg sensors in fixed point,
against the float FK over the workspace, its operation count (the cycle estimate's) and the contraction
the generator reports."""

import numpy as np
import pytest

from stewart_drake.control.gains import ControllerConfig
from stewart_drake.core.geometry import load_preset
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.core.sampling import random_poses
from stewart_drake.firmware.fk_gen import contraction, pose_jacobian, word_scales
from stewart_drake.firmware.generate import generate
from stewart_drake.firmware.module import compile_generated
from stewart_drake.fixedpoint.generic import pose_words


def run_fk(m, measured, start):
    out = np.empty_like(start)
    for k in range(len(start)):
        w = m.ffi.new("sd_word[6]", start[k].tolist())
        m.lib.sd_fk(m.ffi.new("sd_count[6]", measured[k].tolist()), w)
        out[k] = list(w)
    return out


@pytest.mark.parametrize("name", ["utn-dynamic", "gonzalez-dutra-2009"])
def test_sd_fk_error_against_the_float_fk_over_the_workspace(name):
    """300 workspace poses, the sensors' counts of their exact lengths, sd_fk from the previous estimate
    a few LSB off (±3 length LSB, ±30 angle words: a tick of fast motion). The float FK's answer is the
    sampled pose itself. The fixed-point estimate q_w explains the sensors as well as the firmware's IK
    can: the residual r = measured − IK_fx(q_w) is at most the IK's own error ε = |L(q_w) − IK_fx(q_w)|
    (largest over the sample) plus one LSB of the update's rounding; and its error against the float FK
    is the first-order propagation of those residuals, |q_w − q| ≤ |∂L/∂q⁻¹| (ε + |r| + res/2), with 10 %
    for the second-order term (a few mm on legs of ~0.5 m: ~1 %)."""
    p = load_preset(name)
    cfg = ControllerConfig.for_platform(p)
    m = compile_generated(generate(p, cfg))
    q = random_poses(p, 300, seed=0, region="workspace")
    res, lsb, sc = cfg.timing.sensor_resolution, cfg.ik_format.length_lsb, word_scales(cfg)
    measured = np.round(leg_lengths(p, q) / res).astype(np.int32)
    rng = np.random.default_rng(0)
    start = (pose_words(q, cfg.ik_format) + rng.integers(-3, 4, (len(q), 6)) * np.r_[1, 1, 1, 10, 10, 10]).astype(
        np.int16
    )
    out = run_fk(m, measured, start)
    q_w = out * sc
    L_fx, nsat = m.ik(out)
    assert not nsat.any()
    r = np.abs(measured * res - L_fx * lsb)
    eps = np.abs(leg_lengths(p, q_w) - L_fx * lsb)
    assert r.max() <= eps.max() + lsb
    bound = np.array(
        [np.abs(np.linalg.inv(pose_jacobian(p, x, "utn"))) @ (e + d + res / 2) for x, e, d in zip(q_w, eps, r)]
    )
    assert np.all(np.abs(q_w - q) <= 1.1 * bound)
    assert np.abs(q_w - q)[:, :3].max() < 5 * lsb  # millimetres on the default format: the IK's resolution


def test_sd_fk_operation_count_is_the_cycle_estimates():
    """The instrumented build counts, per sd_fk call, exactly the operations the cycle estimate costs."""
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
    assert g.fk_cycles.cycles > 6 * g.ik_cycles.cycles


def test_contraction_reported_by_the_generator():
    """The chord converges on utn-dynamic's workspace (spectral radius < 1) and not on utn-kinematic's,
    and the README says which."""
    ok, bad = load_preset("utn-dynamic"), load_preset("utn-kinematic")
    assert contraction(ok, ControllerConfig.for_platform(ok)) < 1 < contraction(bad, ControllerConfig.for_platform(bad))
    assert "NOT below 1" in generate(bad, ControllerConfig.for_platform(bad)).files["README.md"]
    assert "below 1: each iteration" in generate(ok, ControllerConfig.for_platform(ok)).files["README.md"]
