"""The numpy layers' own tests need no Drake: the tests under tests/core, tests/control, tests/fixedpoint,
tests/workspace, tests/script and tests/design pass with pydrake unimportable (``tests/cli/_no_drake.py`` loaded as a pytest
plugin), so each layer is checked the way a machine without Drake would run it. The Drake cross-checks of those
layers live in tests/drake and their Drake-backed commands in tests/cli."""

import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PLUGIN = "tests.cli._no_drake"
DRAKE_FREE = (
    "tests/core",
    "tests/system",
    "tests/mechanisms",
    "tests/control",
    "tests/fixedpoint",
    "tests/workspace",
    "tests/script",
    "tests/design",
    "tests/calibration",
    "tests/spec",
)


def pytest_without_drake(*args):
    """``python -m pytest -p tests.cli._no_drake ARGS`` from the repository root: ``(exit code, output)``."""
    env = dict(os.environ, PYTHONPATH=str(ROOT), MPLBACKEND="Agg")
    # -v cancels the configured -q: pytest then prints the plugin's header line and one line per file.
    argv = [sys.executable, "-m", "pytest", "-p", PLUGIN, "-p", "no:cacheprovider", "-v", *args]
    r = subprocess.run(argv, capture_output=True, text=True, cwd=ROOT, env=env, timeout=600)
    return r.returncode, r.stdout + r.stderr


def test_plugin_hides_pydrake_from_the_tests():
    """Loaded with ``-p``, the plugin makes a Drake test fail at collection (else the run below proves nothing)."""
    rc, out = pytest_without_drake("--collect-only", "tests/drake/test_leg_drake.py")
    assert rc != 0 and "No module named 'pydrake" in out, out[-2000:]


def test_numpy_layers_tests_pass_without_drake():
    rc, out = pytest_without_drake(*DRAKE_FREE)
    assert "pydrake blocked (tests/cli/_no_drake.py); already imported before the blocker: none" in out
    assert rc == 0, out[-4000:]
    for folder in DRAKE_FREE:
        assert f"{folder}/test_" in out, f"no test of {folder} ran"
