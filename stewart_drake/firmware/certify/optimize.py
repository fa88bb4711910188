"""``optimize``: the word formats of the generated firmware chosen by the certificate — the fewest word
bits (or ``sd_ik`` cycles) whose *proven* error bound meets a budget with no possible saturation — and,
for comparison, the choice simulation alone would make (sampled min/max and sampled error over random
poses, as MathWorks' ``fxpopt`` does), checked by the certifier for a pose where it overflows.

What the generator can vary: ``word_bits`` 8..16, ``length_lsb`` (a whole number of sensor counts, so
``sd_tick`` can scale set-points to counts), ``trig`` (``tfr16`` at 16 bits, or the exact table). For
each word size and trig the smallest LSB that proves no saturation is the best for the error (the error
in millimetres grows with the LSB), so each candidate costs a few certificates."""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from stewart_drake.control.gains import ControllerConfig
from stewart_drake.core.geometry import Platform
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.errors import CertifyError, QuantityError, StewartError
from stewart_drake.firmware.certify.box import PoseBox
from stewart_drake.firmware.certify.certificate import Certificate, certify
from stewart_drake.firmware.certify.recipe import Model
from stewart_drake.firmware.certify.sampling import measure_words
from stewart_drake.firmware.generate import GeneratedFirmware, generate
from stewart_drake.fixedpoint.generic import QFormat, pose_words
from stewart_drake.spec.quantity import parse_number

SIM_SAMPLES = 20_000  # the simulation-only choice sees this many random poses
PRUNE_SAMPLES = 4096  # random poses that prune a format before its proof (a real saturation or error)
SEARCH_CELLS = 30_000  # cells per candidate certificate while searching (sound, a little looser)
LSB_TRIES = 8  # LSB steps per candidate before it is declared infeasible


def parse_budget(text: str) -> float:
    """``error_budget``: metres from ``0.5mm``, ``500um``, ``0.0005m`` or ``0.0005``."""
    try:
        v = parse_number(text, "length", "error_budget")
    except QuantityError:
        v = math.nan
    if not v > 0:
        raise CertifyError(CertifyError.BUDGET.format(value=text))
    return v


@dataclass
class Candidate:
    """One format with its proven (or sampled) verdict."""

    fmt: QFormat
    error_mm: float | None  # proven (None: saturation possible) or, for the simulation-only choice, sampled
    saturation_possible: bool
    ik_cycles: float | None = None
    witness: dict | None = None

    def to_dict(self) -> dict:
        return {
            "word_bits": self.fmt.word_bits,
            "length_lsb_m": self.fmt.length_lsb,
            "trig": self.fmt.trig,
            "error_mm": self.error_mm,
            "saturation_possible": self.saturation_possible,
            "ik_cycles": self.ik_cycles,
            "witness": self.witness,
        }


@dataclass
class OptimizeResult:
    """The chosen formats (``chosen``: None if no format meets the budget), the default format's and the
    simulation-only choice's certificates for comparison, every format tried, and the firmware."""

    platform: str
    budget_m: float
    objective: str
    chosen: Candidate | None
    default: Candidate
    simulation_only: Candidate | None
    simulation_only_proven: Candidate | None
    tried: list = field(default_factory=list)
    firmware: GeneratedFirmware | None = None

    def to_dict(self) -> dict:
        return {
            "platform": self.platform,
            "error_budget_mm": self.budget_m * 1e3,
            "objective": self.objective,
            "chosen": None if self.chosen is None else self.chosen.to_dict(),
            "default": self.default.to_dict(),
            "simulation_only": None if self.simulation_only is None else self.simulation_only.to_dict(),
            "simulation_only_proven": None
            if self.simulation_only_proven is None
            else self.simulation_only_proven.to_dict(),
            "tried": [c.to_dict() for c in self.tried],
        }

    def summary(self) -> str:
        def line(label, c):
            if c is None:
                return f"{label}: none"
            err = "unbounded (saturation possible)" if c.error_mm is None else f"{c.error_mm:.4f} mm"
            cyc = "" if c.ik_cycles is None else f", sd_ik {c.ik_cycles:.0f} cycles"
            return f"{label}: {c.fmt.word_bits}-bit words, LSB {c.fmt.length_lsb:g} m, trig {c.fmt.trig}: {err}{cyc}"

        out = [
            f"error budget {self.budget_m * 1e3:g} mm, objective {self.objective}, platform {self.platform}",
            line("chosen (proven)", self.chosen),
            line("default format (proven)", self.default),
            line("simulation-only choice (sampled error)", self.simulation_only),
            line("simulation-only choice (proven)", self.simulation_only_proven),
        ]
        w = None if self.simulation_only_proven is None else self.simulation_only_proven.witness
        if w is not None:
            out.append(
                "the simulation-only choice overflows at "
                + ", ".join(f"{k} {v:.6g}" for k, v in w["pose"].items())
                + f" (saturates {', '.join(w['saturates'])})"
            )
        if self.chosen is None:
            out.append("NO FORMAT the generator can produce meets the budget with a proof")
        return "\n".join(out)


def _candidate(cert: Certificate, cycles: float | None = None) -> Candidate:
    worst = None if cert.saturation_possible or None in cert.error_bound_mm else max(cert.error_bound_mm)
    return Candidate(cert.fmt, worst, cert.saturation_possible, cycles, cert.witness)


def ik_cycles(platform: Platform, config: ControllerConfig, fmt: QFormat) -> float | None:
    """The generated ``sd_ik``'s cycle estimate in format ``fmt`` (None: the generator refuses it)."""
    try:
        return float(generate(platform, replace(config, ik_format=fmt)).ik_cycles.cycles)
    except StewartError:
        return None


def _order(platform, config, objective: str) -> list[tuple[int, str]]:
    """(word_bits, trig) in the order the objective prefers them."""
    opts = [(wb, "exact") for wb in range(8, 17)] + [(16, "tfr16")]
    if objective == "bits":
        return sorted(opts, key=lambda o: (o[0], o[1] != "exact"))
    cyc = {t: ik_cycles(platform, config, QFormat(16, config.ik_format.length_lsb, t)) for t in ("exact", "tfr16")}
    return sorted(opts, key=lambda o: (cyc[o[1]] if cyc[o[1]] is not None else math.inf, o[0]))


def _search(platform, config, box, budget_m, objective, sampled, proven, tried) -> Candidate | None:
    """The first (word_bits, trig) in the objective's order whose smallest saturation-free LSB (whole
    sensor counts) meets the budget: by the samples alone when ``proven`` is None, else by a proof.

    Samples prune rigorously before any proof: a sampled saturation or a sampled error above the budget
    happens at a real pose, so that format cannot be proven either."""
    res = config.timing.sensor_resolution
    rng = np.random.default_rng(11)
    longest = float(leg_lengths(platform, rng.uniform(box.lo, box.hi, (4096, 6)), config.convention).max())
    for wb, trig in _order(platform, config, objective):
        k = max(1, math.ceil(longest / ((1 << (wb - 1)) - 1) / res))
        for _ in range(LSB_TRIES):
            fmt = QFormat(wb, k * res, trig)
            c = sampled(fmt)
            if c is not None and not c.saturation_possible:
                if c.error_mm > budget_m * 1e3:
                    break  # a real pose exceeds the budget; a coarser LSB only adds error
                if proven is None:
                    return c
                c = proven(fmt)
                if c is not None:
                    tried.append(c)
                    if not c.saturation_possible:
                        if c.error_mm is not None and c.error_mm <= budget_m * 1e3:
                            return c
                        break
            k += max(1, math.ceil(0.03 * k))
    return None


def optimize(
    platform: Platform,
    config: ControllerConfig,
    box: PoseBox,
    budget_m: float,
    objective: str = "bits",
    max_cells: int = 200_000,
    search_cells: int = SEARCH_CELLS,
    samples: int = SIM_SAMPLES,
) -> OptimizeResult:
    """Choose the formats (see the module docstring) and generate the firmware for them; compare with the
    default format of ``config`` and with the simulation-only choice (``samples`` random poses)."""

    def proven(fmt: QFormat, cells: int = search_cells) -> Candidate | None:
        try:
            cert = certify(platform, fmt, box, config.convention, cells)
        except StewartError:  # a constant or the box does not fit the words at this LSB
            return None
        return _candidate(cert, ik_cycles(platform, config, fmt))

    q_all = np.random.default_rng(13).uniform(box.lo, box.hi, (samples, 6))

    def sampled(fmt: QFormat, q=q_all[:PRUNE_SAMPLES]) -> Candidate | None:
        try:
            m = Model.build(platform, fmt, config.convention)
        except StewartError:
            return None
        smp = measure_words(m, pose_words(q, fmt))
        err = float(smp.worst_err.max() * fmt.length_lsb * 1e3)
        return Candidate(fmt, err, smp.saturated > 0, None)

    tried: list[Candidate] = []
    chosen = _search(platform, config, box, budget_m, objective, sampled, proven, tried)
    if chosen is not None:  # the final certificate at the full budget (tighter, never looser)
        chosen = proven(chosen.fmt, max(max_cells, search_cells))
    sim = _search(platform, config, box, budget_m, objective, lambda fmt: sampled(fmt, q_all), None, [])
    if sim is not None:
        sim.ik_cycles = ik_cycles(platform, config, sim.fmt)
    sim_proven = None if sim is None else proven(sim.fmt)
    default = proven(config.ik_format)
    fw = None if chosen is None else generate(platform, replace(config, ik_format=chosen.fmt))
    return OptimizeResult(platform.name, budget_m, objective, chosen, default, sim, sim_proven, tried, fw)
