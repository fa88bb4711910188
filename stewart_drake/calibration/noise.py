"""The ``--noise`` SPEC of the calibration commands: ``key=value`` words, a value with its unit.

Keys: ``length`` (σ of a leg sensor reading), ``position`` (σ of a tracked position, per axis), ``angle``
(σ of a measured orientation per axis, or of a tilt). Units: ``m mm um µm nm`` for lengths, ``rad mrad urad
µrad deg`` for angles; a bare number is SI. Keys not given keep ``Noise()``'s defaults (1 µm, 10 µm, 20 µrad).
A σ of 0 is accepted (noise-free synthetic data); the fit weighs it as ``model.NOISE_FLOOR``.
"""

from __future__ import annotations

import dataclasses

from stewart_drake.calibration.model import Noise
from stewart_drake.core.argcheck import param
from stewart_drake.errors import CalibrationError, QuantityError
from stewart_drake.spec.quantity import UNITS, parse_number

# key -> dimension of the quantity grammar
KEYS = {"length": "length", "position": "length", "angle": "angle"}


def parse_noise(words) -> Noise:
    """A ``Noise`` from ``key=value`` words (a list, or one string split at whitespace); messages name the
    parameter ``noise`` (``--noise`` on the command line)."""
    name = param("noise")
    if isinstance(words, str):
        words = words.split()
    if not isinstance(words, (list, tuple)) or not all(isinstance(w, str) for w in words):
        raise CalibrationError(CalibrationError.NOISE_TYPE.format(name=name, value=repr(words)[:80]))
    values = {}
    for w in words:
        if "=" not in w:
            raise CalibrationError(CalibrationError.NOISE_WORD.format(name=name, word=w, keys=", ".join(KEYS)))
        key, text = (s.strip() for s in w.split("=", 1))
        if key not in KEYS:
            raise CalibrationError(CalibrationError.NOISE_KEY.format(name=name, key=key, keys=", ".join(KEYS)))
        dim = KEYS[key]
        bad = CalibrationError(
            CalibrationError.NOISE_VALUE.format(
                name=name, key=key, text=text, units=" ".join(u for u in UNITS[dim] if u)
            )
        )
        try:
            v = parse_number(text, dim, f"--noise: {key}")
        except QuantityError:
            raise bad from None
        if v < 0:
            raise bad
        values[key] = v
    return dataclasses.replace(Noise(), **values)
