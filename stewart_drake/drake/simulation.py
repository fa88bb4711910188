"""Controller-in-the-loop simulation: trajectory source → DSP controller → actuators → closed-loop plant.

One typed, picklable ``Scenario`` describes a run (platform, reference, controller kind and engine, timing
and gains, actuators, integrator, sensor); ``build_simulation(scenario)`` assembles its Diagram and the
loop that drives it::

    reference rows ──▶ DSP tick (fixed | float law, period T) ──command──▶ actuators ──force (fixed input)──┐
        ▲  feed-forward rows ──▶ ▲ leg_lengths                                                              │
        │                        └──────── sensor (prismatic positions) ◀──── plant ◀─────────────────────┘
        └ (core.trajectory: seed, rotating, a (t, pose) CSV, a motion program)

The Diagram holds what runs in C++: the plant; the DSP's side and the actuators (saturation and lag,
``control.actuation``) run between ``Simulator.AdvanceTo`` calls, one compiled call per stop
(``drake.tick_loop``: the same numbers as a ``drake.systems.ControllerSystem`` and ``drake.systems.Actuators``
wired into the Diagram, bit for bit, without a Python call inside the simulator's step).

The feed-forward table (``control.feedforward``) holds, per tick, the leg forces of the inverse dynamics
(plate and legs) along the reference, advanced by the loop's known delays: what a host would compute
with the pose table and download to the DSP. Without it (``feedforward=False``) the PID alone carries
the plate. Both tables are filled for every tick of the run before it starts (``Simulation.prepare``)
and read by tick index.

Logs record, at every plant step, the plant state (pose and leg lengths come from it), the
controller's held command and set-point, its status (tick count, tick time, saturation counts) and the
actuator forces; the reference is logged at the controller's ticks. Everything is deterministic: the
same inputs give the same logs bit for bit (no randomness, no threads in the loop).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np
from pydrake.multibody.math import SpatialVelocity
from pydrake.systems.analysis import Simulator
from tqdm import tqdm

from stewart_drake.control.actuation import Actuation
from stewart_drake.control.feedforward import (
    FeedforwardTable,
    feedforward_engine,
    feedforward_lead,
    initial_leg_forces,
)
from stewart_drake.control.gains import ControllerConfig
from stewart_drake.control.hydraulic import HydraulicActuation
from stewart_drake.control.screw import ScrewActuation
from stewart_drake.control.simulation_log import SimulationLog
from stewart_drake.core.geometry import Platform
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.core.leg_bodies import leg_joint_positions
from stewart_drake.core.rotations import angles_from_matrix, quaternion_to_matrix, rotation_matrix
from stewart_drake.core.trajectory import Trajectory, constant_trajectory, design_poses, get_trajectory
from stewart_drake.design.hydraulic import HydraulicParameters
from stewart_drake.design.screw import ScrewParameters
from stewart_drake.drake.actuator_systems import set_reflected_inertia
from stewart_drake.drake.integrators import (
    CONTINUOUS,
    DEFAULT_INTEGRATOR,
    apply_integrator,
    check_integrator,
    constraint_gaps,
)
from stewart_drake.drake.loop_diagram import VISUALIZER_PERIOD, loop_diagram
from stewart_drake.drake.platform_model import set_pose
from stewart_drake.drake.systems import make_law
from stewart_drake.drake.tick_loop import IdealSensor, SensorReading, TickLoop, periodic_times
from stewart_drake.errors import SimulationError
from stewart_drake.firmware.pil import PilLaw
from stewart_drake.spec.machine import PilSpec

# ----------------------------------------------------------------------------------------------
# The scenario: what a run is, as plain data.


@dataclass(frozen=True)
class ActuatorModel:
    """Leg actuators: a force limit (N, None: the platform's ``legs.max_force``) and a first-order lag
    with time constant ``time_constant`` (s; 0: none); or with ``screw`` an electric screw actuator
    (``control.screw``: its current limit and current loop in place of both; the rotor's reflected mass on
    the plant's prismatic joints), or with ``hydraulic`` a valve-driven cylinder (``control.hydraulic``: its
    supply pressure and force loop in place of both), either stepped by the loop's Python ticks. The stroke end
    stops are the prismatic joints' limits in the plant (SAP enforces them as constraints)."""

    max_force: float | None = None
    time_constant: float = 2e-3
    screw: ScrewParameters | None = None
    hydraulic: HydraulicParameters | None = None

    @property
    def model(self) -> str:
        """``lag``, ``screw`` or ``hydraulic``."""
        return "screw" if self.screw is not None else "hydraulic" if self.hydraulic is not None else "lag"

    def __post_init__(self):
        if self.max_force is not None and not (math.isfinite(self.max_force) and self.max_force > 0):
            raise SimulationError(SimulationError.MAX_FORCE.format(value=self.max_force))
        if not (math.isfinite(self.time_constant) and self.time_constant >= 0):
            raise SimulationError(SimulationError.TIME_CONSTANT.format(value=self.time_constant))


@dataclass(frozen=True, eq=False)
class SensorModel:
    """A leg-length sensor that is not ideal: it reads L + ``offset`` (6,) m + ``noise[k]`` − ``jitter[k]``·dL/dt
    at tick k = round(t / ``period``) (``noise`` ``(n_ticks, 6)`` m, ``jitter`` ``(n_ticks,)`` s: a sample
    taken that late); the controller then quantises the reading."""

    offset: np.ndarray
    noise: np.ndarray
    jitter: np.ndarray
    period: float


@dataclass(frozen=True)
class Scenario:
    """One controller-in-the-loop run, as plain (picklable) data.

    ``platform``: the controller's model (and the plant's unless ``plant_platform``: a perturbed copy models
    manufacturing errors); ``trajectory``: ``seed``, ``rotating``, a CSV path or a ``Trajectory``;
    ``controller``: ``fixed`` or ``float``; ``engine``: ``python`` or ``c`` (the fixed-point tick by
    compiled C; ``firmware``: a user's C file implementing the firmware ABI); ``config``: timing and gains
    (refused if infeasible; None: ``ControllerConfig.for_platform`` with the actuators' lag over the
    reference's poses from 0 to ``design_duration`` s, ``design_poses``); ``actuators``; ``plant_time_step``
    (s): the discrete plant's step, or the continuous plant's logging period and fixed step; ``integrator``:
    one of ``integrators.INTEGRATORS`` (None: ``integrators.DEFAULT_INTEGRATOR``); ``feedforward``: connect
    the model-based force feed-forward table; ``sensor``: None (ideal) or a ``SensorModel``; ``duration`` (s): what ``simulate``
    runs (None: the trajectory's own duration, else 1 s); ``pil``: the tick computed on a target over the link
    (``firmware.pil``; None or no ``target``: on the host); ``seed``: the run's seed (the link faults' draws).
    """

    platform: Platform
    trajectory: object = "seed"
    controller: str = "fixed"
    config: ControllerConfig | None = None
    actuators: ActuatorModel = field(default_factory=ActuatorModel)
    plant_time_step: float = 1e-3
    feedforward: bool = True
    design_duration: float | None = None
    engine: str = "python"
    firmware: str | None = None
    integrator: str | None = None
    plant_platform: Platform | None = None
    sensor: SensorModel | None = None
    duration: float | None = None
    pil: PilSpec | None = None
    seed: int = 0


def set_velocity(plant, context, platform: Platform, trajectory: Trajectory, t: float, h: float = 1e-6) -> None:
    """Set every velocity in ``context`` to the reference's at time ``t`` (central differences of the
    closed-form joint positions, step ``h`` s), so that a run starts on the trajectory, not at rest."""
    qm, qp = trajectory.pose(np.array([t - h, t + h]))
    Rm, Rp = rotation_matrix(qm[3:]), rotation_matrix(qp[3:])
    W = (Rp - Rm) / (2 * h) @ rotation_matrix(trajectory.pose(t)[3:]).T  # [ω]×
    w = np.array([W[2, 1] - W[1, 2], W[0, 2] - W[2, 0], W[1, 0] - W[0, 1]]) / 2
    p_m = qm[:3] - Rm @ platform.rotation_centre
    p_p = qp[:3] - Rp @ platform.rotation_centre
    plant.SetFreeBodySpatialVelocity(context, plant.GetBodyByName("top"), SpatialVelocity(w, (p_p - p_m) / (2 * h)))
    (am, Lm), (ap, Lp) = leg_joint_positions(platform, qm), leg_joint_positions(platform, qp)
    for i in range(6):
        plant.GetJointByName(f"universal_{i + 1}").set_angular_rates(context, (ap[i] - am[i]) / (2 * h))
        plant.GetJointByName(f"prismatic_{i + 1}").set_translation_rate(context, (Lp[i] - Lm[i]) / (2 * h))


# ----------------------------------------------------------------------------------------------
# The Diagram.


@dataclass
class Simulation:
    """A built controller-in-the-loop Diagram and the loop that drives it, ready to run (see
    ``build_simulation``). ``controller``: the ``tick_loop.TickLoop`` (its ``law``, its tables
    ``reference`` and ``feedforward`` once ``prepare`` has filled them; it logs the plant's state and the
    actuators' force at every plant step)."""

    platform: Platform
    trajectory: Trajectory
    kind: str
    config: ControllerConfig
    diagram: object
    plant: object
    controller: TickLoop
    simulator: object = None
    meshcat: object = None
    visualizer: object = None
    plant_time_step: float = 1e-3
    feedforward: object = None
    integrator: str = "sap"
    _ran: bool = False
    _duration: float = 0.0
    _logs: dict = field(default_factory=dict)

    @property
    def tick_loop(self) -> str:
        """Where the ticks run: ``"compiled"`` (one C call per tick, ``firmware.loop_kernel``: the float law or
        the compiled firmware) or ``"python"`` (the reference loop: engine python, a replaced law, no compiler)."""
        return "python" if self.controller.kernel is None else "compiled"

    def close(self) -> None:
        """End what the run holds outside this process (a PIL target: QEMU stopped, the port closed)."""
        if isinstance(self.controller.law, PilLaw):
            self.controller.law.close()

    def run(self, duration: float, progress: bool = False) -> SimulationLog:
        """Simulate ``duration`` seconds from t = 0 (once per Simulation) and return the logs."""
        if not (math.isfinite(duration) and duration > 0):
            raise SimulationError(SimulationError.DURATION.format(value=duration))
        if self._ran:
            raise RuntimeError("a Simulation runs once; build a new one")
        self._ran, self._duration = True, duration
        self.prepare(duration)
        # the visualizer's frames are Diagram events: the loop stops there too (a discrete plant logs there)
        frames = periodic_times(0.0, VISUALIZER_PERIOD, duration) if self.meshcat is not None else ()
        if self.meshcat is not None:
            self.visualizer.StartRecording()
        if progress:
            steps = max(1, int(round(duration / 0.05)))
            # counted in simulated seconds: the rate tqdm shows (simulated s per wall s) is the real-time factor
            fmt = "{desc}: {n:.2f}/{total:.2f} simulated s [{elapsed}<{remaining}, {rate_fmt}]"
            with tqdm(
                total=duration,
                desc=f"simulate {self.kind}",
                unit=" simulated s",
                bar_format=fmt,
                leave=False,
            ) as bar:
                marks = [duration * k / steps for k in range(1, steps + 1)]
                at_mark = set(marks)
                self._logs = self.controller.run(
                    duration, [*frames, *marks], lambda t: bar.update(duration / steps) if t in at_mark else None
                )
        else:
            self._logs = self.controller.run(duration, frames)
        if self.meshcat is not None:
            self.visualizer.StopRecording()
            self.visualizer.PublishRecording()
        return self._collect(duration)

    def extend(self, duration: float) -> SimulationLog:
        """Continue the run (``run``, or an earlier ``extend``) to ``duration`` seconds from t = 0 and return the
        logs from t = 0: the same numbers, bit for bit, as one ``run(duration)`` of a fresh Simulation when the
        run's end was a plant step or a tick (``TickLoop.extend``). For a caller that decides from the logs
        whether the run was long enough: it continues instead of simulating the start again. Not with an
        animation (its recording ended with the run)."""
        if not (math.isfinite(duration) and duration > 0):
            raise SimulationError(SimulationError.DURATION.format(value=duration))
        if not self._ran or self.meshcat is not None or not duration > self._duration:
            raise RuntimeError(f"a Simulation extended to {duration} s after {self._duration} s")  # a caller's bug
        self._duration = duration
        self.prepare(duration)
        self._logs = self.controller.extend(duration)
        return self._collect(duration)

    def prepare(self, duration: float) -> None:
        """Fill the tables the run reads (``run`` calls it): the reference and the feed-forward at every
        tick of ``duration`` seconds, in one batch each, as rows read by tick index (the pose functions
        are elementwise over times: the numbers of one time at a time), and the law's IK of those poses
        (speed only). What a host computes and downloads before the DSP starts."""
        T = self.config.timing.sample_period
        ticks = np.arange(int(math.floor(duration / T + 1e-9)) + 1) * T
        poses = self.trajectory.pose(ticks)
        self.controller.reference = np.ascontiguousarray(poses, dtype=float)
        self.controller.prime(poses)
        if self.feedforward is not None:
            self.controller.feedforward = self.feedforward.prime(ticks)  # the rows of the ticks, in order

    def states(self) -> np.ndarray:
        """``(n, nx)`` the plant states logged by the run (``plant.get_state_output_port()``'s layout)."""
        return self._logs["state"]

    def max_constraint_gap(self, samples: int = 1000) -> float:
        """The largest ball-constraint gap (m) of this run: how far the loop closures opened, over up to
        ``samples`` evenly spaced logged plant states (every state of a shorter run), first and last
        included (``integrators.constraint_gaps``; a state costs ~50 µs)."""
        X = self.states()
        idx = np.unique(np.linspace(0, len(X) - 1, min(len(X), samples)).round().astype(int))
        return float(constraint_gaps(self.plant, X[idx]).max())

    def _collect(self, duration: float) -> SimulationLog:
        logs = self._logs
        t, X, force = logs["times"], logs["state"], logs["force"]
        top = self.plant.GetBodyByName("top")
        i0 = top.floating_positions_start()
        quat = X[:, i0 : i0 + 4]
        p_WT = X[:, i0 + 4 : i0 + 7]
        R = quaternion_to_matrix(quat)
        angles = angles_from_matrix(R, "utn")
        p_WC = p_WT + np.einsum("nij,j->ni", R, self.platform.rotation_centre)
        pose = np.concatenate([p_WC, angles], axis=1)
        joints = [self.plant.GetJointByName(f"prismatic_{i + 1}") for i in range(6)]
        L = X[:, [j.position_start() for j in joints]]
        T = self.config.timing.sample_period
        t_ref = periodic_times(0.0, T, duration)  # the reference at the ticks 0 … k·T <= duration
        return SimulationLog(
            kind=self.kind,
            platform=self.platform.name,
            trajectory=self.trajectory.name,
            sample_period=T,
            t=t,
            pose=pose,
            lengths=L,
            command=logs["command"].copy(),
            setpoint=logs["setpoint"].copy(),
            force=force,
            status=logs["status"],
            t_ref=np.r_[0.0, t_ref],
            reference=self.controller.reference[: len(t_ref) + 1].copy(),
        )


def build_simulation(scenario: Scenario, meshcat=None) -> Simulation:
    """Assemble ``scenario``'s Diagram (plant, actuators, loggers) and the loop that drives it, with the
    plant at the reference's initial pose, legs at the matching lengths and the controller holding them
    against gravity. ``meshcat``: a ``Meshcat`` to record an animation (not part of the scenario: it does
    not pickle)."""
    s = scenario
    platform = s.platform
    integrator = check_integrator(s.integrator or DEFAULT_INTEGRATOR)
    plant_platform = s.plant_platform or platform
    plant_time_step = s.plant_time_step
    if not (math.isfinite(plant_time_step) and plant_time_step > 0):
        raise SimulationError(SimulationError.PLANT_STEP.format(value=plant_time_step))
    trajectory = get_trajectory(s.trajectory)
    actuators = s.actuators
    config = s.config
    if config is None:
        poses = design_poses(trajectory, s.design_duration)
        config = ControllerConfig.for_platform(platform, actuator_lag=actuators.time_constant, poses=poses)
    if s.pil is not None and s.pil.target:
        law = PilLaw(platform, config, s.pil, s.seed)  # the target is started here: ``Simulation.close`` ends it
    else:
        law = make_law(s.controller, platform, config, s.engine, s.firmware)
    try:
        return _build(s, platform, integrator, plant_platform, trajectory, actuators, config, law, meshcat)
    except BaseException:
        if isinstance(law, PilLaw):
            law.close()
        raise


def _build(s, platform, integrator, plant_platform, trajectory, actuators, config, law, meshcat) -> Simulation:
    """``build_simulation`` once the law is made."""
    plant_time_step = s.plant_time_step
    T = config.timing.sample_period
    max_force = actuators.max_force or float(platform.legs.max_force)
    # the plant: reused from an earlier run of this process with the same one (``loop_diagram``)
    built = loop_diagram(plant_platform, plant_time_step, integrator, meshcat)
    diagram, plant = built.diagram, built.plant
    joints = [plant.GetJointByName(f"prismatic_{i + 1}") for i in range(6)]
    sensor_model = s.sensor
    if np.any(plant_platform.length_offset):  # a sensor reads the joint-to-joint length − legs.length_offset
        o = -plant_platform.length_offset
        sensor_model = (
            SensorModel(o, np.zeros((1, 6)), np.zeros(1), 1.0)
            if s.sensor is None
            else replace(s.sensor, offset=np.asarray(s.sensor.offset) + o)
        )
    pos = np.array([j.position_start() for j in joints])
    vel = plant.num_positions() + np.array([j.velocity_start() for j in joints])
    if sensor_model is None:
        sensor = IdealSensor(pos)  # the prismatic positions
    else:
        m = sensor_model
        sensor = SensorReading(
            pos, vel, np.asarray(m.offset, float), np.asarray(m.noise, float), np.asarray(m.jitter, float), m.period
        )
    ff = None
    if s.feedforward:
        lead = feedforward_lead(config, actuators.time_constant)
        ff = FeedforwardTable(platform, trajectory, lead, T, feedforward_engine(s.controller))
    simulator = Simulator(diagram)
    apply_integrator(simulator, integrator, plant_time_step)
    root = simulator.get_mutable_context()
    pose0 = trajectory.pose(0.0)
    pc = plant.GetMyMutableContextFromRoot(root)
    set_pose(plant, pc, plant_platform, pose0)
    set_velocity(plant, pc, plant_platform, trajectory, 0.0)
    L0 = leg_lengths(plant_platform, pose0)
    L0 = sensor.initial_reading(L0) if hasattr(sensor, "initial_reading") else L0
    F0 = initial_leg_forces(platform, trajectory)
    h = 1e-6
    rates0 = (leg_lengths(platform, trajectory.pose(h)) - leg_lengths(platform, trajectory.pose(-h))) / (2 * h)
    # the actuators (saturation, lag; or the screws, the cylinders) are stepped by the loop at the plant steps,
    # starting at F0
    legs = None
    if actuators.screw is not None:
        act, legs = ScrewActuation(actuators.screw, plant_time_step), (pos, vel)
        set_reflected_inertia(plant, pc, actuators.screw)
    elif actuators.hydraulic is not None:
        act, legs = HydraulicActuation(actuators.hydraulic, plant_time_step, plant_platform.L_min), (pos, vel)
    else:
        act = Actuation.from_time_constant(max_force, actuators.time_constant, plant_time_step)
    discrete = integrator not in CONTINUOUS
    loop = TickLoop(
        simulator, plant, pc, diagram.GetInputPort("actuation"), law, sensor, plant_time_step, act, discrete, legs
    )
    loop.reference = trajectory.pose(np.zeros(1))  # until ``run`` fills the tables: the pose at t = 0
    loop.initialize(L0, F0, None if ff is None else ff.force(0.0), rates0)
    simulator.Initialize()
    return Simulation(
        platform,
        trajectory,
        s.controller,
        config,
        diagram,
        plant,
        loop,
        simulator,
        meshcat,
        built.visualizer,
        plant_time_step,
        ff,
        integrator,
    )


def setpoint_step_response(
    platform: Platform,
    config: ControllerConfig | None = None,
    leg: int = 0,
    step: float = 1e-3,
    duration: float = 0.3,
    actuators: ActuatorModel | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """The float twin's closed-loop response, on the actual plant at home, to a set-point step of ``step``
    metres on leg ``leg`` (0-based) at t = 0: ``(t (n,), s (n, 6))``, s = (L(t) − L_rest(t)) / step for
    all six legs, L_rest a run without the step (removes any residual drift of the equilibrium). The
    controller is ``config`` (the run's gains, timing and feed-forward) with an ideal sensor (resolution
    1 nm: the sensor's counts are a separate term of the bounds, and a 10 µm quantiser would add its own
    chatter to a small-signal measurement). Samples at the plant steps (the controller's period by
    default), so s[n] is the sampled step response of the discrete loop from set-point words to lengths."""
    sims = _setpoint_step_runs(platform, config, leg, step, actuators)
    return _step_of([sim.run(duration) for sim in sims], step)


def _setpoint_step_runs(platform, config, leg, step, actuators) -> list[Simulation]:
    """``setpoint_step_response``'s two Simulations, built: the rest run and the stepped run (the float law's
    ``setpoint_offset``: the compiled loop adds it to its set-point table, ``firmware.loop_kernel``)."""
    if not (isinstance(leg, (int, np.integer)) and 0 <= leg < 6):
        raise SimulationError(SimulationError.LEG.format(value=leg))
    if not (math.isfinite(step) and step != 0):
        raise SimulationError(SimulationError.STEP.format(value=step))
    cfg = config or ControllerConfig.for_platform(platform)
    cfg = replace(cfg, timing=replace(cfg.timing, sensor_resolution=1e-9))
    rest = constant_trajectory("home", platform.home_pose())  # for all times: the runs may be extended
    sims = []
    for delta in (0.0, step):
        sim = build_simulation(Scenario(platform, rest, "float", config=cfg, actuators=actuators or ActuatorModel()))
        off = np.zeros(6)
        off[leg] = delta
        sim.controller.law.setpoint_offset = off
        sims.append(sim)
    return sims


def _step_of(logs: list[SimulationLog], step: float) -> tuple[np.ndarray, np.ndarray]:
    """``setpoint_step_response``'s ``(t, s)`` of the rest and stepped runs' logs."""
    return logs[1].t, (logs[1].lengths - logs[0].lengths) / step


def setpoint_step_gain(
    platform: Platform,
    config: ControllerConfig | None = None,
    leg: int = 0,
    step: float = 1e-3,
    duration: float = 0.3,
    actuators: ActuatorModel | None = None,
    settle: float | None = None,
    max_duration: float | None = None,
) -> dict:
    """The ℓ1 gain ‖h‖₁ of the closed loop from a leg's set-point to leg lengths, from the float twin's
    set-point step response (``setpoint_step_response`` of ``duration`` s): h[n] = s[n] − s[n−1] is the
    sampled impulse response, ‖h‖₁ = Σ|h[n]| the total variation of the step response (plus
    |1 − s_end|, the least variation still to come before the stepped leg settles at its DC gain 1).
    With ``settle`` and ``max_duration`` (s): while the last quarter of the run added more than ``settle``
    of ‖h‖₁ and twice the duration is at most ``max_duration``, the runs are continued to twice as long
    (``Simulation.extend``: the numbers of fresh runs that long, without simulating the start again).

    Why it bounds the fixed-point controller's extra error: the fixed-point set-points are the float
    twin's plus an error sequence ε[k] (the 16-bit IK's error, the 1 mm LSB steps, and the sensor's counts
    acting like a set-point offset) with |ε[k]| ≤ A = Δ_IK + LSB + r. The loop about the trajectory is
    linear in that small perturbation, so the extra length error is y = h * ε and
    |y[n]| ≤ Σ_k |h[n−k]|·|ε[k]| ≤ ‖h‖₁·A — tight for the worst-case input ε[k] = A·sign h[n−k].
    The stepped leg's ‖h‖₁ ≥ 1 (the variation from 0 to the DC gain 1 is at least 1; overshoot adds twice
    each excursion). With all six set-points in error at once, leg i collects Σ_j ‖h_ij‖₁; ``coupled`` is
    the column sum Σ_i ‖h_ij‖₁ of the stepped leg, equal to that row sum when the platform's symmetry
    maps any leg onto any other (the hexapods here, at home).

    The sums are over the run, so they are only as good as the run is long: the loop rings down over seconds
    (utn-dynamic's ‖h‖₁ is 10.2 after 1.5 s and 11.27 after 6 s, where it has settled to 0.14 %). ``settled``
    is the share of ``coupled`` the last quarter of the run added: a caller relying on ‖h‖₁ as a bound checks
    that it is small (a measured convergence, not a proof that nothing is left).

    Returns ``{"diagonal": ‖h_jj‖₁, "coupled": Σ_i ‖h_ij‖₁, "tail": |1 − s_jj(end)|, "peak": max s_jj,
    "settled": the last quarter's share of ``coupled``, "t": t, "s": s}``."""
    sims = _setpoint_step_runs(platform, config, leg, step, actuators)
    logs = [sim.run(duration) for sim in sims]
    while True:
        gain = _gain_of(*_step_of(logs, step), leg)
        if settle is None or max_duration is None or gain["settled"] <= settle or 2 * duration > max_duration:
            return gain
        duration *= 2
        logs = [sim.extend(duration) for sim in sims]


def _gain_of(t: np.ndarray, s: np.ndarray, leg: int) -> dict:
    """``setpoint_step_gain``'s dict of the step response ``s`` (n, 6) at times ``t`` (n,)."""
    diag, coupled, tail = _l1_sums(s, leg)
    head = _l1_sums(s[: max(1, (3 * len(s)) // 4)], leg)[1]
    settled = (coupled - head) / coupled
    return {
        "diagonal": diag,
        "coupled": coupled,
        "tail": tail,
        "peak": float(s[:, leg].max()),
        "settled": float(settled),
        "t": t,
        "s": s,
    }


def _l1_sums(s: np.ndarray, leg: int) -> tuple[float, float, float]:
    """``setpoint_step_gain``'s (diagonal, coupled, tail) of the step response ``s`` (n, 6)."""
    tv = np.abs(np.diff(np.vstack([np.zeros((1, 6)), s]), axis=0)).sum(axis=0)
    tail = float(abs(1.0 - s[-1, leg]))
    diag = float(tv[leg] + tail)
    return diag, float(tv.sum() - tv[leg] + diag + np.abs(np.delete(s[-1], leg)).sum()), tail


def simulate(scenario: Scenario, progress: bool = False) -> SimulationLog:
    """Build ``scenario``'s Diagram and run it: the logs of ``scenario.duration`` seconds (default the
    trajectory's own duration, else 1 s); default gains are designed over the poses of the whole run."""
    traj = get_trajectory(scenario.trajectory)
    duration = scenario.duration if scenario.duration is not None else (traj.duration or 1.0)
    if scenario.config is None and scenario.design_duration is None:
        scenario = replace(scenario, design_duration=max(duration, traj.duration or 0.0))
    return build_simulation(replace(scenario, trajectory=traj)).run(duration, progress=progress)
