"""``certify``: the firmware's certificate over a pose box — every word's proven range and headroom,
whether saturation is impossible, possible or certain, a witness pose that saturates the bit-exact
emulation, and a proven bound on |L_firmware - L_float| per leg."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from stewart_drake.core.geometry import Platform
from stewart_drake.core.rotations import angle_scale, length_scale
from stewart_drake.errors import CertifyError
from stewart_drake.firmware.certify.box import KEYS, PoseBox
from stewart_drake.firmware.certify.recipe import BENIGN, Model, word_names
from stewart_drake.firmware.certify.search import MAX_CELLS, run_search
from stewart_drake.firmware.certify.tp17_recipe import tp17_word_names
from stewart_drake.fixedpoint.generic import QFormat

# |L_double - L_exact|: the double IK is ~30 correctly rounded operations on values below 10 m, so its
# error is below 30 * 10 m * 2^-53 < 4e-14 m; this margin is added to every bound
FLOAT_IK_MARGIN_M = 1e-12
MAX_CELLS_LIMIT = 20_000_000


@dataclass
class WordRange:
    """One intermediate word: its proven hull (``min``/``max`` after saturation, as the firmware holds
    it; ``pre_min``/``pre_max`` before), headroom in bits (log2 of the word's range over the largest
    magnitude before saturation; negative: it does not fit), and ``saturation``: ``impossible``,
    ``possible`` (not excluded) or ``certain`` (shown to happen: a cell where every pose clamps, or the
    witness). ``benign``: the trig table's clamp (cos 0 = 1.0), within its certified error."""

    name: str
    min: int
    max: int
    pre_min: int
    pre_max: int
    headroom_bits: float
    saturation: str
    benign: bool = False

    def to_dict(self) -> dict:
        return {
            "name": self.name,
            "min": self.min,
            "max": self.max,
            "pre_min": self.pre_min,
            "pre_max": self.pre_max,
            "headroom_bits": self.headroom_bits,
            "saturation": self.saturation,
            "benign": self.benign,
        }


@dataclass
class Certificate:
    """The certificate of one format over one box (see the module docstring); ``to_dict`` gives the JSON."""

    platform: str
    fmt: QFormat
    convention: str
    box: PoseBox
    length_unit: str
    angle_unit: str
    words: list[WordRange]
    error_bound_lsb: list  # per leg, None where saturation is possible
    saturation_possible: bool
    witness_words: np.ndarray | None
    witness_saturates: list = field(default_factory=list)
    witness_emulation: dict = field(default_factory=dict)
    unresolved: list = field(default_factory=list)  # cells (pose words) left undecided
    unresolved_count: int = 0
    cells: int = 0
    exhausted: bool = False
    implementation: str = "generated"

    @property
    def error_bound_mm(self) -> list:
        """Per leg: the proven bound on |L_firmware - L_float| in mm (None: saturation possible)."""
        return [
            None if e is None else float(np.nextafter((e * self.fmt.length_lsb + FLOAT_IK_MARGIN_M) * 1e3, np.inf))
            for e in self.error_bound_lsb
        ]

    def pose_in_units(self, words) -> list:
        w = np.asarray(words, dtype=float)
        ls, an = length_scale(self.length_unit), angle_scale(self.angle_unit)
        f = self.fmt.frac_bits
        return [float(v) for v in np.r_[w[:3] * self.fmt.length_lsb / ls, w[3:] * (np.pi / (1 << f)) / an]]

    @property
    def witness(self) -> dict | None:
        if self.witness_words is None:
            return None
        return {
            "pose": dict(zip(KEYS, self.pose_in_units(self.witness_words))),
            "pose_words": [int(v) for v in self.witness_words],
            "saturates": self.witness_saturates,
            "emulation_saturations": self.witness_emulation,
        }

    def to_dict(self) -> dict:
        return {
            "platform": self.platform,
            "implementation": self.implementation,
            "format": {
                "word_bits": self.fmt.word_bits,
                "length_lsb_m": self.fmt.length_lsb,
                "trig": self.fmt.trig,
                "convention": self.convention,
            },
            "units": {"length": self.length_unit, "angle": self.angle_unit},
            "box": self.box.to_units(self.length_unit, self.angle_unit),
            "saturation_possible": self.saturation_possible,
            "witness": self.witness,
            "unresolved_cells": [
                {k: [a, b] for k, a, b in zip(KEYS, self.pose_in_units(lo), self.pose_in_units(hi))}
                for lo, hi in self.unresolved
            ],
            "unresolved_count": self.unresolved_count,
            "error_bound_mm": self.error_bound_mm,
            "error_bound_lsb": self.error_bound_lsb,
            "float_ik_margin_mm": FLOAT_IK_MARGIN_M * 1e3,
            "words": [w.to_dict() for w in self.words],
            "cells_evaluated": self.cells,
            "budget_exhausted": self.exhausted,
        }


def _headroom(pre_lo: int, pre_hi: int, limit: int) -> float:
    mag = max(abs(int(pre_lo)), abs(int(pre_hi)), 1)
    return round(float(np.log2(limit / mag)), 2)


def certify(
    platform: Platform,
    fmt: QFormat,
    box: PoseBox,
    convention: str = "utn",
    max_cells: int = MAX_CELLS,
    length_unit: str = "mm",
    angle_unit: str = "pi",
    implementation: str = "generated",
) -> Certificate:
    """Certify the generated ``sd_ik`` of ``platform`` in format ``fmt`` over every pose of ``box``
    (within ``max_cells`` cell evaluations; memory bounded). ``implementation="tp17"``: the seed's DSP
    firmware instead (its own format: whole-mm positions, FRAC16 angles; ``fmt`` must be 16-bit, 1 mm,
    tfr16). Raises ``CertifyError`` if a box end does not fit the pose words."""
    if not (isinstance(max_cells, (int, np.integer)) and 1 <= max_cells <= MAX_CELLS_LIMIT):
        raise CertifyError(CertifyError.CELLS.format(lo=1, hi=MAX_CELLS_LIMIT, value=max_cells))
    f = fmt.frac_bits
    for k in range(3):
        for v in (box.lo[k], box.hi[k]):
            if abs(np.round(v / fmt.length_lsb)) > (1 << f) - 1:
                raise CertifyError(
                    CertifyError.BOX_WORDS.format(
                        key=KEYS[k],
                        value=f"{v / length_scale(length_unit):g} {length_unit}",
                        bits=fmt.word_bits,
                        range_mm=fmt.range_m * 1e3,
                    )
                )
    model = Model.build(platform, fmt, convention)
    lo, hi = box.words(fmt)
    if implementation == "tp17":  # tp17.C truncates positions to whole mm and angles to FRAC16 words
        lo = np.r_[np.trunc(box.lo[:3] * 1e3), np.trunc(box.lo[3:] / np.pi * 32768.0)].astype(np.int64)
        hi = np.r_[np.trunc(box.hi[:3] * 1e3), np.trunc(box.hi[3:] / np.pi * 32768.0)].astype(np.int64)
        hi[3:] = np.minimum(hi[3:], 32767)
    s = run_search(model, lo, hi, max_cells=max_cells, implementation=implementation)
    names = tp17_word_names() if implementation == "tp17" else word_names()
    limit_of = {n: float(1 << (2 * fmt.word_bits - 1)) if n.startswith(("sq", "L32")) else float(1 << f) for n in names}
    words = []
    for k, n in enumerate(names):
        wide = n.startswith("sq") or n.startswith("L32")
        wlo = -(1 << (2 * fmt.word_bits - 1)) if wide else -(1 << f)
        whi = -wlo - 1
        status = "impossible"
        if s.possible[k]:
            status = "possible"
        if s.certain[k]:
            status = "certain"
        words.append(
            WordRange(
                n,
                int(np.clip(s.pre_lo[k], wlo, whi)),
                int(np.clip(s.pre_hi[k], wlo, whi)),
                int(s.pre_lo[k]),
                int(s.pre_hi[k]),
                _headroom(s.pre_lo[k], s.pre_hi[k], limit_of[n]),
                status,
                n in BENIGN,
            )
        )
    sat = any(w.saturation != "impossible" and not w.benign for w in words)
    bound = [None if not np.isfinite(e) else float(e) for e in s.err_bound_lsb]
    return Certificate(
        platform.name,
        fmt,
        convention,
        box,
        length_unit,
        angle_unit,
        words,
        bound,
        sat,
        s.witness,
        s.witness_words,
        s.witness_ops,
        [(c[0], c[1]) for c in s.unresolved],
        s.unresolved_count,
        s.cells,
        s.exhausted,
        implementation,
    )
