"""The package sources a report section can depend on: the import closure of its analysis script.

A section's numbers and figures come from its analysis and the ``stewart_drake`` modules it imports, directly
or not, at module level or inside a function; a module imported also runs its parent packages' ``__init__``.
The closure over those edges is what the result cache keys a section on (``report.cache``), so that an edit of
a module no analysis of a section reaches leaves that section's entry valid. Data files (presets, C sources,
grammars) are not followed: the cache keys every section on all of them.

The edges are read from the source text (``import_targets``: a line scan, ~20× faster than parsing every file:
0.03 s against 0.5 s for the package's 243 files, which the parent process pays on every report) and resolved
against the package's modules:

- ``import a.b.c`` and ``from a.b import c`` reach ``a``, ``a.b`` and ``a.b.c`` where each is a module;
- ``from stewart_drake import name`` reaches ``name``'s defining module (the lazy public API, ``_PUBLIC``), and
  an import that binds the top package to a name (``import stewart_drake as sd``, ``import stewart_drake.x``,
  then ``sd.simulate``) every module of that API;
- imports under ``if TYPE_CHECKING:`` are skipped (they never run).

The scan may over-read (an ``import`` line inside a string adds an edge: a needless recomputation, never a
stale entry); what it must not do is miss an import: ``tests/report/test_code_deps.py`` checks that it finds
every import Python's own parser finds in every package file, and that the package imports modules by
computed name only where these rules cover it (the lazy API, the CLI's commands, the report's analyses).
"""

from __future__ import annotations

import re
from functools import cache
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1]
TOP = PACKAGE.name

_IMPORT = re.compile(
    r"^[ \t]*(?:from[ \t]+(?P<base>\.*[\w.]*)[ \t]+import[ \t]+(?P<names>\([^)]*\)|[^\n#;]*)"
    r"|import[ \t]+(?P<modules>[^\n#;]*))",
    re.M,
)
_TYPE_CHECKING = re.compile(r"^([ \t]*)if[ \t]+(?:typing\.)?TYPE_CHECKING[ \t]*:[ \t]*(?:#.*)?$")


def _without_type_checking(text: str) -> str:
    """``text`` without the bodies of its ``if TYPE_CHECKING:`` blocks (the lines indented deeper than the
    ``if``, blank lines included)."""
    if "TYPE_CHECKING" not in text:
        return text
    out, depth = [], None
    for line in text.splitlines():
        if depth is not None:
            stripped = line.strip()
            if not stripped or len(line) - len(line.lstrip()) > depth:
                continue
            depth = None
        m = _TYPE_CHECKING.match(line)
        if m:
            depth = len(m.group(1).expandtabs())
            continue
        out.append(line)
    return "\n".join(out)


def import_targets(text: str, package: str) -> set[tuple[str, tuple[str, ...]]]:
    """The imports of module source ``text`` (its package ``package``, for relative imports): ``(module,
    names)`` per statement, ``names`` the from-imported names (``()`` for ``import module``; ``("",)`` for
    ``import a.b``, which binds ``a``, and for ``import stewart_drake as sd``)."""
    found = set()
    for m in _IMPORT.finditer(_without_type_checking(text)):
        if m.group("modules") is not None:
            for item in m.group("modules").split(","):
                words = item.split()
                if words:  # binding the top package's name, or the top package under another name
                    found.add((words[0], ("",) if len(words) == 1 or words[0] == TOP else ()))
            continue
        base = m.group("base")
        dots = len(base) - len(base.lstrip("."))
        if dots:
            parent = package.split(".")[: len(package.split(".")) - dots + 1]
            base = ".".join(parent + ([base[dots:]] if base[dots:] else []))
        listed = re.sub(r"#[^\n]*", "", m.group("names")).strip("()").replace("\\", " ")
        names = tuple(item.split()[0] for item in listed.split(",") if item.split())
        found.add((base, names))
    return found


def module_name(path: Path, root: Path = PACKAGE) -> str:
    """The dotted name of package file ``path`` under ``root`` (``a/b/__init__.py`` is ``a.b``)."""
    parts = (root.name, *path.relative_to(root).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


@cache
def _modules(root: Path) -> dict[str, Path]:
    """Every module of the package under ``root`` by dotted name."""
    return {module_name(p, root): p for p in sorted(root.rglob("*.py")) if "__pycache__" not in p.parts}


def all_sources(root: Path = PACKAGE) -> list[Path]:
    """Every package source under ``root``, sorted: what a section of unknown imports can depend on."""
    return sorted(_modules(root).values())


@cache
def _public(root: Path) -> dict[str, str]:
    """The lazy public API of the top package: public name -> the module that defines it (its ``_PUBLIC`` table,
    read from the source: the scan imports nothing)."""
    text = (root / "__init__.py").read_text()
    table = text[text.index("_PUBLIC = {") : text.index("\n}\n", text.index("_PUBLIC = {"))]
    return dict(re.findall(r'"(\w+)": \("([\w.]+)", ', table))


def resolve(targets, root: Path = PACKAGE) -> set[str]:
    """The package modules that imports ``targets`` (``import_targets``' form) reach (see the module docstring)."""
    modules, public, top = _modules(root), _public(root), root.name
    out = set()

    def reach(name: str) -> None:
        parts = name.split(".")
        out.update(q for q in (".".join(parts[: i + 1]) for i in range(len(parts))) if q in modules)

    for base, names in targets:
        if base != top and not base.startswith(top + "."):
            continue
        reach(base)
        for n in names:
            if n == "" or n == "*" and base == top:  # the top name bound (sd.<anything>): the whole lazy API
                for module in public.values():
                    reach(module)
                continue
            if f"{base}.{n}" in modules:  # a submodule (also a public name: ``from stewart_drake import workspace``)
                reach(f"{base}.{n}")
            if base == top and n in public:
                reach(public[n])
    return out


def package_of(name: str, path: Path) -> str:
    """The package that relative imports in module ``name`` (file ``path``) start from."""
    return name if path.name == "__init__.py" else name.rpartition(".")[0]


@cache
def _graph(root: Path) -> dict[str, frozenset[str]]:
    """Per package module, the package modules it imports."""
    modules = _modules(root)
    return {n: frozenset(resolve(import_targets(p.read_text(), package_of(n, p)), root)) for n, p in modules.items()}


def closure(path: Path, root: Path = PACKAGE) -> list[Path]:
    """The package sources (sorted) that the script at ``path`` reaches by imports, itself included when it
    lies in the package: what its section can depend on besides data files."""
    path = Path(path).resolve()
    modules, graph = _modules(root), _graph(root)
    if root in path.parents:
        todo = [module_name(path, root)]
        todo += [n for n in modules if todo[0].startswith(n + ".")]  # its parent packages run first
    else:
        todo = sorted(resolve(import_targets(path.read_text(), ""), root))
    seen: set[str] = set()
    while todo:
        name = todo.pop()
        if name not in seen:
            seen.add(name)
            todo += graph[name]
    return sorted(modules[n] for n in seen)
