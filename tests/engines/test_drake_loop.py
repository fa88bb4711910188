"""The float-law loop of ``sd.simulate`` against the same loop on Pinocchio (``engines.dsp_loop``): the same law,
tick, output delay, actuators and start, only the plant differs, so the plates part by Drake's first-order step
error alone."""

import numpy as np
import pytest

import stewart_drake as sd
import stewart_drake.api.cross_check as C
from stewart_drake.core.geometry import load_preset
from stewart_drake.engines import cross_check as X

STATUS = X.engine_status()
pytestmark = pytest.mark.skipif(STATUS["pinocchio"] is not None, reason=str(STATUS["pinocchio"]))


@pytest.mark.parametrize("preset", ["utn-dynamic", "gonzalez-dutra-2009"])
def test_pinocchio_float_loop_parts_from_drakes_by_its_first_order_step_error(preset):
    r = C.drake_loop_check(load_preset(preset))
    h, h2 = r["fine"]["plant_step_s"]
    e, e2 = r["fine"]["position_m"]
    # Drake's CENIC step is first order and Pinocchio's RK4 fourth: the difference halves with the step (the
    # second-order share is below half the first while h is at most half the actuators' 2 ms lag)
    assert h2 == h / 2 and abs(e2 / e - 0.5) <= 0.25
    assert np.isclose(r["step_ratio"], e2 / e)
    # and it stays within Drake's local error ½ h² |a| summed over the run (a stable loop grows no step's error)
    assert 0 < e <= r["bound_m"]
    # leg lengths and plate rotation part by the same first-order error
    assert abs(r["fine"]["length_m"][1] / r["fine"]["length_m"][0] - 0.5) <= 0.25
    assert abs(r["fine"]["angle_rad"][1] / r["fine"]["angle_rad"][0] - 0.5) <= 0.25
    assert r["ok"]


def test_a_loop_with_other_semantics_is_caught(monkeypatch):
    """The engine's loop without the feed-forward that Drake's runs: a difference that does not shrink with the
    plant step, far above the step error's bound."""
    loop = C.dsp_loop
    monkeypatch.setattr(C, "dsp_loop", lambda *args: loop(*args[:-1], False))
    r = C.drake_loop_check(load_preset("utn-dynamic"))
    assert r["step_ratio"] > 0.75 and r["fine"]["position_m"][0] > r["bound_m"]
    assert r["ok"] is False


def test_cross_check_carries_the_drake_loop():
    r = sd.cross_check("utn-dynamic", engines=["pinocchio"], poses=10, samples=3)
    loop = r.engines["pinocchio"]["drake_loop"]
    assert loop["ok"] and loop["sensor_resolution_m"] > C.FINE_SENSOR  # the machine's sensor, then the fine one
    assert loop["position_m"] > 0  # the machine's sensor: shown, not judged
    assert r.to_dict()["engines"]["pinocchio"]["drake_loop"]["fine"]["plant_step_s"] == [1e-3, 5e-4]
