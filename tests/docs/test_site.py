"""The documentation site builds in strict mode (``mkdocs build --strict``: a broken link or anchor, a page left
out of the nav, a public name without a docstring, a docstring warning from griffe all fail it), into a temporary
folder, without writing into the source tree or leaving anything in the temporary directory; the generated pages
hold every public name and every command option, the example notebooks executed with their figures, and every
link resolves to a file, so the site works opened from disk (``file://``)."""

from __future__ import annotations

import argparse
import importlib.util
import inspect
import re
from pathlib import Path
from urllib.parse import unquote, urlsplit

import stewart_drake
from stewart_drake.cli import COMMANDS, build_parser

ROOT = Path(__file__).resolve().parents[2]


def test_site_builds_strict_without_warnings(site):
    out, log = site
    # mkdocs' own warnings (the notebooks' kernels log "[IPKernelApp] WARNING | ..." about their local transport)
    assert re.findall(r"^WARNING\s+-.*$", log, flags=re.M) == []
    assert (out / "index.html").is_file() and (out / "api.html").is_file()


def public_names() -> list[str]:
    return [n for n in stewart_drake.__all__ if not n.startswith("__")]


def test_every_public_name_is_in_the_api_reference(site):
    """Each name of ``stewart_drake.__all__`` has its heading ``sd.NAME`` and its mkdocstrings block (the anchor
    of the object where it is defined) on the API page."""
    page = (site[0] / "api.html").read_text(encoding="utf-8")
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
        page = (site[0] / "commands" / f"{name}.html").read_text(encoding="utf-8")
        for option in options(parser):
            assert f"<code>{option}</code>" in page, (name, option)


def test_every_example_notebook_is_shown_executed(site):
    """Each notebook's page shows its cells' outputs: at least one figure (an inline PNG). A cell that raises
    fails the build (``allow_errors: false``), hence the fixture."""
    notebooks = sorted((ROOT / "notebooks").glob("*.py"))
    assert len(notebooks) >= 4
    for path in notebooks:
        page = (site[0] / "examples" / f"{path.stem}.html").read_text(encoding="utf-8")
        assert page.count("data:image/png;base64,") >= 1, path.name


HREF = re.compile(r'(?:href|src)="([^"]+)"')


def test_every_link_opens_a_file_from_disk(site):
    """Opened from disk, a link to a folder shows a directory listing: every relative ``href``/``src`` of every
    page resolves to a file of the site (and the nav's links are ``.html`` pages)."""
    out = site[0]
    pages = sorted(p for p in out.rglob("*.html") if p.name != "404.html")  # a web server's page, site-absolute
    assert len(pages) >= 30
    broken = []
    for page in pages:
        for link in HREF.findall(page.read_text(encoding="utf-8")):
            parts = urlsplit(link)
            if parts.scheme or parts.netloc or not parts.path or link.startswith("data:"):
                continue
            target = (page.parent / unquote(parts.path)).resolve()
            if not target.is_file():
                broken.append(f"{page.relative_to(out)} -> {link}")
    assert broken == []


def test_figures_are_drawn_at_build(site):
    """The prose pages show the figures the hook draws from the package (each preset's joints, the angles'
    sense, a workspace), as PNG files the pages link."""
    from stewart_drake.core.geometry import PRESETS

    presets = (site[0] / "presets.html").read_text(encoding="utf-8")
    for name in PRESETS:
        assert f'src="img/platform-{name}.png"' in presets
        assert (site[0] / "img" / f"platform-{name}.png").read_bytes().startswith(b"\x89PNG")
    assert 'src="img/convention.png"' in (site[0] / "units.html").read_text(encoding="utf-8")
    assert (site[0] / "img" / "workspace-top.png").stat().st_size > 10_000


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
        page = (site[0] / "commands" / f"{command}.html").read_text(encoding="utf-8")
        assert f'href="../api.html#{hooks.api_target(function)}"' in page, command
