"""The layers of ARCHITECTURE.md, checked on the source: who may import whom, pydrake only in the Drake
package and only at module top, no classes built with ``type(...)``, no private names imported across
modules."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "stewart_drake"

# layer -> the layers its modules may import (besides stewart_drake.errors and the standard library)
CORE = {
    "core",
    "system",
    "mechanisms",
    "fixedpoint",
    "workspace",
    "script",
    "homotopy",
    "design",
    "calibration",
    "spec",
}
CONTROL = {"control", "firmware"}  # the laws, and the same law as generated, compiled C
ALLOWED = {
    **{layer: CORE for layer in CORE},
    **{layer: CORE | CONTROL for layer in CONTROL},
    "drake": CORE | CONTROL | {"drake"},
    "engines": CORE | CONTROL | {"engines"},  # Pinocchio and MuJoCo, optional extras (their own imports only here)
    "api": CORE | CONTROL | {"drake", "engines", "api"},  # the public API (stewart_drake.__all__); the app above it
}
ENGINE_LIBRARIES = ("pinocchio", "mujoco")
APP = {"commands", "report", "analyses", "montecarlo", "synthesis", "cli", "__init__", "__main__"}


def layer_of(path: Path) -> str:
    rel = path.relative_to(PACKAGE)
    return rel.parts[0].removesuffix(".py") if len(rel.parts) > 1 or rel.suffix else rel.stem


def modules():
    return sorted(p for p in PACKAGE.rglob("*.py"))


def imports(tree: ast.AST):
    """(node, absolute module name, imported names) for every import in ``tree``, at any depth."""
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for a in node.names:
                yield node, a.name, []
        elif isinstance(node, ast.ImportFrom):
            yield node, ("." * node.level) + (node.module or ""), [a.name for a in node.names]


def top_level_nodes(tree: ast.Module) -> set[int]:
    """ids of import nodes at module level (including inside top-level if/try blocks)."""
    out = set()
    stack = list(tree.body)
    while stack:
        n = stack.pop()
        if isinstance(n, (ast.Import, ast.ImportFrom)):
            out.add(id(n))
        elif isinstance(n, (ast.If, ast.Try)):
            stack.extend(
                n.body
                + n.orelse
                + getattr(n, "finalbody", [])
                + [h for x in getattr(n, "handlers", []) for h in x.body]
            )
    return out


LAYERS = sorted({layer_of(p) for p in modules()})


def test_every_module_has_a_layer():
    """A new top-level module or package must be given a layer here (and in ARCHITECTURE.md)."""
    unknown = sorted({layer_of(p) for p in modules()} - set(ALLOWED) - APP - {"errors"})
    assert not unknown, f"modules outside every layer: {unknown}"


@pytest.mark.parametrize("path", modules(), ids=lambda p: str(p.relative_to(PACKAGE)))
def test_module_respects_its_layer(path):
    tree = ast.parse(path.read_text(encoding="utf-8"))
    layer = layer_of(path)
    top = top_level_nodes(tree)
    problems = []
    for node, name, names in imports(tree):
        if name.startswith("."):
            problems.append(f"line {node.lineno}: relative import {name}")
            continue
        if name == "pydrake" or name.startswith("pydrake."):
            if layer != "drake":
                problems.append(f"line {node.lineno}: imports {name} outside the drake package")
            elif id(node) not in top:
                problems.append(f"line {node.lineno}: imports {name} inside a function")
            continue
        if name.split(".")[0] in ENGINE_LIBRARIES and layer != "engines":
            problems.append(f"line {node.lineno}: imports {name} outside the engines package")
        if not name.startswith("stewart_drake"):
            continue
        parts = name.split(".")
        target = parts[1] if len(parts) > 1 else None
        if target in (None, "errors") or layer in APP:
            pass
        elif target not in ALLOWED.get(layer, set()) | {layer}:
            problems.append(f"line {node.lineno}: {layer} imports {name} (layer {target})")
        private = [n for n in names if n.startswith("_") and not n.startswith("__")]
        if private:
            problems.append(f"line {node.lineno}: imports private {private} from {name}")
    for node in ast.walk(tree):
        if (
            isinstance(node, ast.Call)
            and isinstance(node.func, ast.Name)
            and node.func.id == "type"
            and len(node.args) == 3
        ):
            problems.append(f"line {node.lineno}: class built with type(name, bases, dict)")
    assert not problems, "\n".join(problems)
