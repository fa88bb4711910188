"""Pose boxes for the certificate: ``KEY=LO..HI`` words in user units, the presets' workspace boxes, and
the conversion to boxes of pose words."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from stewart_drake.core.geometry import Platform
from stewart_drake.core.rotations import angle_scale, length_scale
from stewart_drake.errors import CertifyError, QuantityError
from stewart_drake.fixedpoint.generic import QFormat, pose_words
from stewart_drake.spec.quantity import parse_quantity

KEYS = ("px", "py", "pz", "a", "b", "g")
# Workspace boxes stated for a preset (mm, fractions of pi); other platforms get home ± 10 % of the stroke
# range on x, y, z and ±15° on each angle (the region `firmware check` samples).
WORKSPACE_BOXES = {
    "utn-kinematic": ((-60.0, 60.0), (-60.0, 60.0), (120.0, 250.0), (-0.08, 0.08), (-0.08, 0.08), (-0.08, 0.08)),
}


@dataclass(frozen=True)
class PoseBox:
    """An axis-aligned box of poses: ``lo``, ``hi`` (6,) in SI (m, rad; convention of the firmware)."""

    lo: np.ndarray
    hi: np.ndarray

    def to_units(self, length_unit: str = "mm", angle_unit: str = "pi") -> dict:
        """``{key: [lo, hi]}`` in the given units."""
        s = np.r_[[1 / length_scale(length_unit)] * 3, [1 / angle_scale(angle_unit)] * 3]
        return {k: [float(f"{self.lo[i] * s[i]:.12g}"), float(f"{self.hi[i] * s[i]:.12g}")] for i, k in enumerate(KEYS)}

    def words(self, fmt: QFormat) -> tuple[np.ndarray, np.ndarray]:
        """``(lo, hi)`` int64 (6,) pose words covering every pose of the box (the conversion is monotone)."""
        return pose_words(self.lo, fmt), pose_words(self.hi, fmt)


def workspace_box(platform: Platform) -> PoseBox:
    """The preset's stated workspace box, or home ± 10 % of the stroke range and ±15° (see ``WORKSPACE_BOXES``)."""
    if platform.name in WORKSPACE_BOXES:
        b = np.array(WORKSPACE_BOXES[platform.name], dtype=float)
        s = np.r_[[1e-3] * 3, [np.pi] * 3]
        return PoseBox(b[:, 0] * s, b[:, 1] * s)
    home = platform.home_pose()
    t = 0.1 * (platform.L_max - platform.L_min)
    r = np.radians(15.0)
    d = np.r_[[t] * 3, [r] * 3]
    return PoseBox(home - d, home + d)


def parse_box(specs: list[str] | None, platform: Platform, length_unit: str = "mm", angle_unit: str = "pi") -> PoseBox:
    """The box of ``KEY=LO..HI`` words (``KEY`` in px py pz a b g; lengths in ``length_unit``, angles in
    ``angle_unit``); keys not given keep the workspace box's range. Raises ``OptionError`` naming the word."""
    base = workspace_box(platform)
    lo, hi = base.lo.copy(), base.hi.copy()
    seen = set()
    for spec in specs or []:
        key, sep, text = spec.strip().partition("=")
        if not sep or key not in KEYS or ".." not in text:
            raise CertifyError(CertifyError.BOX_WORD.format(value=spec))
        if key in seen:
            raise CertifyError(CertifyError.BOX_TWICE.format(key=key, value=spec))
        seen.add(key)
        k = KEYS.index(key)
        dim, scale = ("length", length_scale(length_unit)) if k < 3 else ("angle", angle_scale(angle_unit))
        try:  # a bare number is in length_unit/angle_unit; a number with its unit is taken as written
            q = parse_quantity(text, dim, f"box {spec!r}", forms=("range",), bare=scale)
        except QuantityError as e:
            template = CertifyError.BOX_WORD if e.template == QuantityError.NUMBER else CertifyError.BOX_ORDER
            raise CertifyError(template.format(value=spec)) from None
        va, vb = q.values
        if k >= 3 and max(abs(va), abs(vb)) > np.pi:
            raise CertifyError(CertifyError.BOX_ANGLE.format(value=spec))
        lo[k], hi[k] = va, vb
    return PoseBox(lo, hi)
