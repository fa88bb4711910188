"""Software in the loop: the fixed-point law with its tick computed by compiled C — the module generated
for the platform and the controller's configuration, or a user's C file that implements the ABI
(``sd_firmware.h``). Same interface as the Python law (``control.FixedPointLaw``): only ``step`` changes,
and its numbers are the same bit for bit (the tests compare whole closed-loop logs)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from stewart_drake.control.gains import ControllerConfig
from stewart_drake.control.laws import FixedPointLaw
from stewart_drake.core.geometry import Platform
from stewart_drake.errors import FirmwareError
from stewart_drake.firmware.generate import generate
from stewart_drake.firmware.module import TickRunner, compile_generated, compile_user
from stewart_drake.fixedpoint.generic import pose_words


class CFixedPointLaw(FixedPointLaw):
    """``FixedPointLaw`` with ``step`` done by ``sd_tick`` of a compiled firmware module: the generated
    module for ``platform`` and ``config`` or, with ``firmware``, a user's C file implementing the ABI
    (compiled against the header generated for the same platform and format)."""

    def __init__(self, platform: Platform, config: ControllerConfig | None = None, firmware: str | Path | None = None):
        super().__init__(platform, config)
        self.firmware = None if firmware is None else Path(firmware).resolve()
        self.generated = generate(self.platform, self.config)
        m = (
            compile_user(Path(firmware), self.generated)  # as given: its messages name the file as the user wrote it
            if self.firmware is not None
            else compile_generated(self.generated)
        )
        self.module = m
        self.runner = TickRunner(m)
        self._words: dict[bytes, np.ndarray] = {}
        # the host's side of one tick (quantising, feed-forward words, state vector) runs in C too
        # (sd_host.c: the same IEEE operations as FixedPointLaw's numpy code), one call per tick
        ffi = m.ffi
        self._L, self._ff, self._state, self._out = np.zeros(6), np.zeros(6), np.zeros(30), np.zeros(18)
        self._p_pose = ffi.from_buffer(f"{m.word}[]", self.runner.pose)
        self._p_L, self._p_ff, self._p_state, self._p_out = (
            ffi.from_buffer("double[]", a) for a in (self._L, self._ff, self._state, self._out)
        )
        self._null = ffi.NULL
        self._host_tick = m.lib.sd_host_tick
        self._res, self._range = float(self.timing.sensor_resolution), float(self.timing.command_range)
        self._lsb = float(self.config.ik_format.length_lsb)

    def prime(self, poses) -> None:
        """Convert ``(n, 6)`` reference poses to pose words in one batch and remember them (speed only)."""
        poses = np.ascontiguousarray(np.asarray(poses, dtype=float).reshape(-1, 6))
        for q, w in zip(poses, pose_words(poses, self.config.ik_format)):
            self._words[q.tobytes()] = w

    def step(self, state, reference, measured, feedforward=None):
        """One tick by the compiled ``sd_tick`` (see ``FixedPointLaw.step``): the PID state words go into
        the C ``sd_state`` and come back out, so the state and the logs are unchanged."""
        ref = np.ascontiguousarray(reference, dtype=float)
        w = self._words.get(ref.tobytes())
        if w is None:
            self.cache_misses += 1
            w = pose_words(ref, self.config.ik_format)
        r = self.runner
        r.pose[:] = w
        self._L[:] = measured
        self._state[:] = state
        if feedforward is not None:
            self._ff[:] = feedforward
        k = self._host_tick(
            r.state_ptr,
            self._p_pose,
            self._p_L,
            self._res,
            self._p_ff if feedforward is not None else self._null,
            self._range,
            self._lsb,
            self._p_state,
            self._p_out,
        )
        if k < 0:
            raise FirmwareError(FirmwareError.SENSOR_COUNTS.format(value=np.asarray(measured).tolist()))
        o = self._out
        return o[:6].copy(), o[6:12].copy(), self._state.copy(), o[12:].copy()
