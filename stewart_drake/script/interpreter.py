"""Run a checked ``Program``: evaluate its statements in order, feeding moves and waits to a
``runtime.Motion``. Arithmetic is IEEE double; ``/`` is true division, ``DIV`` floor division, ``MOD``
the remainder with the divisor's sign (Python's ``//`` and ``%``), so the emitted Python computes the
same numbers."""

from __future__ import annotations

import math

from stewart_drake.errors import (
    SCRIPT_DIVISION_BY_ZERO,
    SCRIPT_LOOP_MOVES,
    SCRIPT_LOOP_STEPS,
    SCRIPT_NO_FINITE_VALUE,
    SCRIPT_OVERFLOW,
    SCRIPT_TOO_MANY_STEPS,
    SCRIPT_UNDEFINED,
)
from stewart_drake.script import ast
from stewart_drake.script.check import assigned_names
from stewart_drake.script.errors import ScriptError
from stewart_drake.script.runtime import CONSTANTS, FUNCTIONS, MAX_SEGMENTS, Motion, fmt_number, for_count, for_range

MAX_STEPS = 1_000_000  # statements executed + loop iterations


def execute(program: ast.Program, motion: Motion) -> dict:
    """Run ``program`` on ``motion``; return the final variables. Errors carry the program's source."""
    it = _Interpreter(motion, assigned_names(program.body))
    try:
        it.block(program.body)
    except ScriptError as e:
        e.source = program.source
        raise
    return it.env


class _Interpreter:
    def __init__(self, motion: Motion, assigned: dict):
        self.motion = motion
        self.env: dict[str, float] = {}
        self.assigned = assigned
        self.steps = 0

    def tick(self, at):
        self.steps += 1
        if self.steps > MAX_STEPS:
            raise ScriptError(SCRIPT_TOO_MANY_STEPS.format(limit=MAX_STEPS), at)

    def check_loop(self, s, count: int) -> None:
        """Refuse, before its first iteration, a FOR loop whose iterations (times the moves and waits its
        body surely makes, ``static_segments``) would pass ``MAX_STEPS`` or ``MAX_SEGMENTS``."""
        steps = count * (1 + static_cost(s.body)[0])
        if self.steps + steps > MAX_STEPS:
            raise ScriptError(SCRIPT_LOOP_STEPS.format(count=count, steps=steps, limit=MAX_STEPS), s.at)
        moves = count * static_cost(s.body)[1]
        if len(self.motion.segments) + moves > MAX_SEGMENTS:
            raise ScriptError(SCRIPT_LOOP_MOVES.format(moves=moves, limit=MAX_SEGMENTS), s.at)

    def block(self, body):
        for s in body:
            self.tick(s.at)
            self.stmt(s)

    def stmt(self, s):
        if isinstance(s, ast.Assign):
            self.env[s.name] = self.eval(s.value)
        elif isinstance(s, ast.Move):
            pos = [self.eval(a.value) for a in s.args if a.name is None]
            kws = {a.name: self.eval(a.value) for a in s.args if a.name is not None}
            d = None if s.duration is None else self.eval(s.duration)
            self.motion.move(*pos, duration=d, at=s.at, keyword=s.keyword, **kws)
        elif isinstance(s, ast.Wait):
            self.motion.wait(self.eval(s.duration), at=s.at)
        elif isinstance(s, ast.Units):
            self.motion.units(*(n for n, _ in s.names), at=s.at)
        elif isinstance(s, ast.For):
            step = 1.0 if s.step is None else self.eval(s.step)
            start, stop = self.eval(s.start), self.eval(s.stop)
            self.check_loop(s, for_count(start, stop, step, at=s.at))
            for v in for_range(start, stop, step, at=s.at):
                self.tick(s.at)
                self.env[s.var] = v
                self.block(s.body)
        elif isinstance(s, ast.If):
            for cond, body in s.branches:
                if self.eval(cond):
                    self.block(body)
                    break
            else:
                self.block(s.orelse or ())
        elif isinstance(s, ast.While):
            while self.eval(s.cond):
                self.tick(s.at)
                self.block(s.body)
        else:  # pragma: no cover
            raise TypeError(f"unknown statement {type(s).__name__}")

    def eval(self, e):
        if isinstance(e, ast.Num):
            return e.value
        if isinstance(e, ast.Var):
            if e.name in self.env:
                return self.env[e.name]
            if e.name in CONSTANTS:
                return CONSTANTS[e.name][0]
            first = self.assigned.get(e.name)
            hint = (
                f": it is first assigned at line {first.line}, column {first.column}, after this use" if first else ""
            )
            raise ScriptError(SCRIPT_UNDEFINED.format(name=e.name) + hint, e.at)
        if isinstance(e, ast.Unary):
            v = self.eval(e.operand)
            return -v if e.op == "-" else +v
        if isinstance(e, ast.Not):
            return not self.eval(e.operand)
        if isinstance(e, ast.Call):
            args = [self.eval(a) for a in e.args]
            fn = FUNCTIONS[e.name][1]
            try:
                v = fn(*args)
            except (ValueError, OverflowError):
                v = math.nan
            if not math.isfinite(v):
                shown = ", ".join(fmt_number(a) for a in args)
                raise ScriptError(SCRIPT_NO_FINITE_VALUE.format(name=e.name, args=shown), e.at)
            return float(v)
        if isinstance(e, ast.Binary):
            if e.op == "AND":
                return bool(self.eval(e.left)) and bool(self.eval(e.right))
            if e.op == "OR":
                return bool(self.eval(e.left)) or bool(self.eval(e.right))
            a, b = self.eval(e.left), self.eval(e.right)
            return _binary(e.op, a, b, e.at)
        raise TypeError(f"unknown expression {type(e).__name__}")  # pragma: no cover


def static_cost(body) -> tuple[int, int]:
    """Lower bounds ``(steps, segments)`` on what ``body`` does each time it runs: one step per statement
    and, for nested FOR loops with literal bounds, their iterations times (1 + their bodies' steps);
    segments are its moves and positive literal waits, likewise multiplied. IF and WHILE bodies may not
    run, so they count 0: the bounds never refuse a program that would have fitted."""
    steps = moves = 0
    for s in body:
        steps += 1
        if isinstance(s, ast.Move) or (
            isinstance(s, ast.Wait) and isinstance(s.duration, ast.Num) and s.duration.value > 0
        ):
            moves += 1
        elif isinstance(s, ast.For) and all(
            isinstance(e, ast.Num) for e in (s.start, s.stop) + ((s.step,) if s.step else ())
        ):
            step = 1.0 if s.step is None else s.step.value
            k = (s.stop.value - s.start.value) / step if step else -1.0
            n = int(math.floor(k + 1e-9)) + 1 if 0 <= k < 1e18 else 0
            inner_steps, inner_moves = static_cost(s.body)
            steps += n * (1 + inner_steps)
            moves += n * inner_moves
    return steps, moves


_COMPARE = {
    "=": lambda a, b: a == b,
    "<>": lambda a, b: a != b,
    "<": lambda a, b: a < b,
    "<=": lambda a, b: a <= b,
    ">": lambda a, b: a > b,
    ">=": lambda a, b: a >= b,
}


_ARITH = {
    "+": lambda a, b: a + b,
    "-": lambda a, b: a - b,
    "*": lambda a, b: a * b,
    "/": lambda a, b: a / b,
    "DIV": lambda a, b: a // b,
    "MOD": lambda a, b: a % b,
}


def _binary(op, a, b, at):
    if op in _COMPARE:
        return _COMPARE[op](a, b)
    if op in ("/", "DIV", "MOD") and b == 0:
        raise ScriptError(SCRIPT_DIVISION_BY_ZERO.format(a=fmt_number(a), op=op), at)
    try:
        v = _ARITH[op](a, b)
    except OverflowError:
        v = math.inf
    if not math.isfinite(v):
        raise ScriptError(SCRIPT_OVERFLOW.format(a=fmt_number(a), op=op, b=fmt_number(b)), at)
    return v
