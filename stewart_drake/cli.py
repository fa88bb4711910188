"""The ``stewart-drake`` command line. Each subcommand lives in ``stewart_drake/commands/<name>.py``
(``COMMANDS`` maps a command to its module) and defines ``register(subparsers)``, which adds its parser and
sets ``func``. Bad input exits with status 2 and one line on stderr, never a traceback."""

from __future__ import annotations

import argparse
import importlib
import math
import re
import sys

import numpy as np

from stewart_drake import __version__, commands
from stewart_drake.core.argcheck import cli_names
from stewart_drake.errors import StewartError, UsageError
from stewart_drake.system import interrupts, output_folder, processes

# The API's parameter -> its flag, where the flag is not the parameter with ``--`` and ``-`` for ``_``
# (``core.argcheck.param``): what the API's messages call ``all_modes`` the command line calls ``--all``.
CLI_NAMES = {"all_modes": "--all"}

# Every subcommand: its name -> (its module in ``stewart_drake.commands``, the one-line help that
# ``stewart-drake --help`` lists; the module's own parser carries the same text, a test keeps them equal).
# A command's module is imported only when that command runs: the Drake commands import pydrake at
# their module top, and the numpy commands must work where pydrake is not installed.
COMMANDS = {
    "calibrate": (
        "calibrate",
        "identify a built platform's geometry from measured poses; write a calibrated platform file",
    ),
    "compile": (
        "compile",
        "translate a motion program (.stw) to Python (calling this library) or Matlab (the seed's output)",
    ),
    "cross-check": (
        "cross_check",
        "the platform's kinematics and leg forces in Pinocchio and MuJoCo against the closed forms",
    ),
    "cue": (
        "cue",
        "motion cueing: a vehicle's motion (drive file or shipped drive) to platform poses, scored by perceived motion",
    ),
    "dsp-ik": ("dsp_ik", "leg lengths as the DSP56800E firmware computes them (integer mm), with the float IK"),
    "dynamics": ("dynamics", "leg forces along a trajectory (inverse dynamics, with or without Coriolis)"),
    "firmware": (
        "firmware",
        "generate the C firmware (IK + controller tick) or check a C firmware against the emulation",
    ),
    "fk": ("fk", "pose for six leg lengths (forward kinematics); --all: every assembly mode"),
    "ik": ("ik", "leg lengths for a pose (closed-form inverse kinematics)"),
    "init": (
        "init",
        "print a commented platform file template to start from "
        "(stewart-drake init --platform-template radial > my.yaml)",
    ),
    "leg": ("leg", "3R planar leg (seed 003): DH forward kinematics, geometric inverse kinematics"),
    "model": ("model", "generate (write) or inspect the model of a platform: SDF (Drake), URDF + closures, MJCF"),
    "modes": ("modes", "natural frequencies (Hz) and mode shapes at a pose; --drake checks them against Drake"),
    "montecarlo": (
        "montecarlo",
        "robustness study: many closed-loop runs with drawn tolerances (Dask), or --replay one of them",
    ),
    "optimize": (
        "optimize",
        "design synthesis: the geometry with the smallest actuators that meets a requirements file, proven",
    ),
    "plan-measurements": (
        "plan_measurements",
        "plan calibration poses (D-optimal) inside a workspace box; CSV and a .stw program that visits them",
    ),
    "report": (
        "report",
        "run the analyses on the built-in presets (or on your platform or machine) and write an HTML report",
    ),
    "response": (
        "response",
        "the closed leg loop in the frequency domain at a pose: margins, bandwidth, sensitivity peak, Bode/Nyquist",
    ),
    "run": ("run", "run a motion program (.stw): leg lengths and forces along its trajectory"),
    "servo": ("servo", "servo arm angles and pulse widths for a pose (RC-servo hexapod, seed 002)"),
    "simulate": ("simulate", "run the fixed-point (or float) controller in the loop with the Drake plant"),
    "simulate-measurements": (
        "simulate_measurements",
        "synthetic calibration measurements of a machine drawn around the nominal (truth written apart)",
    ),
    "size": ("size", "actuator sizing: peak/RMS force, speed, acceleration, power and stroke per leg"),
    "stiffness": ("stiffness", "6×6 Cartesian stiffness, compliance and payload deflection at a pose"),
    "tune": ("tune", "tune the leg PID gains and length LSB of a machine to stated margins; write the tuned machine"),
    "view": (
        "view",
        "interactive 3-D viewer (Meshcat on localhost): pose sliders, leg lengths, stroke margins, "
        "singularity distance, assembly modes; or replay a simulate/run log",
    ),
    "workspace": ("workspace", "reachable positions (extents, volume, views) and rotation limits"),
}


class Number(float):
    """A float option value that remembers the text the user typed (messages echo it as written)."""

    text: str

    def __new__(cls, text: str):
        value = super().__new__(cls, text)
        value.text = text
        return value

    def __str__(self) -> str:
        return self.text

    __repr__ = __str__


def finite_number(text: str) -> Number:
    """argparse ``type`` for every float option: a finite number, kept with its text."""
    try:
        value = Number(text.strip())
    except ValueError:
        raise argparse.ArgumentTypeError(UsageError.NOT_A_NUMBER.format(value=text)) from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(UsageError.NOT_FINITE_NUMBER.format(value=text))
    return value


def checked_int(text: str) -> int:
    """argparse ``type`` for every integer option (at most 18 digits: counts, not big numbers)."""
    s = text.strip()
    if len(s.lstrip("+-")) > 18 or not s.lstrip("+-").isdigit():
        raise argparse.ArgumentTypeError(UsageError.NOT_WHOLE.format(value=text))
    return int(s)


# a negative number as a value, exponents and non-finite spellings included (argparse's own matcher takes
# "-1e-3" for an option and says "expected one argument"; "-inf" then meets the finite-number check)
NEGATIVE_NUMBER = re.compile(r"^-(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$|^-(inf|infinity|nan)$", re.IGNORECASE)


class Parser(argparse.ArgumentParser):
    """An ``ArgumentParser`` whose errors are one line (``prog: error: message (see --help)``), exit 2, and
    that reads every negative number as a value (``NEGATIVE_NUMBER``)."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = NEGATIVE_NUMBER

    def error(self, message):
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def _finite_types(parser: argparse.ArgumentParser) -> None:
    """Every ``type=float`` option becomes ``finite_number``, every ``type=int`` ``checked_int``, in
    ``parser`` and its subparsers."""
    for action in parser._actions:
        if action.type is float:
            action.type = finite_number
        elif action.type is int:
            action.type = checked_int
        if isinstance(action, argparse._SubParsersAction):
            for sub in action.choices.values():
                _finite_types(sub)


def command_module(name: str):
    """The module of the subcommand ``name`` (imported now)."""
    return importlib.import_module(f"{commands.__name__}.{COMMANDS[name][0]}")


DESCRIPTION = (
    "Model, size and verify Stewart platforms and the fixed-point controllers that drive them. "
    "Run `stewart-drake COMMAND --help` for a command's options; exit 0: a good result, 1: a result outside "
    "physical limits (still shown), 2: bad input."
)


def build_parser(only: str | None = None) -> argparse.ArgumentParser:
    """The whole command line. ``only=None``: every command's full parser (imports every command
    module); otherwise only the command named ``only`` (if it is one) gets its full parser and the others
    a bare entry with their help, so that only that command's module is imported."""
    parser = Parser(prog="stewart-drake", description=DESCRIPTION)
    parser.add_argument("--version", action="version", version=f"stewart-drake {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for name, (_, help_text) in COMMANDS.items():
        if only is None or name == only:
            command_module(name).register(sub)
        else:
            sub.add_parser(name, help=help_text)
    _finite_types(parser)
    return parser


def _command_in(argv: list[str]) -> str:
    """The subcommand named on the command line: its first word that is not an option ("" if none)."""
    return next((a for a in argv if not a.startswith("-")), "")


def main(argv=None) -> int:
    """Run one command; return its exit status (0 ok, 1 a result outside physical limits, 2 bad input)."""
    from_shell = argv is None
    argv = sys.argv[1:] if argv is None else list(argv)
    parser = build_parser(only=_command_in(argv))
    try:
        args = parser.parse_args(argv)
    except SystemExit as e:  # --help, --version, or a usage error already printed
        return e.code if isinstance(e.code, int) else 2
    name = args.command + (f" {args.op}" if getattr(args, "op", None) else "")
    # recorded per file in output manifests: a command replaces only its own outputs
    processes.handle_sigterm()  # SIGTERM unwinds like Ctrl-C: temporaries removed, worker processes stopped
    restore_environment = processes.mark_cli()  # the worker processes it starts leave Ctrl-C to it
    output_folder.set_command(" ".join(filter(None, (name, getattr(args, "firmware_command", None)))))
    try:
        if from_shell:  # Ctrl-C now unwinds (the command's cleanup runs); while starting it ended at once
            interrupts.unwind()
        # Intermediate overflow/NaN in numpy is not reported as a multi-line RuntimeWarning: every result
        # is checked (finite inputs and outputs, strict JSON, the sanity checks) before it is printed.
        # The API's messages name its parameters (max_iter); here they name the flags (--max-iter).
        with np.errstate(over="ignore", invalid="ignore", divide="ignore", under="ignore"), cli_names(CLI_NAMES):
            return int(args.func(args) or 0)
    except (StewartError, ValueError) as e:
        print(f"stewart-drake {name}: error: {_one_line(e)}", file=sys.stderr)
        return getattr(e, "exit_code", 2)  # PhysicalLimitError: 1
    except OSError as e:
        if isinstance(e, BrokenPipeError):  # e.g. `stewart-drake ... | head`
            sys.stderr.close()
            return 0
        print(f"stewart-drake {name}: error: {_os_message(e)}", file=sys.stderr)
        return 2
    except KeyboardInterrupt as e:  # Ctrl-C, or SIGTERM (processes.Terminated): cleanup ran, children stopped
        if from_shell:
            interrupts.ignore()  # a second Ctrl-C while it says so is no traceback
        term = isinstance(e, processes.Terminated)
        print(f"stewart-drake {name}: {'terminated' if term else 'interrupted'}", file=sys.stderr)
        if from_shell:  # the finally blocks have run; skip the libraries' exit hooks (Dask's half-started
            processes.exit_now(143 if term else 130)  # cluster closing prints tracebacks); workers die with us
        return 143 if term else 130
    except (MemoryError, RecursionError, OverflowError, TypeError, ArithmeticError, AssertionError, RuntimeError) as e:
        detail = _one_line(e)
        print(
            f"stewart-drake {name}: error: " + UsageError.INTERNAL.format(kind=type(e).__name__, detail=detail[:300]),
            file=sys.stderr,
        )
        return 2
    finally:
        restore_environment()
        if from_shell:  # the command has returned: a Ctrl-C in the exit hooks ends it at once, quietly
            interrupts.end_at_once()


def _one_line(e: BaseException) -> str:
    """The message of ``e`` on one line (a multi-line message keeps its first line)."""
    text = str(e).strip() or type(e).__name__
    lines = [ln for ln in text.splitlines() if ln.strip()]
    return lines[0] if len(lines) == 1 else f"{lines[0]} ..." if lines else text


def _os_message(e: OSError) -> str:
    """A file-system error as "FILE: reason", with the file name as given."""
    where = e.filename if e.filename is not None else ""
    reason = e.strerror or str(e)
    if where:
        return f"{where}: {reason}"
    return reason


if __name__ == "__main__":
    sys.exit(main())
