"""``sd.cue``: a vehicle's motion (a ``Drive``) turned into platform poses by a motion-cueing law (classical
washout, hand-set or tuned, or MPC), kept inside the workspace by the limit guard, scored by what a rider
perceives and, with ``simulate=True``, run through the machine's own controller and the Drake plant so that the
scores are those of the *plant's* motion (the controller's lag and the actuators included).

The laws, the guard, the vestibular models and the scores live in ``control.cueing``; this module loads and
checks the inputs once, chains them and judges the run: 0 samples outside the stroke or over the leg speed
limit, in the commanded poses and in the simulated plant, and the loop tracking.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field, is_dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from stewart_drake.api.result import Result
from stewart_drake.control.cueing.classical import HAND_SET, ClassicalParams, classical
from stewart_drake.control.cueing.drive import Drive, load_drive
from stewart_drake.control.cueing.generators import DRIVES
from stewart_drake.control.cueing.guard import WorkspaceGuard
from stewart_drake.control.cueing.platform_motion import platform_drive
from stewart_drake.control.cueing.scores import CHANNELS, score
from stewart_drake.control.cueing.tuning import load_params, tune_classical
from stewart_drake.control.cueing.vestibular import perceive
from stewart_drake.core.argcheck import as_real
from stewart_drake.core.geometry import Platform
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.core.trajectory import table_trajectory
from stewart_drake.errors import (
    CUE_DRIVE,
    CUE_PARAMS,
    CUE_PARAMS_TYPE,
    ArgumentError,
    OptionError,
    PhysicalLimitError,
    UsageError,
)
from stewart_drake.spec import Machine, load_machine
from stewart_drake.workspace.limits import Limits

if TYPE_CHECKING:  # annotations only: matplotlib is loaded when a figure is drawn
    from matplotlib.figure import Figure

    from stewart_drake.api.simulation import Animation, SimulationResult

ALGORITHMS = ("classical", "tuned", "mpc")
TAIL_SAMPLES = 10  # drive samples of the in-the-loop reference past the drive's end (never reached by the run)


def resolve_drive(drive: Drive | str | Path, name: str = "drive") -> Drive:
    """``drive`` as a ``Drive``: itself, a shipped drive by name (``DRIVES``) or a CSV/Parquet drive file
    (``load_drive``: its errors name the file, line and column); anything else is an ``ArgumentError`` naming
    ``name`` (the keyword, or the option) and the value as given."""
    if isinstance(drive, Drive):
        return drive
    if isinstance(drive, (str, Path)):
        if str(drive) in DRIVES:
            return DRIVES[str(drive)]()
        if Path(drive).suffix or Path(drive).exists():
            return load_drive(drive)
    raise ArgumentError(CUE_DRIVE.format(name=name, value=repr(drive), names=", ".join(DRIVES)))


def limit_samples(guard: WorkspaceGuard, t, poses) -> dict:
    """The samples of ``poses`` (N, 6) at the uniform times ``t`` (N,) s outside the platform's own limits, by the
    exact IK (``guard.check`` against the whole stroke, not the guard's margins): ``outside_stroke`` (any leg beyond
    [L_min, L_max]), ``over_speed`` (any leg faster than ``legs.max_speed``; 0 where the platform states none),
    ``outside_joints`` (past the guard's joint cones, if any), with the ``peak_leg_speed_m_s`` (the scores give the
    stroke use)."""
    p = guard.platform
    vmax = p.legs.max_speed
    c = guard.check(poses, t, stroke=p.stroke, max_speed=math.inf if vmax is None else vmax, max_accel=math.inf)
    return {
        "samples": int(len(poses)),
        "outside_stroke": c.outside_stroke,
        "over_speed": c.over_speed,
        "outside_joints": c.outside_joints,
        "max_leg_speed_m_s": vmax,
        "peak_leg_speed_m_s": c.max_speed,
    }


def resample(t_from, values, t_to) -> np.ndarray:
    """``values`` (n, k) sampled at ``t_from`` (n,) s, linearly interpolated at ``t_to`` (m,) s: (m, k)."""
    return np.stack([np.interp(t_to, t_from, values[:, j]) for j in range(values.shape[1])], axis=-1)


def channels(drive: Drive) -> np.ndarray:
    """``(N, 6)``: a drive's specific force (m/s²) and angular velocity (rad/s) side by side (``CHANNELS``)."""
    return np.hstack([drive.specific_force, drive.angular_velocity])


@dataclass(repr=False)
class CueResult(Result):
    """A motion-cueing run (``cue``).

    Attributes:
        drive: the vehicle's motion (``Drive``) cued.
        algorithm: ``"classical"``, ``"tuned"`` or ``"mpc"``; ``params`` the law's parameters used.
        poses: ``(N, 6)`` the guarded commanded poses at ``drive.t`` (m, rad; utn convention, absolute).
        motion: the ``Drive`` a rider on the commanded platform feels.
        perceived: ``{"vehicle", "platform"}`` (and ``"plant"`` when simulated): the perceived ``Drive``s.
        scores: ``control.cueing.scores.score`` of the vehicle against the commanded platform.
        limits: ``limit_samples`` of the commanded poses.
        mpc: the MPC's solve times and exact-IK re-checks (``commanded_poses``), None for the classical laws.
        simulation: the closed-loop run (``SimulationResult``) when ``simulate=True``, else None; then
            ``plant_poses`` (N, 6) the plant's poses at ``drive.t``, ``plant_scores`` and ``plant_limits``.
        failures: why the run is not good (a limit violated, tracking lost); empty when it is.
    """

    machine: Machine
    drive: Drive
    algorithm: str
    params: object
    poses: np.ndarray
    motion: Drive
    perceived: dict
    scores: dict
    limits: dict
    mpc: dict | None = None
    simulation: SimulationResult | None = field(default=None, repr=False)
    plant_poses: np.ndarray | None = None
    plant_scores: dict | None = None
    plant_limits: dict | None = None
    failures: list = field(default_factory=list)

    @property
    def ok(self) -> bool:
        """No limit violated in the commanded poses (nor the simulated plant), and the loop tracked."""
        return not self.failures

    def _fields(self) -> dict:
        d = {
            "platform": self.machine.platform.name,
            "drive": self.drive.name,
            "samples": int(len(self.drive.t)),
            "duration_s": float(self.drive.t[-1] - self.drive.t[0]),
            "algorithm": self.algorithm,
            "params": asdict(self.params) if is_dataclass(self.params) else self.params,
            "scores": self.scores,
            "limits": self.limits,
            **({"mpc": self.mpc} if self.mpc is not None else {}),
            "simulated": self.simulation is not None,
        }
        if self.simulation is not None:
            d["plant_scores"] = self.plant_scores
            d["plant_limits"] = self.plant_limits
            d["simulation"] = {k: v for k, v in self.simulation.summary.items() if k != "warnings"}
        return {**d, "failures": self.failures, "ok": self.ok}

    def plot(self) -> Figure:
        """The perceived specific force and angular velocity per channel: the vehicle's, the commanded
        platform's and (when simulated) the plant's.

        Returns:
            A matplotlib ``Figure`` (six panels).
        """
        # deferred: pyplot is loaded only when a figure is drawn
        import matplotlib.pyplot as plt

        t = self.drive.t
        fig, axes = plt.subplots(3, 2, figsize=(10, 7), sharex=True)
        units = ("m/s²",) * 3 + ("rad/s",) * 3
        for j, (name, unit) in enumerate(zip(CHANNELS, units, strict=True)):
            ax = axes[j % 3, j // 3]
            for key, style in (("vehicle", "k-"), ("platform", "C0-"), ("plant", "C1--")):
                if key in self.perceived:
                    ax.plot(t, channels(self.perceived[key])[:, j], style, lw=1, label=key)
            ax.set_ylabel(f"perceived {name} [{unit}]")
        axes[0, 0].legend(fontsize=7)
        for ax in axes[-1]:
            ax.set_xlabel("t [s]")
        fig.suptitle(f"{self.algorithm} cueing of {self.drive.name} on {self.machine.platform.name}")
        fig.tight_layout()
        return fig

    def plot_legs(self) -> Figure:
        """The legs' lengths along the run against the stroke (commanded, and the plant's when simulated).

        Returns:
            A matplotlib ``Figure``.
        """
        # deferred: pyplot is loaded only when a figure is drawn
        import matplotlib.pyplot as plt

        p, t = self.machine.platform, self.drive.t
        fig, ax = plt.subplots(figsize=(9, 4))
        ax.plot(t, leg_lengths(p, self.poses) * 1e3, lw=1)
        if self.plant_poses is not None:
            ax.plot(t, leg_lengths(p, self.plant_poses) * 1e3, "k:", lw=0.8)
        for end in p.stroke:
            ax.axhline(end * 1e3, color="r", lw=1)
        ax.set(xlabel="t [s]", ylabel="leg length [mm]", title="leg usage against the stroke (red)")
        ax.legend([f"leg {i}" for i in range(1, 7)], ncol=6, fontsize=7)
        fig.tight_layout()
        return fig

    def animate(self, fps: float = 25.0) -> Animation:
        """The run as a Meshcat animation: the simulated plant's motion when simulated (legs red while
        saturated), else the commanded poses (legs red near a stroke end).

        Args:
            fps: frames per second of the animation.

        Returns:
            An ``Animation``: displayed inline in Jupyter, ``save(path)`` writes the HTML.
        """
        if self.simulation is not None:
            return self.simulation.animate(fps)
        # deferred: the Meshcat scene (and the Animation beside the closed loop) import pydrake; cueing needs no Drake
        from stewart_drake.api.simulation import Animation
        from stewart_drake.drake.animation import record_animation

        title = f"{self.algorithm} cueing of {self.drive.name} on {self.machine.platform.name}"
        return Animation(record_animation(self.machine.platform, self.drive.t, self.poses, fps=fps, title=title))


def cueing_params(algorithm: str, params, drive: Drive, guard: WorkspaceGuard):
    """The law's parameters: ``params`` (a ``ClassicalParams`` or, for the classical laws, a YAML file of
    ``tuning.save_params``; an ``MpcParams`` for mpc), else the defaults (classical: ``HAND_SET``; tuned:
    ``tune_classical`` on this drive through ``guard``; mpc: ``MpcParams()``)."""
    if algorithm == "mpc":
        # deferred: MpcParams is defined beside the MPC law, which imports pydrake (classical cueing needs no Drake)
        from stewart_drake.drake.cueing_mpc import MpcParams

        if isinstance(params, (str, Path)):
            raise UsageError(CUE_PARAMS.format(name="params", value=repr(str(params))))
        kind = MpcParams
        if params is None:
            return MpcParams()
    else:
        if isinstance(params, (str, Path)):
            return load_params(params)
        kind = ClassicalParams
        if params is None:
            return HAND_SET if algorithm == "classical" else tune_classical([drive], guard.platform, guard=guard)
    if not isinstance(params, kind):
        raise ArgumentError(
            CUE_PARAMS_TYPE.format(what=kind.__name__, algorithm=algorithm, value=type(params).__name__)
        )
    return params


def commanded_poses(algorithm: str, params, drive: Drive, guard: WorkspaceGuard) -> tuple[np.ndarray, dict | None]:
    """``(poses, mpc)``: ``(N, 6)`` the law's poses for ``drive`` through the workspace ``guard`` (absolute, m and
    rad) and, for the MPC law, its solves: ``worst_solve_s``, ``mean_solve_s`` (wall time of each sample's step),
    ``worst_solve_cpu_s`` (its CPU time on the calling thread),
    ``max_stroke_violation_m`` (the exact IK's re-check after each solve: ≤ 0) and ``fallbacks``; else None."""
    if algorithm != "mpc":
        return guard.guard(classical(drive, params, guard.home), drive.t), None
    # deferred: the MPC law imports pydrake (classical cueing and the cue command run without Drake)
    from stewart_drake.drake.cueing_mpc import mpc_cue

    run = mpc_cue(drive, guard.platform, params, guard.home, limits=guard.limits)
    solves = {
        "worst_solve_s": float(run.solve_times.max()),
        "mean_solve_s": float(run.solve_times.mean()),
        "worst_solve_cpu_s": float(run.cpu_times.max()),
        "max_stroke_violation_m": float(run.stroke_violation.max()),
        "fallbacks": dict(run.fallbacks),
    }
    return guard.guard(run.poses, drive.t), solves


def cue(
    machine: Machine | Platform | str | Path,
    drive: Drive | str | Path,
    *,
    algorithm: str = "classical",
    params=None,
    simulate: bool = False,
    joint_cone: float | None = None,
    progress: bool | None = None,
) -> CueResult:
    """Cue a vehicle's motion on the machine: poses by the law, kept inside the workspace by the guard,
    scored by the perceived motion (otolith and semicircular-canal models) against the vehicle's.

    Args:
        machine: the machine (``load_machine``'s: a ``Machine``, a ``Platform``, a preset name or a machine file).
        drive: the vehicle's motion: a ``Drive``, a shipped drive's name (``"ship-ss4"``, ``"car-lane-change"``,
            ...) or a drive file (CSV or Parquet, ``t,fx,fy,fz,wx,wy,wz[,roll,pitch,yaw]``, SI).
        algorithm: ``"classical"`` (classical washout, hand-set: ``HAND_SET``), ``"tuned"`` (classical washout
            tuned for this drive, or with ``params`` as given) or ``"mpc"`` (model-predictive cueing).
        params: the law's parameters (``ClassicalParams``, ``MpcParams``, or a YAML file written by
            ``tune_classical``'s ``save_params`` for the classical laws); None: the defaults above.
        simulate: also run the poses through the machine's controller (fixed point) and the Drake plant
            (``sd.simulate``) and score the plant's motion.
        joint_cone: the joints' cone half-angle, rad, about the base and plate normals: the guard (and MPC) keep
            every leg within it and ``limits`` counts the samples outside (None: no joint limit; platform files
            give none).
        progress: show the simulation's progress bar.

    Returns:
        A ``CueResult``: its ``failures`` name each limit violated (in the commanded poses, and in the plant)
        and a lost tracking; ``ok`` is True when there are none.

    Raises:
        StewartError: a bad machine, drive or parameter file (naming it and the value as written), an
            unknown algorithm.
    """
    if algorithm not in ALGORITHMS:
        raise ArgumentError(ArgumentError.CHOICE.format(name="algorithm", choices=ALGORITHMS, value=repr(algorithm)))
    if not isinstance(simulate, bool):
        raise ArgumentError(ArgumentError.NOT_BOOL.format(name="simulate", value=repr(simulate)))
    machine = load_machine(machine)
    platform = machine.platform
    drive = resolve_drive(drive)
    cone = None if joint_cone is None else as_real(joint_cone, "joint_cone")
    if cone is not None and not 0 < cone <= math.pi:
        raise OptionError(OptionError.BETWEEN.format(option="joint_cone", lo="0 (excluded)", hi="pi rad", value=cone))
    guard = WorkspaceGuard.for_platform(
        platform, limits=None if cone is None else Limits(base_cone=cone, top_cone=cone)
    )
    params = cueing_params(algorithm, params, drive, guard)
    poses, mpc = commanded_poses(algorithm, params, drive, guard)
    motion = platform_drive(poses, drive.t, guard.home)
    perceived = {"vehicle": perceive(drive), "platform": perceive(motion)}
    limits = limit_samples(guard, drive.t, poses)
    failures = limit_failures(limits, "the commanded poses")
    result = CueResult(
        machine,
        drive,
        algorithm,
        params,
        poses,
        motion,
        perceived,
        score(drive, motion, poses, platform),
        limits,
        mpc=mpc,
        failures=failures,
    )
    if simulate:
        in_the_loop(result, guard, bool(progress))
    return result


def limit_failures(limits: dict, what: str) -> list[str]:
    """One line per kind of limit ``limits`` (``limit_samples``') shows violated in ``what``."""
    out = []
    if limits["outside_stroke"]:
        out.append(f"{limits['outside_stroke']} of {limits['samples']} samples of {what} have a leg outside the stroke")
    if limits["outside_joints"]:
        out.append(f"{limits['outside_joints']} of {limits['samples']} samples of {what} have a joint outside its cone")
    if limits["over_speed"]:
        out.append(
            f"{limits['over_speed']} of {limits['samples']} samples of {what} move a leg faster than "
            f"{limits['max_leg_speed_m_s']:g} m/s (legs.max_speed; peak {limits['peak_leg_speed_m_s']:.4g} m/s)"
        )
    return out


def in_the_loop(result: CueResult, guard: WorkspaceGuard, progress: bool) -> None:
    """Run ``result``'s poses as a table reference through the machine's controller and the Drake plant and
    fill in the plant's poses, scores and limits (at the drive's samples) and its failures (a reference that
    ``simulate`` refuses as beyond the actuators is one, and leaves the plant's fields None)."""
    # deferred: the closed loop imports pydrake (classical cueing needs no Drake)
    from stewart_drake.api.simulation import simulate

    drive, platform = result.drive, result.machine.platform
    t = drive.t - drive.t[0]
    # the last sample's velocity carried on past the run's end (TAIL_SAMPLES): a table held at its last pose
    # would stop the reference dead there, and the loop's last ticks (their feed-forward differences) would see a
    # deceleration that exists only because the drive ends
    k = np.arange(1, TAIL_SAMPLES + 1)
    tail = result.poses[-1] + k[:, None] * (result.poses[-1] - result.poses[-2])
    reference = table_trajectory(f"cue-{drive.name}", np.r_[t, t[-1] + k * drive.dt], np.vstack([result.poses, tail]))
    try:  # the poses as they are (fit=False: a machine's run.fit would move and scale them)
        run = simulate(result.machine, reference, duration=float(t[-1]), fit=False, progress=progress)
    except PhysicalLimitError as e:  # beyond the actuators before the run: a failure of this result, shown with it
        result.failures.append(f"the loop: {e}")
        return
    log = run.log.raw
    plant = resample(log.t, log.pose, t)
    motion = platform_drive(plant, drive.t, guard.home)
    result.simulation = run
    result.plant_poses = plant
    result.perceived["plant"] = perceive(motion)
    result.plant_scores = score(drive, motion, plant, platform)
    result.plant_limits = limit_samples(guard, log.t, log.pose)  # every plant step
    result.failures += limit_failures(result.plant_limits, "the simulated plant")
    result.failures += [f"the loop: {f}" for f in run.verdict["failures"]]
