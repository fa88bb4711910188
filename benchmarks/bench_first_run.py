"""The first run on a fresh machine (item 3 of the second speed issue): the CPU of a command whose compiled-module
cache is empty beside the same command run again on the cache it filled, each printed beside the target
(fresh ≤ 1.2 × warm). Two commands: the full report (``--no-cache``: every section computed both times; the
CPU of the whole process tree, workers and compilers included) and the first ``simulate`` of a user's machine
(``examples/newcomer-210kg.yaml``). Each pair runs back to back in one run, the fresh one first, with the
cache a new temporary folder (``$STEWART_DRAKE_CACHE``).

    PYTHONPATH=. python benchmarks/bench_first_run.py [--report full|quick|none] [--repeat 3] [--checkout DIR]

``--checkout``: run another checkout's commands (e.g. ``git archive main | tar -x -C DIR``: its first command
also writes its bytecode, so compare its later pairs). Beside each pair, the compilers' own CPU in the fresh run, timed directly (every ``c_build.run_compiler`` call
of every process, logged by a ``sitecustomize`` on the commands' path), and the ratio it alone gives,
(warm + compilers) / warm: on a shared machine the two runs' CPU differ by more than the compilers cost.

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
MACHINE = Path("examples") / "newcomer-210kg.yaml"  # in the checkout
COMPILED = re.compile(r"sd-[0-9a-f]{32}\.so")  # a library the compiler built (not a copy: c_build.instance)
LOG_ENV = "BENCH_FIRST_RUN_LOG"
# every Python process of a command (the report's spawned workers too) times its compilers into $BENCH_FIRST_RUN_LOG
SITECUSTOMIZE = f"""
import os, resource
if os.environ.get({LOG_ENV!r}):
    from stewart_drake.system import c_build
    _run = c_build.run_compiler
    def _timed(cmd, what, timeout=None):
        r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
        try:
            return _run(cmd, what, timeout)
        finally:
            r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
            with open(os.environ[{LOG_ENV!r}], "a") as f:
                f.write(f"{{r1.ru_utime + r1.ru_stime - r0.ru_utime - r0.ru_stime}}\\n")
    c_build.run_compiler = _timed
"""


def load() -> str:
    return "load {:.1f} {:.1f} {:.1f}".format(*os.getloadavg())


def cpu_seconds(args: list[str], cache: Path, checkout: Path, log: Path) -> float:
    """User + system CPU seconds of ``python -m stewart_drake ARGS`` run from ``checkout`` and every process it
    waited for, with the compiled-module cache ``cache`` and its compilers' CPU logged to ``log``; raises if the
    command fails."""
    path = os.pathsep.join((str(log.parent), str(checkout)))  # log.parent holds the sitecustomize
    env = dict(os.environ, STEWART_DRAKE_CACHE=str(cache), MPLBACKEND="Agg", PYTHONPATH=path, **{LOG_ENV: str(log)})
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    r = subprocess.run([sys.executable, "-m", "stewart_drake", *args], env=env, cwd=checkout, capture_output=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if r.returncode != 0:
        raise SystemExit(f"{' '.join(args)} exited {r.returncode}: {r.stderr.decode(errors='replace')[-2000:]}")
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def fresh_and_warm(args_of, tmp: Path, tag: str, checkout: Path) -> tuple[float, float, int, float]:
    """CPU seconds of ``args_of(out)`` on an empty cache, then again on the cache it filled (a new output
    folder each time), how many libraries the first run compiled and its compilers' CPU seconds."""
    cache, log = tmp / f"cache-{tag}", tmp / f"compilers-{tag}.log"
    fresh = cpu_seconds(args_of(tmp / f"{tag}-fresh"), cache, checkout, log)
    libraries = sum(1 for p in cache.glob("sd-*.so") if COMPILED.fullmatch(p.name))
    compilers = sum(float(x) for x in log.read_text().split()) if log.exists() else 0.0
    log.unlink(missing_ok=True)
    warm = cpu_seconds(args_of(tmp / f"{tag}-warm"), cache, checkout, log)
    return fresh, warm, libraries, compilers


def met(ratio: float) -> str:
    return f"{ratio:.3f} × (target ≤ {TARGET}: {'met' if ratio <= TARGET else 'NOT met'})"


def line(what: str, fresh: float, warm: float, libraries: int, compilers: float) -> str:
    return (
        f"  {what:28s} fresh {fresh:7.2f} CPU s, warm {warm:7.2f} CPU s: {met(fresh / warm)}\n"
        f"  {'':28s} {libraries} libraries compiled, compilers {compilers:.2f} CPU s: (warm + compilers) / warm "
        f"{met((warm + compilers) / warm)}"
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--report", default="full", choices=["full", "quick", "none"])
    ap.add_argument("--repeat", type=int, default=3, help="simulate pairs (default 3)")
    ap.add_argument("--checkout", type=Path, default=ROOT, help="the checkout whose commands run (default: this)")
    args = ap.parse_args()
    checkout = args.checkout.resolve()
    print(f"first run on a fresh compiled-module cache vs warm, CPU of the process tree, {checkout} ({load()}):")
    with tempfile.TemporaryDirectory(prefix="bench-first-run-") as t:
        tmp = Path(t)
        (tmp / "sitecustomize.py").write_text(SITECUSTOMIZE)
        pairs = []
        for k in range(args.repeat):
            simulate = ["simulate", "--machine", str(MACHINE), "--no-progress"]
            pairs.append(fresh_and_warm(lambda out: [*simulate, "--out", str(out)], tmp, f"simulate{k}", checkout))
            print(line(f"simulate {MACHINE.name} #{k + 1}", *pairs[-1]), flush=True)
        if pairs:
            whole = statistics.median(f / w for f, w, _, _ in pairs)
            direct = statistics.median((w + c) / w for _, w, _, c in pairs)
            print(f"  simulate, median of {len(pairs)}: {met(whole)}; (warm + compilers) / warm {met(direct)}")
        if args.report != "none":
            quick = ["--quick"] if args.report == "quick" else []
            report = ["report", "--no-cache", *quick]
            print(
                line(
                    f"report ({args.report})",
                    *fresh_and_warm(lambda out: [*report, "--out", str(out)], tmp, "report", checkout),
                )
            )
    print(f"({load()})")


if __name__ == "__main__":
    main()
