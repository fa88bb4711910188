"""Controller-in-the-loop simulation: trajectory source → DSP controller → actuators → closed-loop plant.

The Diagram (``build_simulation``)::

    PoseSource ──reference──▶ controller (fixed | float, discrete, period T) ──command──▶ Actuators
        ▲  FeedforwardTable ──▶    ▲ leg_lengths                                           │ force
        │                          └──────── MatrixGain (prismatic positions) ◀── plant ◀──┘
        └ (trajectory: seed, rotating, or a (t, pose) CSV)

The feed-forward table (``feedforward_forces``) holds, per tick, the leg forces of the inverse dynamics
(plate and legs) along the reference, advanced by the loop's known delays: what a host would compute
with the pose table and download to the DSP. Without it (``feedforward=False``) the PID alone carries
the plate.

Loggers record, at every plant step, the plant state (pose and leg lengths come from it), the
controller's held command and set-point, its status (tick count, tick time, saturation counts) and the
actuator forces; the reference is logged at the controller's ticks. Everything is deterministic: the
same inputs give the same logs bit for bit (no randomness, no threads in the loop).
"""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from stewart_drake.control.controller import STATUS, ControllerConfig, make_controller
from stewart_drake.core.csvio import read_numeric_csv
from stewart_drake.core.geometry import Platform
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.core.rotations import angles_from_matrix, pose_to_si, rotation_matrix

# ----------------------------------------------------------------------------------------------
# Trajectories: pose(t) for a scalar or an array of times, (..., 6) metres/radians, utn convention.


@dataclass(frozen=True)
class Trajectory:
    """A pose reference. ``pose(t)``: ``(..., 6)`` for times ``(...)`` (s); ``duration`` the natural
    length in seconds (None: unbounded)."""

    name: str
    fn: object
    duration: float | None = None

    def pose(self, t) -> np.ndarray:
        return self.fn(np.asarray(t, dtype=float))


def _seed_pose(t):
    """SPEC §3: px = −0.1 m, py = 0.1·sin(2t) m, pz = 0.7 m, no rotation."""
    t = np.asarray(t, dtype=float)
    z = np.zeros_like(t)
    return np.stack([z - 0.1, 0.1 * np.sin(2.0 * t), z + 0.7, z, z, z], axis=-1)


def _rotating_pose(t):
    """The plate at pz = 0.7 m turning about Z by 15°·sin(2t) while tilting 5°·sin(3t) about X."""
    t = np.asarray(t, dtype=float)
    z = np.zeros_like(t)
    return np.stack([z, z, z + 0.7, np.radians(5.0) * np.sin(3.0 * t), z, np.radians(15.0) * np.sin(2.0 * t)], axis=-1)


SEED = Trajectory("seed", _seed_pose, 4.0)
ROTATING = Trajectory("rotating", _rotating_pose, 4.0)
TRAJECTORIES = {"seed": SEED, "rotating": ROTATING}


def fit_trajectory(trajectory: Trajectory, platform: Platform, home_height: float = 0.7, stroke: float = 0.4) -> Trajectory:
    """``trajectory`` (made for a platform whose home is pz = ``home_height`` with a stroke of ``stroke``
    metres, as ``SEED`` and ``ROTATING`` are for utn-dynamic) moved to ``platform``'s home and its
    positions scaled by the ratio of the strokes (angles unchanged): the same motion, relative to the
    platform's size."""
    s = (platform.stroke[1] - platform.stroke[0]) / stroke
    centre = np.array([0.0, 0.0, home_height])
    home = platform.home_pose()[:3]

    def fn(t):
        q = trajectory.pose(t).copy()
        q[..., :3] = home + s * (q[..., :3] - centre)
        return q

    return Trajectory(trajectory.name, fn, trajectory.duration)


def load_trajectory_csv(path, length_unit: str = "m", angle_unit: str = "rad") -> Trajectory:
    """A ``(t, px, py, pz, a_x, a_y, a_z)`` CSV (header row optional; times strictly increasing,
    seconds) as a piecewise-linear Trajectory (``table_trajectory``). Errors name the line."""
    data, lines = read_numeric_csv(path, "trajectory", (7,), "t, px, py, pz, a_x, a_y, a_z")
    late = np.flatnonzero(np.diff(data[:, 0]) <= 0)
    if late.size:
        k = late[0] + 1
        raise ValueError(f"{path}:{lines[k]}: time {data[k, 0]} s is not after the previous sample's {data[k - 1, 0]} s")
    return table_trajectory(Path(path).stem, data[:, 0], pose_to_si(data[:, 1:], length_unit, angle_unit))


def table_trajectory(name: str, ts, poses) -> Trajectory:
    """Samples ``ts`` (n,) s, ``poses`` (n, 6) SI as a piecewise-linear Trajectory, held constant after the
    last sample and continued before the first along the first segment: the differences that start a run
    at t = 0 (``initial_leg_forces``, ``set_velocity``) then see the reference's initial velocity, not a
    kink from a pose held before t = 0 (a clamp there read as an acceleration of v/h and threw the plate)."""
    ts, poses = np.asarray(ts, dtype=float), np.asarray(poses, dtype=float)
    slope = (poses[1] - poses[0]) / (ts[1] - ts[0]) if len(ts) > 1 else np.zeros(6)

    def fn(t):
        t = np.asarray(t, dtype=float)
        q = np.stack([np.interp(t, ts, poses[:, j]) for j in range(6)], axis=-1)
        before = (t < ts[0])[..., None]
        return np.where(before, poses[0] + (t - ts[0])[..., None] * slope, q)

    return Trajectory(name, fn, float(ts[-1]))


def get_trajectory(name_or_path, **units) -> Trajectory:
    """``seed``, ``rotating`` or a CSV file path."""
    if isinstance(name_or_path, Trajectory):
        return name_or_path
    s = str(name_or_path)
    if s in TRAJECTORIES:
        return TRAJECTORIES[s]
    if s.endswith(".csv") or Path(s).exists():
        return load_trajectory_csv(s, **units)
    raise ValueError(f"unknown trajectory {s!r}: not one of {', '.join(TRAJECTORIES)} and not a CSV file")


# ----------------------------------------------------------------------------------------------
# Actuators.


@dataclass(frozen=True)
class ActuatorModel:
    """Leg actuators: a force limit (N, None: the platform's ``legs.max_force``) and a first-order lag
    with time constant ``time_constant`` (s; 0: none). The stroke end stops are the prismatic joints'
    limits in the plant (SAP enforces them as constraints)."""

    max_force: float | None = None
    time_constant: float = 2e-3

    def __post_init__(self):
        if self.max_force is not None and not (math.isfinite(self.max_force) and self.max_force > 0):
            raise ValueError(f"ActuatorModel.max_force must be a positive number of newtons, got {self.max_force!r}")
        if not (math.isfinite(self.time_constant) and self.time_constant >= 0):
            raise ValueError(f"ActuatorModel.time_constant must be >= 0 s, got {self.time_constant!r}")


def _systems():
    """LeafSystem classes, built on first use (keeps pydrake out of import time)."""
    global _SYS
    if _SYS is not None:
        return _SYS
    from pydrake.systems.framework import LeafSystem

    class PoseSource(LeafSystem):
        """Output ``pose`` (6) = trajectory.pose(t)."""

        def __init__(self, trajectory: Trajectory):
            super().__init__()
            self.trajectory = trajectory
            # evaluated on a 1-element array, the same code path as a batch of times
            self.DeclareVectorOutputPort("pose", 6, lambda c, o: o.SetFromVector(trajectory.pose(np.array([c.get_time()]))[0]))

    class Actuators(LeafSystem):
        """Input ``command`` (6, N) → output ``force`` (6, N): saturation at ±max_force, then a first-order
        lag discretised exactly at ``period`` (the plant's step), F ← a·F + (1−a)·u, a = exp(−period/τ)."""

        def __init__(self, max_force: float, time_constant: float, period: float):
            super().__init__()
            self.max_force = max_force
            u = self.DeclareVectorInputPort("command", 6)
            if time_constant > 0:
                a = math.exp(-period / time_constant)
                s = self.DeclareDiscreteState(6)

                def update(context, xd):
                    F = context.get_discrete_state(s).value()
                    cmd = np.clip(u.Eval(context), -max_force, max_force)
                    xd.set_value(s, a * F + (1 - a) * cmd)

                self.DeclarePeriodicDiscreteUpdateEvent(period, 0.0, update)
                self.DeclareStateOutputPort("force", s)
                self.state_index = s
            else:
                self.state_index = None
                self.DeclareVectorOutputPort("force", 6, lambda c, o: o.SetFromVector(np.clip(u.Eval(c), -max_force, max_force)))

    class FeedforwardTable(LeafSystem):
        """Output ``force`` (6, N) = ``feedforward_forces`` at the context's time, from a table filled in
        one batch by ``prime(times)`` (a time not in the table is computed on its own: same numbers)."""

        def __init__(self, platform: Platform, trajectory: Trajectory, lead: float, h: float):
            super().__init__()
            self.args = (platform, trajectory, lead, h)
            self.table: dict[float, np.ndarray] = {}
            self.DeclareVectorOutputPort("force", 6, lambda c, o: o.SetFromVector(self.force(c.get_time())))

        def prime(self, times) -> None:
            times = np.asarray(times, dtype=float)
            for t, F in zip(times, feedforward_forces(*self.args[:2], times, *self.args[2:])):
                self.table[float(t)] = F

        def force(self, t: float) -> np.ndarray:
            F = self.table.get(float(t))
            return F if F is not None else feedforward_forces(*self.args[:2], [t], *self.args[2:])[0]

    _SYS = {"PoseSource": PoseSource, "Actuators": Actuators, "FeedforwardTable": FeedforwardTable}
    return _SYS


_SYS = None


def pose_source(trajectory: Trajectory):
    """A LeafSystem with one output ``pose`` (6) = ``trajectory.pose(t)`` (any 6-vector function of time)."""
    return _systems()["PoseSource"](trajectory)


def actuator_system(max_force: float, time_constant: float, period: float):
    """The actuator LeafSystem: input ``command`` (6, N) → output ``force`` (6, N); see ``ActuatorModel``."""
    return _systems()["Actuators"](max_force, time_constant, period)


def initial_leg_forces(platform: Platform, trajectory: Trajectory, t: float = 0.0, h: float = 1e-4) -> np.ndarray:
    """``(6,)`` leg forces (N) that move plate and legs along the reference at time ``t``
    (``dynamics.leg_forces_with_legs`` with central-difference rates): where the controller's integrator
    starts, so a run begins in equilibrium instead of with a gravity sag."""
    from stewart_drake.core.dynamics import leg_forces_with_legs

    qm, q0, qp = trajectory.pose(np.array([t - h, t, t + h]))
    return leg_forces_with_legs(platform, q0, (qp - qm) / (2 * h), (qp - 2 * q0 + qm) / h**2)


def feedforward_lead(config: ControllerConfig, actuator_lag: float) -> float:
    """Seconds by which the feed-forward table leads the reference: a force computed at tick k is
    released after the output delay, held for a sample (on average half of it) and reaches the plate
    through the actuator lag (a first-order lag τ delays slow signals by τ)."""
    return config.timing.output_delay + config.timing.sample_period / 2 + actuator_lag


def feedforward_forces(platform: Platform, trajectory: Trajectory, times, lead: float, h: float) -> np.ndarray:
    """``(n, 6)`` feed-forward leg forces (N) at ``times`` (n,): ``dynamics.leg_forces_with_legs`` at the
    reference pose of t + ``lead``, with its rates from central differences of step ``h`` (the sample
    period: the second difference of the sampled reference, bounded also for piecewise-linear CSV
    references)."""
    from stewart_drake.core.dynamics import leg_forces_with_legs

    t = np.asarray(times, dtype=float).reshape(-1) + lead
    qm, q0, qp = trajectory.pose(t - h), trajectory.pose(t), trajectory.pose(t + h)
    return leg_forces_with_legs(platform, q0, (qp - qm) / (2 * h), (qp - 2 * q0 + qm) / h**2)


def set_velocity(plant, context, platform: Platform, trajectory: Trajectory, t: float, h: float = 1e-6) -> None:
    """Set every velocity in ``context`` to the reference's at time ``t`` (central differences of the
    closed-form joint positions, step ``h`` s), so that a run starts on the trajectory, not at rest."""
    from pydrake.multibody.math import SpatialVelocity

    from stewart_drake.core.leg_bodies import leg_joint_positions

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
    """A built controller-in-the-loop Diagram, ready to run (see ``build_simulation``)."""

    platform: Platform
    trajectory: Trajectory
    kind: str
    config: ControllerConfig
    diagram: object
    plant: object
    controller: object
    loggers: dict
    simulator: object = None
    meshcat: object = None
    visualizer: object = None
    plant_time_step: float = 1e-3
    feedforward: object = None
    integrator: str = "sap"
    _ran: bool = False

    def run(self, duration: float, progress: bool = False) -> "SimulationLog":
        """Simulate ``duration`` seconds from t = 0 (once per Simulation) and return the logs."""
        if not (math.isfinite(duration) and duration > 0):
            raise ValueError(f"duration must be a positive number of seconds, got {duration!r}")
        if self._ran:
            raise RuntimeError("a Simulation runs once; build a new one")
        self._ran = True
        sim = self.simulator
        T = self.config.timing.sample_period
        n = int(math.floor(duration / T + 1e-9)) + 1
        if hasattr(self.controller, "prime"):  # batch the fixed-point IK of the known reference (speed only)
            self.controller.prime(self.trajectory.pose(np.arange(n) * T))
        if self.feedforward is not None:  # the feed-forward table at the ticks, in one batch
            self.feedforward.prime(np.arange(n) * T)
        if self.meshcat is not None:
            self.visualizer.StartRecording()
        if progress:
            from tqdm import tqdm

            steps = max(1, int(round(duration / 0.05)))
            with tqdm(total=steps, desc=f"simulate {self.kind} {duration:g} s", unit=" × 50 ms", leave=False) as bar:
                for k in range(1, steps + 1):
                    sim.AdvanceTo(duration * k / steps)
                    bar.update(1)
        else:
            sim.AdvanceTo(duration)
        if self.meshcat is not None:
            self.visualizer.StopRecording()
            self.visualizer.PublishRecording()
        return self._collect()

    def _collect(self) -> "SimulationLog":
        ctx = self.simulator.get_context()
        logs = {k: lg.FindLog(ctx) for k, lg in self.loggers.items()}
        x = logs["state"]
        t = x.sample_times().copy()
        X = x.data().T
        top = self.plant.GetBodyByName("top")
        i0 = top.floating_positions_start()
        quat = X[:, i0 : i0 + 4]
        p_WT = X[:, i0 + 4 : i0 + 7]
        R = _quat_to_matrix(quat)
        angles = angles_from_matrix(R, "utn")
        p_WC = p_WT + np.einsum("nij,j->ni", R, self.platform.rotation_centre)
        pose = np.concatenate([p_WC, angles], axis=1)
        joints = [self.plant.GetJointByName(f"prismatic_{i + 1}") for i in range(6)]
        L = X[:, [j.position_start() for j in joints]]
        ref = logs["reference"]
        status = logs["status"].data().T
        return SimulationLog(
            kind=self.kind,
            platform=self.platform.name,
            trajectory=self.trajectory.name,
            sample_period=self.config.timing.sample_period,
            t=t,
            pose=pose,
            lengths=L,
            command=logs["command"].data().T.copy(),
            setpoint=logs["setpoint"].data().T.copy(),
            force=logs["force"].data().T.copy(),
            status=status.copy(),
            t_ref=ref.sample_times().copy(),
            reference=ref.data().T.copy(),
        )


def _quat_to_matrix(q) -> np.ndarray:
    """``(n, 4)`` unit quaternions [w, x, y, z] → ``(n, 3, 3)``."""
    q = q / np.linalg.norm(q, axis=1, keepdims=True)
    w, x, y, z = q.T
    return np.stack(
        [
            1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),
            2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
            2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y),
        ],
        axis=-1,
    ).reshape(-1, 3, 3)


def build_simulation(
    platform: Platform,
    trajectory="seed",
    controller: str = "fixed",
    config: ControllerConfig | None = None,
    actuators: ActuatorModel | None = None,
    plant_time_step: float = 1e-3,
    meshcat=None,
    feedforward: bool = True,
    design_duration: float | None = None,
    engine: str = "python",
    firmware=None,
    integrator: str | None = None,
    plant_platform: Platform | None = None,
    sensor=None,
) -> Simulation:
    """Assemble the controller-in-the-loop Diagram and its Simulator, with the plant at the reference's
    initial pose, legs at the matching lengths and the controller holding them against gravity.

    ``controller``: ``fixed`` or ``float``; ``config``: timing and gains (refused if infeasible; default
    ``ControllerConfig.for_platform``: command range and gains designed for ``platform`` and the
    actuators' lag); ``plant_time_step`` (s): the discrete plant's step; ``meshcat``: a ``Meshcat`` to
    record an animation; ``feedforward``: connect the model-based force feed-forward table;
    ``design_duration`` (s): the default gains are designed over the reference's poses from 0 to this
    time (``design_poses``; default the trajectory's duration, else 4 s); ``engine``: ``python`` or ``c``
    (the fixed-point tick by compiled C), ``firmware``: a user's C file implementing the firmware ABI;
    ``integrator``: ``cenic``
    (default: a continuous plant under Drake's error-controlled CENIC, logged every ``plant_time_step``)
    or ``sap`` (a discrete plant stepped at ``plant_time_step``); see ``integrators``; ``plant_platform``: the platform the plant is built
    from (default ``platform``: the controller's model; a perturbed copy models manufacturing errors);
    ``sensor``: a function ``(plant, D (6, nx)) -> LeafSystem`` (input: plant state, output: the six
    measured lengths; optional ``initial_reading(L)``) replacing the ideal sensor ``MatrixGain(D)``.
    """
    from pydrake.systems.analysis import Simulator
    from pydrake.systems.framework import DiagramBuilder
    from pydrake.systems.primitives import LogVectorOutput, MatrixGain

    from stewart_drake.drake.integrators import DEFAULT_INTEGRATOR, apply_integrator, check_integrator
    from stewart_drake.drake.platform_model import build_plant, set_pose

    integrator = check_integrator(integrator or DEFAULT_INTEGRATOR)
    plant_platform = plant_platform or platform
    if not (math.isfinite(plant_time_step) and plant_time_step > 0):
        raise ValueError(f"plant_time_step must be a positive number of seconds, got {plant_time_step!r}")
    trajectory = get_trajectory(trajectory)
    actuators = actuators or ActuatorModel()
    if config is None:
        poses = design_poses(trajectory, design_duration)
        config = ControllerConfig.for_platform(platform, actuator_lag=actuators.time_constant, poses=poses)
    builder = DiagramBuilder()
    plant, scene_graph = build_plant(plant_platform, plant_time_step, builder, continuous=integrator == "cenic")
    ctrl = builder.AddSystem(make_controller(controller, platform, config, engine, firmware))
    ctrl.set_name(f"{controller}_controller")
    src = builder.AddSystem(pose_source(trajectory))
    src.set_name("reference")
    max_force = actuators.max_force or float(platform.legs.max_force)
    act = builder.AddSystem(actuator_system(max_force, actuators.time_constant, plant_time_step))
    act.set_name("actuators")
    nx = plant.num_multibody_states()
    D = np.zeros((6, nx))
    for i in range(6):
        D[i, plant.GetJointByName(f"prismatic_{i + 1}").position_start()] = 1.0
    sensor = builder.AddSystem(MatrixGain(D) if sensor is None else sensor(plant, D))
    sensor.set_name("leg_length_sensor")
    builder.Connect(src.get_output_port(), ctrl.GetInputPort("reference"))
    ff = None
    if feedforward:
        T = config.timing.sample_period
        ff = builder.AddSystem(_systems()["FeedforwardTable"](platform, trajectory, feedforward_lead(config, actuators.time_constant), T))
        ff.set_name("feedforward_table")
        builder.Connect(ff.get_output_port(), ctrl.GetInputPort("feedforward"))
    builder.Connect(plant.get_state_output_port(), sensor.get_input_port())
    builder.Connect(sensor.get_output_port(), ctrl.GetInputPort("leg_lengths"))
    builder.Connect(ctrl.GetOutputPort("command"), act.get_input_port())
    builder.Connect(act.get_output_port(), plant.get_actuation_input_port())
    T = config.timing.sample_period
    # the discrete plant logs at its steps; the continuous one at the same period (not at every integrator step)
    lp = () if integrator == "sap" else (plant_time_step,)
    loggers = {
        "state": LogVectorOutput(plant.get_state_output_port(), builder, *lp),
        "command": LogVectorOutput(ctrl.GetOutputPort("command"), builder, *lp),
        "setpoint": LogVectorOutput(ctrl.GetOutputPort("setpoint"), builder, *lp),
        "status": LogVectorOutput(ctrl.GetOutputPort("status"), builder, *lp),
        "force": LogVectorOutput(act.get_output_port(), builder, *lp),
        "reference": LogVectorOutput(src.get_output_port(), builder, T),
    }
    visualizer = None
    if meshcat is not None:
        from pydrake.geometry import MeshcatVisualizer, MeshcatVisualizerParams

        visualizer = MeshcatVisualizer.AddToBuilder(builder, scene_graph, meshcat, MeshcatVisualizerParams(publish_period=1 / 32))
    diagram = builder.Build()
    simulator = Simulator(diagram)
    apply_integrator(simulator, integrator)
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
    ctrl.initialize(ctrl.GetMyMutableContextFromRoot(root), L0, F0, None if ff is None else ff.force(0.0), rates0)
    if act.state_index is not None:
        act.GetMyMutableContextFromRoot(root).SetDiscreteState(act.state_index, np.clip(F0, -max_force, max_force))
    simulator.Initialize()
    return Simulation(platform, trajectory, controller, config, diagram, plant, ctrl, loggers, simulator, meshcat, visualizer, plant_time_step, ff, integrator)


def setpoint_step_response(platform: Platform, config: ControllerConfig | None = None, leg: int = 0, step: float = 1e-3,
                           duration: float = 0.3, actuators: ActuatorModel | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The float twin's closed-loop response, on the actual plant at home, to a set-point step of ``step``
    metres on leg ``leg`` (0-based) at t = 0: ``(t (n,), s (n, 6))``, s = (L(t) − L_rest(t)) / step for
    all six legs, L_rest a run without the step (removes any residual drift of the equilibrium). The
    controller is ``config`` (the run's gains, timing and feed-forward) with an ideal sensor (resolution
    1 nm: the sensor's counts are a separate term of the bounds, and a 10 µm quantiser would add its own
    chatter to a small-signal measurement). Samples at the plant steps (the controller's period by
    default), so s[n] is the sampled step response of the discrete loop from set-point words to lengths."""
    from dataclasses import replace

    if not (isinstance(leg, (int, np.integer)) and 0 <= leg < 6):
        raise ValueError(f"leg must be 0 … 5, got {leg!r}")
    if not (math.isfinite(step) and step != 0):
        raise ValueError(f"step must be a non-zero number of metres, got {step!r}")
    cfg = config or ControllerConfig.for_platform(platform)
    cfg = replace(cfg, timing=replace(cfg.timing, sensor_resolution=1e-9))
    home = platform.home_pose()
    rest = Trajectory("home", lambda t: np.broadcast_to(home, np.shape(t) + (6,)).copy(), duration)
    runs = []
    for delta in (0.0, step):
        sim = build_simulation(platform, rest, "float", cfg, actuators)
        off = np.zeros(6)
        off[leg] = delta
        sim.controller.setpoint_offset = off
        runs.append(sim.run(duration))
    return runs[1].t, (runs[1].lengths - runs[0].lengths) / step


def setpoint_step_gain(platform: Platform, config: ControllerConfig | None = None, leg: int = 0, **kwargs) -> dict:
    """The ℓ1 gain ‖h‖₁ of the closed loop from a leg's set-point to leg lengths, from the float twin's
    set-point step response (``setpoint_step_response``; ``kwargs`` go there): h[n] = s[n] − s[n−1] is the
    sampled impulse response, ‖h‖₁ = Σ|h[n]| the total variation of the step response (plus
    |1 − s_end|, the least variation still to come before the stepped leg settles at its DC gain 1).

    Why it bounds the fixed-point controller's extra error: the fixed-point set-points are the float
    twin's plus an error sequence ε[k] (the 16-bit IK's error, the 1 mm LSB steps, and the sensor's counts
    acting like a set-point offset) with |ε[k]| ≤ A = Δ_IK + LSB + r. The loop about the trajectory is
    linear in that small perturbation, so the extra length error is y = h * ε and
    |y[n]| ≤ Σ_k |h[n−k]|·|ε[k]| ≤ ‖h‖₁·A — tight for the worst-case input ε[k] = A·sign h[n−k].
    The stepped leg's ‖h‖₁ ≥ 1 (the variation from 0 to the DC gain 1 is at least 1; overshoot adds twice
    each excursion). With all six set-points in error at once, leg i collects Σ_j ‖h_ij‖₁; ``coupled`` is
    the column sum Σ_i ‖h_ij‖₁ of the stepped leg, equal to that row sum when the platform's symmetry
    maps any leg onto any other (the hexapods here, at home).

    Returns ``{"diagonal": ‖h_jj‖₁, "coupled": Σ_i ‖h_ij‖₁, "tail": |1 − s_jj(end)|, "peak": max s_jj,
    "t": t, "s": s}``."""
    t, s = setpoint_step_response(platform, config, leg, **kwargs)
    tv = np.abs(np.diff(np.vstack([np.zeros((1, 6)), s]), axis=0)).sum(axis=0)
    tail = float(abs(1.0 - s[-1, leg]))
    diag = float(tv[leg] + tail)
    coupled = float(tv.sum() - tv[leg] + diag + np.abs(np.delete(s[-1], leg)).sum())
    return {"diagonal": diag, "coupled": coupled, "tail": tail, "peak": float(s[:, leg].max()), "t": t, "s": s}


def design_poses(trajectory: Trajectory, duration: float | None = None, n: int = 64) -> np.ndarray:
    """``(n, 6)`` poses of ``trajectory`` evenly spread over [0, ``duration``] (default the trajectory's
    duration, else 4 s): what the default gain design (``control.design_gains``) takes as the poses the
    loop will visit (the struts' stiffness and the leg-space masses vary along the way)."""
    d = duration if duration is not None else (trajectory.duration or 4.0)
    if not (math.isfinite(d) and d >= 0):
        raise ValueError(f"design duration must be a number of seconds >= 0, got {d!r}")
    return trajectory.pose(np.linspace(0.0, d, n))


def simulate(platform: Platform, trajectory="seed", controller: str = "fixed", duration: float | None = None, progress=False, **kwargs) -> "SimulationLog":
    """Build and run: the logs of ``duration`` seconds (default the trajectory's own duration); the
    default gains are designed over the poses of the run."""
    traj = get_trajectory(trajectory)
    duration = duration if duration is not None else (traj.duration or 1.0)
    if kwargs.get("config") is None:
        kwargs.setdefault("design_duration", max(duration, traj.duration or 0.0))
    return build_simulation(platform, traj, controller, **kwargs).run(duration, progress=progress)


# ----------------------------------------------------------------------------------------------
# Logs.


@dataclass
class SimulationLog:
    """The logs of one run, numpy arrays in SI units.

    ``t`` (n,) plant-step times; ``pose`` (n, 6) measured plate pose (utn); ``lengths`` (n, 6) true leg
    lengths; ``command`` (n, 6) held controller output (N); ``setpoint`` (n, 6) held set-points (m);
    ``force`` (n, 6) actuator forces (N); ``status`` (n, len(STATUS)); ``t_ref`` (m,), ``reference``
    (m, 6) the pose reference at the controller's ticks.
    """

    kind: str
    platform: str
    trajectory: str
    sample_period: float
    t: np.ndarray
    pose: np.ndarray
    lengths: np.ndarray
    command: np.ndarray
    setpoint: np.ndarray
    force: np.ndarray
    status: np.ndarray
    t_ref: np.ndarray
    reference: np.ndarray

    ARRAYS = ("t", "pose", "lengths", "command", "setpoint", "force", "status", "t_ref", "reference")

    def tick_times(self) -> np.ndarray:
        """The controller's tick times read from the logged status (one per tick, in order)."""
        ticks = self.status[:, STATUS.index("ticks")].astype(int)
        times = self.status[:, STATUS.index("last_tick_time")]
        first = np.r_[True, np.diff(ticks) != 0] & (ticks > 0)
        return times[first]

    def saturations(self) -> np.ndarray:
        """``(6,)`` saturated ticks per leg over the run."""
        return self.status[-1, 4:10].copy()

    def length_error(self, trajectory: Trajectory, platform: Platform) -> np.ndarray:
        """``(n, 6)`` true leg length − the exact IK of the reference at the same time (m)."""
        return self.lengths - leg_lengths(platform, trajectory.pose(self.t))

    def pose_error(self, trajectory: Trajectory) -> np.ndarray:
        """``(n, 6)`` measured pose − reference pose at the same time (m, rad)."""
        return self.pose - trajectory.pose(self.t)

    def save(self, directory) -> list[Path]:
        """Write ``log.npz`` (every array) and ``log.csv`` (one row per plant step); return the paths."""
        d = Path(directory)
        d.mkdir(parents=True, exist_ok=True)
        npz = d / "log.npz"
        np.savez(npz, **{k: getattr(self, k) for k in self.ARRAYS}, kind=self.kind, platform=self.platform, trajectory=self.trajectory, sample_period=self.sample_period)
        header = (
            ["t"] + [f"pose_{c}" for c in ("px", "py", "pz", "ax", "ay", "az")]
            + [f"L{i}" for i in range(1, 7)] + [f"setpoint{i}" for i in range(1, 7)]
            + [f"command{i}" for i in range(1, 7)] + [f"force{i}" for i in range(1, 7)] + list(STATUS)
        )
        rows = np.concatenate([self.t[:, None], self.pose, self.lengths, self.setpoint, self.command, self.force, self.status], axis=1)
        path = d / "log.csv"
        with path.open("w", newline="") as fh:
            w = csv.writer(fh)
            w.writerow(header)
            w.writerows([[repr(float(v)) for v in r] for r in rows])
        return [npz, path]


# ----------------------------------------------------------------------------------------------
# Verdict.

# Tracking is lost when a leg's length error or the plate's position error exceeds this fraction of the
# stroke range (20 mm on utn-dynamic's 0.4 m stroke; the seed run's error is ~1 mm).
TRACKING_LOST_FRACTION = 0.05
# A leg whose command stays saturated (at the command range) longer than this, in one stretch, has
# lost authority over its leg.
MAX_SATURATION_S = 0.05


def longest_saturation(log: "SimulationLog") -> np.ndarray:
    """``(6,)`` the longest stretch (s) over which each leg's command was saturated on every tick."""
    ticks = log.status[:, STATUS.index("ticks")].astype(int)
    first = np.r_[True, np.diff(ticks) != 0] & (ticks > 0)
    counts = log.status[first][:, 4:10]
    sat = np.diff(np.vstack([np.zeros((1, 6)), counts]), axis=0) > 0  # (ticks, 6) saturated on that tick
    out = np.zeros(6)
    for j in range(6):
        s = np.r_[0, sat[:, j].astype(np.int8), 0]
        d = np.diff(s)
        starts, ends = np.flatnonzero(d == 1), np.flatnonzero(d == -1)
        out[j] = (ends - starts).max() * log.sample_period if len(starts) else 0.0
    return out


def tracking_verdict(platform: Platform, length_error, pose_error, log: "SimulationLog") -> dict:
    """Whether a run tracked its reference: ``{"tracking_bound_mm", "saturation_bound_s",
    "longest_saturation_s" (6,), "failures": [messages]}``; a failure is a leg error or plate position
    error beyond ``TRACKING_LOST_FRACTION`` × the stroke range (lost tracking, with its first time), or a
    leg saturated for longer than ``MAX_SATURATION_S`` in one stretch."""
    bound = TRACKING_LOST_FRACTION * float(platform.L_max - platform.L_min)
    failures = []
    e = np.abs(np.asarray(length_error))
    pe = np.linalg.norm(np.asarray(pose_error)[:, :3], axis=1)
    for name, err, legwise in (("leg length", e, True), ("plate position", pe, False)):
        bad = (err > bound).reshape(len(err), -1).any(axis=1)
        if np.any(bad):
            i = int(np.argmax(bad))
            which = f" of leg {int(np.argmax(err[i])) + 1}" if legwise else ""
            failures.append(f"tracking lost: the {name} error{which} exceeds {bound * 1e3:.1f} mm ({TRACKING_LOST_FRACTION:g} × the stroke range) "
                            f"first at t = {log.t[i]:.4f} s, and reaches {err.max() * 1e3:.1f} mm")
    longest = longest_saturation(log)
    for j in np.flatnonzero(longest > MAX_SATURATION_S):
        failures.append(f"leg {j + 1} saturated for {longest[j]:.3f} s in one stretch (longer than {MAX_SATURATION_S:g} s): "
                        "its actuator cannot follow the reference")
    return {"tracking_bound_mm": bound * 1e3, "saturation_bound_s": MAX_SATURATION_S,
            "longest_saturation_s": longest.tolist(), "failures": failures}
