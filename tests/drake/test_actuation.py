"""``control.actuation.Actuation`` (the actuators the closed loop steps itself) against Drake's own
``drake.systems.Actuators`` (``Saturation`` and a discrete ``LinearSystem``): the lag's step and the saturation
give the same bits — random forces and commands over five decades, commands beyond the limit, several time
constants — and so does the lag's weight a = exp(−h/τ). The closed-loop logs are pinned against a Diagram
with ``Actuators`` in ``test_tick_loop.py``; this pins the arithmetic on far more values."""

import numpy as np
import pytest

from stewart_drake.control.actuation import Actuation
from stewart_drake.drake.systems import Actuators

MAX_FORCE = 300.0


@pytest.mark.parametrize("time_constant, step", [(2e-3, 1e-3), (5e-3, 1e-3), (1e-3, 5e-4)])
def test_lag_step_equals_drakes_linear_system(time_constant, step):
    act = Actuators(MAX_FORCE, time_constant, step)
    mine = Actuation.from_time_constant(MAX_FORCE, time_constant, step)
    ctx = act.lag.CreateDefaultContext()
    port = act.lag.get_input_port()
    saturation = act.GetSubsystemByName("saturation")
    sat_ctx = saturation.CreateDefaultContext()
    rng = np.random.default_rng(11)
    for _ in range(500):
        F = rng.normal(0, 1, 6) * 10.0 ** rng.uniform(-2, 3, 6)
        u = rng.normal(0, 1, 6) * 10.0 ** rng.uniform(-2, 3, 6)  # some beyond ±MAX_FORCE
        saturation.get_input_port().FixValue(sat_ctx, u)
        u_sat = saturation.get_output_port().Eval(sat_ctx)
        np.testing.assert_array_equal(mine.saturate(u), u_sat)
        ctx.SetDiscreteState(F)
        port.FixValue(ctx, u_sat)
        drake = act.lag.EvalUniquePeriodicDiscreteUpdate(ctx).get_vector(0).CopyToVector()
        np.testing.assert_array_equal(mine.step(F, u), drake)
        np.testing.assert_array_equal(act.lag.get_output_port().Eval(ctx), F)  # the force is the lag's state


def test_no_lag_is_the_saturated_command():
    mine = Actuation.from_time_constant(MAX_FORCE, 0.0, 1e-3)
    assert not mine.has_lag
    np.testing.assert_array_equal(
        mine.saturate([-400.0, -300.0, -1.5, 0.0, 299.9, 1e9]), [-300, -300, -1.5, 0, 299.9, 300]
    )
