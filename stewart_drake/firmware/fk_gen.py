"""``sd_fk`` of the generated firmware: the controller's pose estimate from the leg sensors, in fixed point.

    int sd_fk(const sd_count measured[6], sd_word pose[6]);   /* pose: the previous estimate in, the new out */

A chord (simplified Newton) iteration on the firmware's own IK: ``FK_ITERATIONS`` times,
e = measured − sd_ik(pose) · counts_per_LSB (counts) and pose += round(K e), with K = (∂L/∂q)⁻¹ at the home
pose (q the pose words: length LSBs and Q(word_bits−1) fractions of π) computed here at generation time
as 16-bit mantissas with a shift per pose word. No division, no square root beyond sd_ik's, a fixed
number of operations (so a fixed cycle count: ``fk_ops``). The chord contracts the error by
‖I − K ∂L/∂q(q)‖ per iteration (< 1 over the workspace of the presets; the tests check the result
against the float FK over the workspace), from the previous tick's estimate a few LSB away. Its fixed
points are the poses whose firmware IK matches the sensors to within the step's rounding: the estimate
is as good as the fixed-point IK it inverts.
"""

from __future__ import annotations

from collections import Counter

import numpy as np

from stewart_drake.control.gains import ControllerConfig, counts_per_lsb
from stewart_drake.core.geometry import Platform
from stewart_drake.core.kinematics import inverse_jacobian
from stewart_drake.core.rotations import angular_velocity_map
from stewart_drake.core.sampling import random_poses

FK_ITERATIONS = 6
MANTISSA_MAX = 32767
CONTRACTION_POSES = 256  # workspace poses the chord's contraction is evaluated on at generation time
_CONTRACTION: dict[bytes, float] = {}  # by geometry and convention: the C engine generates once per simulation


def pose_jacobian(platform: Platform, pose, convention: str) -> np.ndarray:
    """``(..., 6, 6)`` ∂L/∂q at ``(..., 6)`` poses: J⁻¹ · diag(I, E(angles)), q = [p (m), angles (rad)]."""
    A = inverse_jacobian(platform, pose, convention)
    E = angular_velocity_map(np.asarray(pose)[..., 3:], convention)
    return np.concatenate([A[..., :3], A[..., 3:] @ E], axis=-1)


def word_scales(config: ControllerConfig) -> np.ndarray:
    """``(6,)`` SI units per pose word: the length LSB for positions, π / 2^f for angles."""
    fmt = config.ik_format
    return np.r_[np.full(3, fmt.length_lsb), np.full(3, np.pi / (1 << fmt.frac_bits))]


def fk_gain(platform: Platform, config: ControllerConfig) -> np.ndarray:
    """``(6, 6)`` K in pose words per sensor count: (∂L/∂q at home)⁻¹ scaled to the words and counts."""
    K = np.linalg.inv(pose_jacobian(platform, platform.home_pose(), config.convention))
    return K * config.timing.sensor_resolution / word_scales(config)[:, None]


def fk_gain_words(platform: Platform, config: ControllerConfig) -> tuple[np.ndarray, np.ndarray]:
    """``(mantissas (6, 6) int, shifts (6,) int)``: K[j, i] ≈ mantissa[j, i] / 2^shift[j], each row's
    largest mantissa in [2^14, 2^15)."""
    K = fk_gain(platform, config)
    big = np.abs(K).max(axis=1)
    shifts = np.floor(np.log2(MANTISSA_MAX / big)).astype(int)
    shifts = np.maximum(shifts, 1)
    m = np.round(K * 2.0 ** shifts[:, None]).astype(np.int64)
    return np.clip(m, -MANTISSA_MAX, MANTISSA_MAX), shifts


def contraction(platform: Platform, config: ControllerConfig) -> float:
    """The chord's worst spectral radius of I − K ∂L/∂q over ``CONTRACTION_POSES`` sampled workspace poses
    (``core.sampling``, seed 0; a sample, not a bound): below 1 the iteration converges there, at that rate."""
    conv = config.convention
    parts = (
        platform.base_anchors,
        platform.top_anchors,
        platform.top_anchors_per_leg,
        platform.rotation_centre,
        platform.stroke,
    )
    key = b"".join(np.asarray(a, dtype=float).tobytes() for a in (*parts, platform.home_pose())) + conv.encode()
    if key not in _CONTRACTION:
        K = np.linalg.inv(pose_jacobian(platform, platform.home_pose(), conv))
        q = random_poses(platform, CONTRACTION_POSES, seed=0, region="workspace", convention=conv)
        _CONTRACTION[key] = float(np.abs(np.linalg.eigvals(np.eye(6) - K @ pose_jacobian(platform, q, conv))).max())
    return _CONTRACTION[key]


def fk_ops(ik_ops: Counter) -> Counter:
    """Operations of one ``sd_fk``: per iteration the IK, 6 errors (scale, subtract), 36 multiply-accumulates
    of a 16-bit gain by a 32-bit error (two multiplies and an add each) and 6 rounded updates."""
    per = Counter(ik_ops)
    per.update({"L_mult": 6 + 2 * 36, "L_sub": 6, "L_add": 36 + 6, "add": 6})
    return Counter({k: FK_ITERATIONS * v for k, v in per.items()})


def fk_prototype() -> str:
    """The header's declaration of ``sd_fk``."""
    return (
        "/* the pose from the leg sensors: pose holds the previous estimate on entry, the new one on return\n"
        f"   ({FK_ITERATIONS} chord iterations on sd_ik with the gain of the home pose); returns the saturation count */\n"
        "int sd_fk(const sd_count measured[6], sd_word pose[6]);\n"
    )


def fk_source(platform: Platform, config: ControllerConfig) -> str:
    """The C of ``sd_fk`` (appended to ``sd_firmware.c``, after the tick: it uses asr, satw, sd_ik)."""
    m, s = fk_gain_words(platform, config)
    rows = ",\n    ".join("{" + ", ".join(f"{int(v)}L" for v in row) + "}" for row in m)
    return f"""
/* ---- sd_fk: chord iterations on sd_ik, gain K = (dL/dq at home)^-1 in pose words per count,
   K[j][i] = FK_K[j][i] / 2^FK_S[j] (generation time) ---- */
#define SD_FK_ITERATIONS {FK_ITERATIONS}
#define SD_FK_COUNTS_PER_LSB {counts_per_lsb(config)}
static const int32_t FK_K[6][6] = {{
    {rows}
}};
static const int FK_S[6] = {{{", ".join(str(int(v)) for v in s)}}};

int sd_fk(const sd_count measured[6], sd_word pose[6])
{{
    int it, i, j, nsat = 0;
    for (it = 0; it < SD_FK_ITERATIONS; it++) {{
        sd_word L[6];
        int64_t e[6];
        nsat += sd_ik(pose, L);
        for (i = 0; i < 6; i++) {{
            SD_OP(SD_L_mult);
            SD_OP(SD_L_sub);
            e[i] = (int64_t)measured[i] - (int64_t)L[i] * SD_FK_COUNTS_PER_LSB;
        }}
        for (j = 0; j < 6; j++) {{
            int64_t acc = 0;
            for (i = 0; i < 6; i++) {{
                SD_OP(SD_L_mult);
                SD_OP(SD_L_mult);
                SD_OP(SD_L_add);
                acc += (int64_t)FK_K[j][i] * e[i];
            }}
            SD_OP(SD_L_add);
            SD_OP(SD_add);
            pose[j] = (sd_word)satw((int64_t)pose[j] + asr(acc + ((int64_t)1 << (FK_S[j] - 1)), FK_S[j]), &nsat);
        }}
    }}
    return nsat;
}}
"""


def fk_readme(cycles, clock_hz: float, rho: float) -> str:
    """The README's section on ``sd_fk`` with its cycle estimate and the chord's contraction ``rho``."""
    verdict = (
        f"below 1: each iteration shrinks the error at least {1 / rho:.1f}×"
        if rho < 1
        else "NOT below 1: away from home sd_fk may not converge on this platform (use the float FK on the host)"
    )
    return (
        "\n## Pose from the sensors: `sd_fk`\n\n"
        f"`sd_fk(measured, pose)`: {FK_ITERATIONS} chord iterations on `sd_ik` from the previous estimate in `pose`, "
        "gain (∂L/∂q at home)⁻¹ as 16-bit mantissas with a shift per pose word (see `stewart_drake.firmware.fk_gen`). "
        f"Cycle estimate: {cycles.cycles:.0f} cycles = {cycles.cycles / clock_hz * 1e6:.1f} µs "
        f"({FK_ITERATIONS} × (the IK + 6 errors + 36 multiply-accumulates + 6 updates)). Contraction (the spectral "
        f"radius of I − K ∂L/∂q, worst of {CONTRACTION_POSES} sampled workspace poses): {rho:.2f}, {verdict}. Its "
        "accuracy is the IK's: the estimate is a pose whose fixed-point IK matches the sensors as well as that IK "
        "can (a few length LSB on the default format).\n"
    )
