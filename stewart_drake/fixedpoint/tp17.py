"""The seed's DSP56800E inverse kinematics (``tp17.C``, seed 000) ported operation by operation,
vectorised over a batch of poses.

Units are the firmware's: positions px, py, pz in integer millimetres (``Frac16`` variables holding
integers), angles as fractions of pi (C ``double``; ``alpha = 0.1`` means 0.1 pi rad = 18 deg), leg
lengths returned as integer millimetres (``Word16``). The platform is the firmware's integer
geometry: b = 925, d = 150, a = 1225/2 = 612 mm (C integer division), constants FRAC16(0.2886)
for sqrt(3)/6 and FRAC16(0.5773) for sqrt(3)/3.

Two lines of the seed's listing are garbled by its print (``Yt1`` repeats ``extract_h(L_mult(co21,
xt1))`` many times; the ``co32 =`` assignment lost its left-hand side); both are restored by the
symmetry of the other eight lines. The base anchors ``Xb1..Yb6`` the firmware computes first are dead
code: the leg formulas recompute their offsets from b and d (as ``aux32``), and this port does the same.
With :mod:`.q15`'s library functions the port reproduces all 24 DSP values of the seed table exactly.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from stewart_drake.core.argcheck import check_shape, first_index
from stewart_drake.errors import DspPoseError
from stewart_drake.fixedpoint import q15
from stewart_drake.fixedpoint.q15 import (
    FRAC16,
    L_add,
    L_mult,
    L_negate,
    add,
    extract_h,
    mfr32Sqrt,
    negate,
    tfr16CosPIx,
    tfr16SinPIx,
)

TP17_GEOMETRY_MM = {"a": 1225 // 2, "b": 925, "d": 150}
# The firmware's literal constants (their FRAC16 words are 9456, 18916, 16384).
C_SQRT3_6, C_SQRT3_3, C_HALF = 0.2886, 0.5773, 0.5


@dataclass(frozen=True)
class Tp17Trace:
    """Every intermediate word of one batch (arrays over the batch shape ``S``; all int64 words).

    angle_words (S, 3)        FRAC16 of alpha, beta, gamma (pi-fractions)
    sin, cos    (S, 3)        tfr16SinPIx / tfr16CosPIx of those words (Q15)
    R           (S, 3, 3)     co11..co33, the rotation matrix as the firmware holds it (Q15)
    top_T       (3, 3)        xt, yt, zt of the three plate joints in the plate frame (mm)
    top_B       (S, 3, 3)     Xt, Yt, Zt of the three plate joints in the base frame (mm)
    base_offset (6, 3)        the base-anchor offsets the leg formulas subtract, as words (mm):
                              leg vector = top_B[joint] + base_offset[leg]
    leg         (S, 6, 3)     the three leg-vector components (aux16 words, mm)
    L32         (S, 6)        the Frac32 sum of squares handed to mfr32Sqrt
    lengths     (S, 6)        mfr32Sqrt results: the leg lengths (mm)
    """

    angle_words: np.ndarray
    sin: np.ndarray
    cos: np.ndarray
    R: np.ndarray
    top_T: np.ndarray
    top_B: np.ndarray
    base_offset: np.ndarray
    leg: np.ndarray
    L32: np.ndarray
    lengths: np.ndarray


def tp17_plate_words(a: int = 612) -> np.ndarray:
    """``(3, 3)`` xt, yt, zt of the plate joints T1, T2, T3 (mm), as the firmware computes them."""
    h, t, half = FRAC16(C_SQRT3_6), FRAC16(C_SQRT3_3), FRAC16(C_HALF)
    xt1 = extract_h(L_mult(h, a))
    yt1 = extract_h(L_mult(half, a))
    xt2 = extract_h(L_mult(negate(t), a))  # FRAC16(-0.5773) == -FRAC16(0.5773): truncation is symmetric
    xt3 = xt1
    yt3 = extract_h(L_mult(FRAC16(-C_HALF), a))
    return np.array([[xt1, yt1, 0], [xt2, 0, 0], [xt3, yt3, 0]], dtype=np.int64)


def tp17_base_offsets(b: int = 925, d: int = 150) -> np.ndarray:
    """``(6, 3)`` the offsets added to the plate joint to form each leg vector (mm words), exactly as
    the leg formulas compute them (x: ``extract_h(aux32)``; y: the chain of ``add``s of ±d/2, ±b/2)."""
    h, t, half = FRAC16(C_SQRT3_6), FRAC16(C_SQRT3_3), FRAC16(C_HALF)
    o1 = extract_h(L_add(L_negate(L_mult(d, h)), L_negate(L_mult(b, t))))
    o2 = extract_h(L_add(L_negate(L_mult(d, h)), L_mult(b, h)))
    o3 = extract_h(L_add(L_mult(d, t), L_mult(b, h)))
    hd = extract_h(L_mult(half, d))
    hb = extract_h(L_mult(half, b))
    # y offsets are applied as successive saturating adds in tp17_trace (order matters only on saturation)
    return np.array(
        [[o1, -hd, 0], [o2, -hd - hb, 0], [o3, -hb, 0], [o3, hb, 0], [o2, hd + hb, 0], [o1, hd, 0]], dtype=np.int64
    )


# Seed 000's comparison table ("Tabla comparativa"): the poses as printed (px, py, pz mm; alpha, beta, gamma
# in degrees), the same poses as the firmware takes them (the printed degrees / 180, fractions of pi: 18° -> 0.1)
# and the lengths the DSP printed (mm). Read-only: the analyses and the tests share them.
SEED_POSES_MM_DEG = np.array(
    [[0, 0, 100, 0, 0, 0], [0, 0, 120, 18, 0, 0], [0, 0, 130, 27, 0, 0], [10, 10, 140, 36, 0, 18]], dtype=float
)
SEED_DSP_POSES = np.c_[SEED_POSES_MM_DEG[:, :3], SEED_POSES_MM_DEG[:, 3:] / 180.0]
SEED_DSP_MM = np.array(
    [
        [475, 471, 473, 473, 471, 475],
        [504, 515, 477, 477, 469, 458],
        [523, 548, 480, 480, 478, 449],
        [638, 521, 547, 391, 608, 325],
    ],
    dtype=float,
)
for _table in (SEED_POSES_MM_DEG, SEED_DSP_POSES, SEED_DSP_MM):
    _table.flags.writeable = False

# leg i ends at plate joint LEG_JOINT[i]; its y offset is built from these terms, added in order
LEG_JOINT = (0, 0, 1, 1, 2, 2)
_Y_TERMS = (("-hd",), ("-hd", "-hb"), ("-hb",), ("+hb",), ("+hd", "+hb"), ("+hd",))


def check_dsp_poses(poses) -> np.ndarray:
    """Validate ``(..., 6)`` firmware poses [px, py, pz mm, alpha, beta, gamma pi-fractions] and
    return them as float. Positions are truncated toward zero to integer mm (the C assignment to a
    ``Frac16``) and must fit 16 bits; angles must lie in [-1, 1] (one turn). Errors name the pose."""
    q = np.asarray(poses, dtype=float)

    check_shape(q, "DSP poses", (..., 6), DspPoseError)
    pos = np.trunc(q[..., :3])
    for bad, template, part in (
        (~np.isfinite(q).all(axis=-1), DspPoseError.NOT_FINITE, slice(None)),
        (((pos < q15.MIN16) | (pos > q15.MAX16)).any(axis=-1), DspPoseError.POSITION, slice(3)),
        ((np.abs(q[..., 3:]) > 1.0).any(axis=-1), DspPoseError.ANGLES, slice(3, None)),
    ):
        k = first_index(bad)
        if k is not None:
            name = "pose" if k == () else f"pose {k[0] if len(k) == 1 else k}"
            raise DspPoseError(template.format(name=name, values=q[k][part].tolist()))
    return q


def _tp17_core(q: np.ndarray, a: int, b: int, d: int, trace: bool) -> dict:
    """The loop body on validated poses ``q`` (..., 6); returns the lengths and, with ``trace``,
    every intermediate word (kept as separate arrays while computing: strided writes are slow)."""
    S = q.shape[:-1]
    px, py, pz = (np.trunc(q[..., k]).astype(np.int64) for k in range(3))
    w = FRAC16(q[..., 3:])
    aw, bw, gw = w[..., 0], w[..., 1], w[..., 2]
    cosA, cosB, cosG = tfr16CosPIx(aw), tfr16CosPIx(bw), tfr16CosPIx(gw)
    sinA, sinB, sinG = tfr16SinPIx(aw), tfr16SinPIx(bw), tfr16SinPIx(gw)

    def m(x, y):
        return extract_h(L_mult(x, y))

    sAsB = m(sinA, sinB)
    sAcB = m(sinA, cosB)
    co = [
        [add(m(cosB, cosG), m(sAsB, sinG)), add(m(negate(cosB), sinG), m(sAsB, cosG)), m(cosA, sinB)],
        [m(cosA, sinG), m(cosA, cosG), negate(sinA)],
        [add(m(negate(sinB), cosG), m(sAcB, sinG)), add(m(sinB, sinG), m(sAcB, cosG)), m(cosA, cosB)],
    ]
    p = (px, py, pz)
    top_T = tp17_plate_words(a)
    top_B = [
        [
            add(
                add(add(m(co[r][0], int(top_T[j, 0])), m(co[r][1], int(top_T[j, 1]))), m(co[r][2], int(top_T[j, 2]))),
                p[r],
            )
            for r in range(3)
        ]
        for j in range(3)
    ]

    half = FRAC16(C_HALF)
    hd, hb = extract_h(L_mult(half, d)), extract_h(L_mult(half, b))
    terms = {"-hd": negate(hd), "-hb": negate(hb), "+hd": hd, "+hb": hb}
    offsets = tp17_base_offsets(b, d)
    legs, L32 = [], []
    for i in range(6):
        X, Y, Z = top_B[LEG_JOINT[i]]
        X = add(offsets[i, 0], X)  # add(extract_h(aux32), Xt)
        for term in _Y_TERMS[i]:
            Y = add(Y, terms[term])
        legs.append((X, Y, Z))
        L32.append(L_add(L_mult(Z, Z), L_add(L_mult(Y, Y), L_mult(X, X))))
    L32 = np.stack(L32, -1)
    out = {"lengths": mfr32Sqrt(L32)}
    if trace:

        def full(x):
            return np.broadcast_to(x, S)

        out.update(
            angle_words=w,
            sin=np.stack([sinA, sinB, sinG], -1),
            cos=np.stack([cosA, cosB, cosG], -1),
            R=np.stack([np.stack([full(c) for c in row], -1) for row in co], -2),
            top_T=top_T,
            top_B=np.stack([np.stack([full(c) for c in row], -1) for row in top_B], -2),
            base_offset=offsets,
            leg=np.stack([np.stack([full(c) for c in v], -1) for v in legs], -2),
            L32=L32,
        )
    return out


CHUNK = 16384  # poses per pass: keeps the temporaries in cache


def tp17_trace(poses, a: int = 612, b: int = 925, d: int = 150) -> Tp17Trace:
    """Run the firmware's loop body on ``(..., 6)`` poses (mm, pi-fractions); every intermediate word."""
    return Tp17Trace(**_tp17_core(check_dsp_poses(poses), a, b, d, trace=True))


def tp17_leg_lengths(
    poses, a: int = 612, b: int = 925, d: int = 150, counter: q15.SaturationCounter | None = None
) -> np.ndarray:
    """``(..., 6)`` integer leg lengths (mm) the DSP computes for ``(..., 6)`` poses
    [px, py, pz mm; alpha, beta, gamma fractions of pi]. ``counter``: a
    :class:`~.q15.SaturationCounter` to record saturations in (entered for the call; its ``mask``,
    if any, must have the batch shape, and the batch is then computed in one pass)."""
    q = check_dsp_poses(poses)
    if counter is not None:
        with counter:
            return _tp17_core(q, a, b, d, trace=False)["lengths"]
    flat = q.reshape(-1, 6)
    if len(flat) <= CHUNK:
        return _tp17_core(q, a, b, d, trace=False)["lengths"]
    out = np.empty((len(flat), 6), dtype=np.int64)
    for k in range(0, len(flat), CHUNK):
        out[k : k + CHUNK] = _tp17_core(flat[k : k + CHUNK], a, b, d, trace=False)["lengths"]
    return out.reshape(q.shape)


def dsp_poses_from_si(poses_si) -> np.ndarray:
    """``(..., 6)`` SI poses (m, rad) -> the firmware's units (mm, pi-fractions); positions are left
    fractional (the firmware truncates them when it stores them)."""
    q = np.array(poses_si, dtype=float)
    q[..., :3] *= 1e3
    q[..., 3:] /= np.pi
    return q


def dsp_poses_to_si(poses_dsp) -> np.ndarray:
    """The firmware's ``(..., 6)`` poses (mm, pi-fractions) -> SI (m, rad), positions truncated to whole mm."""
    q = np.array(poses_dsp, dtype=float)
    q[..., :3] = np.trunc(q[..., :3]) * 1e-3
    q[..., 3:] *= np.pi
    return q


# ------------------------------------------------------------------------------------------------
# Where the firmware's error comes from: a telescoping chain of models between the float IK and the DSP.

ERROR_STAGES = (
    ("a = 612", "the plate side a = 1225/2 = 612 mm (C integer division) instead of 612.5 mm"),
    (
        "anchor words",
        "anchors as the firmware's integer-mm words: FRAC16(0.2886), FRAC16(0.5773) and extract_h truncation",
    ),
    ("angle words", "the angles truncated to Q15 words by FRAC16 (sin/cos still exact)"),
    ("sin/cos library", "tfr16SinPIx/tfr16CosPIx instead of the exact sine and cosine of the angle words"),
    ("matrix products", "co11..co33: products of sines and cosines truncated by extract_h(L_mult)"),
    ("R·anchor products", "Xt, Yt, Zt: R times the anchor words truncated to integer mm (extract_h), summed"),
    ("square root", "mfr32Sqrt: the integer length nearest the root of the integer sum of squares"),
)


def _model_lengths(top, offsets, R, p):
    """|p + R t_joint(i) + offset_i| for float top (3, 3), offsets (6, 3), R (..., 3, 3), p (..., 3)."""
    t = top[list(LEG_JOINT)]  # (6, 3)
    v = p[..., None, :] + np.einsum("...rk,ik->...ir", R, t) + offsets
    return np.sqrt(np.einsum("...k,...k->...", v, v))


def _rot_utn_from_sc(s, c):
    """R = Ry(b) Rx(a) Rz(g) from float sines/cosines (..., 3) of (a, b, g)."""
    sA, sB, sG = s[..., 0], s[..., 1], s[..., 2]
    cA, cB, cG = c[..., 0], c[..., 1], c[..., 2]
    return np.stack(
        [
            np.stack([cB * cG + sA * sB * sG, -cB * sG + sA * sB * cG, cA * sB], -1),
            np.stack([cA * sG, cA * cG, -sA], -1),
            np.stack([-sB * cG + sA * cB * sG, sB * sG + sA * cB * cG, cA * cB], -1),
        ],
        -2,
    )


def tp17_error_stages(poses, a: int = 612, b: int = 925, d: int = 150) -> dict:
    """Split DSP - float IK into the contributions of :data:`ERROR_STAGES`, for ``(..., 6)`` firmware
    poses (mm, pi-fractions). The float reference is the exact platform (a = 1225/2 = 612.5 mm) at the
    pose as given (positions truncated to mm, as the firmware stores them).

    Returns ``{"float": (..., 6) mm, "dsp": (..., 6) mm, "models": [(..., 6)] * 8, "stages":
    {name: (..., 6) mm}}`` where ``models[0]`` is the float IK, ``models[-1]`` the DSP's integers and
    stage k = models[k+1] - models[k], so the stages sum exactly to dsp - float.
    """
    q = check_dsp_poses(poses)
    tr = tp17_trace(q, a, b, d)
    p = np.trunc(q[..., :3])
    ang = q[..., 3:] * np.pi
    s3 = np.sqrt(3.0)

    def exact_geometry(a_mm):
        top = np.array([[s3 / 6 * a_mm, a_mm / 2, 0], [-s3 / 3 * a_mm, 0, 0], [s3 / 6 * a_mm, -a_mm / 2, 0]])
        base = np.array(
            [
                [s3 / 6 * (2 * b + d), d / 2, 0],
                [-s3 / 6 * (b - d), (b + d) / 2, 0],
                [-s3 / 6 * (b + 2 * d), b / 2, 0],
                [-s3 / 6 * (b + 2 * d), -b / 2, 0],
                [-s3 / 6 * (b - d), -(b + d) / 2, 0],
                [s3 / 6 * (2 * b + d), -d / 2, 0],
            ]
        )
        return top, -base

    R_exact = _rot_utn_from_sc(np.sin(ang), np.cos(ang))
    ang_w = tr.angle_words * np.pi / 32768.0
    R_wordangles = _rot_utn_from_sc(np.sin(ang_w), np.cos(ang_w))
    R_lib = _rot_utn_from_sc(tr.sin / 32768.0, tr.cos / 32768.0)
    R_words = tr.R / 32768.0
    top_w, off_w = tr.top_T.astype(float), tr.base_offset.astype(float)
    a_float = 1225 / 2 if a == 1225 // 2 else a  # the design value the C's 1225/2 meant
    models = [
        _model_lengths(*exact_geometry(a_float), R_exact, p),
        _model_lengths(*exact_geometry(a), R_exact, p),
        _model_lengths(top_w, off_w, R_exact, p),
        _model_lengths(top_w, off_w, R_wordangles, p),
        _model_lengths(top_w, off_w, R_lib, p),
        _model_lengths(top_w, off_w, R_words, p),
        np.sqrt(np.einsum("...k,...k->...", tr.leg.astype(float), tr.leg.astype(float))),
        tr.lengths.astype(float),
    ]
    stages = {name: models[k + 1] - models[k] for k, (name, _) in enumerate(ERROR_STAGES)}
    return {"float": models[0], "dsp": models[-1], "models": models, "stages": stages}
