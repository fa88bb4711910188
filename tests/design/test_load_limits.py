"""Physics at the edges (issue 24, item 5d): an unstable loaded platform and a deflection beyond the linear
range are results outside limits (exit 1, no deflection number); damping the eigen-solve cannot resolve and a
massless plate are refused; modes beyond the rigid-body range are flagged; an infeasible motion is said
before the run; montecarlo's summary.json is strict JSON."""

import json

import numpy as np
import pytest

from stewart_drake.cli import main
from stewart_drake.control.feasibility import infeasible_motion
from stewart_drake.core.geometry import load_platform
from stewart_drake.core.trajectory import table_trajectory
from stewart_drake.design.load_limits import MAX_LEG_STRAIN, unstable_direction
from stewart_drake.design.payload import with_payload
from stewart_drake.design.stiffness import static_wrench, stiffness_matrix

POSE = ["--platform", "utn-dynamic", "--pose", "0", "0", "700", "0", "0", "0"]


def test_unstable_direction_is_one_the_plate_falls_along():
    """1e-300 N/m legs under a 1 kg payload: K is not positive definite, and along the direction named the
    exact (nonlinear) static wrench pushes the plate further (positive work), checked by a central
    difference of ``static_wrench``: an independent computation of the same physics."""
    p = with_payload(load_platform("utn-dynamic"), 1.0)
    q = np.array([0, 0, 0.7, 0, 0, 0.0])
    k = np.full(6, 1e-300)
    v = unstable_direction(stiffness_matrix(p, q, k))
    assert v is not None
    eps = 1e-6
    dW = (static_wrench(p, q, eps * v, k) - static_wrench(p, q, -eps * v, k)) / (2 * eps)
    assert float(v @ dW) > 0  # the wrench grows along the displacement: no restoring force
    assert unstable_direction(stiffness_matrix(p, q, np.full(6, 1e6))) is None


def test_stiffness_unstable_is_exit_1_without_a_deflection(capsys):
    rc = main(["stiffness", *POSE, "--leg-stiffness", "1e-300", "--payload", "1", "--json"])
    out, err = capsys.readouterr()
    res = json.loads(out)
    assert rc == 1 and res["deflection"] is None and "unstable" in res["limits"][0] and "unstable" in err


def test_deflection_beyond_the_linear_range_is_not_printed(capsys):
    """2 kN/m legs under 20 kg: the legs would change length by more than 1 %; the linear answer is not a
    number to print. With 1 MN/m legs the same load deflects ~µm: printed, exit 0."""
    rc = main(["stiffness", *POSE, "--leg-stiffness", "2e3", "--payload", "20"])
    out, err = capsys.readouterr()
    assert rc == 1 and "deflection under the payload (" not in out and "beyond the linear range" in err
    assert f"ends at {MAX_LEG_STRAIN * 100:g} %" in err
    rc = main(["stiffness", *POSE, "--leg-stiffness", "1e6", "--payload", "20", "--json"])
    res = json.loads(capsys.readouterr().out)
    assert rc == 0 and res["limits"] == [] and abs(res["deflection"][2]) < 1e-3


def test_modes_refuses_unresolvable_damping_and_flags_unstable(capsys):
    assert main(["modes", *POSE, "--leg-stiffness", "1e6", "--leg-damping", "1e300"]) == 2
    err = capsys.readouterr().err
    assert "--leg-damping 1e+300 N·s/m gives damping ratios" in err and err.count("\n") == 1
    assert main(["modes", *POSE, "--leg-stiffness", "1e-300", "--payload", "1"]) == 1
    assert "unstable" in capsys.readouterr().err


def test_modes_zero_inertia_and_tiny_mass(tmp_path, capsys):
    text = open("stewart_drake/examples/newcomer-150kg.yaml").read()
    f = tmp_path / "zero.yaml"
    f.write_text(text.replace("inertia: [30.0, 30.0, 55.0", "inertia: [0.0, 0.0, 0.0"))
    pose = ["--pose", "0", "0", "1200", "0", "0", "0"]
    assert main(["modes", "--platform", str(f), *pose]) == 2
    err = capsys.readouterr().err
    assert "mass matrix is not positive definite" in err and "LAPACK" not in err and "leading minor" not in err
    f.write_text(
        text.replace("mass: 150.0", "mass: 1.0e-30").replace(
            "inertia: [30.0, 30.0, 55.0", "inertia: [1e-30, 1e-30, 1e-30"
        )
    )
    main(["modes", "--platform", str(f), *pose, "--json"])
    res = json.loads(capsys.readouterr().out)
    assert res["frequencies_hz"][-1] > 1e15 and "axial resonance" in res["warnings"][0]


def test_a_step_in_one_millisecond_is_infeasible_before_the_run(tmp_path, capsys):
    """0.1 m up in 1 ms on utn-dynamic: ~1e5 m/s², tens of kN against 200 N; said before the run (exit 1,
    no output folder); the seed trajectory is feasible."""
    pytest.importorskip("pydrake")  # runs a Drake-backed command; the numpy-layer run (no pydrake) skips it
    t = np.arange(0, 1.0005, 1e-3)
    pz = np.where(t < 0.5, 0.7, 0.8)
    csv = tmp_path / "jump.csv"
    csv.write_text("t,px,py,pz,ax,ay,az\n" + "".join(f"{a:.3f},0,0,{b},0,0,0\n" for a, b in zip(t, pz)))
    out = tmp_path / "sim"
    assert main(["simulate", "--trajectory", str(csv), "--out", str(out), "--no-progress"]) == 1
    err = capsys.readouterr().err
    assert "the motion is infeasible: leg " in err and "(legs.max_force)" in err and not out.exists()
    p = load_platform("utn-dynamic")
    seed = table_trajectory("s", t, np.c_[-0.1 + 0 * t, 0.1 * np.sin(2 * t), 0.7 + 0 * t, 0 * t, 0 * t, 0 * t])
    assert infeasible_motion(p, seed, t[:-1], 1e-3) is None


def test_montecarlo_summary_is_strict_json(tmp_path):
    """Every run failed (NaN metrics, as ``run_scenario`` writes them): the worst run's metrics were bare
    NaN in summary.json; now null, strict JSON that a parser refusing NaN reads."""
    from stewart_drake.montecarlo.summary import METRICS, summarise, write_outputs

    nan = float("nan")
    rows = [
        {"run": i, "seed": i + 1, "gain_scale": 1.0 + i, **dict.fromkeys(METRICS, nan), "lost_tracking": True}
        | {"error": "RuntimeError: x", "wall_s": 0.1}
        for i in range(2)
    ]
    summary = summarise(rows, {"platform": "utn-dynamic"}, "k")
    write_outputs(tmp_path / "mc", rows, summary)

    def refuse(c):
        raise ValueError(c)

    res = json.loads((tmp_path / "mc" / "summary.json").read_text(), parse_constant=refuse)
    assert res["worst_run"]["max_leg_error_m"] is None and "worst_run.max_leg_error_m" in res["non_finite"]["paths"][0]
