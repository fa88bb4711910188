"""Classical washout as a compiled streaming step: ``classical_kernel.c`` through ``system.c_build`` (cffi), the
law of ``classical.classical`` one sample at a time from a carried state, as a real-time loop runs it (the numpy
law filters a whole recorded drive at once).

The same filters (``vestibular.bilinear`` at the drive's step, each starting at rest at the first sample's input,
``scipy.signal.lfilter_zi``), the same transposed direct form II recursion and order of sums as ``lfilter`` and
``classical``, so the poses agree with ``classical`` to the last bits of a sine or arcsine.

``coef`` (68 doubles): per filter (8: translational x, y, z; tilt low-pass x, y; rotational roll, pitch, yaw)
``b0..b3, a1..a3`` (zero-padded to third order), then ``scale_xy, scale_z, scale_rot, g, tilt_max, tilt_step``
and the home pose (6). ``state`` (27 doubles): three filter states per filter, the two rate-limited tilts and a
started flag.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from scipy import signal

from stewart_drake.control.cueing.classical import ClassicalParams, translational_tf
from stewart_drake.control.cueing.drive import GRAVITY, Drive
from stewart_drake.control.cueing.vestibular import bilinear
from stewart_drake.system.c_build import load, source_keyed_library

SOURCE = Path(__file__).with_name("classical_kernel.c")
CDEF = "void sd_washout(int64_t n, const double *coef, double *state, const double *u, double *pose);"
STATE_SIZE = 8 * 3 + 3


def filters(params: ClassicalParams, dt: float) -> list[tuple[np.ndarray, np.ndarray]]:
    """The eight continuous filters ``(num, den)`` of ``classical`` in the kernel's order."""
    p = params
    trans = [translational_tf(w, p.hp_zeta, p.hp_break) for w in (p.hp_xy, p.hp_xy, p.hp_z)]
    tilt = (np.array([p.tilt_lp**2]), np.array([1.0, 2 * p.tilt_zeta * p.tilt_lp, p.tilt_lp**2]))
    rot = (np.array([1.0, 0.0]), np.array([1.0, 2 * p.hp_rot_zeta * p.hp_rot, p.hp_rot**2]))
    return [*trans, tilt, tilt, rot, rot, rot]


class WashoutKernel:
    """The compiled classical washout for one drive step ``dt`` (s) about ``home`` ``(6,)``: ``run(u)`` takes
    ``(n, 6)`` samples ``(f (m/s²), ω (rad/s))`` in the head frame and returns ``(n, 6)`` poses (m, rad, ``utn``),
    carrying its state from call to call (the first call starts every filter at rest at its first input)."""

    def __init__(self, params: ClassicalParams, dt: float, home):
        self.ffi, self.lib = load(source_keyed_library(SOURCE, CDEF, "sd-washout-kernel"), CDEF)
        self.params = params
        self.discrete = [bilinear(num, den, dt) for num, den in filters(params, dt)]
        coef = []
        for b, a in self.discrete:
            coef += [*np.pad(b, (0, 4 - len(b))), *np.pad(a[1:], (0, 3 - len(a[1:])))]
        p = params
        coef += [p.scale_xy, p.scale_z, p.scale_rot, GRAVITY, p.tilt_max, p.tilt_rate * dt, *np.asarray(home, float)]
        self.coef = np.array(coef, dtype=float)
        self.state: np.ndarray | None = None

    def _start(self, u0: np.ndarray) -> np.ndarray:
        """The filters' states at rest at the first sample's inputs (``classical``'s ``zi * u[0]``)."""
        p = self.params
        inputs = [
            p.scale_xy * u0[0],
            p.scale_xy * u0[1],
            p.scale_z * u0[2] - p.scale_z * GRAVITY,
            p.scale_xy * u0[0],
            p.scale_xy * u0[1],
            *(p.scale_rot * u0[3:]),
        ]
        state = np.zeros(STATE_SIZE)
        for k, ((b, a), x) in enumerate(zip(self.discrete, inputs, strict=True)):
            zi = signal.lfilter_zi(b, a) * x
            state[3 * k : 3 * k + len(zi)] = zi
        return state

    def run(self, u) -> np.ndarray:
        """``(n, 6)`` poses for the samples ``u`` ``(n, 6)``, continuing from the previous call."""
        u = np.ascontiguousarray(u, dtype=float).reshape(-1, 6)
        if self.state is None:
            self.state = self._start(u[0])
        out = np.empty_like(u)
        fb = self.ffi.from_buffer
        self.lib.sd_washout(
            len(u), fb("double[]", self.coef), fb("double[]", self.state), fb("double[]", u), fb("double[]", out)
        )
        return out


def classical_compiled(drive: Drive, params: ClassicalParams, home) -> np.ndarray:
    """``(N, 6)``: ``classical(drive, params, home)`` by the compiled step, sample after sample."""
    return WashoutKernel(params, drive.dt, home).run(np.hstack([drive.specific_force, drive.angular_velocity]))
