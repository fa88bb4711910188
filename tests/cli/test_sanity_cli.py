"""Physical-limit checks of the ``simulate`` command, which runs a Drake simulation: a reference the actuators cannot
follow exits 1 saying why (the numpy commands' limit checks: ``tests/core/test_sanity.py``)."""

import contextlib
import io
import json
import re

import pytest

from stewart_drake.cli import main


def cli(*argv):
    """``(exit code, stdout, stderr)`` of the CLI run in-process; an exception other than SystemExit
    (a traceback) fails the test."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            rc = main([str(a) for a in argv])
        except SystemExit as e:  # argparse
            rc = e.code
    return rc, out.getvalue(), err.getvalue()


def test_simulate_lost_tracking_exits_1(tmp_path):
    """A reference that jumps 60 mm in 2 ms at t = 0.05 s asks for far more than the actuators' force
    range: the legs fall tens of millimetres behind. The summary states the bound and the run exits 1
    saying why."""
    f = tmp_path / "step.csv"
    f.write_text("t,px,py,pz,ax,ay,az\n0,0,0,700,0,0,0\n0.05,0,0,700,0,0,0\n0.052,0,0,760,0,0,0\n0.3,0,0,760,0,0,0\n")
    rc, out, err = cli("simulate", "--trajectory", f, "--length-unit", "mm", "--angle-unit", "deg", "--out", tmp_path / "o", "--no-progress")
    summary = json.loads(out)
    assert rc == 1 and summary["tracking_bound_mm"] == pytest.approx(0.05 * 400)
    assert summary["max_leg_error_mm"] > summary["tracking_bound_mm"]
    assert re.search(r"tracking lost: the leg length error of leg \d exceeds 20\.0 mm \(0\.05 × the stroke range\) first at t = ", err)
    assert json.loads((tmp_path / "o" / "summary.json").read_text())["failures"] == summary["failures"] != []
