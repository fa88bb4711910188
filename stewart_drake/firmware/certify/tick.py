"""The controller tick certified: proven ranges of the PID words of ``sd_tick`` (``control.FixedPointLaw``,
the same Q15/Q31 intrinsics) for stated bounds on the measured-length error, the leg speed and the
feed-forward, and whether the conditional-integration anti-windup keeps the integrator off its rails.

Every operation of the tick is monotone in each argument (products by positive gain mantissas, shifts,
saturating sums, ``extract_h``), so each word's exact hull is the operation at its arguments' ends. The two
filters and the integrator are states: their ranges are invariants, found by iterating the exact endpoint
map from ``sd_init``'s zeros to a fixed point (filters), and for the integrator the smallest level J such
that an integrator within one increment of J with a positive error must find the command on its upper rail
(so conditional integration stops it), and symmetrically below. Without such a level the integrator is
bounded only by its saturating adds (no wrap: every operation saturates; windup is not excluded).

"Saturation" means what it means for ``sd_ik``: an operation whose exact result does not fit its word and is
clamped. The integrator and the command (its Q31 sum and the Q15 word) have rails by design: the command's clamp
is the actuator's limit and conditional integration's trigger, so their reaching a rail is reported
(``rail: true``, and ``anti_windup_proven``) but is not a saturation of the arithmetic; any other word that may
clamp makes ``saturation_possible`` true (the error, a difference or a gain product does not fit its word: the
tick computes something other than the law for inputs within the stated bounds)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from stewart_drake.control.gains import DIFF_SHIFT, ControllerConfig, FixedGains, counts_per_lsb
from stewart_drake.fixedpoint import q15

FILTER_ITERATIONS = 100_000


@dataclass
class TickWord:
    """One word of the tick: its proven range and whether a saturation may clamp it."""

    name: str
    min: int
    max: int
    bits: int
    saturation: str
    rail: bool = False  # a designed limit (integrator, command): reaching it is not a saturation of the arithmetic

    @property
    def headroom_bits(self) -> float:
        mag = max(abs(self.min), abs(self.max), 1)
        return round(float(np.log2(2.0 ** (self.bits - 1) / mag)), 2)

    def to_dict(self) -> dict:
        return {
            "name": self.name,
            "min": self.min,
            "max": self.max,
            "headroom_bits": self.headroom_bits,
            "saturation": self.saturation,
            "rail": self.rail,
        }


@dataclass
class TickCertificate:
    """Ranges of the tick's words for the stated input bounds; ``anti_windup``: the integrator is proven
    to stay strictly inside its rails."""

    max_error_m: float
    max_speed_mps: float
    max_feedforward_n: float
    words: list[TickWord] = field(default_factory=list)
    anti_windup: bool = False

    @property
    def saturation_possible(self) -> bool:
        """Whether a word of the arithmetic (not a rail) may saturate for inputs within the bounds."""
        return any(w.saturation != "impossible" and not w.rail for w in self.words)

    def to_dict(self) -> dict:
        return {
            "saturation_possible": self.saturation_possible,
            "max_error_mm": self.max_error_m * 1e3,
            "max_speed_mps": self.max_speed_mps,
            "max_feedforward_n": self.max_feedforward_n,
            "anti_windup_proven": self.anti_windup,
            "no_wrap": True,  # every operation of sd_tick saturates (ETSI intrinsics); casts follow a saturation
            "words": [w.to_dict() for w in self.words],
        }


def _i(x) -> int:
    return int(np.asarray(x))


def _shifted(mant: int, shift: int, x: int) -> tuple[int, bool]:
    """sat32(L_mult(mant, x) << shift) and whether it clamped."""
    raw = 2 * mant * x * (1 << shift)
    return _i(q15.sat32(raw)), not (q15.MIN32 <= raw <= q15.MAX32)


def _filter_range(alpha: int, d_lo: int, d_hi: int) -> tuple[int, int, bool]:
    """Invariant range of f <- add(f, mult_r(alpha, sub(d, f))) from f = 0 with d in [d_lo, d_hi], and whether
    an operation of the step may clamp there (each is monotone: its extremes are at the ranges' ends)."""

    def step(f, d):
        return _i(q15.add(f, q15.mult_r(alpha, q15.sub(d, f))))

    lo = hi = 0
    for _ in range(FILTER_ITERATIONS):
        nlo, nhi = min(lo, step(lo, d_lo)), max(hi, step(hi, d_hi))
        if (nlo, nhi) == (lo, hi):
            break
        lo, hi = nlo, nhi
    else:
        return q15.MIN16, q15.MAX16, True  # not converged: the word's own range (sound)
    diff = (d_lo - hi, d_hi - lo)  # the exact sub(d, f) over the ranges
    sums = [f + _i(q15.mult_r(alpha, q15.sat16(d - f))) for f, d in ((lo, d_lo), (hi, d_hi))]  # the exact add
    clamp = min(*diff, *sums) < q15.MIN16 or max(*diff, *sums) > q15.MAX16
    return lo, hi, clamp


def _u32(P, integ, D, V, ff):
    """The command sum as ``sd_tick`` forms it (saturating at each step; monotone in every argument)."""
    return q15.L_add(q15.L_add(q15.L_sub(q15.L_add(P, integ), D), V), q15.L_deposit_h(ff))


def certify_tick(
    config: ControllerConfig, max_error_m: float, max_speed_mps: float, max_feedforward_n: float
) -> TickCertificate:
    """Ranges of the tick's words when |set-point − measured| <= ``max_error_m``, every leg (and its
    set-point) moves at most ``max_speed_mps``, and |feed-forward| <= ``max_feedforward_n``."""
    t = config.timing
    g = FixedGains.from_si(config.gains, t)
    cpl = counts_per_lsb(config)
    status = {}

    def word(name, lo, hi, bits, clamp, rail=False):
        status[name] = TickWord(name, int(lo), int(hi), bits, "possible" if clamp else "impossible", rail)

    E = math.ceil(max_error_m / t.sensor_resolution)
    e_lo, e_hi = max(-E, q15.MIN16), min(E, q15.MAX16)
    word("error e (counts)", e_lo, e_hi, 16, E > q15.MAX16)
    moving = 1 if max_speed_mps > 0 else 0  # one count / LSB more: the rounding of two readings or set-points
    dm = math.ceil(max_speed_mps * t.sample_period / t.sensor_resolution) + moving
    dm_w = _i(q15.sat16(q15.sat16(dm) << DIFF_SHIFT))
    word("measurement difference", -dm_w, dm_w, 16, dm > q15.MAX16 or dm << DIFF_SHIFT > q15.MAX16)
    ds = (math.ceil(max_speed_mps * t.sample_period / config.ik_format.length_lsb) + moving) * cpl
    ds_w = _i(q15.sat16(q15.sat16(ds) << DIFF_SHIFT))
    word("set-point difference", -ds_w, ds_w, 16, ds > q15.MAX16 or ds << DIFF_SHIFT > q15.MAX16)
    *df, df_clamp = _filter_range(g.alpha, -dm_w, dm_w)
    *vf, vf_clamp = _filter_range(g.alpha_ff, -ds_w, ds_w)
    word("derivative filter", *df, 16, df_clamp)
    word("set-point velocity filter", *vf, 16, vf_clamp)
    P = [_shifted(g.kp.mantissa, g.kp.shift, x) for x in (e_lo, e_hi)]
    D = [_shifted(g.kd.mantissa, g.kd.shift, x) for x in df]
    V = [_shifted(g.kv.mantissa, g.kv.shift, x) for x in vf]
    dI = [_shifted(g.ki.mantissa, g.ki.shift, x) for x in (e_lo, e_hi)]
    word("P (Q31)", P[0][0], P[1][0], 32, P[0][1] or P[1][1])
    word("D (Q31)", D[0][0], D[1][0], 32, D[0][1] or D[1][1])
    word("V (Q31)", V[0][0], V[1][0], 32, V[0][1] or V[1][1])
    word("integrator increment (Q31)", dI[0][0], dI[1][0], 32, dI[0][1] or dI[1][1])
    F = _i(q15.sat16(round(max_feedforward_n / t.command_range * 32768.0)))
    word("feed-forward (Q15)", -F, F, 16, max_feedforward_n / t.command_range * 32768.0 > q15.MAX16)

    # integrator: the smallest J >= 0 such that, for every positive error e of a tick, an integrator in
    # (J - dI(e), J] finds the command on its upper rail at that e (so conditional integration holds it)
    e_pos = np.arange(1, e_hi + 1, dtype=np.int64)
    e_neg = np.arange(e_lo, 0, dtype=np.int64)

    def gain_words(k, e):
        return q15.sat32(q15.L_mult(k.mantissa, e) << k.shift)

    def blocked_up(J: int) -> bool:
        if e_pos.size == 0:
            return True
        low = np.maximum(J - gain_words(g.ki, e_pos) + 1, q15.MIN32)
        return bool(np.all(_u32(gain_words(g.kp, e_pos), low, D[1][0], V[0][0], -F) >= q15.MAX32))

    def blocked_down(J: int) -> bool:
        if e_neg.size == 0:
            return True
        high = np.minimum(J - gain_words(g.ki, e_neg) - 1, q15.MAX32)
        return bool(np.all(_u32(gain_words(g.kp, e_neg), high, D[0][0], V[1][0], F) <= q15.MIN32))

    J_hi = _bisect(blocked_up, 0, q15.MAX32, up=True)
    J_lo = _bisect(blocked_down, q15.MIN32, 0, up=False)
    proven = J_hi is not None and J_lo is not None
    I_lo = q15.MIN32 if J_lo is None else J_lo
    I_hi = q15.MAX32 if J_hi is None else J_hi
    word("integrator (Q31)", I_lo, I_hi, 32, not proven, rail=True)
    u_lo = _i(_u32(P[0][0], I_lo, D[1][0], V[0][0], -F))
    u_hi = _i(_u32(P[1][0], I_hi, D[0][0], V[1][0], F))
    word("command sum u32 (Q31)", u_lo, u_hi, 32, u_hi >= q15.MAX32 or u_lo <= q15.MIN32, rail=True)
    word("command (Q15)", u_lo >> 16, u_hi >> 16, 16, u_hi >= q15.MAX32 or u_lo <= q15.MIN32, rail=True)
    return TickCertificate(max_error_m, max_speed_mps, max_feedforward_n, list(status.values()), proven)


def _bisect(ok, lo: int, hi: int, up: bool) -> int | None:
    """The level nearest 0 in [lo, hi] where the monotone test ``ok`` holds (None: nowhere)."""
    if up:
        if not ok(hi):
            return None
        while lo < hi:
            mid = (lo + hi) // 2
            if ok(mid):
                hi = mid
            else:
                lo = mid + 1
        return lo
    if not ok(lo):
        return None
    while lo < hi:
        mid = (lo + hi + 1) // 2
        if ok(mid):
            lo = mid
        else:
            hi = mid - 1
    return hi
