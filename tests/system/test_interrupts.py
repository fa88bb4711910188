"""Who answers Ctrl-C (system.interrupts): the command line is recognised from the interpreter's own command
line (never a spawned worker, never another program), a worker only by its parent, and a command run
in-process leaves no mark in its caller's environment (the mark made a later command, started by the test
runner, ignore Ctrl-C as if it were the runner's worker: the Dask orphan test's full-suite timeouts)."""

from __future__ import annotations

import os

import pytest

from stewart_drake import cli
from stewart_drake.system import interrupts, processes

PY = "/usr/bin/python3"


@pytest.mark.parametrize(
    "argv,expected",
    [
        ([PY, "/venv/bin/stewart-drake", "ik", "--pose", "0"], True),  # the console script (its shebang)
        ([PY, "-m", "stewart_drake.cli", "montecarlo"], True),
        ([PY, "-m", "stewart_drake", "ik"], True),
        ([PY, "-B", "-W", "ignore", "-mstewart_drake.cli", "ik"], True),  # options before, -m joined
        ([PY, "-X", "importtime", "/venv/bin/stewart-drake"], True),  # an option's value is not the script
        # a spawned worker: its sys.argv is the parent's, its interpreter command line is not
        (
            [PY, "-B", "-c", "from multiprocessing.spawn import spawn_main; spawn_main()", "--multiprocessing-fork"],
            False,
        ),
        ([PY, "-m", "pytest", "tests"], False),
        ([PY, "-m", "stewart_drake.system.isolate"], False),
        ([PY, "my_study.py", "stewart-drake"], False),
        ([PY], False),  # the interactive interpreter
        ([PY, "-m"], False),
    ],
)
def test_the_command_line_is_recognised_from_the_interpreter_command_line(argv, expected):
    assert interrupts.is_command_line(argv) is expected


def test_a_worker_is_a_child_of_the_marked_process(monkeypatch):
    monkeypatch.setenv(interrupts.CLI_PID_ENV, str(os.getppid()))
    assert interrupts.is_worker()
    monkeypatch.setenv(interrupts.CLI_PID_ENV, str(os.getpid()))  # the marked process itself
    assert not interrupts.is_worker()
    monkeypatch.delenv(interrupts.CLI_PID_ENV)
    assert not interrupts.is_worker()


@pytest.mark.parametrize("before", [None, "12345"])
def test_mark_cli_restores_the_environment(monkeypatch, before):
    if before is None:
        monkeypatch.delenv(interrupts.CLI_PID_ENV, raising=False)
    else:
        monkeypatch.setenv(interrupts.CLI_PID_ENV, before)
    restore = processes.mark_cli()
    assert os.environ[interrupts.CLI_PID_ENV] == str(os.getpid())
    restore()
    assert os.environ.get(interrupts.CLI_PID_ENV) == before


def test_a_command_run_in_process_leaves_no_mark(monkeypatch, capsys):
    monkeypatch.delenv(interrupts.CLI_PID_ENV, raising=False)
    assert cli.main(["ik", "--platform", "utn-dynamic", "--pose", "0", "0", "700", "0", "0", "0"]) == 0
    assert "mm" in capsys.readouterr().out  # it ran (leg lengths printed)
    assert interrupts.CLI_PID_ENV not in os.environ
    assert cli.main(["ik", "--pose", "0", "0", "1e9", "0", "0", "0"]) != 0  # and after a failing command
    assert interrupts.CLI_PID_ENV not in os.environ
