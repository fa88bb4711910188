"""Physical-limit checks of the ``simulate`` command, which runs a Drake simulation: a trajectory out of stroke or
below the base refused before running, a platform without plate mass refused, absurd --plant-step/--period/--duration
refused before any work, and a reference the actuators cannot follow exits 1 saying why (the numpy commands' checks:
``tests/core/test_sanity.py``)."""

import re

import numpy as np
import pytest

from tests.core.test_sanity import NOPLATE, assert_refused_before_allocation, assert_refused_in_one_line, cli


@pytest.fixture
def noplate(tmp_path):
    f = tmp_path / "noplate.yaml"
    f.write_text(NOPLATE)
    return f


def test_simulate_infeasible_step_exits_1_before_running(tmp_path):
    """A reference that jumps 60 mm in 2 ms at t = 0.05 s asks for far more than the actuators' force
    range: said before the run (issue 24, 5d: it ran, lost tracking by tens of millimetres, or ended in a
    raw solver message), exit 1, nothing written."""
    f = tmp_path / "step.csv"
    f.write_text("t,px,py,pz,ax,ay,az\n0,0,0,700,0,0,0\n0.05,0,0,700,0,0,0\n0.052,0,0,760,0,0,0\n0.3,0,0,760,0,0,0\n")
    rc, out, err = cli(
        "simulate",
        "--trajectory",
        f,
        "--length-unit",
        "mm",
        "--angle-unit",
        "deg",
        "--out",
        tmp_path / "o",
        "--no-progress",
    )
    assert rc == 1 and out == "" and not (tmp_path / "o").exists()
    assert re.search(r"the motion is infeasible: leg \d needs a mean [\d.e+]+ N over the 0.05 s from t = 0.0", err)
    assert "more than the actuators' 200 N (legs.max_force)" in err


def test_tracking_verdict_names_lost_tracking():
    """The verdict's lost-tracking failure (a leg error beyond 5 % of the stroke range), on a synthetic log."""
    from stewart_drake.control.laws import STATUS
    from stewart_drake.control.simulation_log import SimulationLog, tracking_verdict
    from stewart_drake.core.geometry import load_platform

    p = load_platform("utn-dynamic")
    n = 100
    t = np.arange(n) * 1e-3
    z = np.zeros((n, 6))
    e = z.copy()
    e[60:, 2] = 0.03  # 30 mm on leg 3 from t = 0.06 s: beyond 20 mm
    status = np.zeros((n, len(STATUS)))
    log = SimulationLog("fixed", p.name, "x", 1e-3, t, z, z, z, z, z, status, t, z)
    v = tracking_verdict(p, e, z, log)
    assert v["tracking_bound_mm"] == pytest.approx(0.05 * 400)
    assert re.match(
        r"tracking lost: the leg length error of leg 3 exceeds 20\.0 mm \(0\.05 × the stroke range\) first at t = 0\.0600 s, "
        r"and reaches 30\.0 mm",
        v["failures"][0],
    )


def test_simulate_refuses_out_of_stroke_and_below_base_before_running(tmp_path):
    rc, out, err = cli(
        "simulate", "--platform", "utn-kinematic", "--duration", 0.5, "--out", tmp_path / "o", "--no-progress"
    )
    assert rc == 1 and out == "" and not (tmp_path / "o").exists()
    assert "the seed reference leaves the stroke: first at t = 0.0000 s, leg 1 length 891.074 mm" in err
    f = tmp_path / "below.csv"
    f.write_text("t,px,py,pz,ax,ay,az\n0,0,0,-0.7,0,0,0\n1,0,0,-0.7,0,0,0\n")
    rc, _, err = cli("simulate", "--trajectory", f, "--out", tmp_path / "o", "--no-progress")
    assert rc == 1 and "the below reference at t = 0.0000 s: the plate is below the base" in err


def test_missing_plate_is_an_error_for_dynamics_and_simulate_only(noplate, tmp_path):
    msg = (
        "platform 'noplate' has no plate mass properties (YAML key 'plate' missing, or its mass is 0): '{c}' needs plate.mass "
        "and plate.inertia (or plate.thickness and plate.density for a utn platform)"
    )
    rc, out, err = cli("dynamics", "--platform", noplate)
    assert rc == 2 and out == "" and err.strip() == "stewart-drake dynamics: error: " + msg.format(c="dynamics")
    rc, _, err = cli("simulate", "--platform", noplate, "--out", tmp_path / "o", "--no-progress")
    assert rc == 2 and err.strip() == "stewart-drake simulate: error: " + msg.format(c="simulate")
    assert cli("ik", "--platform", noplate, "--pose", 0, 0, 700, 0, 0, 0)[0] == 0
    assert cli("workspace", "--platform", noplate, "--resolution", 0.05)[0] == 0


@pytest.mark.parametrize(
    "argv, message",
    [
        (
            ("simulate", "--plant-step", "1", "--no-progress"),
            "--plant-step 1 s is longer than the controller period 0.001 s; the plant step must resolve the period (at most one period)",
        ),
        (
            ("simulate", "--period", "0.004", "--plant-step", "0.004", "--no-progress"),
            "--plant-step 0.004 s is longer than the actuators' time constant 0.002 s, the platform's fastest modelled dynamics",
        ),
        (
            ("simulate", "--period", "10", "--no-progress"),
            "--period 10 s is too slow for platform utn-dynamic: its fastest open-loop mode grows at 7.13/s",
        ),
    ],
)
def test_simulate_bad_options_exit_2_with_the_message(argv, message, tmp_path):
    assert_refused_in_one_line(argv, message, tmp_path)


@pytest.mark.parametrize(
    "argv, pattern",
    [
        (
            ("simulate", "--duration", "1e9", "--no-progress"),
            r"--duration 1000000000 s would need 1e\+12 plant steps of 0.001 s \(~10\^\d+ GB\); the limit is \S+ GB on this machine; use a shorter --duration",
        ),
        (
            ("simulate", "--duration", "7200", "--no-progress"),
            r"--duration 7200 s would need 7.2e\+06 plant steps of 0.001 s \(~2 h\); the limit is ~1 h",
        ),
    ],
)
def test_simulate_work_is_bounded_before_allocation(argv, pattern, tmp_path, monkeypatch):
    assert_refused_before_allocation(argv, pattern, tmp_path, monkeypatch)
