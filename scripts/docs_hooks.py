"""MkDocs hooks (``mkdocs.yml``: ``hooks``): the pages that are generated from the sources, so that they cannot
drift from them.

- ``commands/*.md``: one reference page per ``stewart-drake`` command, its usage and every option read from the
  command's own argparse parser (``stewart_drake.cli.build_parser``);
- ``api.md``: one mkdocstrings block per name of ``stewart_drake.__all__``; a public name (or a public method or
  property of a public class) without a docstring is a warning, so ``mkdocs build --strict`` fails on it;
- ``examples/*.py``: the example notebooks (``notebooks/*.py``, jupytext percent scripts), executed and rendered
  with their outputs and figures by mkdocs-jupyter (``mkdocs.yml``: no cache, so a page never shows an earlier
  run's output; a notebook that raises fails the build);
- ``img/*.png``: the figures of the prose pages, drawn by the package at build time (each preset's joints and legs,
  the pose angles' sense, a workspace, the report section "The loop" on the 210 kg example machine, a ship drive
  cued in the loop);
- the motion-cueing page's side-by-side table (``CUEING_TABLE`` in ``motion-cueing.md``), computed at build time.
"""

from __future__ import annotations

import argparse
import importlib
import inspect
import io
import logging
from functools import partial
from pathlib import Path

import jupytext
import matplotlib
from mkdocs.plugins import event_priority
from mkdocs.structure.files import File

import stewart_drake
from stewart_drake.analyses import motion_cueing
from stewart_drake.cli import COMMANDS, build_parser

log = logging.getLogger("mkdocs.hooks.stewart_drake")
ROOT = Path(__file__).resolve().parents[1]
NOTEBOOKS = ROOT / "notebooks"
LOOP_MACHINE = ROOT / "examples" / "newcomer-210kg.yaml"  # the machine of the figures of "The loop" (loop-*.png)

# Prose pages a command's reference links to (relative to the commands/ folder).
SEE_ALSO = {
    "compile": ["../motion-language.md"],
    "run": ["../motion-language.md"],
    "size": ["../envelope-file.md", "../motion-language.md"],
    "init": ["../platform-file.md", "../envelope-file.md"],
    "montecarlo": ["../montecarlo-vary.md"],
    "firmware": ["../firmware-abi.md", "../pil-link.md"],
    "simulate": ["../firmware-abi.md"],
    "tune": ["../designing-the-loop.md"],
    "cue": ["../motion-cueing.md"],
}


# The public function each command calls (``import stewart_drake as sd``), linked from its page.
PYTHON = {
    "cross-check": "cross_check",
    "ik": "ik",
    "fk": "fk",
    "dynamics": "inverse_dynamics",
    "stiffness": "stiffness",
    "modes": "modes",
    "size": "size",
    "workspace": "workspace",
    "simulate": "simulate",
    "cue": "cue",
    "response": "loop_response",
    "tune": "tune",
    "montecarlo": "montecarlo",
    "firmware": "firmware",
    "report": "report",
}


def _cell(text: str) -> str:
    """Text safe inside a Markdown table cell."""
    return " ".join(str(text).split()).replace("|", "\\|")


def _option_rows(parser: argparse.ArgumentParser) -> list[str]:
    rows = ["| option | value | default | what |", "|---|---|---|---|"]
    for a in parser._actions:  # argparse keeps its actions here; there is no public accessor
        if isinstance(a, (argparse._HelpAction, argparse._SubParsersAction)):
            continue
        names = ", ".join(f"`{s}`" for s in a.option_strings) or f"`{a.metavar or a.dest}` (positional)"
        if a.choices is not None:
            value = " \\| ".join(f"`{c}`" for c in a.choices)
        elif a.nargs == 0:
            value = "flag"
        else:
            metavar = a.metavar if a.metavar is not None else a.dest.upper()
            if isinstance(metavar, tuple):
                metavar = " ".join(metavar)
            count = {None: "", "?": " (optional)", "*": " ...", "+": " ..."}.get(a.nargs, "")
            if isinstance(a.nargs, int) and a.nargs > 1 and not isinstance(a.metavar, tuple):
                metavar = " ".join([metavar] * a.nargs)
            value = f"`{metavar}`{count}"
        default = "" if a.default in (None, argparse.SUPPRESS, False) or a.required else f"`{a.default}`"
        if a.required:
            default = "required"
        help_text = (a.help or "") % {"default": a.default, "prog": parser.prog} if a.help else ""
        rows.append(f"| {names} | {value} | {_cell(default)} | {_cell(help_text)} |")
    return rows


def _subparsers(parser: argparse.ArgumentParser) -> dict:
    for a in parser._actions:
        if isinstance(a, argparse._SubParsersAction):
            return dict(a.choices)
    return {}


def command_page(name: str, parser: argparse.ArgumentParser) -> str:
    """The reference page of command ``name`` from its parser: usage, description, options, subcommands."""
    help_line = COMMANDS[name][1]
    out = [f"# stewart-drake {name}", "", help_line[0].upper() + help_line[1:] + ".", ""]
    out += ["```text", parser.format_usage().strip(), "```", ""]
    if parser.description:
        out += [parser.description.strip(), ""]
    module = inspect.getdoc(importlib.import_module(f"stewart_drake.commands.{COMMANDS[name][0]}")) or ""
    more = module.split("\n\n", 1)[1:]  # the module docstring past its first paragraph (the help line again)
    if more:
        out += [more[0].strip(), ""]
    function = PYTHON.get(name)
    if function and function in public_names():
        out += [f"From Python: [`sd.{function}`](../api.md#{api_target(function)}).", ""]
    subs = _subparsers(parser)
    if len(_option_rows(parser)) > 2:
        out += ["## Options", "", *_option_rows(parser), ""]
    for sub_name, sub in subs.items():
        out += [f"## {name} {sub_name}", "", "```text", sub.format_usage().strip(), "```", ""]
        if sub.description:
            out += [sub.description.strip(), ""]
        out += [*_option_rows(sub), ""]
    out += [
        "## Exit status",
        "",
        "0: the run is good; 1: a result outside physical limits (shown, with the first violation named); "
        "2: bad input, one line on stderr naming the option, file, line or field.",
        "",
    ]
    links = SEE_ALSO.get(name, [])
    if links:
        out += ["See also: " + ", ".join(f"[{Path(p).stem.replace('-', ' ')}]({p})" for p in links) + ".", ""]
    out += ["*Generated from the command's argparse parser by `scripts/docs_hooks.py`.*", ""]
    return "\n".join(out)


def commands_index() -> str:
    rows = ["| command | what |", "|---|---|"]
    rows += [f"| [`{n}`]({n}.md) | {_cell(h)} |" for n, (_, h) in COMMANDS.items()]
    return "\n".join(
        ["# Commands", "", "`stewart-drake COMMAND --help` prints the same options as these pages.", "", *rows, ""]
    )


def public_names() -> list[str]:
    """``stewart_drake.__all__`` (the public API), without ``__version__``."""
    return [n for n in getattr(stewart_drake, "__all__", []) if not n.startswith("_")]


def public_object(name: str):
    """The object behind public name ``name``: a name that is also an internal subpackage (``sd.firmware``,
    ``sd.workspace``, ...) is a shadow whose ``__public__`` is the public function or namespace module."""
    obj = getattr(stewart_drake, name)
    return getattr(obj, "__public__", obj)


def api_target(name: str) -> str:
    """Where public name ``name`` is defined (``module.qualname``, or the module's name for a namespace such as
    ``sd.firmware``): the names are loaded lazily by the package's ``__getattr__``, so mkdocstrings, which reads
    the sources statically, is pointed at their definitions."""
    obj = public_object(name)
    return obj.__name__ if inspect.ismodule(obj) else f"{obj.__module__}.{obj.__qualname__}"


def _members(obj) -> dict:
    """The public members a page shows of a class (its own attributes) or of a module (what it defines)."""
    if inspect.isclass(obj):
        return {k: v for k, v in vars(obj).items() if not k.startswith("_")}
    if inspect.ismodule(obj):
        names = getattr(obj, "__all__", None) or [k for k in vars(obj) if not k.startswith("_")]
        return {k: getattr(obj, k) for k in names if getattr(getattr(obj, k), "__module__", None) == obj.__name__}
    return {}


def undocumented(names) -> list[str]:
    """Public names, and the public methods/properties of public classes and namespaces (one level down, and
    the methods of a namespace's classes), that have no docstring of their own."""
    missing = []

    def visit(obj, shown: str, depth: int) -> None:
        target = obj.fget if isinstance(obj, property) else getattr(obj, "__func__", obj)
        if not (callable(target) or inspect.ismodule(target) or isinstance(obj, property)):
            return  # a field or constant: documented by its class's docstring
        if not (getattr(target, "__doc__", None) or "").strip():
            missing.append(shown)
        if depth < 2:
            for attr, member in _members(target).items():
                visit(member, f"{shown}.{attr}", depth + 1)

    for n in names:
        visit(public_object(n), n, 0)
    return missing


def api_page(names) -> str:
    out = [
        "# API reference",
        "",
        "`import stewart_drake as sd`: every name of `sd.__all__`, SI units (m, rad, s, N, kg) unless an argument "
        "says otherwise. See [units and conventions](units.md).",
        "",
    ]
    if "__version__" in getattr(stewart_drake, "__all__", []):
        out += ["`sd.__version__`: the package's version (a string).", ""]
    for n in names:
        out += [f"::: {api_target(n)}", "    options:", f'      heading: "sd.{n}"', ""]
    return "\n".join(out)


def examples_index(paths) -> str:
    rows = ["| notebook | what |", "|---|---|"]
    for path in paths:
        nb = jupytext.read(path)
        title = next((c.source.splitlines()[0].lstrip("# ") for c in nb.cells if c.cell_type == "markdown"), path.stem)
        rows.append(f"| [`{path.name}`]({path.name}) | {_cell(title)} |")
    return "\n".join(
        [
            "# Examples",
            "",
            "Notebooks written as jupytext percent scripts in `notebooks/`, shown here as they ran when this site "
            "was built, outputs and figures included. Open one as a notebook with `jupyter lab` (after `pip install "
            "jupyterlab`; jupytext's extension opens `notebooks/*.py` as notebooks: right-click, *Open With → "
            "Notebook*), convert it with `jupytext --to notebook --execute notebooks/NAME.py`, or run it as a "
            "script: `python notebooks/NAME.py`. They write only into a temporary folder that they remove.",
            "",
            *rows,
            "",
        ]
    )


def on_config(config):
    """Expand the nav's ``Commands`` and ``Examples`` entries into one page per command and notebook."""
    generated = {
        "commands/index.md": ["commands/index.md", *(f"commands/{n}.md" for n in COMMANDS)],
        "examples/index.md": ["examples/index.md", *(f"examples/{p.stem}.py" for p in sorted(NOTEBOOKS.glob("*.py")))],
    }
    for entry in config["nav"]:
        if isinstance(entry, dict):
            for title, target in entry.items():
                if isinstance(target, str) and target in generated:
                    entry[title] = generated[target]
    return config


def figures() -> dict[str, bytes]:
    """The prose pages' figures, ``{site path: PNG}``, drawn by the package itself."""
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from stewart_drake import workspace as ws
    from stewart_drake.analyses.the_loop import docs_figures
    from stewart_drake.core.geometry import PRESETS, load_preset
    from stewart_drake.design.drawings import convention_figure, platform_figure
    from stewart_drake.report.subject import from_machine_file
    from stewart_drake.workspace.views import view_figures

    def png(fig) -> bytes:
        buf = io.BytesIO()
        fig.savefig(buf, format="png", dpi=90)
        plt.close(fig)
        return buf.getvalue()

    out = {f"img/platform-{name}.png": png(platform_figure(load_preset(name))) for name in PRESETS}
    ship = stewart_drake.cue("gonzalez-dutra-2009", CUEING_DRIVE(), algorithm="tuned", simulate=True)
    out["img/cueing-perception.png"] = png(ship.plot())
    out["img/cueing-legs.png"] = png(ship.plot_legs())
    gd = load_preset("gonzalez-dutra-2009")
    out["img/convention.png"] = png(convention_figure(gd))
    views = view_figures(ws.constant_orientation_workspace(gd, resolution=0.02), title="gonzalez-dutra-2009")
    for name, fig in views.items():
        out[f"img/workspace-{name}.png"] = png(fig)
    for name, fig in docs_figures(from_machine_file(LOOP_MACHINE)).items():
        out[f"img/loop-{name}.png"] = png(fig)
    return out


# The marker in motion-cueing.md that the side-by-side table replaces, its drives (20 s of each sea state, as in the
# ship notebook: the build stays quick) and the drive of the page's figures.
CUEING_TABLE = "<!-- cueing-table -->"
CUEING_DRIVES = [partial(stewart_drake.ship_drive, s, 20.0, seed=s) for s in (3, 4, 5, 6)]
CUEING_DRIVE = CUEING_DRIVES[2]
CUEING_BUDGET = 128  # the tuning's evaluations: one generation (the report's full section runs tune_classical's 400)


def cueing_table() -> str:
    """The motion-cueing page's table: hand-set and tuned classical washout and MPC on gonzalez-dutra-2009, per ship
    drive, the commanded motion's scores (``analyses.motion_cueing.score_table``)."""
    machine = stewart_drake.load_machine("gonzalez-dutra-2009")
    runs = motion_cueing.cue_runs(machine, [d() for d in CUEING_DRIVES], simulate=False, budget=CUEING_BUDGET)
    header, rows = motion_cueing.score_table(runs, plant=False)
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    for r in rows:
        lines.append("| " + " | ".join(v if isinstance(v, str) else f"{v:.3g}" for v in r) + " |")
    return "\n".join(lines)


def on_page_markdown(markdown, page, config, files):
    """Fill in the computed parts of a prose page (the motion-cueing table)."""
    if CUEING_TABLE in markdown:
        return markdown.replace(CUEING_TABLE, cueing_table())
    return markdown


@event_priority(100)  # before mkdocs-jupyter's on_files, which turns the notebooks added here into pages
def on_files(files, config):
    """Add the generated pages and figures, and the example notebooks, to the site."""
    parser = build_parser()
    commands = _subparsers(parser)
    files.append(File.generated(config, "commands/index.md", content=commands_index()))
    for name in COMMANDS:
        files.append(File.generated(config, f"commands/{name}.md", content=command_page(name, commands[name])))
    names = public_names()
    if not names:
        log.warning("stewart_drake.__all__ is missing or empty: the API reference would be empty")
    for n in undocumented(names):
        log.warning(f"public name without a docstring: stewart_drake.{n}")
    files.append(File.generated(config, "api.md", content=api_page(names)))
    notebooks = sorted(NOTEBOOKS.glob("*.py"))
    files.append(File.generated(config, "examples/index.md", content=examples_index(notebooks)))
    for path in notebooks:
        files.append(File.generated(config, f"examples/{path.name}", abs_src_path=str(path)))
    for name, data in figures().items():
        files.append(File.generated(config, name, content=data))
    return files
