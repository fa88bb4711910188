"""Parse motion-language source into a ``Program`` (see ``stewart.lark`` for the grammar).

Lark's LALR(1) parser does the work; this module turns its tree into ``ast`` nodes with source
positions and turns every Lark exception into a ``ScriptError`` of the form
``file:line:column: error: unexpected <token>; expected <tokens>``.
"""

from __future__ import annotations

import functools
from importlib import resources
from typing import NamedTuple

from lark import Lark, Token
from lark.exceptions import UnexpectedCharacters, UnexpectedInput, UnexpectedToken, VisitError
from lark.visitors import Transformer_NonRecursive

from stewart_drake.errors import (
    SCRIPT_CANNOT_PARSE,
    SCRIPT_EXPRESSION_DEPTH,
    SCRIPT_LOOP_DEPTH,
    SCRIPT_NUMBER_TOO_LARGE,
    SCRIPT_RESERVED,
    SCRIPT_STATEMENT_DEPTH,
    SCRIPT_SYNTAX,
)
from stewart_drake.script import ast
from stewart_drake.script.errors import Loc, ScriptError

# Deeper nesting than this is refused (later passes recurse over the tree).
MAX_DEPTH = 100
# Statement nesting the Python back end can express: Python allows 100 indentation levels (the emitted
# code adds one) and 20 statically nested loop blocks.
MAX_STMT_DEPTH = 60
MAX_LOOP_DEPTH = 16

# Modula-2 keywords the seed's Stewart.g reserved and this language does not (yet) implement.
# Upper case only, like the seed's (case-sensitive) ANTLR tokens; lower-case spellings are names.
RESERVED_WORDS = frozenset(
    "ALIAS ARRAY ASSOCIATIVE BEGIN BINDINGS CASE CONST DEFINITION EXIT FROM IMPLEMENTATION IMPORT LOOP "
    "MODULE OF OPAQUE POINTER PROCEDURE RECORD REPEAT RETURN SET TYPE UNTIL VAR VARIADIC".split()
)
# Terminals that are words (shown as keywords in messages); matched case-insensitively.
KEYWORDS = (
    "MOVE",
    "_DURATION",
    "WAIT",
    "UNITS",
    "FOR",
    "TO",
    "BY",
    "DO",
    "END",
    "IF",
    "THEN",
    "ELSIF",
    "ELSE",
    "WHILE",
    "OR",
    "AND",
    "NOT",
    "DIV",
    "MOD",
)
_KEYWORD_SPELLING = {"MOVE": "mover", "_DURATION": "en", "WAIT": "wait", "UNITS": "units"}
_DESCRIBE = {
    "NAME": "a name",
    "NUMBER": "a number",
    "CMP_OP": "a comparison (= <> < <= > >=)",
    "EQ": "'='",
    "ASSIGN": "':='",
    "$END": "end of file",
}

_CMP = {"==": "=", "=": "=", "<>": "<>", "#": "<>", "!=": "<>", "<": "<", "<=": "<=", ">": ">", ">=": ">="}


@functools.cache
def _lark() -> Lark:
    grammar = resources.files(__package__).joinpath("stewart.lark").read_text(encoding="utf-8")
    return Lark(
        grammar, parser="lalr", lexer="basic", maybe_placeholders=True, lexer_callbacks={"NAME": _check_reserved}
    )


def _check_reserved(tok: Token) -> Token:
    if tok.value in RESERVED_WORDS:
        raise _ReservedWord(tok)
    return tok


class _ReservedWord(Exception):
    def __init__(self, tok):
        self.tok = tok


def _describe_terminal(name: str) -> str:
    if name in _DESCRIBE:
        return _DESCRIBE[name]
    if name in KEYWORDS:
        return _KEYWORD_SPELLING.get(name, name)
    for t in _lark().terminals:
        if t.name == name and t.pattern.type == "str":
            return repr(t.pattern.value)
    return name


def _describe_token(tok: Token) -> str:
    if tok.type == "$END":
        return "end of file"
    if tok.type in KEYWORDS:
        return f"keyword {tok.value!r}"
    if tok.type == "NAME":
        return f"name {tok.value!r}"
    if tok.type == "NUMBER":
        return f"number {tok.value}"
    return repr(tok.value)


def expected_list(names) -> str:
    """Human list of expected terminals: ``')'`` or ``one of: ')', ',', a name``."""
    names = set(names)
    if "CMP_OP" in names:
        names.discard("EQ")  # '=' is listed among the comparisons
    items = sorted({_describe_terminal(n) for n in names})
    if not items:
        return "nothing more"
    return items[0] if len(items) == 1 else "one of: " + ", ".join(items)


def _end_position(text: str) -> tuple[int, int]:
    lines = text.split("\n")
    return len(lines), len(lines[-1]) + 1


def parse(text: str, filename: str = "<program>") -> ast.Program:
    """Parse ``text`` into a ``Program``; raise ``ScriptError`` (never anything else) on bad input."""
    if not isinstance(text, str):
        raise TypeError(f"program text must be str, got {type(text).__name__}")
    try:
        tree = _lark().parse(text)
    except _ReservedWord as e:
        tok = e.tok
        raise ScriptError(SCRIPT_RESERVED.format(word=tok.value), Loc(filename, tok.line, tok.column), text) from None
    except UnexpectedToken as e:
        tok = e.token
        if tok.type == "$END" or tok.line is None or tok.line < 1:
            line, col = _end_position(text)
        else:
            line, col = tok.line, tok.column
        expected = e.accepts or e.expected
        msg = SCRIPT_SYNTAX.format(found=_describe_token(tok), expected=expected_list(expected))
        raise ScriptError(msg, Loc(filename, line, col), text, kind="syntax error") from None
    except UnexpectedCharacters as e:
        found = "end of file" if e.pos_in_stream >= len(text) else f"character {text[e.pos_in_stream]!r}"
        msg = SCRIPT_SYNTAX.format(found=found, expected=expected_list(_accepts_at(text[: e.pos_in_stream])))
        raise ScriptError(msg, Loc(filename, e.line, e.column), text, kind="syntax error") from None
    except UnexpectedInput as e:  # any other Lark input error
        raise ScriptError(
            SCRIPT_CANNOT_PARSE.format(problem=e),
            Loc(filename, getattr(e, "line", 1) or 1, getattr(e, "column", 1) or 1),
            text,
            kind="syntax error",
        ) from None
    try:
        body = _ToAst(filename).transform(tree)
    except VisitError as e:
        if isinstance(e.orig_exc, ScriptError):
            err = e.orig_exc
            raise ScriptError(err.message, err.at, text, err.kind) from None
        raise
    except ScriptError as err:
        raise ScriptError(err.message, err.at, text, err.kind) from None
    return ast.Program(tuple(body), filename, text)


def _accepts_at(prefix: str) -> set:
    """Terminals the parser accepts after ``prefix`` (used for lexical errors)."""
    try:
        ip = _lark().parse_interactive(prefix)
        ip.exhaust_lexer()
        return ip.accepts()
    except (UnexpectedInput, _ReservedWord):
        return set()


def _depth(*nodes) -> int:
    return 1 + max((getattr(n, "depth", 0) for n in nodes if n is not None), default=0)


class _ToAst(Transformer_NonRecursive):
    """Lark tree -> ``ast`` nodes. Non-recursive, so deep input cannot overflow the stack here."""

    def __init__(self, filename: str):
        super().__init__()
        self.filename = filename

    def _loc(self, tok: Token) -> Loc:
        return Loc(self.filename, tok.line, tok.column)

    def _limit(self, node, at: Loc):
        if getattr(node, "depth", 0) > MAX_DEPTH:
            raise ScriptError(SCRIPT_EXPRESSION_DEPTH.format(limit=MAX_DEPTH), at, kind="syntax error")
        return node

    # -- program structure
    def start(self, items):
        stmts = [s for s in items if s is not None]
        _check_nesting(stmts)  # bodies were checked as they were built; the top level here
        return stmts

    def body(self, items):
        stmts = tuple(s for s in items if s is not None)
        _check_nesting(stmts)
        return stmts

    def assign(self, items):
        name, _, value = items
        return ast.Assign(name.value, value, self._loc(name))

    def move(self, items):
        kw, arglist, duration = items
        return ast.Move(kw.value, tuple(arglist or ()), duration, self._loc(kw))

    def arglist(self, items):
        return [a if isinstance(a, ast.Arg) else ast.Arg(None, a, _expr_loc(a)) for a in items]

    def kwarg(self, items):
        name, _, value = items
        return ast.Arg(name.value, value, self._loc(name))

    def wait(self, items):
        kw, duration = items
        return ast.Wait(duration, self._loc(kw))

    def units(self, items):
        kw, *names = items
        return ast.Units(tuple((n.value, self._loc(n)) for n in names if n is not None), self._loc(kw))

    def for_stmt(self, items):
        kw, var, _, start, _to, stop, _by, step, _do, body, _end = items
        return ast.For(var.value, start, stop, step, body, self._loc(kw), self._loc(var))

    def if_stmt(self, items):
        kw, cond, _then, body, *rest = items
        # rest: _Elsif..., ELSE token or None, else body or None, END
        branches = [(cond, body)] + [(b.cond, b.body) for b in rest if isinstance(b, _Elsif)]
        orelse = rest[-2]
        return ast.If(tuple(branches), orelse, self._loc(kw))

    def elsif(self, items):
        _kw, cond, _then, body = items
        return _Elsif(cond, body)

    def while_stmt(self, items):
        kw, cond, _do, body, _end = items
        return ast.While(cond, body, self._loc(kw))

    # -- expressions
    def _chain(self, items):
        node = items[0]
        for op, right in zip(items[1::2], items[2::2]):
            at = self._loc(op)
            name = op.value.upper() if op.type in ("DIV", "MOD", "AND", "OR") else _CMP.get(op.value, op.value)
            node = self._limit(ast.Binary(name, node, right, at, _depth(node, right)), at)
        return node

    or_test = and_test = comparison = arith = term = _chain

    def not_op(self, items):
        kw, operand = items
        at = self._loc(kw)
        return self._limit(ast.Not(operand, at, _depth(operand)), at)

    def neg(self, items):
        op, operand = items
        at = self._loc(op)
        return self._limit(ast.Unary("-", operand, at, _depth(operand)), at)

    def pos(self, items):
        op, operand = items
        at = self._loc(op)
        return self._limit(ast.Unary("+", operand, at, _depth(operand)), at)

    def number(self, items):
        (tok,) = items
        value = float(tok.value)
        if value == float("inf"):
            raise ScriptError(SCRIPT_NUMBER_TOO_LARGE.format(text=tok.value), self._loc(tok))
        return ast.Num(value, tok.value, self._loc(tok))

    def var(self, items):
        (tok,) = items
        return ast.Var(tok.value, self._loc(tok))

    def call(self, items):
        name, *args = items
        args = tuple(a for a in args if a is not None)
        at = self._loc(name)
        return self._limit(ast.Call(name.value, args, at, _depth(*args)), at)


class _Elsif(NamedTuple):
    cond: object
    body: tuple


def _expr_loc(e) -> Loc:
    """Where an expression starts (its leftmost token)."""
    while isinstance(e, ast.Binary):
        e = e.left
    return e.at


def _check_nesting(stmts) -> None:
    for s in stmts:
        if _stmt_depth(s) > MAX_STMT_DEPTH:
            raise ScriptError(SCRIPT_STATEMENT_DEPTH.format(limit=MAX_STMT_DEPTH), s.at, kind="syntax error")
        if _stmt_depth(s, loops_only=True) > MAX_LOOP_DEPTH:
            raise ScriptError(SCRIPT_LOOP_DEPTH.format(limit=MAX_LOOP_DEPTH), s.at, kind="syntax error")


def _stmt_depth(s, loops_only: bool = False) -> int:
    """Statement nesting depth: the most statements on a path from ``s`` inward (bodies of FOR/IF/WHILE
    one level each); with ``loops_only``, the most FOR/WHILE statements on such a path. Iterative."""
    best, stack = 0, [(s, 0)]
    while stack:
        node, d = stack.pop()
        loop = isinstance(node, (ast.For, ast.While))
        d += 1 if (loop or not loops_only) else 0
        best = max(best, d)
        if loop:
            stack.extend((c, d) for c in node.body)
        elif isinstance(node, ast.If):
            for _, body in node.branches:
                stack.extend((c, d) for c in body)
            stack.extend((c, d) for c in node.orelse or ())
    return best
