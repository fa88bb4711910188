"""Inputs are read once, as a stream with a byte budget (issue 24, item 1d and the file items of 10): a
device, a FIFO or a process substitution works like a file, an endless one is refused by the budget (its
``stat`` size is 0), and worker counts follow one rule."""

from __future__ import annotations

import os
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from stewart_drake.core.trajectory import read_trajectory_table
from stewart_drake.system.processes import max_workers
from tests.cli._inprocess import cli

POSES = "px,py,pz,a,b,g\n0,0,0.7,0,0,0\n0.01,0,0.71,0,0,0\n"
TRAJ = "t,x,y,z,a,b,c\n0,0,0,0.70,0,0,0\n0.5,0,0,0.71,0,0,0\n1,0,0,0.72,0,0,0\n1.5,0,0,0.71,0,0,0\n"


def pipe_path(text: str) -> str:
    """A process substitution ``<(printf ...)``: the read end of a pipe as ``/dev/fd/N``, written by a thread."""
    r, w = os.pipe()

    def feed():
        with os.fdopen(w, "w") as fh:
            fh.write(text)

    threading.Thread(target=feed, daemon=True).start()
    return f"/dev/fd/{r}"


def test_dev_zero_as_poses_is_refused_by_the_budget(here, capsys):
    """`ik --poses /dev/zero` grew to 24 GB (the size check read stat: 0 for a device)."""
    t0 = time.perf_counter()
    rc, _, err = cli(capsys, "ik", "--platform", "utn-dynamic", "--poses", "/dev/zero")
    assert rc == 2 and err.startswith("stewart-drake ik: error: /dev/zero:1: a line longer than")
    assert time.perf_counter() - t0 < 10


def test_dev_zero_as_platform_is_not_a_folder(here, capsys):
    rc, _, err = cli(capsys, "ik", "--platform", "/dev/zero", "--pose", "0", "0", "700", "0", "0", "0")
    assert rc == 2 and "larger than the 1000000-byte limit for a platform file" in err and "folder" not in err


def test_process_substitution_is_read_once(here, capsys):
    """`<(...)` was refused as "no rows": the fast path read the pipe, the line reader found it empty."""
    rc, out, err = cli(capsys, "ik", "--platform", "utn-dynamic", "--length-unit", "m", "--poses", pipe_path(POSES))
    assert rc in (0, 1), err
    rc2, out2, _ = cli(capsys, "ik", "--platform", "utn-dynamic", "--length-unit", "m", "--poses", _file(here, POSES))
    assert (rc, out.splitlines()[1:]) == (rc2, out2.splitlines()[1:])


def test_finished_fifo_as_trajectory_does_not_hang(here, capsys):
    """A FIFO given to `dynamics --trajectory` hung: the CSV was opened twice."""
    fifo = here / "t.csv"
    os.mkfifo(fifo)

    def feed():
        with open(fifo, "w") as fh:
            fh.write(TRAJ)

    threading.Thread(target=feed, daemon=True).start()
    rc, out, err = cli(capsys, "dynamics", "--platform", "utn-dynamic", "--trajectory", "t.csv", "--csv")
    assert rc == 0, err
    fifo.unlink()
    rc2, out2, _ = cli(capsys, "dynamics", "--platform", "utn-dynamic", "--trajectory", _file(here, TRAJ), "--csv")
    assert out == out2


def test_trajectory_table_from_a_pipe_equals_the_file(here):
    """montecarlo's CSV reference read the file twice (load + table): one read now, the same numbers."""
    name, ts, poses = read_trajectory_table(pipe_path(TRAJ), "m", "rad")
    _, ts2, poses2 = read_trajectory_table(_file(here, TRAJ), "m", "rad")
    assert np.array_equal(ts, ts2) and np.array_equal(poses, poses2) and len(ts) == 4


@pytest.mark.parametrize("command", ["montecarlo", "workspace", "report"])
def test_worker_counts_follow_one_rule(here, capsys, command):
    """`montecarlo --workers 1000` started 1000 Dask workers on 2 cores."""
    option = "--jobs" if command == "report" else "--workers"
    t0 = time.perf_counter()
    rc, _, err = cli(capsys, command, option, "1000", "--out", "o")
    assert err.strip().endswith(
        f"error: {option} must be between {0 if command == 'montecarlo' else 1} and {max_workers()}, got 1000"
    )
    assert time.perf_counter() - t0 < 5 and not (here / "o").exists()


def test_binary_c_file_is_one_line(here, capsys):
    """A binary `.c` file printed a UTF-8 codec error."""
    (here / "bin.c").write_bytes(b"int x;\n\xff\xfe\x00garbage")
    rc, _, err = cli(capsys, "firmware", "check", "bin.c")
    assert (
        rc == 2
        and err.strip() == "stewart-drake firmware: error: bin.c:2: not UTF-8 text (byte 7); not a C source file?"
    )


def test_vary_yaml_duplicate_keys_and_size(here, capsys):
    (here / "v.yaml").write_text("sensor_noise: 1um\nlatency_jitter: 1ms\nsensor_noise: 2um\n")
    rc, _, err = cli(capsys, "montecarlo", "--vary", "v.yaml", "--runs", "2", "--out", "o")
    assert rc == 2 and "v.yaml:3: 'sensor_noise' is given twice (first on line 1)" in err
    (here / "big.yaml").write_text("sensor_noise: 1um\n" + "#" * 200_000 + "\n")
    rc, _, err = cli(capsys, "montecarlo", "--vary", "big.yaml", "--runs", "2", "--out", "o")
    assert rc == 2 and "big.yaml" in err and "100000-byte limit" in err
    assert not (here / "o").exists()


def _file(folder: Path, text: str) -> str:
    p = folder / f"f{abs(hash(text))}.csv"
    p.write_text(text)
    return str(p)


@pytest.mark.parametrize("keep", [0.5, 0.05, 0.9])
def test_truncated_replay_npz_is_one_line(here, capsys, keep):
    """`view --replay` of a truncated npz printed a BadZipFile traceback."""
    np.savez(here / "log.npz", t=np.arange(50.0), pose=np.zeros((50, 6)), status=np.zeros((50, 4)), platform="p")
    data = (here / "log.npz").read_bytes()
    (here / "cut.npz").write_bytes(data[: int(len(data) * keep)])
    rc, out, err = cli(capsys, "view", "--replay", "cut.npz")
    assert rc == 2 and out == "" and err.startswith("stewart-drake view: error: --replay cut.npz: not a simulate log (")
