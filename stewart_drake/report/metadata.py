"""An analysis script's report metadata read from its source, without importing it.

The report's parent process needs only each analysis's ``TITLE``, ``ORDER``, ``COST``, ``INPUTS`` (the files a
script outside the package declares it reads: ``report.cache``), ``NEEDS`` and ``PRESET_ONLY`` (whether it runs on
a user's machine and what it needs of it: ``report.subject``) and whether it defines ``build`` and ``parts`` to
order, schedule and key the sections; the workers import the scripts (they run them).
Importing all seventeen in the parent as well cost 1.7 s of CPU before the first worker started (each script
pulls in scipy, Drake, the firmware tools, …; measured with ``time.process_time`` around
``discover_analyses()``), while the source's syntax tree gives the same constants in ~0.05 s. A script whose
metadata is not plain literals at its top level (a computed ``TITLE``, a ``build`` imported from elsewhere)
gets ``None`` here and is imported, as before.
"""

from __future__ import annotations

import ast
from pathlib import Path

CONSTANTS = ("TITLE", "ORDER", "COST", "INPUTS", "NEEDS", "PRESET_ONLY")


def read(path: Path) -> dict | None:
    """``{"TITLE": …, "ORDER": …, "COST": …, "INPUTS": …, "NEEDS": …, "PRESET_ONLY": …, "build": bool,
    "parts": bool}`` of the script at ``path`` (``COST`` 0.0 and the others None when absent; ``build``/``parts``:
    a top-level ``def`` of that name), or None when a constant
    present is not a literal, ``TITLE``/``ORDER``/``build`` is missing, or a name is bound otherwise (an
    assignment or import of ``build``/``parts``, a second binding of a constant): then only importing the
    script says what it holds."""
    tree = ast.parse(Path(path).read_bytes(), str(path))
    found: dict = {"COST": 0.0, "INPUTS": None, "NEEDS": None, "PRESET_ONLY": None}
    defs: set[str] = set()
    bound: list[str] = []
    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            bound.append(node.name)
            defs.add(node.name)
        elif isinstance(node, (ast.Assign, ast.AnnAssign, ast.AugAssign)):
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
            names = [n.id for t in targets for n in ast.walk(t) if isinstance(n, ast.Name)]
            bound += names
            if len(names) == 1 and names[0] in CONSTANTS and isinstance(node, (ast.Assign, ast.AnnAssign)):
                try:
                    found[names[0]] = ast.literal_eval(node.value)
                except ValueError:
                    return None
        elif isinstance(node, (ast.Import, ast.ImportFrom)):
            bound += [(a.asname or a.name).split(".")[0] for a in node.names]
        elif not (isinstance(node, ast.Expr) or _is_main_guard(node)):  # if/try/for/with may bind anything
            return None
    watched = [n for n in bound if n in (*CONSTANTS, "build", "parts")]
    if len(watched) != len(set(watched)) or "*" in bound:
        return None
    if "TITLE" not in found or "ORDER" not in found or "build" not in defs:
        return None
    if "build" in watched and "build" not in defs or "parts" in watched and "parts" not in defs:
        return None
    return {
        "TITLE": found["TITLE"],
        "ORDER": found["ORDER"],
        "COST": found["COST"],
        "INPUTS": found["INPUTS"],
        "NEEDS": found["NEEDS"],
        "PRESET_ONLY": found["PRESET_ONLY"],
        "build": True,
        "parts": "parts" in defs,
    }


def _is_main_guard(node) -> bool:
    """``if __name__ == "__main__": …`` (runs only when the script is run as a program)."""
    return (
        isinstance(node, ast.If)
        and not node.orelse
        and isinstance(node.test, ast.Compare)
        and isinstance(node.test.left, ast.Name)
        and node.test.left.id == "__name__"
        and len(node.test.comparators) == 1
        and isinstance(node.test.comparators[0], ast.Constant)
        and node.test.comparators[0].value == "__main__"
    )
