"""Shared pieces of the property (fuzz) tests: an in-process CLI runner in a scratch folder, the
invariants every run must keep, and hypothesis settings for CI (bounded, derandomised) and for the
long ``-m fuzz`` run (``STEWART_FUZZ_EXAMPLES`` examples per test, default 5000: 20,000 in all; derandomised)."""

from __future__ import annotations

import contextlib
import io
import json
import os
import re
import shutil
import tempfile
from pathlib import Path

import pytest
from hypothesis import HealthCheck, settings

from stewart_drake.cli import main

ROOT = Path(__file__).resolve().parents[2]
FUZZ_EXAMPLES = int(os.environ.get("STEWART_FUZZ_EXAMPLES", "5000"))  # x 4 tests = 20,000
_HEALTH = list(HealthCheck)


def ci(n: int):
    """Settings for a CI property test: ``n`` examples, derandomised (the same every run)."""
    return settings(max_examples=n, derandomize=True, deadline=None, database=None, suppress_health_check=_HEALTH)


def fuzz(fn):
    """Mark a long property test: ``pytest -m fuzz``; ``FUZZ_EXAMPLES`` examples, derandomised."""
    fn = settings(
        max_examples=FUZZ_EXAMPLES, derandomize=True, deadline=None, database=None, suppress_health_check=_HEALTH
    )(fn)
    return pytest.mark.fuzz(fn)


PLATFORM_TEMPLATE = (ROOT / "stewart_drake" / "templates" / "platform-utn.yaml").read_text()
PROGRAM = (ROOT / "examples" / "circle.stw").read_text()


def scratch() -> Path:
    """A new scratch working folder with the files the argument vectors refer to."""
    d = Path(tempfile.mkdtemp(prefix="sd-fuzz-"))
    (d / "good.yaml").write_text(PLATFORM_TEMPLATE)
    (d / "bad.yaml").write_text("utn: {b: [1, 2\n")
    (d / "poses.csv").write_text("px,py,pz,a,b,g\n0,0,100,0,0,0\n10,0,120,0,5,0\n")
    (d / "traj.csv").write_text("t,px,py,pz,a,b,g\n" + "".join(f"{t / 10},0,0,0.7,0,0,0\n" for t in range(6)))
    (d / "prog.stw").write_text(PROGRAM)
    (d / "userdir").mkdir()
    (d / "userdir" / "notes.txt").write_text("the user's notes")
    (d / "afile.txt").write_text("the user's file")
    (d / "emptydir").mkdir()
    return d


def tree(folder: Path) -> dict:
    """Relative path -> file bytes (None for folders) of everything under ``folder``."""
    out = {}
    for root, dirs, files in os.walk(folder):
        for name in dirs:
            out[os.path.relpath(os.path.join(root, name), folder)] = None
        for name in files:
            p = os.path.join(root, name)
            out[os.path.relpath(p, folder)] = Path(p).read_bytes()
    return out


def run_cli(argv: list[str], cwd: Path) -> tuple[int, str, str]:
    """``main(argv)`` in ``cwd`` with stdout/stderr captured."""
    old = os.getcwd()
    out, err = io.StringIO(), io.StringIO()
    os.chdir(cwd)
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            rc = main(argv)
    finally:
        os.chdir(old)
    return rc, out.getvalue(), err.getvalue()


OUTPUT_OPTIONS = ("--out", "--write", "-o", "--output", "--write-sdf")
_PROGRAM_ERROR = re.compile(r"^[^:\n]+:\d+:\d+: [a-z ]*error: ")
_NONFINITE = re.compile(r"(?<![A-Za-z_])(nan|NaN|inf|Infinity)(?![A-Za-z_])")


def _allowed_targets(argv: list[str]) -> list[str]:
    """Paths (relative to the scratch folder) that a run may create or change: its output options'
    values, the default output folders, and single-file outputs' manifests."""
    targets = []
    for i, a in enumerate(argv[:-1]):
        if a in OUTPUT_OPTIONS:
            targets.append(os.path.normpath(argv[i + 1]))
    if argv and argv[0] in ("simulate", "report", "run") and "--out" not in argv:
        targets.append({"simulate": "simulation", "report": "report", "run": "runs"}[argv[0]])
    return targets


def check_run(argv: list[str], cwd: Path, before: dict, rc: int, out: str, err: str) -> None:
    """The invariants of any run: exit 0/1/2; no traceback and no 'internal error'; an exit 2 says
    why in one line; strict JSON for --json; no NaN/inf printed (the inputs are finite); nothing
    written outside the output options; the user's files unchanged."""
    where = f"argv={argv!r}\nrc={rc}\nstderr={err[-2000:]!r}"
    assert rc in (0, 1, 2), where
    assert "Traceback" not in err and "internal error" not in err, where
    if rc == 2:
        first = err.strip().splitlines()[0] if err.strip() else ""
        program_error = _PROGRAM_ERROR.match(first)  # file:line:column: kind: message, source line, caret
        assert first.startswith("stewart-drake") or program_error, where
        if not program_error:
            assert len(err.strip().splitlines()) == 1, where
    if "--json" in argv and rc in (0, 1) and out.strip():
        json.loads(out, parse_constant=lambda c: pytest.fail(f"non-JSON constant {c}\n{where}"))
    if rc in (0, 1):
        assert not _NONFINITE.search(out), f"non-finite number printed\n{where}\nstdout={out[-2000:]!r}"
    after = tree(cwd)
    allowed = _allowed_targets(argv)

    def ok(rel: str) -> bool:
        for t in allowed:
            if rel == t or rel.startswith(t.rstrip("/") + os.sep):
                return True
            parent = os.path.dirname(t)
            if os.path.basename(rel) == ".stewart-drake-manifest.json" and os.path.dirname(rel) == parent:
                return True
        return False

    changed = [k for k in set(before) | set(after) if before.get(k, b"") != after.get(k, b"") and not ok(k)]
    assert not changed, f"written outside the outputs: {sorted(changed)[:5]}\n{where}"
    for k, v in before.items():
        if v is not None and not ok(k) or k in ("userdir/notes.txt", "afile.txt"):
            assert after.get(k) == v, f"{k} changed or removed\n{where}"
    assert not [k for k in after if ".sd-tmp-" in k], f"temporary litter {sorted(after)}\n{where}"


def run_and_check(argv: list[str], folder: Path | None = None) -> tuple[int, str, str]:
    """Run ``argv`` in a (new) scratch folder and check ``check_run``; the folder is removed after."""
    d = folder or scratch()
    try:
        before = tree(d)
        rc, out, err = run_cli(argv, d)
        check_run(argv, d, before, rc, out, err)
        return rc, out, err
    finally:
        if folder is None:
            shutil.rmtree(d, ignore_errors=True)
