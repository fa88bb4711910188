"""Property tests over input files: platform YAML (valid trees mutated into wrong types, NaN/inf,
huge numbers, unknown keys, aliases, tags, raw byte noise), CSV files (BOM, widths, text, huge
fields, bad bytes) and program text (generated from the Lark grammar, and mutated examples). Every
run keeps ``_fuzz.check_run``'s invariants; a platform that loads gives well-formed SDF XML."""

from __future__ import annotations

import re
import shutil
import xml.parsers.expat

import yaml
from hypothesis import assume, given
from hypothesis import strategies as st
from hypothesis.extra.lark import from_lark

from stewart_drake.script.parser import _lark
from tests.cli._fuzz import PLATFORM_TEMPLATE, PROGRAM, ci, fuzz, run_and_check, scratch

BASE = yaml.safe_load(PLATFORM_TEMPLATE)

# ----------------------------------------------------------------------------------------------
# YAML trees.

LEAVES = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.integers(min_value=-(10**400), max_value=10**400),
    st.sampled_from(
        [
            0,
            -1,
            1e300,
            -1e-300,
            1e6,
            0.5,
            700.0,
            2**63,
            True,
            False,
            None,
            "",
            "big",
            "nan",
            "1e3",
            "../../x",
            'evil"><!--',
            "a::b",
            "m",
            "mm",
            "inch",
            "\u00e9",
            "x" * 300,
        ]
    ),
    st.text(max_size=20),
)


def paths(tree, prefix=()):
    """Every (path, value) in a nested dict/list tree."""
    yield prefix, tree
    if isinstance(tree, dict):
        for k, v in tree.items():
            yield from paths(v, prefix + (k,))
    elif isinstance(tree, list):
        for i, v in enumerate(tree):
            yield from paths(v, prefix + (i,))


def set_at(tree, path, value):
    if not path:
        return value
    node = tree
    for p in path[:-1]:
        node = node[p]
    node[path[-1]] = value
    return tree


@st.composite
def platform_trees(draw):
    """The template's tree with 0..4 mutations: a value replaced (by a leaf, a list or a mapping), a
    key removed, an unknown key added, a list lengthened or shortened."""
    import copy

    tree = copy.deepcopy(BASE)
    for _ in range(draw(st.integers(0, 4))):
        where = draw(st.sampled_from(list(paths(tree))))
        path, value = where
        kind = draw(st.integers(0, 5))
        if kind <= 1:
            tree = set_at(tree, path, draw(LEAVES))
        elif kind == 2 and path:
            parent = tree
            for p in path[:-1]:
                parent = parent[p]
            if isinstance(parent, dict):
                del parent[path[-1]]
            elif isinstance(parent, list):
                parent.pop(path[-1])
        elif kind == 3 and isinstance(value, dict):
            value[draw(st.sampled_from(["strok", "mass", "colour", "Name", "b", "legs"]))] = draw(LEAVES)
        elif kind == 4 and isinstance(value, list):
            value.append(draw(LEAVES) if not value else value[-1])
        else:
            tree = set_at(tree, path, draw(st.sampled_from([[], {}, [1, 2], {"a": 1}, [[1, 2, 3]] * 6])))
    return tree


def dump(tree) -> str:
    try:
        return yaml.safe_dump(tree, allow_unicode=True, default_flow_style=None)
    except (ValueError, OverflowError, yaml.YAMLError):
        return "name: x\n"


TEXT_TWEAKS = [
    lambda s: s,
    lambda s: "a: &a [1, 2, 3]\nb: [*a, *a]\n" + s,
    lambda s: s.replace("stroke:", "stroke: !!python/tuple"),
    lambda s: s + "\nutn: &u {b: 0.4, d: 0.1, a: 0.2}\n",
    lambda s: "\ufeff" + s,
    lambda s: s.replace("0.", ".nan #", 1),
    lambda s: s[: len(s) // 2],
    lambda s: s + "\n" + "  " * 3 + "- [" * 40,
    lambda s: s.replace(":", "", 1),
]


def well_formed(text: str) -> None:
    p = xml.parsers.expat.ParserCreate()
    p.Parse(text, True)


def check_platform(text: str, extra: bytes = b"") -> None:
    d = scratch()
    try:
        (d / "p.yaml").write_bytes(text.encode("utf-8", "surrogatepass") + extra)
        rc, out, err = run_and_check(
            ["ik", "--platform", "p.yaml", "--pose", "0", "0", "700", "0", "0", "0", "--json"], d
        )
        if rc == 2:
            assert err.startswith("stewart-drake ik: error: p.yaml") or "pose" in err or "platform" in err, err
        else:
            rc2, sdf, err2 = run_and_check(["model", "--platform", "p.yaml"], d)
            if rc2 == 0:
                well_formed(sdf)
    finally:
        shutil.rmtree(d, ignore_errors=True)


yaml_inputs = st.tuples(
    platform_trees(), st.sampled_from(range(len(TEXT_TWEAKS))), st.sampled_from([b"", b"\0", b"\xff\xfe", b"\x1b[0m"])
)


@ci(60)
@given(yaml_inputs)
def test_platform_yaml(case):
    tree, tweak, extra = case
    check_platform(TEXT_TWEAKS[tweak](dump(tree)), extra)


@fuzz
@given(yaml_inputs)
def test_platform_yaml_fuzz(case):
    tree, tweak, extra = case
    check_platform(TEXT_TWEAKS[tweak](dump(tree)), extra)


# ----------------------------------------------------------------------------------------------
# CSV files.

CELLS = st.one_of(
    st.sampled_from(["0", "100", "0.7", "-5", "1e3", "nan", "inf", "", " ", "abc", '"1,2"', "1e400", "0x1"]),
    st.floats(allow_nan=False, allow_infinity=False, min_value=-1e3, max_value=1e3).map(repr),
    st.text(max_size=5),
)


@st.composite
def csv_files(draw):
    rows = draw(st.lists(st.lists(CELLS, min_size=0, max_size=20), min_size=0, max_size=12))
    sep = draw(st.sampled_from([",", ";", "\t"]))
    body = "\n".join(sep.join(r) for r in rows)
    data = body.encode("utf-8", "surrogatepass")
    prefix = draw(st.sampled_from([b"", b"\xef\xbb\xbf", b"t,px,py,pz,a,b,g\n"]))
    suffix = draw(st.sampled_from([b"", b"\n", b"\xff", b"\0", b"\n" + b"9" * 140_000]))
    return prefix + data + suffix


def check_csv(data: bytes, command: str) -> None:
    d = scratch()
    try:
        (d / "f.csv").write_bytes(data)
        argv = {
            "ik": ["ik", "--poses", "f.csv", "--json"],
            "dynamics": ["dynamics", "--trajectory", "f.csv", "--json"],
            "simulate": ["simulate", "--trajectory", "f.csv", "--out", "userdir"],
        }[command]
        rc, out, err = run_and_check(argv, d)
        if rc == 2 and command != "simulate":
            assert "f.csv" in err or "pose" in err or "sample" in err or "trajectory" in err, err
    finally:
        shutil.rmtree(d, ignore_errors=True)


@ci(60)
@given(csv_files(), st.sampled_from(["ik", "dynamics", "simulate"]))
def test_csv(data, command):
    check_csv(data, command)


@fuzz
@given(csv_files(), st.sampled_from(["ik", "dynamics", "simulate"]))
def test_csv_fuzz(data, command):
    check_csv(data, command)


# ----------------------------------------------------------------------------------------------
# Program text.

_NUMBER = re.compile(r"\d+(\.\d*)?([eE][+-]?\d+)?")
SMALL = ["0", "1", "2", "0.5", "3", "0.01", "10"]


def small_numbers(text: str, pick) -> str:
    """Numeric literals replaced by small ones: loop counts and durations stay tiny (bounding big
    programs is the language runtime's test)."""
    return _NUMBER.sub(lambda m: pick(), text)


@st.composite
def programs(draw):
    if draw(st.booleans()):
        text = draw(from_lark(_lark(), start="start"))
        assume("while" not in text.lower())  # unbounded loops: the runtime limits' business
        rnd = draw(st.randoms(use_true_random=False))
        text = small_numbers(text, lambda: rnd.choice(SMALL))
    else:
        text = PROGRAM
        for _ in range(draw(st.integers(1, 4))):
            i = draw(st.integers(0, len(text)))
            j = draw(st.integers(i, min(len(text), i + 8)))
            text = (
                text[:i]
                + draw(
                    st.sampled_from(
                        [
                            "",
                            "(",
                            ")",
                            "END",
                            "mover(",
                            "x",
                            "1e999",
                            "/",
                            ";",
                            "\0",
                            "IF",
                            "units m, rad\n",
                            "FOR i := 1 TO 2 DO",
                            "*)",
                            "(*",
                        ]
                    )
                )
                + text[j:]
            )
        assume("while" not in text.lower())
    return text


def check_program(text: str, command: str) -> None:
    d = scratch()
    try:
        (d / "p.stw").write_bytes(text.encode("utf-8", "surrogatepass"))
        argv = {
            "compile": ["compile", "p.stw", "--emit", "python"],
            "matlab": ["compile", "p.stw", "--emit", "matlab", "-o", "out.m"],
            "run": ["run", "p.stw", "--out", "runout", "--json"],
        }[command]
        run_and_check(argv, d)
    finally:
        shutil.rmtree(d, ignore_errors=True)


@ci(40)
@given(programs(), st.sampled_from(["compile", "matlab", "run"]))
def test_program_text(text, command):
    check_program(text, command)


@fuzz
@given(programs(), st.sampled_from(["compile", "matlab", "run"]))
def test_program_text_fuzz(text, command):
    check_program(text, command)
