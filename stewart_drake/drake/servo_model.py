"""The Drake side of the RC-servo hexapod (seed 002): the closed-loop plant of its SDF
(``core/sdf_models.servo_hexapod_sdf``), cross-checks against the numpy solver, and the seed's control
loop as discrete systems.

Model names: ``base``, ``platform`` (link frame P), frames ``pivot_i``, ``platform_anchor_i`` and
``arm_tip_i``; ``arm_i`` on the actuated revolute ``servo_i`` whose angle is the servo's mechanical
angle (``mechanisms/servo_mounting``); ``rod_i`` on the ball joint ``rod_joint_i``, a ball constraint closing
its end onto ``platform_anchor_i`` (a discrete SAP plant, as ball constraints need).
"""

from __future__ import annotations

import math

import numpy as np
from pydrake.math import RigidTransform, RotationMatrix
from pydrake.multibody.inverse_kinematics import InverseKinematics
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph, DiscreteContactApproximation, MultibodyPlant
from pydrake.multibody.tree import PdControllerGains
from pydrake.solvers import SnoptSolver, SolverOptions
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import BasicVector, DiagramBuilder, LeafSystem
from pydrake.systems.primitives import LogVectorOutput, TrajectorySource
from pydrake.trajectories import PiecewisePolynomial

from stewart_drake.core.rotations import angles_from_matrix, rotation_matrix
from stewart_drake.core.sdf import rpy
from stewart_drake.core.sdf_models import SERVO_HEXAPOD_MODEL, servo_hexapod_sdf
from stewart_drake.errors import SimulationError
from stewart_drake.mechanisms.servo import (
    FRAME_RATE_HZ,
    ServoHexapod,
    angles_from_pulses,
    quantise_pulses,
    solve,
)
from stewart_drake.mechanisms.servo_loop import servo_gains
from stewart_drake.mechanisms.servo_mounting import (
    frame_from_zx,
    joint_arm_angles,
    pulse_joint_angles,
    servo_joint_home,
)

# Drake IK results are accepted when every rod length is this close to s (Drake FK), success flag or not:
# SNOPT reaches ~1e-9 m on this loop-closure problem before reporting "cannot be improved".
IK_GAP_TOL_M = 1e-8


def _simulate_and_read_logs(diagram, logs: dict, t_end: float) -> dict:
    """Simulate ``diagram`` to ``t_end``; return ``{"t": sample times, name: (n, k) logged data}``."""
    sim = Simulator(diagram)
    sim.AdvanceTo(t_end)
    ctx = sim.get_context()
    out = {}
    for name, log in logs.items():
        data = log.FindLog(ctx)
        out["t"] = data.sample_times()
        out[name] = data.data().T
    return out


def build_plant(hexapod: ServoHexapod, time_step: float = 1e-3, builder=None, pd_gains=None, visuals: bool = True):
    """A finalized discrete (SAP) closed-loop ``MultibodyPlant`` of the hexapod and its ``SceneGraph``.
    ``pd_gains`` = (kp N·m/rad, kd N·m·s/rad) makes every servo a PD-controlled actuator (Drake's
    implicit PD, clamped to the servo's effort limit, driven by the desired-state input port).
    ``visuals=False``: the plant alone (SceneGraph None; the parser then registers no geometry): the same
    dynamics (the model has no collision geometry), built and stepped faster, for what shows nothing."""
    if not time_step > 0:
        raise SimulationError(SimulationError.DISCRETE_STEP.format(value=time_step))
    builder = builder or DiagramBuilder()
    if visuals:
        plant, scene_graph = AddMultibodyPlantSceneGraph(builder, time_step)
    else:
        plant, scene_graph = builder.AddSystem(MultibodyPlant(time_step)), None
    plant.set_discrete_contact_approximation(DiscreteContactApproximation.kLagged)
    Parser(plant).AddModelsFromString(servo_hexapod_sdf(hexapod), "sdf")
    home = servo_joint_home(hexapod)
    for i in range(6):
        plant.GetJointByName(f"servo_{i + 1}").set_default_angle(home[i])
        if pd_gains is not None:
            plant.GetJointActuatorByName(f"servo_{i + 1}").set_controller_gains(
                PdControllerGains(p=pd_gains[0], d=pd_gains[1])
            )
    plant.Finalize()
    return plant, scene_graph


# ----------------------------------------------------------------------------------------------
# Cross-checks against Drake.


class ServoPlant:
    """A finalized plant of ``hexapod`` plus a context, with helpers to pose it."""

    def __init__(self, hexapod: ServoHexapod, time_step: float = 1e-3):
        self.hexapod = hexapod
        self.plant, _ = build_plant(hexapod, time_step, visuals=False)  # poses and IK only: nothing shown
        self.context = self.plant.CreateDefaultContext()
        p = self.plant
        self.servos = [p.GetJointByName(f"servo_{i + 1}") for i in range(6)]
        self.rods = [p.GetJointByName(f"rod_joint_{i + 1}") for i in range(6)]
        # looked up once: the pose loops of the cross-checks use them for every pose
        self.platform_body = p.GetBodyByName("platform")
        self.arms = [p.GetBodyByName(f"arm_{i + 1}") for i in range(6)]
        self.rod_frames = [  # each ball joint's fixed R_AF (on the arm) and R_RM (on the rod)
            (
                j.frame_on_parent().GetFixedPoseInBodyFrame().rotation().matrix(),
                j.frame_on_child().GetFixedPoseInBodyFrame().rotation().matrix(),
            )
            for j in self.rods
        ]
        self._frames = {}

    def frame_pose(self, name: str) -> np.ndarray:
        """``(3,)`` position of frame ``name`` in the world (= base) frame, metres."""
        frame = self._frames.get(name)
        if frame is None:
            frame = self._frames[name] = self.plant.GetFrameByName(name)
        return frame.CalcPoseInWorld(self.context).translation()

    def set_platform(self, pose) -> None:
        """Put the platform at a seed-002 pose [x, y, z, phi, theta, psi] (Rz·Ry·Rx)."""
        pose = np.asarray(pose, dtype=float)
        X = RigidTransform(RotationMatrix(rotation_matrix(pose[3:], "zyx")), pose[:3])
        self.plant.SetFreeBodyPose(self.context, self.platform_body, X)

    def set_servos(self, angles) -> None:
        """Servo joint angles (radians, the servo's own sense); each rod is then pointed at its anchor."""
        for i, j in enumerate(self.servos):
            j.set_angle(self.context, float(angles[i]))
        # Arm tips, anchors and arm frames do not depend on the rods' angles: read them all from one evaluation
        # of the kinematics before any rod is set (setting a rod first would make Drake recompute it per rod).
        tips = [self.frame_pose(f"arm_tip_{i + 1}") for i in range(6)]
        d_all = [self.frame_pose(f"platform_anchor_{i + 1}") - tips[i] for i in range(6)]
        R_WAs = [arm.EvalPoseInWorld(self.context).rotation().matrix() for arm in self.arms]
        for i, j in enumerate(self.rods):
            d, R_WA = d_all[i], R_WAs[i]
            R_Wrod = frame_from_zx(d, R_WA[:, 0])
            # Ball joint: R_FM with F fixed on the arm (its model-zero orientation relative to the arm).
            X_AF, X_RM = self.rod_frames[i]
            R_FM = (R_WA @ X_AF).T @ R_Wrod @ X_RM
            j.set_angles(self.context, rpy(R_FM))

    def servo_angles(self) -> np.ndarray:
        return np.array([j.get_angle(self.context) for j in self.servos])


def frame_errors(h: ServoPlant) -> dict:
    """Worst differences (m) between the parsed plant's frames and the geometry: pivots, anchors, arm length."""
    hex_ = h.hexapod
    piv = np.array([h.plant.GetFrameByName(f"pivot_{i + 1}").GetFixedPoseInBodyFrame().translation() for i in range(6)])
    anc = np.array(
        [h.plant.GetFrameByName(f"platform_anchor_{i + 1}").GetFixedPoseInBodyFrame().translation() for i in range(6)]
    )
    arm = np.array(
        [
            np.linalg.norm(h.plant.GetFrameByName(f"arm_tip_{i + 1}").GetFixedPoseInBodyFrame().translation())
            for i in range(6)
        ]
    )
    return {
        "pivots": float(np.abs(piv - hex_.base_pivots).max()),
        "anchors": float(np.abs(anc - hex_.platform_anchors).max()),
        "arm_length": float(np.abs(arm - hex_.arm_length).max()),
    }


def drake_home_joint_angles(h: ServoPlant, tol: float = 1e-10) -> np.ndarray:
    """The servo joint angles at the home pose found by Drake's ``InverseKinematics`` (arm and rod at
    right angles is *not* imposed: only the rod length s via the ball constraints)."""
    return drake_ik_joint_angles(h, h.hexapod.home_pose()[None], start=np.zeros(6), tol=tol)[0]


def drake_ik_joint_angles(h: ServoPlant, poses, start=None, tol: float = 1e-10) -> np.ndarray:
    """``(n, 6)`` servo joint angles found by Drake's ``InverseKinematics`` with the platform locked at
    each pose; the solver starts from ``start`` (default: the model's home joint angles)."""
    plant, ctx = h.plant, h.context
    start = servo_joint_home(h.hexapod) if start is None else np.asarray(start, float)
    solver, options = SnoptSolver(), SolverOptions()
    options.SetOption(solver.solver_id(), "Major feasibility tolerance", tol)
    options.SetOption(solver.solver_id(), "Major optimality tolerance", 1e-10)
    idx = np.array([j.position_start() for j in h.servos])
    platform_joint = plant.GetJointByName("platform")
    out = np.empty((len(poses), 6))
    for k, pose in enumerate(np.atleast_2d(poses)):
        h.set_platform(pose)
        h.set_servos(start)
        platform_joint.Lock(ctx)
        ik = InverseKinematics(plant, ctx)
        q = ik.q()
        ik.get_mutable_prog().AddQuadraticErrorCost(np.eye(6) * 1e-6, start, q[idx])
        result = solver.Solve(ik.prog(), plant.GetPositions(ctx), options)
        platform_joint.Unlock(ctx)
        out[k] = result.GetSolution(q)[idx]
        # SNOPT sometimes stops with "cannot be improved" at a point that already closes the loops far
        # below any mechanical tolerance: judge by Drake's own forward kinematics instead.
        h.set_servos(out[k])
        gap = max(
            abs(
                np.linalg.norm(h.frame_pose(f"platform_anchor_{i + 1}") - h.frame_pose(f"arm_tip_{i + 1}"))
                - h.hexapod.rod_length
            )
            for i in range(6)
        )
        if not (result.is_success() or gap <= IK_GAP_TOL_M):
            raise RuntimeError(
                f"Drake InverseKinematics failed at pose {k} {np.asarray(pose).tolist()}: "
                f"rod length off by {gap:.3g} m ({result.get_solution_result()})"
            )
    return out


def drake_rod_length_errors(h: ServoPlant, poses, pulse_us, joint_home) -> np.ndarray:
    """``(n, 6)`` | |arm tip − anchor| − s | (metres) computed by Drake's forward kinematics with the
    platform at each pose and each servo turned by the pulse width from ``joint_home``."""
    out = np.empty((len(poses), 6))
    for k, pose in enumerate(np.atleast_2d(poses)):
        h.set_platform(pose)
        h.set_servos(pulse_joint_angles(h.hexapod, pulse_us[k], joint_home))
        for i in range(6):
            d = h.frame_pose(f"platform_anchor_{i + 1}") - h.frame_pose(f"arm_tip_{i + 1}")
            out[k, i] = abs(np.linalg.norm(d) - h.hexapod.rod_length)
    return out


def compare_with_drake(hexapod: ServoHexapod, poses) -> dict:
    """All Drake cross-checks for reachable, in-travel ``poses`` (n, 6); worst errors.

    frames: SDF frames read back (m); home: Drake-IK home joint angles vs ``servo_joint_home`` (rad);
    fk: rod length error with the servos turned by the eq. 13-14 pulses (m); ik: Drake-IK joint angles
    vs the pulse-derived ones (rad); mirror_fk: the same FK check with the odd/even sign ignored (m),
    which must be large.
    """
    h = ServoPlant(hexapod)
    sol = solve(hexapod, poses)
    if not np.all(sol.ok):
        bad = int(np.argmin(sol.ok))
        raise SimulationError(SimulationError.SERVO_POSES.format(index=bad, why=sol.violations()[0]))
    home = drake_home_joint_angles(h)
    res = {"frames": max(frame_errors(h).values()), "home": float(np.abs(home - servo_joint_home(hexapod)).max())}
    res["fk"] = float(drake_rod_length_errors(h, poses, sol.pulse_raw, home).max())
    ik = drake_ik_joint_angles(h, poses, start=home)
    res["ik"] = float(np.abs(ik - pulse_joint_angles(hexapod, sol.pulse_raw, home)).max())
    unmirrored = hexapod.neutral_us + np.abs(sol.pulse_raw - hexapod.neutral_us) * np.sign(sol.delta)
    res["mirror_fk"] = float(drake_rod_length_errors(h, poses, unmirrored, home).max())
    return res


# ----------------------------------------------------------------------------------------------
# The seed's control loop as a discrete system.


class ServoController(LeafSystem):
    """The seed's loop (read pose → R → l_i → alpha_i → W_i → output) at the servo frame rate.

    Input ``pose`` (6): [x, y, z, phi, theta, psi] (m, rad, Rz·Ry·Rx). Every 1/frame_rate_hz s the system
    samples the pose and latches, zero-order-hold, these state outputs:
    - ``pulse_us`` (6): eqs. 13-14 clamped to the travel and rounded to ``resolution_us`` (the driver);
    - ``status`` (6): 0 ok, 1 travel limit hit (pulse clamped), 2 unreachable (pulse of the nearest angle);
    - ``arm_angle`` (6): the arm angles (rad) the quantised pulses command (eqs. 13-14 inverted).
    Outputs depend on state only (no direct feedthrough): one frame of delay, as on the real loop.
    Initial state: every servo at its neutral pulse (home).
    """

    def __init__(self, hexapod: ServoHexapod, frame_rate_hz: float = FRAME_RATE_HZ, resolution_us: float = 1.0):
        if not frame_rate_hz > 0:
            raise SimulationError(SimulationError.FRAME_RATE.format(value=frame_rate_hz))
        super().__init__()
        self.hexapod, self.period, self.resolution_us = hexapod, 1.0 / frame_rate_hz, resolution_us
        self._pose = self.DeclareVectorInputPort("pose", 6)
        w0 = quantise_pulses(hexapod.neutral_us, resolution_us)
        self._pulse = self.DeclareDiscreteState(BasicVector(w0))
        self._status = self.DeclareDiscreteState(6)
        self.DeclarePeriodicDiscreteUpdateEvent(self.period, 0.0, self._CalcUpdate)
        self.DeclareStateOutputPort("pulse_us", self._pulse)
        self.DeclareStateOutputPort("status", self._status)
        self.DeclareVectorOutputPort("arm_angle", 6, self._CalcArmAngle, {self.xd_ticket()})

    def _CalcUpdate(self, context, state):
        sol = solve(self.hexapod, self._pose.Eval(context))
        status = np.where(~sol.reachable, 2.0, np.where(~sol.within_travel, 1.0, 0.0))
        state.get_mutable_vector(self._pulse).SetFromVector(quantise_pulses(sol.pulse, self.resolution_us))
        state.get_mutable_vector(self._status).SetFromVector(status)

    def _CalcArmAngle(self, context, output):
        output.SetFromVector(angles_from_pulses(self.hexapod, context.get_discrete_state(self._pulse).value()))


def run_controller(
    hexapod: ServoHexapod,
    times,
    poses,
    duration: float | None = None,
    frame_rate_hz: float = FRAME_RATE_HZ,
    resolution_us: float = 1.0,
) -> dict:
    """Drive the controller in a Diagram with a first-order-hold pose trajectory through ``(times,
    poses)`` (n,), (n, 6); return ``t`` (k,), ``pulse_us`` (k, 6), ``status`` (k, 6) and ``pose`` (k, 6)
    logged once per frame. Drake publishes a log sample at t_k before that instant's update, so
    ``pulse_us[k]`` is the pulse held during [t_k - T, t_k), computed from ``pose[k - 1]`` (the one-frame
    delay); ``pulse_us[0]`` is the initial (neutral) state."""
    times = np.asarray(times, dtype=float)
    poses = np.asarray(poses, dtype=float)
    builder = DiagramBuilder()
    src = builder.AddSystem(TrajectorySource(PiecewisePolynomial.FirstOrderHold(times, poses.T)))
    ctrl = builder.AddSystem(ServoController(hexapod, frame_rate_hz, resolution_us))
    builder.Connect(src.get_output_port(), ctrl.GetInputPort("pose"))
    T = 1.0 / frame_rate_hz
    logs = {name: LogVectorOutput(ctrl.GetOutputPort(name), builder, T) for name in ("pulse_us", "status")}
    logs["pose"] = LogVectorOutput(src.get_output_port(), builder, T)
    out = _simulate_and_read_logs(builder.Build(), logs, float(times[-1] if duration is None else duration))
    return out


# ----------------------------------------------------------------------------------------------
# The loop closed: controller → servos → closed-loop plant.


class ServoDrive(LeafSystem):
    """Six hobby servos' electronics, pulse width → the plant's PD set-point.

    Input ``pulse_us`` (6). Each servo's target is the joint angle ``pulse_joint_angles`` (its physics:
    (W − W0)/r from home, in the pulse-increasing sense). Every ``time_step`` (s) the set-point moves
    toward the target by at most ``servo_speed``·time_step (the no-load speed limit); output
    ``desired_state`` (12) = [set-points; their rates], for ``MultibodyPlant``'s desired-state port,
    whose implicit PD (``servo_gains``) clamps the torque to the stall torque. Initial set-point:
    ``joint_home`` (6,), radians.
    """

    def __init__(self, hexapod: ServoHexapod, joint_home, time_step: float):
        super().__init__()
        self.hexapod, self.time_step = hexapod, time_step
        self.joint_home = np.asarray(joint_home, dtype=float)
        self.max_step = hexapod.servo_speed * time_step
        self._pulse = self.DeclareVectorInputPort("pulse_us", 6)
        self._xd = self.DeclareDiscreteState(BasicVector(np.r_[self.joint_home, np.zeros(6)]))
        self.DeclarePeriodicDiscreteUpdateEvent(time_step, 0.0, self._CalcUpdate)
        self.DeclareStateOutputPort("desired_state", self._xd)

    def _CalcUpdate(self, context, state):
        q = context.get_discrete_state(self._xd).value()[:6]
        target = pulse_joint_angles(self.hexapod, self._pulse.Eval(context), self.joint_home)
        # np.clip's arithmetic (max, then min) without its per-call overhead: this runs every time step
        dq = np.minimum(np.maximum(target - q, -self.max_step), self.max_step)
        state.get_mutable_vector(self._xd).SetFromVector(np.concatenate((q + dq, dq / self.time_step)))


def run_closed_loop(
    hexapod: ServoHexapod,
    times,
    poses,
    duration: float | None = None,
    time_step: float = 1e-3,
    frame_rate_hz: float = FRAME_RATE_HZ,
    resolution_us: float = 1.0,
) -> dict:
    """The seed's control loop closed in simulation, one Diagram::

        TrajectorySource(pose ref) → ServoController (50 Hz, 1 µs) → ServoDrive (speed limit) → plant (PD servos)

    The reference is a first-order hold through ``(times, poses)`` (n,), (n, 6) (m, rad, zyx). The plant
    starts at rest at home. Returns, sampled every ``time_step`` (k samples): ``t``, ``reference`` and
    ``pose`` (platform, from the plant state) (k, 6); ``arm_angle`` (k, 6), the simulated arms' alpha;
    ``arm_angle_ref`` (k, 6), eq. 9 at the reference; ``rod_gap`` (k, 6) | |arm tip − anchor| − s | (m),
    the ball constraints' violation; ``pulse_us`` (k, 6); ``status`` (k, 6).
    """
    times = np.asarray(times, dtype=float)
    poses = np.asarray(poses, dtype=float)
    if poses.shape != (len(times), 6) or len(times) < 2:
        raise SimulationError(
            SimulationError.CLOSED_LOOP_SHAPES.format(times_shape=times.shape, poses_shape=poses.shape)
        )
    if not time_step > 0:
        raise SimulationError(SimulationError.TIME_STEP.format(value=time_step))
    builder = DiagramBuilder()
    plant, _ = build_plant(hexapod, time_step, builder, pd_gains=servo_gains(hexapod), visuals=False)
    home = servo_joint_home(hexapod)
    src = builder.AddSystem(TrajectorySource(PiecewisePolynomial.FirstOrderHold(times, poses.T)))
    ctrl = builder.AddSystem(ServoController(hexapod, frame_rate_hz, resolution_us))
    drive = builder.AddSystem(ServoDrive(hexapod, home, time_step))
    instance = plant.GetModelInstanceByName(SERVO_HEXAPOD_MODEL)
    order = [
        int(plant.get_joint_actuator(a).joint().name().split("_")[1]) - 1
        for a in plant.GetJointActuatorIndices(instance)
    ]
    if order != list(range(6)):
        raise RuntimeError(f"servo actuators are not in the order servo_1..servo_6: {order}")
    builder.Connect(src.get_output_port(), ctrl.GetInputPort("pose"))
    builder.Connect(ctrl.GetOutputPort("pulse_us"), drive.GetInputPort("pulse_us"))
    builder.Connect(drive.GetOutputPort("desired_state"), plant.get_desired_state_input_port(instance))
    logs = {
        "reference": LogVectorOutput(src.get_output_port(), builder, time_step),
        "state": LogVectorOutput(plant.get_state_output_port(), builder, time_step),
        "pulse_us": LogVectorOutput(ctrl.GetOutputPort("pulse_us"), builder, time_step),
        "status": LogVectorOutput(ctrl.GetOutputPort("status"), builder, time_step),
    }
    out = _simulate_and_read_logs(builder.Build(), logs, float(times[-1] if duration is None else duration))
    # Kinematics of the logged states.
    pc = plant.CreateDefaultContext()
    body = plant.GetBodyByName("platform")
    servos = [plant.GetJointByName(f"servo_{i + 1}") for i in range(6)]
    tips = [plant.GetFrameByName(f"arm_tip_{i + 1}") for i in range(6)]
    anchors = [plant.GetFrameByName(f"platform_anchor_{i + 1}") for i in range(6)]
    nq = plant.num_positions()
    k = len(out["t"])
    pose, R, joints, gap = np.empty((k, 6)), np.empty((k, 3, 3)), np.empty((k, 6)), np.empty((k, 6))
    for j, x in enumerate(out.pop("state")):
        plant.SetPositions(pc, x[:nq])
        X = plant.EvalBodyPoseInWorld(pc, body)
        pose[j, :3] = X.translation()
        R[j] = X.rotation().matrix()
        joints[j] = [sj.get_angle(pc) for sj in servos]
        for i in range(6):
            d = anchors[i].CalcPoseInWorld(pc).translation() - tips[i].CalcPoseInWorld(pc).translation()
            gap[j, i] = abs(math.sqrt(d.dot(d)) - hexapod.rod_length)  # np.linalg.norm's own sum for a vector
    pose[:, 3:] = angles_from_matrix(R, "zyx")  # elementwise: the same bits as one matrix at a time
    out.update(
        pose=pose,
        arm_angle=joint_arm_angles(hexapod, joints),
        rod_gap=gap,
        arm_angle_ref=solve(hexapod, out["reference"]).angles,
    )
    return out
