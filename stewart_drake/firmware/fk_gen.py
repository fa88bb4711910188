"""``sd_fk`` of the generated firmware: the controller's pose estimate from the leg sensors, in fixed point.

    int sd_fk(const sd_count measured[6], sd_word pose[6]);   /* pose: the previous estimate in, the new out */

Newton on the firmware's own IK: ``FK_ITERATIONS`` times, e = measured − sd_ik(pose) · counts_per_LSB (counts),
the Jacobian of the current estimate from the IK's leg vectors l_i (rows [l_i, (r_i × l_i)ᵀ E(angles)]: the
rows of J⁻¹ · diag(I, E) times L_i, so the right-hand side is L_i e_i and no length is divided), the 6×6
system solved by elimination with partial pivoting in 64-bit integers, pose += the rounded step. The answer is
the estimate with the smallest largest |e_i| among the start and the iterates (the last evaluated by one more
IK): once converged the residuals are the IK's ±1 LSB, which a step multiplies by the Jacobian's conditioning,
so a later iterate may be worse than an earlier one. A fixed number of operations (so a fixed cycle count:
``fk_ops``). Why Newton and not a chord with the home
pose's gain (the first version): on utn-kinematic's workspace (a 0.1 m home height, ±0.35 rad) ∂L/∂q
changes so much that I − K ∂L/∂q has eigenvalues outside the unit disc (spectral radius 1.8, eigenvalues of
K ∂L/∂q with negative real parts: no damping converges); Newton's Jacobian is the current estimate's, so
from a previous estimate within its convergence ball (a tick of motion) it converges quadratically
until the IK's resolution stops it. Its fixed points are the poses whose firmware IK matches the sensors
to within the step's rounding: the estimate is as good as the fixed-point IK it inverts.
"""

from __future__ import annotations

from collections import Counter

import numpy as np

from stewart_drake.control.gains import ControllerConfig, counts_per_lsb
from stewart_drake.core.geometry import Platform
from stewart_drake.core.kinematics import inverse_jacobian
from stewart_drake.core.rotations import angular_velocity_map
from stewart_drake.fixedpoint.generic import platform_words

FK_ITERATIONS = 6
Y_BITS = 8  # the unknowns carry 2^Y_BITS (and the counts per LSB) beyond the pose words' units
MUL_BITS = 20  # elimination multipliers (|f| <= 1 by partial pivoting) in Q20
UPDATE_BITS = 30  # the update's constant factors G_j in Q30
# per-iteration step limits (m, rad): near a singularity the IK's 1-LSB steps make the Newton step jump
# (the step scales as 1 / σ_min); a clamp keeps each iteration local, as the float Newton's 0.1 m / 0.5 rad
MAX_STEP_M, MAX_STEP_RAD = 0.02, 0.05


def pose_jacobian(platform: Platform, pose, convention: str) -> np.ndarray:
    """``(..., 6, 6)`` ∂L/∂q at ``(..., 6)`` poses: J⁻¹ · diag(I, E(angles)), q = [p (m), angles (rad)]."""
    A = inverse_jacobian(platform, pose, convention)
    E = angular_velocity_map(np.asarray(pose)[..., 3:], convention)
    return np.concatenate([A[..., :3], A[..., 3:] @ E], axis=-1)


def word_scales(config: ControllerConfig) -> np.ndarray:
    """``(6,)`` SI units per pose word: the length LSB for positions, π / 2^f for angles."""
    fmt = config.ik_format
    return np.r_[np.full(3, fmt.length_lsb), np.full(3, np.pi / (1 << fmt.frac_bits))]


def update_factors(config: ControllerConfig) -> np.ndarray:
    """``(6,)`` int G_j: pose word j moves by y_j G_j / 2^UPDATE_BITS, y_j the solution of the scaled system
    (positions: LSB · counts_per_LSB · 2^Y_BITS per word; angles: π / 2^f of that)."""
    cpl = counts_per_lsb(config)
    c = np.pi / (1 << config.ik_format.frac_bits)
    per = np.r_[np.ones(3), np.full(3, c)] * cpl * (1 << Y_BITS)
    return np.round((1 << UPDATE_BITS) / per).astype(np.int64)


def step_limits(config: ControllerConfig) -> np.ndarray:
    """``(6,)`` int the per-iteration step limits in pose words (``MAX_STEP_M``, ``MAX_STEP_RAD``), at least 1."""
    return np.maximum(
        1, np.floor(np.r_[np.full(3, MAX_STEP_M), np.full(3, MAX_STEP_RAD)] / word_scales(config))
    ).astype(np.int64)


def fk_ops(ik_ops: Counter) -> Counter:
    """Operations of one ``sd_fk``: per evaluated estimate (``FK_ITERATIONS`` + 1) the IK, the angle map E
    (2 products), per leg the row [l_i, (r_i × l_i)ᵀ E] and its right-hand side, and the residual's comparison
    with the best; per Newton step (``FK_ITERATIONS``) the elimination with partial pivoting (15 comparisons,
    15 multipliers, 70 row updates), the back substitution (15 multiply-subtracts, 6 divisions) and 6 updates.
    A division (a 64-bit quotient, the run-time library's) is costed as two ``div_s`` steps and a normalising
    shift."""
    per = Counter(ik_ops)
    per.update({"L_mult": 2, "L_shl": 2, "negate": 2})  # E
    per.update({"L_sub": 6 * 3, "L_add": 6 * 3})  # r_i = l_i - p + b_i
    per.update({"L_mult": 6 * 6, "L_sub": 6 * 3})  # r_i x l_i
    per.update({"L_mult": 6 * 9, "L_add": 6 * 6, "L_shl": 6 * 3})  # (r_i x l_i)^T E
    per.update({"L_mult": 6 * 2, "L_sub": 6, "L_shl": 6})  # e_i, L_i e_i 2^Y
    per.update({"L_sub": 6})  # the residual's largest |e_i|, compared with the best estimate's
    solve = Counter()
    divs = 15 + 6
    solve.update({"L_sub": 15, "L_shl": 15})  # pivot comparisons, multiplier scaling
    solve.update({"L_mult": 70, "L_sub": 70, "L_shl": 70})  # row updates (right-hand side included)
    solve.update({"L_mult": 15, "L_sub": 15})  # back substitution
    solve.update({"div_s": 2 * divs, "L_shl": divs})
    solve.update({"L_mult": 6, "L_add": 6, "L_shl": 6, "add": 6, "sub": 12})  # updates, clamped to the step limits
    # FK_ITERATIONS steps, each from an evaluated estimate, and the last estimate evaluated too
    total = Counter({k: (FK_ITERATIONS + 1) * v for k, v in per.items()})
    total.update({k: FK_ITERATIONS * v for k, v in solve.items()})
    return total


def fk_prototype() -> str:
    """The header's declaration of ``sd_fk``."""
    return (
        "/* the pose from the leg sensors: pose holds the previous estimate on entry, the new one on return\n"
        f"   ({FK_ITERATIONS} Newton iterations on sd_ik, the Jacobian from its leg vectors; the iterate that explains\n"
        "   the sensors best); returns the saturation count */\n"
        "int sd_fk(const sd_count measured[6], sd_word pose[6]);\n"
    )


def _angle_map_c(convention: str) -> str:
    """C of E's columns (Q(f)) from the IK's sines and cosines sn[k], cs[k] of the three angles."""
    if convention == "utn":  # w_a = Ry ex, w_b = ey, w_g = Ry Rx ez
        cols = (
            ("cs[1]", "0", "-sn[1]"),
            ("0", "ONE", "0"),
            ("asr(cs[0] * sn[1], F)", "-sn[0]", "asr(cs[0] * cs[1], F)"),
        )
    else:  # zyx: w_a = Rz Ry ex, w_b = Rz ey, w_g = ez
        cols = (
            ("asr(cs[2] * cs[1], F)", "asr(sn[2] * cs[1], F)", "-sn[1]"),
            ("-sn[2]", "cs[2]", "0"),
            ("0", "0", "ONE"),
        )
    lines = [f"E[{r}][{j}] = {cols[j][r]};" for j in range(3) for r in range(3)]
    count = "SD_OP(SD_L_mult); SD_OP(SD_L_mult); SD_OP(SD_L_shl); SD_OP(SD_L_shl); SD_OP(SD_negate); SD_OP(SD_negate);"
    return "\n        ".join([*lines, count])


def fk_source(platform: Platform, config: ControllerConfig, trace_at: dict) -> str:
    """The C of ``sd_fk`` (appended to ``sd_firmware.c``, after the tick: it uses asr, satw and ik_core with
    the trace layout ``trace_at``)."""
    _, B = platform_words(platform, config.ik_format)
    G = update_factors(config)
    lim = step_limits(config)
    f = config.ik_format.frac_bits
    rows = ", ".join("{" + ", ".join(f"{int(v)}L" for v in b) + "}" for b in B)
    return f"""
/* ---- sd_fk: Newton on sd_ik. Per iteration, with the IK's leg vectors l_i (length words), r_i = l_i - p + b_i
   and its angle map E (columns: the rotation axes of the three angles, Q{f}), the system
   l_i . dp + (r_i x l_i)^T E (c da) = L_i e_i / counts_per_LSB   (c = pi / 2^{f} rad per angle word)
   is the Newton step J^-1 dq = e scaled by L_i (no division by the lengths); it is solved by elimination with
   partial pivoting in 64-bit integers (multipliers Q{MUL_BITS}, unknowns scaled by counts_per_LSB 2^{Y_BITS}). ---- */
#define SD_FK_ITERATIONS {FK_ITERATIONS}
#define SD_FK_COUNTS_PER_LSB {counts_per_lsb(config)}
static const int32_t FK_B[6][3] = {{{rows}}};
static const int64_t FK_G[6] = {{{", ".join(f"{int(v)}LL" for v in G)}}};
static const int64_t FK_MAX[6] = {{{", ".join(f"{int(v)}LL" for v in lim)}}}; /* per-iteration step limits, words */

static int64_t fk_div(int64_t a, int64_t b)
{{
    SD_OP(SD_div_s);
    SD_OP(SD_div_s);
    SD_OP(SD_L_shl);
    return b ? a / b : 0;
}}

int sd_fk(const sd_count measured[6], sd_word pose[6])
{{
    enum {{ F = {f}, ONE = 1 << {f} }};
    int it, i, j, k, nsat = 0;
    sd_word best[6];
    int64_t best_r = -1;
    for (it = 0; it <= SD_FK_ITERATIONS; it++) {{ /* the last pass evaluates the last step's estimate only */
        int32_t tr[SD_TRACE_WORDS];
        sd_word L[6];
        int64_t A[6][7], E[3][3], sn[3], cs[3], y[6], r_max = 0;
        int perm[6];
        nsat += ik_core(pose, L, tr);
        for (k = 0; k < 3; k++) {{
            sn[k] = tr[{trace_at["sin"]} + k];
            cs[k] = tr[{trace_at["cos"]} + k];
        }}
        {_angle_map_c(config.convention)}
        for (i = 0; i < 6; i++) {{
            int64_t l[3], r[3], c[3], e;
            for (k = 0; k < 3; k++) {{
                l[k] = tr[{trace_at["leg"]} + 3 * i + k];
                SD_OP(SD_L_sub);
                SD_OP(SD_L_add);
                r[k] = l[k] - pose[k] + FK_B[i][k];
                A[i][k] = l[k];
            }}
            for (k = 0; k < 3; k++) {{
                int a = (k + 1) % 3, b = (k + 2) % 3;
                SD_OP(SD_L_mult);
                SD_OP(SD_L_mult);
                SD_OP(SD_L_sub);
                c[k] = r[a] * l[b] - r[b] * l[a];
            }}
            for (j = 0; j < 3; j++) {{
                SD_OP(SD_L_mult);
                SD_OP(SD_L_mult);
                SD_OP(SD_L_mult);
                SD_OP(SD_L_add);
                SD_OP(SD_L_add);
                SD_OP(SD_L_shl);
                A[i][3 + j] = asr(c[0] * E[0][j] + c[1] * E[1][j] + c[2] * E[2][j], F);
            }}
            SD_OP(SD_L_mult);
            SD_OP(SD_L_sub);
            e = (int64_t)measured[i] - (int64_t)L[i] * SD_FK_COUNTS_PER_LSB;
            SD_OP(SD_L_sub);
            if ((e < 0 ? -e : e) > r_max) r_max = e < 0 ? -e : e;
            SD_OP(SD_L_mult);
            SD_OP(SD_L_shl);
            A[i][6] = (int64_t)L[i] * e * ((int64_t)1 << {Y_BITS});
            perm[i] = i;
        }}
        if (best_r < 0 || r_max < best_r) {{ /* the estimate that explains the sensors best so far */
            best_r = r_max;
            for (j = 0; j < 6; j++) best[j] = pose[j];
        }}
        if (it == SD_FK_ITERATIONS) break;
        for (k = 0; k < 6; k++) {{ /* elimination, rows permuted by index */
            int m = k;
            int64_t big = A[perm[k]][k] < 0 ? -A[perm[k]][k] : A[perm[k]][k];
            for (i = k + 1; i < 6; i++) {{
                int64_t v = A[perm[i]][k] < 0 ? -A[perm[i]][k] : A[perm[i]][k];
                SD_OP(SD_L_sub);
                if (v > big) {{ big = v; m = i; }}
            }}
            i = perm[k]; perm[k] = perm[m]; perm[m] = i;
            for (i = k + 1; i < 6; i++) {{
                int64_t *a = A[perm[i]], *u = A[perm[k]], fm;
                SD_OP(SD_L_shl);
                fm = fk_div(a[k] * ((int64_t)1 << {MUL_BITS}), u[k]); /* |fm| <= 2^{MUL_BITS} */
                for (j = k + 1; j < 7; j++) {{
                    SD_OP(SD_L_mult);
                    SD_OP(SD_L_sub);
                    SD_OP(SD_L_shl);
                    a[j] -= asr(fm * u[j], {MUL_BITS});
                }}
            }}
        }}
        for (k = 5; k >= 0; k--) {{ /* back substitution (a zero pivot: that unknown stays 0) */
            int64_t *u = A[perm[k]], acc = u[6];
            for (j = k + 1; j < 6; j++) {{
                SD_OP(SD_L_mult);
                SD_OP(SD_L_sub);
                acc -= u[j] * y[j];
            }}
            y[k] = fk_div(acc, u[k]);
        }}
        for (j = 0; j < 6; j++) {{
            int64_t d;
            SD_OP(SD_L_mult);
            SD_OP(SD_L_add);
            SD_OP(SD_L_shl);
            d = asr(y[j] * FK_G[j] + ((int64_t)1 << {UPDATE_BITS - 1}), {UPDATE_BITS});
            SD_OP(SD_sub);
            SD_OP(SD_sub);
            d = d > FK_MAX[j] ? FK_MAX[j] : (d < -FK_MAX[j] ? -FK_MAX[j] : d);
            SD_OP(SD_add);
            pose[j] = (sd_word)satw((int64_t)pose[j] + d, &nsat);
        }}
    }}
    for (j = 0; j < 6; j++) pose[j] = best[j]; /* the first pass sets it: best_r starts below any residual */
    return nsat;
}}
"""


def fk_readme(cycles, clock_hz: float) -> str:
    """The README's section on ``sd_fk`` with its cycle estimate."""
    return (
        "\n## Pose from the sensors: `sd_fk`\n\n"
        f"`sd_fk(measured, pose)`: {FK_ITERATIONS} Newton iterations on `sd_ik` from the previous estimate in `pose`, "
        "returning the estimate that explains the sensors best (the smallest largest-leg residual of the start and "
        "the iterates); "
        "each solves J⁻¹ Δq = e with the Jacobian of the current estimate, built from the IK's own leg vectors "
        "(rows [l_i, (r_i × l_i)ᵀ E], the equation scaled by L_i: no division by the lengths), by elimination with "
        "partial pivoting in 64-bit integers (see `stewart_drake.firmware.fk_gen`). "
        f"Cycle estimate: {cycles.cycles:.0f} cycles = {cycles.cycles / clock_hz * 1e6:.1f} µs "
        f"({FK_ITERATIONS + 1} × (the IK + the Jacobian's rows) + {FK_ITERATIONS} × (the 6×6 system + 21 divisions, "
        "each costed as two `div_s` and a shift)). Its "
        "accuracy is the IK's: the estimate is a pose whose fixed-point IK matches the sensors as well as that IK "
        "can (a few length LSB on the default format), propagated by the Jacobian's conditioning.\n"
    )
