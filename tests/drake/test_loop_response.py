"""The linear loop of ``control.frequency`` against the nonlinear Drake loop: a set-point sine through the real
law and the closed-chain plant, fitted, agrees with the model within ``drake.loop_response``'s tolerance (fit
error, quantisers, linearisation ∝ amplitude, the start's transient, the first-order integrator's ω·h)."""

import math

import pytest

from stewart_drake.api.response import loop_response

# a 1 µm sensor and a 0.25 ms plant step keep the quantiser and integrator terms of the tolerance small
FINE = {"sensors.resolution": "1um", "run.plant_step": "0.25ms"}


@pytest.mark.parametrize("freq", [2.0, 20.0])
def test_float_law_measured_response_agrees(freq):
    r = loop_response("utn-dynamic", measure=[freq], **FINE, **{"controller.law": "float"})
    (p,) = r.measured
    d = abs(p.response[0] - p.linear[0])
    assert d <= p.tolerance[0], (freq, p.response[0], p.linear[0], p.tolerance[0])
    # the tolerance is a few percent of the response, not a pass for anything
    assert p.tolerance[0] < 0.1 * abs(p.linear[0])


def test_fixed_law_fine_format_measured_response_agrees():
    # the finest 16-bit set-point word that still holds the longest leg (32767 LSB ≥ the stroke's end)
    r = loop_response(
        "utn-dynamic", measure=[20.0], **FINE, **{"controller.law": "fixed", "firmware.length_lsb": "30um"}
    )
    (p,) = r.measured
    assert abs(p.response[0] - p.linear[0]) <= p.tolerance[0]
    assert p.tolerance[0] < 0.1 * abs(p.linear[0])


def test_margins_of_the_designed_loop():
    r = loop_response("utn-dynamic", **{"controller.law": "float"})
    assert r.spectral_radius < 1
    # symmetric hexapod at home: every leg's loop has the same margins (to the frequency grid's interpolation)
    gms = [m["gain_margin_db"] for m in r.margins]
    assert max(gms) - min(gms) < 1e-6
    assert r.ok == (min(gms) >= 6.0 and min(m["phase_margin_deg"] for m in r.margins) >= 30.0)
    assert r.bandwidth_hz is not None and 0 < r.bandwidth_hz < 500
    assert math.isfinite(r.sensitivity_peak) and r.sensitivity_peak >= 1
