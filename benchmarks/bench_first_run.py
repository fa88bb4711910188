"""The first run on a fresh machine (item 3 of the second speed issue): the CPU of a command whose compiled-module
cache is empty beside the same command run again on the cache it filled, each printed beside the target
(fresh ≤ 1.2 × warm). Two commands: the full report (``--no-cache``: every section computed both times; the
CPU of the whole process tree, workers and compilers included) and the first ``simulate`` of a user's machine
(``examples/newcomer-210kg.yaml``). Each pair runs back to back in one run, the fresh one first, with the
cache a new temporary folder (``$STEWART_DRAKE_CACHE``).

    PYTHONPATH=. python benchmarks/bench_first_run.py [--report full|quick|none] [--repeat 3]

``--report quick`` runs the smaller report (its compiled share is larger: a stricter ratio); ``none`` only
the simulate pairs (``--repeat`` of them, the median ratio printed). Measures only; the machine's load is
printed first and last.
"""

from __future__ import annotations

import argparse
import os
import re
import resource
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
TARGET = 1.2  # the issue's: the first run costs at most 1.2 × the CPU of a run on a warm cache
MACHINE = ROOT / "examples" / "newcomer-210kg.yaml"
COMPILED = re.compile(r"sd-[0-9a-f]{32}\.so")  # a library the compiler built (not a copy: c_build.instance)


def load() -> str:
    return "load {:.1f} {:.1f} {:.1f}".format(*os.getloadavg())


def cpu_seconds(args: list[str], cache: Path) -> float:
    """User + system CPU seconds of ``python -m stewart_drake ARGS`` and every process it waited for, with
    the compiled-module cache ``cache``; raises if the command fails."""
    env = dict(os.environ, STEWART_DRAKE_CACHE=str(cache), MPLBACKEND="Agg", PYTHONPATH=str(ROOT))
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    r = subprocess.run([sys.executable, "-m", "stewart_drake", *args], env=env, cwd=ROOT, capture_output=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if r.returncode != 0:
        raise SystemExit(f"{' '.join(args)} exited {r.returncode}: {r.stderr.decode(errors='replace')[-2000:]}")
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def fresh_and_warm(args_of, tmp: Path, tag: str) -> tuple[float, float, int]:
    """CPU seconds of ``args_of(out)`` on an empty cache, then again on the cache it filled (a new output
    folder each time), and how many libraries the first run compiled."""
    cache = tmp / f"cache-{tag}"
    fresh = cpu_seconds(args_of(tmp / f"{tag}-fresh"), cache)
    libraries = sum(1 for p in cache.glob("sd-*.so") if COMPILED.fullmatch(p.name))
    warm = cpu_seconds(args_of(tmp / f"{tag}-warm"), cache)
    return fresh, warm, libraries


def line(what: str, fresh: float, warm: float, libraries: int) -> str:
    ratio = fresh / warm
    met = "met" if ratio <= TARGET else "NOT met"
    return (
        f"  {what:28s} fresh {fresh:7.2f} CPU s, warm {warm:7.2f} CPU s: {ratio:.3f} × (target ≤ {TARGET}: {met}; "
        f"{libraries} libraries in the fresh cache)"
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--report", default="full", choices=["full", "quick", "none"])
    ap.add_argument("--repeat", type=int, default=3, help="simulate pairs (default 3)")
    args = ap.parse_args()
    print(f"first run on a fresh compiled-module cache vs warm, CPU of the process tree ({load()}):")
    with tempfile.TemporaryDirectory(prefix="bench-first-run-") as t:
        tmp = Path(t)
        pairs = []
        for k in range(args.repeat):
            simulate = ["simulate", "--machine", str(MACHINE), "--no-progress"]
            pairs.append(fresh_and_warm(lambda out: [*simulate, "--out", str(out)], tmp, f"simulate{k}"))
            print(line(f"simulate {MACHINE.name} #{k + 1}", *pairs[-1]), flush=True)
        if pairs:
            ratio = statistics.median(f / w for f, w, _ in pairs)
            print(
                f"  simulate, median of {len(pairs)}: {ratio:.3f} × (target ≤ {TARGET}: {'met' if ratio <= TARGET else 'NOT met'})"
            )
        if args.report != "none":
            quick = ["--quick"] if args.report == "quick" else []
            report = ["report", "--no-cache", *quick]
            print(
                line(
                    f"report ({args.report})", *fresh_and_warm(lambda out: [*report, "--out", str(out)], tmp, "report")
                )
            )
    print(f"({load()})")


if __name__ == "__main__":
    main()
