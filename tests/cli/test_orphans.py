"""Children die with their parent, quietly (issue 24, item 1f): the workers of a process pool or of a Dask
LocalCluster, and the multiprocessing resource tracker, are gone soon after the command is killed
(SIGKILL), terminated (SIGTERM) or interrupted (SIGINT to the whole process group, as Ctrl-C sends it),
and an interrupted command prints one line, no traceback per worker."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def group_members(pgid: int) -> list[int]:
    """The live (not zombie) processes of process group ``pgid``."""
    out = []
    for d in Path("/proc").iterdir():
        if not d.name.isdigit():
            continue
        try:
            stat = (d / "stat").read_text()
        except OSError:
            continue
        fields = stat.rsplit(")", 1)[1].split()
        if int(fields[2]) == pgid and fields[0] != "Z":
            out.append(int(d.name))
    return out


def start(argv, cwd) -> subprocess.Popen:
    # $STEWART_DRAKE_CLI_PID names this process, as it did inside the full suite once a test had run
    # cli.main in-process: the command, a child of the process the variable names, ignored Ctrl-C as if
    # it were one of that process's workers and ran all 200 runs (the "outlived 30 s" of the full suite).
    # A command line is never a worker (system.interrupts).
    env = dict(os.environ, PYTHONPATH=str(ROOT), MPLBACKEND="Agg", STEWART_DRAKE_CLI_PID=str(os.getpid()))
    return subprocess.Popen(
        [sys.executable, "-m", "stewart_drake.cli", *argv],
        cwd=cwd,
        env=env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,  # its own process group: what a terminal's Ctrl-C reaches
    )


def workers(pgid: int) -> list[int]:
    """The spawned worker processes in the group (not the resource tracker)."""
    out = []
    for pid in group_members(pgid):
        try:
            if b"spawn_main" in Path(f"/proc/{pid}/cmdline").read_bytes():
                out.append(pid)
        except OSError:
            pass
    return out


def wait_for_workers(p: subprocess.Popen, n: int, busy: float, timeout: float = 90.0) -> None:
    t0 = time.monotonic()
    while len(workers(p.pid)) < n:
        assert p.poll() is None, f"the command ended before its workers started: {p.stderr.read()}"
        assert time.monotonic() - t0 < timeout, "the workers did not start"
        time.sleep(0.2)
    time.sleep(busy)  # the workers are busy (the Dask runs started)


def wait_gone(pgid: int, timeout: float = 3.0) -> list[int]:
    """The group's processes left ``timeout`` s after the parent ended (dying *with* it: at once, not when
    their task is done)."""
    t0 = time.monotonic()
    while (left := group_members(pgid)) and time.monotonic() - t0 < timeout:
        time.sleep(0.2)
    return left


RUNS = {
    # a process pool (report's and the workspace sweep's worker_pool)
    "pool": ["workspace", "--platform", "utn-dynamic", "--resolution", "0.002", "--workers", "2", "--out", "w"],
    # a Dask LocalCluster (its nannies' worker processes)
    "dask": [
        "montecarlo",
        "--platform",
        "utn-dynamic",
        "--runs",
        "200",
        "--workers",
        "2",
        "--out",
        "m",
        "--no-progress",
    ],
}


@pytest.mark.parametrize(
    "kind,sig,to_group",
    [
        ("pool", signal.SIGKILL, False),
        ("pool", signal.SIGTERM, False),
        ("dask", signal.SIGINT, True),
    ],
    ids=["pool-SIGKILL", "pool-SIGTERM", "dask-SIGINT-group"],
)
def test_children_die_with_the_parent_quietly(tmp_path, kind, sig, to_group):
    p = start(RUNS[kind], tmp_path)
    try:
        wait_for_workers(p, 2, busy=4.0 if kind == "dask" else 1.0)
        if kind == "dask":  # interrupted while the runs are under way: the first finished run is in the journal
            journal, t0 = tmp_path / "m" / "montecarlo.partial.jsonl", time.monotonic()
            while not journal.exists():
                assert p.poll() is None and time.monotonic() - t0 < 120, "no run finished"
                time.sleep(0.2)
        if to_group:
            os.killpg(p.pid, sig)
        else:
            p.send_signal(sig)
        try:  # its output pipe closes when the command and every child of it have ended
            _, err = p.communicate(timeout=30)
        except subprocess.TimeoutExpired:
            pytest.fail(f"processes outlived the command (holding its stderr): {group_members(p.pid)}")
        left = wait_gone(p.pid)
    finally:
        for pid in group_members(p.pid):
            os.kill(pid, signal.SIGKILL)
    assert left == [], f"orphans left: {left}"
    assert "Traceback" not in err and "KeyboardInterrupt" not in err and "leaked" not in err, err
    if sig != signal.SIGKILL:
        lines = [ln for ln in err.splitlines() if ln.strip() and "%|" not in ln]
        word = "interrupted" if sig == signal.SIGINT else "terminated"
        assert lines[-1:] == [f"stewart-drake {RUNS[kind][0]}: {word}"], err
        assert len(lines) <= 2, err  # at most a note before it, never a traceback per worker
        assert p.returncode == (130 if sig == signal.SIGINT else 143)
    # nothing half-written is left beside the output
    assert [q.name for q in tmp_path.iterdir() if ".sd-tmp-" in q.name] == []
