"""Software in the loop: the fixed-point controller LeafSystem with its tick computed by compiled C —
the module generated for the platform and the controller's configuration, or a user's C file that
implements the ABI (``sd_firmware.h``). Same ports, timing, zero-order hold and logs as the Python
engine (``control.FixedPointController``): only ``compute`` changes, and its numbers are the same bit
for bit (the tests compare whole closed-loop logs)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from stewart_drake.control.controller import _FixedLaw, _make_class
from stewart_drake.fixedpoint.generic import pose_words
from stewart_drake.firmware.generate import generate
from stewart_drake.firmware.module import TickRunner, compile_generated, compile_user

class _CFixedLaw(_FixedLaw):
    """``_FixedLaw`` with ``compute`` done by ``sd_tick`` of a compiled firmware module."""

    firmware: Path | None = None  # set on the per-file subclass

    def _setup(self):
        super()._setup()
        self.generated = generate(self.platform, self.config)
        m = compile_user(self.firmware, self.generated) if self.firmware is not None else compile_generated(self.generated)
        self.module = m
        self.runner = TickRunner(m)
        self._words: dict[bytes, np.ndarray] = {}
        # the host's side of one tick (quantising, feed-forward words, state vector) runs in C too
        # (sd_host.c: the same IEEE operations as _FixedLaw's numpy code), one call per tick
        ffi = m.ffi
        self._L, self._ff, self._state, self._out = np.zeros(6), np.zeros(6), np.zeros(30), np.zeros(18)
        self._p_pose = ffi.from_buffer(f"{m.word}[]", self.runner.pose)
        self._p_L, self._p_ff, self._p_state, self._p_out = (ffi.from_buffer("double[]", a) for a in (self._L, self._ff, self._state, self._out))
        self._null = ffi.NULL
        self._host_tick = m.lib.sd_host_tick
        self._res, self._range = float(self.timing.sensor_resolution), float(self.timing.command_range)
        self._lsb = float(self.config.ik_format.length_lsb)

    def prime(self, poses) -> None:
        """Convert ``(n, 6)`` reference poses to pose words in one batch and remember them (speed only)."""
        poses = np.ascontiguousarray(np.asarray(poses, dtype=float).reshape(-1, 6))
        for q, w in zip(poses, pose_words(poses, self.config.ik_format)):
            self._words[q.tobytes()] = w

    def compute(self, ref, L, pid, ff=None):
        """One tick by the compiled ``sd_tick`` (see ``_FixedLaw.compute``): the PID state words go into
        the C ``sd_state`` and come back out, so the LeafSystem's discrete state and logs are unchanged."""
        ref = np.ascontiguousarray(ref, dtype=float)
        w = self._words.get(ref.tobytes())
        if w is None:
            self.cache_misses += 1
            w = pose_words(ref, self.config.ik_format)
        r = self.runner
        r.pose[:] = w
        self._L[:] = L
        self._state[:] = pid
        if ff is not None:
            self._ff[:] = ff
        k = self._host_tick(r._ptr, self._p_pose, self._p_L, self._res, self._p_ff if ff is not None else self._null, self._range,
                            self._lsb, self._p_state, self._p_out)
        if k < 0:
            raise ValueError(f"measured leg lengths {np.asarray(L).tolist()} m do not fit the firmware's 32-bit sensor counts")
        o = self._out
        return o[:6].copy(), o[6:12].copy(), self._state.copy(), o[12:].copy()


_CLASSES: dict[str, type] = {}


def CFixedPointController(platform, config=None, firmware: str | Path | None = None):
    """The fixed-point controller LeafSystem running compiled C: the generated module for ``platform`` and
    ``config`` or, with ``firmware``, a user's C file implementing the ABI (compiled against the header
    generated for the same platform and format)."""
    key = "" if firmware is None else str(Path(firmware).resolve())
    if key not in _CLASSES:
        law = type("_CFixedLawFile", (_CFixedLaw,), {"firmware": None if firmware is None else Path(key)})
        _CLASSES[key] = _make_class("CFixedPointController", law)
    return _CLASSES[key](platform, config)
