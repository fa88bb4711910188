"""``stewart-drake optimize`` end to end on seed 001's requirements: a proven design whose design.yaml every
command takes, requirements.json complete; ``workspace --prove`` on a larger box: violated, a witness, exit 1."""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
import time
from importlib import resources
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq

from stewart_drake.cli import main
from stewart_drake.core.geometry import load_platform_yaml
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.core.sanity import plate_anchor_heights
from stewart_drake.errors import OutputError
from stewart_drake.synthesis.requirements import load_requirements

ROOT = Path(__file__).resolve().parents[2]
SEED_001 = str(resources.files("stewart_drake") / "examples" / "seed_001_requirements.yaml")


def test_optimize_writes_a_proven_platform_file(tmp_path, capsys):
    out = tmp_path / "o"
    rc = main(["optimize", "--requirements", SEED_001, "--out", str(out), "--budget", "48", "--pop-size", "16",
               "--workers", "0", "--json"])  # fmt: skip
    result = json.loads(capsys.readouterr().out)
    assert rc == 0 and result["ok"] and result["proof"]["status"] == "proven"
    for name in ("pareto.parquet", "pareto.csv", "pareto.png", "design.yaml", "requirements.json", "evaluations.jsonl"):
        assert (out / name).is_file(), name
    table = pq.read_table(out / "pareto.parquet").to_pydict()
    assert sum(table["chosen"]) == 1 and len(table["row"]) == len(result["search"]["front"])
    reqs = json.loads((out / "requirements.json").read_text())["requirements"]
    assert {"required", "achieved", "margin", "established"} <= set(reqs[0]) and all(r["met"] for r in reqs)
    # design.yaml is an ordinary platform file: stroke, home height, payload as plate, actuator as legs
    p = load_platform_yaml(out / "design.yaml")
    req = load_requirements(SEED_001)
    d = result["design"]
    assert p.L_min == d["L_min"] and p.L_max == d["L_max"] and p.mass == req.mass
    assert p.legs.max_force == req.max_force and p.legs.stiffness == req.stiffness
    # a sample of the required box on the file's platform (the proof covers every pose)
    rng = np.random.default_rng(0)
    poses = p.home_pose() + req.box_lo + rng.random((20_000, 6)) * (req.box_hi - req.box_lo)
    L = leg_lengths(p, poses)
    assert np.all((L >= p.L_min) & (L <= p.L_max)) and np.all(plate_anchor_heights(p, poses) > 0)
    assert (
        main(
            ["ik", "--platform", str(out / "design.yaml"), "--pose", "0", "0", f"{p.home_height * 1e3}", "0", "0", "0"]
        )
        == 0
    )
    box = np.c_[req.box_lo, req.box_hi]
    box[3:] = np.degrees(box[3:])
    args = ["workspace", "--platform", str(out / "design.yaml"), "--prove", "--json", "--require-box"]
    capsys.readouterr()
    assert main(args + [f"{v}" for v in box.ravel()]) == 0
    assert json.loads(capsys.readouterr().out)["status"] == "proven"
    # an infeasible requirement on the same design: twice the box -> violated, a witness, exit 1
    assert main(args + [f"{v}" for v in (2 * box).ravel()]) == 1
    proof = json.loads(capsys.readouterr().out)
    assert proof["status"] == "violated"
    w = proof["witness"]
    L = leg_lengths(p, np.array(w["pose"]))[w["leg"] - 1]
    assert L < p.L_min or L > p.L_max or w["what"].startswith("plate")


def test_unmeetable_requirements_exit_1_with_the_reason(tmp_path, capsys):
    """A 1 N actuator meets nothing: exit 1 (a result, not bad input), one line naming the least violated."""
    text = (resources.files("stewart_drake") / "examples" / "seed_001_requirements.yaml").read_text()
    path = tmp_path / "r.yaml"
    path.write_text(text.replace("max_force: 5000", "max_force: 1"))
    rc = main(["optimize", "--requirements", str(path), "--out", str(tmp_path / "o"), "--budget", "12",
               "--pop-size", "12", "--workers", "0"])  # fmt: skip
    err = capsys.readouterr().err.strip()
    assert rc == 1 and len(err.splitlines()) == 1
    assert "no design among 12 evaluated meets every requirement (least violated: force by" in err


def test_prove_unresolved_exits_1(capsys):
    box = ["-0.07", "0.07", "-0.09", "0.09", "-0.05", "0.045", "-8", "7", "-6", "6", "-9", "9"]
    rc = main(["workspace", "--platform", "gonzalez-dutra-2009", "--prove", "--max-cells", "5", "--json",
               "--require-box", *box])  # fmt: skip
    out = json.loads(capsys.readouterr().out)
    assert rc == 1 and out["status"] == "unresolved" and out["unresolved_count"] > 0


def test_optimize_exits_1_when_the_performance_proof_is_unresolved(tmp_path, capsys):
    """``--max-cells 60``: the box's stroke is proven in 48 cells, force/frequency/condition need more: each says
    ``unresolved`` in requirements.json (``met`` false, the cells left counted), "not proven yet" on the terminal,
    and the exit status is 1."""
    out = tmp_path / "o"
    rc = main(["optimize", "--requirements", SEED_001, "--out", str(out), "--budget", "48", "--pop-size", "16",
               "--workers", "0", "--max-cells", "60"])  # fmt: skip
    text = capsys.readouterr().out
    assert rc == 1 and "proof of the box: proven" in text
    doc = json.loads((out / "requirements.json").read_text())
    perf = {r["requirement"]: r for r in doc["requirements"] if "status" in r}
    assert set(perf) == {"actuator.max_force", "actuator.max_speed", "limits.min_frequency_hz", "limits.max_condition"}
    # speed is proven on the 48 cells of the first level (each cell carries the requirements still open on it)
    assert perf.pop("actuator.max_speed")["status"] == "proven"
    assert all(r["status"] == "unresolved" and not r["met"] for r in perf.values())
    assert doc["performance_proof"]["requirements"]["force"]["unresolved_count"] > 0 and not doc["ok"]
    # an unfinished proof reads as one: not proven yet, the cells used and left, why it stopped; never NOT MET
    used = doc["performance_proof"]["cells_examined"]
    assert "NOT MET" not in text and doc["performance_proof"]["stopped"] == "cap"
    for name, r in perf.items():
        key = {
            "actuator.max_force": "force",
            "limits.min_frequency_hz": "frequency",
            "limits.max_condition": "condition",
        }
        left = doc["performance_proof"]["requirements"][key[name]]["unresolved_count"]
        assert (r["cells_used"], r["cells_left"]) == (used, left)
        assert f" ({used} cells used, {left} left; the cell cap (--max-cells) was reached)" in text
        assert re.search(rf"not proven yet +{name}: required [0-9.]+, sampled [0-9.]+ [NHz]* \({used} cells used", text)


def test_a_finished_search_continues_with_a_larger_budget(tmp_path, capsys):
    """The same folder with a larger ``--budget``: the first run's 24 designs come from its journal, 12 more are
    evaluated and appended, and the run writes its outputs (the journal stays claimed as append-only: claimed whole,
    its growth was read as a change and the run refused at its end, exit 2)."""
    out = tmp_path / "o"
    args = ["optimize", "--requirements", SEED_001, "--out", str(out), "--pop-size", "12", "--workers", "0",
            "--max-cells", "60", "--json"]  # fmt: skip
    assert main(args + ["--budget", "24"]) in (0, 1)
    capsys.readouterr()
    assert main(args + ["--budget", "36"]) in (0, 1)
    search = json.loads(capsys.readouterr().out)["search"]
    assert (search["evaluated_now"], search["from_cache"], search["designs"]) == (12, 24, 36)
    assert len((out / "evaluations.jsonl").read_text().splitlines()) == 1 + 36


def test_a_second_optimize_into_a_running_ones_folder_is_refused(tmp_path, capsys):
    """Two runs into one --out both ran, appending to one journal (9,097 lines for 4,800 designs): the folder is
    held for the first run's lifetime and the second is refused before any work (exit 2, one line), the first's
    journal untouched by it."""
    out = tmp_path / "o"
    env = dict(os.environ, PYTHONPATH=str(ROOT), MPLBACKEND="Agg", PYTHONDONTWRITEBYTECODE="1")
    first = subprocess.Popen(
        [sys.executable, "-m", "stewart_drake", "optimize", "--requirements", SEED_001, "--out", str(out),
         "--budget", "100000", "--workers", "0", "--no-progress"],
        env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    try:
        t0 = time.monotonic()
        while not (out / "evaluations.jsonl").exists() and first.poll() is None and time.monotonic() - t0 < 60:
            time.sleep(0.05)
        assert first.poll() is None, first.stderr.read()
        rc = main(["optimize", "--requirements", SEED_001, "--out", str(out), "--budget", "24", "--workers", "0"])
        err = capsys.readouterr().err.strip()
        assert rc == 2 and err.splitlines() == [
            f"stewart-drake optimize: error: {OutputError.BUSY.format(option='--out', typed=str(out))}"
        ]
        xs = [tuple(json.loads(line)["row"]["x"]) for line in (out / "evaluations.jsonl").read_text().splitlines()[1:]]
        assert len(set(xs)) == len(xs)  # one search's designs, none twice
    finally:
        first.kill()
        first.wait()


def test_a_box_proof_out_of_cells_reads_not_proven_yet_on_each_of_its_rows(tmp_path, capsys):
    """``--max-cells 10``: the box's first level is 48 cells, so its proof (stroke, joint cone) stops before any:
    each row it decides says how far it got, and the exit status is 1."""
    rc = main(["optimize", "--requirements", SEED_001, "--out", str(tmp_path / "o"), "--budget", "12",
               "--pop-size", "12", "--workers", "0", "--max-cells", "10"])  # fmt: skip
    text = capsys.readouterr().out
    note = "(0 cells used, 48 left; the cell cap (--max-cells) was reached)"
    assert rc == 1 and f"proof of the box: not proven yet {note}" in text and "NOT MET" not in text
    for name in ("workspace: every pose of the box", "limits.joint_cone: every pose of the box"):
        assert re.search(rf"not proven yet +{re.escape(name)}[^\n]*: {re.escape(note)}", text), name
