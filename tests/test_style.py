"""The house style is checked, not hoped for: ``ruff check`` (pycodestyle, pyflakes, import order, pyupgrade,
bugbear) and ``ruff format --check`` at 120 characters, as configured in pyproject.toml."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def ruff(*args: str) -> subprocess.CompletedProcess:
    exe = shutil.which("ruff", path=str(Path(sys.executable).parent)) or shutil.which("ruff")
    if exe is None:
        pytest.fail("ruff is not installed (it is in the test extras: pip install -e '.[test]')")
    return subprocess.run([exe, *args], capture_output=True, text=True, cwd=ROOT)


def test_ruff_lint_is_clean():
    r = ruff("check", "--no-cache", ".")
    assert r.returncode == 0, r.stdout[-4000:] + r.stderr[-2000:]


def test_ruff_format_is_applied():
    r = ruff("format", "--check", "--no-cache", ".")
    assert r.returncode == 0, r.stdout[-4000:] + r.stderr[-2000:]
