"""The model-based force feed-forward: the leg forces of the inverse dynamics (plate and legs) along the
reference, sampled at the controller's ticks and advanced by the loop's known delays.

On the DSP it is a table (six Q15 words per tick, written by the host with the pose table: 12 bytes per
tick, 12 kB per second at 1 kHz) and costs one ``L_deposit_h`` and one ``L_add`` per leg
(``timing.FEEDFORWARD_OPS_PER_LEG``, in the cycle model). Computing it on the DSP instead would take the
inverse dynamics per tick (``timing.ONLINE_FEEDFORWARD_OPS``: a linearised model F = F_home + M_L·L̈_ref,
36 multiply-accumulates and the second differences, is ~150 cycles; the full model with the Jacobian solve
is several thousand cycles, more than the IK).
"""

from __future__ import annotations

import pickle

import numpy as np

from stewart_drake.control.gains import ControllerConfig
from stewart_drake.core import leg_forces_kernel
from stewart_drake.core.distinct import distinct_rows
from stewart_drake.core.dynamics import leg_forces_with_legs
from stewart_drake.core.geometry import Platform
from stewart_drake.core.trajectory import Trajectory
from stewart_drake.system.memo import Memo, digest


def feedforward_lead(config: ControllerConfig, actuator_lag: float) -> float:
    """Seconds by which the feed-forward table leads the reference: a force computed at tick k is
    released after the output delay, held for a sample (on average half of it) and reaches the plate
    through the actuator lag (a first-order lag τ delays slow signals by τ)."""
    return config.timing.output_delay + config.timing.sample_period / 2 + actuator_lag


def feedforward_forces(
    platform: Platform, trajectory: Trajectory, times, lead: float, h: float, engine: str = "numpy"
) -> np.ndarray:
    """``(n, 6)`` feed-forward leg forces (N) at ``times`` (n,): ``dynamics.leg_forces_with_legs`` at the
    reference pose of t + ``lead``, with its rates from central differences of step ``h`` (the sample
    period: the second difference of the sampled reference, bounded also for piecewise-linear CSV
    references). ``engine``: ``"numpy"`` (the reference, what the analyses of a run compare with) or ``"c"``
    (``core.leg_forces_kernel``: within its ``RELATIVE_TOLERANCE`` of numpy's; numpy where it is not built).
    Computed ``CHUNK_ROWS`` ticks at a time; tables of more than one row are remembered (``TABLE_CACHE``) and
    read-only."""
    t = np.asarray(times, dtype=float).reshape(-1) + lead
    engine = "c" if engine == "c" and leg_forces_kernel.engine() == "c" else "numpy"
    if len(t) < 2:
        return _table(platform, trajectory, t, h, engine)
    try:  # the inputs by value: the platform, the reference (its pose function and data), times, step, engine
        key = digest(pickle.dumps((platform, trajectory, h, engine), protocol=5), t.tobytes())
    except (pickle.PicklingError, TypeError, AttributeError):  # a reference built around a local function
        return _table(platform, trajectory, t, h, engine)

    def compute() -> np.ndarray:
        table = _table(platform, trajectory, t, h, engine)
        table.flags.writeable = False
        return table

    return TABLE_CACHE.get(key, compute)


def feedforward_engine(controller: str) -> str:
    """Which inverse dynamics computes the tables (``FeedforwardTable``) of a loop with the ``controller`` law
    (``"fixed"`` or ``"float"``) here: ``"c"`` (``core.leg_forces_kernel``, compiled once per source into the
    shared build cache; a batch it cannot prove well-conditioned runs numpy) for the fixed-point law, which reads
    the table as Q15 words, so that the tolerance reaches its log only where it moves a word across a rounding
    boundary; ``"numpy"`` (``dynamics.leg_forces_with_legs``, the reference) for the float law, whose log would
    carry every last bit, and everywhere without a C compiler. The run's summary records it."""
    return leg_forces_kernel.engine() if controller == "fixed" else "numpy"


CHUNK_ROWS = 4096  # ticks at a time: the numpy inverse dynamics' temporaries are ~7 kB a row


def _table(platform: Platform, trajectory: Trajectory, t, h: float, engine: str) -> np.ndarray:
    """``(n, 6)`` the forces at the reference times ``t`` (n,), ``CHUNK_ROWS`` at a time (the pose functions and
    the inverse dynamics are elementwise over rows: the same numbers as one batch), so that the working memory
    is bounded whatever the length of the run: only the ``(n, 6)`` result grows with it."""
    out = np.empty((len(t), 6))
    for s in range(0, len(t), CHUNK_ROWS):
        tc = t[s : s + CHUNK_ROWS]
        qm, q0, qp = trajectory.pose(tc - h), trajectory.pose(tc), trajectory.pose(tc + h)
        qd, qdd = (qp - qm) / (2 * h), (qp - 2 * q0 + qm) / h**2
        if engine == "c":
            out[s : s + len(tc)] = leg_forces_kernel.leg_forces(platform, q0, qd, qdd)
        else:
            out[s : s + len(tc)] = _forces_of_distinct_rows(platform, q0, qd, qdd)
    return out


def _forces_of_distinct_rows(platform: Platform, q, qd, qdd) -> np.ndarray:
    """``leg_forces_with_legs`` of each distinct (pose, rates, accelerations) row once, spread back over the
    ``(n, 6)`` rows (the same numbers: it is elementwise over rows; rows compared bit for bit): a held
    reference — the set-point step's rest pose (``drake.simulation.setpoint_step_gain``), a CSV that pauses —
    costs numpy one row per distinct state, not one per tick."""
    rows, inverse = distinct_rows(np.concatenate([q, qd, qdd], axis=1))
    if len(rows) == len(q):
        return leg_forces_with_legs(platform, q, qd, qdd)
    return leg_forces_with_legs(platform, *(np.ascontiguousarray(rows[:, k : k + 6]) for k in (0, 6, 12)))[inverse]


TABLE_CACHE = Memo(8)  # the last 8 feed-forward tables of this process


class FeedforwardTable:
    """``feedforward_forces`` of ``trajectory`` at tick times by ``engine`` (``feedforward_engine``'s), filled in one
    batch by ``prime(times)``; a time not in the table is computed on its own (same numbers)."""

    def __init__(self, platform: Platform, trajectory: Trajectory, lead: float, h: float, engine: str = "numpy"):
        self.platform, self.trajectory, self.lead, self.h, self.engine = platform, trajectory, lead, h, engine
        self._primed: tuple = (np.zeros(0), np.zeros((0, 6)))
        self._table: dict[float, np.ndarray] | None = None

    def prime(self, times) -> np.ndarray:
        """Compute the rows at ``times`` (n,) s in one batch and remember them; returns them, ``(n, 6)`` N
        (read-only: a table shared through ``TABLE_CACHE``)."""
        times = np.asarray(times, dtype=float)
        rows = feedforward_forces(self.platform, self.trajectory, times, self.lead, self.h, self.engine)
        self._primed, self._table = (times, rows), None
        return rows

    def force(self, t: float) -> np.ndarray:
        """``(6,)`` N at time ``t`` (s)."""
        if self._table is None:  # looked up by time only where asked to (a Drake source per tick)
            self._table = {float(ti): F for ti, F in zip(*self._primed)}
        F = self._table.get(float(t))
        if F is None:
            F = feedforward_forces(self.platform, self.trajectory, [t], self.lead, self.h, self.engine)[0]
        return F


def initial_leg_forces(platform: Platform, trajectory: Trajectory, t: float = 0.0, h: float = 1e-4) -> np.ndarray:
    """``(6,)`` leg forces (N) that move plate and legs along the reference at time ``t``
    (``dynamics.leg_forces_with_legs`` with central-difference rates): where the controller's integrator
    starts, so a run begins in equilibrium instead of with a gravity sag."""
    qm, q0, qp = trajectory.pose(np.array([t - h, t, t + h]))
    return leg_forces_with_legs(platform, q0, (qp - qm) / (2 * h), (qp - 2 * q0 + qm) / h**2)
