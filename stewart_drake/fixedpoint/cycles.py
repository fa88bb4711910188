"""Cycle model of one inverse-kinematics evaluation on the MC56F8367 (DSP56800E core, 60 MHz, 60 MIPS).

Cycles = sum over operations of (calls per evaluation) x (cycles per call). The calls are *counted*,
not guessed: :func:`.scalar.tp17_op_counts` runs a line-by-line port of the firmware's loop body and
counts every intrinsic and library call (the FRAC16 of literal constants is folded by the compiler
and not counted; the FRAC16 of the ``double`` angles happens at run time and is).

The cycles per call (``CYCLE_TABLE``) are estimates, documented per entry; no hardware measurement is
available (the seed's cycle counter calls are commented out). Change the table to study other
assumptions; everything downstream (:func:`ik_latency_s`) follows it.

=================  ======  ============================================================================
operation          cycles  basis
=================  ======  ============================================================================
ALU intrinsics        1    add, sub, negate, L_add, L_sub, L_negate, L_mult (mpy), extract_h, round,
                           mult, mult_r, shl, shr: single-cycle DSP56800E instructions
operand move          1    per ALU intrinsic: the firmware keeps every intermediate in a global
                           variable, so each operation needs about one load or store (MOVE, 1 cycle)
mfr32Sqrt           150    rtlib assembly: 15 trial-bit steps of ~8.5 cycles (bfset, mpy, cmp, nop,
                           ble, bfclr half the time) + the nearest-of-two tail (~14) + jsr/rts (~9)
tfr16SinPIx         160    compiled ``tfr16.c``: ~135 instructions on the executed path (prologue and
                           register saves 14, fold 20, six mac_r Horner steps ~75, tail 25) + branches
tfr16CosPIx         190    the fold (~30 cycles) + a call to tfr16SinPIx
FRAC16(double)      160    ``double`` is 32-bit IEEE in software on the 56800E (no FPU): a software
                           float multiply (~100) and float-to-int conversion (~60)
loop overhead        10    the ``for(;;)`` branch and the stores of L1..L6 beyond the ALU moves
=================  ======  ============================================================================

With these figures one evaluation takes about 3.4 k cycles, ~56 µs at 60 MHz: the library calls and
the run-time double conversions are ~80 % of it, the 214 ALU intrinsics the rest.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from stewart_drake.errors import FixedPointError
from stewart_drake.fixedpoint.scalar import tp17_op_counts

CLOCK_HZ = 60e6

ALU_OPS = (
    "add",
    "sub",
    "negate",
    "abs_s",
    "L_add",
    "L_sub",
    "L_negate",
    "L_abs",
    "L_mult",
    "extract_h",
    "extract_l",
    "L_deposit_h",
    "L_deposit_l",
    "round",
    "mult",
    "mult_r",
    "shl",
    "shr",
    "L_shl",
    "L_shr",
)

CYCLE_TABLE: dict[str, float] = {
    **{op: 1.0 for op in ALU_OPS},
    "move": 1.0,  # per ALU op (see the module table)
    "mfr32Sqrt": 150.0,
    "tfr16SinPIx": 160.0,
    "tfr16CosPIx": 190.0,
    "FRAC16": 160.0,  # run-time FRAC16 of a double
    "div_s": 20.0,  # rep #16 div + sign handling
    "loop": 10.0,
}


@dataclass(frozen=True)
class CycleEstimate:
    """Cycles of one evaluation; ``breakdown`` maps operation -> (calls, cycles)."""

    cycles: float
    clock_hz: float
    breakdown: dict = field(default_factory=dict)

    @property
    def seconds(self) -> float:
        return self.cycles / self.clock_hz

    @property
    def microseconds(self) -> float:
        return self.seconds * 1e6


def estimate_cycles(
    op_counts: dict, table: dict | None = None, clock_hz: float = CLOCK_HZ, loops: int = 1
) -> CycleEstimate:
    """Cycles for a dict of operation -> calls (one evaluation), with one operand move per ALU op.
    Raises ``FixedPointError`` naming an operation missing from the table."""
    table = dict(CYCLE_TABLE if table is None else table)
    breakdown = {}
    n_alu = 0
    for op, n in sorted(op_counts.items()):
        if op not in table:
            raise FixedPointError(FixedPointError.NO_CYCLES.format(op=op))
        breakdown[op] = (int(n), n * table[op])
        if op in ALU_OPS:
            n_alu += n
    breakdown["move"] = (int(n_alu), n_alu * table["move"])
    breakdown["loop"] = (loops, loops * table["loop"])
    total = sum(c for _, c in breakdown.values())
    return CycleEstimate(float(total), float(clock_hz), breakdown)


def tp17_cycles(table: dict | None = None, clock_hz: float = CLOCK_HZ) -> CycleEstimate:
    """Cycle estimate of one pass of tp17.C's loop body (six leg lengths from one pose)."""
    return estimate_cycles(tp17_op_counts(), table, clock_hz)


def ik_latency_s(table: dict | None = None, clock_hz: float = CLOCK_HZ) -> float:
    """Computation latency (s) of one DSP IK evaluation: the delay a controller-in-the-loop model
    should put between sampling a pose and the leg-length set-points being available."""
    return tp17_cycles(table, clock_hz).seconds
