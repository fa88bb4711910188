"""C generation: a self-contained C99 firmware module for any platform — the fixed-point IK of
``fixedpoint.generic`` and the controller tick of ``control.FixedPointLaw`` (PID, feed-forward word,
saturation, anti-windup) with the designed gains — bit-identical to the emulation.

ABI (``sd_firmware.h``; ``sd_word`` is ``int16_t``: word_bits 8..16)::

    int  sd_ik(const sd_word pose[6], sd_word lengths[6]);     /* returns the saturation count */
    void sd_init(sd_state *s);
    int  sd_tick(sd_state *s, const sd_word pose[6], const sd_count measured[6],
                 const int16_t feedforward[6], int16_t command[6]); /* returns saturated legs */
    int  sd_ik_trace(const sd_word pose[6], int32_t trace[SD_TRACE_WORDS]);  /* every intermediate word */

Pose words: positions in length LSBs, angles as Q(word_bits-1) fractions of pi; lengths in length LSBs;
``measured`` in sensor counts (``sd_count`` = ``int32_t``: at 10 µm per count a 16-bit word would only
reach 0.33 m); ``feedforward`` and ``command`` Q15 fractions of the command range (``feedforward`` may be
NULL: no feed-forward). Every constant is computed here, at generation time; the C has no floating point.

The op counts of the emitted code are known statically (``GeneratedFirmware.ik_ops`` / ``tick_ops``,
names of ``fixedpoint.cycles.CYCLE_TABLE``) and give the cycle estimates in the README; the instrumented
build (``-DSD_COUNT_OPS``) counts the same operations as they execute.
"""

from __future__ import annotations

import hashlib
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from stewart_drake.control.gains import DIFF_SHIFT, ControllerConfig, FixedGains, counts_per_lsb
from stewart_drake.control.laws import check_no_sensor_gains
from stewart_drake.control.timing import FEEDFORWARD_OPS_PER_LEG, ISR_OVERHEAD_CYCLES, PID_OPS_PER_LEG
from stewart_drake.core.geometry import Platform
from stewart_drake.errors import FirmwareError
from stewart_drake.firmware.fk_gen import fk_ops, fk_prototype, fk_readme, fk_source
from stewart_drake.fixedpoint.cycles import CYCLE_TABLE, CycleEstimate, estimate_cycles
from stewart_drake.fixedpoint.generic import QFormat, platform_words, rotation_monomials, trig_words

# Operation names the generated code counts (the instrumented build's order).
OPS = (
    "add",
    "sub",
    "negate",
    "mult",
    "L_mult",
    "L_add",
    "L_sub",
    "L_shl",
    "shl",
    "mult_r",
    "extract_h",
    "L_deposit_h",
    "mfr32Sqrt",
    "tfr16SinPIx",
    "tfr16CosPIx",
    "table",
    "div_s",  # sd_fk's divisions (firmware.fk_gen)
)
# cycles of a quarter-wave table look-up (fold, index, load, sign): exact trig only
TABLE_CYCLES = 6.0
# trace layout of sd_ik_trace (int32 words)
TRACE_FIELDS = (("pose", 6), ("sin", 3), ("cos", 3), ("R", 9), ("leg", 18), ("sq", 6), ("lengths", 6))
TRACE_WORDS = sum(n for _, n in TRACE_FIELDS)
TRACE_AT = {name: sum(n for _, n in TRACE_FIELDS[:k]) for k, (name, _) in enumerate(TRACE_FIELDS)}
FILES = ("sd_firmware.h", "sd_firmware.c", "README.md")
# the gain words of the host build's table ``sd_gains``, in its order (the target's constants of the same names)
GAIN_WORDS = ("KP_M", "KP_S", "KI_M", "KI_S", "KD_M", "KD_S", "KV_M", "KV_S", "ALPHA", "ALPHA_FF")


@dataclass
class GeneratedFirmware:
    """The generated module: ``files`` name -> text, the static op counts of one ``sd_ik`` and of one
    ``sd_tick`` beyond its IK (``ik_ops``, ``tick_ops``), and the cycle estimates.

    ``host_files``: the C the host compiles (``firmware.module``): ``files``' C with the gains read from the
    table ``sd_gains`` (the words ``gain_words``, in the order of ``GAIN_WORDS``) instead of compile-time
    constants, and the header without the controller's rate. Firmware that differs only in its gains (the
    Monte Carlo's runs, a period sweep) has the same ``host_files``: one compiled library serves them all."""

    platform: str
    fmt: QFormat
    convention: str
    config: ControllerConfig
    files: dict = field(default_factory=dict)
    host_files: dict = field(default_factory=dict)
    gain_words: tuple[int, ...] = ()
    ik_ops: Counter = field(default_factory=Counter)
    tick_ops: Counter = field(default_factory=Counter)
    fk_ops: Counter = field(default_factory=Counter)  # one sd_fk (firmware.fk_gen)

    @property
    def ik_cycles(self) -> CycleEstimate:
        return estimate_cycles(self.ik_ops, _cycle_table())

    @property
    def fk_cycles(self) -> CycleEstimate:
        """Cycles of one ``sd_fk`` (its iterations unrolled in the count: one loop overhead)."""
        return estimate_cycles(self.fk_ops, _cycle_table())

    @property
    def tick_cycles(self) -> float:
        """Cycles of one controller tick: IK + PIDs with feed-forward + ISR overhead."""
        return (
            self.ik_cycles.cycles + estimate_cycles(self.tick_ops, _cycle_table(), loops=0).cycles + ISR_OVERHEAD_CYCLES
        )

    @property
    def digest(self) -> str:
        h = hashlib.sha256()
        for k in sorted(self.files):
            h.update(k.encode() + b"\0" + self.files[k].encode())
        return h.hexdigest()

    def write(self, out: Path) -> list[Path]:
        """Write the files into the folder ``out`` (created); returns their paths."""
        out.mkdir(parents=True, exist_ok=True)
        paths = []
        for name, text in self.files.items():
            (out / name).write_text(text)
            paths.append(out / name)
        return paths


def _cycle_table() -> dict:
    t = dict(CYCLE_TABLE)
    t["table"] = TABLE_CYCLES
    return t


class _Emitter:
    """Straight-line C for the IK with a static count of the operations it emits."""

    def __init__(self):
        self.lines: list[str] = []
        self.ops: Counter = Counter()
        self.tmp = 0

    def op(self, name: str, n: int = 1) -> None:
        self.ops[name] += n

    def emit(self, line: str) -> None:
        self.lines.append("    " + line)


def _c_int(v: int) -> str:
    v = int(v)
    if v == -(2**31):
        return "(-2147483647L - 1L)"
    return f"{v}L" if abs(v) > 32767 else str(v)


def generate(platform: Platform, config: ControllerConfig) -> GeneratedFirmware:
    """The firmware module for ``platform`` with ``config`` (its ``ik_format``, ``convention``, timing and
    gains). Raises ValueError if the format cannot be generated (exact trig beyond 16-bit words, a
    sensor resolution that does not divide the length LSB, a platform that does not fit the words)."""
    fmt, conv = config.ik_format, config.convention
    check_no_sensor_gains(platform)
    if fmt.word_bits > 16:
        raise FirmwareError(FirmwareError.WORD_BITS.format(value=fmt.word_bits))
    cpl = counts_per_lsb(config)
    gains = FixedGains.from_si(config.gains, config.timing)
    r_T, B = platform_words(platform, fmt)
    f = fmt.frac_bits
    lo, hi = -(1 << f), (1 << f) - 1
    acc_hi = (1 << (2 * fmt.word_bits - 1)) - 1

    e = _Emitter()
    # -- trig
    names = ("x", "y", "z")
    for k, ax in enumerate(names):
        if fmt.trig == "tfr16":
            e.emit(f"s{ax} = tfr16_sin((int32_t)pose[{3 + k}]);")
            e.emit(f"c{ax} = tfr16_cos((int32_t)pose[{3 + k}]);")
            e.op("tfr16SinPIx")
            e.op("tfr16CosPIx")
        else:
            e.emit(f"s{ax} = table_sin((int32_t)pose[{3 + k}]);")
            e.emit(f"c{ax} = table_cos((int32_t)pose[{3 + k}]);")
            e.op("table", 2)
    # -- rotation entries as the emulation forms them (rotation_from_words)
    mono = rotation_monomials(conv)
    for i in range(3):
        for j in range(3):
            target = f"R{i}{j}"
            first = True
            for factors, coef in mono[i][j].items():
                if not factors:
                    term = str(hi)
                else:
                    term = factors[0]
                    for fac in factors[1:]:
                        term = f"mulq({term}, {fac}, &nsat)"
                        e.op("mult")
                for _ in range(abs(coef)):
                    if first:
                        if coef > 0:
                            e.emit(f"{target} = {term};")
                        else:
                            e.emit(f"{target} = negw({term}, &nsat);")
                            e.op("negate")
                        first = False
                    else:
                        fn = "addw" if coef > 0 else "subw"
                        e.emit(f"{target} = {fn}({target}, {term}, &nsat);")
                        e.op("add" if coef > 0 else "sub")
            if first:
                e.emit(f"{target} = 0;")
    e.emit(
        "if (trace) { "
        + " ".join(f"trace[{TRACE_AT['R'] + 3 * i + j}] = R{i}{j};" for i in range(3) for j in range(3))
        + " }"
    )
    # -- legs
    for i in range(6):
        e.emit(
            f"/* leg {i + 1}: plate anchor offset ({', '.join(str(int(v)) for v in r_T[i])}), base anchor ({', '.join(str(int(v)) for v in B[i])}) LSB */"
        )
        e.emit("sq = 0;")
        for r in range(3):
            e.emit(f"v = pose[{r}];")
            for k in range(3):
                if r_T[i, k]:
                    e.emit(f"v = addw(v, mulr(R{r}{k}, {_c_int(r_T[i, k])}), &nsat);")
                    e.op("mult")
                    e.op("add")
            if B[i, r]:
                e.emit(f"v = subw(v, {_c_int(B[i, r])}, &nsat);")
                e.op("sub")
            e.emit(f"if (trace) trace[{TRACE_AT['leg'] + 3 * i + r}] = (int32_t)v;")
            e.emit("sq = sqacc(sq, v, &nsat);")
            e.op("L_mult")
            e.op("L_add")
        e.emit(f"if (trace) trace[{TRACE_AT['sq'] + i}] = (int32_t)(sq > 2147483647L ? 2147483647L : sq);")
        e.emit(f"S[{i}] = sq;")
        e.op("mfr32Sqrt")
    e.emit("isqrt_near6(S, lengths, &nsat);")
    ik_ops = Counter(e.ops)

    # trig table
    table = ""
    if fmt.trig == "exact":
        H = 1 << (f - 1)
        k = np.arange(H + 1)
        U = np.round(np.sin(np.pi * k / (1 << f)) * (1 << f)).astype(np.int64)
        _verify_table(U, fmt)
        rows = [", ".join(str(int(v)) for v in U[a : a + 16]) for a in range(0, H + 1, 16)]
        ttype = "uint16_t" if f <= 15 else "uint32_t"
        table = (
            f"/* U[k] = round(2^{f} sin(pi k / 2^{f})), k = 0..2^{f - 1}, unsaturated (verified at generation against\n"
            f"   the emulation on all {2**fmt.word_bits} angle words) */\nstatic const {ttype} SIN_TABLE[{H + 1}] = {{\n    "
            + ",\n    ".join(rows)
            + "\n};\n"
        )

    # the controller tick's operations beyond the IK: the cycle model's (control.PID_OPS_PER_LEG and
    # FEEDFORWARD_OPS_PER_LEG, six legs); the emitted sd_tick below performs exactly these (a test counts them)
    tick_ops = Counter()
    for ops in (PID_OPS_PER_LEG, FEEDFORWARD_OPS_PER_LEG):
        for k, v in ops.items():
            tick_ops[k] += 6 * v

    g = GeneratedFirmware(platform.name, fmt, conv, config, ik_ops=ik_ops, tick_ops=tick_ops)
    ctx = dict(
        name=platform.name,
        wb=fmt.word_bits,
        f=f,
        lo=lo,
        hi=hi,
        lsb=fmt.length_lsb,
        trig=fmt.trig,
        conv=conv,
        word="int16_t",
        acc_hi=acc_hi,
        acc_lo=-acc_hi - 1,
        cpl=cpl,
        diff_shift=DIFF_SHIFT,
        kp=gains.kp,
        ki=gains.ki,
        kd=gains.kd,
        kv=gains.kv,
        alpha=gains.alpha,
        alpha_ff=gains.alpha_ff,
        T=config.timing.sample_period,
        res=config.timing.sensor_resolution,
        rng=config.timing.command_range,
        sqrt_bits=fmt.word_bits,
        trace_words=TRACE_WORDS,
        ops=OPS,
        at_sin=TRACE_AT["sin"],
        at_cos=TRACE_AT["cos"],
        at_len=TRACE_AT["lengths"],
        **offset_context(platform, config),
    )
    # sd_fk (firmware.fk_gen): appended, so the IK and tick above are unchanged
    end = "\n#endif /* SD_FIRMWARE_H */"
    fk = fk_source(platform, config, TRACE_AT)
    for files, host in ((g.files, False), (g.host_files, True)):
        files["sd_firmware.h"] = _header(ctx, config, host).replace(end, "\n" + fk_prototype() + end, 1)
        files["sd_firmware.c"] = _source(ctx, e.lines, table, host) + fk
    g.gain_words = _gain_words(gains)
    g.files["README.md"] = _readme(ctx, g, config, r_T, B)
    g.fk_ops = fk_ops(ik_ops)
    g.files["README.md"] += fk_readme(g.fk_cycles, config.timing.clock_hz)
    return g


def offset_counts(platform: Platform, config: ControllerConfig) -> np.ndarray:
    """``(6,)`` int64 ``legs.length_offset`` in sensor counts, rounded to nearest (the firmware adds them to
    the readings: joint-to-joint length = reading + offset; within half a count of the file's values)."""
    return np.round(platform.length_offset / config.timing.sensor_resolution).astype(np.int64)


def offset_context(platform: Platform, config: ControllerConfig) -> dict:
    """The C of the sensor offsets: a constant table and ``measured[i] + SD_LENGTH_OFFSET[i]`` when any is
    non-zero; a platform without offsets generates the code it always did."""
    off = offset_counts(platform, config)
    if not np.any(off):
        return {"offset_table": "", "measured": "measured[i]"}
    table = (
        "/* legs.length_offset in sensor counts (calibration): joint-to-joint length = reading + offset */\n"
        f"static const int32_t SD_LENGTH_OFFSET[6] = {{{', '.join(str(int(v)) for v in off)}}};\n"
    )
    return {"offset_table": table, "measured": "(int64_t)measured[i] + SD_LENGTH_OFFSET[i]"}


def _verify_table(U: np.ndarray, fmt: QFormat) -> None:
    """The quarter-wave folding must give the emulation's sine and cosine on every angle word."""
    f = fmt.frac_bits
    H = 1 << (f - 1)
    lo, hi = -(1 << f), (1 << f) - 1
    w = np.arange(lo, hi + 1)
    s, c = trig_words(w, fmt)
    a = np.abs(w)
    ss = np.clip(np.sign(w) * U[np.where(a > H, (1 << f) - a, a)], lo, hi)
    cc = np.clip(np.where(a <= H, U[np.clip(H - a, 0, H)], -U[np.clip(a - H, 0, H)]), lo, hi)
    if np.any(ss != s) or np.any(cc != c):
        bad = int(w[np.flatnonzero((ss != s) | (cc != c))[0]])
        raise FirmwareError(FirmwareError.SINE_TABLE.format(index=bad))


def _header(c: dict, config: ControllerConfig, host: bool = False) -> str:
    """The firmware's header; ``host``: without the controller's rate (the host build's gains are a table)."""
    rate = "with the gains its host sets" if host else f"at {1 / c['T']:g} Hz"
    return f"""/* sd_firmware.h -- generated by `stewart-drake firmware generate` for platform {c["name"]!r}; do not edit.
 * Fixed-point IK ({c["wb"]}-bit words, length LSB {c["lsb"]:g} m, trig {c["trig"]}, convention {c["conv"]}) and the
 * controller tick (PID + feed-forward word + saturation + anti-windup) {rate}. C99, no floating point.
 * Bit-identical to stewart_drake.fixedpoint.generic / stewart_drake.control.laws (FixedPointLaw). See README.md. */
#ifndef SD_FIRMWARE_H
#define SD_FIRMWARE_H

#include <stdint.h>

typedef {c["word"]} sd_word;   /* a {c["wb"]}-bit data word */
typedef int32_t sd_count;   /* a leg-length sensor reading, counts of {c["res"]:g} m */

#define SD_WORD_BITS {c["wb"]}
#define SD_FRAC_BITS {c["f"]}
#define SD_TRACE_WORDS {c["trace_words"]}

/* The controller's state (sd_init zeroes it; the host may set it to hold a pose). */
typedef struct {{
    int32_t integ[6];     /* integrator, Q31 fraction of the command range */
    sd_count prev[6];     /* previous measurement, counts */
    int16_t dfilt[6];     /* filtered measurement difference, counts * 2^{c["diff_shift"]} */
    sd_word setpoint[6];  /* the set-point of the last tick, length LSBs */
    int16_t vfilt[6];     /* filtered set-point difference, counts * 2^{c["diff_shift"]} */
    int16_t saturated[6]; /* 1 where the last tick's command saturated */
}} sd_state;

/* six leg lengths (length LSBs) of a pose (positions in length LSBs, angles Q{c["f"]} fractions of pi);
   returns the number of saturations in the arithmetic (0 on a geometric pose) */
int sd_ik(const sd_word pose[6], sd_word lengths[6]);
/* sd_ik that also writes every intermediate word: pose 6, sin 3, cos 3, R 9 (row-major, Q{c["f"]}),
   leg vectors 18 (LSB), squared lengths 6 (capped at 2^31 - 1), lengths 6 */
int sd_ik_trace(const sd_word pose[6], int32_t trace[SD_TRACE_WORDS]);
void sd_init(sd_state *s);
/* one controller tick: set-points from the pose, PID per leg, Q15 commands; feedforward may be NULL.
   Returns the number of legs whose command saturated. */
int sd_tick(sd_state *s, const sd_word pose[6], const sd_count measured[6], const int16_t feedforward[6], int16_t command[6]);

#ifdef SD_COUNT_OPS
/* instrumented build: operations executed, in the order of SD_OP_NAMES */
#define SD_OP_N {len(c["ops"])}
#define SD_OP_NAMES "{" ".join(c["ops"])}"
extern long sd_op_counts[SD_OP_N];
#endif

#endif /* SD_FIRMWARE_H */
"""


TFR16 = """/* Motorola tfr16.c sin(pi x), cos(pi x) of a Q15 word (7-term polynomial, Horner with mac_r) */
static int32_t s16(int64_t x) { return x > 32767 ? 32767 : x < -32768 ? -32768 : (int32_t)x; }
static int32_t s32(int64_t x) { return x > 2147483647L ? (int32_t)2147483647L : x < (-2147483647L - 1L) ? (int32_t)(-2147483647L - 1L) : (int32_t)x; }
static const int32_t SINE_COEF[7] = {12867, -21166, 10445, -2440, 336, -30, 1}; /* FRAC16(c_k / 8) */
static int32_t horner(int32_t c, int32_t a, int32_t b)
{
    return (int32_t)asr(s32((int64_t)s32((int64_t)c * 65536 + s32(2 * (int64_t)a * b)) + 0x8000), 16);
}
static int32_t tfr16_sin(int32_t x)
{
    int32_t z, t, r;
    int64_t acc;
    int i, sign = 0;
    SD_OP(SD_tfr16SinPIx);
    if (x < 0) { sign = 1; x = s16(-(int64_t)x); }
    if (x > 16384) x = s16(32767 - (int64_t)x);
    z = s16(asr((int64_t)x * x + 0x4000, 15));
    t = horner(SINE_COEF[5], z, SINE_COEF[6]);
    for (i = 4; i >= 0; i--) t = horner(SINE_COEF[i], t, z);
    acc = s32(2 * (int64_t)t * x);
    acc = s32(acc * 8);
    r = (int32_t)asr(s32(acc + 0x8000), 16);
    return sign ? s16(-(int64_t)r) : r;
}
static int32_t tfr16_cos(int32_t x)
{
    int32_t z;
    int sign = 0;
    SD_OP(SD_tfr16CosPIx);
    if (x < 0) x = s16(-(int64_t)x);
    if (x > 16384) { x = s16(32767 - (int64_t)x); sign = 1; }
    x = s16(16384 - (int64_t)x);
    if (sign) x = s16((int64_t)x + 1);
#ifdef SD_COUNT_OPS
    sd_op_counts[SD_tfr16SinPIx]--; /* the inner sine is part of CosPIx's cost */
#endif
    z = tfr16_sin(x);
    return sign ? s16(-(int64_t)z) : z;
}
"""

TABLE_TRIG = """/* 1.0 (sin pi/2, cos 0) is stored as the word's top, 2^f - 1: the table's rounding, not a saturation (not counted) */
static int32_t table_top(int64_t v) { return (int32_t)(v > SD_HI ? SD_HI : v); }
static int32_t table_sin(int32_t w)
{
    int32_t a = w < 0 ? -w : w;
    int64_t v;
    SD_OP(SD_table);
    if (a > SD_HALF) a = (SD_HI + 1) - a;
    v = (int64_t)SIN_TABLE[a];
    return table_top(w < 0 ? -v : v);
}
static int32_t table_cos(int32_t w)
{
    int32_t a = w < 0 ? -w : w;
    int64_t v = a <= SD_HALF ? (int64_t)SIN_TABLE[SD_HALF - a] : -(int64_t)SIN_TABLE[a - SD_HALF];
    SD_OP(SD_table);
    return table_top(v);
}
"""


def _gains_block(c: dict) -> str:
    """The target's gains: compile-time constants."""
    kp, ki, kd, kv = c["kp"], c["ki"], c["kd"], c["kv"]
    return f"""/* gains (generation time): kp {kp.mantissa}/2^15 << {kp.shift}, ki {ki.mantissa}/2^15 << {ki.shift} (per tick),
   kd {kd.mantissa}/2^15 << {kd.shift}, kv {kv.mantissa}/2^15 << {kv.shift} (per tick, on differences * 2^{c["diff_shift"]}) */
#define KP_M {kp.mantissa}
#define KP_S {kp.shift}
#define KI_M {ki.mantissa}
#define KI_S {ki.shift}
#define KD_M {kd.mantissa}
#define KD_S {kd.shift}
#define KV_M {kv.mantissa}
#define KV_S {kv.shift}
#define ALPHA {c["alpha"]}
#define ALPHA_FF {c["alpha_ff"]}"""


def _host_gains_block() -> str:
    """The host build's gains: the words of ``GAIN_WORDS`` read from ``sd_gains``, which the loader fills."""
    lines = "\n".join(f"#define {name} sd_gains[{k}]" for k, name in enumerate(GAIN_WORDS))
    return f"""/* gains: set by the host's loader before the first tick (the host build: firmware that differs only in its
   gains shares one library) */
int32_t sd_gains[{len(GAIN_WORDS)}];
{lines}"""


def _gain_words(g: FixedGains) -> tuple[int, ...]:
    """The words of ``GAIN_WORDS`` for the gains ``g``: what the host build reads from ``sd_gains``."""
    return (*(w for k in (g.kp, g.ki, g.kd, g.kv) for w in (k.mantissa, k.shift)), g.alpha, g.alpha_ff)


def _source(c: dict, ik_lines: list[str], table: str, host: bool = False) -> str:
    """The firmware's C: its gains compile-time constants, or (``host``) read from ``sd_gains``."""
    enum = ", ".join(f"SD_{n}" for n in c["ops"])
    trig = TFR16 if c["trig"] == "tfr16" else TABLE_TRIG
    return f"""/* sd_firmware.c -- generated by `stewart-drake firmware generate` for platform {c["name"]!r}; do not edit.
 * The fixed-point IK of stewart_drake.fixedpoint.generic, operation by operation, and the controller tick
 * of stewart_drake.control.laws (FixedPointLaw), with every constant computed at generation time. */
#include "sd_firmware.h"

enum {{ {enum} }};
#ifdef SD_COUNT_OPS
long sd_op_counts[SD_OP_N];
#define SD_OP(k) (sd_op_counts[k]++)
#else
#define SD_OP(k) ((void)0)
#endif

#define SD_LO ({c["lo"]}L)
#define SD_HI {c["hi"]}L
#define SD_HALF {c["hi"] // 2 + 1}L
#define SD_ACC_LO ({c["acc_lo"]}LL)
#define SD_ACC_HI {c["acc_hi"]}LL

/* floor(x / 2^n): the arithmetic right shift without implementation-defined behaviour */
static int64_t asr(int64_t x, int n) {{ return x >= 0 ? (x >> n) : (-((-(x + 1)) >> n) - 1); }}
static int32_t satw(int64_t x, int *nsat)
{{
    if (x > SD_HI) {{ ++*nsat; return (int32_t)SD_HI; }}
    if (x < SD_LO) {{ ++*nsat; return (int32_t)SD_LO; }}
    return (int32_t)x;
}}
/* Q{c["f"]} product truncated toward -inf, saturated (the extract_h(L_mult) idiom) */
static int32_t mulq(int32_t a, int32_t b, int *nsat) {{ SD_OP(SD_mult); return satw(asr((int64_t)a * b, {c["f"]}), nsat); }}
/* the same product, unsaturated (the sum it feeds saturates) */
static int64_t mulr(int32_t a, int64_t b) {{ SD_OP(SD_mult); return asr((int64_t)a * b, {c["f"]}); }}
static int32_t addw(int64_t a, int64_t b, int *nsat) {{ SD_OP(SD_add); return satw(a + b, nsat); }}
static int32_t subw(int64_t a, int64_t b, int *nsat) {{ SD_OP(SD_sub); return satw(a - b, nsat); }}
static int32_t negw(int64_t a, int *nsat) {{ SD_OP(SD_negate); return satw(-a, nsat); }}
/* sq + v^2 in the {2 * c["wb"]}-bit accumulator, saturating */
static int64_t sqacc(int64_t sq, int64_t v, int *nsat)
{{
    int64_t x = sq + v * v;
    SD_OP(SD_L_mult);
    SD_OP(SD_L_add);
    if (x > SD_ACC_HI) {{ ++*nsat; return SD_ACC_HI; }}
    return x;
}}
/* lengths[i] = the nearer of y, y + 1 to sqrt(S[i]) (y the largest with y^2 <= S[i]: a {c["sqrt_bits"]}-step bit search,
   skipping the trial bits above the largest root, which stay 0), saturated to the word; the six searches
   run side by side (independent: the same results, scheduled in parallel). S[i] < 2^{2 * c["wb"] - 1}: 32-bit words. */
static void isqrt_near6(const int64_t S[6], sd_word lengths[6], int *nsat)
{{
    uint32_t y[6] = {{0, 0, 0, 0, 0, 0}}, s[6];
    int64_t mx = 0;
    int i, k;
    for (i = 0; i < 6; i++) {{
        SD_OP(SD_mfr32Sqrt);
        s[i] = (uint32_t)(S[i] < 0 ? 0 : S[i]);
        if ((int64_t)s[i] > mx) mx = s[i];
    }}
    k = {c["sqrt_bits"] - 1};
    while (k > 0 && ((int64_t)1 << (2 * k)) > mx) k--;
    for (; k >= 0; k--) {{
        for (i = 0; i < 6; i++) {{
            uint32_t t = y[i] | ((uint32_t)1 << k);
            y[i] = t * t <= s[i] ? t : y[i];
        }}
    }}
    for (i = 0; i < 6; i++) {{
        int64_t yy = y[i], dy = (int64_t)s[i] - yy * yy, dr = (yy + 1) * (yy + 1) - (int64_t)s[i];
        lengths[i] = (sd_word)satw(dr < dy ? yy + 1 : yy, nsat);
    }}
}}
{table}{trig}
static inline int ik_core(const sd_word pose[6], sd_word lengths[6], int32_t *trace)
{{
    int nsat = 0;
    int32_t sx, cx, sy, cy, sz, cz;
    int32_t R00, R01, R02, R10, R11, R12, R20, R21, R22;
    int64_t sq, v, S[6];
    if (trace) {{ int k; for (k = 0; k < 6; k++) trace[k] = pose[k]; }}
{chr(10).join(ik_lines)}
    if (trace) {{
        int k;
        trace[{c["at_sin"]}] = sx; trace[{c["at_sin"]} + 1] = sy; trace[{c["at_sin"]} + 2] = sz;
        trace[{c["at_cos"]}] = cx; trace[{c["at_cos"]} + 1] = cy; trace[{c["at_cos"]} + 2] = cz;
        for (k = 0; k < 6; k++) trace[{c["at_len"]} + k] = lengths[k];
    }}
    return nsat;
}}

int sd_ik(const sd_word pose[6], sd_word lengths[6]) {{ return ik_core(pose, lengths, 0); }}
int sd_ik_trace(const sd_word pose[6], int32_t trace[SD_TRACE_WORDS])
{{
    sd_word lengths[6];
    return ik_core(pose, lengths, trace);
}}

/* ---- the controller tick: Q15/Q31 intrinsics (ETSI semantics) ---- */
static int32_t sat16(int64_t x) {{ return x > 32767 ? 32767 : x < -32768 ? -32768 : (int32_t)x; }}
static int32_t sat32(int64_t x) {{ return x > 2147483647L ? (int32_t)2147483647L : x < (-2147483647L - 1L) ? (int32_t)(-2147483647L - 1L) : (int32_t)x; }}
static int32_t i_add(int32_t a, int32_t b) {{ SD_OP(SD_add); return sat16((int64_t)a + b); }}
static int32_t i_sub(int32_t a, int32_t b) {{ SD_OP(SD_sub); return sat16((int64_t)a - b); }}
static int32_t i_sub_l(int64_t a, int64_t b) {{ SD_OP(SD_sub); return sat16(a - b); }} /* a 32-bit difference to a word */
static int64_t i_scale(int64_t a, int32_t k) {{ SD_OP(SD_L_mult); return a * k; }}      /* LSBs to counts (integer mpy) */
static int32_t i_mult_r(int32_t a, int32_t b) {{ SD_OP(SD_mult_r); return sat16(asr((int64_t)a * b + 0x4000, 15)); }}
static int32_t i_shl(int32_t a, int n) {{ SD_OP(SD_shl); return sat16((int64_t)a * ((int64_t)1 << n)); }}
static int32_t i_L_mult(int32_t a, int32_t b) {{ SD_OP(SD_L_mult); return sat32(2 * (int64_t)a * b); }}
static int32_t i_L_shl(int32_t a, int n) {{ SD_OP(SD_L_shl); return sat32((int64_t)a * ((int64_t)1 << n)); }}
static int32_t i_L_add(int32_t a, int32_t b) {{ SD_OP(SD_L_add); return sat32((int64_t)a + b); }}
static int32_t i_L_sub(int32_t a, int32_t b) {{ SD_OP(SD_L_sub); return sat32((int64_t)a - b); }}
static int32_t i_extract_h(int32_t a) {{ SD_OP(SD_extract_h); return (int32_t)asr(a, 16); }}
static int32_t i_L_deposit_h(int32_t a) {{ SD_OP(SD_L_deposit_h); return a * 65536; }}

{_host_gains_block() if host else _gains_block(c)}
#define COUNTS_PER_LSB {c["cpl"]}
#define DIFF_SHIFT {c["diff_shift"]}
{c["offset_table"]}
void sd_init(sd_state *s)
{{
    int i;
    for (i = 0; i < 6; i++) {{
        s->integ[i] = 0; s->prev[i] = 0; s->dfilt[i] = 0; s->setpoint[i] = 0; s->vfilt[i] = 0; s->saturated[i] = 0;
    }}
}}

int sd_tick(sd_state *s, const sd_word pose[6], const sd_count measured[6], const int16_t feedforward[6], int16_t command[6])
{{
    sd_word sp[6];
    int i, nsat = 0;
    sd_ik(pose, sp);
    for (i = 0; i < 6; i++) {{
        int64_t m = {c["measured"]};
        int32_t e = i_sub_l(i_scale(sp[i], COUNTS_PER_LSB), m);                 /* error, counts */
        int32_t dm = i_shl(i_sub_l(m, s->prev[i]), DIFF_SHIFT);                  /* measurement difference */
        int32_t dfilt = i_add(s->dfilt[i], i_mult_r(ALPHA, i_sub(dm, s->dfilt[i])));
        int32_t ds = i_shl(i_sub_l(i_scale((int64_t)sp[i] - s->setpoint[i], COUNTS_PER_LSB), 0), DIFF_SHIFT);
        int32_t vfilt = i_add(s->vfilt[i], i_mult_r(ALPHA_FF, i_sub(ds, s->vfilt[i])));
        int32_t P = i_L_shl(i_L_mult(KP_M, e), KP_S);
        int32_t D = i_L_shl(i_L_mult(KD_M, dfilt), KD_S);
        int32_t V = i_L_shl(i_L_mult(KV_M, vfilt), KV_S);
        int32_t u = i_L_add(i_L_sub(i_L_add(P, s->integ[i]), D), V);
        int32_t dI, grown;
        int hi, lo;
        if (feedforward) u = i_L_add(u, i_L_deposit_h(feedforward[i]));
        hi = u >= 2147483647L;
        lo = u <= (-2147483647L - 1L);
        command[i] = (int16_t)i_extract_h(u);
        dI = i_L_shl(i_L_mult(KI_M, e), KI_S);
        grown = i_L_add(s->integ[i], dI);
        if (!((hi && e > 0) || (lo && e < 0))) s->integ[i] = grown;  /* anti-windup: conditional integration */
        s->saturated[i] = (int16_t)(hi || lo);
        nsat += hi || lo;
        s->prev[i] = (sd_count)m;
        s->dfilt[i] = (int16_t)dfilt;
        s->setpoint[i] = sp[i];
        s->vfilt[i] = (int16_t)vfilt;
    }}
    return nsat;
}}
"""


def _readme(c: dict, g: GeneratedFirmware, config: ControllerConfig, r_T, B) -> str:
    ik = g.ik_cycles
    tick = g.tick_cycles
    clock = config.timing.clock_hz
    ops = ", ".join(f"{k} ×{v}" for k, v in sorted(g.ik_ops.items()))
    tops = ", ".join(f"{k} ×{v}" for k, v in sorted(g.tick_ops.items()))
    gains = config.gains
    return f"""# Firmware module for platform `{c["name"]}`

Generated by `stewart-drake firmware generate`. Files: `sd_firmware.h` (the ABI), `sd_firmware.c` (C99, no
floating point, no library calls). Compile with any C99 compiler, e.g.
`cc -std=c99 -Wall -Wextra -Werror -pedantic -c sd_firmware.c`; `-DSD_COUNT_OPS` builds the instrumented
variant that counts the operations below as they execute.

## Words

| word | type | meaning |
| --- | --- | --- |
| `pose[0..2]` | `sd_word` ({c["wb"]}-bit) | position px, py, pz of the plate's rotation centre in the base frame, in length LSBs of {c["lsb"]:g} m (round to nearest when converting) |
| `pose[3..5]` | `sd_word` | angles a_x, a_y, a_z (convention `{c["conv"]}`) as Q{c["f"]} fractions of π: word = trunc(angle / π · 2^{c["f"]}) |
| `lengths[i]` | `sd_word` | leg i + 1 length in length LSBs ({c["lsb"]:g} m) |
| `measured[i]` | `sd_count` (int32) | leg i + 1 measured length in sensor counts of {c["res"]:g} m |
| `feedforward[i]` | `int16_t` | feed-forward force of leg i + 1, Q15 fraction of the command range {c["rng"]:g} N (NULL: none) |
| `command[i]` | `int16_t` | commanded force of leg i + 1, Q15 fraction of {c["rng"]:g} N |
| `sd_state` | struct | integrator (Q31), previous measurement (counts), filtered differences (counts · 2^{c["diff_shift"]}), last set-point (LSB), saturation flags |

sin/cos: {"the DSP library polynomial (Motorola tfr16.c)" if c["trig"] == "tfr16" else "a quarter-wave table of correctly rounded words"}.
Rotation R = {"Ry(a_y) Rx(a_x) Rz(a_z)" if c["conv"] == "utn" else "Rz(a_z) Ry(a_y) Rx(a_x)"}, each entry a sum of products truncated to Q{c["f"]}.
Constants (length LSBs): plate anchor offsets from the rotation centre {r_T.tolist()}; base anchors {B.tolist()}.

## Controller

Sample rate {1 / c["T"]:g} Hz; designed gains kp {gains.kp:.6g} N/m, ki {gains.ki:.6g} N/(m·s), kd {gains.kd:.6g} N·s/m,
kv {gains.kv:.6g} N·s/m; as words: kp {c["kp"].mantissa}·2^{c["kp"].shift}/2^15, ki {c["ki"].mantissa}·2^{c["ki"].shift}/2^15, kd {c["kd"].mantissa}·2^{c["kd"].shift}/2^15,
kv {c["kv"].mantissa}·2^{c["kv"].shift}/2^15, filters α {c["alpha"]}, α_ff {c["alpha_ff"]} (Q15); {c["cpl"]} counts per length LSB.

## Cycle estimate (MC56F8367 cycle model, {clock / 1e6:g} MHz)

- `sd_ik`: {ik.cycles:.0f} cycles = {ik.microseconds:.1f} µs ({ops})
- `sd_tick`: {tick:.0f} cycles = {tick / clock * 1e6:.1f} µs (the IK, then per tick {tops}, and {ISR_OVERHEAD_CYCLES} cycles of interrupt overhead)

The per-operation cycles are those of `stewart_drake.fixedpoint.cycles.CYCLE_TABLE` (estimates), with the
{c["sqrt_bits"]}-step square root costed as `mfr32Sqrt`{" and a table look-up as 6 cycles" if c["trig"] == "exact" else ""}.
"""
