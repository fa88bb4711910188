"""``envelope_peaks``: the plate-only ``envelope_sizing``'s peak force and speed without its acceleration bounds,
and ``condition_number``'s values, bit for bit (the synthesis's sampled check relies on them being those functions'
numbers)."""

from __future__ import annotations

import numpy as np
import pytest

from stewart_drake.core.geometry import load_platform
from stewart_drake.core.kinematics import condition_number
from stewart_drake.design.envelope import CHUNK, Envelope, EnvelopeError, envelope_peaks, envelope_sizing
from stewart_drake.design.payload import with_payload


@pytest.mark.parametrize("v_max", [[0.3, 0.3, 0.2, 1.0, 1.5, 2.0], [0.3, 0.0, 0.2, 0.0, 1.5, 0.0]])
def test_envelope_peaks_are_envelope_sizings_bit_for_bit(v_max):
    # an offset payload (every coupling term), more poses than one chunk (the chunking), some angular rates zero
    p = with_payload(load_platform("gonzalez-dutra-2009"), 40.0, [0.03, -0.02, 0.15])
    rng = np.random.default_rng(3)
    span = np.array([0.08, 0.08, 0.06, 0.12, 0.12, 0.15])
    poses = p.home_pose() + (2 * rng.random((CHUNK + 777, 6)) - 1) * span
    env = Envelope(poses, np.array(v_max), np.array([3.0, 4.0, 6.0, 12.0, 10.0, 20.0]))
    es = envelope_sizing(p, env, stroke=False)
    force, speed, cond = envelope_peaks(p, env, stroke=False)
    assert force.tobytes() == es.peak_force.tobytes()  # identical bits, not merely close
    assert speed.tobytes() == es.peak_speed.tobytes()
    assert cond.tobytes() == condition_number(p, poses).tobytes()


def test_envelope_peaks_checks_the_workspace_as_envelope_sizing():
    p = load_platform("gonzalez-dutra-2009")
    far = p.home_pose() + np.array([0.0, 0.0, 5.0, 0.0, 0.0, 0.0])  # 5 m up: beyond the stroke
    env = Envelope(far[None], np.full(6, 0.1), np.full(6, 1.0))
    with pytest.raises(EnvelopeError) as a:
        envelope_sizing(p, env)
    with pytest.raises(EnvelopeError) as b:
        envelope_peaks(p, env)
    assert str(a.value) == str(b.value)
