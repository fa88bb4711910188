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
