"""``scripts/screenshots`` (named in the README) runs (issue 24, item 6: it failed at its first import,
``No module named 'stewart_drake.browser'``): it reaches its own checks and answers in one line."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def run(*argv, cwd):
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    return subprocess.run(
        [sys.executable, str(ROOT / "scripts" / "screenshots"), *argv], cwd=cwd, env=env, capture_output=True, text=True
    )


def test_screenshots_script_runs_and_checks_its_report(tmp_path):
    r = run("missing", cwd=tmp_path)
    assert r.returncode == 2 and r.stderr.strip() == "screenshots: missing/index.html not found", r.stderr
    r = run("--help", cwd=tmp_path)
    assert r.returncode == 0 and "--out" in r.stdout
    (tmp_path / "rep").mkdir()
    (tmp_path / "rep" / "index.html").write_text("<html></html>")
    (tmp_path / "mine").mkdir()
    (tmp_path / "mine" / "notes.txt").write_text("x")
    r = run("rep", "--out", "mine", cwd=tmp_path)  # without Chromium: says so; with it: refuses the user's folder
    assert r.returncode == 2 and "Traceback" not in r.stderr, r.stderr
    assert "Chromium is not installed" in r.stderr or "'notes.txt'" in r.stderr
    assert (tmp_path / "mine" / "notes.txt").read_text() == "x"
