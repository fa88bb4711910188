"""The closed loop's DSP side in compiled C, one call per stop (``fixedpoint/c/sd_loop.c``): what
``drake.tick_loop.TickLoop`` does between two ``AdvanceTo`` calls — the plant state read where Drake keeps
it, the sensor, the law's tick, the output release, the actuators' command written where Drake reads it,
the actuators (``control.actuation``) and the logs appended to preallocated arrays — without a Python
operation per tick.

Two laws: the fixed-point law with the compiled firmware (``firmware.sil.CFixedPointLaw``: ``sd_loop.c`` is
linked into the firmware module and calls the same ``sd_host_tick``), and the float law
(``control.laws.FloatLaw``: a C translation, operation for operation, compiled with ``-ffp-contract=off``
into a library of its own). Same numbers as the numpy reference bit for bit (``tests/drake/test_tick_loop.py``
runs both loops and the all-Drake Diagram). Anything else — the Python emulation of the firmware (``engine
python``), a law or sensor of another kind, a law whose ``step`` was replaced — runs the Python loop, and so
does the float law where no C compiler is found (one note on stderr per process).
"""

from __future__ import annotations

import sys

import numpy as np

from stewart_drake.control.laws import STATUS, FloatLaw
from stewart_drake.control.loop_sensor import IdealSensor, SensorReading
from stewart_drake.errors import FirmwareError
from stewart_drake.system.c_build import C_DIR, UNAVAILABLE, load, source_keyed_library

SOURCE = C_DIR / "sd_loop.c"
HEADER = C_DIR / "sd_loop.h"
FLAGS = ("-ffp-contract=off",)  # a·b + c stays two roundings, as numpy computes it
NO_COMPILER_NOTE = "note: no C compiler: the float loop's ticks run in Python (bit-identical, slower)"
_FLOAT_LIB: list = []


def _cdef() -> str:
    """The declarations between the CDEF markers of ``sd_loop.h`` (the cffi ``cdef`` of the kernel)."""
    text = HEADER.read_text(encoding="utf-8")
    return text.split("/* CDEF BEGIN */", 1)[1].split("/* CDEF END */", 1)[0]


CDEF = _cdef()


def float_library():
    """``(ffi, lib)`` of ``sd_loop.c`` alone (the float law), or None without a compiler (noted once)."""
    if not _FLOAT_LIB:
        try:
            key = CDEF + HEADER.read_text(encoding="utf-8")  # the cache key covers the header
            _FLOAT_LIB.append(load(source_keyed_library(SOURCE, key, "sd-loop", "-O2", FLAGS), CDEF))
        except UNAVAILABLE:
            print(NO_COMPILER_NOTE, file=sys.stderr)
            _FLOAT_LIB.append(None)
    return _FLOAT_LIB[0]


def _own_step(law, cls) -> bool:
    """Whether ``law`` computes its tick with ``cls.step`` (not a subclass's or an instance's replacement)."""
    return type(law).step is cls.step and "step" not in vars(law)


def make_kernel(law, sensor) -> LoopKernel | None:
    """The C kernel for ``law`` read by ``sensor`` (``control.loop_sensor``'s ``SensorReading`` or
    ``IdealSensor``), or None
    when the Python loop must run (see the module's docstring)."""
    from stewart_drake.firmware.sil import CFixedPointLaw  # it imports this module's CDEF

    if type(sensor) not in (IdealSensor, SensorReading):
        return None
    if isinstance(sensor, SensorReading):  # rows the C code may index: the Python loop raises on others
        n = len(sensor.jitter)
        if n < 1 or np.shape(sensor.noise) != (n, 6) or np.shape(sensor.offset) not in ((6,), (1, 6)):
            return None
    if isinstance(law, CFixedPointLaw) and _own_step(law, CFixedPointLaw):
        # every module with a tick links the kernel (``module.compile_generated``, ``compile_user``)
        return LoopKernel(law.module.ffi, law.module.lib, law, sensor)
    if isinstance(law, FloatLaw) and _own_step(law, FloatLaw):
        built = float_library()
        return None if built is None else LoopKernel(*built, law, sensor)
    return None


class LoopKernel:
    """One run's ``sd_loop``: the law's constants and the sensor set once (``__init__``), the per-tick tables
    (``tables``), then Drake's memory, the schedule, the controller's state and the log arrays (``start``).
    ``stop(i)``, ``log(i)``, ``update(i)``: the C functions on this run's struct (``sd_loop.h``)."""

    def __init__(self, ffi, lib, law, sensor):
        self.ffi, self.lib, self.law, self.sensor = ffi, lib, law, sensor
        self.s = s = ffi.new("sd_loop *")
        self._keep: list = []  # the arrays the struct points into
        self.fixed = not isinstance(law, FloatLaw)
        t = law.timing
        s.fixed = int(self.fixed)
        s.latency_none = int(t.latency == "none")
        if self.fixed:
            s.fw_state = ffi.cast("void *", law.runner.state_ptr)
            s.res, s.range, s.lsb = law._res, law._range, law._lsb
        else:
            g, T = law.config.gains, t.sample_period
            # the scalars FloatLaw.step computes: g.kd / T, g.kv / T, g.ki * T (same IEEE operations)
            s.kp, s.kd_T, s.kv_T, s.ki_T = g.kp, g.kd / T, g.kv / T, g.ki * T
            s.alpha_d, s.alpha_ff = g.derivative_filter, g.feedforward_filter
            s.lim, s.res = law._limit, t.sensor_resolution
            s.length_offset = self._ptr("double *", np.asarray(law._offset, dtype=float))
        s.pos = self._ptr("int64_t *", np.asarray(sensor.positions, dtype=np.int64))
        s.ideal_sensor = int(not isinstance(sensor, SensorReading))
        if not s.ideal_sensor:
            s.vel = self._ptr("int64_t *", np.asarray(sensor.velocities, dtype=np.int64))
            s.offset = self._ptr("double *", np.asarray(sensor.offset, dtype=float).reshape(6))
            s.noise = self._ptr("double *", np.asarray(sensor.noise, dtype=float).reshape(-1, 6))
            s.jitter = self._ptr("double *", np.asarray(sensor.jitter, dtype=float).reshape(-1))
            s.n_noise, s.noise_period = len(sensor.jitter), sensor.period
        self.stop, self.log, self.update = lib.sd_loop_stop, lib.sd_loop_log, lib.sd_loop_update

    def _ptr(self, ctype: str, a: np.ndarray):
        """A C pointer of type ``ctype`` into the C-contiguous array ``a`` (kept alive with the struct)."""
        a = np.ascontiguousarray(a)
        self._keep.append(a)
        return self.ffi.cast(ctype, a.__array_interface__["data"][0])

    def _view(self, ctype: str, a: np.ndarray):
        """A C pointer into ``a`` itself (a view of Drake's memory: never a copy)."""
        if not (a.flags["C_CONTIGUOUS"] and a.dtype == np.float64):
            raise RuntimeError("a view of Drake's memory is not a contiguous float64 vector")  # a bug
        self._keep.append(a)
        return self.ffi.cast(ctype, a.__array_interface__["data"][0])

    def tables(self, poses) -> None:
        """The law's side of the tick tables for the reference ``(n_ticks, 6)`` poses, in one batch: the
        float law's set-points (``FloatLaw.setpoints`` of the rows: the IK is elementwise over poses), the
        firmware's pose words (``CFixedPointLaw.step``'s)."""
        law, s = self.law, self.s
        poses = np.ascontiguousarray(np.asarray(poses, dtype=float).reshape(-1, 6))
        if self.fixed:
            from stewart_drake.fixedpoint.generic import pose_words

            words = pose_words(poses, law.config.ik_format).astype(law.module.word_dtype)
            s.pose_words = self._ptr("void *", words)
        else:
            s.setpoint = self._ptr("double *", np.asarray(law.setpoints(poses), dtype=float).reshape(-1, 6))
        s.n_ticks = len(poses)

    def start(
        self, x, actuation, actuators, lag_force, schedule, feedforward, held, memory, status, at_tick, logs, row=0
    ) -> None:
        """Point the struct at Drake's memory — the plant state ``x`` and its actuation input ``actuation``
        (numpy views valid for the run) —, the ``actuators`` (``control.actuation.Actuation``) with their lag
        state ``lag_force`` (6, N; None without a lag), the ``schedule`` (``tick_loop.Schedule``), the
        feed-forward rows (``(n_ticks, 6)`` N, or None), the controller's state (``at_tick``: ``dsp_state.releases_at_tick``) and the ``logs`` (``held``
        (n, 12), ``status`` (n, len(STATUS)), ``state`` (n, nx), ``force`` (n, 6)), written from ``row`` on (the rows before it:
        an earlier run's, ``TickLoop.extend``)."""
        s = self.s
        indices = [self.sensor.positions] + ([self.sensor.velocities] if isinstance(self.sensor, SensorReading) else [])
        if not all(0 <= i < len(x) for i in np.concatenate(indices).tolist()):
            raise RuntimeError("sensor indices outside the plant state")  # a bug: they are the plant's joints
        s.x, s.input = self._view("double *", x), self._view("double *", actuation)
        s.max_force, s.has_lag = actuators.max_force, int(actuators.has_lag)
        if actuators.has_lag:
            s.lag_a, s.lag_b = actuators.a, actuators.b
            s.lag_force[0:6] = np.asarray(lag_force, dtype=float).tolist()
        s.times = self._ptr("double *", np.asarray(schedule.times, dtype=float))
        s.tick = self._ptr("int32_t *", np.asarray(schedule.tick, dtype=np.int32))
        s.release = self._ptr("int8_t *", np.asarray(schedule.release, dtype=np.int8))
        s.log = self._ptr("int8_t *", np.asarray(schedule.log, dtype=np.int8))
        s.step = self._ptr("int8_t *", np.asarray(schedule.step, dtype=np.int8))
        s.n_stops = len(schedule.times)
        if feedforward is not None:
            ff = np.asarray(feedforward, dtype=float)
            if len(ff) < s.n_ticks:
                raise RuntimeError(f"feed-forward table of {len(ff)} rows for {s.n_ticks} ticks")  # a bug
            s.ff = self._ptr("double *", ff)
        s.at_tick = int(at_tick)
        s.held[0:12] = np.asarray(held, dtype=float)[:12].tolist()
        s.memory[0:42] = np.asarray(memory, dtype=float).tolist()
        s.status[0 : len(STATUS)] = np.asarray(status, dtype=float).tolist()
        s.held_log = self._ptr("double *", logs["held"])
        s.status_log = self._ptr("double *", logs["status"])
        s.x_log = self._ptr("double *", logs["state"])
        s.force_log = self._ptr("double *", logs["force"])
        s.n_rows, s.nx = logs["state"].shape
        s.row = row

    def state(self) -> tuple:
        """``(held (12,), memory (42,), status, lag_force (6,))`` now (copies)."""
        s = self.s
        held, memory, status = np.array(list(s.held)), np.array(list(s.memory)), np.array(list(s.status))
        return held, memory, status[: len(STATUS)], np.array(list(s.lag_force))

    def raise_error(self, code: int) -> None:
        """The error of a failed ``stop``/``update`` (``code`` < 0)."""
        if code == -1:
            L = list(self.s.error_lengths)
            raise FirmwareError(FirmwareError.SENSOR_COUNTS.format(value=L))
        raise RuntimeError(f"sd_loop failed with {code}")  # a tick beyond the tables or the logs: a bug
