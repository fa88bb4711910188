"""The screw actuators' small signal in the linear loop (``control.frequency.screw_plant_matrices``) against the
nonlinear Drake loop with the screw law stepped by the tick loop: a set-point sine small enough that the leg's
velocity stays inside the friction's and efficiency's blend (v_s = 10 mm/s; ``measure_point`` cuts the
amplitude to that) agrees with the model."""

import math

import pytest

from stewart_drake.api.response import loop_response
from stewart_drake.control.screw import FRICTION_SPEED
from stewart_drake.errors import ResponseError

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


def test_a_hydraulic_machine_is_refused_naming_the_model():
    with pytest.raises(ResponseError, match=r"^actuators.model hydraulic: the loop's linear model holds the lag"):
        loop_response("utn-dynamic", **{"actuators.model": "hydraulic"})
