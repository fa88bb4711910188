"""The DSP controller without Drake: timing and cycle model (``timing``), gain design and Q15 encoding
(``gains``), the float and fixed-point PID laws as plain classes (``laws``), the force feed-forward
(``feedforward``). ``stewart_drake.drake.systems`` wraps a law in a Drake ``LeafSystem``."""

from stewart_drake.control.feedforward import FeedforwardTable, feedforward_forces, feedforward_lead, initial_leg_forces
from stewart_drake.control.gains import (
                                         DESIGN_POSES,
                                         DIFF_SHIFT,
                                         HEAVY_MODE_DAMPING,
                                         ROUTH_FRACTION,
                                         STIFFNESS_MARGIN,
                                         UNKNOWN_POSE_STIFFNESS_FACTOR,
                                         ControllerConfig,
                                         FixedGains,
                                         PidGains,
                                         Q15Gain,
                                         counts_per_lsb,
                                         design_gains,
                                         design_pose_subset,
                                         leg_space_inertia,
                                         q15_gain,
                                         strut_stiffness,
)
from stewart_drake.control.laws import CONTROLLER_KINDS, STATUS, FixedPointLaw, FloatLaw
from stewart_drake.control.timing import (
                                         CROSSOVER_MARGIN,
                                         FEEDFORWARD_OPS_PER_LEG,
                                         ISR_OVERHEAD_CYCLES,
                                         LATENCY_MODES,
                                         ONLINE_FEEDFORWARD_OPS,
                                         PHASE_BUDGET,
                                         PID_OPS_PER_LEG,
                                         DspTiming,
                                         check_timing,
                                         loop_delay,
                                         tick_cycles,
)
from stewart_drake.errors import TimingError

__all__ = [
    "CONTROLLER_KINDS", "CROSSOVER_MARGIN", "DESIGN_POSES", "DIFF_SHIFT", "FEEDFORWARD_OPS_PER_LEG", "HEAVY_MODE_DAMPING",
    "ISR_OVERHEAD_CYCLES", "LATENCY_MODES", "ONLINE_FEEDFORWARD_OPS", "PHASE_BUDGET", "PID_OPS_PER_LEG", "ROUTH_FRACTION",
    "STATUS", "STIFFNESS_MARGIN", "UNKNOWN_POSE_STIFFNESS_FACTOR", "ControllerConfig", "DspTiming", "FeedforwardTable",
    "FixedGains", "FixedPointLaw", "FloatLaw", "PidGains", "Q15Gain", "TimingError", "check_timing", "counts_per_lsb",
    "design_gains", "design_pose_subset", "feedforward_forces", "feedforward_lead", "initial_leg_forces", "leg_space_inertia",
    "loop_delay", "q15_gain", "strut_stiffness", "tick_cycles",
]
