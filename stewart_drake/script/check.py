"""Static checks, done on the whole program before it runs (all problems reported at once):
numbers vs conditions, ``mover`` argument lists, function names and argument counts, ``units`` names,
assignments to constants, and variables that are never assigned anywhere."""

from __future__ import annotations

import difflib

from stewart_drake.core.rotations import ANGLE_UNITS, LENGTH_UNITS
from stewart_drake.errors import (
    SCRIPT_FUNC_ARITY,
    SCRIPT_FUNC_UNKNOWN,
    SCRIPT_MOVE_ARITY,
    SCRIPT_MOVE_DUPLICATE_ARG,
    SCRIPT_MOVE_POSITIONAL_AFTER_KEYWORD,
    SCRIPT_MOVE_UNKNOWN_ARG,
    SCRIPT_NEVER_ASSIGNED,
)
from stewart_drake.script import ast
from stewart_drake.script.errors import ScriptError, raise_all
from stewart_drake.script.runtime import ARG_ALIASES, ARG_NAMES, CONSTANTS, FUNCTIONS

NUMBER, CONDITION = "number", "condition"


def did_you_mean(name: str, candidates) -> str:
    """ " (did you mean 'x'?)" with the candidate closest to ``name`` (difflib), or "" when none is close."""
    close = difflib.get_close_matches(name, sorted(candidates), n=1)
    return f" (did you mean {close[0]!r}?)" if close else ""


def check(program: ast.Program) -> None:
    """Raise ``ScriptError``/``ScriptErrors`` listing every static problem, in source order."""
    c = _Checker(assigned_names(program.body))
    c.block(program.body)
    for e in c.errors:
        e.source = program.source
    raise_all(c.errors)


def assigned_names(body) -> dict:
    """Every name assigned (or used as a FOR variable) anywhere in ``body`` -> its first ``Loc``."""
    out = {}
    stack = list(reversed(body))
    while stack:
        s = stack.pop()
        if isinstance(s, ast.Assign):
            out.setdefault(s.name, s.at)
        elif isinstance(s, ast.For):
            out.setdefault(s.var, s.var_at)
            stack.extend(reversed(s.body))
        elif isinstance(s, ast.If):
            for _, b in reversed(s.branches):
                stack.extend(reversed(b))
            stack.extend(reversed(s.orelse or ()))
        elif isinstance(s, ast.While):
            stack.extend(reversed(s.body))
    return out


class _Checker:
    def __init__(self, assigned: dict):
        self.errors: list[ScriptError] = []
        self.assigned = assigned

    def err(self, msg, at):
        self.errors.append(ScriptError(msg, at))

    def block(self, body):
        for s in body:
            self.stmt(s)

    def stmt(self, s):
        if isinstance(s, ast.Assign):
            self._target(s.name, s.at)
            self.number(s.value, "an assignment")
        elif isinstance(s, ast.Move):
            self.move(s)
        elif isinstance(s, ast.Wait):
            self.number(s.duration, "wait")
        elif isinstance(s, ast.Units):
            self.units(s)
        elif isinstance(s, ast.For):
            self._target(s.var, s.var_at)
            for e in (s.start, s.stop, s.step):
                if e is not None:
                    self.number(e, "FOR")
            self.block(s.body)
        elif isinstance(s, ast.If):
            for cond, body in s.branches:
                self.condition(cond, "IF")
                self.block(body)
            self.block(s.orelse or ())
        elif isinstance(s, ast.While):
            self.condition(s.cond, "WHILE")
            self.block(s.body)

    def _target(self, name, at):
        if name in CONSTANTS:
            self.err(f"cannot assign to the constant {name!r}", at)

    def move(self, s: ast.Move):
        positional = [a for a in s.args if a.name is None]
        keywords = [a for a in s.args if a.name is not None]
        seen_kw = False
        for a in s.args:
            if a.name is None and seen_kw:
                self.err(SCRIPT_MOVE_POSITIONAL_AFTER_KEYWORD.format(kw=s.keyword), a.at)
            seen_kw = seen_kw or a.name is not None
        if len(positional) > 6 or (not keywords and len(positional) != 6):
            self.err(SCRIPT_MOVE_ARITY.format(kw=s.keyword, n=len(s.args)), s.at)
        given = set(ARG_NAMES[: len(positional)])
        for a in keywords:
            canon = ARG_ALIASES.get(a.name, a.name)
            if canon not in ARG_NAMES:
                self.err(
                    SCRIPT_MOVE_UNKNOWN_ARG.format(kw=s.keyword, name=a.name) + did_you_mean(a.name, ARG_NAMES), a.at
                )
            elif canon in given:
                self.err(SCRIPT_MOVE_DUPLICATE_ARG.format(kw=s.keyword, name=canon), a.at)
            given.add(canon)
        for a in s.args:
            self.number(a.value, f"{s.keyword} argument")
        if s.duration is not None:
            self.number(s.duration, f"{s.keyword} duration")

    def units(self, s: ast.Units):
        kinds = {}
        for name, at in s.names:
            kind = "length" if name in LENGTH_UNITS else "angle" if name in ANGLE_UNITS else None
            if kind is None:
                self.err(
                    f"units: {name!r} is not a unit; expected {' or '.join(LENGTH_UNITS)} (length), "
                    f"{' or '.join(ANGLE_UNITS)} (angle)",
                    at,
                )
            elif kind in kinds:
                self.err(f"units: two {kind} units given ({kinds[kind]!r} and {name!r})", at)
            else:
                kinds[kind] = name

    # -- expressions: return their kind
    def number(self, e, context):
        if self.expr(e) == CONDITION:
            self.err(f"{context} needs a number, got a condition", _start(e))

    def condition(self, e, context):
        if self.expr(e) == NUMBER:
            self.err(f"{context} needs a condition such as x > 0, got a number", _start(e))

    def expr(self, e) -> str:
        if isinstance(e, ast.Num):
            return NUMBER
        if isinstance(e, ast.Var):
            if e.name not in self.assigned and e.name not in CONSTANTS:
                self.err(
                    SCRIPT_NEVER_ASSIGNED.format(name=e.name)
                    + did_you_mean(e.name, set(self.assigned) | set(CONSTANTS)),
                    e.at,
                )
            return NUMBER
        if isinstance(e, ast.Unary):
            self.number(e.operand, f"unary {e.op}")
            return NUMBER
        if isinstance(e, ast.Not):
            self.condition(e.operand, "NOT")
            return CONDITION
        if isinstance(e, ast.Call):
            if e.name not in FUNCTIONS:
                self.err(
                    SCRIPT_FUNC_UNKNOWN.format(name=e.name, available=", ".join(sorted(FUNCTIONS)))
                    + did_you_mean(e.name, FUNCTIONS),
                    e.at,
                )
            else:
                n = FUNCTIONS[e.name][0]
                if len(e.args) != n:
                    self.err(
                        SCRIPT_FUNC_ARITY.format(name=e.name, expected=n, s="" if n == 1 else "s", n=len(e.args)), e.at
                    )
            for a in e.args:
                self.number(a, f"{e.name}()")
            return NUMBER
        if isinstance(e, ast.Binary):
            if e.op in ast.LOGIC_OPS:
                self.condition(e.left, e.op)
                self.condition(e.right, e.op)
                return CONDITION
            self.number(e.left, f"'{e.op}'")
            self.number(e.right, f"'{e.op}'")
            return CONDITION if e.op in ast.COMPARE_OPS else NUMBER
        raise TypeError(f"unknown expression node {type(e).__name__}")  # pragma: no cover


def _start(e):
    while isinstance(e, ast.Binary):
        e = e.left
    return e.at
