"""Design checks at a pose: the Cartesian stiffness (``stiffness``) and the natural frequencies (``modes``)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from stewart_drake.api.result import Result
from stewart_drake.core.argcheck import as_flag, as_real, check_shape, param
from stewart_drake.core.geometry import Platform, check_platform
from stewart_drake.core.kinematics import inverse_kinematics, leg_lengths, require_nonsingular
from stewart_drake.core.rotations import check_convention, rotation_matrix
from stewart_drake.core.sanity import check_finite, check_gravity, check_poses
from stewart_drake.design.load_limits import (
    MAX_DAMPING_RATIO,
    beyond_linear_range,
    damping_ratio_scale,
    rigid_body_limit_hz,
    unstable_direction,
)
from stewart_drake.design.modes import analytic_modes, damping_matrix, spatial_inertia, subspace_mac
from stewart_drake.design.payload import payload_wrench, with_payload
from stewart_drake.design.stiffness import compliance, deflection, displace, leg_stiffness_vector, principal_stiffness
from stewart_drake.design.stiffness import stiffness_matrix as cartesian_stiffness
from stewart_drake.errors import (
    OPTION_LEG_DAMPING,
    OPTION_LEG_DAMPING_RESOLVE,
    OPTION_SAMPLE_RATE,
    GeometryError,
    OptionError,
    PayloadError,
    PhysicalLimitError,
    StewartError,
)

# The heaviest payload taken (kg): 1000 t, beyond the heaviest motion platforms built; more is a unit mistake.
MAX_PAYLOAD = 1e6


@dataclass
class Load:
    """A platform at a pose with its payload, checked once for ``stiffness`` and ``modes``: the platform
    carrying the payload, the pose ``q`` (6,) SI, leg stiffnesses ``k`` (6,) N/m and the payload position
    ``p_TP`` (3,) m."""

    platform: Platform
    q: np.ndarray
    k: np.ndarray
    p_TP: np.ndarray
    gravity: float
    legs: bool
    payload: float
    convention: str


def load_at_pose(
    platform: Platform,
    pose,
    leg_stiffness=None,
    convention: str = "utn",
    legs: bool = False,
    payload: float = 0.0,
    payload_com=(0.0, 0.0, 0.0),
    gravity: float = 9.81,
    *,
    shown_com=None,
    unit: str = "m",
    check_pose: bool = True,
) -> Load:
    """The checks ``stiffness`` and ``modes`` share: gravity finite and >= 0, the payload above the plate
    (``shown_com``: its position as the user wrote it, in ``unit``), the leg stiffness (argument, else the
    platform's ``legs.stiffness``), and the pose analysable (finite, near, above the base; then within the
    stroke and away from a singularity: ``PhysicalLimitError``)."""
    check_platform(platform)
    q = check_shape(pose, param("pose"), (6,))
    check_convention(convention)
    legs = as_flag(legs, param("legs"))
    loaded, p_TP = carrying(platform, payload, payload_com, gravity, shown_com=shown_com, unit=unit)
    if leg_stiffness is not None:
        k = leg_stiffness_vector(leg_stiffness, param("leg_stiffness"))
    else:
        k = leg_stiffness_vector(platform.legs.stiffness, "legs.stiffness")
    load = Load(loaded, q, k, p_TP, gravity, legs, payload, convention)
    if check_pose:
        require_analysable(load)
    return load


def require_analysable(load: Load) -> None:
    """Refuse a pose that cannot be analysed: the sanity checks every command applies (finite, near the
    platform, plate above the base), then within the stroke and away from a singularity
    (``PhysicalLimitError``)."""
    check_poses(load.platform, load.q, load.convention, what=param("pose"))
    try:
        inverse_kinematics(load.platform, load.q, load.convention)
        require_nonsingular(load.platform, load.q, load.convention)
    except StewartError as e:
        raise PhysicalLimitError(str(e)) from None


def carrying(platform: Platform, payload: float, payload_com, gravity: float, *, shown_com=None, unit: str = "m"):
    """``(platform carrying the payload, p_TP (3,) m)`` after checking ``gravity`` (finite, >= 0) and that the
    payload sits on the plate (``shown_com``: its position as the user wrote it, in ``unit``)."""
    payload = as_real(payload, param("payload"))
    gravity = as_real(gravity, param("gravity"))
    if not (np.isfinite(gravity) and gravity >= 0):
        raise OptionError(OptionError.GRAVITY.format(option=param("gravity"), value=gravity))
    check_gravity(gravity, param("gravity"))
    if np.isfinite(payload) and payload > MAX_PAYLOAD:
        raise PayloadError(PayloadError.TOO_HEAVY.format(option=param("payload"), value=payload, limit=MAX_PAYLOAD))
    p_TP = check_finite(check_shape(payload_com, param("payload_com"), (3,)), param("payload_com"))
    shown = p_TP if shown_com is None else shown_com
    if shown[2] < 0:
        raise PayloadError(PayloadError.BELOW_PLATE.format(option=param("payload_com"), z=shown[2], unit=unit))
    return with_payload(platform, payload, p_TP, param("payload")), p_TP


@dataclass(repr=False)
class StiffnessResult(Result):
    """The Cartesian stiffness about the rotation centre at a pose (``stiffness``).

    Attributes:
        matrix: ``(6, 6)`` stiffness K (rows: force N, moment N·m; columns: δp m, δθ rad), with the load's
            geometric term.
        zero_load: ``(6, 6)`` K without the load's geometric term.
        compliance: ``(6, 6)`` K⁻¹.
        principal: principal translational (N/m) and rotational (N·m/rad) stiffnesses, softest first, and
            their directions (one per row).
        payload_wrench: ``(6,)`` the payload's weight as a wrench about the rotation centre (N, N·m).
        deflection: ``(6,)`` the static deflection under it (m, rad); None when the loaded platform is unstable
            or the deflection is beyond the linear range (then it is not a number to trust).
        pose: ``(6,)`` the pose (m, rad).
        leg_stiffness: ``(6,)`` N/m.
        platform: the platform's name.
        convention: Euler convention of the pose.
        legs: the legs' masses are included.
        payload: kg.
        payload_com: ``(3,)`` m, in the plate frame.
        gravity: m/s².
        limits: the physical limits reached (the loaded platform unstable, the deflection beyond the linear
            range), one sentence each; ``ok`` is False when there is one.
    """

    matrix: np.ndarray
    zero_load: np.ndarray
    compliance: np.ndarray
    principal: dict
    payload_wrench: np.ndarray
    deflection: np.ndarray
    pose: np.ndarray
    leg_stiffness: np.ndarray
    platform: str
    convention: str
    legs: bool
    payload: float
    payload_com: np.ndarray
    gravity: float
    limits: list = field(default_factory=list)

    @property
    def ok(self) -> bool:
        """What ``stiffness`` exits 0 for: the loaded platform stable and its deflection within the linear range."""
        return not self.limits

    def _fields(self) -> dict:
        return {
            "platform": self.platform,
            "pose": self.pose,
            "length_unit": "m",
            "angle_unit": "rad",
            "convention": self.convention,
            "leg_stiffness_n_per_m": self.leg_stiffness,
            "legs_model": self.legs,
            "payload_kg": self.payload,
            "payload_com_m": self.payload_com,
            "gravity": self.gravity,
            "stiffness": self.matrix,
            "stiffness_zero_load": self.zero_load,
            "compliance": self.compliance,
            "principal_stiffness": self.principal,
            "payload_wrench": self.payload_wrench,
            "deflection": self.deflection,
            "deflection_edge_units": self.deflection,
            "limits": self.limits,
        }


def stiffness(
    platform: Platform,
    pose: ArrayLike,
    leg_stiffness: float | ArrayLike | None = None,
    *,
    convention: str = "utn",
    legs: bool = False,
    payload: float = 0.0,
    payload_com: ArrayLike = (0.0, 0.0, 0.0),
    gravity: float = 9.81,
) -> StiffnessResult:
    """The 6×6 Cartesian stiffness about the rotation centre at a pose, its principal values, the compliance
    and the static deflection under a payload.

    Args:
        platform: the platform.
        pose: ``(6,)`` the pose (m, rad).
        leg_stiffness: axial stiffness of every leg, N/m (a number or six); default the platform's
            ``legs.stiffness``.
        convention: Euler convention of the pose.
        legs: include the legs' masses in the load.
        payload: a point mass carried by the plate, kg.
        payload_com: ``(3,)`` its position in the plate frame, m (z >= 0).
        gravity: m/s².

    Returns:
        The stiffness, compliance, principal stiffnesses and deflection; ``limits`` (and ``ok`` False) when the
        loaded platform is unstable or the deflection is beyond the linear range.

    Raises:
        StewartError: bad options or a pose that is not analysable; ``PhysicalLimitError`` outside the stroke or
            at a singularity.
    """
    load = load_at_pose(platform, pose, leg_stiffness, convention, legs, payload, payload_com, gravity)
    return stiffness_at(load)


def stiffness_at(load: Load) -> StiffnessResult:
    """``stiffness`` of a checked ``Load``."""
    p, q, k, c, g = load.platform, load.q, load.k, load.convention, load.gravity
    K = cartesian_stiffness(p, q, k, c, g, load.legs)
    K0 = cartesian_stiffness(p, q, k, c, g, load.legs, loaded=False)
    pr = principal_stiffness(K)
    w = payload_wrench(p, rotation_matrix(q[3:], c), load.payload, load.p_TP, g)
    principal = {
        "translational_n_per_m": pr.translational,
        "translational_directions": pr.translational_dirs.T,
        "rotational_nm_per_rad": pr.rotational,
        "rotational_directions": pr.rotational_dirs.T,
    }
    d = deflection(K, w)
    # an unstable loaded platform, or a deflection beyond the linear range: a result outside limits, and the
    # deflection is not a number to print
    limits = []
    v = unstable_direction(K)
    if v is not None:
        limits.append(
            "the loaded platform is unstable at this pose: its stiffness K is not positive definite, it falls away "
            f"along [{' '.join(f'{x:+.3f}' for x in v)}] (x y z m, rx ry rz rad): the load's geometric stiffness "
            "exceeds the legs'"
        )
    else:
        why = beyond_linear_range(leg_lengths(p, q, c), leg_lengths(p, displace(q, d, c), c), d)
        if why:
            limits.append(f"the deflection under the payload is beyond the linear range: {why}")
    return StiffnessResult(
        K, K0, compliance(K), principal, w, None if limits else d, q, k, p.name, c, load.legs, load.payload,
        load.p_TP, g, limits,
    )  # fmt: skip


@dataclass(repr=False)
class ModesResult(Result):
    """Natural frequencies and mode shapes about the static equilibrium at a pose (``modes``).

    Attributes:
        frequencies_hz: ``(6,)`` natural frequencies, Hz, lowest first.
        damping_ratio: ``(6,)`` damping ratios.
        shapes: ``(6, 6)`` mode shapes, one per column (complex with damping).
        controller: how a controller at ``sample_rate`` sees the lowest mode.
        drake: Drake's linearisation of the same plant and its agreement (with ``drake=True``), else None.
        pose: ``(6,)`` m, rad.
        leg_stiffness: ``(6,)`` N/m.
        leg_damping: N·s/m.
        legs: the legs' masses are included.
        platform: the platform's name.
        warnings: model-range warnings (a mode above the legs' own axial resonance).
        limits: the physical limits reached (the loaded platform unstable: a 0 Hz mode is that fall), one
            sentence each; ``ok`` is False when there is one.
    """

    frequencies_hz: np.ndarray
    damping_ratio: np.ndarray
    shapes: np.ndarray
    controller: dict
    drake: dict | None
    pose: np.ndarray
    leg_stiffness: np.ndarray
    leg_damping: float
    legs: bool
    platform: str
    warnings: list = field(default_factory=list)
    limits: list = field(default_factory=list)

    @property
    def ok(self) -> bool:
        """What ``modes`` exits 0 for: the loaded platform stable at the pose."""
        return not self.limits

    def _fields(self) -> dict:
        out = {
            "platform": self.platform,
            "pose": self.pose,
            "legs_model": self.legs,
            "leg_stiffness_n_per_m": self.leg_stiffness,
            "leg_damping_ns_per_m": self.leg_damping,
            "frequencies_hz": self.frequencies_hz,
            "damping_ratio": self.damping_ratio,
            "mode_shapes": self.shapes.T.real if self.leg_damping == 0 else None,
            "controller": self.controller,
        }
        if self.drake is not None:
            out["drake"] = self.drake
        out["warnings"] = self.warnings
        out["limits"] = self.limits
        return out


def modes(
    platform: Platform,
    pose: ArrayLike,
    leg_stiffness: float | ArrayLike | None = None,
    *,
    leg_damping: float = 0.0,
    convention: str = "utn",
    legs: bool = False,
    payload: float = 0.0,
    payload_com: ArrayLike = (0.0, 0.0, 0.0),
    gravity: float = 9.81,
    sample_rate: float = 1000.0,
    drake: bool = False,
) -> ModesResult:
    """Natural frequencies and mode shapes about the static equilibrium at a pose (legs as springs and
    dampers), analytic; with ``drake``, checked against Drake's linearisation of the plant.

    Args:
        platform: the platform.
        pose: ``(6,)`` the pose (m, rad).
        leg_stiffness: axial stiffness of every leg, N/m; default the platform's ``legs.stiffness``.
        leg_damping: axial damping of every leg, N·s/m.
        convention: Euler convention of the pose.
        legs: include the legs' masses.
        payload: a point mass carried by the plate, kg.
        payload_com: ``(3,)`` its position in the plate frame, m.
        gravity: m/s².
        sample_rate: the controller's sample rate, Hz (how many samples per lowest period).
        drake: also linearise the Drake plant and compare (needs pydrake).

    Returns:
        The frequencies, damping ratios, shapes and the controller's view of the lowest mode; ``limits`` (and
        ``ok`` False) when the loaded platform is unstable, ``warnings`` beyond the rigid-plate model's range.

    Raises:
        StewartError: bad options or a pose that is not analysable; a singular mass matrix; a damping the
            eigen-solve cannot resolve.
    """
    load = load_at_pose(
        platform, pose, leg_stiffness, convention, legs, payload, payload_com, gravity, check_pose=False
    )
    check_modes_options(leg_damping, sample_rate)
    drake = as_flag(drake, param("drake"))
    require_analysable(load)
    return modes_at(load, leg_damping, sample_rate, drake)


def check_modes_options(leg_damping: float, sample_rate: float) -> None:
    """``OptionError`` for a damping that is not finite and >= 0 or a sample rate that is not positive."""
    leg_damping = as_real(leg_damping, param("leg_damping"))
    sample_rate = as_real(sample_rate, param("sample_rate"))
    if not (np.isfinite(leg_damping) and leg_damping >= 0):
        raise OptionError(OPTION_LEG_DAMPING.format(name=param("leg_damping"), value=leg_damping))
    if not (np.isfinite(sample_rate) and sample_rate > 0):
        raise OptionError(OPTION_SAMPLE_RATE.format(name=param("sample_rate"), value=sample_rate))


def modes_at(load: Load, leg_damping: float, sample_rate: float, drake: bool) -> ModesResult:
    """``modes`` of a checked ``Load``."""
    p, q, k, c, legs = load.platform, load.q, load.k, load.convention, load.legs
    K = cartesian_stiffness(p, q, k, c, load.gravity, legs)
    M = spatial_inertia(p, q, c, legs)
    C = damping_matrix(p, q, leg_damping, c) if leg_damping > 0 else None
    if not np.linalg.eigvalsh(0.5 * (M + M.T))[0] > 0:  # a zero or singular inertia: LAPACK's "not positive definite"
        raise GeometryError(GeometryError.INERTIA_SINGULAR.format(name=p.name, mass=p.mass))
    zeta = damping_ratio_scale(K, M, C)
    if zeta > MAX_DAMPING_RATIO:
        raise OptionError(
            OPTION_LEG_DAMPING_RESOLVE.format(
                name=param("leg_damping"), value=leg_damping, zeta=zeta, limit=MAX_DAMPING_RATIO
            )
        )
    m = analytic_modes(K, M, C)
    f1 = float(m.frequencies_hz[0])
    delay = 1.5 / sample_rate  # one sample of output delay + half a sample of zero-order hold
    controller = {
        "sample_rate_hz": sample_rate,
        "samples_per_lowest_period": sample_rate / f1 if f1 > 0 else None,
        "loop_delay_s": delay,
        "phase_lag_at_lowest_deg": 360.0 * f1 * delay,
    }
    checked = None
    if drake:
        # Deferred: only this check needs Drake; stiffness and modes run without pydrake.
        from stewart_drake.drake.design_checks import drake_modes

        d = drake_modes(p, q, k, leg_damping, c, load.gravity, legs)
        md = d["modes"]
        checked = {
            "frequencies_hz": md.frequencies_hz,
            "damping_ratio": md.damping_ratio,
            "relative_difference": np.abs(md.frequencies_hz / m.frequencies_hz - 1),
            "mac": subspace_mac(m.shapes, md.shapes, m.frequencies_hz),
            "equilibrium_residual": d["residual"],
            "method": "closed-loop plant, reduced by finite differences" if legs else "spring plant, Drake Linearize",
        }
    v = unstable_direction(K)
    limits = (
        []
        if v is None
        else [
            "the loaded platform is unstable at this pose: its stiffness K is not positive definite, it falls away along "
            f"[{' '.join(f'{x:+.3f}' for x in v)}] (x y z m, rx ry rz rad); a mode of 0 Hz is that fall, not a frequency"
        ]
    )
    # beyond the legs' own axial resonance the rigid-plate model does not hold: a warning (the model's range,
    # not the platform's limit); a 1e-30 kg plate printed 1e18 Hz as if it were a result
    f_rigid = rigid_body_limit_hz(leg_lengths(p, q, c))
    warnings = []
    if m.frequencies_hz[-1] > f_rigid:
        warnings.append(
            f"mode 6 at {m.frequencies_hz[-1]:.4g} Hz is above the legs' own axial resonance (~{f_rigid:.4g} Hz, c/2L "
            f"for steel legs): the rigid-plate, massless-leg model does not hold there; check plate.mass "
            f"({p.mass:g} kg), plate.inertia and the leg stiffness"
        )
    return ModesResult(
        m.frequencies_hz, m.damping_ratio, m.shapes, controller, checked, q, k, leg_damping, legs, p.name, warnings,
        limits,
    )  # fmt: skip
