"""The 3R planar robotic leg of seed 003: Denavit–Hartenberg forward kinematics and geometric inverse
kinematics with both elbow branches (plain numpy, batched over leading dimensions).

The chain (seed Table 1, all d = 0 and alpha_DH = 0): joint 1 theta = q1 - 90°, a = l1 (thigh);
joint 2 theta = q2, a = l2 (shank); joint 3 theta = alpha (fixed), a = l3 (foot), with
alpha = 134.6° - 180° = -45.4°. Only q1 (hip) and q2 (knee) move. In the DH base frame 0 (x forward,
y up, the leg hangs down at q = 0) the foot is (seed eqs. 7-9)

    Px = l1 sin q1 + l2 sin(q1+q2) + l3 sin(q1+q2+alpha)
    Py = -l1 cos q1 - l2 cos(q1+q2) - l3 cos(q1+q2+alpha),      gamma = q1 + q2 + alpha.

The seed's inverse kinematics (eqs. 13-20) has errors; ``inverse_kinematics_3r`` is the corrected
method and ``seed_inverse_kinematics`` the printed one, kept to show the difference:
- eqs. 13-14 work "before the -90° rotation": in that frame the target is (x, y) = (-Py, Px) (the seed
  never rotates it) and the wrist is (x - l3 cos gamma, y - l3 sin gamma) (eq. 14 prints cos);
- eq. 15 gives the elbow angle delta by the law of cosines; it *is* the knee angle: q2 = ±delta.
  Eq. 18's ±(180° - alpha) is the fixed ankle angle's supplement, unrelated to the target;
- eq. 16's asin(l2 sin delta / r) is wrong when the elbow is obtuse (l1 + l2 cos delta < 0) and eq. 17's
  atan loses the quadrant: q1 = atan2(y_w, x_w) ∓ atan2(l2 sin delta, l1 + l2 cos delta);
- eq. 17 prints "theta1^b = theta1^a = ..." (a typo), and the printed T0^3 is garbled: its rotation
  block is [[sin g, cos g], [-cos g, sin g]] and (Px, Py, 0) belongs in the last column.
With the ankle fixed, gamma is not free: ``inverse_kinematics`` solves the 2-DOF leg from the foot
position alone (links 2 and 3 are one rigid body: a virtual shank of length l23 at angle phi).

Branches: "a" has the (virtual) knee angle >= 0 and "b" <= 0, as the seed pairs eqs. 17-18.
Angles in radians, lengths in metres.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from stewart_drake.core.argcheck import first_index
from stewart_drake.core.rotations import wrap_angle
from stewart_drake.errors import LegError, UnreachableTargetError

ALPHA_SEED = np.radians(134.6 - 180.0)
BRANCHES = ("a", "b")
# A target this close (relative) outside the reachable annulus is treated as on its boundary (rounding).
BOUNDARY_RTOL = 1e-12


# The longest link taken (m): a legged robot's links are centimetres to a metre; squares of lengths far beyond
# (1e308) overflow the IK's arithmetic.
MAX_LINK_M = 100.0


@dataclass(frozen=True)
class Leg3R:
    """The seed-003 leg. Lengths in metres, angles in radians.

    Defaults are our choice (the seed gives no numbers): a small servo-driven leg with thigh l1 = 80 mm,
    shank l2 = 80 mm, foot l3 = 30 mm; hip q1 in [-90°, 90°] and knee q2 in [-135°, 135°] (what a
    standard RC servo and a printed knee allow); the seed's fixed ankle alpha = -45.4°.
    """

    l1: float = 0.080
    l2: float = 0.080
    l3: float = 0.030
    alpha: float = float(ALPHA_SEED)
    q1_limits: tuple = (float(np.radians(-90.0)), float(np.radians(90.0)))
    q2_limits: tuple = (float(np.radians(-135.0)), float(np.radians(135.0)))
    name: str = "leg-3r"

    def __post_init__(self):
        for n in ("l1", "l2", "l3"):
            v = getattr(self, n)
            if not (np.isfinite(v) and 0 < v <= MAX_LINK_M):
                raise LegError(LegError.LENGTH.format(name=n, value=v, limit=MAX_LINK_M))
        if not np.isfinite(self.alpha):
            raise LegError(LegError.ALPHA.format(value=self.alpha))
        for n in ("q1_limits", "q2_limits"):
            lo, hi = getattr(self, n)
            if not (np.isfinite(lo) and np.isfinite(hi) and lo < hi):
                raise LegError(LegError.LIMITS.format(name=n, value=getattr(self, n)))

    @property
    def shank(self) -> tuple[float, float]:
        """(l23, phi): the knee-to-foot distance and its angle from the shank's axis (links 2+3 rigid)."""
        x = self.l2 + self.l3 * np.cos(self.alpha)
        y = self.l3 * np.sin(self.alpha)
        return float(np.hypot(x, y)), float(np.arctan2(y, x))

    @property
    def reach(self) -> tuple[float, float]:
        """(r_min, r_max): the foot's distance from the hip over all q (ignoring joint limits), metres."""
        l23, _ = self.shank
        return abs(self.l1 - l23), self.l1 + l23


def dh_rows(leg: Leg3R) -> list[dict]:
    """The DH table (seed Table 1) as rows: ``joint``, ``link``, ``kind`` (revolute|fixed), ``theta``
    (the offset for a revolute joint, the value for a fixed one), ``d``, ``a``, ``alpha`` (DH twist)."""
    return [
        {"joint": "hip", "link": "thigh", "kind": "revolute", "theta": -np.pi / 2, "d": 0.0, "a": leg.l1, "alpha": 0.0},
        {"joint": "knee", "link": "shank", "kind": "revolute", "theta": 0.0, "d": 0.0, "a": leg.l2, "alpha": 0.0},
        {"joint": "ankle", "link": "foot", "kind": "fixed", "theta": leg.alpha, "d": 0.0, "a": leg.l3, "alpha": 0.0},
    ]


def dh_transform(theta, d, a, alpha) -> np.ndarray:
    """Seed eq. 2, A = Rotz(theta)·T(0,0,d)·T(a,0,0)·Rotx(alpha): ``(..., 4, 4)`` for broadcast inputs."""
    theta, d, a, alpha = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (theta, d, a, alpha)))
    ct, st, ca, sa = np.cos(theta), np.sin(theta), np.cos(alpha), np.sin(alpha)
    z, o = np.zeros_like(theta), np.ones_like(theta)
    rows = [ct, -ca * st, sa * st, a * ct, st, ca * ct, -sa * ct, a * st, z, sa, ca, d, z, z, z, o]
    return np.stack(rows, axis=-1).reshape(theta.shape + (4, 4))


def _check_q(q) -> np.ndarray:
    q = np.asarray(q, dtype=float)
    if q.shape[-1:] != (2,):
        raise LegError(LegError.ANGLES_2.format(shape=q.shape))
    return q


def frame_transforms(leg: Leg3R, q) -> np.ndarray:
    """``(..., 4, 4, 4)``: T_0^0 (identity), T_0^1, T_0^2, T_0^3 for joint angles ``q`` (..., 2)."""
    q = _check_q(q)
    out = [np.broadcast_to(np.eye(4), q.shape[:-1] + (4, 4))]
    for k, row in enumerate(dh_rows(leg)):
        theta = row["theta"] + (q[..., k] if row["kind"] == "revolute" else 0.0)
        out.append(out[-1] @ dh_transform(theta, row["d"], row["a"], row["alpha"]))
    return np.stack(out, axis=-3)


def forward_kinematics(leg: Leg3R, q) -> np.ndarray:
    """Seed eq. 6: ``(..., 4, 4)`` T_0^3 = A_0^1 A_1^2 A_2^3, the foot frame in the DH base frame."""
    return frame_transforms(leg, q)[..., 3, :, :]


def foot(leg: Leg3R, q) -> np.ndarray:
    """Seed eqs. 7-9: ``(..., 3)`` [Px, Py, gamma] (metres, metres, radians) for ``q`` (..., 2).

    ``q`` may also be ``(..., 3)`` [q1, q2, q3]: the general 3R chain with the ankle at q3 instead of alpha.
    """
    q = np.asarray(q, dtype=float)
    if q.shape[-1:] not in ((2,), (3,)):
        raise LegError(LegError.ANGLES_2_3.format(shape=q.shape))
    q3 = q[..., 2] if q.shape[-1] == 3 else leg.alpha
    s1, s12, g = q[..., 0], q[..., 0] + q[..., 1], q[..., 0] + q[..., 1] + q3
    px = leg.l1 * np.sin(s1) + leg.l2 * np.sin(s12) + leg.l3 * np.sin(g)
    py = -leg.l1 * np.cos(s1) - leg.l2 * np.cos(s12) - leg.l3 * np.cos(g)
    return np.stack([px, py, g], axis=-1)


def foot_jacobian(leg: Leg3R, q) -> np.ndarray:
    """``(..., 2, 2)`` d[Px, Py]/d[q1, q2] (metres per radian)."""
    q = _check_q(q)
    s1, s12, g = q[..., 0], q[..., 0] + q[..., 1], q[..., 0] + q[..., 1] + leg.alpha
    dx2 = leg.l2 * np.cos(s12) + leg.l3 * np.cos(g)
    dy2 = leg.l2 * np.sin(s12) + leg.l3 * np.sin(g)
    J = [leg.l1 * np.cos(s1) + dx2, dx2, leg.l1 * np.sin(s1) + dy2, dy2]
    return np.stack(J, axis=-1).reshape(q.shape[:-1] + (2, 2))


def seed_t03_rotation(gamma) -> np.ndarray:
    """The correct rotation block of T_0^3: ``(..., 2, 2)`` [[sin g, cos g], [-cos g, sin g]]."""
    g = np.asarray(gamma, dtype=float)
    return np.stack([np.sin(g), np.cos(g), -np.cos(g), np.sin(g)], -1).reshape(g.shape + (2, 2))


def check_branch(branch: str) -> float:
    """The knee sign of an elbow branch: +1 for 'a' (knee angle >= 0), -1 for 'b'; ``LegError`` otherwise."""
    if branch not in BRANCHES:
        raise LegError(LegError.BRANCH.format(branch=branch))
    return 1.0 if branch == "a" else -1.0


def _two_link(x, y, l1, l2, sign, what):
    """Both-branch 2R IK in the frame where angles are measured from x: (shoulder, elbow) angles."""
    r = np.hypot(x, y)
    lo, hi = abs(l1 - l2), l1 + l2
    c = (r**2 - l1**2 - l2**2) / (2 * l1 * l2)
    bad = (r < lo * (1 - BOUNDARY_RTOL)) | (r > hi * (1 + BOUNDARY_RTOL)) | ~np.isfinite(r)
    idx = first_index(bad)
    if idx is not None:
        raise UnreachableTargetError(idx, float(np.asarray(r)[idx]), lo, hi, what)
    elbow = sign * np.arccos(np.clip(c, -1.0, 1.0))  # eq. 15
    shoulder = np.arctan2(y, x) - np.arctan2(l2 * np.sin(elbow), l1 + l2 * np.cos(elbow))
    return wrap_angle(shoulder), elbow


def _check_target(target, n) -> np.ndarray:
    target = np.asarray(target, dtype=float)
    if target.shape[-1:] != (n,):
        raise LegError(LegError.TARGET.format(n=n, names="Px, Py" if n == 2 else "Px, Py, gamma", shape=target.shape))
    return target


def inverse_kinematics(leg: Leg3R, target, branch: str = "a") -> np.ndarray:
    """The leg's geometric IK: foot position ``target`` (..., 2) [Px, Py] -> ``(..., 2)`` [q1, q2].

    Links 2 and 3 form one rigid body (the ankle is fixed), so the foot is reached by a 2R chain of
    l1 and l23 whose elbow is q2 + phi. Raises ``UnreachableTargetError`` naming the first target out
    of reach; joint limits are not applied (see ``within_limits``).
    """
    sign = check_branch(branch)
    t = _check_target(target, 2)
    l23, phi = leg.shank
    q1, elbow = _two_link(-t[..., 1], t[..., 0], leg.l1, l23, sign, "the foot")
    return np.stack([q1, wrap_angle(elbow - phi)], axis=-1)


def inverse_kinematics_3r(leg: Leg3R, target, branch: str = "a") -> np.ndarray:
    """The seed's geometric 3R method, corrected: ``target`` (..., 3) [Px, Py, gamma] ->
    ``(..., 3)`` [q1, q2, q3] with gamma = q1 + q2 + q3 (q3 = alpha when the target came from this leg)."""
    sign = check_branch(branch)
    t = _check_target(target, 3)
    g = t[..., 2]
    x, y = -t[..., 1], t[..., 0]  # the frame "before the -90° rotation"
    xw, yw = x - leg.l3 * np.cos(g), y - leg.l3 * np.sin(g)  # eqs. 13-14, corrected
    q1, q2 = _two_link(xw, yw, leg.l1, leg.l2, sign, "the ankle (wrist)")
    return np.stack([q1, q2, wrap_angle(g - q1 - q2)], axis=-1)


SEED_FIXES = ("frame", "sin14", "elbow18", "atan2")
SEED_FIX_TEXT = {
    "frame": "rotate the target into the frame before the -90° offset: (x, y) = (-Py, Px)",
    "sin14": "eq. 14: y - l3 sin(gamma), not cos",
    "elbow18": "eq. 18: q2 = ±delta (eq. 15's elbow angle), not ±(180° - alpha)",
    "atan2": "eqs. 16-17: q1 = atan2(y_w, x_w) ∓ atan2(l2 sin q2, l1 + l2 cos q2), not asin/atan",
}


def seed_inverse_kinematics(leg: Leg3R, target, branch: str = "a", fixes=()) -> np.ndarray:
    """Seed eqs. 13-20 as printed, with any subset of the corrections ``fixes`` (names in
    ``SEED_FIXES``, explained in ``SEED_FIX_TEXT``) applied: ``(..., 3)`` [q1, q2, q3]; NaN where the
    formulas have no real value. With every fix this is ``inverse_kinematics_3r`` (without its
    reachability check). For showing the seed's errors, not for control."""
    sign = check_branch(branch)
    unknown = sorted(set(fixes) - set(SEED_FIXES))
    if unknown:
        raise LegError(LegError.SEED_FIX.format(fix=unknown[0], valid=", ".join(SEED_FIXES)))
    t = _check_target(target, 3)
    px, py, g = t[..., 0], t[..., 1], t[..., 2]
    x, y = (-py, px) if "frame" in fixes else (px, py)
    x02 = x - leg.l3 * np.cos(g)  # eq. 13
    y02 = y - leg.l3 * (np.sin(g) if "sin14" in fixes else np.cos(g))  # eq. 14
    r2 = x02**2 + y02**2
    with np.errstate(invalid="ignore", divide="ignore"):
        delta = np.arccos((r2 - leg.l1**2 - leg.l2**2) / (2 * leg.l1 * leg.l2))  # eq. 15
        q2 = sign * delta if "elbow18" in fixes else np.broadcast_to(sign * (np.pi - leg.alpha), delta.shape)  # eq. 18
        if "atan2" in fixes:
            q1 = np.arctan2(y02, x02) - np.arctan2(leg.l2 * np.sin(q2), leg.l1 + leg.l2 * np.cos(q2))
        else:
            beta = np.arcsin(leg.l2 * np.sin(delta) / np.sqrt(r2))  # eq. 16
            q1 = np.arctan(y02 / x02) - sign * beta  # eq. 17
    return np.stack([q1, q2, g - q1 - q2], axis=-1)  # eqs. 19-20


def within_limits(leg: Leg3R, q) -> np.ndarray:
    """``(...)`` True where q1 and q2 are inside their limits."""
    q = _check_q(q)
    (a, b), (c, d) = leg.q1_limits, leg.q2_limits
    return (q[..., 0] >= a) & (q[..., 0] <= b) & (q[..., 1] >= c) & (q[..., 1] <= d)


def limit_violations(leg: Leg3R, q) -> list[dict]:
    """Every joint-limit violation as ``{"index", "joint": "q1"|"q2", "value_rad", "limit_rad", "excess_rad"}``."""
    q = _check_q(q)
    out = []
    for j, (lo, hi) in enumerate((leg.q1_limits, leg.q2_limits)):
        v = q[..., j]
        for idx in np.argwhere((v < lo) | (v > hi)):
            idx = tuple(int(i) for i in idx)
            val = float(v[idx])
            lim = lo if val < lo else hi
            out.append(
                {
                    "index": list(idx),
                    "joint": f"q{j + 1}",
                    "value_rad": val,
                    "limit_rad": lim,
                    "excess_rad": abs(val - lim),
                }
            )
    return out


def joint_points(leg: Leg3R, q) -> np.ndarray:
    """``(..., 4, 2)`` hip, knee, ankle and foot positions in the DH base frame (for plots), metres."""
    return frame_transforms(leg, q)[..., :, :2, 3]


def random_configurations(leg: Leg3R, n: int, seed: int = 0) -> np.ndarray:
    """``(n, 2)`` joint angles uniform within the joint limits."""
    rng = np.random.default_rng(seed)
    return np.stack([rng.uniform(*leg.q1_limits, n), rng.uniform(*leg.q2_limits, n)], axis=-1)
