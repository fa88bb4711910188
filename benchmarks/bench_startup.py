"""Start-up cost of the numpy-only commands beside ``python -c "import numpy"``, measured in the same run.

    PYTHONPATH=. python benchmarks/bench_startup.py [--repeat 7] [--compare OTHER_CHECKOUT]

Each case runs in a fresh interpreter (``python -m stewart_drake ...`` from the checkout, ``PYTHONPATH`` set to
it); its figure is the CPU time (user + sys) the child used, read with ``resource.getrusage(RUSAGE_CHILDREN)``
around the run, the best of ``--repeat``. CPU time rather than wall time: the machine may be shared, and a
waiting process costs wall time but no CPU time. Bytecode is cached under a temporary
``PYTHONPYCACHEPREFIX`` (filled by a first, untimed round), as an installed package has its ``.pyc``: no run
pays for compiling the sources, and nothing is written into the checkouts. The rounds are interleaved (every case and checkout once per
round) so that all see the same machine state. The reference is ``python -c "import numpy"`` from the same
round; the target is a numpy-only command's start-up within 2x the reference. With ``--compare``,
the other checkout's figures print beside (e.g. main before a change). Pins nothing; exit 0.
"""

from __future__ import annotations

import argparse
import os
import resource
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
TARGET = 2.0  # a numpy-only command's start-up <= 2x `python -c "import numpy"` in the same run

REFERENCE = ["-c", "import numpy"]
# the numpy-only commands a user scripts, each with a small input (the figure is start-up, not the work)
CASES = {
    "ik": ["ik", "--platform", "utn-dynamic", "--pose", "0", "0", "700", "0", "0", "0"],
    "fk": ["fk", "--platform", "utn-dynamic", "--lengths", *["730"] * 6],
    "fk --all": ["fk", "--all", "--platform", "utn-dynamic", "--lengths", *["730"] * 6],
    "dsp-ik": ["dsp-ik", "--pose", "0", "0", "100", "0.1", "0", "0"],
    "servo": ["servo", "--pose", "0", "0", "0", "0", "0", "0", "--from-home"],
    "leg fk": ["leg", "fk", "0.1", "0.2"],
    "workspace --help": ["workspace", "--help"],
    "--help": ["--help"],
}


def cpu_seconds(checkout: Path, args: list[str], cache: str) -> float:
    """CPU seconds (user + sys) of one fresh interpreter running ``args`` with ``checkout`` on its path and
    its bytecode cached under ``cache``."""
    env = dict(os.environ, PYTHONPATH=str(checkout), PYTHONPYCACHEPREFIX=cache)
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    p = subprocess.run([sys.executable, *args], cwd=checkout, env=env, capture_output=True, text=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if p.returncode != 0:
        raise SystemExit(f"{' '.join(args)} in {checkout} exited {p.returncode}: {p.stderr.strip()[-500:]}")
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=7, help="rounds; each figure is the best of them")
    parser.add_argument("--compare", type=Path, help="another checkout timed in the same rounds")
    parser.add_argument("--only", nargs="*", choices=list(CASES), help="time only these cases")
    opts = parser.parse_args()
    checkouts = [ROOT] + ([opts.compare.resolve()] if opts.compare else [])
    cases = {name: CASES[name] for name in (opts.only or CASES)}
    runs = {"import numpy": REFERENCE} | {name: ["-m", "stewart_drake", *argv] for name, argv in cases.items()}
    best = {(c, name): float("inf") for c in checkouts for name in runs}
    with tempfile.TemporaryDirectory(prefix="sd-bench-pycache-") as cache:
        for round_ in range(opts.repeat + 1):  # round 0 compiles the bytecode, untimed
            for name, args in runs.items():
                for checkout in checkouts:
                    seconds = cpu_seconds(checkout, args, cache)
                    if round_:
                        best[checkout, name] = min(best[checkout, name], seconds)
    print(f"CPU time (user+sys), best of {opts.repeat}; target: each command <= {TARGET:g}x `import numpy`")
    header = f"{'case':<18}{'this ms':>9}{'ratio':>7}"
    if opts.compare:
        header += f"{'other ms':>10}{'ratio':>7}"
    print(header + f"{'target':>8}  ok")
    for name in runs:
        row = f"{name:<18}"
        for checkout in checkouts:
            ratio = best[checkout, name] / best[checkout, "import numpy"]
            row += f"{best[checkout, name] * 1e3:>{9 if checkout == ROOT else 10}.0f}{ratio:>7.2f}"
        ok = best[ROOT, name] <= TARGET * best[ROOT, "import numpy"]
        print(row + f"{TARGET:>7g}x  {'yes' if ok else 'NO'}")
    if opts.compare:
        print(f"this: {ROOT}\nother: {checkouts[1]}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
