"""The API and the command line give the same numbers for calibration (``calibrate``, ``plan-measurements``,
``simulate-measurements``), design synthesis (``optimize``, ``workspace --require-box --prove``) and the firmware
certificate (``firmware certify``, with ``--tick``): each command's ``--json`` equals its API function's
``to_dict()``, on a preset and on a YAML platform of the test's own where the command takes any platform.

Tolerance as in ``test_api_matches_cli.py`` (1e-12 relative): where the CLI takes mm or degrees the test types
them and gives the API the SI value by one product, so both sides compute from floats a few ulps apart at most.
Counts, statuses and strings must be equal. Fields that are wall-clock times are removed before comparing.
"""

from __future__ import annotations

import json
import math
from importlib import resources

import numpy as np
import pytest

import stewart_drake as sd
from stewart_drake.cli import main
from tests.api.test_api_matches_cli import OWN_YAML, assert_same

DEG = math.pi / 180.0


@pytest.fixture(scope="module")
def own_yaml(tmp_path_factory):
    path = tmp_path_factory.mktemp("platform") / "mine.yaml"
    path.write_text(OWN_YAML)
    return str(path)


@pytest.fixture(params=["utn-dynamic", "own"])
def platform_arg(request, own_yaml):
    return own_yaml if request.param == "own" else request.param


def cli_json(capsys, *argv) -> tuple[int, dict]:
    rc = main([str(a) for a in argv])
    return rc, json.loads(capsys.readouterr().out)


def without_times(d):
    """``d`` without its wall-clock fields (``seconds``), at any depth."""
    if isinstance(d, dict):
        return {k: without_times(v) for k, v in d.items() if k != "seconds"}
    if isinstance(d, list):
        return [without_times(v) for v in d]
    return d


def test_plan_and_simulate_measurements_and_calibrate(capsys, platform_arg, tmp_path):
    """plan-measurements → simulate-measurements → calibrate, each command against its API function, on the
    same synthetic data; and the calibration is a calibration: on the held-out poses the calibrated model
    predicts the true machine's readings better than the nominal (the truth is drawn with ±1 mm anchors)."""
    # plan: a ±20 mm, ±4° box typed in mm/deg at the command line, given in m/rad to the API
    plan = sd.plan_measurements(platform_arg, 30, workspace=(20 * 1e-3, 20 * 1e-3, 15 * 1e-3, 4 * DEG), candidates=300)
    rc, cli = cli_json(capsys, "plan-measurements", "--platform", platform_arg, "--poses", 30, "--workspace", 20, 20,
                       15, 4, "--candidates", 300, "--out", tmp_path / "plan", "--json")  # fmt: skip
    assert rc == 0
    assert_same(plan.to_dict(), cli)
    assert plan.poses.shape == (30, 6) and plan.program().count("\n") > 30
    # simulate the measurements of a machine drawn around the nominal at the planned poses (the CLI's CSV)
    poses_csv = tmp_path / "plan" / "poses.csv"
    sim = sd.simulate_measurements(platform_arg, poses_csv, seed=3)
    rc, cli = cli_json(capsys, "simulate-measurements", "--platform", platform_arg, "--poses", poses_csv,
                       "--seed", 3, "--out", tmp_path / "sim", "--json")  # fmt: skip
    assert rc == 0
    assert_same(sim.to_dict(), cli)
    measured = tmp_path / "sim" / "measurements.csv"
    assert sim.to_csv(tmp_path / "api.csv").read_text() == measured.read_text()
    # calibrate with a seeded holdout
    cal = sd.calibrate(platform_arg, measured, holdout=0.25, seed=1)
    rc, cli = cli_json(capsys, "calibrate", "--platform", platform_arg, "--measurements", measured,
                       "--holdout", 0.25, "--seed", 1, "--no-plots", "--out", tmp_path / "cal", "--json")  # fmt: skip
    assert rc == 0 and cal.converged
    assert_same(cal.to_dict(), cli)
    with pytest.raises(sd.StewartError, match=r"--holdout 0\.7: give a fraction in \(0, 0\.5\]"):
        sd.calibrate(platform_arg, measured, holdout=0.7)
    v = cal.to_dict()["validation"]
    assert v["calibrated"]["position"]["rms"] < 0.1 * v["nominal"]["position"]["rms"]
    # the calibrated platform: the command's file and Platform.to_yaml give the same anchors
    written = sd.load_platform(tmp_path / "cal" / "calibrated.yaml")
    again = sd.load_platform(cal.platform.to_yaml(tmp_path / "api.yaml"))
    for p in (written, again):
        np.testing.assert_allclose(p.base_anchors, cal.platform.base_anchors, rtol=0, atol=1e-12)
        np.testing.assert_allclose(p.top_anchors_per_leg, cal.platform.top_anchors_per_leg, rtol=0, atol=1e-12)


def test_calibrate_bad_split_is_one_error(tmp_path):
    """``holdout`` and ``validate`` together are refused by the API itself (the CLI's argparse group is not
    there to do it)."""
    with pytest.raises(sd.UsageError, match="not both"):
        sd.calibrate("utn-dynamic", tmp_path / "m.csv", holdout=0.2, validate=tmp_path / "v.csv")


def test_prove_workspace(capsys, platform_arg):
    """``workspace --require-box ... --prove`` (angles typed in degrees) against ``sd.prove_workspace`` (rad)."""
    box = [-0.01, 0.01, -0.01, 0.01, -0.01, 0.01, -2.0, 2.0, -2.0, 2.0, -3.0, 3.0]
    lo, hi = np.array(box[0::2]), np.array(box[1::2])
    lo[3:] *= DEG
    hi[3:] *= DEG
    r = sd.prove_workspace(platform_arg, lo, hi, limits="stroke,joints", joint_cone=45 * DEG, max_cells=2000)
    rc, cli = cli_json(capsys, "workspace", "--platform", platform_arg, "--prove", "--limits", "stroke,joints",
                       "--max-cells", 2000, "--json", "--require-box", *box)  # fmt: skip
    assert rc == (0 if r.proven else 1)
    assert_same(without_times(r.to_dict()), without_times(cli))
    assert r.proof.status in ("proven", "violated", "unresolved") and r.proof.cells_examined <= 2000


def test_prove_workspace_refuses_low_above_high():
    with pytest.raises(sd.UsageError, match="low is above high"):
        sd.prove_workspace("utn-dynamic", [0.01, 0, 0, 0, 0, 0], [0.0, 0, 0, 0, 0, 0])


def test_firmware_certify_with_tick(capsys):
    """``firmware certify --tick`` (tick error typed in mm) against ``sd.firmware.certify`` (m), and
    ``sd.firmware.certify_tick`` alone gives the same tick words."""
    box = ["pz=150..200", "a=-0.02..0.02"]
    r = sd.firmware.certify("utn-dynamic", box=box, max_cells=300, tick=True, tick_error=3 * 1e-3)
    rc, cli = cli_json(capsys, "firmware", "certify", "--platform", "utn-dynamic", "--box", *box, "--max-cells", 300,
                       "--tick", "--tick-error", 3, "--json")  # fmt: skip
    assert rc == (1 if r.saturation_possible else 0)
    assert_same(without_times(r.to_dict()), without_times(cli))
    tick = sd.firmware.certify_tick("utn-dynamic", tick_error=3e-3)
    assert_same(tick.to_dict(), r.to_dict()["tick"])
    with pytest.raises(sd.UsageError, match="^tick_error must be >= 0, got -0.001$"):
        sd.firmware.certify_tick("utn-dynamic", tick_error=-1e-3)


def test_optimize_small_budget(capsys, tmp_path):
    """``optimize`` (12 designs, in this process) against ``sd.optimize``: the same front, the same chosen
    design and proof; ``.pareto`` holds the front's rows in SI and marks the chosen one."""
    req = str(resources.files("stewart_drake") / "examples" / "seed_001_requirements.yaml")
    r = sd.optimize(req, budget=12, pop_size=12, workers=0)
    rc, cli = cli_json(capsys, "optimize", "--requirements", req, "--out", tmp_path / "o", "--budget", 12,
                       "--pop-size", 12, "--workers", 0, "--json")  # fmt: skip
    assert rc == (0 if r.ok else 1)
    assert_same(without_times(r.to_dict()), without_times(cli))
    front = r.pareto
    n = len(cli["search"]["front"])
    assert front["x"].shape == (n, len(front["variables"])) and front["chosen"].sum() == 1
    assert front["peak_force"].shape == (n,) and np.all(front["L_max"] > front["L_min"])
    assert isinstance(r.platform, sd.Platform) and r.platform.L_max == pytest.approx(r.synthesis.design["L_max"])
