"""Argument helpers shared by the subcommands (units, platform, pose, JSON output)."""

from __future__ import annotations

import copy
import math
import re
import sys

import numpy as np

from stewart_drake.core.geometry import PRESETS, Platform, load_platform
from stewart_drake.core.rotations import ANGLE_UNITS, CONVENTIONS, LENGTH_UNITS
from stewart_drake.errors import MachineError, QuantityError, StewartError, UsageError
from stewart_drake.spec import Machine, apply_overrides, load_machine
from stewart_drake.spec.load import is_machine_file
from stewart_drake.system.jsonout import dumps_strict
from stewart_drake.system.output_folder import OutputFolder

# what a command takes of a machine file given as --platform
MACHINE_LOADED = "its platform, the payload on the plate"
MACHINE_KINEMATIC = "its platform: the geometry, without the payload"


def add_platform_arg(parser, default: str | None = "utn-kinematic", machine: str = MACHINE_LOADED) -> None:
    """``--platform NAME|FILE``: a built-in preset, a platform YAML file or a machine file (``machine``: what the
    command takes of it)."""
    parser.add_argument(
        "--platform",
        default=default,
        metavar="NAME|FILE",
        help=f"a preset ({', '.join(PRESETS)}), a platform YAML file or a machine file ({machine}) (default: {default})",
    )


def add_unit_args(parser, length_default: str = "mm", angle_default: str = "deg") -> None:
    """``--length-unit`` and ``--angle-unit``: the units of the pose values on the command line."""
    parser.add_argument(
        "--length-unit", choices=list(LENGTH_UNITS), default=length_default, help=f"default {length_default}"
    )
    parser.add_argument(
        "--angle-unit",
        choices=list(ANGLE_UNITS),
        default=angle_default,
        help=f"default {angle_default} ('pi': a fraction of pi)",
    )
    parser.add_argument(
        "--convention", choices=list(CONVENTIONS), default="utn", help="Euler convention (default utn: Ry·Rx·Rz)"
    )


def platform_machine(args) -> Machine | None:
    """The machine when ``--platform`` names a machine file (a platform file with machine sections such as
    ``payload``, ``controller``, ``firmware``; ``stewart-drake init --machine-template``), else None."""
    return load_machine(args.platform) if is_machine_file(args.platform) else None


def refuse_machine_file(sources, use: str) -> None:
    """Refuse a machine file among the ``--platform`` values ``sources`` of a command that reads the whole machine
    with another option (``use``, e.g. ``"--machine"``), in one line naming the file as written."""
    for source in [sources] if isinstance(sources, str) else sources or ():
        if is_machine_file(source):
            raise UsageError(UsageError.MACHINE_AS_PLATFORM.format(path=source, use=use))


def platform_arg(args) -> str | Platform | None:
    """``--platform`` for an API call that loads it: the text as given (a preset or a platform file, named
    as the user wrote it), or for a machine file its platform with the payload on the plate."""
    machine = platform_machine(args)
    return args.platform if machine is None else machine.loaded_platform


def platform_from_args(args) -> Platform:
    """The platform named by ``--platform`` (a preset or a YAML file), validated. A machine file gives its
    platform with the payload on the plate (``Machine.loaded_platform``)."""
    machine = platform_machine(args)
    return load_platform(args.platform) if machine is None else machine.loaded_platform


def add_force_arg(parser) -> None:
    """``--force``: write into an existing folder that holds files stewart-drake did not write."""
    parser.add_argument(
        "--force",
        action="store_true",
        help="write into an existing folder that holds other files (they are never touched; see README, Output folders)",
    )


def output_folder(args, option: str = "--out", names: tuple[str, ...] = ()) -> OutputFolder | None:
    """The checked ``--out`` destination (``atomic.OutputFolder``), or None when none was given.
    Call it before any work so that a refused destination costs nothing (``names``: the files the command
    writes, refused there before the work when another's file holds one)."""
    value = getattr(args, option.lstrip("-").replace("-", "_"))
    if value is None:
        return None
    offered = "--force" if hasattr(args, "force") else None  # a refusal names --force only where it exists
    force = getattr(args, "force", False)
    return OutputFolder(value, force=force, option=option, force_option=offered, names=names)


def print_json(obj) -> None:
    """Print ``obj`` as strict JSON (``dumps_strict``)."""
    sys.stdout.write(dumps_strict(obj) + "\n")


def _jsonable(x):
    if isinstance(x, np.ndarray):
        return x.tolist()
    if isinstance(x, np.generic):
        return x.item()
    raise TypeError(f"not JSON serialisable: {type(x).__name__}")


def reject_unused(args, needs: str, applies: bool, **defaults) -> None:
    """Raise ``UsageError`` when an option was changed from its default (``defaults``: attribute name
    -> default) although it does not apply (``applies`` false): an ignored option is an error."""
    if applies:
        return
    for name, default in defaults.items():
        if getattr(args, name) != default:
            raise UsageError(UsageError.NEEDS.format(option="--" + name.replace("_", "-"), needs=needs))


def finite_option(value, option: str) -> float:
    """``value`` if it is a finite number, else a ``UsageError`` naming the option."""
    if value is not None and not math.isfinite(value):
        raise UsageError(UsageError.NOT_FINITE.format(option=option, value=value))
    return value


def add_machine_args(parser) -> None:
    """``--machine FILE`` and ``--set PATH=VALUE`` (read by ``machine_from_args``)."""
    parser.add_argument(
        "--machine",
        default=None,
        metavar="FILE",
        help="a machine file: a platform file with controller, firmware, sensors, actuators, payload, run and "
        "motions sections (`stewart-drake init --machine-template` writes one); default: --platform "
        "(utn-dynamic) with the defaults",
    )
    parser.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="PATH=VALUE",
        help="set one field of the machine by its spec path, e.g. --set controller.period=0.5ms "
        "--set payload.mass=150kg (repeatable; after the other options)",
    )


# option (argparse dest) -> spec path: the one table between the command line and the machine's fields.
# A flag given sets its path; an error about the path names the flag.
FLAG_PATHS = {
    "controller": ("--controller", "controller.law"),
    "period": ("--period", "controller.period"),
    "latency": ("--latency", "controller.latency"),
    "engine": ("--engine", "controller.engine"),
    "no_feedforward": ("--no-feedforward", "controller.feedforward"),
    "sensor_resolution": ("--sensor-resolution", "sensors.resolution"),
    "word_bits": ("--word-bits", "firmware.word_bits"),
    "length_lsb": ("--length-lsb", "firmware.length_lsb"),
    "trig": ("--trig", "firmware.trig"),
    "plant_step": ("--plant-step", "run.plant_step"),
    "integrator": ("--integrator", "run.integrator"),
    "fit": ("--fit", "run.fit"),
    "duration": ("--duration", "run.duration"),
    "pil": ("--pil", "pil.target"),
    "pil_fault": ("--pil-fault", "pil.fault"),
    "pil_on_fault": ("--pil-on-fault", "pil.on_fault"),
}
# store_true flags: the value they set
FLAG_VALUES = {"no_feedforward": False, "fit": True}


def machine_from_args(args, flag_paths: dict = FLAG_PATHS) -> Machine:
    """The machine of ``--machine`` (else ``--platform``, else utn-dynamic) with the flags of ``flag_paths``
    (``{dest: (flag, spec path)}``; a command without a flag skips it) that were given and each ``--set``
    (applied together: a section is checked as a whole); an error about a flag's path names the flag."""
    if args.machine is not None and args.platform is not None:
        raise UsageError(UsageError.NOT_BOTH.format(first="--machine", second="--platform"))
    machine = load_machine(args.machine or args.platform or "utn-dynamic")
    given = [d for d in flag_paths if getattr(args, d, None) is not None and getattr(args, d, None) is not False]
    set_paths = {w.split("=", 1)[0].strip() for w in args.set}
    named = [d for d in given if flag_paths[d][1] not in set_paths]  # a path also --set is named as a path
    flags = {flag_paths[d][1]: FLAG_VALUES.get(d, getattr(args, d)) for d in given}
    try:
        return apply_overrides(machine, [*(f"{p}={v}" for p, v in flags.items()), *args.set])
    except (MachineError, QuantityError) as e:
        raise flag_error(e, flag_paths, named) from None


def flag_text(text: str, table: dict, given=None) -> str:
    """``text`` (an API message) with the names of ``table`` (option dest -> ``(flag, spec path or None)``; only
    those of the ``given`` dests, if given) turned into the command line's: a spec path, an API keyword
    written ``name=value`` and one that starts the message become the flag (``controller.period`` ->
    ``--period``, ``length_lsb=0.5`` -> ``--length-lsb 0.5``, ``fit=True`` -> ``--fit``, ``rate must be`` ->
    ``--rate must be``)."""
    for dest, (flag, path) in table.items():
        if given is None or dest in given:
            if path:
                text = text.replace(path, flag)
            text = re.sub(rf"(?<![\w.-]){re.escape(dest)}=True\b", flag, text)  # a store_true flag
            text = re.sub(rf"(?<![\w.-]){re.escape(dest)}=", flag + " ", text)
            if text.startswith(dest + " "):
                text = flag + text[len(dest) :]
    return text


def flag_error(e: StewartError, table: dict, given=None) -> StewartError:
    """``e`` with its message's spec paths and API keywords named by their flags (``flag_text``; the same
    class)."""
    message = flag_text(str(e), table, given)
    if message == str(e):
        return e
    e = copy.copy(e)
    e.args = (message,)
    return e
