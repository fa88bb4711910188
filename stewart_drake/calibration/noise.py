"""The ``--noise`` SPEC of the calibration commands: ``key=value`` words, a value with its unit.

Keys: ``length`` (σ of a leg sensor reading), ``position`` (σ of a tracked position, per axis), ``angle``
(σ of a measured orientation per axis, or of a tilt). Units: ``m mm um µm nm`` for lengths, ``rad mrad urad
µrad deg`` for angles; a bare number is SI. Keys not given keep ``Noise()``'s defaults (1 µm, 10 µm, 20 µrad).
A σ of 0 is accepted (noise-free synthetic data); the fit weighs it as ``model.NOISE_FLOOR``.
"""

from __future__ import annotations

import dataclasses
import re
from decimal import Decimal, InvalidOperation

from stewart_drake.calibration.model import Noise
from stewart_drake.errors import CalibrationError

_LENGTH = {"": 0, "m": 0, "mm": -3, "um": -6, "µm": -6, "nm": -9}
_ANGLE = {"": 1.0, "rad": 1.0, "mrad": 1e-3, "urad": 1e-6, "µrad": 1e-6, "deg": 0.017453292519943295}
KEYS = {"length": _LENGTH, "position": _LENGTH, "angle": _ANGLE}
_NUM = re.compile(r"\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*([a-zµ]*)\s*")


def parse_noise(words) -> Noise:
    """A ``Noise`` from ``key=value`` words (a list, or one string split at whitespace)."""
    if isinstance(words, str):
        words = words.split()
    values = {}
    for w in words:
        if "=" not in w:
            raise CalibrationError(CalibrationError.NOISE_WORD.format(word=w, keys=", ".join(KEYS)))
        key, text = (s.strip() for s in w.split("=", 1))
        if key not in KEYS:
            raise CalibrationError(CalibrationError.NOISE_KEY.format(key=key, keys=", ".join(KEYS)))
        units = KEYS[key]
        m = _NUM.fullmatch(text)
        try:
            number = Decimal(m.group(1)) if m else None
        except InvalidOperation:
            number = None
        if number is None or m.group(2) not in units or number < 0 or not number.is_finite():
            raise CalibrationError(
                CalibrationError.NOISE_VALUE.format(key=key, text=text, units=" ".join(u for u in units if u))
            )
        scale = units[m.group(2)]
        values[key] = float(number.scaleb(scale)) if units is _LENGTH else float(number) * scale
    return dataclasses.replace(Noise(), **values)
