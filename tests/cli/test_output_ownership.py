"""Who owns a file in an output folder (issue 24, items 1 and 1b): the manifest records, per file, the
command that wrote it and a SHA-256 of its content; a command replaces only its own earlier files, a file
changed since belongs to the user, nothing is followed through a symbolic link, a damaged manifest is not
an empty folder, and a temporary is recognised by its marker, not its name."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from stewart_drake.errors import OutputError
from stewart_drake.system.output_folder import MANIFEST, OutputFolder, atomic_folder, load_manifest
from tests.cli._inprocess import cli


def write(folder, files: dict, command: str, force: bool = False):
    with atomic_folder(OutputFolder(folder, force=force, command=command)) as tmp:
        for name, text in files.items():
            (tmp / name).parent.mkdir(parents=True, exist_ok=True)
            (tmp / name).write_text(text)


def test_another_commands_folder_is_refused_and_its_files_kept(here, capsys):
    """Item 1: `workspace --out fw` over `firmware generate`'s folder deleted its three files, exit 0."""
    rc, _, _ = cli(capsys, "firmware", "generate", "--platform", "utn-dynamic", "--out", "fw", "--no-compile")
    assert rc == 0
    before = {p.name: p.read_bytes() for p in (here / "fw").iterdir()}
    rc, _, err = cli(capsys, "workspace", "--platform", "utn-dynamic", "--out", "fw", "--resolution", "0.05")
    assert rc == 2 and "was written by `stewart-drake firmware generate`" in err and "'README.md'" in err
    assert {p.name: p.read_bytes() for p in (here / "fw").iterdir()} == before
    # ... while the same command regenerates its own folder (it was refused before: "holds files this
    # command did not write (.stewart-drake-manifest.json)")
    rc, _, err = cli(capsys, "firmware", "generate", "--platform", "utn-dynamic", "--out", "fw", "--no-compile")
    assert rc == 0, err
    entries = load_manifest(here / "fw")
    assert {e["command"] for e in entries.values()} == {"firmware generate"}
    assert sorted(entries) == sorted(n for n in before if n != MANIFEST)


def test_force_writes_beside_another_commands_files_and_keeps_their_entries(here):
    write("d", {"a.txt": "A"}, "alpha")
    write("d", {"b.txt": "B"}, "beta", force=True)
    write("d", {"b.txt": "B2", "c.txt": "C"}, "beta", force=True)  # beta replaces its own b.txt only
    m = load_manifest(here / "d")
    assert {k: v["command"] for k, v in m.items()} == {"a.txt": "alpha", "b.txt": "beta", "c.txt": "beta"}
    assert (here / "d" / "a.txt").read_text() == "A" and (here / "d" / "b.txt").read_text() == "B2"


def test_force_run_without_force_refused_because_of_the_others_files(here):
    write("d", {"a.txt": "A"}, "alpha")
    with pytest.raises(OutputError, match="'a.txt' was written by `stewart-drake alpha`"):
        OutputFolder("d", command="beta")


def test_changed_file_belongs_to_the_user(here):
    """A file whose content changed since the tool wrote it is never overwritten nor deleted."""
    write("d", {"a.txt": "A", "b.txt": "B"}, "alpha")
    (here / "d" / "a.txt").write_text("my edit")
    with pytest.raises(OutputError, match="changed since stewart-drake wrote it .e.g. 'a.txt'"):
        OutputFolder("d", command="alpha")
    # --force: ours replaced/removed, the edited file kept, and a new output of that name is a clash
    write("d", {"c.txt": "C"}, "alpha", force=True)
    assert (here / "d" / "a.txt").read_text() == "my edit" and not (here / "d" / "b.txt").exists()
    with pytest.raises(OutputError, match="'a.txt' exists and was not written by stewart-drake"):
        write("d", {"a.txt": "new"}, "alpha", force=True)
    assert (here / "d" / "a.txt").read_text() == "my edit"


def test_manifest_entry_through_a_symlink_never_deletes_outside(here):
    """Item 1b: an entry `link/p2.txt` appended to the manifest, `link -> /elsewhere`: --force deleted
    /elsewhere/p2.txt."""
    elsewhere = here / "elsewhere"
    elsewhere.mkdir()
    (elsewhere / "p2.txt").write_text("precious")
    write("d", {"r.txt": "R"}, "alpha")
    os.symlink(elsewhere, here / "d" / "link")
    m = json.loads((here / "d" / MANIFEST).read_text())
    m["files"]["link/p2.txt"] = {"command": "alpha", "sha256": __import__("hashlib").sha256(b"precious").hexdigest()}
    (here / "d" / MANIFEST).write_text(json.dumps(m))
    with pytest.raises(OutputError, match="'link'"):  # the link is the user's entry
        OutputFolder("d", command="alpha")
    write("d", {"s.txt": "S"}, "alpha", force=True)
    assert (elsewhere / "p2.txt").read_text() == "precious" and (here / "d" / "link").is_symlink()
    with pytest.raises(OutputError, match="'link/p2.txt' exists and was not written"):
        write("d", {"link/p2.txt": "ours"}, "alpha", force=True)
    assert (elsewhere / "p2.txt").read_text() == "precious"


def test_user_file_listed_in_an_edited_manifest_is_not_deleted(here):
    write("d", {"r.txt": "R"}, "alpha")
    (here / "d" / "user.txt").write_text("mine")
    m = json.loads((here / "d" / MANIFEST).read_text())
    m["files"]["user.txt"] = dict(m["files"]["r.txt"])  # listed, but the hash is not its content's
    (here / "d" / MANIFEST).write_text(json.dumps(m))
    with pytest.raises(OutputError, match="'user.txt'"):
        OutputFolder("d", command="alpha")
    write("d", {"r.txt": "R2"}, "alpha", force=True)
    assert (here / "d" / "user.txt").read_text() == "mine"


@pytest.mark.parametrize("manifest", ["{not json", "[]", '{"tool": "stewart-drake", "files": 3}', ""])
def test_damaged_manifest_is_not_an_empty_folder(here, manifest):
    """A folder holding only an invalid manifest counted as empty, and was replaced."""
    (here / "d").mkdir()
    (here / "d" / MANIFEST).write_text(manifest)
    for force in (False, True):
        with pytest.raises(OutputError, match="its manifest .stewart-drake-manifest.json is damaged"):
            OutputFolder("d", command="alpha", force=force)
    assert (here / "d" / MANIFEST).read_text() == manifest


def test_stale_temporary_needs_the_marker(here):
    """User entries named like `.NAME.sd-tmp-<dead pid>-<8 hex>` were removed as stale temporaries."""
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    mine = here / f".d.sd-tmp-{dead.pid}-0badcafe"
    mine.mkdir()
    (mine / "notes.txt").write_text("mine")
    write("d", {"r.txt": "R"}, "alpha")
    assert (mine / "notes.txt").read_text() == "mine"
    assert sorted(p.name for p in here.iterdir()) == sorted(["d", mine.name])


def test_symlink_in_the_folder_is_never_replaced_through(here):
    """A new output whose name is a link in the folder: refused, the link's target untouched."""
    target = here / "target.txt"
    target.write_text("precious")
    (here / "d").mkdir()
    os.symlink(target, here / "d" / "r.txt")
    with pytest.raises(OutputError, match="'r.txt' exists and was not written"):
        write("d", {"r.txt": "R"}, "alpha", force=True)
    assert target.read_text() == "precious" and (here / "d" / "r.txt").is_symlink()


def test_single_file_of_another_command_is_not_replaced(here, capsys):
    """`-o FILE` replaces only a file this command wrote, unchanged since."""
    prog = Path(__file__).resolve().parents[2] / "examples" / "circle.stw"
    rc, _, err = cli(capsys, "compile", prog, "--emit", "python", "-o", "c.py")
    assert rc == 0, err
    rc, _, err = cli(capsys, "compile", prog, "--emit", "python", "-o", "c.py")
    assert rc == 0, err
    (here / "c.py").write_text("# my edits")
    rc, _, err = cli(capsys, "compile", prog, "--emit", "python", "-o", "c.py")
    assert rc == 2 and "never overwritten" in err and (here / "c.py").read_text() == "# my edits"


def test_compile_dash_means_standard_output(here, capsys):
    """Item 10: `compile -o -` wrote a file named "-"; "-" is standard output, as for other tools."""
    prog = Path(__file__).resolve().parents[2] / "examples" / "circle.stw"
    rc, out, err = cli(capsys, "compile", prog, "--emit", "python", "-o", "-")
    assert rc == 0, err
    assert not (here / "-").exists() and list(here.iterdir()) == []
    rc, expected, _ = cli(capsys, "compile", prog, "--emit", "python")
    assert out == expected and "def " in out


def test_disk_full_names_the_option_and_the_file(here):
    """Disk full said only "No space left on device" (which file? which option?)."""
    import errno

    with pytest.raises(OutputError) as e:
        with atomic_folder(OutputFolder("d", command="alpha")) as tmp:
            (tmp / "ok.txt").write_text("x")
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(tmp / "sub" / "big.csv"))
    assert str(e.value) == f"--out 'd': cannot write there ({here / 'd' / 'sub' / 'big.csv'}: No space left on device)"
    assert list(here.iterdir()) == []  # nothing half-written, no temporary
