"""The package works installed, not only from a checkout: ``pip install .`` (not editable) into a fresh
virtual environment, then ``stewart-drake report --quick`` from a folder outside the source tree. The
installed files are not modified by the run (nothing is written into site-packages)."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

from tests.report.test_analyses import FINDINGS

ROOT = Path(__file__).resolve().parents[2]
AT_ROOT = {".git", ".venv", "build", "report", ".pytest_cache", ".hypothesis"}


def skip(folder: str, names: list[str]) -> set[str]:
    """What the source copy leaves out: build state, caches, the checkout's own outputs."""
    out = {n for n in names if n == "__pycache__" or n.endswith(".egg-info")}
    return out | (AT_ROOT & set(names) if Path(folder) == ROOT else set())


def snapshot(folder: Path) -> dict[str, tuple[int, int]]:
    """Every file under ``folder``: (size, mtime in ns)."""
    return {
        str(p.relative_to(folder)): (p.stat().st_size, p.stat().st_mtime_ns) for p in folder.rglob("*") if p.is_file()
    }


def test_installed_package_writes_the_report_from_anywhere(tmp_path):
    source = tmp_path / "source"  # a copy: pip builds in the source folder, the checkout stays untouched
    shutil.copytree(ROOT, source, ignore=skip, symlinks=True)
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True)
    python = venv / "bin" / "python"
    pip = subprocess.run(
        [python, "-m", "pip", "install", "--quiet", "--disable-pip-version-check", str(source)],
        capture_output=True,
        text=True,
    )
    assert pip.returncode == 0, pip.stderr[-3000:]
    shutil.rmtree(source)  # the installed package cannot lean on the copy

    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV")}
    env.update(MPLBACKEND="Agg", PATH=f"{venv / 'bin'}{os.pathsep}{env.get('PATH', '')}")
    where = subprocess.run(
        [python, "-c", "import stewart_drake; print(stewart_drake.__file__)"],
        capture_output=True,
        text=True,
        cwd=elsewhere,
        env=env,
        check=True,
    )
    package = Path(where.stdout.strip()).parent
    assert venv in package.parents, f"imported from {package}, not the fresh venv"
    before = snapshot(package)

    out = elsewhere / "X"
    run = subprocess.run(
        [venv / "bin" / "stewart-drake", "report", "--quick", "--out", "X"],
        capture_output=True,
        text=True,
        cwd=elsewhere,
        env=env,
        timeout=900,
    )
    checks = json.loads((out / "checks.json").read_text())
    rows = checks["checks"] if isinstance(checks, dict) else checks
    failed = [r["what"] for r in rows if not r["passed"]]
    # the presets' declared findings fail (exit 1, shown in the report); nothing else may
    findings = tuple(f for fs in FINDINGS.values() for f in fs)
    assert len(rows) > 50 and [w for w in failed if not w.startswith(findings)] == [], failed
    assert run.returncode == (1 if failed else 0), run.stderr[-3000:]
    assert (out / "index.html").is_file()
    assert snapshot(package) == before, "the run changed files inside the installed package"
