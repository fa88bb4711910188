"""``montecarlo``'s output folder (issue 24, item 1c and the resume-folder items of 10): ``--out`` checked
before any run, replays kept beside their study, a write error (disk full) is one line naming the file and
leaves a folder the rerun resumes, and a damaged resume folder is one line naming the file."""

from __future__ import annotations

import json
import os
import resource
import subprocess
import sys
import time
from pathlib import Path

import pytest

from stewart_drake.errors import StudyError
from stewart_drake.montecarlo.study import PARTIAL, PartialWriter, load_partial
from tests.cli._inprocess import cli

ROOT = Path(__file__).resolve().parents[2]
STUDY = ["montecarlo", "--runs", "2", "--workers", "0", "--duration", "0.2", "--no-progress"]


def test_out_dot_refused_before_any_run(here, capsys):
    """`--out .` ran every run, wrote into the working directory, then refused."""
    t0 = time.perf_counter()
    rc, _, err = cli(capsys, *STUDY, "--out", ".")
    assert rc == 2 and "--out '.': refusing to write into the working directory" in err
    assert time.perf_counter() - t0 < 5 and list(here.iterdir()) == []


def test_study_reruns_beside_its_replay_and_keeps_it(here, capsys):
    """After `--replay 0` the same study command was refused ("holds files stewart-drake did not write")."""
    rc, _, err = cli(capsys, *STUDY, "--out", "mc")
    assert rc in (0, 1), err
    rc, _, err = cli(capsys, *STUDY, "--out", "mc", "--replay", "0", "--no-animation")
    assert rc == 0, err
    replay = {p.name: p.read_bytes() for p in (here / "mc" / "replay-0").iterdir()}
    rc, _, err = cli(capsys, *STUDY, "--out", "mc")
    assert rc in (0, 1), err
    assert {p.name: p.read_bytes() for p in (here / "mc" / "replay-0").iterdir()} == replay
    # a study with other settings is still refused there, the replay untouched
    rc, _, err = cli(capsys, *STUDY[:-1], "--seed", "5", "--no-progress", "--out", "mc")
    assert rc == 2 and "another study" in err and (here / "mc" / "replay-0" / "row.json").is_file()


def test_disk_full_names_the_file_and_the_rerun_resumes(here, capsys):
    """A disk-full failure left a 0-byte partial and the rerun was refused ("another key (None...)")."""
    env = dict(os.environ, PYTHONPATH=str(ROOT), MPLBACKEND="Agg", PYTHONDONTWRITEBYTECODE="1")
    cmd = [sys.executable, "-m", "stewart_drake.cli", *STUDY, "--out", "mc"]

    def small_files():  # any file beyond 60 bytes fails to grow (EFBIG, as ENOSPC would)
        resource.setrlimit(resource.RLIMIT_FSIZE, (60, resource.RLIM_INFINITY))

    r = subprocess.run(cmd, cwd=here, env=env, capture_output=True, text=True, preexec_fn=small_files)
    assert r.returncode == 2 and "Traceback" not in r.stderr, r.stderr
    assert r.stderr.strip().startswith("stewart-drake montecarlo: error: --out 'mc': cannot write there (")
    assert "mc/" in r.stderr and "File too large" in r.stderr  # the file, the option, the reason
    assert not [p for p in here.rglob("*") if p.is_file() and p.stat().st_size == 0]
    rc, _, err = cli(capsys, *STUDY, "--out", "mc")
    assert rc in (0, 1), err
    assert (here / "mc" / "summary.json").is_file() and not (here / "mc" / PARTIAL).exists()


def _partial(folder: Path, rows: list[str]) -> None:
    w = PartialWriter(folder, "k" * 16)
    w.write({"run": 0, "x": 1.0})
    w.fh.append_texts(rows)  # lines that verify (system.journal), rows that are damaged
    w.close()


@pytest.mark.parametrize("row", ["{}", '{"run": "1"}', "[1]", "3"])
def test_damaged_partial_row_is_one_line(here, row):
    _partial(here / "mc", [row])
    with pytest.raises(StudyError, match=rf"^{here / 'mc' / PARTIAL}: damaged \(a row without a run index"):
        load_partial(here / "mc", "k" * 16)


@pytest.mark.parametrize("head", ["[1]", "{", '"key"'])
def test_damaged_partial_header_is_one_line(here, head):
    (here / "mc").mkdir()
    (here / "mc" / PARTIAL).write_text(head + "\n")
    with pytest.raises(StudyError, match=rf"^{here / 'mc' / PARTIAL}: damaged"):
        load_partial(here / "mc", "k" * 16)


@pytest.mark.parametrize("text", ["[]", "{", '{"settings": 3}'])
def test_damaged_study_json_is_one_line(here, capsys, text):
    (here / "mc").mkdir()
    (here / "mc" / "study.json").write_text(text)
    with pytest.raises(StudyError, match=r"study.json: damaged"):
        load_partial(here / "mc", "k" * 16)
    rc, _, err = cli(capsys, *STUDY, "--out", "mc", "--replay", "0")
    assert rc == 2 and len(err.strip().splitlines()) == 1


def test_study_json_edited_in_a_finished_folder_is_the_users(here, capsys):
    rc, _, err = cli(capsys, *STUDY, "--out", "mc")
    assert rc in (0, 1), err
    (here / "mc" / "study.json").write_text("[]")
    rc, _, err = cli(capsys, *STUDY, "--out", "mc")
    assert rc == 2 and "'study.json'" in err and "changed since" in err
    assert json.loads((here / "mc" / "study.json").read_text()) == []


def test_a_study_failing_before_its_first_run_leaves_no_folder(here):
    """Scheduler errors left folders: the journal (and its folder) is made at the first finished run."""
    w = PartialWriter(here / "mc", "k" * 16)
    w.close()
    assert not (here / "mc").exists()
