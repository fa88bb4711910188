"""The one home of a closed-loop run: ``plan_run`` checks a run's settings and builds its ``Scenario``;
``simulate`` runs it and summarises it. ``stewart-drake simulate``, ``run --simulate``, every Monte Carlo run
and the report's loops build their runs here, so that the timing checks, the gain-design horizon, the tick
count and the engine/firmware rules are written once.

Imports pydrake (through ``drake.simulation``): ``import stewart_drake`` loads this module on first use of
``simulate``.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from stewart_drake.api.result import Result, plain
from stewart_drake.control import ControllerConfig, DspTiming, check_timing
from stewart_drake.control.feasibility import infeasible_motion
from stewart_drake.control.feedforward import feedforward_engine
from stewart_drake.control.gains import PidGains
from stewart_drake.control.simulation_log import SimulationLog
from stewart_drake.control.tuning import LoopSpec, tuned_gains
from stewart_drake.control.verdict import run_verdict
from stewart_drake.core.geometry import PRESETS, Platform, load_preset
from stewart_drake.core.sanity import (
    check_trajectory,
    check_work,
    fmt_value,
    require_plant_plate,
)
from stewart_drake.core.trajectory import Trajectory, design_poses, fit_trajectory, get_trajectory
from stewart_drake.core.unit_hint import other_unit_hint
from stewart_drake.drake.firmware_run import run_user_firmware
from stewart_drake.drake.integrators import DEFAULT_INTEGRATOR
from stewart_drake.drake.simulation import ActuatorModel, Scenario, SensorModel, build_simulation
from stewart_drake.errors import (
    FIRMWARE_FORMAT_ADOPTED,
    OPTION_DURATION_PERIOD,
    OPTION_ENGINE_FIXED,
    OPTION_FIRMWARE_ENGINE,
    PIL_STOPPED,
    SIMULATION_GAP_WARNING,
    FirmwareError,
    MachineError,
    OptionError,
    PhysicalLimitError,
    UsageError,
)
from stewart_drake.firmware.certify.box import workspace_box
from stewart_drake.firmware.engine import default_engine
from stewart_drake.firmware.fingerprint import PLATFORM_HASH, platform_hash, read_fingerprint
from stewart_drake.firmware.module import check_source
from stewart_drake.script import compile_program
from stewart_drake.script.source import read_program
from stewart_drake.spec import Gains, Machine, load_machine
from stewart_drake.system.isolate import FIRMWARE_IDLE_LIMIT_S, check_time_limit

if TYPE_CHECKING:  # annotations only: matplotlib and pandas are loaded when a figure or a table is asked for
    import pandas
    from matplotlib.figure import Figure

# Memory per plant step of the logs (state, command, set-point, force, status: ~100 doubles) and of
# log.csv's rows while they are written, and wall time per plant step (the fixed-point controller and
# the SAP plant: ~1 ms on one core); a run is refused beyond the memory budget or MAX_RUN_SECONDS.
BYTES_PER_STEP = 4000
SECONDS_PER_STEP = 1e-3
MAX_RUN_SECONDS = 3600.0


def check_simulation_size(duration: float, plant_step: float, option: str, value) -> None:
    """Refuse a simulation whose logs would not fit in memory or that would run for more than an hour."""
    check_work(
        option,
        f"{fmt_value(value)} s",
        duration / plant_step,
        f"plant steps of {fmt_value(plant_step)} s",
        BYTES_PER_STEP,
        seconds_per=SECONDS_PER_STEP,
        max_seconds=MAX_RUN_SECONDS,
        hint=f"; use a shorter {option}",
    )


def tick_count(duration: float, period: float) -> int:
    """The controller ticks of a run of ``duration`` s at ``period`` s: t = 0, T, ... <= duration."""
    return int(math.floor(duration / period + 1e-9)) + 1


@dataclass(frozen=True)
class RunPlan:
    """A checked closed-loop run: its ``scenario`` (what ``drake.simulation.build_simulation`` builds), the
    controller's ``timing``, the ``duration`` (s), the ``warnings`` found while checking and the units a CSV
    reference was read in (``read_units``, None for others)."""

    scenario: Scenario
    timing: DspTiming
    duration: float
    warnings: tuple = ()
    read_units: dict | None = None
    time_limit: float = 60.0  # a user's firmware: seconds the simulated time may stand still (drake.firmware_run)
    machine: Machine | None = None  # the machine run (with the firmware's format where one was adopted)

    @property
    def config(self) -> ControllerConfig:
        """The controller's timing and gains."""
        return self.scenario.config


PIL_COMMANDS = ("simulate", "run --simulate")  # the callers of plan_run whose run goes to a PIL target (pil.target)

# plan_run's and simulate's keywords of earlier versions -> the spec path they set (None: the machine's)
KEYWORD_PATHS = {
    "controller": "controller.law",
    "period": "controller.period",
    "latency": "controller.latency",
    "sensor_resolution": "sensors.resolution",
    "feedforward": "controller.feedforward",
    "engine": "controller.engine",
    "plant_step": "run.plant_step",
    "integrator": "run.integrator",
    "fit": "run.fit",
    "duration": "run.duration",
}


def run_machine(machine: Machine | Platform | str | Path, keywords: dict, overrides: dict) -> Machine:
    """``machine`` (a ``Machine``, a ``Platform`` with every other section at its defaults, or a machine file)
    with the given ``keywords`` (``KEYWORD_PATHS``' names; None: the machine's) and ``overrides`` by spec path
    (``{"controller.period": 5e-4}``, values in SI or as quantity text)."""
    given = {KEYWORD_PATHS[k]: v for k, v in keywords.items() if v is not None}
    return load_machine(machine, {**given, **overrides})


def firmware_source(path, what: str = "firmware") -> Path:
    """The C file of ``path``: a file, or a folder holding ``sd_firmware.c`` (``firmware generate``'s); a
    ``FirmwareError`` naming ``what`` and the path as written otherwise."""
    p = Path(path) if str(path).strip() else None
    if p is not None and p.is_dir() and (p / "sd_firmware.c").is_file():
        p = p / "sd_firmware.c"
    return check_source(p if p is not None else path, what)


def _length(v: float) -> str:
    return f"{v * 1e3:g} mm" if v >= 1e-3 else f"{v * 1e6:g} µm"


def adopt_firmware(machine: Machine, path) -> tuple[Machine, list]:
    """``(machine, warnings)``: the machine a firmware's loop runs, with the number format, sensor resolution
    and rate the firmware at ``path`` records (``firmware.fingerprint``) where they differ from the machine's
    (a warning names each: the loop must compute what the firmware computes). A firmware recorded for another
    platform (its content hash) raises ``MachineError`` naming both; one without a record runs as is."""
    rec = read_fingerprint(path)
    if rec is None:
        return machine, []
    opts, where = rec
    mine, recorded_hash = platform_hash(machine.platform), opts[PLATFORM_HASH]
    if recorded_hash is None and opts["platform"] in PRESETS:  # generated before the hash was recorded
        recorded_hash = platform_hash(load_preset(opts["platform"]))
    if recorded_hash is not None and recorded_hash != mine:
        raise MachineError(
            MachineError.FIRMWARE_PLATFORM.format(
                firmware=where,
                recorded=opts["platform"],
                recorded_hash=recorded_hash,
                platform=machine.platform.name,
                platform_hash=mine,
            )
        )
    fw, c, r = machine.firmware, machine.controller, machine.sensors
    length = _length
    recorded = {  # path: (the firmware's, the machine's, what it is, how it is shown)
        "firmware.word_bits": (opts["word_bits"], fw.word_bits, "word bits", str),
        "firmware.length_lsb": (opts["length_lsb"], fw.length_lsb, "length LSB", length),
        "firmware.trig": (opts["trig"], fw.trig, "trig", str),
        "firmware.convention": (opts["convention"], fw.convention, "convention", str),
        "sensors.resolution": (opts["sensor_resolution"], r.resolution, "sensor resolution", length),
        "controller.period": (1.0 / opts["rate"], c.period, "rate", lambda v: f"{1 / v:g} Hz"),
    }
    changed = {k: v for k, v in recorded.items() if v[0] != v[1]}
    if not changed:
        return machine, []
    warnings = [
        FIRMWARE_FORMAT_ADOPTED.format(what=f"{what} {show(new)}", machine=show(old))
        for new, old, what, show in changed.values()
    ]
    fmt = {k.split(".")[1]: v[0] for k, v in changed.items() if k.startswith("firmware.")}
    machine = replace(machine, firmware=replace(fw, **fmt)) if fmt else machine
    if "sensors.resolution" in changed:
        machine = replace(machine, sensors=replace(r, resolution=changed["sensors.resolution"][0]))
    if "controller.period" in changed:
        machine = replace(machine, controller=replace(c, period=changed["controller.period"][0]))
    return machine, warnings


def _sensor(machine: Machine, duration: float) -> SensorModel | None:
    """The machine's sensor noise as a ``SensorModel`` (drawn from ``run.seed``), None for an ideal sensor."""
    sigma, period = machine.sensors.noise, machine.controller.period
    if sigma == 0:
        return None
    n = tick_count(duration, period) + 1
    noise = np.random.default_rng(machine.run.seed).normal(0.0, sigma, (n, 6))
    return SensorModel(np.zeros(6), noise, np.zeros(n), period)


def _motion(motion, platform: Platform, rate: float, **units) -> Trajectory:
    """The reference of ``motion``: a ``.stw`` program is run from the platform's home pose and sampled at
    the controller's ``rate``; the others are ``get_trajectory``'s."""
    if isinstance(motion, (str, Path)) and str(motion).endswith(".stw"):
        traj = compile_program(read_program(str(motion)), str(motion), platform)[1].trajectory(rate)
        return replace(traj, name=Path(motion).stem)
    return get_trajectory(motion, **units)


def actuator_model(machine: Machine) -> ActuatorModel:
    """The loop's ``ActuatorModel`` of ``machine.actuators``: the lag, or the screw with its current loop's
    (the cylinder with its valve's) time constant as the lag the gains and the feed-forward are designed for."""
    a = machine.actuators
    if a.model == "screw":
        screw = a.screw(machine.platform.legs.max_force)
        return ActuatorModel(screw.max_force, screw.current_time_constant, screw)
    if a.model == "hydraulic":  # the force loop's lag as the lag
        hyd = a.hydraulic(machine.platform)
        return ActuatorModel(hyd.max_force, hyd.valve_time_constant, hydraulic=hyd)
    return ActuatorModel(a.max_force, a.time_constant)


def plan_run(
    platform: Machine | Platform | str | Path,
    trajectory: str | Path | Trajectory | None = None,
    controller: str | None = None,
    duration: float | None = None,
    *,
    period: float | None = None,
    latency: str | None = None,
    sensor_resolution: float | None = None,
    plant_step: float | None = None,
    feedforward: bool | None = None,
    engine: str | None = None,
    firmware: str | None = None,
    time_limit: float = FIRMWARE_IDLE_LIMIT_S,
    integrator: str | None = None,
    fit: bool | None = None,
    allow_out_of_stroke: bool = False,
    length_unit: str = "m",
    angle_unit: str = "rad",
    smooth: float | None = None,
    actuators: ActuatorModel | None = None,
    sensor: SensorModel | None = None,
    plant_platform: Platform | None = None,
    gain_scale: float = 1.0,
    nominal_gains: bool = False,
    gains=None,
    command_range: float | None = None,
    checks: bool = True,
    command: str = "simulate",
    duration_shown=None,
    **overrides,
) -> RunPlan:
    """Check a closed-loop run's settings and build its ``Scenario``. Its keywords from ``trajectory`` to
    ``smooth`` are ``simulate``'s options, documented there once.

    ``platform``: a ``Machine`` (or a ``Platform`` or machine file: a machine with defaults); the keywords
    ``controller``, ``period``, ``latency``, ``sensor_resolution``, ``plant_step``, ``feedforward``, ``engine``,
    ``integrator`` and ``fit`` set their spec paths (``KEYWORD_PATHS``; None keeps the machine's), and
    ``overrides`` set any spec path (``**{"firmware.length_lsb": "30um"}``). The loop's number format is the
    machine's ``firmware`` (or, with ``firmware``, the one the firmware records: ``adopt_firmware``).
    ``actuators``, ``sensor``, ``plant_platform``: a perturbed run (Monte Carlo); ``gain_scale`` multiplies
    the designed gains; ``nominal_gains``: design them for the nominal timing (``DspTiming()``: what the
    firmware was built for) rather than this run's (``gains``: those nominal gains, computed once by the caller,
    e.g. a Monte Carlo study); ``command_range``: the Q15 command's full scale, N (default the
    platform's ``legs.max_force``); ``checks=False`` skips the per-run sanity checks (the
    caller has checked the study); ``command``: how messages name the caller; ``duration_shown``: the
    duration as the user wrote it.
    """
    keywords = dict(
        controller=controller,
        period=period,
        latency=latency,
        sensor_resolution=sensor_resolution,
        plant_step=plant_step,
        feedforward=feedforward,
        engine=engine,
        integrator=integrator,
        fit=fit,
        duration=duration,
    )
    machine = run_machine(platform, keywords, overrides)
    warnings: list[str] = []
    if firmware is not None:
        firmware = str(firmware_source(firmware))
        machine, warnings = adopt_firmware(machine, firmware)
    time_limit = check_time_limit(time_limit)
    machine.check_loop_format()
    platform = machine.loaded_platform
    ctl, fmt = machine.controller, machine.firmware
    controller, period, latency = ctl.law, ctl.period, ctl.latency
    feedforward, engine, sensor_resolution = ctl.feedforward, ctl.engine, machine.sensors.resolution
    plant_step, integrator, fit = machine.run.plant_step, machine.run.integrator, machine.run.fit
    duration = machine.run.duration
    trajectory = machine.motion if trajectory is None else trajectory
    if checks:
        require_plant_plate(platform, command)  # the plate carries the legs: not negligible against them
    plant_step = plant_step if plant_step is not None else min(period, 1e-3)
    csv = isinstance(trajectory, (str, Path)) and str(trajectory) not in ("seed", "rotating")
    units = {"length_unit": length_unit, "angle_unit": angle_unit}
    traj = _motion(trajectory, platform, 1.0 / period, **units, **({"smooth": smooth} if smooth is not None else {}))
    if fit:
        traj = fit_trajectory(traj, platform)
    duration = duration if duration is not None else (traj.duration or 1.0)
    actuators = actuators or actuator_model(machine)
    if actuators.screw is not None and actuators.screw.encoder_resolution is not None:
        sensor_resolution = actuators.screw.encoder_resolution  # the legs' sensor is the motor's encoder
    # the lag the gains are designed for: the lag's (the machine's nominal one), or the screw's current loop's
    # (the cylinder's valve's)
    design_lag = machine.actuators.time_constant if actuators.model == "lag" else actuators.time_constant
    sensor = sensor if sensor is not None else _sensor(machine, duration)
    timing = DspTiming(
        sample_period=period,
        latency=latency,
        sensor_resolution=sensor_resolution,
        command_range=float(platform.legs.max_force) if command_range is None else command_range,
    )
    if checks:
        timing.check()
        # the screw's current loop is stepped exactly (zero-order hold), the cylinder's by sub-steps: a plant step
        # may be longer than either
        lag = actuators.time_constant if actuators.model == "lag" else 0.0
        check_timing(platform, period, plant_step, lag, timing.output_delay)
        if duration < period:  # the log would hold the initial state only, its errors 0: no result at all
            raise OptionError(OPTION_DURATION_PERIOD.format(value=fmt_value(duration), period=fmt_value(period)))
        shown = duration_shown if duration_shown is not None else duration
        check_simulation_size(duration, plant_step, "run.duration", shown)
        ticks = np.arange(tick_count(duration, period)) * period
        try:
            warnings += check_trajectory(
                platform, ticks, traj.pose(ticks), "utn", f"the {traj.name} reference", allow_out_of_stroke
            )
        except PhysicalLimitError as e:  # a CSV in the other unit than it was read in says so
            hint = (
                other_unit_hint(platform, traj.pose(ticks), length_unit, angle_unit, api=True)
                if csv and not fit
                else ""
            )
            raise PhysicalLimitError(str(e) + hint) from None
        why = infeasible_motion(platform, traj, ticks, period)
        if why:  # before the run: no controller follows it (it ended in raw solver messages)
            raise PhysicalLimitError(why)
    # the gains designed for the platform over the poses of the whole run (and the reference's own length)
    poses = design_poses(traj, max(duration, traj.duration or 0.0))
    form = {"ik_format": fmt.qformat(), "convention": fmt.convention}
    scale = gain_scale * ctl.gain_scale
    if isinstance(ctl.gains, Gains):
        gains = PidGains(kp=ctl.gains.kp, ki=ctl.gains.ki, kd=ctl.gains.kd, kv=ctl.gains.kv)
    elif nominal_gains and gains is None:
        gains = ControllerConfig.for_platform(platform, poses=poses).gains
    elif not nominal_gains:
        gains = ControllerConfig.for_platform(platform, timing, design_lag, poses=poses).gains
    # the tuner, around the design, at plan time (a Monte Carlo study's runs share the nominal design instead)
    if ctl.gains == "tune" and not nominal_gains:
        designed = ControllerConfig.for_platform(platform, timing, gains=gains, **form)
        spec = LoopSpec.of(designed, design_lag, plant_step, feedforward)
        box = workspace_box(platform)
        gains = tuned_gains(platform, designed, controller, spec, box.lo, box.hi)
    if scale != 1.0:
        gains = replace(gains, kp=gains.kp * scale, ki=gains.ki * scale, kd=gains.kd * scale, kv=gains.kv * scale)
    config = ControllerConfig.for_platform(platform, timing, gains=gains, **form)
    if (engine == "c" or firmware) and controller != "fixed":
        raise UsageError(OPTION_ENGINE_FIXED.format(controller=controller))
    if firmware and engine == "python":
        raise UsageError(OPTION_FIRMWARE_ENGINE)
    engine = "c" if firmware else default_engine(engine, controller, f"stewart-drake {command.split()[0]}")
    # one run on a target: simulate and run --simulate; the studies of many runs (Monte Carlo, the report, the
    # response) keep the host loop, whose numbers the target's equal
    pil = machine.pil if machine.pil.target and command in PIL_COMMANDS else None
    if pil is not None and (controller != "fixed" or firmware):
        law = "user firmware's" if firmware else controller
        raise FirmwareError(FirmwareError.PIL_LAW.format(target=pil.target, law=law))
    scenario = Scenario(
        platform,
        traj,
        controller,
        config,
        actuators,
        plant_time_step=plant_step,
        feedforward=feedforward,
        engine=engine,
        firmware=firmware,
        integrator=integrator or DEFAULT_INTEGRATOR,
        plant_platform=plant_platform,
        sensor=sensor,
        duration=duration,
        pil=pil,
        seed=machine.run.seed,
    )
    read_units = {"length": length_unit, "angle": angle_unit} if csv else None
    return RunPlan(scenario, timing, duration, tuple(warnings), read_units, time_limit, machine)


@dataclass(frozen=True)
class Log:
    """The logs of a closed-loop run, arrays by name (SI): ``t`` (n,) s; ``pose`` (n, 6) measured pose;
    ``lengths`` (n, 6) true leg lengths, m; ``command`` and ``force`` (n, 6) N; ``setpoint`` (n, 6) m;
    ``status`` (n, k); ``length_error`` and ``pose_error`` (n, 6) against the reference; ``t_ref`` (m,),
    ``reference`` (m, 6) the reference at the ticks. ``log["pose"]`` or ``log.pose``."""

    raw: SimulationLog
    length_error: np.ndarray
    pose_error: np.ndarray

    def __getitem__(self, name: str) -> np.ndarray:
        if name in ("length_error", "pose_error"):
            return getattr(self, name)
        if name not in SimulationLog.ARRAYS:
            raise KeyError(name)
        return getattr(self.raw, name)

    def __getattr__(self, name: str):
        if name in SimulationLog.ARRAYS:
            return getattr(self.raw, name)
        raise AttributeError(name)

    def keys(self) -> list[str]:
        """The names of the arrays."""
        return [*SimulationLog.ARRAYS, "length_error", "pose_error"]

    def to_pandas(self) -> pandas.DataFrame:
        """One row per plant step: ``t``, the pose, leg lengths, set-points, commands, forces, errors.

        Returns:
            A ``pandas.DataFrame`` (pandas must be installed).
        """
        # deferred: pandas is optional (a notebook's), the library does not need it
        import pandas as pd

        cols = {"t": self.raw.t}
        for name, arr in (
            ("pose", self.raw.pose),
            ("L", self.raw.lengths),
            ("setpoint", self.raw.setpoint),
            ("command", self.raw.command),
            ("force", self.raw.force),
            ("length_error", self.length_error),
        ):
            labels = ("px", "py", "pz", "a", "b", "g") if name == "pose" else range(1, 7)
            cols.update({f"{name}_{c}": arr[:, i] for i, c in enumerate(labels)})
        return pd.DataFrame(cols)


@dataclass(frozen=True)
class Animation:
    """A self-contained HTML Meshcat animation of a run (shown inline by Jupyter; ``save`` writes it)."""

    html: str

    def _repr_html_(self) -> str:
        escaped = self.html.replace("&", "&amp;").replace('"', "&quot;")
        return f'<iframe srcdoc="{escaped}" style="width: 100%; height: 480px; border: none"></iframe>'

    def save(self, path: str | Path) -> Path:
        """Write the page to ``path`` (a new file).

        Args:
            path: where to write, e.g. ``"run.html"``.

        Returns:
            The path written.
        """
        p = Path(path)
        with p.open("x", encoding="utf-8") as fh:  # never overwrite a file the user did not name to replace
            fh.write(self.html)
        return p


@dataclass(repr=False)
class SimulationResult(Result):
    """A closed-loop run (``simulate``).

    Attributes:
        summary: the run's settings, gains and errors (the dict ``stewart-drake simulate`` writes to
            summary.json, less its ``files``).
        log: the logs, arrays by name (``log.to_pandas()``).
        verdict: ``{"tracking_bound_mm", "saturation_bound_s", "longest_saturation_s", "tracking_lost",
            "saturated_legs", "failures"}`` (``control.verdict.run_verdict``).
        warnings: what was allowed but is worth knowing (a reference outside the stroke, an opened loop).
        plan: the checked run (its ``Scenario``, timing and duration).
    """

    summary: dict
    log: Log
    verdict: dict
    warnings: list
    plan: RunPlan = field(repr=False)

    @property
    def ok(self) -> bool:
        """The run tracked its reference (no failure in ``verdict``)."""
        return not self.verdict["failures"]

    def _fields(self) -> dict:
        return self.summary

    def plot(self) -> Figure:
        """Leg-length errors and leg forces over time.

        Returns:
            A matplotlib ``Figure``.
        """
        # deferred: pyplot is loaded only when a figure is drawn
        import matplotlib.pyplot as plt

        log = self.log.raw
        fig, ax = plt.subplots(2, 1, figsize=(9, 6), sharex=True)
        ax[0].plot(log.t, self.log.length_error * 1e3)
        ax[0].set_ylabel("leg length − IK(reference) [mm]")
        ax[0].legend([f"leg {i}" for i in range(1, 7)], ncol=6, fontsize=7)
        ax[1].plot(log.t, log.force)
        ax[1].set_ylabel("actuator force [N]")
        ax[1].set_xlabel("t [s]")
        fig.suptitle(
            f"{log.kind} controller, {log.trajectory} trajectory on {log.platform.replace('$', r'\$')}, "
            f"T = {log.sample_period * 1e3:g} ms"
        )
        return fig

    def animate(self, fps: float = 25.0) -> Animation:
        """The run as a Meshcat animation (legs turn red near a stroke end or while saturated).

        Args:
            fps: frames per second of the animation.

        Returns:
            An `Animation`: displayed inline in Jupyter, ``save(path)`` writes the HTML.
        """
        # deferred: the Meshcat scene is built only when an animation is asked for
        from stewart_drake.drake.animation import log_saturating, record_animation

        log = self.log.raw
        sc = self.plan.scenario
        html = record_animation(
            sc.plant_platform or sc.platform,
            log.t,
            log.pose,
            saturating=log_saturating(log.status),
            fps=fps,
            title=f"{log.kind} controller, {log.trajectory} on {log.platform}",
        )
        return Animation(html)


def simulate(
    machine: Machine | Platform | str | Path,
    trajectory: str | Path | Trajectory | None = None,
    *,
    progress: bool = False,
    **options,
) -> SimulationResult:
    """Run the fixed-point (or float) controller in the loop with the Drake plant.

    Args:
        machine: the machine (``load_machine``'s), a platform (it must have plate mass properties; every other
            section at its defaults) or a machine file.
        trajectory: the pose reference: ``"seed"``, ``"rotating"``, a CSV file of t, pose rows, a ``.stw``
            motion program, or a `Trajectory` (default the machine's first motion).
        progress: show a progress bar.
        **options: the run's options (below, ``plan_run``'s keywords) and any spec path,
            ``**{"firmware.length_lsb": "30um", "controller.period": 5e-4}`` (values in SI or in the quantity
            grammar). An option left out (or None) keeps the machine's value. ``**{"pil.target": "qemu"}`` runs
            each tick on the firmware built for a Cortex-M4 in QEMU (``"qemu:semihosting"``: its faster build,
            the link on the semihosting console; ``"serial:/dev/ttyX"``: on a board) over the PIL link, in lock
            step (``summary["pil"]``: the link's counters, faults, round trips and the measured tick;
            docs/simulation-to-board.md).

    Keyword Args:
        controller (str | None): ``"fixed"`` (the DSP's fixed-point law) or ``"float"`` (its float twin) (spec
            path ``controller.law``).
        duration (float | None): simulated seconds (default ``run.duration``, else the trajectory's, else 1 s).
        period (float | None): controller sample period, s (``controller.period``).
        latency (str | None): when a tick's output is released: ``"sample"`` (one sample later),
            ``"computation"`` (after the cycle model's computation time) or ``"none"`` (``controller.latency``).
        sensor_resolution (float | None): leg-length sensor resolution, m per count (``sensors.resolution``).
        plant_step (float | None): plant time step, s (default the period, at most 1 ms) (``run.plant_step``).
        feedforward (bool | None): connect the model-based force feed-forward (``controller.feedforward``).
        engine (str | None): the fixed-point tick: ``"c"`` (the generated firmware, compiled) or ``"python"``
            (the emulation); default ``"c"`` where a C compiler is found (``controller.engine``).
        firmware (str | Path | None): a C file implementing the firmware ABI, or the folder ``firmware
            generate`` wrote, run as the controller tick (in a child process: a hang, ``exit()`` or crash in it
            is one ``StewartError`` naming the file). The loop runs the number format, sensor resolution and
            rate the firmware records (a warning names each that differs from the machine's); a firmware
            recorded for another platform is refused.
        time_limit (float): seconds the simulated time may stand still while ``firmware`` runs (default 60).
        integrator (str | None): ``"cenic-fixed"`` (default), ``"cenic"`` or ``"sap"`` (``run.integrator``).
        fit (bool | None): move and scale the reference to the platform's home height and stroke (``run.fit``).
        allow_out_of_stroke (bool): simulate a reference that leaves the stroke (a warning) instead of raising.
        length_unit (str): unit of a CSV reference's positions (default ``"m"``).
        angle_unit (str): unit of a CSV reference's angles (default ``"rad"``).
        smooth (float | None): replace a CSV reference's samples by a smoothing spline's within this RMS
            tolerance (the file's units); without it, a file rounded so coarsely that its second differences
            are noise is refused.

    Returns:
        The summary, logs and verdict of the run.

    Raises:
        StewartError: bad settings (``MachineError`` naming the spec path or the keyword, a period too slow for
            the dynamics, a run too large, an engine that does not fit the controller, ...);
            ``PhysicalLimitError`` when the reference leaves the stroke or is beyond the actuators (force or
            speed), before the run.
    """
    return run_plan(plan_run(machine, trajectory, **options), progress=progress)


def run_plan(plan: RunPlan, progress: bool = False, on_warning=None, meshcat=None) -> SimulationResult:
    """Run a checked ``RunPlan`` and summarise it (``on_warning(message)`` is called for each warning as it
    is found, e.g. to print it before the run's progress bar)."""
    warnings = list(plan.warnings)
    for w in warnings:
        if on_warning:
            on_warning(w)
    sc, timing = plan.scenario, plan.timing
    t_wall = time.perf_counter()
    if sc.firmware and meshcat is None:  # the user's C runs in a child process with a time limit
        log, gap, tick_loop = run_user_firmware(sc, plan.duration, progress, sc.firmware, plan.time_limit)
        energy = None
    else:
        sim = build_simulation(sc, meshcat=meshcat)
        try:
            log = sim.run(plan.duration, progress=progress)
            pil = sim.controller.law.report() if sc.pil is not None else None
        finally:
            sim.close()
        gap = sim.max_constraint_gap()
        tick_loop = "pil" if sc.pil is not None else sim.tick_loop
        energy = sim.controller.energy
    t_wall = time.perf_counter() - t_wall
    if gap > timing.sensor_resolution / 10:
        warnings.append(SIMULATION_GAP_WARNING.format(gap=gap, count=timing.sensor_resolution))
        if on_warning:
            on_warning(warnings[-1])
    traj = sc.trajectory
    truth = sc.plant_platform or sc.platform
    e = log.length_error(traj, truth)
    pe = log.pose_error(traj)
    config = sc.config
    summary = {
        "platform": sc.platform.name,
        "trajectory": traj.name,
        "read_units": plan.read_units,
        "controller": sc.controller,
        "engine": sc.engine,
        "tick_loop": tick_loop,  # "compiled" for either law where the loop kernel runs; "engine" is the firmware's
        "actuator_model": sc.actuators.model,  # not "lag": the Python loop (the compiled kernel steps the lag only)
        "firmware": sc.firmware,
        "sample_period_s": timing.sample_period,
        "latency": timing.latency,
        "feedforward": sc.feedforward,
        # the tables' inverse dynamics, "c" (compiled, within leg_forces_kernel.RELATIVE_TOLERANCE) or "numpy"
        "feedforward_engine": feedforward_engine(sc.controller) if sc.feedforward else None,
        "gains": {k: getattr(config.gains, k) for k in ("kp", "ki", "kd", "kv")},
        "firmware_format": {
            "word_bits": config.ik_format.word_bits,
            "length_lsb_m": config.ik_format.length_lsb,
            "trig": config.ik_format.trig,
            "convention": config.convention,
        },
        "command_range_N": config.timing.command_range,
        "output_delay_s": timing.output_delay,
        "computation_time_s": timing.computation_time,
        "plant_time_step_s": sc.plant_time_step,
        "integrator": sc.integrator,
        "max_constraint_gap_m": gap,
        "duration_s": plan.duration,
        "wall_s": t_wall,
        "real_time_factor": plan.duration / t_wall if t_wall > 0 else None,
        "ticks": int(len(log.tick_times())),
        "max_leg_error_mm": float(np.abs(e).max() * 1e3),
        "rms_leg_error_mm": float(np.sqrt(np.mean(e**2)) * 1e3),
        "max_position_error_mm": float(np.abs(pe[:, :3]).max() * 1e3),
        "max_angle_error_deg": float(np.degrees(np.abs(pe[:, 3:]).max())),
        "saturated_ticks_per_leg": log.saturations().astype(int).tolist(),
    }
    if energy is not None:  # a screw's or cylinder's energy flows over the run, J per leg (their ``powers``)
        summary["actuator_energy_J"] = {k: v.tolist() for k, v in energy.items()}
    # tracking, and the loop's own verdict: chatter (force ripple about the inverse-dynamics force) and
    # saturation at the reference's ends (control/verdict.py; each Monte Carlo run is judged there too)
    verdict, loop = run_verdict(sc.platform, truth, traj, log, config, e, pe)
    for w in loop.pop("warnings"):
        warnings.append(w)
        if on_warning:
            on_warning(w)
    summary.update(loop)
    if sc.pil is not None:
        summary["pil"] = pil
        if pil["stopped_at_tick"] is not None:
            verdict["failures"].append(PIL_STOPPED.format(**pil))
    summary.update(verdict)
    summary["warnings"] = warnings
    return SimulationResult(plain(summary), Log(log, e, pe), verdict, warnings, plan)
