"""The seed's DSP56800E firmware (tp17.C) as a function: ``dsp_ik`` gives the six integer leg lengths the
firmware computes for a pose, bit-exactly, with the float IK of the same pose beside them."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from stewart_drake.api.result import Result
from stewart_drake.core.argcheck import as_choice, as_flag, as_real_array, param
from stewart_drake.core.geometry import load_preset
from stewart_drake.core.rotations import angle_scale
from stewart_drake.core.sanity import above_base, below_base_message, plate_anchor_heights
from stewart_drake.errors import API_POSE_SHAPE, DspPoseError, UsageError
from stewart_drake.firmware.engine import ENGINES, resolve_engine
from stewart_drake.firmware.host import tp17_leg_lengths_c
from stewart_drake.fixedpoint.q15 import SaturationCounter
from stewart_drake.fixedpoint.tp17 import TP17_GEOMETRY_MM, check_dsp_poses, tp17_error_stages, tp17_trace

__all__ = ["dsp_ik", "DspIKResult"]

# The float IK's platform: utn-kinematic's (the firmware's a = 1225 // 2 = 612 mm is 612.5 mm there).
FLOAT_GEOMETRY_MM = {"a": 612.5, "b": 925, "d": 150}


@dataclass(repr=False)
class DspIKResult(Result):
    """The firmware's leg lengths for one pose (``dsp_ik``). The firmware works in its own integer units:
    whole millimetres for positions and lengths, FRAC16 words (fractions of pi × 32768) for angles; those
    words are kept as the firmware computes them, and every other number is SI.

    Attributes:
        firmware_pose: ``(6,)`` the pose as the firmware stores it: px, py, pz in whole mm (truncated toward
            zero, as the C assignment to a ``Frac16``) and alpha, beta, gamma in fractions of pi.
        angle_words: the three FRAC16 angle words the firmware computes with.
        engine: ``"python"`` (the numpy emulation) or ``"c"`` (tp17.C compiled for the host).
        dsp_words: ``(6,)`` the firmware's leg lengths, integer mm (its own unit).
        float_lengths: ``(6,)`` the float IK's leg lengths of the same pose on utn-kinematic, m.
        saturations: saturated operations of the firmware's arithmetic, by kind (empty when none).
        flags: why the result is outside limits (plate below the base, saturated arithmetic); empty when good.
        trace: with ``trace=True`` the firmware's intermediate words (``sin_q15``, ``cos_q15``, ``R_q15``,
            ``plate_joints_T_mm``, ``plate_joints_B_mm``, ``leg_vectors_mm``, ``L32``: Q15 words and
            integer mm, the firmware's units), else None.
    """

    firmware_pose: np.ndarray
    angle_words: list
    engine: str
    dsp_words: np.ndarray
    float_lengths: np.ndarray
    saturations: dict
    flags: list
    trace: dict | None = None

    @property
    def pose(self) -> np.ndarray:
        """``(6,)`` the pose the firmware computes, in m and rad (positions whole mm)."""
        q = self.firmware_pose
        return np.r_[q[:3] * 1e-3, q[3:] * np.pi]

    @property
    def dsp_lengths(self) -> np.ndarray:
        """``(6,)`` the firmware's leg lengths in m (its integer mm words × 1e-3)."""
        return self.dsp_words * 1e-3

    @property
    def difference(self) -> np.ndarray:
        """``(6,)`` the firmware's lengths minus the float IK's, m."""
        return (self.dsp_words - self.float_lengths * 1e3) * 1e-3

    @property
    def ok(self) -> bool:
        """No flag: the plate above the base and no saturated arithmetic."""
        return not self.flags

    def _fields(self) -> dict:
        p = self.pose
        out = {
            "pose": {
                "px": p[0],
                "py": p[1],
                "pz": p[2],
                "alpha": p[3],
                "beta": p[4],
                "gamma": p[5],
                "angle_words": self.angle_words,
            },
            "geometry": {
                "firmware": {k: v * 1e-3 for k, v in TP17_GEOMETRY_MM.items()},
                "float": {k: v * 1e-3 for k, v in FLOAT_GEOMETRY_MM.items()},
            },
            "engine": self.engine,
            "dsp_lengths": self.dsp_lengths,
            "float_lengths": self.float_lengths,
            "difference": self.difference,
            "saturations": self.saturations,
            "flags": self.flags,
        }
        if self.trace is not None:
            out["trace"] = self.trace
        return out


def firmware_pose(pose: ArrayLike, angle_unit: str = "rad", what: str = "pose") -> np.ndarray:
    """``(6,)`` a pose [px, py, pz mm, a, b, g in ``angle_unit``] as the firmware's [mm, fractions of pi];
    an angle beyond ±180° is refused naming ``A``/``B``/``G`` and the value as given."""
    raw = as_real_array(pose, what)
    if raw.shape != (6,):
        raise UsageError(API_POSE_SHAPE.format(what=what, shape=raw.shape))
    q = raw.copy()
    with np.errstate(over="ignore"):  # 1e308 deg is inf pi: refused just below as beyond ±180°
        q[3:] = raw[3:] * angle_scale(angle_unit) / np.pi
    for k, name in enumerate(("A", "B", "G")):
        if abs(q[3 + k]) > 1.0:
            raise DspPoseError(DspPoseError.ANGLE_OPTION.format(name=name, value=raw[3 + k], unit=angle_unit))
    return check_dsp_poses(q)


def dsp_ik(pose: ArrayLike, *, engine: str = "python", trace: bool = False) -> DspIKResult:
    """The six leg lengths the seed's DSP56800E firmware (tp17.C) computes for a pose, bit-exactly, with
    the float IK of the same pose (on utn-kinematic, whose a = 612.5 mm is the firmware's 612 mm).

    The firmware stores positions as whole millimetres (truncated toward zero; the m → mm product is first
    rounded at 1e-9 mm so that 0.57 m is 570 mm, not 569) and angles as FRAC16 fractions of pi.

    Args:
        pose: ``(6,)`` ``[px, py, pz, alpha, beta, gamma]`` in metres and radians (utn convention); the
            position must fit the firmware's 16-bit mm words and the angles lie within ±pi.
        engine: ``"python"``: the numpy emulation; ``"c"``: tp17.C compiled for the host (bit-identical;
            without a C compiler the Python engine runs, with a note on stderr).
        trace: also keep the firmware's intermediate words.

    Returns:
        The firmware's integer lengths (its own mm words), the float IK's lengths and the flags.

    Raises:
        StewartError: a pose of the wrong shape, not finite, beyond ±pi or beyond the 16-bit mm words.
    """
    q = as_real_array(pose, "pose")
    if q.shape != (6,):
        raise UsageError(API_POSE_SHAPE.format(what="pose", shape=q.shape))
    engine = as_choice(engine, "engine", ENGINES)
    trace = as_flag(trace, "trace")
    with np.errstate(over="ignore", invalid="ignore"):
        mm = np.round(q[:3] * 1e3, 9)
    return dsp_ik_firmware(firmware_pose(np.r_[mm, q[3:]], "rad"), engine=engine, trace=trace)


def dsp_ik_firmware(q: np.ndarray, *, engine: str = "python", trace: bool = False) -> DspIKResult:
    """``dsp_ik`` of a firmware pose ``q`` (6,) [mm, fractions of pi] checked by ``firmware_pose``: what
    ``stewart-drake dsp-ik`` calls, so that its typed numbers reach the firmware without a unit round trip."""
    q = check_dsp_poses(q)
    # the firmware's platform is utn-kinematic's (a = 612 vs 612.5 mm). An emulator shows what the firmware
    # computes: a pose whose plate dips below the base is computed, shown and flagged, as ik does for a pose
    # outside the stroke. Any pose of the DSP's range (16-bit mm, one turn: ``check_dsp_poses``) is computed.
    kin = load_preset("utn-kinematic")
    pose_si = np.r_[np.trunc(q[:3]) * 1e-3, q[3:] * np.pi]
    flags = [] if above_base(kin, pose_si) else [below_base_message(param("pose"), plate_anchor_heights(kin, pose_si))]
    with SaturationCounter() as sat:
        tr = tp17_trace(q)
    if sat.total:
        flags.append(
            f"the firmware's arithmetic saturated ({dict(sat.counts)}); its lengths for this pose are clipped, not geometric"
        )
    flt = tp17_error_stages(q)["float"]
    engine = resolve_engine(engine, "stewart-drake dsp-ik")
    dsp = tp17_leg_lengths_c(q) if engine == "c" else tr.lengths.astype(int)
    words = None
    if trace:
        words = {
            "sin_q15": tr.sin.tolist(),
            "cos_q15": tr.cos.tolist(),
            "R_q15": tr.R.tolist(),
            "plate_joints_T_mm": tr.top_T.tolist(),
            "plate_joints_B_mm": tr.top_B.tolist(),
            "leg_vectors_mm": tr.leg.tolist(),
            "L32": tr.L32.tolist(),
        }
    return DspIKResult(
        np.r_[np.trunc(q[:3]), q[3:]],
        tr.angle_words.tolist(),
        engine,
        np.asarray(dsp, dtype=int),
        np.asarray(flt, dtype=float) * 1e-3,
        dict(sat.counts),
        flags,
        words,
    )
