"""The recipe's words at single poses, in integers only: what ``recipe.evaluate`` gives on one-pose cells
(``lo == hi``) for the trace words and their clamp flags, without the float enclosures of the errors (at a
pose the sampled error comes from the emulation against the float IK, ``sampling.length_errors``). The
sampled side of the certificate evaluates tens of thousands of poses; this is its fast path (a test pins
it word for word and flag for flag against ``evaluate``)."""

from __future__ import annotations

import numpy as np

from stewart_drake.firmware.certify.recipe import AXES, CellEval, Model, Recorder, isqrt_nearest, rotation_entry


def point_words(model: Model, w: np.ndarray) -> CellEval:
    """``evaluate(model, w, w)``'s words and flags at the ``(n, 6)`` pose words ``w`` (int64): ``pre_lo`` =
    ``pre_hi`` the words before saturation, ``possible`` = ``certain`` where the word clamps; the error
    enclosures are not computed (``err_lo`` = −inf, ``err_hi`` = inf)."""
    w = np.asarray(w, dtype=np.int64)
    n, f = w.shape[0], model.fmt.frac_bits
    lo, hi = model.lo, model.hi
    rec = Recorder(n, model)
    rec.pre_lo[:, :6] = w
    words = {}
    for k, ax in enumerate(AXES):  # sine and cosine words: the tables at the angle word, clamped
        a = w[:, 3 + k]
        for name, table, label in (("s", model.tables.sin_pre, "sin"), ("c", model.tables.cos_pre, "cos")):
            pre = table.query(a, a)[0]
            words[f"{name}{ax}"] = rec.sat(f"{label}.{ax}", pre, pre, lo, hi, final=True)[0]
    R = {}
    for i in range(3):  # rotation entries: products and sums as rotation_from_words forms them
        for j in range(3):
            acc, inner = rotation_entry(model, words, i, j)
            k = rec.index[f"R[{i}][{j}]"]
            rec.possible[:, k] |= inner
            R[(i, j)] = rec.sat(f"R[{i}][{j}]", acc, acc, lo, hi, final=True)[0]
    for i in range(6):  # legs: v = p + sum_k floor(R_rk c_ik / 2^f) - b; sq = sum v^2; L = isqrt_near(sq)
        sq = np.zeros(n, dtype=np.int64)
        for r in range(3):
            name = f"leg{i + 1}.{AXES[r]}"
            v = w[:, r]
            for k in range(3):
                c = int(model.r_T[i, k])
                if c:
                    v = rec.sat(name, v + ((R[(r, k)] * c) >> f), v + ((R[(r, k)] * c) >> f), lo, hi)[0]
            b = int(model.B[i, r])
            if b:
                v = rec.sat(name, v - b, v - b, lo, hi, final=True)[0]
            else:
                rec.pre_lo[:, rec.index[name]] = rec.pre_hi[:, rec.index[name]] = v
            sq = rec.sat(f"sq{i + 1}", sq + v * v, sq + v * v, -model.acc_hi - 1, model.acc_hi, final=r == 2)[0]
        L = isqrt_nearest(sq)
        rec.sat(f"length{i + 1}", L, L, lo, hi, final=True)
    rec.certain[:] = rec.possible  # a single pose: a word that may clamp does
    rec.pre_hi[:] = rec.pre_lo
    return CellEval(
        rec.pre_lo, rec.pre_hi, rec.possible, rec.certain, np.full((n, 6), -np.inf), np.full((n, 6), np.inf)
    )
