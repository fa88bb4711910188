"""``loop_response``: the closed leg loop in the frequency domain about a held pose (``control.frequency``), with
its margins against stated minimums, and optionally checked against the nonlinear Drake loop
(``drake.loop_response``).

Imports pydrake (through ``api.simulation``): the run is planned by ``plan_run``, so the gains, timing and
actuators are those a run of the machine at that pose uses.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from stewart_drake.api.result import Result
from stewart_drake.api.simulation import plan_run, run_machine
from stewart_drake.control.feedforward import feedforward_lead, initial_leg_forces
from stewart_drake.control.frequency import (
    MIN_GAIN_MARGIN_DB,
    MIN_PHASE_MARGIN_DEG,
    LoopModel,
    bandwidth,
    default_frequencies,
    effective_gains,
    margins,
)
from stewart_drake.control.hydraulic import small_signal as hydraulic_signal
from stewart_drake.control.screw import small_signal
from stewart_drake.core.argcheck import check_finite_samples, check_shape
from stewart_drake.core.geometry import Platform
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.core.trajectory import constant_trajectory
from stewart_drake.drake.loop_response import measure_duration, measure_point
from stewart_drake.errors import ResponseError
from stewart_drake.spec import Machine

if TYPE_CHECKING:  # annotations only: matplotlib is loaded when a figure is asked for
    from matplotlib.figure import Figure

# at most this many frequencies in one response (the 6×6 responses are ~1 kB per frequency)
MAX_FREQUENCIES = 100_000
# at most this many measured frequencies, and this many simulated seconds in all (each is a closed-loop run)
MAX_MEASURED = 50
MAX_MEASURE_SECONDS = 600.0


@dataclass(repr=False)
class LoopResponse(Result):
    """The closed leg loop about ``pose`` (``loop_response``).

    Attributes:
        pose: (6,) the held pose (m, rad).
        law: ``float`` or ``fixed`` (the fixed law's model uses its Q15 gains' values).
        frequencies: (n,) Hz.
        setpoint: (n, 6, 6) complex, leg length i per unit set-point of leg j (m/m), feed-forward included.
        cartesian: (n, 6, 6) complex, pose per unit pose reference (J⁻¹·setpoint·J).
        loop: (n, 6) complex, each leg's return ratio with the other legs closed.
        sensitivity_peak: the largest singular value of S = (I + c_y·G)⁻¹ over the frequencies.
        margins: per leg (6 dicts) ``gain_margin_db``, ``phase_crossover_hz``, ``phase_margin_deg``,
            ``gain_crossover_hz``.
        bandwidth_hz: the lowest −3 dB frequency of the legs' own set-point responses (None: above the grid).
        spectral_radius: the closed loop's largest pole magnitude (< 1: stable).
        failures: what is below the minimums (``MIN_GAIN_MARGIN_DB``, ``MIN_PHASE_MARGIN_DEG``, a stable loop).
        measured: the points measured on the nonlinear Drake loop (``drake.loop_response.MeasuredPoint``).
    """

    pose: np.ndarray
    law: str
    frequencies: np.ndarray
    setpoint: np.ndarray
    cartesian: np.ndarray
    loop: np.ndarray
    sensitivity_peak: float
    margins: list
    bandwidth_hz: float | None
    spectral_radius: float
    failures: list
    measured: list = field(default_factory=list)

    @property
    def ok(self) -> bool:
        """The loop is stable with at least the minimum margins (and every measured point agrees)."""
        return not self.failures

    def _fields(self) -> dict:
        def cx(a):
            return {"magnitude": np.abs(a), "phase_deg": np.degrees(np.angle(a))}

        return {
            "pose": self.pose,
            "law": self.law,
            "frequencies_hz": self.frequencies,
            "setpoint": cx(self.setpoint),
            "cartesian": cx(self.cartesian),
            "loop": cx(self.loop),
            "sensitivity_peak": self.sensitivity_peak,
            "margins": self.margins,
            "min_gain_margin_db": MIN_GAIN_MARGIN_DB,
            "min_phase_margin_deg": MIN_PHASE_MARGIN_DEG,
            "bandwidth_hz": self.bandwidth_hz,
            "spectral_radius": self.spectral_radius,
            "measured": [
                {
                    "frequency_hz": p.freq,
                    "leg": p.leg + 1,
                    "amplitude_m": p.amplitude,
                    "measured": cx(p.response[p.leg]),
                    "linear": cx(p.linear[p.leg]),
                    "difference": float(abs(p.response[p.leg] - p.linear[p.leg])),
                    "tolerance": float(p.tolerance[p.leg]),
                    "agrees": p.agrees,
                }
                for p in self.measured
            ],
            "failures": self.failures,
        }

    def plot(self) -> Figure:
        """Bode plot of each leg's set-point response (magnitude and phase) with any measured points, and the
        Nyquist plot of each leg's return ratio.

        Returns:
            A matplotlib ``Figure``.
        """
        # deferred: pyplot is loaded only when a figure is drawn
        import matplotlib.pyplot as plt

        f = self.frequencies
        fig = plt.figure(figsize=(11, 6))
        ax_m, ax_p = fig.add_subplot(2, 2, 1), fig.add_subplot(2, 2, 3)
        ax_n = fig.add_subplot(1, 2, 2)
        for i in range(6):
            h = self.setpoint[:, i, i]
            ax_m.semilogx(f, 20 * np.log10(np.abs(h)), label=f"leg {i + 1}")
            ax_p.semilogx(f, np.degrees(np.unwrap(np.angle(h))))
            L = self.loop[:, i]
            ax_n.plot(L.real, L.imag, lw=1)
        for p in self.measured:
            h = p.response[p.leg]
            ax_m.semilogx([p.freq], [20 * np.log10(abs(h))], "k.", ms=8)
            ax_p.semilogx([p.freq], [np.degrees(np.angle(h))], "k.", ms=8)
        ax_m.set_ylabel("|L / set-point| [dB]")
        ax_m.legend(fontsize=7, ncol=3)
        ax_p.set_ylabel("phase [deg]")
        ax_p.set_xlabel("frequency [Hz]")
        ax_n.plot([-1], [0], "r+", ms=12)
        ax_n.set_xlim(-3, 1)
        ax_n.set_ylim(-2, 2)
        ax_n.set_aspect("equal")
        ax_n.set_xlabel("Re L")
        ax_n.set_ylabel("Im L")
        m = min(self.margins, key=lambda d: d["gain_margin_db"])
        ax_n.set_title(f"Nyquist, per leg: GM {m['gain_margin_db']:.1f} dB, PM {m['phase_margin_deg']:.0f}°")
        fig.suptitle(f"{self.law} law, sensitivity peak {self.sensitivity_peak:.2f}")
        fig.tight_layout()
        return fig


def loop_response(
    machine: Machine | Platform | str | Path,
    pose=None,
    frequencies=None,
    *,
    measure=None,
    leg: int = 1,
    amplitude: float = 1e-3,
    **overrides,
) -> LoopResponse:
    """The closed leg loop of ``machine`` linearised about ``pose``: set-point and Cartesian frequency responses,
    per-leg gain and phase margins, bandwidth and sensitivity peak.

    Args:
        machine: a ``Machine``, a ``Platform`` or a machine file (its controller, actuators and sensors).
        pose: (6,) the held pose (m, rad; default the platform's home).
        frequencies: (n,) Hz, each in (0, 1/(2T)) (default 300 log-spaced from 0.1 Hz to the Nyquist frequency).
        measure: frequencies (Hz) at which to measure the response on the nonlinear Drake loop (a set-point sine
            on ``leg`` through the machine's law and plant; None: none).
        leg: the leg (1..6) driven by ``measure``.
        amplitude: the sine's amplitude at most (m; smaller where the command would exceed a tenth of its range).
        **overrides: any spec path (``**{"controller.law": "float"}``).

    Returns:
        The responses, margins and verdict (``ok``).

    Raises:
        StewartError: bad input (``ResponseError`` naming the argument), the pose outside the stroke, a timing
            the platform cannot hold (``plan_run``'s checks).
    """
    m = run_machine(machine, {}, overrides)
    platform = m.loaded_platform
    pose = platform.home_pose() if pose is None else check_shape(pose, "pose", (6,), ResponseError)
    check_finite_samples(pose, "pose")
    if not (isinstance(leg, (int, np.integer)) and 1 <= leg <= 6):
        raise ResponseError(ResponseError.LEG.format(value=leg))
    if not (np.isfinite(amplitude) and amplitude > 0):
        raise ResponseError(ResponseError.AMPLITUDE.format(value=amplitude))
    plan = plan_run(m, constant_trajectory("held pose", pose), duration=1.0, command="response")
    sc = plan.scenario
    T = plan.timing.sample_period
    f = default_frequencies(T) if frequencies is None else _frequencies(frequencies, T, "frequencies")
    lag = sc.actuators.time_constant
    steps = T / sc.plant_time_step
    if lag > 0 and abs(steps - round(steps)) > 1e-9 * steps:  # the lag steps at the plant steps between ticks
        raise ResponseError(ResponseError.PLANT_STEPS.format(step=sc.plant_time_step, period=T))
    lead = feedforward_lead(sc.config, lag) if sc.feedforward else None
    # the screws and cylinders about the forces that hold the plate at the pose, as the run starts
    screw = cylinders = None
    hold = initial_leg_forces(sc.platform, sc.trajectory)
    if sc.actuators.screw is not None:
        screw = small_signal(sc.actuators.screw, hold, sc.plant_time_step)
    if sc.actuators.hydraulic is not None:
        L = leg_lengths(sc.platform, pose)
        cylinders = hydraulic_signal(sc.actuators.hydraulic, hold, L, sc.platform.L_min, sc.plant_time_step)
    model = LoopModel.build(
        sc.platform, pose, effective_gains(sc.controller, sc.config), T, plan.timing.output_delay, lag,
        sc.plant_time_step, lead, screw, cylinders,
    )  # fmt: skip
    Tsp = model.setpoint_response(f)
    L, S = model.loops(f)
    per_leg = [margins(f, L[:, i]) for i in range(6)]
    bws = [bandwidth(f, Tsp[:, i, i]) for i in range(6)]
    bw = None if any(b is None for b in bws) else min(bws)
    rho = model.spectral_radius
    failures = []
    if not rho < 1:
        failures.append(ResponseError.UNSTABLE.format(rho=rho))
    gm = min(d["gain_margin_db"] for d in per_leg)
    pm = min(d["phase_margin_deg"] for d in per_leg)
    if gm < MIN_GAIN_MARGIN_DB:
        failures.append(ResponseError.GAIN_MARGIN.format(value=gm, minimum=MIN_GAIN_MARGIN_DB))
    if pm < MIN_PHASE_MARGIN_DEG:
        failures.append(ResponseError.PHASE_MARGIN.format(value=pm, minimum=MIN_PHASE_MARGIN_DEG))
    measured = []
    fms = None if measure is None else _frequencies(measure, T, "measure", MAX_MEASURED)
    if fms is not None and rho < 1:  # an unstable loop has no steady response to measure
        total = sum(measure_duration(model, float(fm)) for fm in fms)
        if total > MAX_MEASURE_SECONDS:
            raise ResponseError(
                ResponseError.MEASURE_WORK.format(count=len(fms), seconds=total, limit=MAX_MEASURE_SECONDS)
            )
        for fm in fms:
            p = measure_point(sc, model, float(fm), leg - 1, amplitude)
            measured.append(p)
            if not p.agrees:
                failures.append(
                    ResponseError.DISAGREES.format(
                        f=p.freq, d=float(abs(p.response[p.leg] - p.linear[p.leg])), tol=float(p.tolerance[p.leg])
                    )
                )
    return LoopResponse(
        pose=np.asarray(pose, dtype=float),
        law=sc.controller,
        frequencies=f,
        setpoint=Tsp,
        cartesian=model.cartesian_response(f),
        loop=L,
        sensitivity_peak=float(np.linalg.svd(S, compute_uv=False).max()),
        margins=per_leg,
        bandwidth_hz=bw,
        spectral_radius=rho,
        failures=failures,
        measured=measured,
    )


def _frequencies(values, T: float, name: str, limit: int = MAX_FREQUENCIES) -> np.ndarray:
    f = np.atleast_1d(np.asarray(values, dtype=float))
    if f.ndim != 1 or not 1 <= len(f) <= limit:
        raise ResponseError(ResponseError.COUNT.format(name=name, count=f.size, limit=limit))
    nyq = 0.5 / T
    bad = ~(np.isfinite(f) & (f > 0) & (f < nyq))
    if bad.any():
        i = int(np.argmax(bad))
        raise ResponseError(ResponseError.FREQUENCY.format(name=name, index=i + 1, value=float(f[i]), nyquist=nyq))
    return f
