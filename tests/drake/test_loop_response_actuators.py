"""The screw actuators' and hydraulic cylinders' small signals in the linear loop (``control.frequency``'s
``screw_plant_matrices``, ``hydraulic_plant_matrices``) against the nonlinear Drake loop with their laws stepped
by the tick loop: a set-point sine small enough to stay in the linearisation's range (a screw's leg velocity
inside the friction's and efficiency's blend, v_s = 10 mm/s, ``measure_point`` cutting the amplitude to that; a
cylinder's spool on the side that feeds the leakage) agrees with the model."""

import math

import pytest

from stewart_drake.api.response import loop_response
from stewart_drake.control.screw import FRICTION_SPEED

# a 0.1 µm sensor: the amplitudes are a few µm
FINE = {"sensors.resolution": "0.1um", "run.plant_step": "0.25ms", "controller.law": "float"}


@pytest.mark.parametrize("freq", [2.0, 20.0])
def test_screw_loop_measured_response_agrees(freq):
    r = loop_response("utn-dynamic", measure=[freq], **FINE, **{"actuators.model": "screw"})
    (p,) = r.measured
    # the 1 mm asked for is cut to keep the leg's peak velocity 2πf·A within a tenth of the blend's speed
    assert 2 * math.pi * freq * p.amplitude <= FRICTION_SPEED / 10 * (1 + 1e-12)
    assert abs(p.response[0] - p.linear[0]) <= p.tolerance[0], (p.response[0], p.linear[0], p.tolerance[0])
    assert p.tolerance[0] < 0.2 * abs(p.linear[0])


def test_the_screw_changes_the_loop():
    # the rotor's reflected mass and the blends' damping at rest slow the loop: a lower bandwidth than the lag's
    lag = loop_response("utn-dynamic", **{"controller.law": "float"})
    screw = loop_response("utn-dynamic", **{"controller.law": "float", "actuators.model": "screw"})
    assert screw.spectral_radius < 1 and screw.ok
    assert screw.bandwidth_hz < 0.5 * lag.bandwidth_hz


@pytest.mark.parametrize("freq", [10.0, 20.0])
def test_hydraulic_loop_measured_response_agrees(freq):
    # the cylinders linearised at the leakage's equilibrium (the valve on the side that feeds it): a sine small
    # enough to keep the spool there (0.1 mm: the velocity compensation's swing, a quarter of that opening)
    r = loop_response(
        "utn-dynamic",
        measure=[freq],
        amplitude=1e-4,
        **{**FINE, "sensors.resolution": "0.01um", "actuators.model": "hydraulic"},
    )
    (p,) = r.measured
    assert r.spectral_radius < 1
    assert p.agrees, (p.response, p.linear, p.tolerance)
    assert p.tolerance[0] < 0.1 * abs(p.linear[0])
