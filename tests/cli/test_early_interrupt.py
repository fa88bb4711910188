"""Ctrl-C at any moment of a command ends it quietly (issue 24, item 2): while the command line imports numpy
and pydrake and parses its options (the first ~0.5-1 s, where a KeyboardInterrupt traceback came out of
the imports), and while the command runs. Quietly: no traceback, one line ("stewart-drake simulate:
interrupted") and the conventional status 130.

The delays count from the moment numpy's extension is mapped into the command (the package's first
statement, which installs the handler, ran just before: numpy is the command line's first heavy import).
Before that, for the first ~30 ms of the interpreter (its own startup and ``site``, before any line of this
package runs), Python's default handler is in place and no code of ours can answer: an interrupt there
ends the process by SIGINT, with the interpreter's traceback of its startup."""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
# a command that imports pydrake and then runs for a minute (it is always interrupted before it ends)
SIMULATE = ["simulate", "--platform", "utn-dynamic", "--duration", "60", "--no-progress"]
DELAYS_S = (0.0, 0.02, 0.05, 0.1, 0.2, 0.35, 0.5, 0.8, 1.2, 2.5)
ENTRIES = {
    "module-cli": [sys.executable, "-m", "stewart_drake.cli"],
    "module": [sys.executable, "-m", "stewart_drake"],
    "script": [str(Path(sys.executable).with_name("stewart-drake"))],
}
LINE = re.compile(r"stewart-drake( simulate)?: interrupted")


def interrupt_after(entry: list[str], delay: float, cwd) -> tuple[int, str]:
    env = dict(os.environ, PYTHONPATH=str(ROOT), MPLBACKEND="Agg")
    p = subprocess.Popen(
        [*entry, *SIMULATE],
        cwd=cwd,
        env=env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,  # its own process group: what a terminal's Ctrl-C reaches
    )
    try:
        maps, t0 = Path(f"/proc/{p.pid}/maps"), time.monotonic()
        while p.poll() is None and "_multiarray_umath" not in maps.read_text():
            assert time.monotonic() - t0 < 30, "numpy was never imported"
            time.sleep(0.002)
        time.sleep(delay)
        os.killpg(p.pid, signal.SIGINT)
        _, err = p.communicate(timeout=60)
    finally:
        if p.poll() is None:
            os.killpg(p.pid, signal.SIGKILL)
            p.wait()
    return p.returncode, err


@pytest.mark.parametrize("entry", list(ENTRIES), ids=list(ENTRIES))
def test_ctrl_c_at_any_moment_ends_quietly(tmp_path, entry):
    if entry == "script" and not Path(ENTRIES["script"][0]).exists():
        pytest.skip("no stewart-drake script beside this interpreter")
    for delay in DELAYS_S if entry == "module-cli" else (0.0, 0.2, 1.2):
        code, err = interrupt_after(ENTRIES[entry], delay, tmp_path)
        where = f"SIGINT at {delay} s: status {code}, stderr:\n{err}"
        assert "Traceback" not in err and "KeyboardInterrupt" not in err, where
        assert code == 130, where
        lines = [ln for ln in err.splitlines() if ln.strip()]
        assert lines and LINE.fullmatch(lines[-1]), where  # the last line says so
        # before it, at most the run's own one-line warnings (printed as the run goes)
        assert all(ln.startswith("stewart-drake simulate: warning: ") for ln in lines[:-1]), where
    assert list(tmp_path.iterdir()) == []  # nothing written: the run's folder is complete or absent
