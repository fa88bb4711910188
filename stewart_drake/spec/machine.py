"""A machine as one tree of frozen, typed dataclasses: the platform, its actuators, sensors, controller,
firmware number format, payload, motions (and optional requirements and calibration).

Every field is in SI (metres, seconds, newtons, kilograms) and checked on construction; an error names the
field's spec path (``controller.period must be > 0 s, got -1``). ``spec.load.load_machine`` reads one from
YAML with overrides by path; ``FIELDS`` lists every overridable path with its dimension.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from stewart_drake.core.geometry import Platform
from stewart_drake.core.rotations import CONVENTIONS
from stewart_drake.core.trajectory import Trajectory
from stewart_drake.design.hydraulic import HydraulicParameters
from stewart_drake.design.payload import with_payload
from stewart_drake.design.screw import ScrewParameters
from stewart_drake.errors import MachineError
from stewart_drake.fixedpoint.generic import TRIG_MODES, QFormat

LAWS = ("fixed", "float")
# controller.gains as a word: today's design for the platform, or the tuner's gains (``control.tuning``)
GAIN_WORDS = ("design", "tune")
LATENCIES = ("sample", "computation", "none")
ENGINES = ("c", "python")

MOTION_WORDS = ("seed", "rotating")
PIL_TARGETS = ("qemu", "qemu:semihosting", "serial:PATH")
PIL_FAULTS = ("drop", "corrupt", "delay", "duplicate")
PIL_REACTIONS = ("hold", "stop")
PIL_FAULT_RULE = "KIND:RATE (0 < RATE < 1 a tick) or KIND:@K[,K...] (ticks, from 1), KIND one of " + ", ".join(
    PIL_FAULTS
)


def _fmt(v) -> str:
    return f"{v:g}" if isinstance(v, float) else str(v)


def _number(path: str, value, rule: str, ok) -> None:
    """``MachineError`` unless ``value`` is a finite real number with ``ok(value)``."""
    good = isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool)
    if not (good and math.isfinite(value) and ok(value)):
        raise MachineError(MachineError.RANGE.format(path=path, rule=rule, value=_fmt(value)))


def _word(path: str, value, valid) -> None:
    if value not in valid:
        raise MachineError(MachineError.RANGE.format(path=path, rule="one of " + ", ".join(valid), value=value))


@dataclass(frozen=True)
class FirmwareFormat:
    """The number format of the fixed-point IK in the firmware and the loop: ``word_bits`` (signed words,
    8..31), ``length_lsb`` (m per LSB of a length word), ``trig`` (``tfr16``: the DSP library, 16-bit
    words only; ``exact``: correctly rounded) and the angle ``convention`` of the pose words. The defaults
    are the DSP's: 16-bit words, 1 mm, tfr16, utn."""

    word_bits: int = 16
    length_lsb: float = 1e-3
    trig: str = "tfr16"
    convention: str = "utn"

    def __post_init__(self):
        wb = self.word_bits
        if not (isinstance(wb, (int, np.integer)) and not isinstance(wb, bool) and 8 <= wb <= 31):
            raise MachineError(MachineError.RANGE.format(path="firmware.word_bits", rule="an integer 8..31", value=wb))
        _number("firmware.length_lsb", self.length_lsb, "> 0 m", lambda v: v > 0)
        _word("firmware.trig", self.trig, TRIG_MODES)
        _word("firmware.convention", self.convention, CONVENTIONS)
        if self.trig == "tfr16" and wb != 16:
            raise MachineError(
                MachineError.RANGE.format(
                    path="firmware.word_bits", rule="16 with trig tfr16 (use trig exact)", value=wb
                )
            )

    def qformat(self) -> QFormat:
        """The IK's ``QFormat``."""
        return QFormat(int(self.word_bits), float(self.length_lsb), self.trig)


@dataclass(frozen=True)
class Gains:
    """Explicit leg PID gains (SI): ``kp`` N/m, ``ki`` N/(m·s), ``kd`` and ``kv`` N·s/m."""

    kp: float
    ki: float
    kd: float
    kv: float

    def __post_init__(self):
        for name in ("kp", "ki", "kd", "kv"):
            _number(f"controller.gains.{name}", getattr(self, name), ">= 0", lambda v: v >= 0)


@dataclass(frozen=True)
class ControllerSpec:
    """The controller: ``law`` (``fixed``: the DSP's fixed-point law; ``float``: its float twin), sample
    ``period`` (s), ``latency`` (``sample``, ``computation`` or ``none``), ``gains`` (``"design"``: designed
    for the platform over the run's poses; ``"tune"``: chosen by ``control.tuning`` at plan time to meet the
    minimum margins over the workspace box's grid; or explicit ``Gains``), ``gain_scale`` (a factor on the designed
    gains), ``feedforward`` (the model-based force feed-forward) and ``engine`` (``c``, ``python`` or None:
    ``c`` where a compiler is found)."""

    law: str = "fixed"
    period: float = 1e-3
    latency: str = "sample"
    gains: str | Gains = "design"
    gain_scale: float = 1.0
    feedforward: bool = True
    engine: str | None = None

    def __post_init__(self):
        _word("controller.law", self.law, LAWS)
        _number("controller.period", self.period, "> 0 s", lambda v: v > 0)
        _word("controller.latency", self.latency, LATENCIES)
        if not (self.gains in GAIN_WORDS or isinstance(self.gains, Gains)):
            raise MachineError(
                MachineError.RANGE.format(
                    path="controller.gains", rule="design, tune or {kp, ki, kd, kv}", value=self.gains
                )
            )
        _number("controller.gain_scale", self.gain_scale, "> 0", lambda v: v > 0)
        if not isinstance(self.feedforward, bool):
            raise MachineError(
                MachineError.RANGE.format(path="controller.feedforward", rule="true or false", value=self.feedforward)
            )
        if self.engine is not None:
            _word("controller.engine", self.engine, ENGINES)


@dataclass(frozen=True)
class SensorSpec:
    """The leg-length sensors: ``resolution`` (m per count; the controller sees whole counts) and ``noise``
    (σ of white Gaussian noise on each reading, m)."""

    resolution: float = 1e-5
    noise: float = 0.0

    def __post_init__(self):
        _number("sensors.resolution", self.resolution, "> 0 m", lambda v: v > 0)
        _number("sensors.noise", self.noise, ">= 0 m", lambda v: v >= 0)


# the screw actuator's fields (``control.screw.ScrewParameters``; None: its default) -> (rule, check)
SCREW_FIELDS = {
    "lead": ("> 0 m", lambda v: v > 0),
    "torque_constant": ("> 0 N·m/A", lambda v: v > 0),
    "rotor_inertia": (">= 0 kg·m²", lambda v: v >= 0),
    "efficiency": ("in (0, 1]", lambda v: 0 < v <= 1),
    "coulomb_friction": (">= 0 N", lambda v: v >= 0),
    "viscous_friction": (">= 0 N·s/m", lambda v: v >= 0),
    "max_current": ("> 0 A", lambda v: v > 0),
    "rated_current": ("> 0 A", lambda v: v > 0),
    "max_motor_speed": ("> 0 rad/s", lambda v: v > 0),
    "current_time_constant": (">= 0 s", lambda v: v >= 0),
    "winding_resistance": (">= 0 Ω", lambda v: v >= 0),
    "encoder_counts": ("an integer >= 1 per revolution", lambda v: v >= 1 and float(v).is_integer()),
}
# the hydraulic cylinder's fields (``control.hydraulic.HydraulicParameters``; None: its default) -> (rule, check)
HYDRAULIC_FIELDS = {
    "piston_area": ("> 0 m²", lambda v: v > 0),
    "rod_area": ("> 0 m²", lambda v: v > 0),
    "dead_volume": ("> 0 m³", lambda v: v > 0),
    "bulk_modulus": ("> 0 Pa", lambda v: v > 0),
    "supply_pressure": ("> 0 Pa", lambda v: v > 0),
    "return_pressure": (">= 0 Pa", lambda v: v >= 0),
    "valve_flow_gain": ("> 0 m³/(s·√Pa)", lambda v: v > 0),
    "valve_time_constant": ("> 0 s", lambda v: v > 0),
    "leakage": (">= 0 m³/(s·Pa)", lambda v: v >= 0),
    "force_gain": ("> 0 per N", lambda v: v > 0),
}
MODEL_FIELDS = {"lag": {}, "screw": SCREW_FIELDS, "hydraulic": HYDRAULIC_FIELDS}
ACTUATOR_MODELS = tuple(MODEL_FIELDS)


@dataclass(frozen=True)
class ActuatorSpec:
    """The leg actuators: ``model`` (``lag``: a first-order lag ``time_constant`` s (0: none) and a force
    limit; ``screw``: an electric motor on a screw, ``control.screw``, with the fields of ``SCREW_FIELDS``;
    ``hydraulic``: a servo valve and cylinder, ``control.hydraulic``, with the fields of ``HYDRAULIC_FIELDS``;
    each of those None for its default, sized from the force limit) and the force limit ``max_force`` (N; None:
    the platform's ``legs.max_force``). A model's fields are refused with another model."""

    time_constant: float = 2e-3
    max_force: float | None = None
    model: str = "lag"
    lead: float | None = None
    torque_constant: float | None = None
    rotor_inertia: float | None = None
    efficiency: float | None = None
    coulomb_friction: float | None = None
    viscous_friction: float | None = None
    max_current: float | None = None
    rated_current: float | None = None
    max_motor_speed: float | None = None
    current_time_constant: float | None = None
    winding_resistance: float | None = None
    encoder_counts: int | None = None
    piston_area: float | None = None
    rod_area: float | None = None
    dead_volume: float | None = None
    bulk_modulus: float | None = None
    supply_pressure: float | None = None
    return_pressure: float | None = None
    valve_flow_gain: float | None = None
    valve_time_constant: float | None = None
    leakage: float | None = None
    force_gain: float | None = None

    def __post_init__(self):
        _number("actuators.time_constant", self.time_constant, ">= 0 s", lambda v: v >= 0)
        if self.max_force is not None:
            _number("actuators.max_force", self.max_force, "> 0 N", lambda v: v > 0)
        _word("actuators.model", self.model, ACTUATOR_MODELS)
        for model, checks in MODEL_FIELDS.items():
            for name, (rule, ok) in checks.items():
                value = getattr(self, name)
                if value is None:
                    continue
                if self.model != model:
                    rule = f"left out unless actuators.model is {model}"
                    raise MachineError(MachineError.RANGE.format(path=f"actuators.{name}", rule=rule, value=value))
                _number(f"actuators.{name}", value, rule, ok)

    def screw(self, platform_max_force: float) -> ScrewParameters:
        """The screw's parameters, the defaults sized for ``max_force`` (else ``platform_max_force``) N."""
        given = {name: getattr(self, name) for name in SCREW_FIELDS}
        if given["encoder_counts"] is not None:
            given["encoder_counts"] = int(given["encoder_counts"])
        return ScrewParameters.defaults(self.max_force or float(platform_max_force), **given)

    def hydraulic(self, platform: Platform) -> HydraulicParameters:
        """The cylinder's parameters, the defaults sized for ``max_force`` (else the legs') N, the platform's
        stroke and its legs' ``max_speed`` (m/s)."""
        given = {name: getattr(self, name) for name in HYDRAULIC_FIELDS}
        force = self.max_force or float(platform.legs.max_force)
        speed = platform.legs.max_speed
        return HydraulicParameters.defaults(force, platform.L_max - platform.L_min, speed, **given)


@dataclass(frozen=True)
class PayloadSpec:
    """A point mass ``mass`` (kg) fixed to the plate at ``position`` (3,) m in the plate frame (z >= 0)."""

    mass: float = 0.0
    position: tuple = (0.0, 0.0, 0.0)

    def __post_init__(self):
        _number("payload.mass", self.mass, ">= 0 kg", lambda v: v >= 0)
        pos = tuple(float(v) for v in np.asarray(self.position, dtype=float).reshape(-1))
        if len(pos) != 3 or not all(math.isfinite(v) for v in pos):
            raise MachineError(
                MachineError.RANGE.format(path="payload.position", rule="three finite numbers, m", value=self.position)
            )
        if pos[2] < 0:
            raise MachineError(
                MachineError.RANGE.format(path="payload.position", rule="at z >= 0 (on the plate)", value=list(pos))
            )
        object.__setattr__(self, "position", pos)


@dataclass(frozen=True)
class RunSpec:
    """How one run is simulated: ``duration`` (s; None: the motion's, else 1 s), ``plant_step`` (s; None:
    the period, at most 1 ms), ``integrator`` (None: the default) and ``fit`` (move and scale the motion to
    the platform's home height and stroke) and ``seed`` (of the run's random processes: sensor noise)."""

    duration: float | None = None
    plant_step: float | None = None
    integrator: str | None = None
    fit: bool = False
    seed: int = 0

    def __post_init__(self):
        if self.duration is not None:
            _number("run.duration", self.duration, "> 0 s", lambda v: v > 0)
        if self.plant_step is not None:
            _number("run.plant_step", self.plant_step, "> 0 s", lambda v: v > 0)
        if not isinstance(self.fit, bool):
            raise MachineError(MachineError.RANGE.format(path="run.fit", rule="true or false", value=self.fit))
        if not (isinstance(self.seed, (int, np.integer)) and not isinstance(self.seed, bool) and self.seed >= 0):
            raise MachineError(MachineError.RANGE.format(path="run.seed", rule="an integer >= 0", value=self.seed))


@dataclass(frozen=True)
class PilSpec:
    """Processor in the loop: ``target`` (None: the tick runs on the host; ``qemu``: the firmware built for the
    Cortex-M4 in QEMU's MPS2 AN386, its link on the board's UART; ``qemu:semihosting``: the same with the link on
    the semihosting console, a frame a call; ``serial:PATH``: a board on the serial port PATH) computes each tick
    over the link (``firmware.link``); ``fault`` injects link faults (``drop``, ``corrupt``, ``delay``,
    ``duplicate``) at a seeded rate a tick (``drop:0.01``, seeded by ``run.seed``) or at given ticks
    (``corrupt:@10,200``, counted from 1); ``on_fault``: the controller's reaction to a tick without a command,
    ``hold`` (keep the last command) or ``stop`` (zero force from then on: the run fails); ``timeout`` (s): how
    long the host waits for a tick's command (a lost frame costs that)."""

    target: str | None = None
    fault: str | None = None
    on_fault: str = "hold"
    timeout: float = 5.0

    def __post_init__(self):
        t = self.target
        if t is not None and not (t in PIL_TARGETS[:2] or (t.startswith("serial:") and len(t) > len("serial:"))):
            rule = "one of " + ", ".join(PIL_TARGETS)
            raise MachineError(MachineError.RANGE.format(path="pil.target", rule=rule, value=t))
        if self.fault is not None:
            self.fault_plan()
        _word("pil.on_fault", self.on_fault, PIL_REACTIONS)
        _number("pil.timeout", self.timeout, "> 0 s", lambda v: v > 0)

    def fault_plan(self) -> tuple[str, float | None, tuple]:
        """``(kind, rate a tick or None, ticks counted from 1)`` of ``fault`` (``MachineError`` naming ``pil.fault``)."""
        kind, _, arg = str(self.fault).partition(":")
        try:
            if kind not in PIL_FAULTS or not arg:
                raise ValueError(kind)  # the one message below
            if arg.startswith("@"):
                ticks = tuple(sorted({int(w) for w in arg[1:].split(",")}))
                if ticks[0] < 1:
                    raise ValueError(arg)  # the one message below
                return kind, None, ticks
            rate = float(arg)
            if not 0 < rate < 1:
                raise ValueError(arg)  # the one message below
            return kind, rate, ()
        except ValueError:
            raise MachineError(
                MachineError.RANGE.format(path="pil.fault", rule=PIL_FAULT_RULE, value=self.fault)
            ) from None


def check_motion(path: str, motion) -> None:
    """``MachineError`` unless ``motion`` is ``seed``, ``rotating``, a ``.csv`` or ``.stw`` path or a
    ``Trajectory``."""
    if isinstance(motion, Trajectory):
        return
    s = str(motion)
    if not (s in MOTION_WORDS or s.lower().endswith((".csv", ".stw"))):
        raise MachineError(MachineError.MOTION.format(path=path, value=s))


@dataclass(frozen=True)
class Machine:
    """A machine and how it runs. ``platform``: the ``Platform`` as written (``loaded_platform`` adds the
    payload); ``motions``: the references it runs (``seed``, ``rotating``, CSV or ``.stw`` paths, or
    ``Trajectory`` objects), the first is the default; ``requirements`` and ``calibration``: paths or None;
    ``platform_source``: the preset name or file it came from, if any."""

    platform: Platform
    actuators: ActuatorSpec = field(default_factory=ActuatorSpec)
    sensors: SensorSpec = field(default_factory=SensorSpec)
    controller: ControllerSpec = field(default_factory=ControllerSpec)
    firmware: FirmwareFormat = field(default_factory=FirmwareFormat)
    motions: tuple = ("seed",)
    requirements: str | None = None
    calibration: str | None = None
    payload: PayloadSpec = field(default_factory=PayloadSpec)
    run: RunSpec = field(default_factory=RunSpec)
    pil: PilSpec = field(default_factory=PilSpec)
    platform_source: str | None = None

    def __post_init__(self):
        if not isinstance(self.platform, Platform):
            raise MachineError(
                MachineError.RANGE.format(
                    path="platform",
                    rule="a Platform (load_machine reads names and files)",
                    value=type(self.platform).__name__,
                )
            )
        motions = (self.motions,) if isinstance(self.motions, (str, Trajectory)) else tuple(self.motions)
        if not motions:
            raise MachineError(MachineError.RANGE.format(path="motions", rule="at least one motion", value="[]"))
        for i, m in enumerate(motions):
            check_motion(f"motions item {i + 1}", m)
        object.__setattr__(self, "motions", motions)

    def check_loop_format(self) -> None:
        """Refuse a number format whose length words cannot hold the stroke's end: a closed loop with it would
        clamp its set-points there without a word (``MachineError`` naming ``firmware.length_lsb``). A
        certificate of such a format is another matter: it finds the clamp and says so."""
        longest, fmt = float(self.platform.stroke[1]), self.firmware
        if fmt.qformat().range_m < longest:
            raise MachineError(
                MachineError.WORD_RANGE.format(
                    bits=fmt.word_bits,
                    lsb=_fmt(fmt.length_lsb),
                    range=_fmt(fmt.qformat().range_m),
                    longest=_fmt(longest),
                )
            )

    @property
    def loaded_platform(self) -> Platform:
        """The platform whose plate carries ``payload`` (the plant's and the gain design's)."""
        p = self.payload
        return with_payload(self.platform, p.mass, p.position, option="payload") if p.mass else self.platform

    @property
    def motion(self):
        """The default motion (the first of ``motions``)."""
        return self.motions[0]

    def replace(self, **overrides) -> Machine:
        """A copy with fields replaced by spec path (``{"controller.period": 5e-4}``; values in SI or
        quantity text as ``spec.load.apply_overrides`` reads them)."""
        # deferred: load imports this module (the grammar of overrides lives with the loader)
        from stewart_drake.spec.load import apply_overrides

        return apply_overrides(self, overrides)

    def to_yaml(self) -> str:
        """The machine as YAML (SI numbers, the platform inline): ``load_machine`` reads it back."""
        # deferred: load imports this module
        from stewart_drake.spec.load import machine_yaml

        return machine_yaml(self)


SECTIONS = {
    "actuators": ActuatorSpec,
    "sensors": SensorSpec,
    "controller": ControllerSpec,
    "firmware": FirmwareFormat,
    "payload": PayloadSpec,
    "run": RunSpec,
    "pil": PilSpec,
}
# spec path -> dimension for the quantity grammar ("bool", "word", "int", "vector", "gains", "optional ..." too)
FIELDS = {
    "actuators.time_constant": "time",
    "actuators.max_force": "force?",
    "actuators.model": ("word", ACTUATOR_MODELS),
    "actuators.lead": "length?",
    "actuators.torque_constant": "ratio?",
    "actuators.rotor_inertia": "ratio?",
    "actuators.efficiency": "ratio?",
    "actuators.coulomb_friction": "force?",
    "actuators.viscous_friction": "ratio?",
    "actuators.max_current": "ratio?",
    "actuators.rated_current": "ratio?",
    "actuators.max_motor_speed": "ratio?",
    "actuators.current_time_constant": "time?",
    "actuators.winding_resistance": "ratio?",
    "actuators.encoder_counts": "int?",
    "actuators.piston_area": "ratio?",
    "actuators.rod_area": "ratio?",
    "actuators.dead_volume": "ratio?",
    "actuators.bulk_modulus": "pressure?",
    "actuators.supply_pressure": "pressure?",
    "actuators.return_pressure": "pressure?",
    "actuators.valve_flow_gain": "ratio?",
    "actuators.valve_time_constant": "time?",
    "actuators.leakage": "ratio?",
    "actuators.force_gain": "ratio?",
    "sensors.resolution": "length",
    "sensors.noise": "length",
    "controller.law": ("word", LAWS),
    "controller.period": "time",
    "controller.latency": ("word", LATENCIES),
    "controller.gains": "gains",
    "controller.gain_scale": "ratio",
    "controller.feedforward": "bool",
    "controller.engine": ("word?", ENGINES),
    "firmware.word_bits": "int",
    "firmware.length_lsb": "length",
    "firmware.trig": ("word", TRIG_MODES),
    "firmware.convention": ("word", CONVENTIONS),
    "payload.mass": "mass",
    "payload.position": "length3",
    "run.duration": "time?",
    "run.plant_step": "time?",
    "run.integrator": ("word?", ("cenic-fixed", "cenic", "sap")),
    "run.fit": "bool",
    "run.seed": "int",
    "pil.target": "text?",
    "pil.fault": "text?",
    "pil.on_fault": ("word", PIL_REACTIONS),
    "pil.timeout": "time",
}
