"""A report section's code (``report.code_deps``): the import closure of its analysis. A miss in it would serve
a stale section from the cache, so the line scan is held to Python's own parser over every package file, the
package's imports by computed name are pinned to the ones the rules cover, and the closure is held to the
modules an analysis really loads; an edit then changes the code version of exactly the sections reaching it."""

from __future__ import annotations

import ast
import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from stewart_drake.report import cache, code_deps
from stewart_drake.report.code_deps import PACKAGE, closure, import_targets, module_name, package_of, resolve

ANALYSES = sorted((PACKAGE / "analyses").glob("[!_]*.py"))


def _forget() -> None:
    """Forget the memoised reads of the package (a test edits a copy of it)."""
    for f in (cache._package_digest, cache.data_version, cache.code_version):
        f.cache_clear()
    for f in (code_deps._modules, code_deps._public, code_deps._graph):
        f.cache_clear()


def _parsed_targets(text: str, package: str) -> set:
    """``import_targets`` by Python's parser: every Import/ImportFrom node outside ``if TYPE_CHECKING:``."""
    found = set()

    def visit(node) -> None:
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
            for child in node.orelse:
                visit(child)
            return
        if isinstance(node, ast.Import):
            for a in node.names:
                found.add((a.name, ("",) if not a.asname or a.name == "stewart_drake" else ()))
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parent = package.split(".")[: len(package.split(".")) - node.level + 1]
                base = ".".join(parent + ([base] if base else []))
            found.add((base, tuple(a.name for a in node.names)))
        for child in ast.iter_child_nodes(node):
            visit(child)

    visit(ast.parse(text))
    return found


def test_the_line_scan_finds_every_import_the_parser_finds():
    """Every package file: the modules its imports reach by the line scan include those by ``ast`` (the scan
    may over-read: an example in a docstring)."""
    for path in sorted(PACKAGE.rglob("*.py")):
        name = module_name(path)
        text = path.read_text()
        scanned, parsed = import_targets(text, package_of(name, path)), _parsed_targets(text, package_of(name, path))
        assert parsed <= scanned and resolve(parsed) <= resolve(scanned), path


def test_the_scan_reads_the_forms_of_import():
    text = (
        "import os, stewart_drake.core.kinematics as K\n"
        "from . import geometry\n"
        "from ..report import (\n    parallel_map,\n    run_standalone,  # both\n)\n"
        "def f():\n    from stewart_drake.design.stiffness import geometric_load_term\n"
        "if typing.TYPE_CHECKING:\n    from stewart_drake.api.simulation import simulate\n\n    import x\n"
        "y = 1\n"
    )
    assert import_targets(text, "stewart_drake.core") == {
        ("os", ("",)),
        ("stewart_drake.core.kinematics", ()),
        ("stewart_drake.core", ("geometry",)),
        ("stewart_drake.report", ("parallel_map", "run_standalone")),
        ("stewart_drake.design.stiffness", ("geometric_load_term",)),
    }
    reached = resolve(import_targets(text, "stewart_drake.core"))
    assert {"stewart_drake", "stewart_drake.core.geometry", "stewart_drake.design.stiffness"} <= reached
    assert "stewart_drake.api.simulation" not in reached  # only under TYPE_CHECKING
    # the lazy public API: a name reaches its module; the bound top name reaches every module of the API
    import stewart_drake

    assert code_deps._public(PACKAGE) == {name: module for name, (module, _) in stewart_drake._PUBLIC.items()}
    assert "stewart_drake.api.simulation" in resolve({("stewart_drake", ("simulate",))})
    assert "stewart_drake.synthesis.api" in resolve({("stewart_drake", ("",))})


def test_imports_by_computed_name_are_only_where_the_rules_cover_them():
    """The lazy API (``stewart_drake/__init__``: covered by the public-name rule), the CLI's commands (no
    analysis reaches the CLI) and the report's analysis loader (an analysis loads itself)."""
    dynamic = re.compile(r"import_module\(|__import__\(|spec_from_file_location\(|runpy|exec_module\(")
    sites = {str(p.relative_to(PACKAGE)) for p in PACKAGE.rglob("*.py") if dynamic.search(p.read_text())}
    assert sites == {"__init__.py", "cli.py", "report/__init__.py"}
    for path in ANALYSES:
        assert PACKAGE / "cli.py" not in closure(path), path.name


# In a fresh interpreter: load each analysis as the report's workers do, build the cheap ones (quick), and list
# the package modules then loaded.
LOADED = """
import json, sys
from pathlib import Path
import matplotlib
matplotlib.use("Agg")
from stewart_drake.report import build_section, load_analysis, loaded, parts
parts.IN_WORKER = True
a = load_analysis(Path(sys.argv[1]))
loaded(a.path)
if sys.argv[2] == "build":
    build_section(a, quick=True)
print(json.dumps(sorted(m for m in sys.modules if m == "stewart_drake" or m.startswith("stewart_drake."))))
"""
BUILT = {"seed_table", "leg", "drake_kinematics", "servo"}  # a few seconds together


def test_the_closure_holds_every_module_an_analysis_loads():
    procs = {
        p: subprocess.Popen(
            [sys.executable, "-c", LOADED, str(p), "build" if p.stem in BUILT else "import"],
            stdout=subprocess.PIPE,
            text=True,
            env={**os.environ, "MPLBACKEND": "Agg", "OPENBLAS_NUM_THREADS": "1"},
        )
        for p in ANALYSES
    }
    for path, proc in procs.items():
        out, _ = proc.communicate(timeout=600)
        assert proc.returncode == 0, path
        sources = {module_name(p) for p in closure(path)}
        assert set(json.loads(out)) <= sources, (path.name, set(json.loads(out)) - sources)


@pytest.fixture
def package_copy(tmp_path):
    """A copy of the package's sources and data (no bytecode) to edit, with the memoised reads forgotten."""
    root = tmp_path / "stewart_drake"
    shutil.copytree(PACKAGE, root, ignore=shutil.ignore_patterns("__pycache__", "*.so", "*.pyc"))
    yield root
    _forget()


def _versions(root: Path) -> dict:
    _forget()
    return {name: cache.code_version(root / "analyses" / f"{name}.py", root) for name in ("seed_table", "synthesis")}


def test_an_edit_changes_the_code_version_of_the_sections_that_reach_it_only(package_copy):
    root = package_copy
    assert (root / "synthesis" / "search.py") in closure(root / "analyses" / "synthesis.py", root)
    assert (root / "synthesis" / "search.py") not in closure(root / "analyses" / "seed_table.py", root)
    v0 = _versions(root)
    with open(root / "synthesis" / "search.py", "a") as f:
        f.write("\n# edited\n")
    v1 = _versions(root)
    assert v1["synthesis"] != v0["synthesis"] and v1["seed_table"] == v0["seed_table"]
    with open(root / "report" / "render.py", "a") as f:  # the report's own code: every section
        f.write("\n# edited\n")
    v2 = _versions(root)
    assert v2["synthesis"] != v1["synthesis"] and v2["seed_table"] != v1["seed_table"]
    preset = next((root / "presets").glob("*.yaml"))
    preset.write_text(preset.read_text() + "\n# edited\n")  # a data file: every section
    v3 = _versions(root)
    assert v3["synthesis"] != v2["synthesis"] and v3["seed_table"] != v2["seed_table"]
    (root / "__pycache__").mkdir(exist_ok=True)
    (root / "__pycache__" / "x.cpython-312.pyc").write_bytes(b"\0")  # bytecode is not code
    assert _versions(root) == v3


def test_a_script_outside_the_package_reaches_what_it_imports(tmp_path):
    script = tmp_path / "mine.py"
    script.write_text("from stewart_drake.core.geometry import load_preset\nTITLE = 'mine'\n")
    sources = closure(script)
    assert PACKAGE / "core" / "geometry.py" in sources and PACKAGE / "synthesis" / "search.py" not in sources
    script.write_text("import stewart_drake as sd\n")  # sd.<anything>: the whole public API
    assert PACKAGE / "synthesis" / "api.py" in closure(script)
