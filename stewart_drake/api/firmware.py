"""The firmware: ``generate`` writes the C firmware (IK + controller tick) for a platform; ``check`` compares a
C firmware with the bit-exact emulation. ``sd.firmware.generate(...)``, ``sd.firmware.check(...)``."""

from __future__ import annotations

import json
import math
import shutil
import tempfile
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

from stewart_drake.api.result import Result
from stewart_drake.control import ControllerConfig, DspTiming
from stewart_drake.core.geometry import Platform
from stewart_drake.core.trajectory import Trajectory, design_poses, get_trajectory
from stewart_drake.errors import CertifyError, MachineError, OptionError, StewartError, UsageError
from stewart_drake.firmware.certify.box import parse_box
from stewart_drake.firmware.certify.certificate import Certificate
from stewart_drake.firmware.certify.certificate import certify as certify_ik
from stewart_drake.firmware.certify.optimize import OptimizeResult as CertifiedFormats
from stewart_drake.firmware.certify.optimize import optimize as choose_formats
from stewart_drake.firmware.certify.optimize import parse_budget
from stewart_drake.firmware.certify.search import MAX_CELLS
from stewart_drake.firmware.certify.tick import TickCertificate
from stewart_drake.firmware.certify.tick import certify_tick as certify_tick_words
from stewart_drake.firmware.fingerprint import (
    DESIGN_POSES,
    motion_record,
    platform_hash,
    poses_hash,
    read_fingerprint,
    recorded_design_poses,
    resolve_options,
    stamp,
)
from stewart_drake.firmware.generate import generate as generate_sources
from stewart_drake.firmware.module import check_source, compile_generated
from stewart_drake.firmware.target_build import build_target, check_target
from stewart_drake.fixedpoint.generic import QFormat
from stewart_drake.spec import Machine, apply_overrides, load_machine
from stewart_drake.system.c_build import compiler_by_name, compilers
from stewart_drake.system.isolate import FIRMWARE_TIME_LIMIT_S, check_time_limit, run_isolated
from stewart_drake.system.output_folder import OutputFolder, atomic_folder

__all__ = [
    "generate",
    "build",
    "check",
    "certify",
    "certify_tick",
    "optimize",
    "GenerateResult",
    "BuildResult",
    "CheckResult",
    "CertifyResult",
    "TickResult",
    "OptimizeResult",
]


# The firmware format's keywords (``**format`` of every function below) -> the spec path each sets. ``rate``
# (Hz) sets ``controller.period`` to ``1 / rate``.
FORMAT_PATHS = {
    "word_bits": "firmware.word_bits",
    "length_lsb": "firmware.length_lsb",
    "trig": "firmware.trig",
    "convention": "firmware.convention",
    "rate": "controller.period",
    "sensor_resolution": "sensors.resolution",
}
MAX_RATE_HZ = 1e6  # a faster loop is a unit mistake (a period typed as a rate); MachineError.FORMAT_RATE says it
MAX_C_WORD_BITS = 16  # the generated C holds words in 16-bit data words


def controller_config(platform: Platform, fmt: dict, trajectory=None, poses=None) -> ControllerConfig:
    """The firmware's number format, timing and gains for ``fmt`` (``machine_format``'s, checked), designed over
    ``trajectory``'s poses, else over ``poses`` ``(n, 6)`` SI, else home."""
    qformat = QFormat(fmt["word_bits"], fmt["length_lsb"], fmt["trig"])
    timing = DspTiming(
        sample_period=1.0 / fmt["rate"],
        sensor_resolution=fmt["sensor_resolution"],
        command_range=float(platform.legs.max_force),
    ).check()
    poses = poses if trajectory is None else design_poses(get_trajectory(trajectory))
    return ControllerConfig.for_platform(platform, timing, poses=poses, ik_format=qformat, convention=fmt["convention"])


def format_keywords(format: dict) -> dict:
    """The keywords of ``format`` that are given (not None); a ``MachineError`` naming one that is not a
    firmware format keyword (``FORMAT_PATHS``) and the valid ones."""
    for name in format:
        if name not in FORMAT_PATHS:
            raise MachineError(MachineError.FORMAT_KEYWORD.format(name=name, valid=", ".join(FORMAT_PATHS)))
    return {k: v for k, v in format.items() if v is not None}


def machine_format(platform, format: dict) -> tuple[Machine, dict]:
    """``(machine, format)``: the machine of ``platform`` (a ``Machine``, a ``Platform``, a preset name or a
    platform or machine file) with the firmware format keywords of ``format`` applied to their spec paths
    (``FORMAT_PATHS``; checked as the machine's fields are, errors naming the path), and the resolved
    ``word_bits``, ``length_lsb`` (m), ``trig``, ``convention``, ``rate`` (Hz) and ``sensor_resolution`` (m):
    each given, else the machine's (a platform's machine has the DSP's defaults).

    Raises:
        MachineError, QuantityError: an unknown keyword, a value out of its field's range, a rate that is not
            in (0, 1e6] Hz, words wider than the generated C holds (16 bits).
    """
    given = format_keywords(format)
    rate = given.get("rate")
    if rate is not None:
        number = isinstance(rate, (int, float)) and not isinstance(rate, bool)
        if not (number and math.isfinite(rate) and 0 < rate <= MAX_RATE_HZ):
            shown = f"{rate:g}" if number else repr(rate)
            raise MachineError(MachineError.FORMAT_RATE.format(value=shown))
    overrides = {FORMAT_PATHS[k]: 1.0 / rate if k == "rate" else v for k, v in given.items()}
    machine = apply_overrides(load_machine(platform), overrides)
    fw = machine.firmware
    if fw.word_bits > MAX_C_WORD_BITS:
        rule = "in 8..16 for generated C (16-bit data words and narrower)"
        value = given.get("word_bits", fw.word_bits)
        raise MachineError(MachineError.RANGE.format(path="firmware.word_bits", rule=rule, value=value))
    resolved = dict(
        word_bits=int(fw.word_bits),
        length_lsb=float(fw.length_lsb),
        trig=fw.trig,
        convention=fw.convention,
        rate=rate if rate is not None else 1.0 / machine.controller.period,
        sensor_resolution=float(machine.sensors.resolution),
    )
    return machine, resolved


def _options(platform, format: dict, trajectory, platform_source):
    """The module's options (``format``: the firmware format keywords, ``machine_format``), checked, and its gains
    designed: (platform, config, options to record)."""
    machine, f = machine_format(platform, format)
    platform = machine.platform
    platform_source = machine.platform_source if platform_source is None else platform_source
    config = controller_config(machine.loaded_platform, f, trajectory)
    options = dict(
        platform=platform.name if platform_source is None else str(platform_source),
        **f,
        trajectory=trajectory,
        platform_hash=platform_hash(platform),
    )
    return platform, config, options


def _module(platform, config, options: dict):
    """The generated module (``GeneratedFirmware``) with ``options`` recorded in its files."""
    g = generate_sources(platform, config)
    trajectory = options["trajectory"]
    if isinstance(trajectory, Trajectory):  # no name `check` can look up: the design poses beside the C
        options = dict(options)
        options["trajectory"], g.files[DESIGN_POSES] = motion_record(trajectory.name, design_poses(trajectory))
    g.files = stamp(g.files, options)  # the options, for `firmware check`
    return g


@dataclass(repr=False)
class GenerateResult(Result):
    """The generated firmware (``firmware.generate``).

    Attributes:
        summary: platform, output folder, number format, rate, gains, files (name, bytes), cycle estimates
            of ``sd_ik`` and ``sd_tick``, and the compilers that compile-checked it.
        files: the paths written.
        config: the controller's number format, timing and gains.
    """

    summary: dict
    files: list
    config: ControllerConfig

    def _fields(self) -> dict:
        return self.summary


def generate(
    platform: Platform | Machine,
    out: str | Path,
    *,
    trajectory: str | Trajectory | None = None,
    compile: bool = True,
    on_note: Callable[[str], None] | None = None,
    platform_source: str | None = None,
    **format,
) -> GenerateResult:
    """Generate the C firmware (``sd_firmware.h``, ``sd_firmware.c``, README) for a platform into a folder.

    The number format, rate and sensor resolution are the machine's (``firmware``, ``1 / controller.period``,
    ``sensors.resolution``; for a ``Platform``, those of a machine with defaults: the DSP's 16-bit words,
    1 mm, tfr16, utn, 1 kHz, 10 µm); a keyword given replaces its value.

    Args:
        platform: the platform, or a ``Machine`` (its gains are designed with its payload on the plate).
        out: the output folder: new, empty, or holding only files this command wrote (the manifest records each
            with its sha256; another command's file or a changed one is refused, never replaced).
        trajectory: design the gains over this reference's poses (default: home only). A `Trajectory` (no
            name ``check`` can look up) also writes its design poses to ``sd_design_poses.json`` beside the C,
            which ``check`` reads (their hash is recorded in the fingerprint).
        compile: compile-check the C with every C compiler found.
        on_note: called with a note (no compiler found).
        platform_source: how the platform is named (a preset name or a YAML path), recorded with the other
            options in the files (a fingerprint ``check`` reads back); default the platform's name.
        **format: the firmware format keywords, each replacing the machine's value: ``word_bits`` (data word
            width, 8..16: ``firmware.word_bits``), ``length_lsb`` (metres per length LSB: ``firmware.length_lsb``),
            ``trig`` (``"tfr16"``: the DSP's, 16-bit words only; ``"exact"``: ``firmware.trig``), ``convention``
            (Euler convention of the pose angles: ``firmware.convention``), ``rate`` (controller rate, Hz:
            ``1 / controller.period``), ``sensor_resolution`` (leg sensor, m per count: ``sensors.resolution``).

    Returns:
        The summary and the files written.

    Raises:
        StewartError: bad options, or an output folder that holds other files.
    """
    platform, config, options = _options(platform, format, trajectory, platform_source)
    rate = options["rate"]
    folder = OutputFolder(out)  # the policy, before any work: new, empty, or this command's own verified files
    out = Path(out)
    g = _module(platform, config, options)
    compiled = []
    if compile:
        for cc in compilers():
            # the files written, as a target compiles them: -std=c99 -Wall -Wextra -Werror -pedantic
            compile_generated(g, compiler=cc, constants=True)
            compiled.append(cc.name)
        if not compiled and on_note:
            on_note("no C compiler found; the module was not compile-checked")
    with atomic_folder(folder) as tmp:
        written = g.write(tmp)
    ik = g.ik_cycles
    summary = {
        "platform": platform.name,
        "out": str(out),
        "format": {
            "word_bits": config.ik_format.word_bits,
            "length_lsb_m": config.ik_format.length_lsb,
            "trig": config.ik_format.trig,
            "convention": config.convention,
        },
        "rate_hz": rate,
        "gains": {k: getattr(config.gains, k) for k in ("kp", "ki", "kd", "kv")},
        "files": [{"name": p.name, "bytes": (out / p.name).stat().st_size} for p in written],
        "ik_cycles": round(ik.cycles),
        "ik_us": round(ik.microseconds, 2),
        "tick_cycles": round(g.tick_cycles),
        "tick_us": round(g.tick_cycles / config.timing.clock_hz * 1e6, 2),
        "compiled_with": compiled,
    }
    return GenerateResult(summary, [out / p.name for p in written], config)


@dataclass(repr=False)
class BuildResult(Result):
    """The generated firmware built for a target (``firmware.build``).

    Attributes:
        summary: platform, target and board, output folder, the files written, the bytes of code (flash) and of
            data (``data_bytes`` initialised, ``bss_bytes`` zeroed: RAM), and the worst-case stack depth in
            bytes (``stack_bytes``; None: unbounded) with its call path from the reset handler.
        files: the paths written.
    """

    summary: dict
    files: list

    def _fields(self) -> dict:
        return self.summary


BUILD_FILES = ("sd_pil.elf", "sd_pil.map", "sd_pil.su", "build.json")


def build(
    platform: Platform | Machine,
    out: str | Path,
    *,
    target: str = "cortex-m4",
    trajectory: str | Trajectory | None = None,
    platform_source: str | None = None,
    **format,
) -> BuildResult:
    """Build the generated firmware (``sd_ik``, ``sd_tick``, ``sd_fk``) with the PIL runtime for a
    microcontroller: an ELF that boots on the target's board and runs ``sd_tick`` for each sensor frame of the
    link (``firmware.link``), its linker map, the per-function stack usage (``sd_pil.su``) and ``build.json``.

    The options are those of ``generate``; the module is compiled with the strict flags (``-Werror``).

    Args:
        platform: the platform, or a ``Machine``.
        out: the output folder: new, empty, or holding only files this command wrote.
        target: ``"cortex-m4"`` (the Arm MPS2+ AN386 board, as QEMU's ``mps2-an386`` models it, the link on its
            UART), ``"cortex-m4-semihosting"`` (the same board, the link on the semihosting console: QEMU or a
            debug probe) or ``"stm32f405"`` (an STM32F405/F407 board, the link on USART2).
        trajectory: design the gains over this reference's poses (as ``generate``).
        platform_source: how the platform is named in the recorded options (as ``generate``).
        **format: the firmware format keywords of ``generate``.

    Returns:
        The summary (sizes, stack depth) and the files written.

    Raises:
        StewartError: bad options, an unknown target, no cross compiler, a failing build, or an output folder
            that holds other files.
    """
    check_target(target)
    platform, config, options = _options(platform, format, trajectory, platform_source)
    folder = OutputFolder(out)  # the policy, before any work
    out = Path(out)
    g = _module(platform, config, options)
    with tempfile.TemporaryDirectory(prefix="sd-build-") as work:
        b = build_target(g.files, Path(work), target)
        summary = {"platform": platform.name, "out": str(out), **b.to_dict()}
        stack_usage = "".join(p.read_text() for p in sorted(Path(work).glob("*.su")))
        with atomic_folder(folder) as tmp:
            shutil.copyfile(b.elf, tmp / BUILD_FILES[0])
            shutil.copyfile(b.map, tmp / BUILD_FILES[1])
            (tmp / BUILD_FILES[2]).write_text(stack_usage)
            (tmp / BUILD_FILES[3]).write_text(json.dumps(summary, indent=2) + "\n")
    summary["files"] = list(BUILD_FILES)
    return BuildResult(summary, [out / n for n in BUILD_FILES])


@dataclass(repr=False)
class CheckResult(Result):
    """A C firmware compared with the emulation (``firmware.check``).

    Attributes:
        ik: ``sd_ik`` over workspace poses: poses, differing poses, worst difference (LSB), the first
            difference.
        tick: ``sd_tick`` over a recorded closed-loop stream (None when the firmware has no ``sd_tick``).
        identical: the firmware computes what the emulation computes, bit for bit.
    """

    ik: dict
    tick: dict | None
    identical: bool
    report: dict

    def _fields(self) -> dict:
        return self.report


def check(
    path: str | Path,
    platform: Machine | Platform | str | Path | None = None,
    *,
    poses: int = 100_000,
    seed: int = 0,
    trace: bool = False,
    duration: float = 0.5,
    compiler: str | None = None,
    time_limit: float = FIRMWARE_TIME_LIMIT_S,
    trajectory: str | Trajectory | None = None,
    **format,
) -> CheckResult:
    """Compile a C firmware against the header generated for the platform and compare it with the bit-exact
    emulation: ``sd_ik`` over random workspace poses and ``sd_tick`` over a recorded closed-loop stream.

    The module's options default to those recorded in the file (or in the ``sd_firmware.h`` next to it) by
    ``generate`` (a fingerprint), else to ``generate``'s defaults; an option given that differs from the
    recorded one is refused, naming both (the check would compare the C with another module's emulation).

    Args:
        path: the C file (implementing ``sd_firmware.h``).
        platform: the machine or platform it was generated for (a ``Machine``, a ``Platform``, a preset name, a
            platform or machine file; default as recorded).
        poses: workspace poses compared.
        seed: random seed of the poses.
        trace: trace the first differing pose word by word.
        duration: seconds of closed loop recorded for ``sd_tick``.
        compiler: a compiler name (default the first found).
        time_limit: seconds the check may run the firmware (compiled and run in a child process: a hang,
            ``exit()`` or crash in it is one ``StewartError`` naming the file).
        trajectory: the reference the gains were designed over (as generated; a module generated from a
            `Trajectory` reads its design poses from the ``sd_design_poses.json`` beside it, or takes that
            same `Trajectory` here).
        **format: the firmware format keywords (``generate``'s: ``word_bits``, ``length_lsb``, ``trig``,
            ``convention``, ``rate``, ``sensor_resolution``), as generated: each defaults to the recorded one.

    Returns:
        The comparison; ``identical`` when bit-exact.

    Raises:
        StewartError: a missing or unreadable file, a firmware that does not compile, bad options, an option
            that differs from the one recorded in the file.
    """
    check_source(path)
    limit = check_time_limit(time_limit)
    given = dict(
        format_keywords(format),
        platform=None,  # compared below by the platform's name (a preset, a path or an API platform's name)
        trajectory=trajectory if trajectory is None or isinstance(trajectory, str) else None,
    )
    o, mismatch = resolve_options(given, path)
    if mismatch:  # the check would compare the C with another module's emulation
        raise UsageError(UsageError.FIRMWARE_OPTIONS.format(file=path, mismatch=mismatch))
    rec = read_fingerprint(path)
    if platform is None:
        # a preset, a platform file or a machine file (whose payload the gains were designed with)
        platform = load_machine(o["platform"]).loaded_platform
    else:
        machine = load_machine(platform)  # a machine's payload is on the plate its gains are designed for
        platform = machine.loaded_platform
        if rec and _platform_name(rec[0]["platform"]) != machine.platform.name:
            mismatch = f"platform={machine.platform.name} here, {rec[0]['platform']} in {rec[1]}"
            raise UsageError(UsageError.FIRMWARE_OPTIONS.format(file=path, mismatch=mismatch))
    design, motion = None, o["trajectory"] if isinstance(o["trajectory"], dict) else None
    if isinstance(trajectory, Trajectory):
        o["trajectory"] = trajectory
        if motion and poses_hash(design_poses(trajectory)) != motion.get("sha256"):
            mismatch = (
                f"trajectory={trajectory.name!r} here, other design poses than {motion.get('name')!r} in {rec[1]}"
            )
            raise UsageError(UsageError.FIRMWARE_OPTIONS.format(file=path, mismatch=mismatch))
    elif motion:  # generated from a Python Trajectory: its design poses, recorded beside the C
        o["trajectory"], design = None, recorded_design_poses(motion, rec[1])
    _, f = machine_format(platform, {k: o[k] for k in FORMAT_PATHS})
    config = controller_config(platform, f, o["trajectory"], design)
    cc = compiler_by_name(compiler) if compiler else None
    # the user's code runs in a child process: a hang, an exit() or a crash is one line naming the file
    r = run_isolated(
        _check_in_child, Path(path), platform, config, poses, seed, trace, duration, cc, path=str(path), limit=limit
    )
    return CheckResult(r["ik"], r["tick"], r["identical"], r)


def _check_in_child(beat, *args) -> dict:
    """``drake.firmware_check.check_firmware(*args)``, run by ``system.isolate`` in a child process (deferred
    import: only check needs Drake, it records a closed loop; generate runs without pydrake)."""
    from stewart_drake.drake.firmware_check import check_firmware

    return check_firmware(*args)


def _platform_name(recorded: str) -> str:
    """The name of the platform a fingerprint records (a preset name, a platform or machine file's path, or an
    API platform's name)."""
    try:
        return load_machine(recorded).platform.name
    except StewartError:
        return recorded


# -- the firmware certificate ------------------------------------------------------------------------------------
@dataclass(repr=False)
class CertifyResult(Result):
    """The firmware certificate over a pose box (``firmware.certify``).

    Attributes:
        certificate: every ``sd_ik`` word's proven range and saturation, the proven bound on
            ``|L_firmware - L_float|`` per leg, a saturating witness pose if one was found.
        tick: the ``sd_tick`` words' certificate (``tick=True``), else None.
    """

    certificate: Certificate
    tick: TickCertificate | None = None

    @property
    def saturation_possible(self) -> bool:
        """Whether some arithmetic word may saturate: of ``sd_ik`` in the box (a witness, or cells left undecided)
        or, when certified, of ``sd_tick`` within its bounds (its rails excluded)."""
        return bool(self.certificate.saturation_possible) or bool(self.tick and self.tick.saturation_possible)

    def _fields(self) -> dict:
        d = self.certificate.to_dict()
        if self.tick is not None:
            d["tick"] = self.tick.to_dict()
            d["saturation_possible"] = self.saturation_possible
        return d


@dataclass(repr=False)
class TickResult(Result):
    """The controller tick's certificate (``firmware.certify_tick``): each ``sd_tick`` word's proven range and
    saturation, and whether the anti-windup keeps the integrator inside its rails (``certificate``)."""

    certificate: TickCertificate

    def _fields(self) -> dict:
        return self.certificate.to_dict()


@dataclass(repr=False)
class OptimizeResult(Result):
    """The word formats chosen by the proof (``firmware.optimize``).

    Attributes:
        search: the chosen formats (``chosen``: None when no format meets the budget), the default format's
            and the simulation-only choice's certificates, every format tried, the generated firmware.
        out: the folder the chosen firmware was written to (None when not asked or nothing was chosen).
    """

    search: CertifiedFormats
    out: Path | None = None

    @property
    def chosen(self):
        """The chosen format and its certificate, or None when no format meets the budget."""
        return self.search.chosen

    def summary(self) -> str:
        """The comparison as text (what ``stewart-drake firmware optimize`` prints)."""
        return self.search.summary()

    def _fields(self) -> dict:
        return self.search.to_dict()


def _shown(platform) -> str:
    return str(platform) if isinstance(platform, (str, Path)) else platform.name


def certify(
    platform: str | Path | Platform | Machine,
    *,
    box: Sequence[str] | None = None,
    length_unit: str = "mm",
    angle_unit: str = "pi",
    max_cells: int | None = None,
    implementation: str = "generated",
    tick: bool = False,
    tick_error: float = 5e-3,
    tick_speed: float = 0.1,
    tick_feedforward: float = 0.0,
    trajectory: str | Trajectory | None = None,
    **format,
) -> CertifyResult:
    """Prove, over every pose of a box, each ``sd_ik`` word's range, whether it can saturate, and a bound on
    ``|L_firmware - L_float|`` per leg (interval branch and bound, memory bounded); optionally the
    ``sd_tick`` words too.

    Args:
        platform: a preset name, a platform or machine file, a ``Platform`` or a ``Machine`` (the format,
            rate and sensor resolution below default to the machine's: a platform's are the DSP's).
        box: pose box words ``KEY=LO..HI`` (KEY one of px py pz a b g, in ``length_unit``/``angle_unit``);
            keys not given keep the workspace box's range (None: the workspace box).
        length_unit: unit of px py pz in ``box``.
        angle_unit: unit of a b g in ``box`` (``"pi"``: fractions of π).
        max_cells: branch-and-bound budget, cells evaluated (default 200000).
        implementation: ``"generated"`` (the ``sd_ik`` of ``generate`` in this format) or ``"tp17"`` (the
            seed's DSP firmware; platform ``utn-kinematic``).
        tick: also certify ``sd_tick``'s words for the bounds below.
        tick_error: bound on ``|set-point - measured|``, m.
        tick_speed: bound on the legs' speed, m/s.
        tick_feedforward: bound on ``|feed-forward|``, N.
        trajectory: design the gains over this reference's poses (default: home only).
        **format: the firmware format keywords (``generate``'s: ``word_bits``, ``length_lsb``, ``trig``,
            ``convention``, ``rate``, ``sensor_resolution``), each replacing the machine's value.

    Returns:
        The certificate; ``saturation_possible`` says whether a word may saturate.

    Raises:
        StewartError: a bad box, budget or format; ``tp17`` on another platform.
    """
    machine, f = machine_format(platform, format)
    p = machine.platform
    config = controller_config(machine.loaded_platform, f, trajectory)
    pose_box = parse_box(box, p, length_unit, angle_unit)
    fmt = config.ik_format
    if implementation == "tp17":
        if p.name != "utn-kinematic":
            raise CertifyError(CertifyError.IMPLEMENTATION.format(value=_shown(platform)))
        fmt = QFormat(16, 1e-3, "tfr16")
    cells = MAX_CELLS if max_cells is None else max_cells
    cert = certify_ik(p, fmt, pose_box, config.convention, cells, length_unit, angle_unit, implementation)
    ticked = _certify_tick(config, tick_error, tick_speed, tick_feedforward) if tick else None
    return CertifyResult(cert, ticked)


def _certify_tick(config: ControllerConfig, error: float, speed: float, feedforward: float) -> TickCertificate:
    """The tick certificate after the bounds' checks (``OptionError`` naming the keyword and its SI value)."""
    for name, v in (("tick_error", error), ("tick_speed", speed), ("tick_feedforward", feedforward)):
        if not (math.isfinite(v) and v >= 0):
            raise OptionError(OptionError.AT_LEAST.format(option=name, min=0, value=f"{v:g}"))
    return certify_tick_words(config, error, speed, feedforward)


def certify_tick(
    platform: str | Path | Platform | Machine,
    *,
    tick_error: float = 5e-3,
    tick_speed: float = 0.1,
    tick_feedforward: float = 0.0,
    trajectory: str | Trajectory | None = None,
    **format,
) -> TickResult:
    """Prove the ranges of ``sd_tick``'s PID words (and whether the anti-windup keeps the integrator inside its
    rails) for stated bounds on the error, the legs' speed and the feed-forward.

    Args:
        platform: a preset name, a platform or machine file, a ``Platform`` or a ``Machine`` (the format,
            rate and sensor resolution below default to the machine's: a platform's are the DSP's).
        tick_error: bound on ``|set-point - measured|``, m.
        tick_speed: bound on the legs' speed, m/s.
        tick_feedforward: bound on ``|feed-forward|``, N.
        trajectory: design the gains over this reference's poses (default: home only).
        **format: the firmware format keywords (``generate``'s: ``word_bits``, ``length_lsb``, ``trig``,
            ``convention``, ``rate``, ``sensor_resolution``), each replacing the machine's value.

    Returns:
        The tick's certificate.

    Raises:
        StewartError: a negative or non-finite bound, a bad format.
    """
    machine, f = machine_format(platform, format)
    config = controller_config(machine.loaded_platform, f, trajectory)
    return TickResult(_certify_tick(config, tick_error, tick_speed, tick_feedforward))


def optimize(
    platform: str | Path | Platform | Machine,
    *,
    error_budget: str | float,
    objective: str = "bits",
    out: str | Path | None = None,
    box: Sequence[str] | None = None,
    length_unit: str = "mm",
    angle_unit: str = "pi",
    max_cells: int | None = None,
    trajectory: str | Trajectory | None = None,
    **format,
) -> OptimizeResult:
    """Choose the length LSB, word bits and trigonometry so that the proven ``sd_ik`` error meets a budget
    without saturation over a pose box (``objective``: fewest bits or fewest cycles), and generate that
    firmware; compared with the default format and with a simulation-only choice.

    Args:
        platform: a preset name, a platform or machine file, a ``Platform`` or a ``Machine`` (the format,
            rate and sensor resolution below default to the machine's: a platform's are the DSP's).
        error_budget: the bound to meet: metres, or text such as ``"0.5mm"``, ``"500um"``.
        objective: ``"bits"`` or ``"cycles"``.
        out: write the chosen firmware (``sd_firmware.h``/``.c``, README) into this folder.
        box: pose box words as for ``certify`` (None: the workspace box).
        length_unit: unit of px py pz in ``box``.
        angle_unit: unit of a b g in ``box``.
        max_cells: the final certificate's budget, cells evaluated (default 200000).
        trajectory: design the gains over this reference's poses (default: home only).
        **format: the firmware format keywords (``generate``'s: ``word_bits``, ``length_lsb``, ``trig``,
            ``convention``, ``rate``, ``sensor_resolution``), each replacing the machine's value: the default
            format (the comparison's baseline) and the gains' design.

    Returns:
        The chosen formats (``chosen`` None when none meets the budget) and the comparison.

    Raises:
        StewartError: a bad budget, box or format, or an output folder that holds other files.
    """
    budget = parse_budget(error_budget)
    folder = None if out is None else OutputFolder(out)
    machine, f = machine_format(platform, format)
    p = machine.platform
    config = controller_config(machine.loaded_platform, f, trajectory)
    pose_box = parse_box(box, p, length_unit, angle_unit)
    res = choose_formats(p, config, pose_box, budget, objective, MAX_CELLS if max_cells is None else max_cells)
    written = None
    if folder is not None and res.chosen is not None:
        with atomic_folder(folder) as tmp:
            res.firmware.write(tmp)
        written = folder
    return OptimizeResult(res, written)
