"""The numpy layers work on a machine without Drake: with pydrake unimportable, every module of the core
and control layers imports, and the numpy commands run end to end with the same output as with Drake."""

from __future__ import annotations

import json
import os
import pkgutil
import subprocess
import sys
from pathlib import Path

import pytest

import stewart_drake

ROOT = Path(__file__).resolve().parents[2]
RUNNER = str(Path(__file__).with_name("_no_drake.py"))
NUMPY_PACKAGES = (
    "core",
    "system",
    "mechanisms",
    "control",
    "fixedpoint",
    "workspace",
    "script",
    "homotopy",
    "design",
    "firmware",
    "calibration",
    "spec",
)


def run(*args, cwd):
    env = dict(os.environ, PYTHONPATH=str(ROOT), MPLBACKEND="Agg")
    return subprocess.run(
        [sys.executable, RUNNER, *args], capture_output=True, text=True, cwd=cwd, env=env, timeout=300
    )


def test_blocker_blocks():
    """The harness really hides pydrake (else every other test here proves nothing)."""
    r = run("-c", "import pydrake", cwd=ROOT)
    assert r.returncode != 0 and "No module named 'pydrake'" in r.stderr


def test_every_numpy_module_imports_without_pydrake():
    names = [
        m.name
        for pkg in NUMPY_PACKAGES
        for m in pkgutil.walk_packages([str(Path(stewart_drake.__file__).parent / pkg)], f"stewart_drake.{pkg}.")
    ]
    names += [f"stewart_drake.{pkg}" for pkg in NUMPY_PACKAGES]
    assert len(names) > 40
    code = "import importlib, sys\nfor n in sys.argv[3:]: importlib.import_module(n)\nprint('ok', len(sys.argv[3:]))"
    r = subprocess.run(
        [sys.executable, RUNNER, "-c", code, *names],
        capture_output=True,
        text=True,
        cwd=ROOT,
        env=dict(os.environ, PYTHONPATH=str(ROOT)),
        timeout=300,
    )
    assert r.returncode == 0, r.stderr[-2000:]
    assert "pydrake" not in r.stderr


COMMANDS = {
    "ik": ["ik", "--platform", "utn-dynamic", "--pose", "5", "-3", "720", "2", "-1", "3", "--json"],
    "fk": [
        "fk",
        "--platform",
        "utn-dynamic",
        "--lengths",
        "753.9",
        "753.8",
        "750.2",
        "745.4",
        "749.4",
        "744.6",
        "--json",
    ],
    "dynamics": ["dynamics", "--platform", "utn-dynamic", "--trajectory", "seed", "--json"],
    "dsp-ik": ["dsp-ik", "--pose", "0", "0", "100", "0.1", "0", "0", "--json"],
    "workspace": ["workspace", "--platform", "utn-kinematic", "--resolution", "0.05", "--json", "--out", "ws"],
    "servo": ["servo", "--pose", "1", "0", "2", "1", "0", "0", "--from-home", "--json"],
    "leg": ["leg", "ik", "100", "40", "--json"],
    "cue": ["cue", "--platform", "gonzalez-dutra-2009", "--drive", "car-braking", "--out", "cue"],
}


@pytest.mark.parametrize("name", sorted(COMMANDS))
def test_numpy_command_runs_without_pydrake_and_agrees(name, tmp_path):
    """Same exit code and the same JSON as the same command with Drake importable."""
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    blocked = run("cli", *COMMANDS[name], cwd=tmp_path / "a")
    assert blocked.returncode == 0, blocked.stderr[-2000:]
    env = dict(os.environ, PYTHONPATH=str(ROOT), MPLBACKEND="Agg")
    normal = subprocess.run(
        [sys.executable, "-m", "stewart_drake.cli", *COMMANDS[name]],
        capture_output=True,
        text=True,
        cwd=tmp_path / "b",
        env=env,
        timeout=300,
    )
    assert normal.returncode == 0, normal.stderr[-2000:]
    drop = {"wall_time_s", "elapsed_s", "out"}
    a, b = json.loads(blocked.stdout), json.loads(normal.stdout)
    if isinstance(a, dict):
        a = {k: v for k, v in a.items() if k not in drop}
        b = {k: v for k, v in b.items() if k not in drop}
    assert a == b
