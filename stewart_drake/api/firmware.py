"""The firmware: ``generate`` writes the C firmware (IK + controller tick) for a platform; ``check`` compares a
C firmware with the bit-exact emulation. ``sd.firmware.generate(...)``, ``sd.firmware.check(...)``."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from stewart_drake.api.result import Result
from stewart_drake.control import ControllerConfig, DspTiming
from stewart_drake.core.c_build import compiler_by_name, compilers
from stewart_drake.core.geometry import Platform, load_platform
from stewart_drake.core.output_folder import atomic_folder
from stewart_drake.core.trajectory import Trajectory, design_poses, get_trajectory
from stewart_drake.errors import (
    OPTION_FIRMWARE_RATE,
    OPTION_FIRMWARE_TFR16,
    OPTION_FIRMWARE_WORD_BITS,
    OPTION_OUT_FOREIGN,
    OPTION_OUT_NOT_FOLDER,
    OptionError,
    OutputError,
    StewartError,
    UsageError,
)
from stewart_drake.firmware.fingerprint import DEFAULTS as FP_DEFAULTS
from stewart_drake.firmware.fingerprint import read_fingerprint, resolve_options, stamp
from stewart_drake.firmware.generate import FILES
from stewart_drake.firmware.generate import generate as generate_sources
from stewart_drake.firmware.module import check_source, compile_generated
from stewart_drake.fixedpoint.generic import QFormat

__all__ = ["generate", "check", "GenerateResult", "CheckResult"]


def controller_config(
    platform: Platform,
    word_bits: int = 16,
    length_lsb: float = 1e-3,
    trig: str = "tfr16",
    convention: str = "utn",
    rate: float = 1000.0,
    sensor_resolution: float = 1e-5,
    trajectory: str | Trajectory | None = None,
) -> ControllerConfig:
    """The firmware's number format, timing and gains (designed over ``trajectory``'s poses, else home)."""
    if not 8 <= word_bits <= 16:
        raise OptionError(OPTION_FIRMWARE_WORD_BITS.format(value=word_bits))
    if not (rate > 0 and rate <= 1e6):
        raise OptionError(OPTION_FIRMWARE_RATE.format(value=rate))
    if trig == "tfr16" and word_bits != 16:
        raise UsageError(OPTION_FIRMWARE_TFR16.format(value=word_bits))
    fmt = QFormat(word_bits, length_lsb, trig)
    timing = DspTiming(
        sample_period=1.0 / rate, sensor_resolution=sensor_resolution, command_range=float(platform.legs.max_force)
    ).check()
    poses = None if trajectory is None else design_poses(get_trajectory(trajectory))
    return ControllerConfig.for_platform(platform, timing, poses=poses, ik_format=fmt, convention=convention)


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


def check_out_folder(out: str | Path) -> Path:
    """``out`` for generated firmware: new, or a folder holding only the generator's files (exit 2 otherwise)."""
    shown, out = out, Path(out)
    if out.exists():
        if not out.is_dir():
            raise OutputError(OPTION_OUT_NOT_FOLDER.format(out=shown))
        foreign = sorted(p.name for p in out.iterdir() if p.name not in FILES)
        if foreign:
            raise OutputError(OPTION_OUT_FOREIGN.format(out=shown, names=", ".join(foreign[:3])))
    return out


def generate(
    platform: Platform,
    out: str | Path,
    *,
    word_bits: int = 16,
    length_lsb: float = 1e-3,
    trig: str = "tfr16",
    convention: str = "utn",
    rate: float = 1000.0,
    sensor_resolution: float = 1e-5,
    trajectory: str | Trajectory | None = None,
    compile: bool = True,
    on_note: Callable[[str], None] | None = None,
    platform_source: str | None = None,
) -> GenerateResult:
    """Generate the C firmware (``sd_firmware.h``, ``sd_firmware.c``, README) for a platform into a folder.

    Args:
        platform: the platform.
        out: the output folder (created; only the firmware's own files are replaced).
        word_bits: data word width, 8..16.
        length_lsb: metres per length LSB.
        trig: the trigonometry (``"tfr16"``: the DSP's; needs 16-bit words).
        convention: Euler convention of the pose angles.
        rate: controller rate, Hz.
        sensor_resolution: leg sensor, m per count.
        trajectory: design the gains over this reference's poses (default: home only).
        compile: compile-check the C with every C compiler found.
        on_note: called with a note (no compiler found).
        platform_source: how the platform is named (a preset name or a YAML path), recorded with the other
            options in the files (a fingerprint ``check`` reads back); default the platform's name.

    Returns:
        The summary and the files written.

    Raises:
        StewartError: bad options, or an output folder that holds other files.
    """
    config = controller_config(platform, word_bits, length_lsb, trig, convention, rate, sensor_resolution, trajectory)
    out = check_out_folder(out)
    g = generate_sources(platform, config)
    options = dict(
        platform=platform.name if platform_source is None else str(platform_source),
        word_bits=word_bits,
        length_lsb=length_lsb,
        trig=trig,
        convention=convention,
        rate=rate,
        sensor_resolution=sensor_resolution,
        trajectory=trajectory if trajectory is None or isinstance(trajectory, str) else trajectory.name,
    )
    g.files = stamp(g.files, options)  # the options, for `firmware check`
    compiled = []
    if compile:
        for cc in compilers():
            compile_generated(g, compiler=cc)  # -std=c99 -Wall -Wextra -Werror -pedantic
            compiled.append(cc.name)
        if not compiled and on_note:
            on_note("no C compiler found; the module was not compile-checked")
    with atomic_folder(out) as tmp:
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
    platform: Platform | str | None = None,
    *,
    poses: int = 100_000,
    seed: int = 0,
    trace: bool = False,
    duration: float = 0.5,
    compiler: str | None = None,
    word_bits: int | None = None,
    length_lsb: float | None = None,
    trig: str | None = None,
    convention: str | None = None,
    rate: float | None = None,
    sensor_resolution: float | None = None,
    trajectory: str | Trajectory | None = None,
) -> CheckResult:
    """Compile a C firmware against the header generated for the platform and compare it with the bit-exact
    emulation: ``sd_ik`` over random workspace poses and ``sd_tick`` over a recorded closed-loop stream.

    The module's options default to those recorded in the file (or in the ``sd_firmware.h`` next to it) by
    ``generate`` (a fingerprint), else to ``generate``'s defaults; an option given that differs from the
    recorded one is refused, naming both (the check would compare the C with another module's emulation).

    Args:
        path: the C file (implementing ``sd_firmware.h``).
        platform: the platform it was generated for (a Platform, a preset name or a YAML path; default as
            recorded).
        poses: workspace poses compared.
        seed: random seed of the poses.
        trace: trace the first differing pose word by word.
        duration: seconds of closed loop recorded for ``sd_tick``.
        compiler: a compiler name (default the first found).
        word_bits: data word width (as generated).
        length_lsb: metres per length LSB (as generated).
        trig: the trigonometry (as generated).
        convention: Euler convention (as generated).
        rate: controller rate, Hz (as generated).
        sensor_resolution: m per count (as generated).
        trajectory: the reference the gains were designed over (as generated).

    Returns:
        The comparison; ``identical`` when bit-exact.

    Raises:
        StewartError: a missing or unreadable file, a firmware that does not compile, bad options, an option
            that differs from the one recorded in the file.
    """
    # deferred: only check needs Drake (it records a closed loop); generate runs without pydrake
    from stewart_drake.drake.firmware_check import check_firmware

    check_source(path)
    given = dict(
        platform=None,  # compared below by the platform's name (a preset, a path or an API platform's name)
        word_bits=word_bits,
        length_lsb=length_lsb,
        trig=trig,
        convention=convention,
        rate=rate,
        sensor_resolution=sensor_resolution,
        trajectory=trajectory if trajectory is None or isinstance(trajectory, str) else None,
    )
    names = {k: "--" + k.replace("_", "-") for k in FP_DEFAULTS}
    o, mismatch = resolve_options(given, path, names)
    if mismatch:  # the check would compare the C with another module's emulation
        raise UsageError(UsageError.FIRMWARE_OPTIONS.format(file=path, mismatch=mismatch))
    rec = read_fingerprint(path)
    if platform is None:
        platform = load_platform(o["platform"])
    else:
        platform = load_platform(platform)
        if rec and _platform_name(rec[0]["platform"]) != platform.name:
            mismatch = f"--platform {platform.name} here, {rec[0]['platform']} in {rec[1]}"
            raise UsageError(UsageError.FIRMWARE_OPTIONS.format(file=path, mismatch=mismatch))
    if isinstance(trajectory, Trajectory):
        o["trajectory"] = trajectory
    config = controller_config(
        platform, o["word_bits"], o["length_lsb"], o["trig"], o["convention"], o["rate"], o["sensor_resolution"],
        o["trajectory"],
    )  # fmt: skip
    cc = compiler_by_name(compiler) if compiler else None
    r = check_firmware(Path(path), platform, config, poses, seed, trace, duration, cc)
    return CheckResult(r["ik"], r["tick"], r["identical"], r)


def _platform_name(recorded: str) -> str:
    """The name of the platform a fingerprint records (a preset name, a YAML path, or an API platform's name)."""
    try:
        return load_platform(recorded).name
    except StewartError:
        return recorded
