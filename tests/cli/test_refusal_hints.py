"""A refused output folder suggests only what the refused command offers (issue 24, item 3): ``--force``
where the command has it, else a folder of its own (a command replaces its own earlier files), and the
option the user typed (``--map``, not ``--out``). ``firmware generate``, ``montecarlo`` and ``stiffness
--map`` have no ``--force`` and suggested it."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

import stewart_drake as sd
from stewart_drake.errors import StewartError

ROOT = Path(__file__).resolve().parents[2]

CASES = {
    # command line (the folder is "busy"), the option refused, the command named, has --force
    "firmware-generate": (["firmware", "generate", "--platform", "utn-dynamic", "--out", "busy"], "--out", None),
    "montecarlo": (["montecarlo", "--platform", "utn-dynamic", "--runs", "2", "--out", "busy"], "--out", None),
    "stiffness-map": (
        ["stiffness", "--platform", "utn-dynamic", "--pose", "0", "0", "700", "0", "0", "0", "--map", "busy"],
        "--map",
        None,
    ),
    "workspace": (["workspace", "--platform", "utn-dynamic", "--out", "busy"], "--out", "--force"),
}
OWN = {"firmware-generate": "firmware generate", "montecarlo": "montecarlo", "stiffness-map": "stiffness"}


def refusal(argv, cwd) -> tuple[int, str]:
    env = dict(os.environ, PYTHONPATH=str(ROOT), MPLBACKEND="Agg")
    p = subprocess.run(
        [sys.executable, "-m", "stewart_drake.cli", *argv],
        cwd=cwd,
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
    )
    return p.returncode, p.stderr


@pytest.mark.parametrize("case", list(CASES))
def test_a_refusal_suggests_what_the_command_offers(tmp_path, case):
    argv, option, force = CASES[case]
    (tmp_path / "busy").mkdir()
    (tmp_path / "busy" / "notes.txt").write_text("mine\n")
    code, err = refusal(argv, tmp_path)
    lines = err.strip().splitlines()
    assert code == 2 and len(lines) == 1, err
    assert f"{option} 'busy'" in lines[0] and "notes.txt" in lines[0], err
    if force:
        assert "or --force to write beside them" in lines[0], err
    else:
        assert "--force" not in lines[0], err
        assert f"or one that `{OWN[case]}` wrote itself" in lines[0], err
    assert sorted(q.name for q in (tmp_path / "busy").iterdir()) == ["notes.txt"]  # nothing written


def test_the_api_suggests_its_own_argument(tmp_path):
    (tmp_path / "notes.txt").write_text("mine\n")
    with pytest.raises(StewartError, match=r"or force=True to write beside them"):
        sd.report(out=tmp_path)
