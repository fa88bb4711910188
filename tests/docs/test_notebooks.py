"""The example notebooks (``notebooks/*.py``, jupytext percent scripts) run as notebooks: each is converted by
jupytext and executed cell by cell by nbclient in the ``python3`` kernel of this environment, with the working
tree's package first on the kernel's path, a temporary folder as its working directory and ``TMPDIR``, and the
source tree checked unchanged afterwards (the notebooks write only into ``tempfile.mkdtemp()`` folders)."""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

import jupytext
import nbformat
import pytest
from nbclient import NotebookClient

ROOT = Path(__file__).resolve().parents[2]
NOTEBOOKS = sorted((ROOT / "notebooks").glob("*.py"))
# The kernel reports which package it imported, after the notebook's own cells.
PROBE = "import stewart_drake as _sd, os as _os; print('PACKAGE', _os.path.dirname(_sd.__file__))"


def tree_state() -> str:
    """Tracked changes and untracked files of the source tree (ignored files, e.g. caches, excluded)."""
    r = subprocess.run(
        ["git", "status", "--porcelain", "--untracked-files=all"], cwd=ROOT, capture_output=True, text=True
    )
    return r.stdout if r.returncode == 0 else pytest.skip("not a git checkout")


def test_the_four_examples_exist():
    names = {p.stem for p in NOTEBOOKS}
    assert {"design_check", "forward_kinematics", "controller_in_the_loop", "montecarlo_study"} <= names


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.stem)
def test_notebook_executes(path, tmp_path, monkeypatch):
    nb = jupytext.read(path)
    nb.cells.append(nbformat.v4.new_code_cell(PROBE))
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]))
    monkeypatch.setenv("PYTHONDONTWRITEBYTECODE", "1")
    monkeypatch.setenv("TMPDIR", str(tmp_path))
    monkeypatch.delenv("MPLBACKEND", raising=False)  # the kernel's inline backend draws the figures
    before = tree_state()
    NotebookClient(nb, kernel_name="python3", timeout=300, resources={"metadata": {"path": str(tmp_path)}}).execute()
    assert tree_state() == before, "the notebook wrote into the source tree"
    printed = "".join(o.get("text", "") for o in nb.cells[-1].outputs)
    assert f"PACKAGE {ROOT / 'stewart_drake'}" in printed
    images = sum("image/png" in o.get("data", {}) for c in nb.cells if c.cell_type == "code" for o in c.outputs)
    assert images >= 1, "every example draws at least one figure"
