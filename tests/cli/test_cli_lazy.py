"""The command line imports a command's module only when that command runs: the numpy commands then
work with pydrake unimportable, and ``--help`` lists every command with the help its module gives."""

import argparse
import json
import pkgutil
import subprocess
import sys

import pytest

from stewart_drake import commands
from stewart_drake.cli import COMMANDS, build_parser, command_module

# Run the CLI in a fresh interpreter where any "import pydrake..." raises ImportError; print which
# command modules and whether any pydrake module got loaded.
BLOCKED = """
import json, sys
sys.modules["pydrake"] = None
from stewart_drake.cli import main
rc = main(sys.argv[1:])
loaded = sorted(m for m in sys.modules
                if m.startswith("stewart_drake.commands.") and not m.split(".")[-1].startswith("_"))
drake = any(m.startswith("pydrake.") for m in sys.modules)
print(json.dumps({"rc": rc, "commands": loaded, "pydrake": drake}), file=sys.stderr)
"""


def run_blocked(*argv):
    p = subprocess.run([sys.executable, "-c", BLOCKED, *argv], capture_output=True, text=True, timeout=300)
    status = json.loads(p.stderr.strip().splitlines()[-1])
    return status, p.stdout, p.stderr


def test_commands_table_matches_the_modules():
    modules = {m.name for m in pkgutil.iter_modules(commands.__path__) if not m.name.startswith("_")}
    assert {module for module, _ in COMMANDS.values()} == modules
    for name, (_, help_text) in COMMANDS.items():
        sub = argparse.ArgumentParser().add_subparsers()
        command_module(name).register(sub)
        assert list(sub.choices) == [name]
        assert sub._choices_actions[0].help == help_text, name


def test_one_command_parser_imports_only_that_command():
    parser = build_parser(only="ik")
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    assert list(sub.choices) == list(COMMANDS)
    full = build_parser()
    full_sub = next(a for a in full._actions if isinstance(a, argparse._SubParsersAction))
    assert parser.format_help() == full.format_help()  # `stewart-drake --help` is unchanged
    assert any(a.dest == "pose" for a in sub.choices["ik"]._actions)
    assert not any(a.dest == "lengths" for a in sub.choices["fk"]._actions)  # a bare entry
    assert any(a.dest == "lengths" for a in full_sub.choices["fk"]._actions)


@pytest.mark.parametrize(
    "argv, command",
    [
        (["ik", "--pose", "0", "0", "100", "0", "0", "0", "--json"], "ik"),
        (["fk", "--lengths", "473", "473", "473", "473", "473", "473", "--json"], "fk"),
        (["dynamics", "--platform", "utn-dynamic", "--t-end", "0.2", "--json"], "dynamics"),
        (["dsp-ik", "--pose", "0", "0", "100", "0.1", "0", "0", "--json"], "dsp_ik"),
        (["workspace", "--resolution", "0.02", "--json"], "workspace"),
        (["servo", "--pose", "0", "0", "0", "0", "0", "0", "--from-home", "--json"], "servo"),
        (["leg", "fk", "0.1", "0.2"], "leg"),
    ],
)
def test_numpy_commands_run_without_pydrake(argv, command):
    status, out, err = run_blocked(*argv)
    assert status["rc"] == 0, err
    assert not status["pydrake"] and status["commands"] == [f"stewart_drake.commands.{command}"]
    assert out.strip()
    if "--json" in argv:
        json.loads(out)


def test_help_and_bad_command_without_pydrake():
    status, out, _ = run_blocked("--help")
    assert status["rc"] == 0 and status["commands"] == [] and all(name in out for name in COMMANDS)
    status, _, err = run_blocked("nosuch")
    assert status["rc"] == 2 and "invalid choice: 'nosuch'" in err


# Run the CLI in a fresh interpreter and print which modules it has loaded at the end.
LOADED = """
import contextlib, io, json, sys
from stewart_drake.cli import main
with contextlib.redirect_stdout(io.StringIO()):
    rc = main(sys.argv[1:])
print(json.dumps({"rc": rc, "modules": sorted(sys.modules)}))
"""
# The libraries of the other commands (Drake, the optimisers, Dask, tables, plots, the motion language, progress
# bars), numpy's masked arrays and the process-pool machinery: no numpy command's work uses them, and each adds
# to its start-up.
NOT_NEEDED = (
    "pydrake",
    "scipy",
    "pymoo",
    "dask",
    "distributed",
    "pandas",
    "matplotlib",
    "lark",
    "tqdm",
    "multiprocessing",
    "concurrent.futures",
    "numpy.ma",
)
# the compiler glue: only where a compiled kernel runs (fk's real-time branch check and homotopy tracker, dsp-ik's
# firmware engine)
COMPILER = ("stewart_drake.system.c_build", "cffi")


@pytest.mark.parametrize(
    "argv, not_needed",
    [
        (["ik", "--platform", "utn-dynamic", "--pose", "0", "0", "700", "0", "0", "0"], NOT_NEEDED + COMPILER),
        (["fk", "--platform", "utn-dynamic", "--lengths", *["730"] * 6], NOT_NEEDED),
        (["fk", "--all", "--platform", "utn-dynamic", "--lengths", *["730"] * 6], NOT_NEEDED),
        (["dsp-ik", "--pose", "0", "0", "100", "0.1", "0", "0"], NOT_NEEDED),
        (["servo", "--pose", "0", "0", "0", "0", "0", "0", "--from-home"], NOT_NEEDED + COMPILER),
        (["leg", "fk", "0.1", "0.2"], NOT_NEEDED + COMPILER),
        (["workspace", "--help"], NOT_NEEDED + COMPILER),
        (["--help"], NOT_NEEDED + COMPILER),
    ],
    ids=lambda v: " ".join(a for a in v[:2] if a != "--platform") if isinstance(v, list) else None,
)
def test_numpy_command_imports_only_what_it_runs(argv, not_needed):
    p = subprocess.run([sys.executable, "-c", LOADED, *argv], capture_output=True, text=True, timeout=300)
    status = json.loads(p.stdout.strip().splitlines()[-1])
    assert status["rc"] == 0, p.stderr
    loaded = [m for m in status["modules"] if any(m == n or m.startswith(n + ".") for n in not_needed)]
    assert loaded == [], f"{' '.join(argv)} imported {loaded[:8]}"
