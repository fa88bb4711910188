"""``control.ripple``: the impulse-response sums against the frequency responses of ``control.frequency``
(Parseval), the bound's linearity in each step and its split by term."""

import numpy as np
import pytest

from stewart_drake.control.frequency import LoopModel
from stewart_drake.control.gains import ControllerConfig
from stewart_drake.control.ripple import SOURCES, quantisation_ripple
from stewart_drake.core.geometry import load_preset


@pytest.fixture(scope="module")
def model():
    p = load_preset("utn-dynamic")
    cfg = ControllerConfig.for_platform(p)
    t = cfg.timing
    return LoopModel.build(p, p.home_pose(), cfg.gains, t.sample_period, t.output_delay, 2e-3, 1e-3, None), cfg


def test_rms_estimate_is_parseval_of_the_frequency_responses(model):
    # Σ_k |h_k|² = T ∫ |H(f)|² df over one period of the spectrum (Parseval): the time-domain sums of ripple.py
    # against the loop's frequency responses from frequency.py, a second computation. From each source to the
    # command: the command word's u = S·e, the sensor's u = −c_y·S·e, the set-point's u = c_r·S·e.
    m, cfg = model
    T = m.T
    lsb, r, rng = 1e-3, 1e-5, cfg.timing.command_range
    rip = quantisation_ripple(m, lsb, r, rng)
    f = (np.arange(8_000) + 0.5) / 8_000 * (0.5 / T)  # midpoints of [0, Nyquist]: H(−f) = conj H(f)
    cr, cy = m.controller_response(f)
    _, S = m.loops(f)
    maps = {"length_lsb": cr[:, None, None] * S, "sensor": -cy[:, None, None] * S, "command_word": S}
    steps = {"length_lsb": lsb, "sensor": r, "command_word": rng / 32768}
    for src in rip.sources:
        H = maps[src.name]
        energy = np.mean(np.sum(np.abs(H) ** 2, axis=2), axis=0)  # (6,) mean over f of Σ_j |H_ij|²
        expected = np.sqrt(energy) * steps[src.name] / np.sqrt(12)
        # the midpoint rule on 8 000 points of responses smooth on that scale (well-damped loop): 0.5 %
        np.testing.assert_allclose(src.rms_N, expected, rtol=5e-3, err_msg=src.name)


def test_bound_is_linear_in_each_step_and_at_least_the_estimate(model):
    m, cfg = model
    a = quantisation_ripple(m, 1e-3, 1e-5, 200.0)
    b = quantisation_ripple(m, 2e-3, 1e-5, 200.0)
    sa, sb = {s.name: s for s in a.sources}, {s.name: s for s in b.sources}
    np.testing.assert_allclose(sb["length_lsb"].bound_N, 2 * sa["length_lsb"].bound_N, rtol=1e-12)
    np.testing.assert_allclose(sb["sensor"].bound_N, sa["sensor"].bound_N, rtol=1e-12)
    # a peak bound is never below an RMS of the same response: ‖h‖₁·q/2 ≥ ‖h‖₂·q/√12 (‖h‖₁ ≥ ‖h‖₂, 1/2 > 1/√12)
    for s in a.sources:
        assert np.all(s.bound_N >= s.rms_N)
    assert a.bound_N >= a.rms_N


def test_terms_split_the_bound_and_name_the_derivative(model):
    m, cfg = model
    rip = quantisation_ripple(m, 1e-3, 1e-5, 200.0)
    for s in rip.sources:
        # |Σ terms| ≤ Σ |terms| tick by tick: the terms' bounds add up to at least the source's
        assert sum(s.terms.values()) >= float(s.bound_N.max()) * (1 - 1e-12)
    sensor = {s.name: s for s in rip.sources}["sensor"]
    # one count through kd/T on its first tick (80 N·s/m / 1 ms × 10 µm = 0.8 N) against kp·count (0.03 N):
    # the derivative carries the sensor's ripple
    assert sensor.dominant_term == "D"
    assert [s.name for s in rip.sources] == list(SOURCES)
    # utn-dynamic at 1 mm: the IK's step is 100 sensor counts, so it dominates the ripple and the cause names it
    assert rip.dominant.name == "length_lsb" and rip.cause().startswith("length_lsb (1000 µm)")
