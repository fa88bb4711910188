"""A closed-loop run with the compiled feed-forward (``core.leg_forces_kernel``, the default) and the same run with
numpy's (the reference): the fixed-point law reads the table as Q15 words (``FixedPointLaw.feedforward_words``), so
the two runs can only part where the tolerance moves a word across a rounding boundary. Those ticks are listed;
before the first of them the logs are identical, and with none (these references) the whole logs are."""

from pathlib import Path

import numpy as np
import pytest

from stewart_drake.api.simulation import plan_run
from stewart_drake.control.simulation_log import SimulationLog
from stewart_drake.core import leg_forces_kernel
from stewart_drake.drake.simulation import build_simulation
from stewart_drake.spec import load_machine

DURATION = 0.3  # s: 300 ticks of the 1 kHz loop
NEWCOMER = Path(__file__).parents[2] / "examples" / "newcomer-210kg.yaml"


def _run(scenario, engine: str):
    sim = build_simulation(scenario)
    if engine:
        sim.feedforward.engine = engine
    sim.prepare(DURATION)
    table = sim.controller.feedforward
    return table, sim.controller.law.feedforward_words(table), sim.run(DURATION)


@pytest.mark.skipif(leg_forces_kernel.library() is None, reason="no C compiler")
@pytest.mark.parametrize(("machine", "trajectory"), [("utn-dynamic", "rotating"), ("newcomer", "rotating")])
def test_a_run_with_the_compiled_feedforward_is_the_reference_run_or_lists_its_boundary_ticks(machine, trajectory):
    machine = load_machine(NEWCOMER) if machine == "newcomer" else machine
    scenario = plan_run(machine, trajectory, "fixed", DURATION, engine="c").scenario
    table_c, words_c, log_c = _run(scenario, "")
    table_np, words_np, log_np = _run(scenario, "numpy")
    assert not np.array_equal(table_c, table_np)  # two computations (last bits), so the comparison means something
    boundary = np.flatnonzero(np.any(words_c != words_np, axis=1))  # ticks whose word the tolerance moved
    assert len(boundary) <= 1, f"feed-forward words differ at ticks {boundary.tolist()}"  # expected: very rare
    first = boundary[0] * scenario.config.timing.sample_period if len(boundary) else np.inf
    same = log_c.t < first  # the logs up to the first boundary tick
    assert np.count_nonzero(same) > 0
    for name in SimulationLog.ARRAYS:
        a, b = getattr(log_c, name), getattr(log_np, name)
        if name in ("t_ref", "reference"):
            np.testing.assert_array_equal(a, b)
        else:
            np.testing.assert_array_equal(a[same], b[same], err_msg=f"{name} before tick {first}")
    assert len(boundary) > 0 or np.all(same)
