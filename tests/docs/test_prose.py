"""The prose pages of the documentation site say what the code does: every motion program on the motion-language
page parses, checks and runs; every ``--vary`` value on the Monte Carlo page parses to the law the page states;
the firmware ABI page's prototypes are those of a generated header; the envelope template of ``init`` sizes the
radial template's platform."""

from __future__ import annotations

import json
import re
import shlex
from pathlib import Path

import numpy as np
import pytest

from stewart_drake.core.geometry import load_preset
from stewart_drake.script import Motion, compile_program, execute, parse, run_program

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"


def fenced(page: str, language: str) -> list[str]:
    """The bodies of the fenced code blocks of ``page`` in ``language``."""
    text = (DOCS / page).read_text(encoding="utf-8")
    return re.findall(rf"^```{language}\n(.*?)^```$", text, flags=re.S | re.M)


MOTION_BLOCKS = fenced("motion-language.md", "stw")


def test_motion_language_page_has_examples():
    assert len(MOTION_BLOCKS) >= 6


@pytest.mark.parametrize("k", range(len(MOTION_BLOCKS)))
def test_motion_language_examples_run(k):
    """Each program parses, passes the static checks and runs on utn-kinematic (the page's preset) with every
    sample inside the stroke (run_program raises a ScriptError otherwise)."""
    platform = load_preset("utn-kinematic")
    result = run_program(MOTION_BLOCKS[k], f"motion-language-{k}.stw", platform)
    lo, hi = platform.stroke
    assert result.trajectory.t[-1] > 0 and np.all((result.L >= lo) & (result.L <= hi))


def test_motion_language_expression_comments_hold():
    """The values the page's comments give for its expression example (``DIV``, ``MOD``, ``atan2``)."""
    block = next(b for b in MOTION_BLOCKS if "DIV" in b)
    _, motion = compile_program(block, "expressions.stw", load_preset("utn-kinematic"))
    env = execute(parse(block, "expressions.stw"), Motion.at_home(load_preset("utn-kinematic")))
    for line in block.splitlines():
        m = re.match(r"(\w+)\s*:?=.*//\s*([-\d.]+)", line)
        if m:
            assert env[m.group(1)] == pytest.approx(float(m.group(2)), rel=1e-12), line
    assert motion.segments[-1].values == pytest.approx((40, 0, 220, 0, 0, 15))


def test_envelope_template_sizes_the_radial_template(tmp_path, capsys):
    """``init --envelope-template`` prints an envelope that loads and that ``size`` accepts on the platform of
    ``init --platform-template radial`` (exit 0: every pose in stroke, no limit exceeded), with the pose count
    its comment promises (3^6)."""
    from stewart_drake.cli import main

    assert main(["init", "--platform-template", "radial"]) == 0
    (tmp_path / "my.yaml").write_text(capsys.readouterr().out)
    assert main(["init", "--envelope-template"]) == 0
    text = capsys.readouterr().out
    assert text.startswith("# A stewart-drake duty envelope") and "3^6 = 729 poses" in text
    (tmp_path / "duty.yaml").write_text(text)
    rc = main(["size", "--platform", str(tmp_path / "my.yaml"), "--envelope", str(tmp_path / "duty.yaml"), "--json"])
    out = json.loads(capsys.readouterr().out)
    assert rc == 0 and out["violation"] is None and out["poses"] == 729
    assert all(leg["peak_force_n"] > 0 for leg in out["legs"])


def test_init_needs_exactly_one_template(capsys):
    from stewart_drake.cli import main

    assert main(["init"]) == 2
    assert main(["init", "--envelope-template", "--platform-template", "utn"]) == 2
    err = capsys.readouterr().err
    assert (
        "one of the arguments --platform-template --machine-template --envelope-template --requirements-template "
        "is required" in err
    )
    assert "not allowed with argument" in err


def vary_rows() -> list[tuple[str, str, list[str]]]:
    text = (DOCS / "montecarlo-vary.md").read_text(encoding="utf-8")
    rows = re.findall(r"^\| `(\w+=[^`]+)` \| (\w+) \| ([^|]+(?:\\\|[^|]+)*) \|$", text, flags=re.M)
    return [(word.replace("\\|", "|"), kind, [v.strip() for v in values.split(",")]) for word, kind, values in rows]


def test_vary_page_has_examples_for_every_key():
    from stewart_drake.montecarlo.spec import KEYS

    assert {w.split("=")[0] for w, _, _ in vary_rows()} == set(KEYS)


@pytest.mark.parametrize("word, kind, values", vary_rows())
def test_vary_examples_parse_to_the_stated_law(word, kind, values):
    from stewart_drake.montecarlo.spec import parse_spec

    law = parse_spec([word]).laws[word.split("=")[0]]
    assert law.kind == kind
    got = [v if isinstance(v, str) else float(v) for v in law.values]
    want = [v if v.isalpha() else float(v) for v in values]
    assert got == want  # exact: units scale in decimal, so "10um" is the float nearest 1e-05


def test_vary_yaml_example_parses(tmp_path):
    from stewart_drake.montecarlo.spec import parse_spec

    (block,) = fenced("montecarlo-vary.md", "yaml")
    (tmp_path / "spec.yaml").write_text(block)
    spec = parse_spec([str(tmp_path / "spec.yaml")])
    assert spec.to_dict() == dict(line.split(": ", 1) for line in block.strip().splitlines())


@pytest.mark.parametrize("word_bits", [16, 12])
def test_firmware_abi_page_matches_a_generated_header(word_bits):
    """Every declaration in the page's C blocks, and every ``sd_state`` field of its table, is in the header that
    ``firmware generate`` writes (for two word sizes: the ABI does not change with the format)."""
    from stewart_drake.control import ControllerConfig, DspTiming
    from stewart_drake.firmware.generate import generate
    from stewart_drake.fixedpoint.generic import QFormat

    platform = load_preset("utn-dynamic")
    config = ControllerConfig.for_platform(platform, DspTiming(), ik_format=QFormat(word_bits=word_bits))
    header = " ".join(generate(platform, config).files["sd_firmware.h"].split())
    declarations = [line for block in fenced("firmware-abi.md", "c") for line in block.splitlines() if line.strip()]
    assert len(declarations) == 6
    for line in declarations:
        assert " ".join(line.split()) in header, line
    text = (DOCS / "firmware-abi.md").read_text(encoding="utf-8")
    fields = re.findall(r"^\| `(\w+)\[6\]` \| `(\w+)` \|", text, flags=re.M)
    assert len(fields) == 6
    for name, ctype in fields:
        assert f"{ctype} {name}[6];" in header, name
    for macro in ("SD_WORD_BITS", "SD_FRAC_BITS", "SD_TRACE_WORDS", "SD_OP_NAMES"):
        assert f"#define {macro}" in header


def shell_commands(page: str) -> list[list[str]]:
    """The ``stewart-drake`` lines of the page's bash blocks, as argument lists (comments dropped), also those run
    through ``bash scripts/with-venv``."""
    lines = [ln.removeprefix("bash scripts/with-venv ") for block in fenced(page, "bash") for ln in block.splitlines()]
    return [shlex.split(ln.split(" #")[0]) for ln in lines if ln.startswith("stewart-drake ")]


def test_getting_started_commands_run(tmp_path, monkeypatch, capsys):
    """Every command of the getting-started page, in order, in an empty folder (``> FILE`` redirects): each exits
    0, i.e. the templates load, the poses are in stroke and the lengths assemble."""
    from stewart_drake.cli import main

    monkeypatch.chdir(tmp_path)
    commands = shell_commands("getting-started.md")
    assert len(commands) >= 8
    for argv in commands:
        target = argv[argv.index(">") + 1] if ">" in argv else None
        argv = argv[1 : argv.index(">")] if target else argv[1:]
        if argv[0] in ("--help",):
            continue
        rc = main(argv)
        out = capsys.readouterr().out
        assert rc == 0, argv
        if target:
            Path(target).write_text(out)
    # then the Python of this page and of the envelope page, on the files the commands wrote
    for block in fenced("getting-started.md", "python") + fenced("envelope-file.md", "python"):
        exec(compile(block, "docs", "exec"), {})
    printed = capsys.readouterr().out
    assert "True" in printed and "N peak on leg 1" in printed


def python_blocks() -> list[tuple[str, str]]:
    return [(p.name, b) for p in sorted(DOCS.glob("*.md")) for b in fenced(p.name, "python")]


@pytest.mark.parametrize("page, block", python_blocks())
def test_python_snippets_call_public_names_with_real_keywords(page, block):
    """Every ``sd.NAME(...)`` (and ``sd.NAME.method(...)``) in the pages' Python is a public name, called with
    keywords its signature has: a snippet cannot drift from the API unnoticed, even where it is not run."""
    import ast
    import inspect

    import stewart_drake as sd

    calls = 0
    for node in ast.walk(ast.parse(block)):
        if not isinstance(node, ast.Call) or not isinstance(node.func, ast.Attribute):
            continue
        chain, value = [node.func.attr], node.func.value
        while isinstance(value, ast.Attribute):
            chain.insert(0, value.attr)
            value = value.value
        if not (isinstance(value, ast.Name) and value.id == "sd"):
            continue
        assert chain[0] in sd.__all__, (page, chain)
        obj = sd
        for name in chain:
            obj = getattr(obj, name)
        params = inspect.signature(obj).parameters
        if not any(p.kind is p.VAR_KEYWORD for p in params.values()):
            for kw in node.keywords:
                assert kw.arg in params, (page, ".".join(chain), kw.arg)
        calls += 1
    assert calls >= 1, page


def test_readme_python_runs_and_is_short():
    """The README's Python runs as written, and the README stays a two-minute read (the rest is on the site)."""
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    blocks = re.findall(r"^```python\n(.*?)^```$", readme, flags=re.S | re.M)
    assert blocks
    for block in blocks:
        exec(compile(block, "README.md", "exec"), {})
    assert len(readme.splitlines()) <= 60
    assert readme.count("```bash") == 1 and "stewart-drake report" in readme and "python -m pytest" in readme
