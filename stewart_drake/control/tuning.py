"""Leg PID gains chosen on the linear loop of ``control.frequency`` to meet stated margins at every pose of a
grid over the workspace box, with the largest worst-pose bandwidth.

The grid (``grid_poses``): the box's centre, its 12 face centres and its 64 corners, less the poses whose legs
leave the stroke. The candidates: today's design (``gains.design_gains``) scaled — kd (= kv) by ``KD_SCALES``,
kp by ``KP_SCALES``, ki by ``KI_SCALES`` times kp's factor (the integral corner ki/kp moves by ``KI_SCALES``
alone) — a deterministic grid of 12 × 7 × 4 gain sets around the design, each the law's PID with its velocity
feed-forward equal to kd. A candidate is feasible when, at every grid pose, the closed loop is stable (every pole |z| < 1) and
each leg's loop, broken at its command with the other five closed, has at least the gain and phase margins
asked for (``frequency.margins``). Among the feasible ones the tuner takes the largest worst-pose bandwidth:
the lowest −3 dB frequency of the legs' set-point responses through the PID, without the feed-forward (the
feed-forward's inverse model would hide the loop's own bandwidth). With a target bandwidth, a candidate must
also reach it. The plant (mass, stiffness, delay, lag) is computed once per pose; each candidate costs one
6×6 solve per pose and frequency and one eigenvalue problem per pose.
"""

from __future__ import annotations

import itertools
import pickle
from dataclasses import dataclass, replace

import numpy as np

from stewart_drake.control.feedforward import feedforward_lead
from stewart_drake.control.frequency import (
    MIN_GAIN_MARGIN_DB,
    MIN_PHASE_MARGIN_DEG,
    LoopModel,
    bandwidth,
    controller_matrices,
    effective_gains,
    margins,
)
from stewart_drake.control.gains import ControllerConfig, PidGains
from stewart_drake.core.geometry import Platform
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.errors import PhysicalLimitError, TuneError
from stewart_drake.system import results

KD_SCALES = tuple(float(x) for x in np.logspace(-1.2, 0.3, 12))
KP_SCALES = tuple(float(x) for x in np.logspace(-1.0, 0.6, 7))
KI_SCALES = (0.05, 0.2, 0.6, 1.5)
# frequencies per pose for the margins and bandwidth (log-spaced to just below Nyquist)
FREQUENCIES = 200
CACHE_KIND = "tune"  # the cache folder of the gains controller.gains: tune ran with (system.results)


def grid_poses(platform: Platform, lo, hi) -> np.ndarray:
    """``(n, 6)`` poses (m, rad): the centre, the 12 face centres and the 64 corners of the box ``lo``..``hi``
    (6,), each once (a box flat in some key repeats them), without those whose legs leave ``platform``'s stroke."""
    lo, hi = np.asarray(lo, dtype=float), np.asarray(hi, dtype=float)
    c = (lo + hi) / 2
    faces = [c + s * np.eye(6)[k] * (hi - lo) / 2 for k in range(6) for s in (-1, 1)]
    corners = [np.where(np.array(b), hi, lo) for b in itertools.product((0, 1), repeat=6)]
    poses = np.array([c, *faces, *corners])
    _, first = np.unique(poses, axis=0, return_index=True)  # a flat box repeats poses: each once, in order
    poses = poses[np.sort(first)]
    L = leg_lengths(platform, poses)
    inside = np.all((L >= platform.L_min) & (L <= platform.L_max), axis=1)
    return poses[inside]


@dataclass(frozen=True)
class LoopSpec:
    """What the linear loop needs besides the gains: sample period ``T``, output ``delay``, actuator ``lag``,
    plant ``step`` (s) and the feed-forward ``lead`` (s, None: none)."""

    T: float
    delay: float
    lag: float
    step: float
    lead: float | None

    @classmethod
    def of(cls, config: ControllerConfig, lag: float, step: float, feedforward: bool) -> LoopSpec:
        """The loop of a controller ``config`` with actuator ``lag`` (s), plant ``step`` (s) and, if
        ``feedforward``, the feed-forward table's lead."""
        t = config.timing
        return cls(t.sample_period, t.output_delay, lag, step, feedforward_lead(config, lag) if feedforward else None)

    def model(self, platform: Platform, pose, gains: PidGains) -> LoopModel:
        return LoopModel.build(platform, pose, gains, self.T, self.delay, self.lag, self.step, self.lead)


@dataclass(frozen=True)
class Evaluation:
    """One gain set over the grid: the worst pose's ``gain_margin_db``, ``phase_margin_deg``,
    ``bandwidth_hz`` (None: above the frequencies) and ``spectral_radius``, and the pose index of each."""

    gains: PidGains
    gain_margin_db: float
    phase_margin_deg: float
    bandwidth_hz: float | None
    spectral_radius: float
    worst_pose: dict

    def meets(self, gain_margin_db: float, phase_margin_deg: float, bandwidth_hz: float | None = None) -> bool:
        ok = self.spectral_radius < 1 and self.gain_margin_db >= gain_margin_db
        ok = ok and self.phase_margin_deg >= phase_margin_deg
        return ok and (bandwidth_hz is None or self.bandwidth >= bandwidth_hz)

    @property
    def bandwidth(self) -> float:
        """``bandwidth_hz``, inf where it is above the frequencies."""
        return np.inf if self.bandwidth_hz is None else self.bandwidth_hz

    def to_dict(self) -> dict:
        return {
            "gains": {k: getattr(self.gains, k) for k in ("kp", "ki", "kd", "kv")},
            "gain_margin_db": self.gain_margin_db,
            "phase_margin_deg": self.phase_margin_deg,
            "bandwidth_hz": self.bandwidth_hz,
            "spectral_radius": self.spectral_radius,
            "worst_pose": self.worst_pose,
        }


class GridLoops:
    """The plant of the loop at each pose of ``poses`` (n, 6), computed once, to evaluate gain sets fast."""

    def __init__(self, platform: Platform, poses, spec: LoopSpec, gains: PidGains):
        self.poses = np.asarray(poses, dtype=float)
        self.spec = spec
        self.freqs = np.logspace(-1, np.log10(0.499 / spec.T), FREQUENCIES)
        self.models = [spec.model(platform, q, gains) for q in self.poses]
        self.G = np.array([m.plant_response(self.freqs) for m in self.models])  # (n, f, 6, 6)

    def evaluate(self, gains: PidGains) -> Evaluation:
        """The worst margins, bandwidth and pole radius of ``gains`` over the grid."""
        z = np.exp(1j * 2 * np.pi * self.freqs * self.spec.T)
        Ac, Bc, Cc, Dc = controller_matrices(gains, self.spec.T)
        H = np.array([Cc @ np.linalg.solve(zk * np.eye(5) - Ac, Bc) + Dc for zk in z])[:, 0]  # (f, 2)
        cr, cy = H[:, 0], -H[:, 1]
        S = np.linalg.inv(np.eye(6) + cy[None, :, None, None] * self.G)  # (n, f, 6, 6)
        L = 1.0 / np.diagonal(S, axis1=-2, axis2=-1) - 1.0  # (n, f, 6)
        Tfb = S @ self.G * cr[None, :, None, None]
        gm = pm = np.inf
        bw, worst = None, {}
        for i in range(len(self.poses)):
            for leg in range(6):
                m = margins(self.freqs, L[i, :, leg])
                if m["gain_margin_db"] < gm:
                    gm, worst["gain_margin"] = m["gain_margin_db"], i
                if m["phase_margin_deg"] < pm:
                    pm, worst["phase_margin"] = m["phase_margin_deg"], i
                b = bandwidth(self.freqs, Tfb[i, :, leg, leg])
                if b is not None and (bw is None or b < bw):
                    bw, worst["bandwidth"] = b, i
        rho, worst["spectral_radius"] = self.spectral_radius(gains)
        return Evaluation(gains, float(gm), float(pm), bw, rho, worst)

    def spectral_radius(self, gains: PidGains) -> tuple[float, int]:
        """The largest closed-loop pole |z| over the grid and its pose index."""
        rhos = [replace_gains(m, gains, self.spec).spectral_radius for m in self.models]
        return float(max(rhos)), int(np.argmax(rhos))


def replace_gains(model: LoopModel, gains: PidGains, spec: LoopSpec) -> LoopModel:
    """``model`` with ``gains`` (the plant kept): the closed loop rebuilt from its plant matrices."""
    Pa, Ga, Cp = model.plant
    I6 = np.eye(6)
    Ac, Bc, Cc, Dc = (np.kron(X, I6) for X in controller_matrices(gains, spec.T))
    Bsp, Bm, Dsp, Dm = Bc[:, :6], Bc[:, 6:], Dc[:, :6], Dc[:, 6:]
    A = np.block([[Pa + Ga @ Dm @ Cp, Ga @ Cc], [Bm @ Cp, Ac]])
    B = np.block([[Ga @ Dsp, Ga], [Bsp, np.zeros((len(Ac), 6))]])
    return replace(model, A=A, B=B, gains=gains)


def candidates(design: PidGains):
    """The gain sets tried (see the module docstring), ``design`` scaled; kv follows kd."""
    for sd_, sp, si in itertools.product(KD_SCALES, KP_SCALES, KI_SCALES):
        kd = design.kd * sd_
        yield replace(design, kp=design.kp * sp, ki=design.ki * si * sp, kd=kd, kv=kd)


def tune_gains(
    loops: GridLoops,
    design: PidGains,
    gain_margin_db: float,
    phase_margin_deg: float,
    bandwidth_hz: float | None = None,
    realise=None,
) -> tuple[Evaluation | None, Evaluation, list[Evaluation]]:
    """``(chosen, best_margin, feasible)``: the feasible candidate with the largest worst-pose bandwidth (None:
    none meets the margins and ``bandwidth_hz``), the stable candidate whose smaller margin excess is largest (a
    degree of phase counted as a fifth of a dB; shown when none is feasible), and every feasible candidate, by
    bandwidth, largest first. Each candidate is evaluated as ``realise(gains)``: the gains the law applies,
    e.g. the fixed law's Q15 words (None: as is)."""
    feasible, best, best_excess = [], None, -np.inf
    for g in candidates(design):
        ev = loops.evaluate(g if realise is None else realise(g))
        excess = min(ev.gain_margin_db - gain_margin_db, (ev.phase_margin_deg - phase_margin_deg) / 5.0)
        if ev.spectral_radius >= 1:
            excess = -np.inf
        if best is None or excess > best_excess:
            best, best_excess = ev, excess
        if ev.meets(gain_margin_db, phase_margin_deg, bandwidth_hz):
            feasible.append(ev)
    feasible.sort(key=lambda e: -e.bandwidth)
    return (feasible[0] if feasible else None), best, feasible


def tuned_gains(platform: Platform, config: ControllerConfig, law: str, spec: LoopSpec, lo, hi) -> PidGains:
    """The gains ``controller.gains: tune`` runs with: the widest-bandwidth candidate around ``config``'s
    designed gains that meets ``MIN_GAIN_MARGIN_DB`` and ``MIN_PHASE_MARGIN_DEG`` at every pose of the grid of
    the box ``lo``..``hi`` (6,), as ``law`` applies them (the fixed law's Q15 words). Raises
    ``PhysicalLimitError`` (naming the best found) when none does.

    Each machine is tuned once: the gains are kept on disk (``system.results``) under the package's version and
    the exact inputs (a pickle of all six), so the next run of the same machine reads them, and a change of the
    code or of any input tunes again. A failure is not kept."""
    key = results.key(pickle.dumps((platform, config, law, spec, np.asarray(lo), np.asarray(hi)), protocol=5))
    kept = results.load(CACHE_KIND, key)
    if isinstance(kept, PidGains):
        return kept
    gains = _tune_for_run(platform, config, law, spec, lo, hi)
    results.store(CACHE_KIND, key, gains)
    return gains


def _tune_for_run(platform: Platform, config: ControllerConfig, law: str, spec: LoopSpec, lo, hi) -> PidGains:
    poses = grid_poses(platform, lo, hi)
    if not len(poses):
        raise PhysicalLimitError(TuneError.NO_POSES.format(name=platform.name))

    def realise(g):
        return effective_gains(law, replace(config, gains=g))

    loops = GridLoops(platform, poses, spec, realise(config.gains))
    chosen, best, _ = tune_gains(loops, config.gains, MIN_GAIN_MARGIN_DB, MIN_PHASE_MARGIN_DEG, realise=realise)
    if chosen is None:
        raise PhysicalLimitError(no_gains_message(best, config.gains, MIN_GAIN_MARGIN_DB, MIN_PHASE_MARGIN_DEG))
    return chosen.gains


def no_gains_message(best: Evaluation, design: PidGains, gm: float, pm: float, bandwidth_hz=None) -> str:
    """``TuneError.NO_GAINS`` for the candidates around ``design``, naming the ``best`` found."""
    bw = f", bandwidth >= {bandwidth_hz:g} Hz" if bandwidth_hz is not None else ""
    best_bw = "none" if best.bandwidth_hz is None else f"{best.bandwidth_hz:.2f} Hz"
    return TuneError.NO_GAINS.format(
        count=len(list(candidates(design))), gm=gm, pm=pm, bw=bw,
        best_gm=best.gain_margin_db, best_pm=best.phase_margin_deg, best_bw=best_bw,
    )  # fmt: skip
