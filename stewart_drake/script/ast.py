"""The motion language's syntax tree: plain frozen dataclasses, each with its source ``Loc``.

Expressions carry ``depth`` (nesting level) so later passes can refuse absurdly deep programs
instead of overflowing Python's stack.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Union

from stewart_drake.script.errors import Loc

# ---- expressions -----------------------------------------------------------------------------


@dataclass(frozen=True)
class Num:
    value: float
    text: str
    at: Loc
    depth: int = 1


@dataclass(frozen=True)
class Var:
    name: str
    at: Loc
    depth: int = 1


@dataclass(frozen=True)
class Unary:
    op: str  # "-" or "+"
    operand: Expr
    at: Loc
    depth: int = 1


@dataclass(frozen=True)
class Binary:
    """Arithmetic (``+ - * / DIV MOD``), comparison (``= <> < <= > >=``) or logic (``AND OR``).
    ``at`` is the operator's position."""

    op: str
    left: Expr
    right: Expr
    at: Loc
    depth: int = 1


@dataclass(frozen=True)
class Not:
    operand: Expr
    at: Loc
    depth: int = 1


@dataclass(frozen=True)
class Call:
    name: str
    args: tuple
    at: Loc
    depth: int = 1


Expr = Union[Num, Var, Unary, Binary, Not, Call]

ARITH_OPS = ("+", "-", "*", "/", "DIV", "MOD")
COMPARE_OPS = ("=", "<>", "<", "<=", ">", ">=")
LOGIC_OPS = ("AND", "OR")

# ---- statements ------------------------------------------------------------------------------


@dataclass(frozen=True)
class Assign:
    name: str
    value: Expr
    at: Loc


@dataclass(frozen=True)
class Arg:
    name: str | None  # None for a positional argument
    value: Expr
    at: Loc


@dataclass(frozen=True)
class Move:
    keyword: str  # as written: "mover" or "move"
    args: tuple  # of Arg
    duration: Expr | None
    at: Loc


@dataclass(frozen=True)
class Wait:
    duration: Expr
    at: Loc


@dataclass(frozen=True)
class Units:
    names: tuple  # of (name, Loc)
    at: Loc


@dataclass(frozen=True)
class For:
    var: str
    start: Expr
    stop: Expr
    step: Expr | None
    body: tuple
    at: Loc
    var_at: Loc


@dataclass(frozen=True)
class If:
    branches: tuple  # of (condition, body)
    orelse: tuple | None
    at: Loc


@dataclass(frozen=True)
class While:
    cond: Expr
    body: tuple
    at: Loc


Stmt = Union[Assign, Move, Wait, Units, For, If, While]


@dataclass(frozen=True)
class Program:
    """A parsed program: its statements, file name and source text (for diagnostics)."""

    body: tuple
    filename: str
    source: str = field(repr=False, default="")
