"""The example notebooks (``notebooks/*.py``, jupytext percent scripts). The site build executes every one of them
and shows it with its outputs (``tests/docs/test_site.py``); here, the route a user takes by hand:
``jupytext --to notebook --execute`` under ``scripts/with-venv``'s environment (``MPLBACKEND=Agg``) finds the
``python3`` kernel the notebooks name, draws the figures inline, imports the working tree's package, and leaves
nothing in the temporary directory or the source tree."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import jupytext
import pytest

ROOT = Path(__file__).resolve().parents[2]
NOTEBOOKS = sorted((ROOT / "notebooks").glob("*.py"))
# The kernel reports which package it imported, after the notebook's own cells.
PROBE = "\n# %%\nimport stewart_drake as _sd, os as _os; print('PACKAGE', _os.path.dirname(_sd.__file__))\n"


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
def test_notebook_names_its_kernel_and_draws_inline(path):
    """A notebook without a kernelspec makes ``jupytext --execute`` fail ("No kernel found"); one without
    ``%matplotlib inline`` shows no figure where ``MPLBACKEND=Agg`` is set (as ``scripts/with-venv`` sets it)."""
    nb = jupytext.read(path)
    assert nb.metadata["kernelspec"]["name"] == "python3"
    code = [c.source for c in nb.cells if c.cell_type == "code"]
    assert code[0].startswith("%matplotlib inline")
    assert "mkdtemp" not in path.read_text(encoding="utf-8"), "a mkdtemp folder outlives the notebook"


def test_jupytext_execute_as_a_user_runs_it(tmp_path):
    """``jupytext --to notebook --execute`` on the design-check notebook (the quickest) with ``MPLBACKEND=Agg``:
    figures in the outputs, the working tree's package imported, the temporary directory left empty."""
    work, scratch = tmp_path / "work", tmp_path / "tmp"
    work.mkdir()
    scratch.mkdir()
    source = work / "design_check.py"
    source.write_text((ROOT / "notebooks" / "design_check.py").read_text(encoding="utf-8") + PROBE, encoding="utf-8")
    env = {**os.environ, "MPLBACKEND": "Agg", "TMPDIR": str(scratch), "PYTHONDONTWRITEBYTECODE": "1"}
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")])
    before = tree_state()
    r = subprocess.run(
        [sys.executable, "-m", "jupytext", "--to", "notebook", "--execute", source.name],
        cwd=work,
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert r.returncode == 0, r.stderr[-3000:]
    assert tree_state() == before, "the notebook wrote into the source tree"
    nb = json.loads((work / "design_check.ipynb").read_text(encoding="utf-8"))
    outputs = [o for c in nb["cells"] if c["cell_type"] == "code" for o in c.get("outputs", [])]
    assert sum("image/png" in o.get("data", {}) for o in outputs) >= 1
    printed = "".join("".join(o.get("text", "")) for o in outputs)
    assert f"PACKAGE {ROOT / 'stewart_drake'}" in printed
    assert sorted(p.name for p in scratch.iterdir()) == [], "the notebook left files in the temporary directory"
