"""``simulate --pil``: the tick computed by the firmware on a target over the PIL link, in lock step with the
plant. The logs equal the host-C loop's bit for bit (the same IEEE conversions on both sides of the same
``sd_tick``); each injected link fault is detected by the counters it should move and gets the stated
reaction; QEMU never outlives the run; the instruction count per tick is measured; the same link runs over a
pseudo-terminal to the host build of the PIL program. Both QEMU links run: ``qemu`` (the board's UART) and
``qemu:semihosting`` (the semihosting console; the same program but for its byte driver).

Cost: over the UART QEMU passes ~100-200 ticks/s here (each byte of a frame is one trip through its UART
model; measured on this 2-core machine under load), over semihosting ~2500 (the whole closed loop), so the
10⁴-tick runs (marked slow) take about 1 min on the UART and 5-10 s on semihosting; the rest run 100-300 ticks.
"""

import json
import os
import shutil
import signal
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

import stewart_drake as sd
import stewart_drake.firmware.pil as pil_module
import stewart_drake.firmware.pil_target as pil_target
from stewart_drake.api.simulation import plan_run
from stewart_drake.errors import PIL_STOPPED
from stewart_drake.firmware.generate import generate
from stewart_drake.firmware.pil import M4_CLOCKS_HZ, PilFaults, program_module
from stewart_drake.firmware.pil_target import INSTRUCTIONS_PER_COUNT, QemuTarget, target_elf
from stewart_drake.firmware.target_build import build_host
from stewart_drake.spec.machine import PilSpec
from tests.cli._inprocess import cli

QEMU = shutil.which("qemu-system-arm") and shutil.which("arm-none-eabi-gcc")
needs_qemu = pytest.mark.skipif(not QEMU, reason="no qemu-system-arm or arm-none-eabi-gcc (Debian packages)")
NEWCOMER = "examples/newcomer-210kg.yaml"
LOGS = ("t", "command", "setpoint", "force", "status", "lengths", "pose")
FAULT_TICK = 40
# a reply normally comes in milliseconds; a dropped frame costs this wait, a loaded machine must not reach it
TIMEOUT = "2s"


def runs(machine, duration, **pil):
    """(the host-C run, the PIL run) of ``machine`` for ``duration`` s."""
    host = sd.simulate(machine, duration=duration, engine="c")
    return host, sd.simulate(machine, duration=duration, **{f"pil.{k}": v for k, v in pil.items()})


def assert_same_logs(a, b, rows=None):
    for k in LOGS:
        x, y = a.log[k], b.log[k]
        assert x.shape == y.shape, k
        assert np.array_equal(x[:rows], y[:rows]), k


@needs_qemu
@pytest.mark.slow
@pytest.mark.parametrize(
    "machine, target",
    [
        ("utn-dynamic", "qemu:semihosting"),
        ("gonzalez-dutra-2009", "qemu:semihosting"),
        (NEWCOMER, "qemu:semihosting"),
        (NEWCOMER, "qemu"),  # the byte-at-a-time UART path, as a board takes it
    ],
)
def test_ten_thousand_ticks_in_qemu_equal_the_host_c_loop_bit_for_bit(machine, target):
    host, pil = runs(machine, 10.0, target=target)
    assert pil.summary["ticks"] == host.summary["ticks"] >= 10_000
    assert_same_logs(host, pil)
    report = pil.summary["pil"]
    assert report["ticks_without_command"] == 0
    assert report["target_counters"]["frames"] == report["ticks"] + 3  # and the handshake, state and status
    assert sum(report["host_counters"].values()) == report["host_counters"]["frames"]


@needs_qemu
def test_qemu_run_equals_the_host_c_loop_and_the_emulation_and_measures_the_tick():
    host, pil = runs(NEWCOMER, 0.3, target="qemu")
    assert_same_logs(host, pil)
    assert_same_logs(sd.simulate(NEWCOMER, duration=0.3, engine="python"), pil)  # the Python emulation's loop
    r = pil.summary["pil"]
    assert pil.summary["tick_loop"] == "pil"
    t = r["timing"]
    # every operation of the generated tick (IK and PID, counted by the generator) is at least one instruction
    sc = pil.plan.scenario
    g = generate(sc.platform, sc.config)
    assert t["instructions_worst"] % INSTRUCTIONS_PER_COUNT == 0
    assert t["instructions_worst"] >= t["instructions_mean"] >= sum(g.ik_ops.values()) + sum(g.tick_ops.values())
    assert t["dsp56800e_cycles"] == g.tick_cycles
    T = sc.config.timing.sample_period
    for name, hz in M4_CLOCKS_HZ.items():
        assert t["period_share"][name] == pytest.approx(t["cortex_m4_cycles_worst"] / hz / T, rel=1e-12)
    assert r["round_trip_s"]["max"] >= r["round_trip_s"]["median"] > 0


@needs_qemu
def test_both_qemu_links_run_the_same_tick_and_count_the_same_instructions():
    """The two QEMU builds differ only in the link's byte driver: the logs are equal, and the instructions
    counted around sd_tick agree to the SysTick's resolution (the count's phase against the 40 ns clock
    differs)."""
    uart = sd.simulate(NEWCOMER, duration=0.2, **{"pil.target": "qemu"})
    semi = sd.simulate(NEWCOMER, duration=0.2, **{"pil.target": "qemu:semihosting"})
    assert_same_logs(uart, semi)
    a, b = uart.summary["pil"], semi.summary["pil"]
    assert a["per_tick"]["tick"] == b["per_tick"]["tick"] == list(range(1, uart.summary["ticks"] + 1))
    ca, cb = np.array(a["per_tick"]["clock_counts"]), np.array(b["per_tick"]["clock_counts"])
    assert np.all(np.abs(ca - cb) <= 1)
    ta, tb = a["timing"], b["timing"]
    assert abs(ta["instructions_worst"] - tb["instructions_worst"]) <= INSTRUCTIONS_PER_COUNT
    assert tb["instructions_resolution"] == INSTRUCTIONS_PER_COUNT


@needs_qemu
@pytest.mark.parametrize("model", ["screw", "hydraulic"])
def test_the_target_drives_screw_and_hydraulic_actuators_like_the_host(model):
    """The actuator models run on the Python tick loop; the tick on the target gives the same logs."""
    options = {"actuators.model": model}
    host = sd.simulate(NEWCOMER, duration=0.3, engine="c", **options)
    pil = sd.simulate(NEWCOMER, duration=0.3, **options, **{"pil.target": "qemu:semihosting"})
    assert pil.summary["tick_loop"] == "pil" and pil.summary["actuator_model"] == model
    assert_same_logs(host, pil)
    assert pil.summary["pil"]["ticks_without_command"] == 0


@needs_qemu
def test_the_semihosting_build_ends_when_the_host_closes_the_link():
    sc = plan_run("utn-dynamic", duration=0.1).scenario
    target = QemuTarget(target_elf(program_module(sc.platform, sc.config), "cortex-m4-semihosting"), "qemu:semihosting")
    try:
        target.process.stdin.close()  # the end of its input: SYS_EXIT, QEMU's exit status 0
        assert target.process.wait(timeout=30) == 0
    finally:
        target.close()


QEMU_TARGETS = ("qemu", "qemu:semihosting")


@needs_qemu
@pytest.mark.parametrize("target", QEMU_TARGETS)
@pytest.mark.parametrize(
    "fault, counts",
    [
        ("corrupt", {"corrupt": 1, "lost": 1}),  # the CRC fails: never acted on, its number then skipped
        ("drop", {"lost": 1}),  # the next frame skips its number
        ("delay", {"lost": 1, "late": 1}),  # the next frame comes first; this one after it
    ],
)
def test_a_tick_without_its_command_is_detected_and_held(fault, counts, target):
    host, pil = runs("utn-dynamic", 0.15, target=target, fault=f"{fault}:@{FAULT_TICK}", timeout=TIMEOUT)
    r = pil.summary["pil"]
    assert r["events"] == [{"tick": FAULT_TICK, "fault": fault}, {"tick": FAULT_TICK, "no_command": "hold"}]
    target = {k: r["target_counters"][k] for k in ("corrupt", "lost", "duplicate", "late")}
    assert target == {"corrupt": 0, "lost": 0, "duplicate": 0, "late": 0} | counts
    assert r["host_counters"]["lost"] == 1  # the reply that never came
    assert pil.ok
    # up to the faulty tick's release the run is the host's; tick k's command is held from (k + 1)·T (latency
    # sample), so the command held then is still tick k - 1's
    t = pil.log["t"]
    k = int(np.searchsorted(t, FAULT_TICK * 1e-3, side="right"))
    assert_same_logs(host, pil, rows=k)
    assert not np.array_equal(host.log["command"], pil.log["command"])
    held = pil.log["command"][(t > (FAULT_TICK - 1) * 1e-3) & (t <= (FAULT_TICK + 1) * 1e-3)]
    assert np.all(held == held[0])  # the command of tick k - 1 kept through tick k's release


@needs_qemu
@pytest.mark.parametrize("target", QEMU_TARGETS)
def test_a_duplicated_frame_is_counted_and_ignored(target):
    host, pil = runs("utn-dynamic", 0.1, target=target, fault=f"duplicate:@{FAULT_TICK}", timeout=TIMEOUT)
    r = pil.summary["pil"]
    assert r["target_counters"]["duplicate"] == 1 and r["ticks_without_command"] == 0
    assert_same_logs(host, pil)  # acted on once: nothing changes


@needs_qemu
def test_stop_commands_zero_force_and_fails_the_run(tmp_path, capsys):
    args = ["--pil", "qemu", "--pil-fault", f"drop:@{FAULT_TICK}", "--pil-on-fault", "stop", "--duration", "0.1"]
    out = tmp_path / "s"
    rc, _, err = cli(capsys, "simulate", *args, "--set", f"pil.timeout={TIMEOUT}", "--out", str(out), "--no-progress")
    assert rc == 1, err
    summary = json.loads((out / "summary.json").read_text())
    p = summary["pil"]
    assert p["stopped_at_tick"] == FAULT_TICK and p["events"][-1] == {"tick": FAULT_TICK, "no_command": "stop"}
    assert summary["failures"][-1] == PIL_STOPPED.format(**p)  # after the fall it causes (tracking lost)
    assert f"stewart-drake simulate: {PIL_STOPPED.format(**p)}" in err
    assert " ticks, 1 without a command; sd_tick worst " in err and "DSP56800E estimate " in err
    rows = (out / "pil.csv").read_text().splitlines()  # the ticks the target answered, each timed
    assert rows[0] == "tick,round_trip_s,clock_counts" and [int(r.split(",")[0]) for r in rows[1:]] == list(
        range(1, FAULT_TICK)
    )
    assert all(float(r.split(",")[1]) > 0 and int(r.split(",")[2]) > 0 for r in rows[1:])
    assert "per_tick" not in p
    log = np.load(out / "log.npz")
    t, command = log["t"], log["command"]
    # tick k's command is released at (k + 1)·T (latency sample): zero from the faulty tick's release on
    assert np.all(command[t > FAULT_TICK * 1e-3] == 0.0) and np.any(command[t < FAULT_TICK * 1e-3] != 0.0)


def test_fault_draws_follow_the_seed():
    spec = PilSpec(target="qemu", fault="corrupt:0.1")
    faults = [PilFaults(spec, seed) for seed in (3, 3, 4)]
    draws = [[f.at(k) for k in range(1, 2001)] for f in faults]
    assert draws[0] == draws[1] != draws[2]
    assert 150 < draws[0].count("corrupt") < 250  # 200 expected: binomial σ ≈ 13.4
    at = PilFaults(PilSpec(target="qemu", fault="drop:@2,5"), 0)
    assert [at.at(k) for k in range(1, 7)] == [None, "drop", None, None, "drop", None]


def test_pil_settings_are_checked_with_their_flags(tmp_path, capsys):
    rc, out, err = cli(capsys, "simulate", "--pil", "usb", "--out", str(tmp_path / "s"))
    assert rc == 2 and err.strip().endswith("--pil must be one of qemu, qemu:semihosting, serial:PATH, got usb")
    rc, out, err = cli(capsys, "simulate", "--pil", "qemu", "--pil-fault", "drop:3", "--out", str(tmp_path / "s"))
    assert rc == 2 and "--pil-fault must be KIND:RATE" in err and err.strip().endswith("got drop:3")
    rc, out, err = cli(capsys, "simulate", "--pil", "qemu", "--controller", "float", "--out", str(tmp_path / "s"))
    assert rc == 2 and "--pil qemu runs the fixed-point firmware" in err
    assert not (tmp_path / "s").exists()


def qemu_children(pid: int) -> list[int]:
    out = subprocess.run(["ps", "-eo", "pid,ppid,comm"], capture_output=True, text=True).stdout.splitlines()[1:]
    return [int(p) for p, pp, c in (ln.split(None, 2) for ln in out) if int(pp) == pid and c.startswith("qemu")]


def alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    return True


@needs_qemu
@pytest.mark.parametrize(
    "sig, target", [(signal.SIGINT, "qemu"), (signal.SIGKILL, "qemu"), (signal.SIGKILL, "qemu:semihosting")]
)
def test_qemu_ends_with_the_run_even_when_it_is_interrupted_or_killed(sig, target):
    code = f"import stewart_drake as sd; sd.simulate('utn-dynamic', duration=30.0, **{{'pil.target': '{target}'}})"
    p = subprocess.Popen([sys.executable, "-c", code], cwd=os.getcwd(), stderr=subprocess.PIPE)
    try:
        for _ in range(1200):  # QEMU starts once the ELF is built and the plant loaded: seconds here
            children = qemu_children(p.pid)
            if children:
                break
            time.sleep(0.05)
        assert children, "no QEMU started"
        time.sleep(1.0)  # ticks under way
        p.send_signal(sig)
        p.wait(timeout=30)
        for _ in range(100):  # SIGKILL: the kernel's parent-death signal reaches QEMU at once
            if not alive(children[0]):
                break
            time.sleep(0.05)
        assert not alive(children[0])
    finally:
        p.kill()
        p.wait()
        p.stderr.close()


@needs_qemu
def test_qemu_ends_when_the_run_fails(monkeypatch):
    monkeypatch.setattr(pil_module, "format_fingerprint", lambda line: bytes(8))  # a host of another format
    started = []
    real = pil_module.open_target
    monkeypatch.setattr(pil_module, "open_target", lambda *a: started.append(real(*a)) or started[-1])
    with pytest.raises(sd.StewartError, match=r"^PIL link: the target .* refused the handshake"):
        sd.simulate("utn-dynamic", duration=0.05, **{"pil.target": "qemu"})
    assert len(started) == 1 and started[0].process.poll() is not None  # stopped, and waited for
    assert qemu_children(os.getpid()) == []


@needs_qemu
def test_a_target_that_dies_mid_run_is_one_error_naming_the_tick(monkeypatch):
    real = pil_module.open_target

    def dying(*args):  # QEMU killed from outside a second into the ticks
        target = real(*args)
        threading.Timer(1.0, target.process.kill).start()
        return target

    monkeypatch.setattr(pil_module, "open_target", dying)
    gone = r"^PIL link: the target closed the link at tick \d+ \(QEMU exited with status -9\)$"  # SIGKILL
    with pytest.raises(sd.StewartError, match=gone):
        sd.simulate("utn-dynamic", duration=30.0, **{"pil.target": "qemu"})


@needs_qemu
def test_a_qemu_that_refuses_to_start_is_one_error_with_its_own_message(monkeypatch):
    link = ("-serial", "none", "-semihosting-config", "enable=on,target=nowhere")  # a QEMU without this option
    monkeypatch.setitem(pil_target.QEMU_LINKS, "qemu:semihosting", ("cortex-m4-semihosting", link))
    with pytest.raises(sd.StewartError) as e:
        sd.simulate("utn-dynamic", duration=0.05, **{"pil.target": "qemu:semihosting"})
    message = str(e.value)
    assert message.startswith("PIL link: the target closed the link at tick 0 (QEMU exited with status 1: ")
    assert "target=nowhere" in message and "\n" not in message


@pytest.mark.skipif(shutil.which("cc") is None, reason="no host C compiler")
def test_serial_link_to_a_host_process_on_a_pseudo_terminal_equals_the_host_c_loop(tmp_path):
    machine = "utn-dynamic"
    host = sd.simulate(machine, duration=0.15, engine="c")
    sc = plan_run(machine, duration=0.15).scenario
    exe = build_host(program_module(sc.platform, sc.config), tmp_path / "pil")
    master, slave = os.openpty()
    board = subprocess.Popen([str(exe)], stdin=master, stdout=master)
    try:
        r = sd.simulate(machine, duration=0.15, **{"pil.target": f"serial:{os.ttyname(slave)}"})
    finally:
        board.kill()
        board.wait()
        os.close(master)
        os.close(slave)
    assert_same_logs(host, r)
    assert r.summary["pil"]["timing"] is None  # the host build has no cycle clock
    per_tick = r.summary["pil"]["per_tick"]  # the serial line's round trip, logged at every tick
    assert per_tick["tick"] == list(range(1, r.summary["ticks"] + 1))
    assert min(per_tick["round_trip_s"]) > 0 and set(per_tick["clock_counts"]) == {None}


def test_only_single_runs_go_to_the_target():
    m = sd.load_machine("utn-dynamic", ["pil.target=qemu", "run.duration=0.1"])
    assert plan_run(m).scenario.pil == m.pil and plan_run(m, command="run --simulate").scenario.pil == m.pil
    for study in ("montecarlo", "report", "response"):  # many runs of the host loop: the target's numbers
        assert plan_run(m, command=study).scenario.pil is None
