"""``stewart-drake run`` / ``compile``, the back ends, and the example programs."""

import csv
import json
import runpy
from pathlib import Path

import numpy as np
import pytest

from stewart_drake.cli import main
from stewart_drake.core.geometry import load_preset
from stewart_drake.script import compile_program
from stewart_drake.script.runtime import Motion

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
SEED = EXAMPLES / "seed_004.stw"


def test_seed_example_emits_the_seeds_matlab_lines(capsys):
    assert main(["compile", str(SEED), "--emit", "matlab"]) == 0
    assert capsys.readouterr().out.splitlines() == [
        "%%CÓDIGO DE MATLAB",
        "L = CinematicaInversa(100,120,300,25,10,0);",
        "T = DinamicaInversa(L)",
    ]


def test_matlab_unrolls_loops_and_notes_units(tmp_path, capsys):
    prog = tmp_path / "loop.stw"
    prog.write_text("FOR i := 1 TO 2 DO mover(10*i, 0, 150, 0, 0, 2.5) END\nwait 0.5\nunits m, rad\nmove(z = 0.2)\n")
    assert main(["compile", str(prog), "--emit", "matlab"]) == 0
    assert capsys.readouterr().out.splitlines() == [
        "%%CÓDIGO DE MATLAB",
        "L = CinematicaInversa(10,0,150,0,0,2.5);",
        "T = DinamicaInversa(L)",
        "L = CinematicaInversa(20,0,150,0,0,2.5);",
        "T = DinamicaInversa(L)",
        "% wait 0.5 s",
        "% units: m, rad",
        "L = CinematicaInversa(0.02,0,0.2,0,0,0.0436332312998582);",
        "T = DinamicaInversa(L)",
    ]


@pytest.mark.parametrize("example", sorted(p.name for p in EXAMPLES.glob("*.stw")))
def test_python_back_end_builds_the_same_motion(example, tmp_path, capsys):
    """The emitted Python, run on its own, builds bit-identical segments and trajectory."""
    platform = load_preset("utn-kinematic")
    src = (EXAMPLES / example).read_text()
    _, motion = compile_program(src, example, platform)
    target = tmp_path / "prog.py"
    assert main(["compile", str(EXAMPLES / example), "--emit", "python", "-o", str(target)]) == 0
    module = runpy.run_path(str(target))
    m2 = Motion.at_home(platform)
    module["program"](m2)
    assert len(m2.segments) == len(motion.segments) > 0
    for a, b in zip(motion.segments, m2.segments):
        assert (a.kind, a.duration, a.values, a.units) == (b.kind, b.duration, b.values, b.units)
        np.testing.assert_array_equal(a.q1, b.q1)
    np.testing.assert_array_equal(motion.trajectory().q, m2.trajectory().q)
    result = module["main"]()  # the module's own entry point: IK + forces
    assert " #1 to (" in capsys.readouterr().out
    np.testing.assert_array_equal(result.trajectory.q, motion.trajectory().q)


def test_python_back_end_mangles_python_keywords(tmp_path):
    prog = tmp_path / "kw.stw"
    prog.write_text("lambda = 1; print = 2; motion = 3\nmover(lambda, print, 100 + motion, 0, 0, 0)\n")
    target = tmp_path / "kw.py"
    assert main(["compile", str(prog), "--emit", "python", "-o", str(target)]) == 0
    code = target.read_text()
    assert "lambda_ = 1" in code and "print_ = 2" in code and "motion_ = 3" in code
    m = Motion.at_home(load_preset("utn-kinematic"))
    runpy.run_path(str(target))["program"](m)
    assert m.segments[0].values == (1, 2, 103, 0, 0, 0)


def test_run_writes_lengths_forces_and_plots(tmp_path, capsys):
    out = tmp_path / "seed"
    assert main(["run", str(SEED), "--out", str(out), "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert sorted(p.name for p in out.iterdir() if p.name != ".stewart-drake-manifest.json") == [
        "forces.png",
        "legs.csv",
        "lengths.png",
        "summary.json",
        "trajectory.csv",
    ]
    assert summary["platform"] == "utn-kinematic" and summary["samples"] == 101
    np.testing.assert_allclose(
        summary["moves"][0]["lengths_mm"], [583.334, 669.133, 508.944, 693.559, 624.865, 364.708], atol=1e-3
    )
    rows = list(csv.reader((out / "legs.csv").open()))
    assert rows[0] == ["t_s"] + [f"L{i}_mm" for i in range(1, 7)] + [f"F{i}_N" for i in range(1, 7)]
    assert len(rows) == 102 and float(rows[1][1]) == pytest.approx(473.1873, abs=1e-4)
    # trajectory.csv (t, q, q̇, q̈ in SI) is the 19-column input of `stewart-drake dynamics --trajectory`
    traj = np.loadtxt(out / "trajectory.csv", delimiter=",", skiprows=1)
    assert traj.shape == (101, 19)
    np.testing.assert_allclose(traj[-1, 1:7], [0.1, 0.12, 0.3, np.radians(25), np.radians(10), 0], atol=1e-15)


def test_run_other_platform_reports_reachability(tmp_path, capsys):
    """The seed's pose (mm scale) is far outside the metre-scale utn-dynamic preset's 0.55..0.95 m stroke."""
    assert main(["run", str(SEED), "--platform", "utn-dynamic", "--out", str(tmp_path / "x")]) == 2
    assert "is out of reach on platform utn-dynamic" in capsys.readouterr().err


def test_run_simulate_controller_in_the_loop(tmp_path, capsys):
    prog = tmp_path / "short.stw"
    prog.write_text("mover(0, 0, 110, 0, 0, 0) en 0.3\n")
    out = tmp_path / "sim"
    assert main(["run", str(prog), "--out", str(out), "--simulate", "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert (out / "simulation" / "log.csv").is_file() and (out / "simulation.png").is_file()
    assert summary["simulation"]["controller"] == "fixed"
    # simulate's defaults: the compiled firmware (a compiler is found here) on the default integrator
    assert summary["simulation"]["engine"] == "c" and summary["simulation"]["integrator"] == "cenic-fixed"
    assert len(summary["simulation"]["max_abs_length_error_mm"]) == 6
