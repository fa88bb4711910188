"""Record the observable behaviour of the ``stewart-drake`` command line, to compare two trees.

``python scripts/record_behaviour.py OUTDIR [--quick-report] [--no-report] [--only NAME ...]`` runs a fixed
list of CLI calls (``CALLS``: every subcommand, three platform presets, bad-input and out-of-limits cases)
as ``python -m stewart_drake.cli ...`` in one fresh temporary working directory, with ``PYTHONPATH`` = the
repository this script sits in, and writes one ``OUTDIR/NN-name.json`` per call::

    {"name", "argv", "exit_code", "stdout": <parsed JSON, or the raw text>, "stderr": <text>,
     "files": {relative path: content}}

``files`` holds what the call wrote into its output folder or file: JSON (and JSON-lines) files parsed, CSV files
as header + rows of strings (the text as written, so numbers compare bit for bit), other text files as their
lines, NumPy ``.npz`` archives as the SHA-256 of each member (a zip's own timestamps are not data), Parquet
files as their columns (read by pyarrow in a child process), any other binary (PNG) as its SHA-256 and size. Then it
records the fixed-point loop's feed-forward words (``FEEDFORWARD_CASES``, ``OUTDIR/feedforward-words.json``: a child
process of the recorded tree, the one place this script runs the package's Python API) and runs ``report --quick`` and
(unless ``--quick-report``) the full ``report`` and copies each one's ``checks.json`` (parsed) with its exit
code into ``OUTDIR/report-quick.json`` / ``OUTDIR/report-full.json``; ``OUTDIR/manifest.json`` lists the
calls, the interpreter, the repository's git commit and the wall times.

Standard library and subprocess only, no ``stewart_drake`` import: the same script records the tree before and
after a restructuring, and ``scripts/compare_behaviour.py A B`` compares two recordings.

Normalisation (``normalise``): every string has the temporary working directory replaced by ``<TMP>`` and the
repository root by ``<REPO>`` (both differ from run to run or from checkout to checkout). Fields that are
legitimately run-dependent (wall times) are removed by ``compare_behaviour.py`` (its ``VOLATILE`` list),
not here, so that a recording keeps everything the tool printed.

The calls are deterministic: every random draw has a fixed ``--seed``, ``PYTHONHASHSEED=0``, the C build cache
(``STEWART_DRAKE_CACHE``) is a fresh folder inside the working directory so every C compile is cold, progress
bars are off, and every output goes into the working directory (never into the repository).
"""

from __future__ import annotations

import argparse
import csv
import hashlib
import io
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
import zipfile
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
PYTHON = sys.executable

# Input files the calls read, written into the working directory before the first call.
INPUTS = {
    # ik --poses: utn-dynamic poses in metres / radians (t column absent: ik takes pose rows).
    "poses.csv": "px,py,pz,a,b,g\n0,0,0.7,0,0,0\n0.05,-0.02,0.72,0.05,-0.03,0.1\n-0.08,0.04,0.68,-0.1,0.02,-0.05\n",
    # dynamics/size --trajectory FILE.csv: t + pose (derivatives by cubic spline), utn-dynamic, metres/radians.
    "traj.csv": (
        "t,px,py,pz,a,b,g\n"
        "0.0,0,0,0.70,0,0,0\n0.1,0.01,0,0.705,0.01,0,0\n0.2,0.03,0.01,0.71,0.02,-0.01,0.02\n"
        "0.3,0.05,0.02,0.72,0.03,-0.02,0.03\n0.4,0.06,0.02,0.72,0.03,-0.02,0.04\n0.5,0.06,0.02,0.72,0.03,-0.02,0.04\n"
    ),
    # dynamics --trajectory: a rise that leaves the stroke (utn-dynamic legs pass 0.95 m near pz = 0.92 m, t = 0.11 s).
    "traj-high.csv": "t,px,py,pz,a,b,g\n0.0,0,0,0.70,0,0,0\n0.05,0,0,0.80,0,0,0\n0.1,0,0,0.90,0,0,0\n0.15,0,0,1.00,0,0,0\n",
    # size --envelope: a box of poses with symmetric velocity/acceleration bounds (utn-dynamic, m / rad).
    "envelope.yaml": (
        "length_unit: mm\nangle_unit: deg\n"
        "box: {min: [-40, -40, 690, -4, -4, -8], max: [40, 40, 710, 4, 4, 8], steps: [2, 2, 2, 2, 2, 2]}\n"
        "velocity: {linear: [200, 200, 100], angular: [20, 20, 40]}\n"
        "acceleration: {linear: [2000, 2000, 4000], angular: [200, 200, 400]}\n"
    ),
    # A program with a syntax error on line 3 (exit 2 with file:line:column).
    "bad.stw": "units mm, deg\nmover(0, 0, 200, 0, 0, 0) en 1.5\nmover(x = ) en 1\n",
    # A platform file with a non-numeric stroke (exit 2 naming the field).
    "bad-platform.yaml": "name: bad\nlength_unit: m\nutn: {b: 0.4, d: 0.1, a: 0.2}\nstroke: [0.55, fast]\n",
    # A file that is not the tool's: --out into its folder must be refused (exit 2).
    "occupied/keep.txt": "not written by stewart-drake\n",
}

# (name, argv after ``python -m stewart_drake.cli``, output path the call writes or None).
# Example programs are copied from examples/ into the working directory, so their paths are relative.
# fmt: off
UD = ["--platform", "utn-dynamic"]
UK = ["--platform", "utn-kinematic"]
GD = ["--platform", "gonzalez-dutra-2009"]
CALLS: list[tuple[str, list[str], str | None]] = [
    # ik
    ("ik-utn-kinematic", ["ik", *UK, "--pose", "10", "-20", "110", "5", "-3", "8", "--angle-unit", "deg", "--json"], None),
    ("ik-utn-dynamic-mm-deg", ["ik", *UD, "--pose", "20", "10", "720", "3", "2", "-4", "--length-unit", "mm", "--angle-unit", "deg", "--json"], None),
    ("ik-gonzalez-zyx", ["ik", *GD, "--pose", "30", "-20", "660", "3", "-2", "5", "--convention", "zyx", "--json"], None),
    ("ik-poses-csv", ["ik", *UD, "--poses", "poses.csv", "--length-unit", "m", "--angle-unit", "rad", "--json"], None),
    ("ik-unreachable", ["ik", *UD, "--pose", "0", "0", "1500", "0", "0", "0", "--json"], None),
    ("ik-nan-pose", ["ik", *UD, "--pose", "0", "0", "nan", "0", "0", "0", "--json"], None),
    ("ik-unknown-platform", ["ik", "--platform", "no-such-preset", "--pose", "0", "0", "700", "0", "0", "0", "--json"], None),
    ("ik-bad-platform-file", ["ik", "--platform", "bad-platform.yaml", "--pose", "0", "0", "700", "0", "0", "0", "--json"], None),
    ("ik-unit-mistake", ["ik", *UD, "--pose", "0", "0", "700", "0", "0", "0", "--length-unit", "m", "--json"], None),
    # fk
    ("fk-newton-utn-dynamic-m", ["fk", *UD, "--lengths", "0.745738", "0.756684", "0.751015", "0.760564", "0.746451", "0.738831", "--length-unit", "m", "--angle-unit", "rad", "--json"], None),
    ("fk-newton-utn-kinematic-initial", ["fk", *UK, "--lengths", "515.165", "455.341", "538.850", "403.308", "521.213", "424.916", "--initial", "0", "0", "100", "0", "0", "0", "--json"], None),
    ("fk-all-homotopy-utn-dynamic", ["fk", *UD, "--lengths", "745.738", "756.684", "751.015", "760.564", "746.451", "738.831", "--all", "--json"], None),
    ("fk-all-homotopy-gonzalez", ["fk", *GD, "--lengths", "777.449", "758.424", "785.068", "774.366", "782.133", "711.266", "--all", "--json"], None),
    ("fk-all-multistart-utn-dynamic", ["fk", *UD, "--lengths", "745.738", "756.684", "751.015", "760.564", "746.451", "738.831", "--all", "--method", "multi-start", "--seed", "3", "--json"], None),
    ("fk-all-homotopy-gonzalez-b", ["fk", *GD, "--lengths", "750", "780", "720", "760", "740", "770", "--all", "--json"], None),
    ("fk-all-no-real-mode", ["fk", *UD, "--lengths", "0.75", "0.76", "0.74", "0.75", "0.77", "0.73", "--all", "--json"], None),
    ("fk-max-iter-too-big", ["fk", *UD, "--lengths", "750", "750", "750", "750", "750", "750", "--max-iter", "5000", "--json"], None),
    # dynamics
    ("dynamics-seed", ["dynamics", *UD, "--trajectory", "seed", "--json"], None),
    ("dynamics-seed-nocoriolis", ["dynamics", *UD, "--trajectory", "seed", "--coriolis", "off", "--json"], None),
    ("dynamics-seed-legs", ["dynamics", *UD, "--trajectory", "seed", "--legs", "on", "--json"], None),
    ("dynamics-legs-without-coriolis", ["dynamics", *UD, "--trajectory", "seed", "--coriolis", "off", "--legs", "on", "--json"], None),
    ("dynamics-csv", ["dynamics", *UD, "--trajectory", "traj.csv", "--length-unit", "m", "--angle-unit", "rad", "--json"], None),
    ("dynamics-out-of-stroke", ["dynamics", *UD, "--trajectory", "traj-high.csv", "--length-unit", "m", "--angle-unit", "rad", "--json"], None),
    ("dynamics-bad-gravity", ["dynamics", *UD, "--trajectory", "seed", "--gravity", "500", "--json"], None),
    # dsp-ik
    ("dsp-ik-python", ["dsp-ik", "--pose", "0", "0", "100", "0.01", "-0.02", "0.03", "--json"], None),
    ("dsp-ik-python-deg-trace", ["dsp-ik", "--pose", "20", "-15", "130", "4", "3", "-6", "--angle-unit", "deg", "--trace", "--json"], None),
    ("dsp-ik-c", ["dsp-ik", "--pose", "0", "0", "100", "0.01", "-0.02", "0.03", "--engine", "c", "--json"], None),
    # workspace
    ("workspace-gonzalez", ["workspace", *GD, "--resolution", "0.05", "--json"], None),
    ("workspace-utn-dynamic-tilted-out", ["workspace", *UD, "--orientation", "5", "0", "10", "--resolution", "0.04", "--limits", "stroke,joints", "--json", "--out", "ws"], "ws"),
    ("workspace-resolution-too-fine", ["workspace", *GD, "--resolution", "1e-7", "--json"], None),
    ("workspace-out-occupied", ["workspace", *GD, "--resolution", "0.05", "--json", "--out", "occupied"], None),
    # servo
    ("servo-pose", ["servo", "--pose", "5", "-5", "110", "3", "-2", "4", "--json"], None),
    ("servo-from-home", ["servo", "--pose", "3", "0", "5", "0", "2", "0", "--from-home", "--json"], None),
    ("servo-trim-out-of-range", ["servo", "--pose", "0", "0", "0", "0", "0", "0", "--from-home", "--trim", "2400", "1500", "1500", "1500", "1500", "1500", "--json"], None),
    # leg (mm, degrees)
    ("leg-fk", ["leg", "fk", "30", "45"], None),
    ("leg-ik-both", ["leg", "ik", "132.092", "-116.072", "--gamma", "29.6", "--branch", "both"], None),
    ("leg-fk-outside-limits", ["leg", "fk", "400", "0"], None),
    ("leg-sdf", ["leg", "sdf", "--write", "legsdf"], "legsdf"),
    # model
    ("model-inspect-utn-dynamic", ["model", *UD, "--inspect", "--json"], None),
    ("model-inspect-gonzalez", ["model", *GD, "--inspect", "--json"], None),
    ("model-write-utn-kinematic", ["model", *UK, "--write", "models"], "models"),
    # simulate (no --json: the summary is summary.json in --out)
    ("simulate-fixed-cenic", ["simulate", *UD, "--trajectory", "seed", "--controller", "fixed", "--integrator", "cenic", "--duration", "0.15", "--no-progress", "--out", "sim1"], "sim1"),
    ("simulate-float-sap", ["simulate", *UD, "--trajectory", "seed", "--controller", "float", "--integrator", "sap", "--duration", "0.15", "--no-progress", "--out", "sim2"], "sim2"),
    ("simulate-fixed-c-rotating", ["simulate", *UD, "--trajectory", "rotating", "--controller", "fixed", "--engine", "c", "--latency", "none", "--duration", "0.1", "--no-progress", "--out", "sim3"], "sim3"),
    ("simulate-period-too-long", ["simulate", *UD, "--trajectory", "seed", "--period", "0.5", "--duration", "0.1", "--no-progress", "--out", "sim4"], "sim4"),
    ("simulate-out-of-stroke", ["simulate", *UD, "--trajectory", "traj-high.csv", "--length-unit", "m", "--angle-unit", "rad", "--duration", "0.15", "--no-progress", "--out", "sim5"], "sim5"),
    # motion programs
    ("run-circle", ["run", "circle.stw", *UK, "--out", "run-circle", "--json"], "run-circle"),
    ("run-seed-004", ["run", "seed_004.stw", "--out", "run-seed", "--json"], "run-seed"),
    ("run-circle-check-branches", ["run", "circle.stw", *UK, "--check-branches", "--branch-samples", "5", "--out", "run-circle-cb", "--json"], "run-circle-cb"),
    ("run-syntax-error", ["run", "bad.stw", *UK, "--out", "run-bad", "--json"], "run-bad"),
    ("compile-python", ["compile", "circle.stw", "--emit", "python"], None),
    ("compile-matlab", ["compile", "seed_004.stw", "--emit", "matlab"], None),
    # design
    ("size-seed", ["size", *UD, "--trajectory", "seed", "--json"], None),
    ("size-program-payload", ["size", *UK, "--program", "circle.stw", "--payload", "2", "--json"], None),
    ("size-envelope", ["size", *UD, "--envelope", "envelope.yaml", "--json"], None),
    ("size-force-violation", ["size", *UD, "--trajectory", "seed", "--payload", "60", "--json"], None),
    ("stiffness-utn-dynamic", ["stiffness", *UD, "--pose", "20", "0", "720", "2", "0", "5", "--payload", "3", "--payload-com", "0", "0", "50", "--json"], None),
    ("stiffness-gonzalez-legs", ["stiffness", *GD, "--pose", "0", "0", "0.66", "0", "0", "0", "--length-unit", "m", "--leg-stiffness", "2e6", "--legs", "on", "--json"], None),
    ("modes-utn-dynamic", ["modes", *UD, "--pose", "0", "0", "700", "0", "0", "0", "--json"], None),
    ("modes-utn-dynamic-drake", ["modes", *UD, "--pose", "20", "0", "700", "0", "3", "0", "--leg-damping", "50", "--drake", "--json"], None),
    # firmware (check compiles the file that generate wrote)
    ("firmware-generate", ["firmware", "generate", *UD, "--out", "fw", "--json"], "fw"),
    ("firmware-check", ["firmware", "check", "fw/sd_firmware.c", *UD, "--poses", "2000", "--duration", "0.1", "--json"], None),
    ("firmware-check-missing-file", ["firmware", "check", "fw/missing.c", *UD, "--json"], None),
    # montecarlo (in-process, 3 short runs)
    ("montecarlo", ["montecarlo", *UD, "--trajectory", "seed", "--runs", "3", "--seed", "7", "--vary", "anchor=±0.5mm", "sensor_noise=10um", "gain_scale=±10%", "--duration", "0.1", "--workers", "0", "--no-animation", "--no-progress", "--out", "mc", "--json"], "mc"),
    ("montecarlo-replay", ["montecarlo", *UD, "--trajectory", "seed", "--runs", "3", "--seed", "7", "--vary", "anchor=±0.5mm", "sensor_noise=10um", "gain_scale=±10%", "--duration", "0.1", "--workers", "0", "--no-progress", "--replay", "1", "--out", "mc", "--json"], "mc/replay-1"),
    ("montecarlo-bad-vary", ["montecarlo", *UD, "--trajectory", "seed", "--runs", "3", "--seed", "7", "--vary", "wobble=3", "--duration", "0.1", "--workers", "0", "--no-progress", "--out", "mc-bad", "--json"], "mc-bad"),
    # view: draw one pose and exit (Meshcat on localhost; the port it got is on stderr)
    ("view-pose", ["view", *UD, "--pose", "10", "0", "720", "2", "0", "3", "--duration", "0", "--json"], None),
    ("view-unreachable", ["view", *GD, "--pose", "0", "0", "1200", "0", "0", "0", "--duration", "0", "--json"], None),
    # init
    ("init-utn", ["init", "--platform-template", "utn"], None),
    ("init-radial", ["init", "--platform-template", "radial"], None),
    ("init-explicit", ["init", "--platform-template", "explicit"], None),
    # usage errors
    ("unknown-option", ["ik", *UD, "--pose", "0", "0", "700", "0", "0", "0", "--json", "--frobnicate"], None),
]

REPORTS = [("report-quick", ["report", "--quick", "--out", "report-quick"], "report-quick"),
           ("report-full", ["report", "--out", "report-full"], "report-full")]

# The fixed-point loop's feed-forward table as the Q15 words the law reads (issue 42 item 2: the table may be computed
# within a stated tolerance, and ``compare_behaviour`` lists the ticks where that moved a word). (name, machine (a
# preset or a file under the repository), trajectory, duration s, ``plan_run`` options): the simulate calls'
# fixed-point runs above, and 2 s of both references on the three presets (fitted to the two they were not made for)
# and the 210 kg machine (its payload, its own fit).
FEEDFORWARD_CASES = [
    ("simulate-fixed-cenic", "utn-dynamic", "seed", 0.15, {}),
    ("simulate-fixed-c-rotating", "utn-dynamic", "rotating", 0.1, {"latency": "none"}),
    *((f"utn-dynamic-{t}", "utn-dynamic", t, 2.0, {}) for t in ("seed", "rotating")),
    *((f"{m}-{t}", m, t, 2.0, {"fit": True}) for m in ("utn-kinematic", "gonzalez-dutra-2009") for t in ("seed", "rotating")),
    *((f"newcomer-210kg-{t}", "examples/newcomer-210kg.yaml", t, 2.0, {}) for t in ("seed", "rotating")),
]

# fmt: on

TEXT_LIMIT = 2_000_000  # bytes: larger text files are recorded by hash


def normalise(obj, tmp: str, repo: str):
    """``obj`` with the run-dependent absolute paths in every string replaced by ``<TMP>`` / ``<REPO>``."""
    if isinstance(obj, str):
        return obj.replace(tmp, "<TMP>").replace(repo, "<REPO>")
    if isinstance(obj, list):
        return [normalise(v, tmp, repo) for v in obj]
    if isinstance(obj, dict):
        return {normalise(k, tmp, repo): normalise(v, tmp, repo) for k, v in obj.items()}
    return obj


def _parse(text: str):
    """``text`` as JSON; else, when its tail from a line opening with ``{`` is JSON (``view`` prints its URL
    first), ``{"text": head, "json": tail}``; else the text itself."""
    try:
        return json.loads(text)
    except ValueError:
        pass
    at = text.find("\n{")
    if at >= 0:
        try:
            return {"text": text[: at + 1], "json": json.loads(text[at + 1 :])}
        except ValueError:
            pass
    return text


def _sha(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


_PARQUET_DUMP = (
    "import json, sys, pyarrow.parquet as pq\n"
    "t = pq.read_table(sys.argv[1])\n"
    "print(json.dumps({'schema': [f'{f.name}: {f.type}' for f in t.schema], 'columns': t.to_pydict()}, default=str))\n"
)


def read_file(path: Path):
    """One output file as comparable content (see the module docstring)."""
    data = path.read_bytes()
    if path.suffix == ".npz":
        with zipfile.ZipFile(path) as z:
            return {"npz_members_sha256": {n: _sha(z.read(n)) for n in sorted(z.namelist())}}
    if path.suffix == ".parquet":
        # Its columns, read by pyarrow in a child process (the file's bytes embed the writer's version).
        p = subprocess.run([PYTHON, "-c", _PARQUET_DUMP, str(path)], check=False, capture_output=True, text=True)
        if p.returncode == 0:
            return {"parquet": json.loads(p.stdout)}
        return {"sha256": _sha(data), "bytes": len(data), "parquet_error": p.stderr.strip().splitlines()[-1:]}
    if len(data) <= TEXT_LIMIT:
        try:
            text = data.decode("utf-8")
        except UnicodeDecodeError:
            text = None
        if text is not None:
            if path.suffix == ".json":
                return _parse(text)
            if path.suffix == ".jsonl":
                return {"jsonl": [_parse(line) for line in text.splitlines() if line.strip()]}
            if path.suffix == ".csv":
                rows = list(csv.reader(io.StringIO(text)))
                return {"csv_header": rows[0] if rows else [], "csv_rows": rows[1:]}
            return text.splitlines()
    return {"sha256": _sha(data), "bytes": len(data)}


def read_output(path: Path) -> dict:
    """Every file under ``path`` (a folder or one file), by path relative to ``path``'s parent."""
    if path.is_file():
        return {path.name: read_file(path)}
    if not path.is_dir():
        return {}
    return {str(p.relative_to(path.parent)): read_file(p) for p in sorted(path.rglob("*")) if p.is_file()}


def environment(tmp: Path) -> dict:
    env = dict(os.environ)
    env.update(
        PYTHONPATH=str(REPO),
        MPLBACKEND="Agg",
        PYTHONHASHSEED="0",
        STEWART_DRAKE_CACHE=str(tmp / ".sd-cache"),
        XDG_CACHE_HOME=str(tmp / ".xdg-cache"),
    )
    return env


def run_call(name: str, argv: list[str], out: str | None, tmp: Path, env: dict, timeout: float) -> tuple[dict, float]:
    cmd = [PYTHON, "-m", "stewart_drake.cli", *argv]
    t0 = time.perf_counter()
    try:
        p = subprocess.run(cmd, cwd=tmp, env=env, check=False, capture_output=True, text=True, timeout=timeout)
        code, stdout, stderr = p.returncode, p.stdout, p.stderr
    except subprocess.TimeoutExpired as e:
        code, stdout, stderr = "timeout", e.stdout or "", e.stderr or ""
        stdout = stdout.decode() if isinstance(stdout, bytes) else stdout
        stderr = stderr.decode() if isinstance(stderr, bytes) else stderr
    wall = time.perf_counter() - t0
    rec = {
        "name": name,
        "argv": ["stewart-drake", *argv],
        "exit_code": code,
        "stdout": _parse(stdout),
        "stderr": stderr,
        "files": read_output(tmp / out) if out else {},
    }
    return normalise(rec, str(tmp), str(REPO)), wall


_FEEDFORWARD_WORDS = """
import json, sys
from pathlib import Path
from stewart_drake.api.simulation import plan_run
from stewart_drake.drake.simulation import build_simulation
from stewart_drake.spec import load_machine
out = {}
for name, machine, trajectory, duration, options in json.loads(sys.argv[1]):
    if machine.endswith(".yaml"):
        machine = load_machine(Path(sys.argv[2]) / machine)
    plan = plan_run(machine, trajectory, "fixed", duration, engine="c", **options)
    sim = build_simulation(plan.scenario)
    sim.prepare(duration)
    words = sim.controller.law.feedforward_words(sim.controller.feedforward)
    out[name] = {"engine": getattr(sim.feedforward, "engine", "numpy"), "words": words.tolist()}
print(json.dumps(out))
"""


def record_feedforward_words(env: dict, tmp: Path) -> dict:
    """The ``FEEDFORWARD_CASES``' Q15 feed-forward words, per case ``{"engine", "words": (ticks, 6) ints}``, computed
    in a child process of the recorded tree (``plan_run`` and ``build_simulation`` as ``simulate`` calls them)."""
    cases = json.dumps(FEEDFORWARD_CASES)
    p = subprocess.run(
        [PYTHON, "-c", _FEEDFORWARD_WORDS, cases, str(REPO)],
        cwd=tmp,
        env=env,
        check=False,
        capture_output=True,
        text=True,
    )
    if p.returncode != 0:
        return {"error": p.stderr.strip().splitlines()[-1:]}
    return json.loads(p.stdout)


def git_commit() -> str:
    try:
        return subprocess.run(
            ["git", "rev-parse", "HEAD"], cwd=REPO, check=False, capture_output=True, text=True
        ).stdout.strip()
    except OSError:
        return ""


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("outdir", type=Path)
    ap.add_argument("--quick-report", action="store_true", help="only report --quick (skip the full report)")
    ap.add_argument("--no-report", action="store_true", help="no report at all (the CLI calls only)")
    ap.add_argument("--only", nargs="+", metavar="NAME", help="only these calls (by name; for debugging the list)")
    ap.add_argument("--timeout", type=float, default=600.0, help="seconds per call (default 600)")
    args = ap.parse_args(argv)

    outdir = args.outdir.resolve()
    if outdir.exists() and any(outdir.iterdir()):
        print(f"record_behaviour: {args.outdir} exists and is not empty", file=sys.stderr)
        return 2
    outdir.mkdir(parents=True, exist_ok=True)
    calls = [(f"{i:02d}-{n}", a, o) for i, (n, a, o) in enumerate(CALLS, 1)]
    if args.only:
        calls = [c for c in calls if c[0].split("-", 1)[1] in args.only or c[0] in args.only]
    reports = [] if args.no_report else REPORTS[:1] if args.quick_report else REPORTS

    walls: dict[str, float] = {}
    t_all = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="sd-behaviour-") as d:
        tmp = Path(d).resolve()
        for rel, text in INPUTS.items():
            (tmp / rel).parent.mkdir(parents=True, exist_ok=True)
            (tmp / rel).write_text(text, encoding="utf-8")
        for stw in sorted((REPO / "examples").glob("*.stw")):
            shutil.copyfile(stw, tmp / stw.name)
        env = environment(tmp)
        for name, argv_, out in calls:
            rec, wall = run_call(name, argv_, out, tmp, env, args.timeout)
            walls[name] = round(wall, 2)
            (outdir / f"{name}.json").write_text(json.dumps(rec, indent=1, ensure_ascii=False) + "\n", encoding="utf-8")
            print(f"{name}: exit {rec['exit_code']}, {wall:.1f} s", flush=True)
        t_calls = time.perf_counter() - t_all
        if not args.only:
            t0 = time.perf_counter()
            rec = {"name": "feedforward-words", "cases": record_feedforward_words(env, tmp)}
            walls["feedforward-words"] = round(time.perf_counter() - t0, 2)
            (outdir / "feedforward-words.json").write_text(json.dumps(rec) + "\n", encoding="utf-8")
            print(f"feedforward-words: {len(rec['cases'])} cases, {walls['feedforward-words']:.1f} s", flush=True)
        for name, argv_, out in reports:
            rec, wall = run_call(name, argv_, None, tmp, env, max(args.timeout, 1800.0))
            checks = tmp / out / "checks.json"
            rec["checks"] = _parse(checks.read_text(encoding="utf-8")) if checks.is_file() else None
            rec = normalise(rec, str(tmp), str(REPO))
            walls[name] = round(wall, 2)
            (outdir / f"{name}.json").write_text(json.dumps(rec, indent=1, ensure_ascii=False) + "\n", encoding="utf-8")
            print(f"{name}: exit {rec['exit_code']}, {wall:.1f} s", flush=True)
    manifest = {
        "repo_commit": git_commit(),
        "python": PYTHON,
        "calls": [{"name": n, "argv": ["stewart-drake", *a]} for n, a, _ in calls],
        "reports": [n for n, _, _ in reports],
        "wall_s": walls,
        "calls_wall_s": round(t_calls, 1),
        "total_wall_s": round(time.perf_counter() - t_all, 1),
    }
    (outdir / "manifest.json").write_text(json.dumps(manifest, indent=1) + "\n", encoding="utf-8")
    print(f"{len(calls)} calls in {t_calls:.0f} s, total {manifest['total_wall_s']:.0f} s -> {outdir}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
