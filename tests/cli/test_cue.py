"""``stewart-drake cue``: the files it writes (the poses read back by ``simulate``'s CSV reader), the output-folder
rules, and refusals of bad input (exit 2, one line naming the flag and the value)."""

import json

import numpy as np

from stewart_drake.control.cueing.drive import save_drive
from stewart_drake.control.cueing.generators import DRIVES
from stewart_drake.core.trajectory import load_trajectory_csv
from tests.cli._inprocess import cli


def test_writes_poses_scores_and_plots(here, capsys):
    rc, out, err = cli(capsys, "cue", "--platform", "gonzalez-dutra-2009", "--drive", "car-lane-change", "--out", "c")
    assert rc == 0, err
    summary = json.loads(out)
    assert sorted(p.name for p in (here / "c").iterdir() if not p.name.startswith(".")) == [
        "legs.png",
        "perception.png",
        "poses.csv",
        "scores.json",
    ]
    full = json.loads((here / "c" / "scores.json").read_text())
    assert full["scores"] == {**summary["scores"], "channels": full["scores"]["channels"]}
    assert (
        "params" in full
        and "params" not in summary
        and set(full["scores"]["channels"])
        == {
            "fx",
            "fy",
            "fz",
            "wx",
            "wy",
            "wz",
        }
    )
    # the poses as simulate --trajectory reads them: one row per drive sample, SI
    traj = load_trajectory_csv(str(here / "c" / "poses.csv"))
    t = np.loadtxt(here / "c" / "poses.csv", delimiter=",", skiprows=1)[:, 0]
    assert len(t) == full["samples"] and traj.duration == t[-1]
    assert np.allclose(traj.pose(t)[:, 2], np.loadtxt(here / "c" / "poses.csv", delimiter=",", skiprows=1)[:, 3])


def test_a_drive_file_is_read(here, capsys):
    save_drive(DRIVES["car-lane-change"](), here / "d.csv")
    rc, out, err = cli(
        capsys, "cue", "--platform", "gonzalez-dutra-2009", "--drive", "d.csv", "--out", "c", "--json", "--animate"
    )
    assert rc == 0, err
    assert "params" in json.loads(out)
    assert (here / "c" / "animation.html").read_text().startswith("<!DOCTYPE html>")


def test_refusals_name_the_flag(here, capsys):
    rc, _, err = cli(capsys, "cue", "--platform", "utn-dynamic", "--drive", "no-such", "--out", "c")
    assert rc == 2 and err.strip().endswith(
        "--drive 'no-such': neither a shipped drive (" + ", ".join(DRIVES) + ") nor a drive file (.csv, .parquet)"
    )
    rc, _, err = cli(
        capsys, "cue", "--drive", "car-lane-change", "--algorithm", "mpc", "--params", "p.yaml", "--out", "c"
    )
    assert rc == 2 and "--params only applies with --algorithm classical or tuned" in err
    rc, _, err = cli(capsys, "cue", "--drive", "car-lane-change", "--joint-cone", "200", "--out", "c")
    assert rc == 2 and err.strip().endswith("--joint-cone must be between 0 (excluded) and 180 degrees, got 200")
    rc, _, err = cli(capsys, "cue", "--drive", "car-lane-change", "--no-progress", "--out", "c")
    assert rc == 2 and "--no-progress only applies with --simulate" in err
    rc, _, err = cli(capsys, "cue", "--drive", "car-lane-change", "--algorithm", "washout", "--out", "c")
    assert rc == 2 and "invalid choice: 'washout'" in err
    assert not (here / "c").exists()  # nothing written on a refusal


def test_never_writes_over_a_users_file(here, capsys):
    (here / "c").mkdir()
    (here / "c" / "poses.csv").write_text("mine\n")
    rc, _, err = cli(capsys, "cue", "--platform", "gonzalez-dutra-2009", "--drive", "car-lane-change", "--out", "c")
    assert rc == 2 and "poses.csv" in err
    assert (here / "c" / "poses.csv").read_text() == "mine\n"
