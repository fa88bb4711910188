"""``size`` of a machine with screw actuators or hydraulic cylinders: the motors' current, torque and speed (the
valves' opening, pressures and flows) along the motion against the force and speed the leg table shows (an
ideal screw is a fixed ratio of them, a cylinder's flow its areas times the speed), and a limit exceeded is a
violation (exit 1, the tables shown)."""

import math

import numpy as np
import pytest

import stewart_drake as sd
from stewart_drake.cli import main
from stewart_drake.spec.load import load_machine

SCREW = ["actuators.model=screw", "actuators.lead=10mm", "actuators.torque_constant=0.2"]
IDEAL = ["actuators.efficiency=1", "actuators.coulomb_friction=0", "actuators.viscous_friction=0"]


def test_an_ideal_screws_motor_is_the_legs_force_and_speed_through_the_lead():
    m = load_machine("utn-dynamic", [*SCREW, *IDEAL, "actuators.rotor_inertia=0"])
    d = sd.size(m, "seed").to_dict()
    rho = 2 * math.pi / 0.01  # rad per metre of travel
    for leg, motor in zip(d["legs"], d["motor"]["legs"]):
        # F = ρ·Kt·i and ω = ρ·L̇ exactly; the RMS current by trapezoid against the table's mean of samples:
        # the same to the end samples' weight, 1/n of a sample
        assert motor["peak_current_a"] == pytest.approx(leg["peak_force_n"] / (rho * 0.2), rel=1e-12)
        assert motor["peak_torque_nm"] == pytest.approx(leg["peak_force_n"] / rho, rel=1e-12)
        assert motor["peak_speed_rad_s"] == pytest.approx(leg["peak_speed_m_s"] * rho, rel=1e-12)
        assert motor["rms_current_a"] == pytest.approx(leg["rms_force_n"] / (rho * 0.2), rel=2 / d["samples"])


def test_the_rotor_and_friction_add_to_the_current():
    ideal = sd.size(load_machine("utn-dynamic", [*SCREW, *IDEAL, "actuators.rotor_inertia=0"]), "seed").to_dict()
    real = sd.size(load_machine("utn-dynamic", SCREW), "seed").to_dict()
    a = np.array([r["rms_current_a"] for r in ideal["motor"]["legs"]])
    b = np.array([r["rms_current_a"] for r in real["motor"]["legs"]])
    assert (b > a).all()


def test_a_motor_limit_exceeded_exits_1_with_the_tables(tmp_path, capsys):
    m = load_machine("utn-dynamic", [*SCREW, "actuators.max_motor_speed=10"])  # rad/s: 95 rpm
    r = sd.size(m, "seed")
    assert not r.ok and r.violation is None
    v = r.actuator_violation
    assert v["quantity"] == "speed" and v["limit_name"] == "max_motor_speed" and v["value"] > 10
    path = tmp_path / "screw.yaml"
    path.write_text(m.to_yaml())
    assert main(["size", "--platform", str(path), "--trajectory", "seed"]) == 1
    out, err = capsys.readouterr()
    assert "peak|i| A" in out and "screw actuators: lead 10 mm" in out
    assert "motor speed peaks at" in err and "actuators.max_motor_speed 10 rad/s" in err


def test_a_lag_machine_has_no_motor_section():
    assert "motor" not in sd.size(load_machine("utn-dynamic"), "seed").to_dict()


HYDRAULIC = ["actuators.model=hydraulic"]


def test_a_cylinders_supply_flow_is_the_pistons():
    m = load_machine("utn-dynamic", HYDRAULIC)
    hyd = m.actuators.hydraulic(m.platform)
    d = sd.size(m, "seed").to_dict()
    assert d["hydraulic"]["violation"] is None
    for leg, cyl in zip(d["legs"], d["hydraulic"]["legs"]):
        # the oil incompressible: A_A·L̇ extending, A_B·|L̇| retracting, so between A_B and A_A times the peak |L̇|
        q = cyl["peak_supply_flow_m3_s"]
        assert (
            hyd.rod_area * leg["peak_speed_m_s"] * (1 - 1e-12)
            <= q
            <= hyd.piston_area * leg["peak_speed_m_s"] * (1 + 1e-12)
        )
        assert 0 < cyl["peak_spool"] < 1


@pytest.mark.parametrize(
    "override, message",
    [
        (["actuators.valve_flow_gain=1e-9"], "valve opening peaks at"),  # an eighth of the default's
        (["actuators.piston_area=2e-7", "actuators.rod_area=1e-7"], "cylinder pressure needed peaks at"),  # 2 N, 1 N
    ],
)
def test_a_cylinder_limit_exceeded_exits_1(tmp_path, capsys, override, message):
    m = load_machine("utn-dynamic", [*HYDRAULIC, *override])
    assert not sd.size(m, "seed").ok
    path = tmp_path / "hydraulic.yaml"
    path.write_text(m.to_yaml())
    assert main(["size", "--platform", str(path), "--trajectory", "seed"]) == 1
    out, err = capsys.readouterr()
    assert "hydraulic cylinders: supply" in out and message in err
