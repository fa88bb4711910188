"""Every analysis script runs on its own (quick mode), writes a report, and all its checks pass."""

import importlib.util
import json

import pytest

from stewart_drake.report import ANALYSES_DIR

SCRIPTS = sorted(p for p in ANALYSES_DIR.glob("*.py") if not p.name.startswith("_"))


@pytest.mark.parametrize("script", SCRIPTS, ids=[p.stem for p in SCRIPTS])
def test_analysis_smoke_runs(script, tmp_path):
    spec = importlib.util.spec_from_file_location(f"smoke_{script.stem}", script)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    out = tmp_path / "rep"
    rc = mod.main(["--quick", "--out", str(out)])
    checks = json.loads((out / "checks.json").read_text())
    failed = [c for c in checks if not c["passed"]]
    assert rc == 0 and not failed, failed
    assert checks, f"{script.name} recorded no checks"
    assert (out / "index.html").stat().st_size > 1000
