"""A user's firmware runs in a child process with a time limit and a closed standard output (issue 24, item
1e): a hang, an ``exit(0)`` in ``sd_ik`` or in a constructor, a segfault, a compiler that never returns are
each one line naming the file, exit 2 (``exit(0)`` was a false pass: exit 0, no output); a ``printf`` in
``sd_ik`` no longer corrupts ``--json``."""

from __future__ import annotations

import json
import os
import shutil
import time
from pathlib import Path

import pytest

from stewart_drake.cli import main
from stewart_drake.system import c_build
from tests.cli._inprocess import cli

pytestmark = pytest.mark.skipif(shutil.which("cc") is None and shutil.which("gcc") is None, reason="no C compiler")

WRAP = """#include <stdlib.h>
#include <stdio.h>
#define sd_tick sd_tick_real
#include "gen/sd_firmware.c"
#undef sd_tick
int sd_tick(sd_state *s, const sd_word pose[6], const sd_count measured[6], const int16_t feedforward[6],
            int16_t command[6]) {
    static int n = 0;
    if (++n > 20) { BODY }
    return sd_tick_real(s, pose, measured, feedforward, command);
}
"""
IK = '#include <stdlib.h>\n#include <stdio.h>\n#include "sd_firmware.h"\n'
FILES = {
    "loop.c": IK + "int sd_ik(const sd_word p[6], sd_word l[6]) { (void)p; for (;;) { l[0]++; } return 0; }\n",
    "exit0.c": IK + "int sd_ik(const sd_word p[6], sd_word l[6]) { (void)p; (void)l; exit(0); }\n",
    "ctor.c": IK
    + "__attribute__((constructor)) static void boom(void) { exit(0); }\n"
    + "int sd_ik(const sd_word p[6], sd_word l[6]) { (void)p; for (int i = 0; i < 6; i++) l[i] = 0; return 0; }\n",
    "segv.c": IK
    + "int sd_ik(const sd_word p[6], sd_word l[6]) { (void)p; (void)l; *(volatile int *)0 = 1; return 0; }\n",
}
MESSAGES = {
    "loop.c": "loop.c: the firmware did not return within 3 s",
    "exit0.c": "exit0.c: the firmware ended the process (exit status 0)",
    "ctor.c": "ctor.c: the firmware ended the process (exit status 0)",
    "segv.c": "segv.c: the firmware crashed (SIGSEGV",
}


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    d = tmp_path_factory.mktemp("fw")
    cwd = os.getcwd()
    os.chdir(d)
    try:
        assert main(["firmware", "generate", "--platform", "utn-dynamic", "--out", "gen", "--no-compile"]) == 0
    finally:
        os.chdir(cwd)
    for name, text in FILES.items():
        (d / name).write_text(text)
    printing = 'int sd_ik(const sd_word p[6], sd_word l[6]) { (void)p; printf("hello\\n"); fflush(stdout); '
    (d / "printf.c").write_text(IK + printing + "for (int i = 0; i < 6; i++) l[i] = 0; return 0; }\n")
    (d / "t_loop.c").write_text(WRAP.replace("BODY", "for (;;) { }"))
    return d


@pytest.mark.parametrize("name", list(FILES))
def test_firmware_check_failures_are_one_line(folder, capsys, monkeypatch, name):
    monkeypatch.chdir(folder)
    t0 = time.perf_counter()
    rc, out, err = cli(capsys, "firmware", "check", name, "--poses", "100", "--time-limit", "3", "--json")
    assert rc == 2 and out == "" and len(err.strip().splitlines()) == 1, err
    assert err.startswith(f"stewart-drake firmware: error: {MESSAGES[name]}"), err
    assert time.perf_counter() - t0 < 60


def test_printf_does_not_corrupt_json(folder, capsys, monkeypatch):
    monkeypatch.chdir(folder)
    rc, out, err = cli(capsys, "firmware", "check", "printf.c", "--poses", "100", "--json")
    assert rc == 1, err  # a zero IK differs from the emulation: a result, shown
    assert json.loads(out)["file"] == "printf.c" and "hello" not in out


def test_compiler_that_never_returns(folder, capsys, monkeypatch, tmp_path):
    cc = tmp_path / "slowcc"
    cc.write_text('#!/bin/sh\nif [ "$1" = "--version" ]; then echo "gcc (fake) 1.0"; exit 0; fi\nexec sleep 600\n')
    cc.chmod(0o755)
    monkeypatch.setenv(c_build.CC_ENV, str(cc))
    monkeypatch.setattr(c_build, "COMPILE_TIMEOUT_S", 2.0)
    monkeypatch.setattr(c_build, "cache_dir", lambda: _fresh(tmp_path / "cache"))
    monkeypatch.chdir(folder)
    t0 = time.perf_counter()
    rc, _, err = cli(capsys, "firmware", "check", "printf.c", "--poses", "100")
    assert rc == 2 and "the C compiler did not finish within 2 s" in err and "printf.c" in err, err
    assert time.perf_counter() - t0 < 30


def test_simulate_user_firmware_that_hangs(folder, capsys, monkeypatch):
    """`simulate --firmware t_loop.c` hung for ever; the default (generated) C engine still runs in-process."""
    monkeypatch.chdir(folder)
    argv = ["simulate", "--platform", "utn-dynamic", "--duration", "0.1", "--no-progress"]
    rc, out, err = cli(capsys, *argv, "--firmware", "t_loop.c", "--time-limit", "4", "--out", "o")
    assert (
        rc == 2 and out == "" and err.startswith("stewart-drake simulate: error: t_loop.c: the firmware did not return")
    )
    assert not Path(folder / "o").exists()


def _fresh(p: Path) -> Path:
    p.mkdir(exist_ok=True)
    return p


MEM_CAP = 1 << 30  # far above what a check needs beside the firmware, far below the machine's memory
MEM = (
    IK
    + "#include <string.h>\n"
    + "int sd_ik(const sd_word p[6], sd_word l[6]) { (void)p; (void)l;\n"
    + "    for (;;) { volatile char *b = malloc(64u << 20); for (size_t i = 0; i < (64u << 20); i += 4096) b[i] = 1; }\n"
    + "    return 0; }\n"
)
FORK = (
    "#define _POSIX_C_SOURCE 200809L\n"  # fork, sleep under -std=c99
    + IK
    + "#include <unistd.h>\n"
    + "#define sd_ik sd_ik_real\n"
    + '#include "gen/sd_firmware.c"\n'
    + "#undef sd_ik\n"
    + "int sd_ik(const sd_word p[6], sd_word l[6]) {\n"
    + "    static int forked = 0;\n"
    + "    if (!forked) { forked = 1; pid_t c = fork();\n"
    + '        if (c == 0) { FILE *f = fopen("orphan.pid", "w"); fprintf(f, "%d", (int)getpid()); fclose(f);'
    + " sleep(60); _exit(0); } }\n"
    + "    return sd_ik_real(p, l); }\n"
)


def test_firmware_that_allocates_without_end(folder, capsys, monkeypatch):
    """An endless malloc in sd_ik stops at the child's address-space cap: one line naming the file, exit 2."""
    from stewart_drake.system import isolate

    monkeypatch.setattr(isolate, "FIRMWARE_MEMORY_LIMIT_BYTES", MEM_CAP)
    monkeypatch.chdir(folder)
    (folder / "mem.c").write_text(MEM)
    rc, out, err = cli(capsys, "firmware", "check", "mem.c", "--poses", "100", "--time-limit", "60")
    assert rc == 2 and out == "" and len(err.strip().splitlines()) == 1, err
    assert err.startswith("stewart-drake firmware: error: mem.c: the firmware ran out of its memory limit (1024 MiB"), (
        err
    )


def test_a_process_the_firmware_forks_ends_with_the_check(folder, capsys, monkeypatch):
    monkeypatch.chdir(folder)
    (folder / "fork.c").write_text(FORK)
    pid_file = folder / "orphan.pid"
    pid_file.unlink(missing_ok=True)
    rc, _, err = cli(capsys, "firmware", "check", "fork.c", "--poses", "100")
    assert rc == 0, err
    deadline = time.monotonic() + 10
    while not pid_file.exists() and time.monotonic() < deadline:
        time.sleep(0.05)
    orphan = int(pid_file.read_text())
    while _alive(orphan) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert not _alive(orphan)


def _alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"
