"""The motion a rider on the platform feels: poses sampled in time → specific force and angular velocity at the
rider's head, in the head frame, as a ``Drive`` that the scores compare with the vehicle's.

The rider sits on the plate, level at the home pose: the head frame is the plate frame turned back by the home
pose's rotation (x forward, y left, z up at home). The head is the pose's point (the platform's rotation centre)
plus ``head`` in the plate frame. Accelerations are second central differences of the sampled head positions
(ends: the next sample's), angular velocities the sampled Euler-angle rates (central differences) through the
convention's rate map; the specific force is ``R_headᵀ (a + g e_z)`` with the base's z axis up.
"""

from __future__ import annotations

import numpy as np

from stewart_drake.control.cueing.drive import GRAVITY, Drive
from stewart_drake.core.argcheck import as_poses
from stewart_drake.core.rotations import angles_from_matrix, angular_velocity_map, rotation_matrix
from stewart_drake.errors import CueingError


def platform_drive(poses, t, home, head=(0.0, 0.0, 0.0), name: str = "platform") -> Drive:
    """The ``Drive`` felt at the head of a rider on the platform moving through ``poses``.

    Args:
        poses: ``(N, 6)`` poses (m, rad, ``utn``) at the times ``t``.
        t: ``(N,)`` s, uniform step (N >= 3).
        home: ``(6,)`` the home pose, where the rider sits level.
        head: ``(3,)`` m, the head in the plate frame, from the pose's point.
        name: the drive's name.

    Returns:
        A ``Drive`` with ``specific_force`` and ``angular_velocity`` ``(N, 3)`` in the head frame and the head
        frame's roll, pitch, yaw from home as ``attitude`` (``zyx``, as a vehicle drive's).
    """
    q = as_poses(poses)
    t = np.asarray(t, dtype=float)
    if q.ndim != 2 or t.shape != (len(q),):
        raise CueingError(CueingError.POSES_TIMES.format(n=q.shape[0] if q.ndim else 1, m=t.size))
    dt = float(t[1] - t[0]) if len(t) > 1 else 1.0
    R_home = rotation_matrix(np.asarray(home, dtype=float)[3:])
    R = rotation_matrix(q[:, 3:])
    R_head = R @ R_home.T
    p = q[:, :3] + R @ np.asarray(head, dtype=float)
    a = np.empty_like(p)
    a[1:-1] = (p[2:] - 2.0 * p[1:-1] + p[:-2]) / dt**2
    a[0], a[-1] = a[1], a[-2]
    f = np.einsum("nji,nj->ni", R_head, a + np.array([0.0, 0.0, GRAVITY]))
    rates = np.gradient(q[:, 3:], dt, axis=0)
    w_base = np.einsum("nij,nj->ni", angular_velocity_map(q[:, 3:]), rates)
    w = np.einsum("nji,nj->ni", R_head, w_base)
    return Drive(name, t, f, w, angles_from_matrix(R_head, "zyx"))
