"""The documentation site, built once per test session for the tests that read it (``test_site.py``) and open it in
a browser (``test_site_browser.py``)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def tree_state() -> str:
    r = subprocess.run(
        ["git", "status", "--porcelain", "--untracked-files=all"], cwd=ROOT, capture_output=True, text=True
    )
    return r.stdout if r.returncode == 0 else pytest.skip("not a git checkout")


@pytest.fixture(scope="session")
def site(tmp_path_factory):
    """The site, built once in strict mode: ``(folder, the build's log)``."""
    out = tmp_path_factory.mktemp("site")
    scratch = tmp_path_factory.mktemp("tmpdir")  # the build's (and the notebooks' kernels') temporary directory
    env = {**os.environ, "PYTHONPATH": str(ROOT), "PYTHONDONTWRITEBYTECODE": "1", "NO_MKDOCS_2_WARNING": "1"}
    env["TMPDIR"] = str(scratch)
    before = tree_state()
    r = subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(out), "--config-file", "mkdocs.yml"],
        cwd=ROOT,
        env=env,
        capture_output=True,
        text=True,
    )
    assert tree_state() == before, "the build wrote into the source tree"
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-6000:]
    assert sorted(p.name for p in scratch.iterdir()) == [], "the build or a notebook left files in the temp directory"
    return out, r.stderr
