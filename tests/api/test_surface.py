"""The public surface: ``python -m stewart_drake`` is the command line; ``import stewart_drake`` is light and its
numpy names work without pydrake; ``Platform.to_yaml`` round-trips; the ``Trajectory`` constructors; errors are
raised as the same ``StewartError``s the command line prints."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import stewart_drake as sd
from stewart_drake.cli import main

ROOT = Path(__file__).resolve().parents[2]
NO_DRAKE = str(ROOT / "tests" / "cli" / "_no_drake.py")
ENV = dict(os.environ, PYTHONPATH=str(ROOT), MPLBACKEND="Agg")


def test_python_m_stewart_drake_is_the_command_line(tmp_path):
    """Same output and exit status as the ``stewart-drake`` entry point (``cli.main``), for a good and a bad call."""
    for argv, rc in ((["ik", "--pose", "0", "0", "100", "0", "0", "0", "--json"], 0), (["ik", "--pose", "0"], 2)):
        m = subprocess.run([sys.executable, "-m", "stewart_drake", *argv], capture_output=True, text=True, env=ENV, cwd=tmp_path)  # fmt: skip
        cli = subprocess.run([sys.executable, "-m", "stewart_drake.cli", *argv], capture_output=True, text=True, env=ENV, cwd=tmp_path)  # fmt: skip
        assert (m.returncode, m.stdout, m.stderr) == (cli.returncode, cli.stdout, cli.stderr)
        assert m.returncode == rc
    v = subprocess.run([sys.executable, "-m", "stewart_drake", "--version"], capture_output=True, text=True, env=ENV)
    assert v.stdout.strip() == f"stewart-drake {sd.__version__}"


def test_import_is_light_and_numpy_names_work_without_pydrake():
    """With pydrake unimportable: ``import stewart_drake`` loads no Drake module, ik/fk/inverse_dynamics/
    stiffness work, and ``simulate`` fails on first use with the missing module named."""
    code = """
import sys
import stewart_drake as sd
assert not any(m.startswith(("pydrake", "stewart_drake.drake")) for m in sys.modules), "Drake loaded on import"
p = sd.load_platform("utn-dynamic")
r = sd.ik(p, [[0, 0, 0.7, 0, 0, 0], [0.01, 0, 0.71, 0, 0.02, 0]])
assert r.lengths.shape == (2, 6) and r.ok
f = sd.fk(p, r.lengths[1])
assert abs(f.solutions[0].pose - [0.01, 0, 0.71, 0, 0.02, 0]).max() < 1e-9
assert sd.inverse_dynamics(p, "seed").forces.shape == (41, 6)
assert sd.stiffness(p, p.home_pose(), 1e6).matrix.shape == (6, 6)
try:
    sd.simulate
except ModuleNotFoundError as e:
    print("simulate:", e.name)
"""
    r = subprocess.run([sys.executable, NO_DRAKE, "-c", code], capture_output=True, text=True, env=ENV, timeout=300)
    assert r.returncode == 0, r.stderr[-2000:]
    assert "simulate: pydrake" in r.stdout


def test_ik_is_vectorised_over_leading_dimensions():
    p = sd.load_platform("utn-dynamic")
    q = np.broadcast_to(p.home_pose(), (2, 3, 6)).copy()
    q[1, 2, 2] = 1.5  # out of stroke
    r = sd.ik(p, q)
    assert r.lengths.shape == (2, 3, 6) and r.within_stroke.shape == (2, 3)
    assert r.within_stroke.sum() == 5 and not r.within_stroke[1, 2]
    flat = sd.ik(p, q.reshape(-1, 6))
    assert np.array_equal(flat.lengths.reshape(2, 3, 6), r.lengths)
    assert r.violations[5] and not any(r.violations[:5])  # C order: the sixth pose


def test_errors_are_the_cli_messages(capsys):
    """The same StewartError: raised from Python, one line (exit 2) from the command line."""
    p = sd.load_platform("utn-dynamic")
    with pytest.raises(sd.StewartError) as e:
        sd.inverse_dynamics(p, "seed", gravity=500)
    assert main(["dynamics", "--platform", "utn-dynamic", "--gravity", "500", "--json"]) == 2
    assert str(e.value) in capsys.readouterr().err


def test_platform_to_yaml_round_trips(tmp_path):
    """Every preset and a platform built from explicit anchors: written, loaded back, equal bit for bit."""
    base = sd.load_platform("utn-dynamic")
    mine = sd.Platform.from_anchors(
        base.base_anchors, base.top_anchors_per_leg, base.stroke, name="mine", mass=5.0, com=base.com, inertia=base.inertia
    )  # fmt: skip
    assert mine.top_anchors.shape == (3, 3) and list(mine.leg_top) == [0, 0, 1, 1, 2, 2]
    for p in [sd.load_platform(n) for n in sd.presets()] + [mine]:
        path = p.to_yaml(tmp_path / f"{p.name}.yaml")
        q = sd.load_platform(path)
        for k in ("base_anchors", "top_anchors", "leg_top", "stroke", "com", "inertia", "rotation_centre"):
            assert np.array_equal(getattr(p, k), getattr(q, k)), (p.name, k)
        assert (p.mass, p.home_height, p.legs, p.name) == (q.mass, q.home_height, q.legs, q.name)
    with pytest.raises(sd.StewartError):  # never overwrites unasked
        mine.to_yaml(tmp_path / "mine.yaml")


def test_trajectory_constructors(tmp_path):
    p = sd.load_platform("utn-dynamic")
    seed = sd.Trajectory.seed()
    assert seed.duration == 4.0 and np.allclose(seed.pose(0.25), [-0.1, 0.1 * np.sin(0.5), 0.7, 0, 0, 0])
    fitted = sd.Trajectory.seed(p, fit=True)  # utn-dynamic is the platform the seed was made for: unchanged
    assert np.allclose(fitted.pose(np.linspace(0, 4, 9)), seed.pose(np.linspace(0, 4, 9)), atol=1e-12)
    rot = sd.Trajectory.rotating()
    q, qd, _ = rot.derivatives(np.array([0.1, 0.2]))
    h = 1e-6  # central difference of the pose against the exact rate (error ~h² q''')
    assert np.allclose((rot.pose(0.1 + h) - rot.pose(0.1 - h)) / (2 * h), qd[0], atol=1e-8)
    csv = tmp_path / "t.csv"
    csv.write_text("t,px,py,pz,a,b,g\n0,0,0,700,0,0,0\n1,10,0,700,0,0,90\n")
    t = sd.Trajectory.from_csv(csv, length_unit="mm", angle_unit="deg")
    assert t.name == "t" and np.allclose(t.pose(0.5), [0.005, 0, 0.7, 0, 0, np.pi / 4])
    prog = tmp_path / "p.stw"
    prog.write_text("units mm, deg\nmover(0, 0, 700, 0, 0, 0) en 0.5\nmove(x = 10) in 0.5\n")
    tp = sd.Trajectory.from_program(prog, p)
    assert tp.name == "p" and len(tp.moves) == 2 and np.allclose(tp.q[-1, :3], [0.01, 0, 0.7])


def test_simulation_result_animates(tmp_path):
    """``animate()`` records a self-contained Meshcat page that Jupyter shows inline; ``save`` never overwrites."""
    r = sd.simulate(sd.load_platform("utn-dynamic"), "seed", duration=0.02, engine="python")
    a = r.animate(fps=50)
    assert "<html" in a.html.lower() and "meshcat" in a.html.lower()
    assert a._repr_html_().startswith("<iframe srcdoc=")
    page = a.save(tmp_path / "run.html")
    assert page.read_text(encoding="utf-8") == a.html
    with pytest.raises(FileExistsError):
        a.save(page)
    assert set(r.to_dict()) >= {"max_leg_error_mm", "failures", "gains", "ticks"} and r.ok == (
        not r.verdict["failures"]
    )


def test_public_names_shared_with_internal_packages():
    """``sd.workspace``, ``sd.montecarlo``, ``sd.report``, ``sd.firmware`` are the public function (namespace),
    and attribute access still reaches the internal package of the same name, however it was imported."""
    import inspect

    import stewart_drake.workspace.grid  # noqa: F401  (the import system's binding must not replace sd.workspace)
    from stewart_drake import workspace as ws
    from stewart_drake.firmware import generate as generate_module
    from stewart_drake.workspace.limits import Limits

    assert ws is sd.workspace and ws.Limits is Limits  # the package's name, through the public object
    assert list(inspect.signature(sd.workspace).parameters)[:4] == ["platform", "orientation", "resolution", "limits"]
    assert sd.workspace(sd.load_platform("gonzalez-dutra-2009"), resolution=0.05).volume > 0
    assert callable(sd.firmware.generate) and sd.firmware.generate is not generate_module
    assert inspect.ismodule(generate_module) and callable(sd.report) and callable(sd.montecarlo)


def test_size_and_dynamics_take_a_trajectory_object():
    """A ``Trajectory`` gives the same sizing as its name (exact rates); one without exact rates (fitted) is
    differentiated by a cubic spline, whose error at dt = 1 ms on this smooth reference is far below 1e-6."""
    p = sd.load_platform("utn-dynamic")
    named = sd.size(p, "seed", dt=0.001).summary["set"]
    assert sd.size(p, sd.Trajectory.seed(), dt=0.001).summary["set"] == named
    splined = sd.size(p, sd.Trajectory.seed(p, fit=True), dt=0.001).summary["set"]
    assert abs(splined["peak_force_n"]["value"] / named["peak_force_n"]["value"] - 1) < 1e-6
    forces = sd.inverse_dynamics(p, sd.Trajectory.seed(), dt=0.1).forces
    assert np.array_equal(forces, sd.inverse_dynamics(p, "seed").forces)


def test_summary_says_where_the_ticks_ran():
    """``tick_loop`` names the loop that ran the ticks: the compiled kernel for the float law too (where a C
    compiler is found), the Python loop for engine python (``engine`` alone names the firmware's engine)."""
    from stewart_drake.system.c_build import compilers

    p = sd.load_platform("utn-dynamic")
    float_run = sd.simulate(p, "seed", duration=0.02, controller="float").to_dict()
    emulated = sd.simulate(p, "seed", duration=0.02, controller="fixed", engine="python").to_dict()
    assert float_run["tick_loop"] == ("compiled" if compilers() else "python")
    assert emulated["tick_loop"] == "python" and emulated["engine"] == "python"
