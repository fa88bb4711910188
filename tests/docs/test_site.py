"""The documentation site builds in strict mode (``mkdocs build --strict``: a broken link or anchor, a page left
out of the nav, a public name without a docstring, a docstring warning from griffe all fail it), into a temporary
folder, without writing into the source tree; the generated pages hold every public name and every command
option."""

from __future__ import annotations

import argparse
import importlib.util
import inspect
import os
import subprocess
import sys
from pathlib import Path

import pytest

import stewart_drake
from stewart_drake.cli import COMMANDS, build_parser

ROOT = Path(__file__).resolve().parents[2]


def tree_state() -> str:
    r = subprocess.run(
        ["git", "status", "--porcelain", "--untracked-files=all"], cwd=ROOT, capture_output=True, text=True
    )
    return r.stdout if r.returncode == 0 else pytest.skip("not a git checkout")


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    """The site, built once in strict mode: ``(folder, the build's log)``."""
    out = tmp_path_factory.mktemp("site")
    env = {**os.environ, "PYTHONPATH": str(ROOT), "PYTHONDONTWRITEBYTECODE": "1", "NO_MKDOCS_2_WARNING": "1"}
    before = tree_state()
    r = subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(out), "--config-file", "mkdocs.yml"],
        cwd=ROOT,
        env=env,
        capture_output=True,
        text=True,
    )
    assert tree_state() == before, "the build wrote into the source tree"
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-6000:]
    return out, r.stderr


def test_site_builds_strict_without_warnings(site):
    out, log = site
    assert "WARNING" not in log
    assert (out / "index.html").is_file() and (out / "api" / "index.html").is_file()


def public_names() -> list[str]:
    return [n for n in stewart_drake.__all__ if not n.startswith("__")]


def test_every_public_name_is_in_the_api_reference(site):
    """Each name of ``stewart_drake.__all__`` has its heading ``sd.NAME`` and its mkdocstrings block (the anchor
    of the object where it is defined) on the API page."""
    page = (site[0] / "api" / "index.html").read_text(encoding="utf-8")
    assert len(public_names()) >= 15
    for n in public_names():
        obj = getattr(stewart_drake, n)
        obj = getattr(obj, "__public__", obj)  # a name shadowing a subpackage (sd.firmware): its public object
        where = obj.__name__ if inspect.ismodule(obj) else f"{obj.__module__}.{obj.__qualname__}"
        assert f'id="{where}"' in page, n
        assert f"sd.{n}" in page, n


def subparsers(parser: argparse.ArgumentParser) -> dict:
    return next(a.choices for a in parser._actions if isinstance(a, argparse._SubParsersAction))


def options(parser: argparse.ArgumentParser) -> list[str]:
    """Every option string of a parser and of its subcommands' parsers."""
    found = [s for a in parser._actions for s in a.option_strings if s not in ("-h", "--help")]
    for a in parser._actions:
        if isinstance(a, argparse._SubParsersAction):
            for sub in a.choices.values():
                found += options(sub)
    return found


def test_every_command_page_lists_every_option(site):
    commands = subparsers(build_parser())
    assert set(commands) == set(COMMANDS)
    for name, parser in commands.items():
        page = (site[0] / "commands" / name / "index.html").read_text(encoding="utf-8")
        for option in options(parser):
            assert f"<code>{option}</code>" in page, (name, option)


def test_every_example_notebook_has_a_page(site):
    notebooks = sorted((ROOT / "notebooks").glob("*.py"))
    assert len(notebooks) >= 4
    for path in notebooks:
        assert (site[0] / "examples" / path.stem / "index.html").is_file(), path.name


def load_hooks():
    spec = importlib.util.spec_from_file_location("docs_hooks", ROOT / "scripts" / "docs_hooks.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_a_public_name_without_docstring_is_reported(monkeypatch):
    """The hook's check that turns a missing docstring into a warning (hence a strict build's failure): a public
    function without one, and an undocumented method of a public class, are named; documented ones are not."""
    hooks = load_hooks()

    def bare():
        pass

    class Documented:
        """A class."""

        def method(self):
            pass

        @property
        def value(self):
            """A documented property."""
            return 1

    monkeypatch.setattr(stewart_drake, "bare", bare, raising=False)
    monkeypatch.setattr(stewart_drake, "Documented", Documented, raising=False)
    assert hooks.undocumented(["bare", "Documented"]) == ["bare", "Documented.method"]
    assert hooks.undocumented(public_names()) == []


def test_command_pages_link_their_python_function(site):
    """Each command that calls a public function links to it (the link is dropped for a name that is not
    public, so a renamed function would silently lose it: the map must name public functions only)."""
    hooks = load_hooks()
    assert set(hooks.PYTHON) <= set(COMMANDS) and set(hooks.PYTHON.values()) <= set(public_names())
    for command, function in hooks.PYTHON.items():
        page = (site[0] / "commands" / command / "index.html").read_text(encoding="utf-8")
        assert f'href="../../api/#{hooks.api_target(function)}"' in page, command
