"""Property test: argument vectors for every subcommand, built from the parser itself (every option,
with valid, odd and invalid values), keep the invariants of ``_fuzz.check_run``: exit 0/1/2, no
traceback, one-line errors, strict JSON, nothing written outside the outputs, the user's files intact.

Work sizes (resolution, duration, step, loop counts) are drawn from small values so that every
example is quick; the commands that write folders (workspace, simulate, run, report, montecarlo) are pointed at
the user's folder, which must be refused before any work (or, with --force, kept intact)."""

from __future__ import annotations

import argparse

from hypothesis import given
from hypothesis import strategies as st

from stewart_drake.cli import build_parser, checked_int, finite_number
from tests.cli._fuzz import ci, fuzz, run_and_check

NUMBERS = [
    "0",
    "1",
    "-1",
    "2.5",
    "100",
    "473",
    "700",
    "-0.473",
    "1e308",
    "-1e308",
    "1e-300",
    "nan",
    "inf",
    "-inf",
    "abc",
    "",
    "0x10",
    "1_000",
    "1e",
    "--",
    " 5",
    "45",
    "90",
    "180",
    "-180",
    "1000",
]
INTS = ["0", "1", "-1", "5", "30", "abc", "1e9", "9" * 30, "", "2"]
PATHS = [
    "good.yaml",
    "bad.yaml",
    "poses.csv",
    "traj.csv",
    "prog.stw",
    "missing.yaml",
    "missing.csv",
    "emptydir",
    "userdir",
    "afile.txt",
    "",
    "/proc/x",
    "..",
    ".",
    "new_out",
    "seed",
    "rotating",
    "utn-kinematic",
    "utn-dynamic",
    "gonzalez-dutra-2009",
    "hobby-servo",
    "userdir/new.m",
]
# Work sizes: small values only (bounding big ones is another test's business), and invalid ones.
SAFE = {
    "--resolution": ["0.05", "0.1", "0", "-0.01", "abc"],
    "--duration": ["0.01", "0.05", "0", "-1", "abc"],
    "--t-end": ["0", "0.5", "1", "-1", "abc"],
    "--dt": ["0.1", "0.25", "0", "-0.1", "abc"],
    "--rate": ["10", "100", "0", "-5", "abc"],
    "--max-iter": ["1", "5", "30", "0", "-1", "abc"],
    "--workers": ["1", "0", "-1", "abc"],
    "--period": ["0.001", "0.002", "0", "-1", "abc"],
    "--plant-step": ["0.001", "0", "-1", "abc"],
    "--tol": ["1e-13", "1e-6", "0", "-1", "abc"],
    "--seed": ["0", "1", "-1", "abc"],
    "--map-n": ["3", "0", "-1", "abc"],
    "--branch-samples": ["2", "0", "-1", "abc"],
}
# multi-start/homotopy FK, full simulations, Drake linearisation, branch checks and maps: seconds each
SKIP = {"--all", "--help", "--version", "--simulate", "--drake", "--check-branches", "--map"}
HEAVY = {"workspace", "simulate", "run", "report", "montecarlo", "response", "tune"}
# The Meshcat viewer is interactive: without --duration it follows its sliders until Ctrl-C (the main
# thread in time.sleep, Meshcat's server thread idle in a futex wait: what looked like a deadlock when it
# ran in-process thousands of times). Every generated `view` vector is bounded by a --duration here.
INTERACTIVE = ("view",)


def commands():
    """(argv prefix, parser) of every leaf subcommand."""
    out = []

    def walk(parser, prefix):
        subs = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
        if not subs:
            out.append((prefix, parser))
        for a in subs:
            for name, p in a.choices.items():
                walk(p, prefix + [name])

    walk(build_parser(), [])
    return out


COMMANDS = commands()


PLAUSIBLE = ["0", "1", "-1", "2.5", "10", "45", "100", "120", "473", "500", "700", "-30", "0.5", "0.7"]
VALID_PATHS = {
    "--platform": ["good.yaml", "utn-kinematic", "utn-dynamic", "gonzalez-dutra-2009", "hobby-servo"],
    "--poses": ["poses.csv"],
    "--trajectory": ["seed", "traj.csv", "rotating"],
    "program": ["prog.stw"],
    "--write": ["new_out", "emptydir"],
    "--output": ["new.m", "new.py"],
    "--write-sdf": ["new_out"],
    "--only": ["seed_table", "leg"],
    "--program": ["prog.stw"],
    "--envelope": ["good.yaml", "missing.yaml"],
}


def values_for(action):
    """Mostly plausible values (3 in 4), else anything from the odd and invalid pools."""
    opt = action.option_strings[-1] if action.option_strings else action.dest
    if opt in SAFE:
        return st.sampled_from(SAFE[opt])
    if action.choices is not None:
        valid = st.sampled_from([str(c) for c in action.choices])
        invalid = st.sampled_from(["x", "", "MM"])
    elif action.type is finite_number:
        valid = st.sampled_from(PLAUSIBLE)
        invalid = st.one_of(
            st.sampled_from(NUMBERS),
            st.floats(allow_nan=True, allow_infinity=True).map(repr),
            st.integers(-(10**6), 10**6).map(str),
        )
    elif action.type is checked_int:
        valid, invalid = st.sampled_from(["0", "1", "5"]), st.sampled_from(INTS)
    else:
        valid = st.sampled_from(VALID_PATHS.get(opt, PATHS))
        invalid = st.sampled_from(PATHS + ["nope"])
    return st.integers(0, 3).flatmap(lambda k: invalid if k == 0 else valid)


def nargs_count(action) -> int | None:
    if isinstance(action.nargs, int):
        return action.nargs
    return {None: 1, "?": 1, "+": 1, "*": 1}.get(action.nargs, 1)


@st.composite
def argv(draw):
    prefix, parser = draw(st.sampled_from(COMMANDS))
    args = list(prefix)
    actions = [
        a for a in parser._actions if not isinstance(a, argparse._HelpAction) and a.option_strings[:1] != ["--version"]
    ]
    for a in actions:
        if a.option_strings and set(a.option_strings) & SKIP:
            continue
        required = not a.option_strings or a.required
        if not required and not draw(st.integers(0, 3)) == 0:
            continue
        if required and a.option_strings and draw(st.integers(0, 19)) == 0:
            continue  # a required option left out
        if a.option_strings:
            args.append(a.option_strings[-1])
        if a.nargs == 0:
            continue
        n = nargs_count(a)
        if draw(st.integers(0, 19)) == 0:
            n = max(0, n + draw(st.sampled_from([-1, 1])))  # one value too few or too many
        args += [draw(values_for(a)) for _ in range(n)]
    if prefix and prefix[0] in HEAVY:
        args += ["--out", "userdir"]  # refused before the work (or, with --force, written beside the user's file)
    if prefix and prefix[0] in INTERACTIVE and "--duration" not in args:
        args += ["--duration", draw(st.sampled_from(["0", "0.01"]))]  # 0: draw once and exit
    if draw(st.integers(0, 39)) == 0:
        args.append(draw(st.sampled_from(["--bogus", "-x", "extra"])))
    return args


def check(vector):
    if "--force" in vector and vector[0] in HEAVY:
        vector = [v for v in vector if v != "--force"]  # --force would run the whole analysis/simulation
    run_and_check(vector)


@ci(150)
@given(argv())
def test_cli_vectors(vector):
    check(vector)


@fuzz
@given(argv())
def test_cli_vectors_fuzz(vector):
    check(vector)


def test_every_subcommand_is_generated():
    names = {" ".join(p) for p, _ in COMMANDS}
    assert names >= {
        "compile",
        "dsp-ik",
        "dynamics",
        "fk",
        "ik",
        "init",
        "leg fk",
        "leg ik",
        "leg sdf",
        "model",
        "report",
        "run",
        "servo",
        "simulate",
        "view",
        "workspace",
    }
