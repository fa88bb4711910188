"""``stewart-drake dynamics``."""

import json

import numpy as np

import stewart_drake.core.dynamics as D
from stewart_drake.cli import main
from stewart_drake.core.geometry import load_preset


def test_seed_json_matches_library(capsys):
    assert main(["dynamics", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["platform"] == "utn-dynamic" and out["coriolis"] is True
    t = np.array(out["t"])
    assert len(t) == 41 and t[-1] == 4.0
    q, qd, qdd = D.seed_trajectory(t)
    np.testing.assert_allclose(out["forces"], D.leg_forces(load_preset("utn-dynamic"), q, qd, qdd), rtol=1e-12)


def test_csv_file_in_degrees_and_csv_out(tmp_path, capsys):
    p = load_preset("utn-dynamic")
    t = np.linspace(0, 2, 201)
    q, qd, qdd = D.harmonic_trajectory(t, [0, 0, 0.7, 0, 0, 0], [0.01, 0, 0, 0, 0, 0.3], 2.0)
    path = tmp_path / "traj.csv"
    rows = np.c_[t, q[:, :3] * 1e3, np.degrees(q[:, 3:])]
    path.write_text("t,px,py,pz,a,b,g\n" + "\n".join(",".join(f"{v:.12g}" for v in r) for r in rows))
    assert (
        main(
            [
                "dynamics",
                "--trajectory",
                str(path),
                "--length-unit",
                "mm",
                "--angle-unit",
                "deg",
                "--csv",
                "--coriolis",
                "off",
            ]
        )
        == 0
    )
    lines = capsys.readouterr().out.strip().splitlines()
    assert lines[0] == "t,F1,F2,F3,F4,F5,F6" and len(lines) == 202
    F = np.array([[float(x) for x in ln.split(",")[1:]] for ln in lines[1:]])
    exact = D.leg_forces(p, q, qd, qdd, coriolis=False)
    # Derivatives from a cubic spline through 10 ms samples: the interior is good to ~1e-4 relative.
    assert np.abs(F[20:-20] - exact[20:-20]).max() < 1e-3


def test_19_column_file_is_exact(tmp_path, capsys):
    t = np.linspace(0, 1, 5)
    q, qd, qdd = D.harmonic_trajectory(t, [0, 0, 0.7, 0, 0, 0], [0, 0.01, 0, 0.2, 0.1, 0.3], 3.0)
    path = tmp_path / "traj.csv"
    np.savetxt(path, np.c_[t, q, qd, qdd], delimiter=",")
    assert main(["dynamics", "--trajectory", str(path), "--json", "--legs", "on"]) == 0
    out = json.loads(capsys.readouterr().out)
    np.testing.assert_allclose(
        out["forces"], D.leg_forces_with_legs(load_preset("utn-dynamic"), q, qd, qdd), rtol=1e-12
    )


def test_bad_input_exits_2_with_one_line(tmp_path, capsys):
    path = tmp_path / "bad.csv"
    path.write_text("0,0,0,0.7,0,0,0\n0.1,0,0,0.7,0,0\n")
    assert main(["dynamics", "--trajectory", str(path)]) == 2
    err = capsys.readouterr().err
    assert "bad.csv:2: expected 7 values" in err and len(err.strip().splitlines()) == 1
    assert main(["dynamics", "--trajectory", str(tmp_path / "none.csv")]) == 2
    assert "does not exist" in capsys.readouterr().err


def test_singular_trajectory_exits_2_naming_the_sample(tmp_path, capsys):
    path = tmp_path / "lock.csv"
    t = np.linspace(0, 1, 6)
    rows = np.c_[t, np.zeros(6), np.zeros(6), np.full(6, 0.7), np.linspace(0, 90, 6), np.zeros(6), np.zeros(6)]
    np.savetxt(path, rows, delimiter=",")
    assert main(["dynamics", "--trajectory", str(path), "--angle-unit", "deg"]) == 2
    assert "sample 6:" in capsys.readouterr().err
