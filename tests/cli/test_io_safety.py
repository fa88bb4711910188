"""Output safety, safe input loading and the one-line error path.

Commands run in-process through ``stewart_drake.cli.main`` in a temporary working directory; the
SIGKILL test runs real subprocesses.
"""

from __future__ import annotations

import json
import os
import random
import shutil
import signal
import stat
import subprocess
import sys
import time
import xml.parsers.expat
from pathlib import Path

import pytest

from stewart_drake.errors import OPTION_JOINT_OVERFLOW, OutputError
from stewart_drake.system.jsonout import dumps_strict
from stewart_drake.system.output_folder import MANIFEST, OutputFolder, atomic_folder, read_manifest, safe_file_stem
from tests.cli._inprocess import cli

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "examples" / "circle.stw"
PLATFORM = (
    "utn: {b: 0.4, d: 0.1, a: 0.2}\nstroke: [0.55, 0.95]\nplate: {mass: 1.5, inertia: [0.01, 0.01, 0.02, 0, 0, 0]}\n"
)


def user_folder(path: Path) -> Path:
    path.mkdir()
    (path / "notes.txt").write_text("mine")
    return path


def no_litter(folder: Path) -> list[str]:
    return [p.name for p in folder.iterdir() if ".sd-tmp-" in p.name or ".old-" in p.name]


# ----------------------------------------------------------------------------------------------
# Output folders.

# Each command given the user's folder as --out: refused before any work (these would take seconds
# to minutes if they ran), the user's file intact.
OUT_COMMANDS = [
    ["workspace", "--resolution", "0.05", "--out"],
    ["simulate", "--duration", "0.3", "--no-progress", "--out"],
    ["run", str(EXAMPLE), "--out"],
    ["report", "--quick", "--only", "seed_table", "--out"],
]


@pytest.mark.parametrize("argv", OUT_COMMANDS, ids=lambda a: a[0])
def test_user_folder_refused_and_kept(here, capsys, argv):
    u = user_folder(here / "u")
    t0 = time.perf_counter()
    rc, out, err = cli(capsys, *argv, "u")
    assert rc == 2
    assert err.strip() == (
        f"stewart-drake {argv[0]}: error: --out 'u': the folder was not written by stewart-drake (no manifest) "
        "(e.g. 'notes.txt', 1 file(s)); give a new or empty folder, or --force to write beside them "
        "(files not written by stewart-drake are never touched)"
    )
    assert time.perf_counter() - t0 < 2.0  # refused before the analyses/simulation ran
    assert sorted(p.name for p in u.iterdir()) == ["notes.txt"] and (u / "notes.txt").read_text() == "mine"
    assert no_litter(here) == []


@pytest.mark.parametrize("typed", [".", "./", "..", "~", "/"])
def test_out_dot_home_root_refused(here, capsys, typed):
    (here / "keep.txt").write_text("x")
    rc, _, err = cli(capsys, "workspace", "--out", typed)
    assert rc == 2 and f"--out {typed!r}: refusing to write into" in err
    assert (here / "keep.txt").read_text() == "x"


def test_out_existing_file_refused(here, capsys):
    (here / "existing_file.txt").write_text("data")
    rc, _, err = cli(capsys, "workspace", "--out", "existing_file.txt")
    assert rc == 2
    assert (
        err.strip()
        == "stewart-drake workspace: error: --out 'existing_file.txt': 'existing_file.txt' exists and is not a folder"
    )
    assert (here / "existing_file.txt").read_text() == "data"
    assert sorted(p.name for p in here.iterdir()) == ["existing_file.txt"]


def test_unwritable_destination_named_as_typed(here, capsys):
    rc, _, err = cli(capsys, "report", "--quick", "--only", "seed_table", "--out", "/proc/x")
    assert rc == 2 and err.startswith("stewart-drake report: error: --out '/proc/x': cannot write there (")
    assert ".x." not in err  # no temporary name the user never typed
    (here / "f").write_text("")
    rc, _, err = cli(capsys, "workspace", "--out", "f/sub")
    assert rc == 2 and err.strip() == "stewart-drake workspace: error: --out 'f/sub': 'f' exists and is not a folder"


def test_force_writes_beside_user_files_and_rerun_replaces_ours(here, capsys):
    user_folder(here / "u")
    rc, out, _ = cli(capsys, "workspace", "--resolution", "0.05", "--out", "u", "--force", "--json")
    assert rc == 0
    names = sorted(p.name for p in (here / "u").iterdir())
    assert "notes.txt" in names and "workspace.json" in names and MANIFEST in names
    ours = read_manifest(here / "u")
    assert "notes.txt" not in ours and sorted(ours) == sorted(n for n in names if n not in ("notes.txt", MANIFEST))
    assert json.loads((here / "u" / "workspace.json").read_text())["platform"] == "gonzalez-dutra-2009"
    # again, still with --force: ours replaced, the user's file untouched, no litter
    (here / "u" / "notes.txt").write_text("edited")
    rc, _, _ = cli(capsys, "workspace", "--resolution", "0.05", "--out", "u", "--force")
    assert rc == 0 and (here / "u" / "notes.txt").read_text() == "edited" and no_litter(here) == []


def test_new_folder_permissions_manifest_and_rerun(here, capsys):
    old = os.umask(0o022)
    try:
        rc, _, _ = cli(capsys, "workspace", "--resolution", "0.05", "--out", "w")
    finally:
        os.umask(old)
    assert rc == 0
    assert stat.S_IMODE((here / "w").stat().st_mode) == 0o755
    listed = read_manifest(here / "w")
    assert sorted(listed) == sorted(p.name for p in (here / "w").iterdir() if p.name != MANIFEST)
    # a folder this tool wrote is reused without --force
    rc, _, _ = cli(capsys, "workspace", "--resolution", "0.05", "--out", "w")
    assert rc == 0 and no_litter(here) == []


def test_empty_folder_accepted(here, capsys):
    (here / "e").mkdir()
    rc, _, _ = cli(capsys, "workspace", "--resolution", "0.05", "--out", "e")
    assert rc == 0 and (here / "e" / "workspace.json").is_file()


def test_clash_with_foreign_file_refused_under_force(here):
    u = user_folder(here / "u")
    (u / "a.txt").write_text("user's")
    out = OutputFolder("u", force=True)
    with pytest.raises(
        OutputError, match=r"^--out 'u': 'a.txt' exists and was not written by stewart-drake; nothing was written$"
    ):
        with atomic_folder(out) as tmp:
            (tmp / "a.txt").write_text("ours")
            (tmp / "b.txt").write_text("ours")
    assert (u / "a.txt").read_text() == "user's" and not (u / "b.txt").exists() and no_litter(here) == []


@pytest.mark.parametrize("exc", [RuntimeError("boom"), KeyboardInterrupt()])
def test_error_or_ctrl_c_leaves_previous_result_and_no_litter(here, exc):
    with atomic_folder("w") as tmp:
        (tmp / "result.txt").write_text("first")
    with pytest.raises(type(exc)):
        with atomic_folder("w") as tmp:
            (tmp / "result.txt").write_text("half")
            raise exc
    assert (here / "w" / "result.txt").read_text() == "first" and no_litter(here) == []
    with pytest.raises(type(exc)):
        with atomic_folder("new") as tmp:
            (tmp / "x").write_text("half")
            raise exc
    assert not (here / "new").exists() and no_litter(here) == []


def test_stale_temp_of_dead_run_cleaned_live_one_kept(here):
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    stale = here / f".w.sd-tmp-{dead.pid}-0123abcd"
    stale.mkdir()
    (stale / "partial.csv").write_text("1,2")
    (stale / ".sd-tmp").write_text(json.dumps({"pid": dead.pid, "token": "0123abcd"}))  # the tool's marker
    alive = here / f".w.sd-tmp-{os.getppid()}-89abcdef"
    alive.mkdir()
    (alive / ".sd-tmp").write_text(json.dumps({"pid": os.getppid(), "token": "89abcdef"}))
    other = here / ".w.old-12345"  # not ours by name: never touched
    other.mkdir()
    # named like a temporary of a dead run, but without the marker (or a marker of another name): the user's
    lookalike = here / f".w.sd-tmp-{dead.pid}-fedcba98"
    lookalike.mkdir()
    (lookalike / "mine.txt").write_text("user data")
    forged = here / f".w.sd-tmp-{dead.pid}-00000000"
    forged.mkdir()
    (forged / ".sd-tmp").write_text(json.dumps({"pid": dead.pid, "token": "11111111"}))
    lookalike_file = here / f".w.sd-tmp-{dead.pid}-abcdef01"
    lookalike_file.write_text("a user's file")
    with atomic_folder("w") as tmp:
        (tmp / "r.txt").write_text("ok")
    assert not stale.exists() and alive.exists() and other.exists()
    assert (lookalike / "mine.txt").read_text() == "user data" and forged.exists() and lookalike_file.exists()


def test_safe_file_stem_confines_names():
    assert safe_file_stem("../../escaped") == "escaped"
    assert safe_file_stem("/abs/x") == "abs_x"
    assert safe_file_stem('evil"><!--') == "evil_--"
    assert safe_file_stem("utn-kinematic") == "utn-kinematic"
    assert safe_file_stem("..") == "platform" and safe_file_stem("\0") == "platform"


# ----------------------------------------------------------------------------------------------
# Single-file outputs.


def test_model_write_policy(here, capsys):
    rc, out, _ = cli(capsys, "model", "--write", "m")
    assert rc == 0 and out.strip() == str(here / "m" / "utn-kinematic.sdf")
    assert cli(capsys, "model", "--write", "m")[0] == 0  # ours: replaced
    (here / "m" / "gonzalez-dutra-2009.sdf").write_text("user's model")
    rc, _, err = cli(capsys, "model", "--platform", "gonzalez-dutra-2009", "--write", "m")
    assert rc == 2 and err.strip() == (
        "stewart-drake model: error: --write 'm/gonzalez-dutra-2009.sdf': the file exists and "
        "was not written by stewart-drake; remove it or choose another name (it is never overwritten)"
    )
    assert (here / "m" / "gonzalez-dutra-2009.sdf").read_text() == "user's model"
    (here / "file").write_text("x")
    rc, _, err = cli(capsys, "model", "--write", "file")
    assert rc == 2 and err.strip() == "stewart-drake model: error: --write 'file': 'file' exists and is not a folder"


def test_leg_sdf_write_twice_and_foreign(here, capsys):
    assert cli(capsys, "leg", "sdf", "--write", "d")[0] == 0
    assert cli(capsys, "leg", "sdf", "--write", "d")[0] == 0
    (here / "e").mkdir()
    (here / "e" / "leg-3r.sdf").write_text("mine")
    rc, _, err = cli(capsys, "leg", "sdf", "--write", "e")
    assert rc == 2 and "--write 'e/leg-3r.sdf': the file exists and was not written by stewart-drake" in err
    assert (here / "e" / "leg-3r.sdf").read_text() == "mine"


def test_compile_output_policy(here, capsys):
    (here / "d").mkdir()
    rc, _, err = cli(capsys, "compile", EXAMPLE, "--emit", "matlab", "-o", "d")
    assert rc == 2 and err.strip() == "stewart-drake compile: error: --output 'd': is a folder; give a file name"
    (here / "prog.m").write_text("user")
    rc, _, err = cli(capsys, "compile", EXAMPLE, "--emit", "matlab", "-o", "prog.m")
    assert (
        rc == 2
        and "the file exists and was not written by stewart-drake" in err
        and (here / "prog.m").read_text() == "user"
    )
    assert cli(capsys, "compile", EXAMPLE, "--emit", "matlab", "-o", "new.m")[0] == 0
    assert cli(capsys, "compile", EXAMPLE, "--emit", "matlab", "-o", "new.m")[0] == 0
    assert (here / "new.m").read_text().strip()


# ----------------------------------------------------------------------------------------------
# Names from input files: file names and XML.


def well_formed(text: str) -> bool:
    p = xml.parsers.expat.ParserCreate()  # no namespace processing: drake: prefixes are plain names
    p.Parse(text, True)
    return True


@pytest.mark.parametrize(
    "name,file",
    [
        ("../../escaped", "escaped.sdf"),
        ("/abs/x", "abs_x.sdf"),
        ('evil"><!--', "evil_--.sdf"),
        ("a::b", "a_b.sdf"),
        ("&amp;", "amp.sdf"),
    ],
)
def test_platform_name_never_a_path_or_markup(here, capsys, name, file):
    (here / "p.yaml").write_text(f"name: {json.dumps(name)}\n" + PLATFORM)
    (here / "w" / "a").mkdir(parents=True)
    rc, out, _ = cli(capsys, "model", "--platform", "p.yaml", "--write", "w/a")
    assert rc == 0 and out.strip() == str(here / "w" / "a" / file)
    assert sorted(p.name for p in (here / "w" / "a").iterdir()) == sorted([file, MANIFEST])
    text = (here / "w" / "a" / file).read_text()
    assert well_formed(text)
    rc, out, _ = cli(capsys, "model", "--platform", "p.yaml", "--inspect", "--json")
    assert rc == 0 and json.loads(out)["platform"] == name


def test_control_character_in_name_refused(here, capsys):
    (here / "p.yaml").write_text('name: "a\\0b"\n' + PLATFORM)
    rc, _, err = cli(capsys, "ik", "--platform", "p.yaml", "--pose", "0", "0", "700", "0", "0", "0")
    assert (
        rc == 2
        and err.strip() == "stewart-drake ik: error: p.yaml:1: name: 'a\\x00b' contains the control character '\\x00'"
    )


# ----------------------------------------------------------------------------------------------
# YAML: safe, bounded, typed; literal messages.

YAML_CASES = [
    ("[1, 2", "p.yaml:1: YAML syntax error: expected ',' or ']', but got '<stream end>'"),
    (
        "utn: {b: 0.4, d: 0.1, a: 0.2}\nstroke: [0.5, 0.9]\n\0",
        "p.yaml:3: YAML syntax error: special characters are not allowed (character #x0000)",
    ),
    (
        "!!python/object/apply:os.system ['echo hi']",
        "p.yaml:1: tag '!!python/object/apply:os.system' is not allowed (plain YAML values only)",
    ),
    ("stroke: 5", "p.yaml:1: stroke: expected a list [...], got 5"),
    ("utn: 5", "p.yaml:1: utn: expected a mapping of keys to values, got 5"),
    ("plate: [1, 2]", "p.yaml:1: plate: expected a mapping of keys to values, got a list"),
    ("- 1\n- 2", "p.yaml: a platform file must be a mapping of keys to values, got a list"),
    (
        "utn: {b: 4000000000000000000000000000000000000000000000000, d: 0.1, a: 0.2}",
        "p.yaml:1: utn.b: 4000000000000000000000000000000000000000000000000 has more than 30 digits",
    ),
    ("utn: {b: 1e300, d: 0.1, a: 0.2}\nstroke: [0.5, 0.9]", "p.yaml:1: utn.b: 1e300 is too large (at most 100 m)"),
    (
        "length_unit: mm\nutn: {b: 1e300, d: 0.1, a: 0.2}\nstroke: [0.5, 0.9]",
        "p.yaml:2: utn.b: 1e300 is too large (at most 100000 mm)",
    ),
    (
        "utn: {b: 0.4, d: 0.1, a: 0.2}\nstrok: [0.5, 0.9]",
        "p.yaml:2: strok: unknown key (did you mean 'stroke'?); valid keys: name, description, length_unit, utn, radial, "
        "base_anchors, top_anchors, leg_top, leg_base, stroke, plate, rotation_centre, home_height, legs, "
        "plate_below_base_allowed, calibration",
    ),
    (
        "utn: {b: 0.4, d: 0.1, a: 0.2}\nstroke: [0.5, 0.9]\nplate: {mas: 1}",
        "p.yaml:3: plate: unknown key 'mas' (did you mean 'mass'?); valid keys: mass, com, inertia, thickness, density",
    ),
    (
        "utn: {b: 0.4, d: 0.1, a: 0.2}\nstroke: [0.5, 0.9]\nplate: {mass: big}",
        "p.yaml:3: plate.mass: expected a number, got big",
    ),
    ("utn: {b: 0.4, d: 0.1, a: 0.2}\nstroke: [0.5, 0.9]\nplate: {mass: -3}", "p.yaml:3: plate.mass: -3 must be >= 0"),
    (
        "utn: {b: 0.4, d: 0.1, a: 0.2}\nstroke: [0.5, 0.9]\nlegs: {cylinder_mass: .nan}",
        "p.yaml:3: legs.cylinder_mass: .nan is not a finite number",
    ),
    (
        "utn: {b: 0.4, d: 0.1, a: 0.2}\nstroke: [0.5, 0.9]\nlegs: {max_force: .inf}",
        "p.yaml:3: legs.max_force: .inf is not a finite number",
    ),
    (
        "utn: {b: 0.4, d: 0.1, a: 0.2}\nstroke: [0.5, 0.9]\nlegs: {piston_radius: -0.01}",
        "p.yaml:3: legs.piston_radius: -0.01 must be >= 0",
    ),
    (
        "utn: {b: 0.4, d: 0.1, a: 0.2}\nstroke: [0.5, 0.9]\nlegs: {piston_mass: 0}",
        "p.yaml:3: legs.piston_mass: 0 must be > 0",
    ),
    ("utn: {b: 0.4, d: 0.1, a: 0.2}\nstroke: [0.5, 0.9, 1.0]", "p.yaml:2: stroke: (3 items) must have 2 items"),
    ("utn: {b: 0.4, d: 0.1, a: 0.2}\nstroke: [0.5, '0.9']", "p.yaml:2: stroke item 2: expected a number, got '0.9'"),
    ("utn: {b: 0.4, d: 0.1, a: 0.2}\nstroke: [0.5, 0.9]\nstroke: [0.5, 0.9]", "p.yaml:3: stroke: key given twice"),
    (
        "utn: {b: 0.4, d: 0.1, a: 0.2}\nstroke: [0.5, 0.9]\nlength_unit: inch",
        "p.yaml:3: length_unit: unknown length unit 'inch'; use m or mm",
    ),
    (
        "utn: {b: 0.4, d: 0.1, a: 0.2}\nstroke: [0.5, 0.9]\nhome_height: true",
        "p.yaml:3: home_height: expected a number, got true",
    ),
    (
        "a: &a [1, 1, 1, 1, 1, 1, 1, 1, 1, 1]\n"
        + "".join(
            f"{c}: &{c} [*{p}, *{p}, *{p}, *{p}, *{p}, *{p}, *{p}, *{p}, *{p}, *{p}]\n"
            for p, c in zip("abcdefgh", "bcdefghi")
        ),
        "p.yaml: more than 100000 values after expanding aliases (an alias bomb?)",
    ),
    ("x: " + "[" * 40 + "]" * 40, "p.yaml:1: nesting deeper than 32 levels"),
]


@pytest.mark.parametrize("text,message", YAML_CASES, ids=range(len(YAML_CASES)))
def test_yaml_literal_messages(here, capsys, text, message):
    (here / "p.yaml").write_text(text)
    t0 = time.perf_counter()
    rc, out, err = cli(capsys, "ik", "--platform", "p.yaml", "--pose", "0", "0", "700", "0", "0", "0")
    assert time.perf_counter() - t0 < 2.0  # refused at once, not after expanding or evaluating anything
    assert rc == 2 and out == "" and err.strip() == f"stewart-drake ik: error: {message}"


def test_yaml_size_limit(here, capsys):
    (here / "big.yaml").write_bytes(b"#" * 1_000_001)
    rc, _, err = cli(capsys, "fk", "--platform", "big.yaml", "--lengths", *["700"] * 6)
    assert (
        rc == 2
        and err.strip() == "stewart-drake fk: error: big.yaml: larger than the 1000000-byte limit for a platform file"
    )


def test_yaml_folder_and_missing(here, capsys):
    (here / "d.yaml").mkdir()
    rc, _, err = cli(capsys, "ik", "--platform", "d.yaml", "--pose", "0", "0", "700", "0", "0", "0")
    assert rc == 2 and err.strip() == "stewart-drake ik: error: platform file 'd.yaml' is a folder, not a file"
    rc, _, err = cli(capsys, "ik", "--platform", "none.yaml", "--pose", "0", "0", "700", "0", "0", "0")
    assert rc == 2 and err.strip() == "stewart-drake ik: error: platform file 'none.yaml' does not exist"


def test_servo_yaml_uses_the_safe_loader(here, capsys):
    (here / "s.yaml").write_text("!!python/name:os.system")
    rc, _, err = cli(capsys, "servo", "--platform", "s.yaml", "--pose", "0", "0", "0", "0", "0", "0")
    assert (
        rc == 2
        and err.strip()
        == "stewart-drake servo: error: s.yaml:1: tag '!!python/name:os.system' is not allowed (plain YAML values only)"
    )
    (here / "s.yaml").write_text("arm_lenght: 25")
    rc, _, err = cli(capsys, "servo", "--platform", "s.yaml", "--pose", "0", "0", "0", "0", "0", "0")
    assert rc == 2 and "s.yaml:1: arm_lenght: unknown key (did you mean 'arm_length'?)" in err


@pytest.mark.parametrize("kind", ["utn", "radial", "explicit"])
def test_platform_templates_load(here, capsys, kind):
    from stewart_drake.core.geometry import load_platform

    rc, out, _ = cli(capsys, "init", "--platform-template", kind)
    assert rc == 0 and out.startswith("# A stewart-drake platform file")
    (here / "my.yaml").write_text(out)
    p = load_platform("my.yaml")
    assert p.mass > 0 and p.name == f"my-{kind}-platform"
    rc, out, _ = cli(
        capsys, "ik", "--platform", "my.yaml", "--pose", "0", "0", f"{p.home_height * 1e3}", "0", "0", "0", "--json"
    )
    assert rc == 0 and json.loads(out)


def test_docs_list_every_platform_key():
    import dataclasses

    from stewart_drake.core.geometry import LegConfig, PlateConfig, PlatformConfig

    doc = (ROOT / "docs" / "platform-file.md").read_text()
    for f in dataclasses.fields(PlatformConfig):
        assert f"`{f.name}" in doc, f.name
    for prefix, cls in (("plate", PlateConfig), ("legs", LegConfig)):
        for f in dataclasses.fields(cls):
            assert f"{prefix}.{f.name}" in doc, f.name


# ----------------------------------------------------------------------------------------------
# CSV.


def test_csv_bom_keeps_first_row(here, capsys):
    (here / "p.csv").write_bytes("\ufeff0,0,100,0,0,0\n0,0,120,0,0,0\n".encode("utf-8"))
    rc, out, _ = cli(capsys, "ik", "--poses", "p.csv", "--json")
    assert rc == 0 and len(json.loads(out)["results"]) == 2


def test_csv_huge_field(here, capsys):
    (here / "p.csv").write_text("0,0,100,0,0,0\n" + "1" * 200_000 + ",0,0,0,0,0\n")
    rc, _, err = cli(capsys, "ik", "--poses", "p.csv")
    assert (
        rc == 2
        and err.strip()
        == "stewart-drake ik: error: p.csv:2: a field is longer than 131072 characters; not a poses file?"
    )


def test_csv_folder_and_nonfinite(here, capsys):
    (here / "d.csv").mkdir()
    rc, _, err = cli(capsys, "dynamics", "--trajectory", "d.csv")
    assert rc == 2 and err.strip() == "stewart-drake dynamics: error: trajectory file 'd.csv' is a folder, not a file"
    (here / "p.csv").write_text("0,0,100,0,0,0\n0,0,nan,0,0,0\n")
    rc, _, err = cli(capsys, "ik", "--poses", "p.csv")
    assert rc == 2 and err.strip() == "stewart-drake ik: error: p.csv:2: column 3: values must be finite, got 'nan'"


# ----------------------------------------------------------------------------------------------
# One error path: argparse, options, JSON.


@pytest.mark.parametrize(
    "argv,message",
    [
        (
            ["leg", "fk"],
            "stewart-drake leg fk: error: the following arguments are required: Q1, Q2 (see stewart-drake leg fk --help)",
        ),
        (
            ["leg", "fk", "10"],
            "stewart-drake leg fk: error: the following arguments are required: Q2 (see stewart-drake leg fk --help)",
        ),
        (
            ["leg", "ik", "1"],
            "stewart-drake leg ik: error: the following arguments are required: PY (see stewart-drake leg ik --help)",
        ),
        (["model", "--json"], "stewart-drake model: error: --json only applies with --inspect"),
        (
            ["leg", "fk", "nan", "1"],
            "stewart-drake leg fk: error: argument Q1: must be a finite number, got 'nan' (see stewart-drake leg fk --help)",
        ),
        (
            ["workspace", "--workers", "1" * 30],
            "stewart-drake workspace: error: argument --workers: not a whole number (at most 18 digits): "
            f"'{'1' * 30}' (see stewart-drake workspace --help)",
        ),
        (["nonsense"], None),
    ],
)
def test_one_line_errors(here, capsys, argv, message):
    rc, out, err = cli(capsys, *argv)
    assert rc == 2 and len(err.strip().splitlines()) == 1
    if message:
        assert err.strip() == message


@pytest.mark.parametrize("op", ["fk", "ik"])
def test_leg_help(capsys, op):
    rc, out, err = cli(capsys, "leg", op, "--help")
    assert rc == 0 and out.startswith(f"usage: stewart-drake leg {op}") and err == ""


def test_strict_json_for_overflow():
    """A non-finite number in a result is written as null and its path listed (strict JSON)."""
    data = json.loads(dumps_strict({"a": [1.0, float("inf")], "b": {"c": float("nan")}, "d": 2.0}))
    assert data == {
        "a": [1.0, None],
        "b": {"c": None},
        "d": 2.0,
        "non_finite": {"paths": ["a[1]", "b.c"], "reason": "not a finite number (written as null)"},
    }


@pytest.mark.parametrize("unit", ["deg", "rad"])
def test_leg_fk_angles_whose_sum_overflows_are_refused(capsys, unit):
    """Joint angles near the float range: gamma = q1 + q2 + alpha overflowed to inf, printed as "gamma = inf
    deg" (found by ``pytest -m fuzz``); they are refused in one line naming the angles."""
    rc, out, err = cli(capsys, "leg", "fk", "1e308", "1e308", "--angle-unit", unit)
    message = OPTION_JOINT_OVERFLOW.format(value="[1e308, 1e308]", unit=unit)  # the values as written
    assert (rc, out, err.strip()) == (2, "", f"stewart-drake leg fk: error: {message}")
    rc, out, _ = cli(capsys, "leg", "fk", "1e300", "1e300", "--angle-unit", unit)  # large, but their sum is a float
    assert rc == 1 and "inf" not in out


def test_program_file_errors(here, capsys):
    (here / "d.stw").mkdir()
    rc, _, err = cli(capsys, "run", "d.stw")
    assert rc == 2 and err.strip() == "stewart-drake run: error: program file 'd.stw' is a folder, not a file"
    (here / "b.stw").write_bytes(b"x = 1\n\0")
    rc, _, err = cli(capsys, "compile", "b.stw", "--emit", "python")
    assert rc == 2 and err.strip() == "stewart-drake compile: error: b.stw:2: a NUL byte; not a program text file"


# ----------------------------------------------------------------------------------------------
# SIGKILL at random moments: never a partial result, no litter after the next run.


def _complete(folder: Path) -> bool:
    listed = read_manifest(folder)
    return (
        listed is not None
        and all((folder / f).is_file() for f in listed)
        and any(n in listed for n in ("checks.json", "summary.json"))
    )


KILL_RUNS = [
    ("report", ["report", "--quick", "--only", "seed_table", "--out"]),
    ("simulate", ["simulate", "--duration", "0.3", "--no-progress", "--out"]),
]


@pytest.mark.parametrize("name,argv", KILL_RUNS, ids=[k[0] for k in KILL_RUNS])
def test_sigkill_never_leaves_partial_output_or_litter(tmp_path, name, argv):
    rng = random.Random(12)
    env = dict(os.environ, PYTHONPATH=str(ROOT), MPLBACKEND="Agg")
    cmd = [sys.executable, "-m", "stewart_drake.cli", *argv, "dest"]
    # how long a full run takes here, so that kills land anywhere in it (mostly late, near the writing)
    t0 = time.perf_counter()
    subprocess.run(cmd, cwd=tmp_path, env=env, capture_output=True, check=True)
    full = time.perf_counter() - t0
    shutil.rmtree(tmp_path / "dest")
    kills = 5
    for k in range(kills):
        p = subprocess.Popen(cmd, cwd=tmp_path, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        time.sleep(rng.uniform(0.3, 1.0) * full)
        p.send_signal(signal.SIGKILL)
        p.wait()
        dest = tmp_path / "dest"
        assert not dest.exists() or _complete(dest), f"kill {k + 1}: partial output {sorted(os.listdir(dest))}"
    # the next run completes and removes what the killed runs left beside it
    subprocess.run(cmd, cwd=tmp_path, env=env, capture_output=True, check=True)
    assert _complete(tmp_path / "dest")
    assert sorted(os.listdir(tmp_path)) == ["dest"]


@pytest.mark.parametrize(
    "argv,message",
    [
        (
            ["workspace", "--joint-cone", "30"],
            "stewart-drake workspace: error: --joint-cone only applies with --limits ...,joints",
        ),
        (
            ["workspace", "--leg-diameter", "0.05"],
            "stewart-drake workspace: error: --leg-diameter only applies with --limits ...,collision",
        ),
        (
            ["workspace", "--max-condition", "50"],
            "stewart-drake workspace: error: --max-condition only applies with --limits ...,dexterity",
        ),
        (["workspace", "--force"], "stewart-drake workspace: error: --force only applies with --out"),
        (
            ["run", str(EXAMPLE), "--controller", "float"],
            "stewart-drake run: error: --controller only applies with --simulate",
        ),
        (
            ["simulate", "--length-unit", "mm"],
            "stewart-drake simulate: error: --length-unit only applies with --trajectory FILE.csv",
        ),
        (
            ["dynamics", "--trajectory", "t.csv", "--t-end", "2"],
            "stewart-drake dynamics: error: --t-end only applies with --trajectory seed",
        ),
        (
            ["dynamics", "--angle-unit", "deg"],
            "stewart-drake dynamics: error: --angle-unit only applies with --trajectory FILE.csv",
        ),
        (
            ["fk", "--lengths", "473", "473", "473", "473", "473", "-473"],
            "stewart-drake fk: error: --lengths: leg 6 length -473 mm must be a positive number",
        ),
        (
            ["fk", "--length-unit", "m", "--lengths", "0.473", "0.473", "0.473", "0.473", "0.473", "-0.473"],
            "stewart-drake fk: error: --lengths: leg 6 length -0.473 m must be a positive number",
        ),
    ],
)
def test_ignored_options_and_inputs_echoed_as_written(here, capsys, argv, message):
    rc, out, err = cli(capsys, *argv)
    assert rc == 2 and out == "" and err.strip() == message
    assert sorted(p.name for p in here.iterdir()) == []  # refused before anything was written


def test_model_write_inspect_json_is_one_document(here, capsys):
    rc, out, _ = cli(capsys, "model", "--write", "m", "--inspect", "--json")
    info = json.loads(out)
    assert rc == 0 and info["sdf_file"] == str(here / "m" / "utn-kinematic.sdf") and Path(info["sdf_file"]).is_file()


def test_servo_write_sdf_json_is_one_document(here, capsys):
    rc, out, _ = cli(capsys, "servo", "--write-sdf", "s", "--json")
    info = json.loads(out)
    assert rc == 0 and info["sdf_file"] == str(here / "s" / "servo-hexapod.sdf") and Path(info["sdf_file"]).is_file()
    assert read_manifest(here / "s") == ["servo-hexapod.sdf"]


@pytest.mark.parametrize(
    "argv",
    [
        ["leg", "ik", "0", "1.6959684595474368e+155", "--gamma", "0", "--l1", "1", "--json"],
        ["dsp-ik", "--pose", "0", "0", "0", "0", "1e308", "0", "--json"],
    ],
)
def test_numeric_overflow_is_one_line_not_a_warning(capsys, argv):
    """Found by the CLI fuzz: an intermediate overflow printed numpy's two-line RuntimeWarning."""
    rc, out, err = cli(capsys, *argv)
    assert rc == 2 and out == "" and len(err.splitlines()) == 1 and "RuntimeWarning" not in err
