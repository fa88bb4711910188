"""The fixed-point law's force ripple from its quantisers, through the linear leg loop of ``control.frequency``:
a rigorous peak bound and an RMS estimate, split by source and by the PID's terms.

Three quantisers sit in the loop: the IK's set-point word (its length LSB), the position sensor (one count) and
the command word (``extract_h``: the Q31 sum truncated to a Q15 word of ``command_range / 2^15`` N). Each adds an
error e_k to a signal of the linear loop — the set-point, the measurement, the command — and the loop carries it
to the actuator command u. With h_k the closed loop's impulse response from one source to the command (6×6 per
tick, ``LoopModel``'s A with that source's input and the command as output):

- **bound** (peak): |δu_i| ≤ Σ_k Σ_j |h_k[i, j]| · ē, for any error sequence with |e| ≤ ē (ē = q/2 for the
  rounding set-point and sensor, q for the truncating command word). Holds for every run the linear model
  describes, limit cycles included, and also for the actuator force: the first-order lag's impulse response is
  positive with unit sum, so it never raises a peak. The sum stops where ‖A^k B‖ has fallen below
  ``TAIL`` of its start.
- **estimate** (RMS): ‖h‖₂ · q/√12, the classical model of a quantiser as white noise uniform in one step. It
  holds when the error changes by about a step every tick (a moving reference, a noisy sensor); a slow reference
  that crosses a set-point step every few ticks excites the kv/T and kd/T paths less often, so the estimate
  then overstates the simulated ripple, and the bound overstates both.

The set-point source is the rounding of the IK's output word alone; the IK's arithmetic error (its trig, its
intermediate words) is a smooth function of the pose that ``firmware.certify`` bounds, a tracking error rather
than a ripple. Terms: P (kp·e), I (the integrator), D (kd/T on the measurement's difference), V (kv/T on the
set-point's difference); a source's bound is at most the sum of its terms' bounds, the term that carries most
of it is the one to change (a gain, or the source's step). Forces in newtons, steps in metres (the command
word's in newtons).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from stewart_drake.control.frequency import LoopModel, controller_matrices
from stewart_drake.control.gains import PidGains

# The impulse response is summed until ‖A^k B‖ falls below this fraction of ‖B‖ (the tail is then a
# geometric series of ratio ≤ the spectral radius, negligible against the sum), or for at most MAX_TICKS ticks.
TAIL = 1e-9
MAX_TICKS = 400_000
SOURCES = ("length_lsb", "sensor", "command_word")
TERMS = ("P", "I", "D", "V")


@dataclass(frozen=True)
class RippleSource:
    """One quantiser's part: ``step`` (m, or N for the command word), ``bound_N`` (6,) peak bound per leg,
    ``rms_N`` (6,) white-noise estimate per leg, ``terms`` {P, I, D, V (and ``word`` for the command word
    itself)}: the bound (N, largest over legs) through each term."""

    name: str
    step: float
    bound_N: np.ndarray
    rms_N: np.ndarray
    terms: dict

    @property
    def dominant_term(self) -> str:
        return max(self.terms, key=self.terms.get)


@dataclass(frozen=True)
class Ripple:
    """The quantisation ripple of one loop: its ``sources`` (``SOURCES`` order), ``ticks`` summed."""

    sources: tuple
    ticks: int

    @property
    def bound_N(self) -> float:
        """The peak bound on the command's (and force's) deviation, N: the sources' bounds added, largest leg."""
        return float(np.sum([s.bound_N for s in self.sources], axis=0).max())

    @property
    def rms_N(self) -> float:
        """The RMS estimate, N: the sources independent, largest leg."""
        return float(np.sqrt(np.sum([s.rms_N**2 for s in self.sources], axis=0)).max())

    @property
    def dominant(self) -> RippleSource:
        """The source with the largest RMS estimate."""
        return max(self.sources, key=lambda s: float(s.rms_N.max()))

    def cause(self) -> str:
        """One line: the dominant source, its step and the term that carries it."""
        d = self.dominant
        unit = f"{d.step:.4g} N" if d.name == "command_word" else f"{d.step * 1e6:.4g} µm"
        return (
            f"{d.name} ({unit}): {float(d.rms_N.max()):.4g} N RMS of {self.rms_N:.4g} N, "
            f"mostly through the {d.dominant_term} term"
        )

    def to_dict(self) -> dict:
        return {
            "bound_N": self.bound_N,
            "rms_N": self.rms_N,
            "cause": self.cause(),
            "ticks": self.ticks,
            "sources": {
                s.name: {
                    "step": s.step,
                    "bound_N": float(s.bound_N.max()),
                    "rms_N": float(s.rms_N.max()),
                    "terms_bound_N": s.terms,
                }
                for s in self.sources
            },
        }


def _term_matrices(gains: PidGains, T: float) -> dict:
    """{term: (Cc (1, 5), Dc (1, 2))}: the part of the PID's command from each term (their sum is
    ``controller_matrices``' C and D)."""
    zero = PidGains(
        kp=0.0, ki=0.0, kd=0.0, kv=0.0,
        derivative_filter=gains.derivative_filter, feedforward_filter=gains.feedforward_filter,
    )  # fmt: skip
    _, _, C0, D0 = controller_matrices(zero, T)  # the integrator's output alone
    out = {"I": (C0, D0)}
    for term, name in (("P", "kp"), ("D", "kd"), ("V", "kv")):
        _, _, C, D = controller_matrices(PidGains(**{**zero.__dict__, name: getattr(gains, name)}), T)
        out[term] = (C - C0, D - D0)
    return out


def quantisation_ripple(model: LoopModel, length_lsb: float, sensor_resolution: float, command_range: float) -> Ripple:
    """The ripple of ``model``'s loop (the fixed law's effective gains) from the set-point word of
    ``length_lsb`` m, a sensor count of ``sensor_resolution`` m and a Q15 command word over ±``command_range``
    N (see the module docstring)."""
    _, Ga, Cp = model.plant
    I6 = np.eye(6)
    _, Bc, _, Dc = (np.kron(X, I6) for X in controller_matrices(model.gains, model.T))
    Z = np.zeros
    # the closed loop's input matrix per source: the set-point's, the measurement's (through the controller's
    # direct term into the plant and into the controller's state), the command's (as the feed-forward's)
    inputs = {
        "length_lsb": model.B[:, :6],
        "sensor": np.vstack([Ga @ Dc[:, 6:], Bc[:, 6:]]),
        "command_word": model.B[:, 6:],
    }
    steps = {"length_lsb": length_lsb, "sensor": sensor_resolution, "command_word": command_range / 32768.0}
    # peak error per step: rounding (half a step) or the command word's truncation (a whole step)
    peak = {"length_lsb": 0.5, "sensor": 0.5, "command_word": 1.0}
    # the command's outputs: the terms', then the command word's own error (its feed-through only)
    outs, feeds = [], {s: [] for s in SOURCES}
    for Ct, Dt in _term_matrices(model.gains, model.T).values():
        Ct, Dt = np.kron(Ct, I6), np.kron(Dt, I6)
        outs.append(np.hstack([Dt[:, 6:] @ Cp, Ct]))
        feeds["length_lsb"].append(Dt[:, :6])
        feeds["sensor"].append(Dt[:, 6:])
        feeds["command_word"].append(Z((6, 6)))
    outs.append(Z((6, len(model.A))))
    feeds["length_lsb"].append(Z((6, 6)))
    feeds["sensor"].append(Z((6, 6)))
    feeds["command_word"].append(I6)
    C_all = np.vstack(outs)  # (30, n): P, I, D, V, word
    B_all = np.hstack([inputs[s] for s in SOURCES])  # (n, 18)
    D_all = np.hstack([np.vstack(feeds[s]) for s in SOURCES])  # (30, 18)
    abs_sum = np.abs(D_all)  # Σ|h_k| per output row and input, the feed-through h_0 first
    total = D_all.reshape(5, 6, 18).sum(axis=0)  # the command: the terms and the word added
    abs_total, sq_total = np.abs(total), total**2
    X = B_all
    start = np.abs(B_all).max()
    ticks = 0
    while ticks < MAX_TICKS:
        H = C_all @ X
        abs_sum += np.abs(H)
        Ht = H.reshape(5, 6, 18).sum(axis=0)
        abs_total += np.abs(Ht)
        sq_total += Ht**2
        X = model.A @ X
        ticks += 1
        if np.abs(X).max() < TAIL * start:
            break
    sources = []
    for k, s in enumerate(SOURCES):
        cols = slice(6 * k, 6 * k + 6)
        e = peak[s] * steps[s]
        terms = {t: float(abs_sum[6 * i : 6 * i + 6, cols].sum(axis=1).max() * e) for i, t in enumerate(TERMS)}
        if s == "command_word":
            terms = {"word": float(abs_sum[24:30, cols].sum(axis=1).max() * e), **terms}
        sources.append(
            RippleSource(
                name=s,
                step=steps[s],
                bound_N=abs_total[:, cols].sum(axis=1) * e,
                rms_N=np.sqrt(sq_total[:, cols].sum(axis=1)) * steps[s] / math.sqrt(12.0),
                terms=terms,
            )
        )
    return Ripple(tuple(sources), ticks)
