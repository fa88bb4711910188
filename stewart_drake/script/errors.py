"""Diagnostics of the motion language, shaped like a compiler's: ``file:line:column: error: message``.

Every problem a program can have (syntax, undefined variable, wrong argument count, unreachable pose,
arithmetic fault) is a ``ScriptError``; several found together are a ``ScriptErrors``. Both derive from
``StewartError`` (hence ``ValueError``), so the CLI prints them without a traceback. Their message
templates are constants in ``stewart_drake.errors``; tests match them.
"""

from __future__ import annotations

from dataclasses import dataclass

from stewart_drake.errors import StewartError


@dataclass(frozen=True)
class Loc:
    """A place in a program: file name, 1-based line and column."""

    filename: str
    line: int
    column: int

    def __str__(self) -> str:
        return f"{self.filename}:{self.line}:{self.column}"


def as_loc(at) -> Loc | None:
    """A ``Loc`` from a ``Loc``, a ``(filename, line, column)`` tuple, or None."""
    if at is None or isinstance(at, Loc):
        return at
    return Loc(*at)


class ScriptError(StewartError):
    """One diagnostic. ``str()`` is ``file:line:column: error: message``; ``render()`` adds the source
    line and a caret under the column when the source text is known."""

    def __init__(self, message: str, at=None, source: str | None = None, kind: str = "error"):
        self.message, self.at, self.source, self.kind = message, as_loc(at), source, kind
        super().__init__(str(self))

    def __str__(self) -> str:
        where = f"{self.at}: " if self.at is not None else ""
        return f"{where}{self.kind}: {self.message}"

    def render(self) -> str:
        text = str(self)
        if self.at is None or not self.source:
            return text
        lines = self.source.splitlines()
        if not 1 <= self.at.line <= len(lines):
            return text
        src = lines[self.at.line - 1].expandtabs(1)
        return f"{text}\n    {src}\n    {' ' * (self.at.column - 1)}^"


class ScriptErrors(ScriptError):
    """Several diagnostics found in one pass (all reported before anything is written)."""

    def __init__(self, errors: list[ScriptError]):
        self.errors = list(errors)
        first = self.errors[0]
        super().__init__(first.message, first.at, first.source, first.kind)

    def __str__(self) -> str:
        return "\n".join(ScriptError.__str__(e) for e in self.errors)

    def render(self) -> str:
        return "\n".join(e.render() for e in self.errors)


def raise_all(errors: list[ScriptError]) -> None:
    """Raise nothing, the single error, or a ``ScriptErrors`` of them all (in source order)."""
    if not errors:
        return
    errors = sorted(errors, key=lambda e: (e.at.line, e.at.column) if e.at else (0, 0))
    raise errors[0] if len(errors) == 1 else ScriptErrors(errors)
