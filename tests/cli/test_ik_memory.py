"""``ik --poses``: the memory a row costs stays within what the command budgets for it (``BYTES_PER_ROW``,
``BYTES_PER_JSON_ROW``), so that its refusal of a file too large for memory comes before it runs out."""

import subprocess
import sys

import numpy as np
import pytest

from stewart_drake.commands.ik import BYTES_PER_JSON_ROW, BYTES_PER_ROW

CODE = (
    "import resource, sys\n"
    "from stewart_drake.cli import main\n"
    "rc = main(sys.argv[1:])\n"
    "print(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss, file=sys.stderr)\n"
)


def _peak_kb(path, *extra) -> int:
    args = ["ik", "--platform", "utn-dynamic", "--length-unit", "m", "--angle-unit", "rad", "--poses", str(path)]
    r = subprocess.run(
        [sys.executable, "-c", CODE, *args, *extra], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True
    )
    assert r.returncode == 0, r.stderr
    return int(r.stderr.split()[-1])


@pytest.mark.parametrize("json_out", [False, True])
def test_peak_memory_per_row_is_within_the_budgeted_cost(tmp_path, json_out):
    """Peak RSS (ru_maxrss, kB on Linux) of 20 000 and 80 000 rows: the growth per row is at most the
    command's own per-row cost, which its refusal of a large file relies on. The difference of two runs removes the interpreter's and the modules' share."""
    if sys.platform != "linux":
        pytest.skip("ru_maxrss is in kB on Linux")
    rng = np.random.default_rng(0)
    files = []
    for n in (20_000, 80_000):
        q = np.c_[rng.uniform(-0.01, 0.01, (n, 2)), 0.7 + rng.uniform(-0.01, 0.01, n), rng.uniform(-0.02, 0.02, (n, 3))]
        f = tmp_path / f"p{n}.csv"
        np.savetxt(f, q, delimiter=",", fmt="%.6f")
        files.append(f)
    extra = ["--json"] if json_out else []
    per_row = (_peak_kb(files[1], *extra) - _peak_kb(files[0], *extra)) * 1024 / 60_000
    assert per_row <= BYTES_PER_ROW + (BYTES_PER_JSON_ROW if json_out else 0)
