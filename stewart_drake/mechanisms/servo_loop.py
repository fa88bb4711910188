"""The RC-servo hexapod's control loop in numbers (numpy only): the servos' position-loop gains from
their datasheet, the static torques that hold a pose, and the bounds on the closed loop's tracking
error that follow from the loop's timing and arithmetic. ``drake/servo_model.run_closed_loop`` runs the
loop these describe; the tests and the report hold its log against ``tracking_bounds``.
"""

from __future__ import annotations

import numpy as np

from stewart_drake.errors import SimulationError
from stewart_drake.mechanisms.servo import FRAME_RATE_HZ, ServoHexapod, arm_angles, pose_jacobian


def servo_gains(hexapod: ServoHexapod) -> tuple[float, float]:
    """``(kp, kd)`` of the servo's position loop, from the datasheet numbers (a DC motor behind a
    proportional position loop): kp = stall torque / ``servo_band`` (full torque that far from the
    target; 1 N·m / 2° = 28.6 N·m/rad for the preset) and kd = stall torque / no-load speed (the motor's
    back-EMF damping seen at the horn: 1 N·m / 6.16 rad/s = 0.162 N·m·s/rad)."""
    return hexapod.servo_torque / hexapod.servo_band, hexapod.servo_torque / hexapod.servo_speed


def static_servo_torques(hexapod: ServoHexapod, poses, g: float = 9.81) -> np.ndarray:
    """``(..., 6)`` the torques (N·m, about alpha) that hold the hexapod still at ``poses`` (..., 6),
    by virtual work: Jᵀτ = −Q with J = dalpha/dpose and Q = [0, 0, −m g, 0, 0, 0] the gravity force on
    the platform plus half of each rod (the centre of mass is the platform origin); each servo also
    carries its arm's weight at a/2 and half its rod at a (cos alpha lever)."""
    m = hexapod.platform_mass + 3 * hexapod.rod_mass
    J = pose_jacobian(hexapod, poses)
    Q = np.zeros(np.shape(J)[:-2] + (6,))
    Q[..., 2] = -m * g
    tau = -np.linalg.solve(np.swapaxes(J, -1, -2), Q[..., None])[..., 0]
    alpha = arm_angles(hexapod, poses)[0]
    return tau + (hexapod.arm_mass / 2 + hexapod.rod_mass / 2) * g * hexapod.arm_length * np.cos(alpha)


def tracking_bounds(
    hexapod: ServoHexapod,
    log: dict,
    time_step: float = 1e-3,
    frame_rate_hz: float = FRAME_RATE_HZ,
    resolution_us: float = 1.0,
) -> dict:
    """Per-sample bounds on the closed-loop tracking error of ``run_closed_loop``'s ``log``, from the
    loop's arithmetic, valid while every reference arm speed stays below ``servo_speed`` (checked):

    arm (k, 6), radians: |alpha − alpha_ref(t)| <= max over s in [t − Λ, t] |alpha_ref(t) − alpha_ref(s)|
        + q/2 + sag, where Λ = T (the pose is sampled once per frame and held) + 2 dt (the drive and the
        plant read their inputs one step late) + kd/kp (the servo's PD lag); q/2 = half the pulse
        resolution in angle (rounding; 0.056° for 1 µs); sag = static torque / kp (a proportional servo
        under load). A reference arm speed below the no-load speed means the speed limit adds no lag.
    pose (k, 6), m and rad: sum_i |J⁻¹_ki| arm_i, the first-order image of the arm bound (J = dalpha/dpose).
    """
    t, ref = log["t"], log["arm_angle_ref"]
    rate = np.abs(np.diff(ref, axis=0)) / np.diff(t)[:, None]
    if rate.max() >= hexapod.servo_speed:
        raise SimulationError(SimulationError.SERVO_SPEED.format(rate=rate.max(), speed=hexapod.servo_speed))
    kp, kd = servo_gains(hexapod)
    lag = 1.0 / frame_rate_hz + 2 * time_step + kd / kp
    n = int(np.ceil(lag / time_step))
    padded = np.concatenate([np.repeat(ref[:1], n, axis=0), ref])  # at rest at alpha_ref(0) before t = 0
    spread = np.max([np.abs(ref - padded[n - j : n - j + len(ref)]) for j in range(n + 1)], axis=0)
    quant = resolution_us / 2 / hexapod.rate_us_per_rad
    sag = np.abs(static_servo_torques(hexapod, log["reference"])) / kp
    arm = spread + quant + sag
    Jinv = np.linalg.inv(pose_jacobian(hexapod, log["reference"]))
    return {
        "arm": arm,
        "pose": np.einsum("...ki,...i->...k", np.abs(Jinv), arm),
        "lag": lag,
        "quantisation": quant,
        "sag": sag,
    }
