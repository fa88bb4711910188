"""One Monte Carlo run as plain, picklable data, and the function that runs it.

Drake objects do not pickle, so a worker receives a ``Study`` (the nominal ``Machine``, the reference, the
SPEC, the seed) and a run index, draws that run's ``Draw`` from its own seed (``sample(machine, spec, seed,
index)``; ``Draw.machine()`` is the drawn machine), turns it into a ``drake.simulation.Scenario`` through
``api.simulation.plan_run`` (``scenario``) and builds its Diagram from that itself (``run_scenario``). The
run's seed is
``run_seed(study.seed, index)``: the first 64-bit word (its low 63 bits) of ``numpy.random.SeedSequence(S,
spawn_key=(index,))``, so any run can be re-drawn alone from (S, index) or from its seed.

What a draw changes (the controller keeps the nominal model, the machine's platform and payload with the gains
designed for its timing: it is what the firmware was built for; every other field of the machine, its firmware
format included, is the drawn machine's):

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
from dataclasses import dataclass, field, fields, replace

import numpy as np

from stewart_drake.api.simulation import KEYWORD_PATHS, actuator_model, plan_run, tick_count
from stewart_drake.control import ControllerConfig, DspTiming
from stewart_drake.control.verdict import run_verdict
from stewart_drake.core.geometry import Platform, base_joints
from stewart_drake.core.quantisation import check_finite_rates, check_quantisation
from stewart_drake.core.trajectory import (
    TRAJECTORIES,
    Trajectory,
    design_poses,
    fit_trajectory,
    get_trajectory,
    read_trajectory_table,
    table_trajectory,
)
from stewart_drake.design.payload import with_payload
from stewart_drake.drake.integrators import DEFAULT_INTEGRATOR
from stewart_drake.drake.simulation import ActuatorModel, Scenario, SensorModel, build_simulation
from stewart_drake.montecarlo.spec import KEYS, VarySpec
from stewart_drake.montecarlo.summary import FAILURE_SEPARATOR
from stewart_drake.script import run_program
from stewart_drake.script.source import read_program
from stewart_drake.spec import Machine, apply_overrides

# A run loses tracking when a leg is this far (m) from the reference's IK, or the state is not finite.
LOST_TRACKING = 5e-3
AXES = ("x", "y", "z")
# the SI unit in a drawn column's name, by the key's dimension
UNIT = {"length": "m", "time": "s", "force": "N", "mass": "kg", "ratio": "", "mode": ""}
# Study's keywords of earlier versions -> the spec path they set (plan_run's, and the run's duration)
STUDY_KEYWORDS = {**KEYWORD_PATHS, "duration": "run.duration"}


def reference_data(motion, length_unit: str = "m", angle_unit: str = "rad") -> dict:
    """A motion as ``Study``'s picklable reference fields: ``seed``/``rotating`` (``trajectory``), a ``.stw``
    program (``program``: its name and text), a CSV of t, pose rows (``table``, read here in the units given) or
    a ``Trajectory`` (``motion``)."""
    if isinstance(motion, Trajectory):
        return {"trajectory": None, "motion": motion}
    m = str(motion)
    if m in TRAJECTORIES:
        return {"trajectory": m}
    if m.endswith(".stw"):
        return {"trajectory": None, "program": (m, read_program(m))}
    return {"trajectory": None, "table": csv_table(m, length_unit, angle_unit)}


def csv_table(path: str, length_unit: str, angle_unit: str) -> tuple:
    """A (t, pose) CSV reference as ``(name, times, poses SI)`` lists (``Study.table``), read here once as a
    stream (``read_trajectory_table`` names a bad line; a FIFO works) and checked as ``load_trajectory_csv``
    checks it (finite rates; rounding noise refused)."""
    name, ts, poses = read_trajectory_table(path, length_unit, angle_unit)
    check_finite_rates(path, ts, poses)
    check_quantisation(path, ts, poses)
    return (name, ts.tolist(), poses.tolist())


@dataclass(frozen=True, init=False)
class Study:
    """A study's fixed settings (picklable): the nominal ``machine`` (its platform, controller, firmware format,
    sensors, actuators, payload and run settings reach every run), what varies (``spec``), the study's ``seed``
    and its number of ``runs``. The reference as data: ``trajectory`` (``seed`` or ``rotating``), ``table`` (a
    CSV read on the client: name, times (n,), poses (n, 6) SI as lists, so that workers need no file),
    ``program`` ((file name, text) of a ``.stw`` motion program) or ``motion`` (a Python ``Trajectory``, pickled
    to the workers with the study); none given: the machine's first motion. ``lost_tracking``: metres of leg
    error that count as lost tracking; ``grid``: one ``{key: SI value}`` per run that replaces that run's draws
    of those keys (a sweep; ``runs`` = its length).

    ``machine`` may be a ``Platform`` (a machine with defaults) and the keywords ``controller``, ``engine``,
    ``integrator``, ``duration``, ``plant_step``, ``fit``, ... set their spec paths (``STUDY_KEYWORDS``). A
    machine whose ``controller.engine`` is None runs the Python tick (``sd.montecarlo`` picks C where a compiler
    is found)."""

    machine: Machine
    spec: VarySpec
    seed: int
    runs: int
    trajectory: str | None = "seed"
    program: tuple | None = None
    table: tuple | None = None
    lost_tracking: float = LOST_TRACKING
    grid: tuple | None = None
    extra: dict = field(default_factory=dict)
    motion: Trajectory | None = None

    def __init__(
        self,
        machine: Machine | Platform,
        spec: VarySpec,
        seed: int,
        runs: int,
        trajectory: str | None = None,
        program: tuple | None = None,
        table: tuple | None = None,
        lost_tracking: float = LOST_TRACKING,
        grid: tuple | None = None,
        extra: dict | None = None,
        motion: Trajectory | None = None,
        **keywords,
    ):
        unknown = set(keywords) - set(STUDY_KEYWORDS)
        if unknown:  # internal: a caller's typo
            raise TypeError(f"Study() got unexpected keywords {sorted(unknown)}")
        machine = machine if isinstance(machine, Machine) else Machine(machine)
        machine = apply_overrides(machine, {STUDY_KEYWORDS[k]: v for k, v in keywords.items() if v is not None})
        if machine.controller.engine is None:
            machine = replace(machine, controller=replace(machine.controller, engine="python"))
        if trajectory is None and program is None and table is None and motion is None:
            ref = reference_data(machine.motion)
            trajectory, program, table, motion = (ref.get(k) for k in ("trajectory", "program", "table", "motion"))
        given = dict(machine=machine, spec=spec, seed=seed, runs=runs, trajectory=trajectory, program=program)
        given |= dict(table=table, lost_tracking=lost_tracking, grid=grid, extra=dict(extra or {}), motion=motion)
        for f in fields(Study):
            object.__setattr__(self, f.name, given[f.name])

    @property
    def platform(self) -> Platform:
        """The nominal platform as written (the machine's, without its payload)."""
        return self.machine.platform

    @property
    def controller(self) -> str:
        """The law: ``fixed`` or ``float`` (``controller.law``)."""
        return self.machine.controller.law

    @property
    def engine(self) -> str:
        """The fixed-point tick: ``c`` or ``python`` (``controller.engine``)."""
        return self.machine.controller.engine

    @property
    def integrator(self) -> str:
        """The plant integrator (``run.integrator``, else the default)."""
        return self.machine.run.integrator or DEFAULT_INTEGRATOR

    @property
    def duration(self) -> float | None:
        """Simulated seconds per run as given (``run.duration``; None: the reference's)."""
        return self.machine.run.duration

    @property
    def plant_step(self) -> float:
        """The plant step, s: ``run.plant_step``, else the nominal period, at most 1 ms (a drawn period leaves
        it as it is)."""
        run = self.machine.run
        return run.plant_step if run.plant_step is not None else min(self.machine.controller.period, 1e-3)

    @property
    def fit(self) -> bool:
        """Move and scale the reference to the platform's home height and stroke (``run.fit``)."""
        return self.machine.run.fit

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


# Draw's attribute names of the keys whose name differs
_ALIASES = {"plate_com_offset": "plate_com"}


@dataclass(frozen=True)
class Draw:
    """One run's draw: ``values`` ``{key: value}`` for every key of ``spec.KEYS`` (SI; vectors as arrays;
    ``anchor``: offsets per physical joint, ``(m, 3)`` base joints in B, leg i on ``base_leg_joint[i]``, and
    ``(k, 3)`` plate anchors in T, leg i on ``platform.leg_top[i]``) and the ``nominal`` machine it was drawn
    from. ``machine()`` is the drawn ``Machine``; each key's value is also an attribute (``d.sample_period``;
    ``base_anchor_offset``, ``top_anchor_offset``, ``plate_com_offset``)."""

    values: dict
    base_leg_joint: np.ndarray
    nominal: Machine

    def __getattr__(self, name: str):
        if name.startswith("__") or "values" not in self.__dict__:
            raise AttributeError(name)
        if name in ("base_anchor_offset", "top_anchor_offset"):
            return self.values["anchor"][name.startswith("top")]
        key = _ALIASES.get(name, name)
        if key not in self.values:
            raise AttributeError(name)
        return self.values[key]

    def machine(self) -> Machine:
        """The drawn ``Machine``: its platform is the plant's (``plant_geometry``) and each key with a spec path
        sets that path (checked as the machine checks it: ``MachineError`` naming the path)."""
        m = self.nominal
        sections: dict = {}
        for key, k in KEYS.items():
            if k.path is not None:
                section, name = k.path.split(".")
                v = self.values[key]
                sections.setdefault(section, {})[name] = tuple(v) if isinstance(v, np.ndarray) else v
        drawn = {s: replace(getattr(m, s), **f) for s, f in sections.items()}
        return replace(m, platform=plant_geometry(m.platform, self), **drawn)

    def columns(self) -> dict:
        """The drawn parameters as flat ``{column: value}`` (SI, names with their unit)."""
        out = {}
        for key, k in KEYS.items():
            v, unit = self.values[key], UNIT[k.dimension]
            if key == "anchor":
                for side, offsets in (("base", v[0]), ("top", v[1])):
                    for j, row in enumerate(offsets):
                        out.update({f"anchor_{side}{j + 1}_{a}_m": float(x) for a, x in zip(AXES, row)})
            elif k.length == 3:
                out.update({f"{key}_{a}_{unit}": float(x) for a, x in zip(AXES, v)})
            elif k.length:
                out.update({f"{key}{i + 1}_{unit}": float(x) for i, x in enumerate(v)})
            else:
                out[f"{key}_{unit}" if unit else key] = v
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


def nominal_value(machine: Machine, key: str):
    """The nominal of ``key``: the machine's value at its spec path (``actuators.max_force`` unset: the
    platform's ``legs.max_force``), the plate's own mass (``plate_mass``), else zero offsets."""
    k = KEYS[key]
    if key == "plate_mass":
        return float(machine.platform.mass)
    if k.path is None:
        return 0.0
    section, name = k.path.split(".")
    v = getattr(getattr(machine, section), name)
    if v is None and k.path == "actuators.max_force":
        v = machine.platform.legs.max_force
    return v if isinstance(v, str) else np.asarray(v, float) if isinstance(v, tuple) else float(v)


def sample(machine: Machine, spec: VarySpec, seed: int, index: int, grid: dict | None = None) -> tuple[int, Draw]:
    """``(run seed, Draw)`` of run ``index`` of a study of ``machine`` seeded ``seed``: every key drawn in
    ``KEYS`` order from the run's own generator (a key left nominal draws nothing); ``grid``: values that replace
    the draws of their keys. ``anchor`` draws ``(6, 3)`` base offsets, one row per leg, then ``(k, 3)`` plate
    offsets; a base joint takes the row of its first leg and the rows of the other legs on it are skipped, so the
    stream (and so every key drawn after) is the same on every architecture."""
    run = run_seed(seed, index)
    rng = np.random.default_rng(np.random.SeedSequence(run, spawn_key=(0,)))
    p, laws = machine.platform, spec.laws
    first, leg_joint = base_joints(p)
    vals = {}
    for key, k in KEYS.items():
        law = laws.get(key)
        if key == "anchor":
            base = np.asarray(_draw_one(rng, law, 0.0, (6, 3))[first], float)
            vals[key] = (base, np.asarray(_draw_one(rng, law, 0.0, (len(p.top_anchors), 3)), float))
            continue
        v = _draw_one(rng, law, nominal_value(machine, key), (k.length,) if k.length else ())
        vals[key] = str(v) if k.dimension == "mode" else np.asarray(v, float) if k.length else float(v)
    vals.update(grid or {})
    return run, Draw(vals, leg_joint, machine)


def draw(study: Study, index: int) -> tuple[int, Draw]:
    """``(run seed, Draw)`` of run ``index`` of ``study`` (``sample`` of its machine; a sweep's grid point
    replaces the draws of its keys)."""
    grid = study.grid[index] if study.grid is not None else None
    return sample(study.machine, study.spec, study.seed, index, grid)


def plant_geometry(platform: Platform, d: Draw) -> Platform:
    """``platform`` with each base joint and plate anchor moved by its offset (legs on one joint move together)
    and the plate's own mass (inertia scaled alike) and centre of mass changed."""
    scale = d.plate_mass / platform.mass if platform.mass > 0 else 1.0
    return platform.replace(
        base_anchors=platform.base_anchors + d.base_anchor_offset[d.base_leg_joint],
        top_anchors=platform.top_anchors + d.top_anchor_offset,
        mass=d.plate_mass,
        inertia=platform.inertia * scale,
        com=platform.com + d.plate_com_offset,
    )


def plant_platform(platform: Platform, d: Draw) -> Platform:
    """The platform the plant is built from: ``plant_geometry``, then the drawn payload added (``with_payload``:
    a point mass at ``payload_position`` in the plate frame); the drawn machine's ``loaded_platform``."""
    return with_payload(plant_geometry(platform, d), d.payload, d.payload_position, option="payload")


def sensor_model(d: Draw, seed: int, period: float, n_ticks: int) -> SensorModel:
    """The run's sensor: L + offset + noise − j·dL/dt. The noise ``(n_ticks, 6)`` and jitter ``(n_ticks,)``
    tables come from the run's seed (generator ``spawn_key=(1,)``); tick k reads row k (k = round(t / period))."""
    rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(1,)))
    noise = rng.normal(0.0, 1.0, size=(n_ticks, 6)) * d.sensor_noise
    jitter = rng.uniform(0.0, 1.0, size=n_ticks) * d.latency_jitter
    return SensorModel(d.leg_offset, noise, jitter, period)


def nominal_gains(study: Study, reference: Trajectory):
    """The gains designed for the nominal machine (its loaded platform, timing and actuator lag) over the
    reference's poses, as ``api.simulation.plan_run`` designs them: the same for every run of a study."""
    m = study.machine
    platform, ctl = m.loaded_platform, m.controller
    duration = study.run_duration(reference)
    poses = design_poses(reference, max(duration, reference.duration or 0.0))
    timing = DspTiming(
        sample_period=ctl.period,
        latency=ctl.latency,
        sensor_resolution=m.sensors.resolution,
        command_range=float(platform.legs.max_force),
    )
    # the lag the gains are designed for: the lag's, a screw's current loop's, a cylinder's valve's
    return ControllerConfig.for_platform(platform, timing, actuator_model(m).time_constant, poses=poses).gains


def scenario(study: Study, index: int, reference: Trajectory | None = None, gains=None) -> tuple[int, Draw, Scenario]:
    """``(run seed, Draw, Scenario)`` of run ``index``, built by ``api.simulation.plan_run`` (the one home of a
    closed-loop run) from the drawn machine (``Draw.machine``): the controller keeps the nominal model (the
    machine's platform and payload) with the ``nominal_gains`` (computed unless given), scaled by the drawn
    ``controller.gain_scale``; the plant, actuators, sensor, timing and number format are the drawn machine's.
    Every draw was checked before the study runs (``draw_checks``), so the per-run checks are skipped."""
    seed, d = draw(study, index)
    drawn = d.machine()
    ref = reference or study.reference()
    duration = study.run_duration(ref)
    period = drawn.controller.period
    model = replace(drawn, platform=study.machine.platform, payload=study.machine.payload)
    plan = plan_run(
        model,
        ref,
        duration=duration,
        plant_step=study.plant_step,
        fit=False,  # the reference is fitted already (Study.reference)
        # a screw or a cylinder: the drawn machine's (the draws actuator_lag and force_limit are the lag's)
        actuators=actuator_model(drawn)
        if drawn.actuators.model != "lag"
        else ActuatorModel(d.force_limit, d.actuator_lag),
        sensor=sensor_model(d, seed, period, tick_count(duration, period) + 1),
        plant_platform=drawn.loaded_platform,
        nominal_gains=True,
        gains=gains if gains is not None else nominal_gains(study, ref),
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
