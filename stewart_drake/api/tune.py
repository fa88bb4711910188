"""``tune``: leg PID gains that meet stated margins on the linear loop at every pose of a grid over the
workspace box (``control.tuning``), the finest length LSB the certificate proves free of saturation
(``firmware.certify``), the quantisation ripple predicted for both (``control.ripple``) against the chatter
limit, and the tuned machine verified by the nonlinear loop (``simulate``) — before and after, side by side.

Imports pydrake (through ``api.simulation``).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from stewart_drake.api.result import Result
from stewart_drake.api.simulation import plan_run, run_machine, run_plan
from stewart_drake.control.chatter import CHATTER_RANGE_FRACTION
from stewart_drake.control.frequency import MIN_GAIN_MARGIN_DB, MIN_PHASE_MARGIN_DEG, effective_gains
from stewart_drake.control.ripple import quantisation_ripple
from stewart_drake.control.tuning import GridLoops, LoopSpec, grid_poses, no_gains_message, tune_gains
from stewart_drake.core.geometry import Platform
from stewart_drake.errors import StewartError, TuneError
from stewart_drake.firmware.certify.box import PoseBox, parse_box
from stewart_drake.firmware.certify.certificate import certify
from stewart_drake.spec import Gains, Machine

if TYPE_CHECKING:  # annotations only: matplotlib is loaded when a figure is asked for
    from matplotlib.figure import Figure

# The certified IK error (mm, largest leg) the chosen format must keep within.
ERROR_BUDGET_M = 0.5e-3
# At most this many sensor counts per length LSB are tried (the finest proven one is taken).
LSB_COUNTS_TRIED = 200
# Cells per certificate while choosing the LSB (``firmware optimize``'s search budget).
CERTIFY_CELLS = 30_000
# Feasible gain sets tried against the ripple budget, widest bandwidth first.
RIPPLE_TRIES = 12


@dataclass(repr=False)
class TuneResult(Result):
    """The tuner's choice (``tune``).

    Attributes:
        machine: the tuned ``Machine`` (its ``controller.gains`` and ``firmware.length_lsb``); None when no gains
            meet the margins.
        before, after: ``{"linear": worst-pose margins, bandwidth, pole radius and gains over the grid;
            "ripple": the predicted ripple (bound and estimate, by source); "run": the nonlinear run's ripple,
            tracking and failures}`` for the machine as given and as tuned (``after`` None without a choice).
        grid: (n, 6) the grid's poses (m, rad).
        targets: the margins and bandwidth asked for, the ripple limit and the error budget.
        format: the chosen format with its certified error (mm).
        failures: why the tuned machine falls short (empty: ok).
        seconds: wall time of the whole tune.
    """

    machine: Machine | None
    before: dict
    after: dict | None
    grid: np.ndarray
    targets: dict
    format: dict | None
    failures: list
    seconds: float

    @property
    def ok(self) -> bool:
        """True when every step passed: margins met, a format proven, the ripple under the limit, the run good."""
        return not self.failures

    def _fields(self) -> dict:
        return {
            "targets": self.targets,
            "grid_poses": self.grid,
            "before": self.before,
            "after": self.after,
            "format": self.format,
            "failures": self.failures,
            "seconds": self.seconds,
        }

    def plot(self) -> Figure:
        """Bars of the worst-pose margins, bandwidth, predicted and simulated ripple and tracking error,
        before and after.

        Returns:
            A matplotlib ``Figure``.
        """
        # deferred: pyplot is loaded only when a figure is drawn
        import matplotlib.pyplot as plt

        rows = [
            ("gain margin [dB]", lambda d: d["linear"]["gain_margin_db"]),
            ("phase margin [deg]", lambda d: d["linear"]["phase_margin_deg"]),
            ("bandwidth [Hz]", lambda d: d["linear"]["bandwidth_hz"] or 0.0),
            ("ripple, estimate [N]", lambda d: d["ripple"]["rms_N"]),
            ("ripple, simulated [N]", lambda d: d.get("run", {}).get("force_ripple_N", math.nan)),
            ("max leg error [mm]", lambda d: d.get("run", {}).get("max_leg_error_mm", math.nan)),
        ]
        fig, axes = plt.subplots(1, len(rows), figsize=(14, 3))
        for ax, (name, get) in zip(axes, rows):
            vals = [get(self.before)] + ([get(self.after)] if self.after else [])
            ax.bar(["before", "after"][: len(vals)], [v if math.isfinite(v) else 0.0 for v in vals])
            ax.set_title(name, fontsize=9)
        fig.suptitle(f"tune: {'ok' if self.ok else '; '.join(self.failures)[:120]}", fontsize=9)
        fig.tight_layout()
        return fig


def _number(value, name: str, rule: str, ok) -> float:
    good = isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool)
    if not (good and math.isfinite(value) and ok(value)):
        raise TuneError(TuneError.MARGIN.format(name=name, rule=rule, value=value))
    return float(value)


def loop_spec(plan) -> LoopSpec:
    """The linear loop's timing, lag and feed-forward lead of a planned run."""
    sc = plan.scenario
    lag, step = sc.actuators.time_constant, sc.plant_time_step
    steps = plan.timing.sample_period / step
    if lag > 0 and abs(steps - round(steps)) > 1e-9 * steps:  # the model steps the lag at the plant steps
        raise TuneError(TuneError.PLANT_STEPS.format(step=step, period=plan.timing.sample_period))
    return LoopSpec.of(sc.config, lag, step, sc.feedforward)


def choose_length_lsb(platform: Platform, machine: Machine, box: PoseBox) -> tuple[float | None, float | None]:
    """``(length_lsb, error_m)``: the finest LSB, a whole number of sensor counts, whose words hold the stroke
    and whose certificate over ``box`` proves no saturation, with its certified error (largest leg);
    ``(None, None)`` when none is proven within ``LSB_COUNTS_TRIED`` counts."""
    r, fmt = machine.sensors.resolution, machine.firmware
    for k in range(1, LSB_COUNTS_TRIED + 1):
        f = replace(fmt, length_lsb=float(f"{k * r:.12g}"))
        if f.qformat().range_m < float(platform.stroke[1]):
            continue
        try:
            cert = certify(platform, f.qformat(), box, fmt.convention, CERTIFY_CELLS)
        except StewartError:  # the box or a constant does not fit the words at this LSB
            continue
        if not cert.saturation_possible:
            return f.length_lsb, max(cert.error_bound_mm) * 1e-3
    return None, None


def _ripple(plan, spec: LoopSpec, pose, gains) -> dict:
    sc = plan.scenario
    model = spec.model(sc.platform, pose, gains)
    r = quantisation_ripple(
        model, sc.config.ik_format.length_lsb, plan.timing.sensor_resolution, plan.timing.command_range
    )
    return r.to_dict()


def _run_summary(result) -> dict:
    s = result.summary
    return {
        "force_ripple_N": float(max(s["force_ripple_N"])),
        "ripple_range_fraction": s["ripple_range_fraction"],
        "chatter": s["chatter"],
        "max_leg_error_mm": s["max_leg_error_mm"],
        "rms_leg_error_mm": s["rms_leg_error_mm"],
        "failures": list(result.verdict["failures"]),
    }


def tune(
    machine: Machine | Platform | str | Path,
    *,
    bandwidth: float | None = None,
    gain_margin_db: float = MIN_GAIN_MARGIN_DB,
    phase_margin_deg: float = MIN_PHASE_MARGIN_DEG,
    error_budget: float = ERROR_BUDGET_M,
    box: list[str] | None = None,
    verify: bool = True,
    **overrides,
) -> TuneResult:
    """Tune ``machine``'s leg PID gains and length LSB (see the module docstring and ``control.tuning``).

    Args:
        machine: a ``Machine``, a ``Platform`` or a machine file.
        bandwidth: the worst-pose feedback bandwidth the gains must reach (Hz; None: the largest found).
        gain_margin_db: the gain margin each leg's loop must keep at every grid pose (dB).
        phase_margin_deg: the phase margin each leg's loop must keep at every grid pose (degrees).
        error_budget: the certified IK error (m) the chosen format must keep within.
        box: ``KEY=LO..HI`` words (``KEY`` in px py pz a b g; mm and degrees, or with a unit) narrowing the
            workspace box (``firmware.certify.workspace_box``) whose grid the gains must hold on and over which
            the format is certified (keys not given keep its range).
        verify: run the nonlinear loop (``simulate``) of the machine as given and as tuned.
        **overrides: any spec path (``**{"controller.period": 5e-4}``).

    Returns:
        The tuned machine, before/after figures and the verdict (``ok``).

    Raises:
        StewartError: bad input (``TuneError`` naming the argument), and ``plan_run``'s checks of the machine.
    """
    t0 = time.perf_counter()
    gm = _number(gain_margin_db, "gain_margin_db", ">= 0 dB", lambda v: v >= 0)
    pm = _number(phase_margin_deg, "phase_margin_deg", "0 … 180 deg", lambda v: 0 <= v < 180)
    budget = _number(error_budget, "error_budget", "> 0 m", lambda v: v > 0)
    m = run_machine(machine, {}, overrides)
    plan = plan_run(m, command="tune")
    sc, timing = plan.scenario, plan.timing
    nyquist = 0.5 / timing.sample_period
    if bandwidth is not None:
        good = isinstance(bandwidth, (int, float, np.integer, np.floating)) and not isinstance(bandwidth, bool)
        if not (good and math.isfinite(bandwidth) and 0 < bandwidth < nyquist):
            raise TuneError(TuneError.BANDWIDTH.format(nyquist=nyquist, value=bandwidth))
    platform = sc.platform
    box = parse_box(box, platform, "mm", "deg")
    poses = grid_poses(platform, box.lo, box.hi)
    if not len(poses):
        raise TuneError(TuneError.NO_POSES.format(name=platform.name))
    spec = loop_spec(plan)
    centre = poses[0]  # the box's centre where it is in stroke: the ripple is predicted there

    def realised(g):  # the gains the law applies (the fixed law's Q15 words)
        return effective_gains(sc.controller, replace(sc.config, gains=g))

    loops = GridLoops(platform, poses, spec, realised(sc.config.gains))
    before_eval = loops.evaluate(realised(sc.config.gains))
    before = {"linear": before_eval.to_dict(), "ripple": _ripple(plan, spec, centre, before_eval.gains)}
    if verify:
        before["run"] = _run_summary(run_plan(plan))
    targets = {
        "gain_margin_db": gm,
        "phase_margin_deg": pm,
        "bandwidth_hz": bandwidth,
        "ripple_limit_N": CHATTER_RANGE_FRACTION * timing.command_range,
        "error_budget_m": budget,
        "grid": "centre, 12 face centres and 64 corners of the workspace box, in stroke",
        "box": box.to_units("mm", "deg"),
    }
    failures: list[str] = []
    chosen, best, feasible = tune_gains(loops, sc.config.gains, gm, pm, bandwidth, realise=realised)
    if chosen is None:
        failures.append(no_gains_message(best, sc.config.gains, gm, pm, bandwidth))
        return TuneResult(None, before, None, poses, targets, None, failures, time.perf_counter() - t0)
    lsb, err = choose_length_lsb(platform, m, box)
    fmt = None
    if lsb is None:
        failures.append(TuneError.NO_FORMAT.format(bits=m.firmware.word_bits, r=m.sensors.resolution))
        lsb = m.firmware.length_lsb
    else:
        fmt = {"word_bits": m.firmware.word_bits, "length_lsb_m": lsb, "trig": m.firmware.trig, "error_m": err}
        if err > budget:
            failures.append(TuneError.BUDGET.format(error=err * 1e3, budget=budget * 1e3))
    limit = targets["ripple_limit_N"]
    tuned_plan, ripple, pick = None, None, chosen
    for ev in feasible[:RIPPLE_TRIES]:  # the widest bandwidth whose predicted ripple fits the chatter limit
        g = ev.gains
        tuned = replace(
            m,
            controller=replace(m.controller, gains=Gains(kp=g.kp, ki=g.ki, kd=g.kd, kv=g.kv), gain_scale=1.0),
            firmware=replace(m.firmware, length_lsb=lsb),
        )
        tuned_plan, pick = plan_run(tuned, command="tune"), ev
        ripple = _ripple(tuned_plan, spec, centre, ev.gains)
        if ripple["rms_N"] <= limit:
            break
    else:
        failures.append(
            TuneError.RIPPLE.format(
                rms=ripple["rms_N"], limit=limit, fraction=CHATTER_RANGE_FRACTION * 100, cause=ripple["cause"]
            )
        )
    after = {"linear": pick.to_dict(), "ripple": ripple}
    if verify:
        run = run_plan(tuned_plan)
        after["run"] = _run_summary(run)
        failures += [TuneError.VERIFY.format(failure=f) for f in run.verdict["failures"]]
    return TuneResult(tuned_plan.machine, before, after, poses, targets, fmt, failures, time.perf_counter() - t0)
