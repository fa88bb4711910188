"""Software in the loop: the fixed-point controller LeafSystem with its tick computed by compiled C —
the module generated for the platform and the controller's configuration, or a user's C file that
implements the ABI (``sd_firmware.h``). Same ports, timing, zero-order hold and logs as the Python
engine (``control.FixedPointController``): only ``compute`` changes, and its numbers are the same bit
for bit (the tests compare whole closed-loop logs)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..control import _FixedLaw, _make_class
from ..fixedpoint.generic import pose_words
from .generate import generate
from .module import compile_generated, compile_user

_STATE_FIELDS = (("integ", np.int32), ("prev", np.int32), ("dfilt", np.int16), ("setpoint", None), ("vfilt", np.int16), ("saturated", np.int16))


class _CFixedLaw(_FixedLaw):
    """``_FixedLaw`` with ``compute`` done by ``sd_tick`` of a compiled firmware module."""

    firmware: Path | None = None  # set on the per-file subclass

    def _setup(self):
        super()._setup()
        self.generated = generate(self.platform, self.config)
        m = compile_user(self.firmware, self.generated) if self.firmware is not None else compile_generated(self.generated)
        if not m.has_tick:
            raise ValueError(f"firmware {str(self.firmware)!r} does not define sd_init and sd_tick; the controller in the loop needs both")
        self.module = m
        ffi = m.ffi
        self._state_buf = bytearray(ffi.sizeof("sd_state"))
        self._state_ptr = ffi.from_buffer("sd_state *", self._state_buf)
        m.lib.sd_init(self._state_ptr)
        self._views = {}
        for name, dt in _STATE_FIELDS:
            dt = dt or m.word_dtype
            off = ffi.offsetof("sd_state", name)
            self._views[name] = np.frombuffer(self._state_buf, dtype=dt, count=6, offset=off)
        self._pose = np.zeros(6, dtype=m.word_dtype)
        self._meas = np.zeros(6, dtype=np.int32)
        self._ff = np.zeros(6, dtype=np.int16)
        self._cmd = np.zeros(6, dtype=np.int16)
        word = m.word
        self._p_pose = ffi.from_buffer(f"{word}[]", self._pose)
        self._p_meas = ffi.from_buffer("int32_t[]", self._meas)
        self._p_ff = ffi.from_buffer("int16_t[]", self._ff)
        self._p_cmd = ffi.from_buffer("int16_t[]", self._cmd)
        self._words: dict[bytes, np.ndarray] = {}

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
        self._pose[:] = w
        m = self.quantise(L)
        if np.any(np.abs(m) > 2**31 - 1):
            raise ValueError(f"measured leg lengths {np.asarray(L).tolist()} m do not fit the firmware's 32-bit sensor counts")
        self._meas[:] = m
        st = np.asarray(pid)
        v = self._views
        v["integ"][:] = st[0:6]
        v["prev"][:] = st[6:12]
        v["dfilt"][:] = st[12:18]
        v["setpoint"][:] = st[18:24]
        v["vfilt"][:] = st[24:30]
        if ff is not None:
            self._ff[:] = self.feedforward_words(ff)
        self.module.lib.sd_tick(self._state_ptr, self._p_pose, self._p_meas, self._p_ff if ff is not None else self.module.ffi.NULL, self._p_cmd)
        command = self._cmd / 32768.0 * self.timing.command_range
        sp = v["setpoint"].astype(np.int64)
        state = np.concatenate([v["integ"], v["prev"], v["dfilt"], v["setpoint"], v["vfilt"]]).astype(float)
        return command, sp * self.config.ik_format.length_lsb, state, v["saturated"].astype(float)


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
