"""``firmware build --target cortex-m4``: the generated firmware with the PIL runtime cross-compiled for the
MPS2+ AN386 (``firmware.target_build``): an ELF that boots (its vector table, and in QEMU where installed a
handshake and ticks over the UART equal to ``sd_tick``), its map, the code and data sizes, and a worst-case
stack depth read two ways (GCC's records, the machine code) that agree."""

import json
import shutil
import socket
import subprocess
import time

import pytest

import stewart_drake as sd
from stewart_drake.api.firmware import controller_config, machine_format
from stewart_drake.errors import FirmwareError
from stewart_drake.firmware import link
from stewart_drake.firmware.generate import generate
from stewart_drake.firmware.target_build import (
    UNBOUNDED,
    build_target,
    call_graph,
    machine_frames,
    program_files,
    stack_depth,
)
from tests.cli._inprocess import cli
from tests.firmware.firmware_cache import firmware_cache  # noqa: F401
from tests.firmware.test_link import fingerprint, reference, ticks

CROSS = shutil.which("arm-none-eabi-gcc")
QEMU = shutil.which("qemu-system-arm")
needs_cross = pytest.mark.skipif(CROSS is None, reason="no arm-none-eabi-gcc (Debian: gcc-arm-none-eabi)")
needs_qemu = pytest.mark.skipif(QEMU is None, reason="no qemu-system-arm (Debian: qemu-system-arm)")


def tool(name, *args, cwd=None) -> str:
    return subprocess.run([shutil.which(name), *args], capture_output=True, text=True, check=True, cwd=cwd).stdout


def generated(tmp_path, **options) -> dict:
    """The generated module's files (name -> text), as ``firmware generate`` writes them."""
    g = sd.firmware.generate(sd.load_platform("utn-dynamic"), tmp_path, compile=False, **options)
    return {f.name: f.read_text() for f in g.files}


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    if CROSS is None:
        pytest.skip("no arm-none-eabi-gcc (Debian: gcc-arm-none-eabi)")
    out = tmp_path_factory.mktemp("m4") / "build"
    r = sd.firmware.build(sd.load_platform("utn-dynamic"), out)
    return out, r.to_dict()


@needs_cross
def test_the_elf_boots_from_its_vector_table(built):
    out, s = built
    symbols = {
        ln.split()[7]: int(ln.split()[1], 16)
        for ln in tool("arm-none-eabi-readelf", "-sW", str(out / s["elf"])).splitlines()
        if len(ln.split()) == 8 and ln.split()[3] in ("FUNC", "OBJECT", "NOTYPE")
    }
    head = tool("arm-none-eabi-readelf", "-h", str(out / s["elf"]))
    assert "ARM" in head and "EXEC" in head
    words = tool("arm-none-eabi-objdump", "-s", "-j", ".text", "--stop-address=8", str(out / s["elf"]))
    sp, reset = (int.from_bytes(bytes.fromhex(w), "little") for w in words.splitlines()[-1].split()[1:3])
    # the AN386's RAM is 4 MiB at 0x20000000: the stack starts at its top; the reset vector is a Thumb address
    assert sp == 0x20000000 + 4 * 2**20
    assert reset == symbols["Reset_Handler"] | 1
    for f in ("sd_ik", "sd_tick", "sd_fk"):
        assert f in symbols


@needs_cross
def test_sizes_agree_with_the_linker_map(built):
    out, s = built
    text = (out / s["map"]).read_text()
    sizes = {}
    for ln in text.splitlines():  # the map's output sections, in column 0: ".bss  0x20000000  0x154 load ..."
        p = ln.split()
        if ln[:1] == "." and len(p) >= 3 and p[0] in (".text", ".data", ".bss") and p[1].startswith("0x"):
            sizes.setdefault(p[0], int(p[2], 16))
    assert s["code_bytes"] >= sizes[".text"] > 0
    assert (s["data_bytes"], s["bss_bytes"]) == (sizes.get(".data", 0), sizes[".bss"])
    f = s["functions"]  # each with what it calls: sd_tick runs sd_ik, and all of it is in the code
    assert s["code_bytes"] > f["sd_tick"]["code_bytes"] > f["sd_ik"]["code_bytes"] > 0
    assert json.loads((out / "build.json").read_text())["code_bytes"] == s["code_bytes"]


@needs_cross
def test_stack_depth_is_a_call_path_whose_frames_gcc_and_the_machine_code_agree_on(tmp_path):
    b = build_target(generated(tmp_path / "gen"), tmp_path / "w")
    frames, calls = call_graph(tmp_path / "w")
    asm, asm_calls = machine_frames(tool("arm-none-eabi-objdump", "-d", "--no-show-raw-insn", str(b.elf)))
    compiled = [f for f in asm if f in frames]
    assert len(compiled) > 20
    for f in compiled:  # two readings of each frame: GCC's -fstack-usage and the pushes in the code
        assert asm[f] == frames[f], f
    path = b.stack_path
    assert path[0] == "Reset_Handler" and "sd_tick" in path
    for a, c in zip(path, path[1:]):
        assert c in set(calls.get(a, ())) | set(asm_calls.get(a, ())), (a, c)
    assert b.stack_bytes == sum(frames[f] for f in path)
    # the main loop's depth is no less than any one function's own depth along it
    assert b.stack_bytes >= b.functions["sd_tick"]["stack_bytes"] > b.functions["sd_ik"]["stack_bytes"] > 0


def test_stack_depth_is_unbounded_through_recursion_or_a_dynamic_frame():
    assert stack_depth({"a": 8, "b": 16}, {"a": ["b"], "b": ["a"]}, "a") == (None, ("a", "b", "a", "(recursion)"))
    assert stack_depth({"a": 8, "b": UNBOUNDED}, {"a": ["b"]}, "a")[0] is None
    assert stack_depth({"a": 8}, {"a": ["lib"]}, "a") == (None, ("a", "lib", "(frame unknown)"))
    assert stack_depth({"a": 8, "b": 16, "c": 4}, {"a": ["b", "c"]}, "a") == (24, ("a", "b"))


def test_machine_frames_reads_pushes_and_refuses_a_register_sized_frame():
    dis = """
00000010 <f>:
      10:\tpush\t{r4, r5, r6, lr}
      12:\tsub\tsp, #40\t@ 0x28
      14:\tvpush\t{d8-d9}
      16:\tbl\t20 <g>
00000020 <g>:
      20:\tstrd\tip, lr, [sp, #-16]!
      24:\tb.w\t30 <h>
00000030 <h>:
      30:\tsub\tsp, r3
      32:\tblx\tr2
"""
    frames, calls = machine_frames(dis)
    assert frames == {"f": 16 + 40 + 16, "g": 16, "h": UNBOUNDED}
    assert calls == {"f": ["g"], "g": ["h"], "h": []}


@needs_cross
def test_a_warning_fails_the_target_build(tmp_path):
    files = generated(tmp_path / "gen")
    files["sd_firmware.c"] += "\nstatic int unused_helper(void) { return 0; }\n"
    with pytest.raises(FirmwareError, match=r"compiling sd_firmware.c failed: .*unused_helper"):
        build_target(files, tmp_path / "w")


def test_program_files_carry_the_modules_fingerprint(tmp_path):
    files = generated(tmp_path / "gen")
    fp = fingerprint(files)
    assert ", ".join(f"0x{b:02x}" for b in fp) in program_files(files)["sd_pil_config.h"]
    assert fingerprint(generated(tmp_path / "gen2", rate=500.0)) != fp


@needs_cross
def test_cli_reports_code_data_and_stack(tmp_path, capsys):
    rc, out, err = cli(capsys, "firmware", "build", "--target", "cortex-m4", "--out", str(tmp_path / "b"))
    assert rc == 0, err
    s = json.loads((tmp_path / "b" / "build.json").read_text())
    assert f"code {s['code_bytes']} B (flash), data {s['data_bytes']} B + bss {s['bss_bytes']} B (RAM)" in out
    assert f"stack depth: {s['stack_bytes']} B worst case (Reset_Handler -> main -> " in out
    assert sorted(p.name for p in (tmp_path / "b").iterdir() if not p.name.startswith(".")) == sorted(
        ["sd_pil.elf", "sd_pil.map", "sd_pil.su", "build.json"]
    )


def test_cli_refuses_an_unknown_target(tmp_path, capsys):
    rc, out, err = cli(capsys, "firmware", "build", "--target", "cortex-m0", "--out", str(tmp_path / "b"))
    assert rc == 2
    assert err.strip().endswith("--target must be one of cortex-m4, cortex-m4-semihosting, stm32f405, got 'cortex-m0'")
    assert not (tmp_path / "b").exists()


def test_cli_names_the_missing_cross_compiler(tmp_path, capsys, monkeypatch):
    monkeypatch.setenv("PATH", str(tmp_path))  # no tools at all
    rc, out, err = cli(capsys, "firmware", "build", "--out", str(tmp_path / "b"))
    assert rc == 2
    assert "firmware build --target cortex-m4: arm-none-eabi-gcc not found on PATH (install gcc-arm-none-eabi)" in err
    assert len(err.strip().splitlines()) == 1
    assert not (tmp_path / "b").exists()


@needs_cross
@needs_qemu
def test_the_elf_in_qemu_answers_a_handshake_and_ticks_like_sd_tick_within_its_stack_bound(built, tmp_path):
    out, s = built
    p = sd.load_platform("utn-dynamic")
    files = generated(tmp_path / "gen")
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    argv = [QEMU, "-M", "mps2-an386", "-nographic", "-monitor", "none"]
    argv += ["-serial", f"tcp:127.0.0.1:{port},server=on,wait=on", "-kernel", str(out / s["elf"])]
    q = subprocess.Popen(argv, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        conn = None
        for _ in range(200):  # QEMU listens within a second here; 10 s for a loaded machine
            try:
                conn = socket.create_connection(("127.0.0.1", port), timeout=1)
                break
            except OSError:
                time.sleep(0.05)
        assert conn is not None, "QEMU did not open its serial port"
        with conn:
            host = link.LinkHost(conn.sendall, link.pipe_reader(conn.fileno()), fingerprint(files))
            host.handshake(10.0)
            pose, measured, ff = ticks(5, seed=3)
            want = reference(generate(p, controller_config(p, machine_format(p, {})[1])), pose, measured, ff)
            for k in range(5):
                r = host.tick(pose[k], measured[k], ff[k], timeout=10.0)
                assert r is not None and list(r.command) == list(want[k])
            assert r.target["frames"] == 6
            used = host.status(10.0)["stack_bytes"]
    finally:
        q.kill()
        q.wait(timeout=10)
    # the static bound holds on the board, and is reached: the measured mark lies in the frame of the worst path's
    # last function, which every tick runs (GCC's -fstack-usage record of it, from the build's sd_pil.su)
    leaf = s["stack_path"][-1]
    su = (out / "sd_pil.su").read_text().splitlines()
    leaf_frame = next(int(ln.split("\t")[1]) for ln in su if ln.split("\t")[0].endswith(":" + leaf))
    assert s["stack_bytes"] - leaf_frame <= used <= s["stack_bytes"]


@needs_cross
def test_the_stm32f405_build_boots_from_flash_with_its_stack_at_the_top_of_sram(tmp_path):
    b = build_target(generated(tmp_path / "gen"), tmp_path / "w", target="stm32f405")
    words = tool("arm-none-eabi-objdump", "-s", "-j", ".text", "--stop-address=0x08000008", str(b.elf))
    sp, reset = (int.from_bytes(bytes.fromhex(w), "little") for w in words.splitlines()[-1].split()[1:3])
    # the reference manual's memory map (RM0090): 128 KiB of SRAM1 + SRAM2 at 0x20000000, flash at 0x08000000
    assert sp == 0x20000000 + 128 * 1024
    assert 0x08000000 < reset < 0x08000000 + b.text and reset & 1  # a Thumb address in the flash
    assert b.stack_bytes is not None and b.data + b.bss + b.stack_bytes < 128 * 1024


@needs_cross
def test_the_semihosting_build_is_the_uart_build_but_for_its_byte_driver(tmp_path):
    files = generated(tmp_path / "gen")
    uart = build_target(files, tmp_path / "uart", target="cortex-m4")
    semi = build_target(files, tmp_path / "semi", target="cortex-m4-semihosting")
    assert semi.functions == uart.functions  # sd_ik, sd_tick, sd_fk: the same code bytes and stack bounds
    assert semi.stack_bytes is not None and semi.stack_path[:3] == ("Reset_Handler", "main", "sd_pil_byte")
    calls = [tool("arm-none-eabi-objdump", "-d", str(b.elf)).count("bkpt\t0x00ab") for b in (uart, semi)]
    assert calls[0] == 0 and calls[1] >= 3  # open, read and write the console (and exit)


def handshake_until_listening(host: link.LinkHost, timeout: float) -> None:
    """The handshake, sent again every half second: QEMU's STM32 USART drops the bytes that arrive before the
    firmware has enabled it (the CMSDK UART of the AN386 holds them), so a HELLO sent while the board starts is
    lost."""
    end = time.monotonic() + timeout
    while True:
        try:
            return host.handshake(min(0.5, end - time.monotonic()))
        except FirmwareError:
            if time.monotonic() >= end - 0.5:
                raise


@needs_cross
@needs_qemu
def test_the_stm32f405_build_in_qemus_netduinoplus2_ticks_like_sd_tick(tmp_path):
    """QEMU's netduinoplus2 is an STM32F405: its flash, SRAM and USART2 (the machine's second serial port; RCC
    and GPIO are not modelled, their writes ignored) run the board build unchanged."""
    p = sd.load_platform("utn-dynamic")
    files = generated(tmp_path / "gen")
    b = build_target(files, tmp_path / "w", target="stm32f405")
    argv = [QEMU, "-M", "netduinoplus2", "-nographic", "-monitor", "none", "-serial", "null", "-serial", "stdio"]
    q = subprocess.Popen([*argv, "-kernel", str(b.elf)], stdin=subprocess.PIPE, stdout=subprocess.PIPE, bufsize=0)
    try:
        host = link.LinkHost(q.stdin.write, link.pipe_reader(q.stdout.fileno()), fingerprint(files))
        handshake_until_listening(host, 10.0)
        pose, measured, ff = ticks(5, seed=6)
        want = reference(generate(p, controller_config(p, machine_format(p, {})[1])), pose, measured, ff)
        for k in range(5):
            r = host.tick(pose[k], measured[k], ff[k], timeout=10.0)
            assert r is not None and list(r.command) == list(want[k])
        assert r.clock is not None and r.clock > 0  # SysTick counted sd_tick
    finally:
        q.kill()
        q.wait(timeout=10)
        q.stdin.close()
        q.stdout.close()
