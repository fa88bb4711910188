"""CSV headers name the columns: a header's names put the columns in order (any order, known aliases), an
unknown or repeated name is refused at its line, and a bad first line is refused as soon as it is read."""

import json
import os
import threading
import time

import numpy as np
import pytest

from stewart_drake.cli import main
from stewart_drake.core.csvio import read_numeric_csv
from stewart_drake.errors import CsvError

POSES = np.array([[0.02, -0.01, 0.70, 0.05, -0.03, 0.1], [-0.015, 0.02, 0.72, -0.02, 0.04, -0.2]])


def _write(path, header, rows):
    path.write_text(header + "\n" + "".join(",".join(f"{v:.9g}" for v in r) + "\n" for r in rows))
    return str(path)


def test_ik_poses_honours_a_header_in_another_order(tmp_path, capsys):
    """``py,px,...`` with the columns swapped gives the lengths of the same poses in the usual order (the
    poses differ in px and py, so reading the columns as written would give other lengths)."""
    plain = _write(tmp_path / "plain.csv", "px,py,pz,a,b,g", POSES)
    swapped = _write(tmp_path / "swapped.csv", "PY, px,z,alpha,beta,gamma", POSES[:, [1, 0, 2, 3, 4, 5]])
    args = ["--platform", "utn-dynamic", "--length-unit", "m", "--angle-unit", "rad", "--json"]
    assert main(["ik", "--poses", plain, *args]) == 0
    want = json.loads(capsys.readouterr().out)["results"]
    assert main(["ik", "--poses", swapped, *args]) == 0
    got = json.loads(capsys.readouterr().out)["results"]
    assert [r["lengths"] for r in got] == [r["lengths"] for r in want]
    assert [r["pose"] for r in got] == POSES.tolist()  # echoed as px,py,pz,a,b,g


def test_dynamics_trajectory_honours_a_header_in_another_order(tmp_path, capsys):
    t = np.linspace(0, 1, 41)
    q = np.c_[0.01 * np.sin(3 * t), 0.02 * np.sin(2 * t), 0.7 + 0.01 * np.cos(t), 0.02 * t, 0 * t, -0.03 * t]
    plain = _write(tmp_path / "plain.csv", "t,px,py,pz,a,b,g", np.c_[t, q])
    swapped = _write(tmp_path / "swapped.csv", "time,pz,py,px,a_x,a_y,a_z", np.c_[t, q[:, [2, 1, 0, 3, 4, 5]]])
    assert main(["dynamics", "--trajectory", plain, "--json"]) == 0
    want = json.loads(capsys.readouterr().out)["forces"]
    assert main(["dynamics", "--trajectory", swapped, "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["forces"] == want


@pytest.mark.parametrize(
    "command,header,name",
    [("ik", "foo,bar,baz,qux,quux,corge", "foo"), ("dynamics", "t,px,py,pz,a,b,roll", "roll")],
)
def test_an_unknown_header_is_refused(tmp_path, capsys, command, header, name):
    rows = np.c_[np.arange(5) * 0.1, np.tile([0, 0, 0.7, 0, 0, 0], (5, 1))] if command == "dynamics" else POSES
    f = _write(tmp_path / "bad.csv", header, rows)
    option = "--trajectory" if command == "dynamics" else "--poses"
    assert main([command, option, f]) == 2
    err = capsys.readouterr().err
    assert f"{f}:1: the first line is a header (not all numbers), but {name!r} names no column" in err
    assert err.count("\n") == 1


def test_a_repeated_column_is_refused(tmp_path):
    f = _write(tmp_path / "twice.csv", "px,py,px,a,b,g", POSES)
    with pytest.raises(CsvError, match=r"twice.csv:1: the header \(px,py,px,a,b,g\) names px twice"):
        read_numeric_csv(f, "poses", (6,), "px,py,pz,a,b,g")


def test_a_bad_header_is_refused_before_the_rest_of_the_file_arrives(tmp_path):
    """A FIFO whose writer sends the header and one row, then holds the pipe open: the reader refuses at
    line 1 without waiting for the end of the file."""
    fifo = tmp_path / "poses.csv"
    os.mkfifo(fifo)
    done = threading.Event()

    def writer():
        with open(fifo, "w") as w:
            w.write("px,py,pz,a,b,g,extra\n0,0,0.7,0,0,0,0\n")
            w.flush()
            done.wait(20)

    th = threading.Thread(target=writer)
    th.start()
    try:
        start = time.monotonic()
        with pytest.raises(CsvError, match="poses.csv:1: expected 6 values"):
            read_numeric_csv(str(fifo), "poses", (6,), "px,py,pz,a,b,g")
        assert time.monotonic() - start < 10  # the writer holds the pipe 20 s
    finally:
        done.set()
        th.join()


def test_runs_own_trajectory_csv_header_is_read(tmp_path):
    """``run`` writes ``t,px,py,pz,alpha,beta,gama,px_dot,...,gama_ddot`` (the seed's spelling): its own
    output reads back as a 19-column trajectory, columns in place."""
    names = ("px", "py", "pz", "alpha", "beta", "gama")
    header = ["t", *names, *(n + "_dot" for n in names), *(n + "_ddot" for n in names)]
    rows = np.arange(38.0).reshape(2, 19)
    f = _write(tmp_path / "trajectory.csv", ",".join(header), rows)
    a, lines = read_numeric_csv(f, "trajectory", (7, 19), "see --help")
    assert np.array_equal(a, rows) and lines.tolist() == [2, 3]


def test_simulate_measurements_refuses_too_many_poses_while_reading(tmp_path, capsys):
    """More poses than simulate-measurements takes (10 000) are refused as the rows arrive: a FIFO whose
    writer sends 12 000 rows and holds the pipe open gets the refusal without the end of the file."""
    fifo = tmp_path / "plan.csv"
    os.mkfifo(fifo)
    done = threading.Event()

    def writer():
        try:
            with open(fifo, "w") as w:
                w.write("px,py,pz,a,b,g\n" + "0,0,0.1,0,0,0\n" * 12_000)
                w.flush()
                done.wait(20)
        except BrokenPipeError:  # the reader refused and closed its end
            pass

    th = threading.Thread(target=writer)
    th.start()
    try:
        start = time.monotonic()
        assert main(["simulate-measurements", "--poses", str(fifo), "--out", str(tmp_path / "out")]) == 2
        assert time.monotonic() - start < 10  # the writer holds the pipe 20 s
    finally:
        done.set()
        th.join()
    assert f"{fifo}: more than 10000 poses" in capsys.readouterr().err
