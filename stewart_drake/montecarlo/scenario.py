"""One Monte Carlo run as plain, picklable data, and the function that runs it.

Drake objects do not pickle, so a worker receives a ``Study`` (the study's fixed settings: platform,
reference, controller, integrator, duration, SPEC, seed) and a run index, draws that run's ``Draw`` from
its own seed, turns it into a ``drake.simulation.Scenario`` (``scenario``) and builds its Diagram from that
itself (``run_scenario``). The run's seed is
``run_seed(study.seed, index)``: the first 64-bit word (its low 63 bits) of ``numpy.random.SeedSequence(S,
spawn_key=(index,))``, so any run can be re-drawn alone from (S, index) or from its seed.

What a draw changes (the controller keeps the nominal model: it is what the firmware was built for):

- the plant is built from the platform with every physical joint moved (``anchor``: one offset per
  distinct base joint and per distinct plate anchor, so that legs sharing a joint keep sharing it) and the
  plate's own mass and centre of mass changed (``plate_mass``: the inertia scales with the mass; ``plate_com``),
  and a point mass ``payload`` added at ``payload_position`` in the plate frame (``design.payload.with_payload``,
  as ``size --payload``);
- the sensor reads L + offset (``leg_offset``) + white noise σ (``sensor_noise``) − j_k·dL/dt, the
  first-order effect of sampling tick k late by j_k ~ U[0, ``latency_jitter``], then quantises with the
  drawn ``sensor_resolution`` (in the controller);
- the controller's ``latency`` mode, ``sample_period`` and its gains × ``gain_scale`` (the gains are
  those designed for the nominal timing and actuator lag: what the firmware was built with);
- the actuators' lag (``actuator_lag``) and force limit (``force_limit``).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field, replace

import numpy as np

from stewart_drake.api.simulation import plan_run, tick_count
from stewart_drake.control import ControllerConfig
from stewart_drake.control.verdict import run_verdict
from stewart_drake.core.geometry import Platform, base_joints
from stewart_drake.core.trajectory import Trajectory, design_poses, fit_trajectory, get_trajectory, table_trajectory
from stewart_drake.design.payload import with_payload
from stewart_drake.drake.integrators import DEFAULT_INTEGRATOR
from stewart_drake.drake.simulation import ActuatorModel, Scenario, SensorModel, build_simulation
from stewart_drake.montecarlo.spec import KEYS, VarySpec
from stewart_drake.montecarlo.summary import FAILURE_SEPARATOR
from stewart_drake.script import run_program

# Nominal values of the keys whose nominal is not the platform's.
NOMINAL = {
    "sensor_resolution": 1e-5,
    "latency": "sample",
    "actuator_lag": 2e-3,
    "gain_scale": 1.0,
    "sensor_noise": 0.0,
    "latency_jitter": 0.0,
    "sample_period": 1e-3,
}
# A run loses tracking when a leg is this far (m) from the reference's IK, or the state is not finite.
LOST_TRACKING = 5e-3
AXES = ("x", "y", "z")


@dataclass(frozen=True)
class Study:
    """A study's fixed settings (picklable). ``trajectory``: ``seed`` or ``rotating``; ``table``: a CSV
    reference read on the client, (name, times (n,), poses (n, 6) SI) as lists, so that workers need no
    file; ``program``: (file name, text) of a ``.stw`` motion program instead; ``fit``: move the trajectory to
    the platform's home; ``lost_tracking``: metres of leg error that count as lost tracking; ``grid``: one
    ``{key: SI value}`` per run that replaces that run's draws of those keys (a sweep; ``runs`` = its length);
    ``motion``: a Python ``Trajectory`` as the reference instead (pickled to the workers with the study)."""

    platform: Platform
    spec: VarySpec
    seed: int
    runs: int
    trajectory: str | None = "seed"
    program: tuple | None = None
    table: tuple | None = None
    fit: bool = False
    controller: str = "fixed"
    integrator: str = DEFAULT_INTEGRATOR
    engine: str = "python"
    duration: float | None = None
    plant_step: float = 1e-3
    lost_tracking: float = LOST_TRACKING
    grid: tuple | None = None
    extra: dict = field(default_factory=dict)
    motion: Trajectory | None = None

    def reference(self) -> Trajectory:
        """The pose reference (built on the worker)."""
        if self.motion is not None:
            ref = self.motion
        elif self.table is not None:
            ref = table_trajectory(*self.table)
        elif self.program is not None:
            name, text = self.program
            ref = replace(
                run_program(text, name, self.platform).trajectory, name=name.rsplit("/", 1)[-1].removesuffix(".stw")
            )
        else:
            ref = get_trajectory(self.trajectory)
        return fit_trajectory(ref, self.platform) if self.fit else ref

    def run_duration(self, reference=None) -> float:
        """Simulated seconds per run (given, else the reference's own duration)."""
        if self.duration is not None:
            return self.duration
        ref = reference or self.reference()
        return ref.duration or 1.0


def run_seed(seed: int, index: int) -> int:
    """The seed (63 bits: a signed 64-bit column holds it) of run ``index`` of a study seeded ``seed``."""
    return int(np.random.SeedSequence(seed, spawn_key=(index,)).generate_state(1, np.uint64)[0]) & (2**63 - 1)


@dataclass(frozen=True)
class Draw:
    """One run's parameters (SI). Anchor offsets per physical joint: ``(m, 3)`` base joints in B (leg i
    on joint ``base_leg_joint[i]``) and ``(k, 3)`` plate anchors in T (leg i on ``platform.leg_top[i]``)."""

    base_anchor_offset: np.ndarray
    top_anchor_offset: np.ndarray
    base_leg_joint: np.ndarray
    leg_offset: np.ndarray
    sensor_resolution: float
    sensor_noise: float
    latency: str
    latency_jitter: float
    actuator_lag: float
    force_limit: float
    plate_mass: float
    plate_com_offset: np.ndarray
    gain_scale: float
    sample_period: float
    payload: float = 0.0
    payload_position: np.ndarray = field(default_factory=lambda: np.zeros(3))

    def columns(self) -> dict:
        """The drawn parameters as flat ``{column: value}`` (SI, names with their unit)."""
        out = {}
        for j, v in enumerate(self.base_anchor_offset):
            out.update({f"anchor_base{j + 1}_{a}_m": float(x) for a, x in zip(AXES, v)})
        for j, v in enumerate(self.top_anchor_offset):
            out.update({f"anchor_top{j + 1}_{a}_m": float(x) for a, x in zip(AXES, v)})
        out.update({f"leg_offset{i + 1}_m": float(x) for i, x in enumerate(self.leg_offset)})
        out.update(
            {
                "sensor_resolution_m": self.sensor_resolution,
                "sensor_noise_m": self.sensor_noise,
                "latency": self.latency,
                "latency_jitter_s": self.latency_jitter,
                "actuator_lag_s": self.actuator_lag,
                "force_limit_N": self.force_limit,
                "plate_mass_kg": self.plate_mass,
            }
        )
        out.update({f"plate_com_{a}_m": float(x) for a, x in zip(AXES, self.plate_com_offset)})
        out["gain_scale"] = self.gain_scale
        out["sample_period_s"] = self.sample_period
        out["payload_kg"] = self.payload
        out.update({f"payload_position_{a}_m": float(x) for a, x in zip(AXES, self.payload_position)})
        return out


def _draw_one(rng, law, nominal, shape=()):
    """A value of ``law`` (None: ``nominal``) of ``shape`` (components drawn independently)."""
    if law is None:
        return np.full(shape, nominal) if shape else nominal
    if law.kind == "fixed":
        if len(law.values) == 3 and shape == (3,):  # X,Y,Z
            return np.asarray(law.values, dtype=float)
        v = law.values[0]
        return np.full(shape, v) if shape else v
    if law.kind == "plusminus":
        w = law.values[0]
        return nominal + rng.uniform(-w, w, size=shape or None)
    if law.kind == "relative":
        p = law.values[0]
        return nominal * (1 + rng.uniform(-p, p, size=shape or None))
    if law.kind == "uniform":
        return rng.uniform(*law.values, size=shape or None)
    if law.kind == "choice":
        return law.values[int(rng.integers(len(law.values)))]
    raise ValueError(f"unknown law {law.kind!r}")  # internal: the study loader accepts only the kinds above


def draw(study: Study, index: int) -> tuple[int, Draw]:
    """``(run seed, Draw)`` of run ``index``: every key drawn in ``KEYS`` order from the run's own
    generator (a key left nominal draws nothing). ``anchor`` draws ``(6, 3)`` base offsets, one row per
    leg, then ``(k, 3)`` plate offsets; a base joint takes the row of its first leg and the rows of the
    other legs on it are skipped, so the stream (and so every key drawn after) is the same on every
    architecture, and a platform with six distinct base anchors draws what it always drew."""
    seed = run_seed(study.seed, index)
    rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(0,)))
    p, laws = study.platform, study.spec.laws
    k = len(p.top_anchors)
    first, leg_joint = base_joints(p)
    vals = {}
    for key in KEYS:
        law = laws.get(key)
        if key == "anchor":
            vals[key] = (_draw_one(rng, law, 0.0, (6, 3))[first], _draw_one(rng, law, 0.0, (k, 3)))
        elif key == "leg_offset":
            vals[key] = _draw_one(rng, law, 0.0, (6,))
        elif key in ("plate_com", "payload_position"):
            vals[key] = _draw_one(rng, law, 0.0, (3,))
        elif key == "force_limit":
            vals[key] = float(_draw_one(rng, law, float(p.legs.max_force)))
        elif key == "plate_mass":
            vals[key] = float(_draw_one(rng, law, float(p.mass)))
        elif key == "payload":
            vals[key] = float(_draw_one(rng, law, 0.0))
        elif key == "latency":
            vals[key] = str(_draw_one(rng, law, NOMINAL[key]))
        else:
            vals[key] = float(_draw_one(rng, law, NOMINAL[key]))
    if study.grid is not None:
        vals.update(study.grid[index])
    return seed, Draw(
        base_anchor_offset=np.asarray(vals["anchor"][0], float),
        top_anchor_offset=np.asarray(vals["anchor"][1], float),
        base_leg_joint=leg_joint,
        leg_offset=np.asarray(vals["leg_offset"], float),
        sensor_resolution=vals["sensor_resolution"],
        sensor_noise=vals["sensor_noise"],
        latency=vals["latency"],
        latency_jitter=vals["latency_jitter"],
        actuator_lag=vals["actuator_lag"],
        force_limit=vals["force_limit"],
        plate_mass=vals["plate_mass"],
        plate_com_offset=np.asarray(vals["plate_com"], float),
        gain_scale=vals["gain_scale"],
        sample_period=vals["sample_period"],
        payload=vals["payload"],
        payload_position=np.asarray(vals["payload_position"], float),
    )


def plant_platform(platform: Platform, d: Draw) -> Platform:
    """The platform the plant is built from: each base joint and plate anchor moved by its offset (legs
    on one joint move together), the plate's own mass (inertia scaled alike) and centre of mass changed,
    then the payload added (``with_payload``: a point mass at ``payload_position`` in the plate frame)."""
    scale = d.plate_mass / platform.mass if platform.mass > 0 else 1.0
    plant = platform.replace(
        base_anchors=platform.base_anchors + d.base_anchor_offset[d.base_leg_joint],
        top_anchors=platform.top_anchors + d.top_anchor_offset,
        mass=d.plate_mass,
        inertia=platform.inertia * scale,
        com=platform.com + d.plate_com_offset,
    )
    return with_payload(plant, d.payload, d.payload_position, option="--vary payload")


def sensor_model(d: Draw, seed: int, period: float, n_ticks: int) -> SensorModel:
    """The run's sensor: L + offset + noise − j·dL/dt. The noise ``(n_ticks, 6)`` and jitter ``(n_ticks,)``
    tables come from the run's seed (generator ``spawn_key=(1,)``); tick k reads row k (k = round(t / period))."""
    rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(1,)))
    noise = rng.normal(0.0, 1.0, size=(n_ticks, 6)) * d.sensor_noise
    jitter = rng.uniform(0.0, 1.0, size=n_ticks) * d.latency_jitter
    return SensorModel(d.leg_offset, noise, jitter, period)


def nominal_gains(study: Study, reference: Trajectory):
    """The gains designed for the nominal platform, timing and actuator lag over the reference's poses (as
    ``simulate`` and ``api.simulation.plan_run`` design them): the same for every run of a study."""
    duration = study.run_duration(reference)
    poses = design_poses(reference, max(duration, reference.duration or 0.0))
    return ControllerConfig.for_platform(study.platform, poses=poses).gains


def scenario(study: Study, index: int, reference: Trajectory | None = None, gains=None) -> tuple[int, Draw, Scenario]:
    """``(run seed, Draw, Scenario)`` of run ``index``, built by ``api.simulation.plan_run`` (the one home of a
    closed-loop run): the controller keeps the nominal model with the ``nominal_gains`` (computed unless
    given), scaled by the draw's ``gain_scale``; the plant, actuators and sensor are the draw's. Every draw was
    checked before the study runs (``draw_checks``), so the per-run checks are skipped."""
    seed, d = draw(study, index)
    ref = reference or study.reference()
    duration = study.run_duration(ref)
    n_ticks = tick_count(duration, d.sample_period) + 1
    plan = plan_run(
        study.platform,
        ref,
        study.controller,
        duration,
        period=d.sample_period,
        latency=d.latency,
        sensor_resolution=d.sensor_resolution,
        plant_step=study.plant_step,
        engine=study.engine,
        integrator=study.integrator,
        actuators=ActuatorModel(d.force_limit, d.actuator_lag),
        sensor=sensor_model(d, seed, d.sample_period, n_ticks),
        plant_platform=plant_platform(study.platform, d),
        gain_scale=d.gain_scale,
        nominal_gains=True,
        gains=gains,
        checks=False,
        command="montecarlo",
    )
    return seed, d, plan.scenario


def run_scenario(study: Study, index: int, keep_log: bool = False, meshcat=None) -> dict:
    """Run ``index`` of ``study``: its row (``{"run", "seed", drawn parameters..., metrics..., verdicts...}``)
    and, with ``keep_log``, the ``SimulationLog`` under ``"log"``. Metrics (SI): leg error = true length −
    the perturbed plant's IK of the reference; pose error = measured − reference pose. Verdicts: those
    ``simulate`` gives (``control.verdict.run_verdict``, see ``VERDICT_COLUMNS``). A run whose simulation
    fails keeps its row, with ``error`` set and ``lost_tracking`` true."""
    t0 = time.perf_counter()
    ref = study.reference()
    seed, d, sc = scenario(study, index, ref)
    row = {"run": index, "seed": seed, **d.columns()}
    log, error = None, ""
    try:
        log = build_simulation(sc, meshcat=meshcat).run(sc.duration)
    except (RuntimeError, ValueError) as e:
        error = f"{type(e).__name__}: {e}".splitlines()[0][:300]
    row.update(_metrics(log, ref, sc.plant_platform, study.lost_tracking, error))
    row.update(verdict_columns(sc, log))
    row["wall_s"] = time.perf_counter() - t0
    if keep_log:
        row["log"] = log
    return row


def verdict_columns(sc: Scenario, log) -> dict:
    """``VERDICT_COLUMNS`` of a run of ``sc`` from its log (None: the run failed; NaN measures, no verdicts:
    its ``error`` says why)."""
    if log is None:
        nan = float("nan")
        measures = ("force_ripple_rms_N", "chatter_ratio", "ripple_range_fraction", "longest_saturation_s")
        return dict.fromkeys(measures, nan) | {
            "chatter": False,
            "saturated": False,
            "tracking_failed": False,
            "failures": "",
        }
    truth = sc.plant_platform or sc.platform
    e, pe = log.length_error(sc.trajectory, truth), log.pose_error(sc.trajectory)
    verdict, loop = run_verdict(sc.platform, truth, sc.trajectory, log, sc.config, e, pe)
    return {
        "force_ripple_rms_N": float(max(loop["force_ripple_N"])),
        "chatter_ratio": float(loop["chatter_ratio"]),
        "ripple_range_fraction": float(loop["ripple_range_fraction"]),
        "longest_saturation_s": float(max(verdict["longest_saturation_s"])),
        "chatter": bool(loop["chatter"]),
        "saturated": bool(verdict["saturated_legs"] or loop["end_saturation"]),
        "tracking_failed": bool(verdict["tracking_lost"]),
        "failures": FAILURE_SEPARATOR.join(verdict["failures"]),
    }


def _metrics(log, ref, platform: Platform, lost: float, error: str) -> dict:
    nan = float("nan")
    if log is None:
        return {
            "max_leg_error_m": nan,
            "rms_leg_error_m": nan,
            "max_position_error_m": nan,
            "rms_position_error_m": nan,
            "max_angle_error_rad": nan,
            "rms_angle_error_rad": nan,
            "saturated_ticks": -1,
            "saturated_leg_ticks": -1,
            "lost_tracking": True,
            "error": error,
        }
    e = log.length_error(ref, platform)
    pe = log.pose_error(ref)
    pos = np.linalg.norm(pe[:, :3], axis=1)
    ang = np.abs(pe[:, 3:]).max(axis=1)
    finite = bool(np.all(np.isfinite(e)) and np.all(np.isfinite(pe)))
    max_leg = float(np.abs(e).max()) if finite else nan
    return {
        "max_leg_error_m": max_leg,
        "rms_leg_error_m": float(np.sqrt(np.mean(e**2))),
        "max_position_error_m": float(pos.max()),
        "rms_position_error_m": float(np.sqrt(np.mean(pos**2))),
        "max_angle_error_rad": float(ang.max()),
        "rms_angle_error_rad": float(np.sqrt(np.mean(ang**2))),
        "saturated_ticks": int(log.status[-1, 3]),
        "saturated_leg_ticks": int(log.saturations().sum()),
        "lost_tracking": bool(not finite or max_leg > lost),
        "error": error,
    }
