"""The "Your machine" guide (``docs/your-machine.md``) runs as written: every command of its bash blocks, in
order, in one empty folder, exits with the status the page gives it (a trailing ``# exit N``, else 0), and its
Python blocks run there after them and print what their comments say."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
PAGE = ROOT / "docs" / "your-machine.md"


def page_commands() -> list[tuple[str, int]]:
    """``(command, expected exit status)`` for each command of the page's bash blocks, a here-document kept
    with its command."""
    text = PAGE.read_text(encoding="utf-8")
    commands = []
    for block in re.findall(r"^```bash\n(.*?)^```$", text, flags=re.S | re.M):
        lines = iter(block.splitlines())
        for line in lines:
            if not line.strip() or line.lstrip().startswith("#"):
                continue
            m = re.search(r"<<'(\w+)'", line)
            if m:  # a here-document: its lines up to the terminator belong to this command
                body = []
                for more in lines:
                    body.append(more)
                    if more.strip() == m.group(1):
                        break
                line = "\n".join([line, *body])
            want = re.search(r"#\s*exit\s+(\d+)\s*$", line)
            commands.append((line, int(want.group(1)) if want else 0))
    return commands


COMMANDS = page_commands()


def test_page_walks_the_whole_path():
    """The guide covers the path from the machine file to the report: each of these commands appears in it,
    and at least one run is shown failing (the 1 mm chatter)."""
    words = " ".join(c for c, _ in COMMANDS)
    for needed in (
        "init --machine-template",
        "ik ",
        "fk ",
        "workspace ",
        "--prove",
        "model ",
        "size ",
        "stiffness ",
        "modes ",
        "firmware generate",
        "firmware check",
        "firmware certify",
        "simulate --machine",
        "--firmware",
        "montecarlo ",
        "report --machine",
    ):
        assert needed in words, needed
    assert any(code == 1 and "simulate" in c and "length_lsb=1mm" in c for c, code in COMMANDS)


def test_page_commands_exit_as_the_page_says(tmp_path):
    """Each command, run as a user types it (``stewart-drake`` is this checkout's ``python -m stewart_drake``),
    exits with the page's status; the chatter run names its cause."""
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir()
    shim = bin_dir / "stewart-drake"
    shim.write_text(f'#!/bin/sh\nexec "{sys.executable}" -m stewart_drake "$@"\n')
    shim.chmod(0o755)
    work = tmp_path / "work"
    work.mkdir()
    env = {
        **os.environ,
        "PATH": f"{bin_dir}{os.pathsep}{os.environ.get('PATH', '')}",
        "PYTHONPATH": str(ROOT),
        "PYTHONDONTWRITEBYTECODE": "1",
        "EXAMPLES": str(ROOT / "examples"),
        "MPLBACKEND": "Agg",
    }
    for command, want in COMMANDS:
        r = subprocess.run(["bash", "-c", command], cwd=work, env=env, capture_output=True, text=True, timeout=300)
        assert r.returncode == want, f"{command}\nexit {r.returncode}, the page says {want}\n{r.stderr[-2000:]}"
        if "length_lsb=1mm" in command and want == 1:
            assert "chatter" in r.stderr and "length LSB (1 mm)" in r.stderr, r.stderr[-1000:]
    assert (work / "joints.png").stat().st_size > 0
    assert (work / "fw" / "sd_firmware.c").is_file()
    text = PAGE.read_text(encoding="utf-8")
    outputs = []
    for block in re.findall(r"^```python\n(.*?)^```$", text, flags=re.S | re.M):
        r = subprocess.run(
            [sys.executable, "-c", block], cwd=work, env=env, capture_output=True, text=True, timeout=300
        )
        assert r.returncode == 0, f"{block}\n{r.stderr[-2000:]}"
        outputs.append(r.stdout)
    # the loop block's comment: the machine's 30 um tracks, the DSP's 1 mm chatters
    assert "3e-05 True []" in outputs[-1] and '0.001 False ["chatter:' in outputs[-1], outputs[-1]


@pytest.mark.parametrize("kind", ["ik", "size"])
def test_machine_file_as_platform(tmp_path, kind):
    """A machine file given as ``--platform`` is its platform, its payload the design commands' ``--payload``:
    ``ik`` gives the platform's lengths; ``size`` carries the machine's payload (more force than the bare
    plate), and ``--payload 0`` given replaces it (the platform's forces,
    bit for bit: the same arithmetic on the same platform)."""
    import json

    import yaml

    from stewart_drake.spec import load_machine

    machine = ROOT / "examples" / "newcomer-210kg.yaml"
    doc = yaml.safe_load(machine.read_text(encoding="utf-8"))
    for key in ("payload", "controller", "firmware", "sensors", "actuators", "motions", "run"):
        doc.pop(key)
    platform = tmp_path / "platform.yaml"
    platform.write_text(yaml.safe_dump(doc))

    def run(path, *more):
        args = ["ik", "--pose", "0", "0", "700", "0", "0", "0"] if kind == "ik" else ["size", "--trajectory", "seed"]
        r = subprocess.run(
            [sys.executable, "-m", "stewart_drake", *args, *more, "--platform", str(path), "--json"],
            cwd=tmp_path,
            env={**os.environ, "PYTHONPATH": str(ROOT)},
            capture_output=True,
            text=True,
            timeout=120,
        )
        assert r.returncode in (0, 1), r.stderr
        return json.loads(r.stdout)

    plain, loaded = run(platform), run(machine)
    if kind == "ik":
        assert loaded["lengths"] == plain["lengths"]
        return
    force = lambda out: [leg["peak_force_n"] for leg in out["legs"]]  # noqa: E731
    assert loaded["payload_kg"] == load_machine(machine).payload.mass
    # the 150 kg ride on the legs: their peak forces together grow by more than half its weight (1.47 kN)
    assert sum(force(loaded)) > sum(force(plain)) + 0.5 * 150 * 9.81
    assert force(run(machine, "--payload", "0")) == force(plain)


def test_firmware_generate_takes_the_machine_format(tmp_path):
    """``firmware generate --platform MACHINE`` records the machine's number format, rate and sensor resolution
    and the platform as written (the hash ``simulate --machine --firmware`` compares); an option given replaces
    its value; a platform alone keeps the DSP's defaults (1 mm)."""
    from stewart_drake.firmware.fingerprint import platform_hash, read_fingerprint
    from stewart_drake.spec import load_machine

    machine = ROOT / "examples" / "newcomer-210kg.yaml"
    m = load_machine(machine)

    def generate(out, *more):
        r = subprocess.run(
            [sys.executable, "-m", "stewart_drake", "firmware", "generate", "--no-compile", "--out", out, *more],
            cwd=tmp_path,
            env={**os.environ, "PYTHONPATH": str(ROOT)},
            capture_output=True,
            text=True,
            timeout=120,
        )
        assert r.returncode == 0, r.stderr
        return read_fingerprint(tmp_path / out / "sd_firmware.c")[0]

    own = generate("fw", "--platform", str(machine))
    assert own["length_lsb"] == m.firmware.length_lsb and own["word_bits"] == m.firmware.word_bits
    assert own["rate"] == 1.0 / m.controller.period and own["sensor_resolution"] == m.sensors.resolution
    assert own["platform_hash"] == platform_hash(m.platform)
    assert generate("fw-1mm", "--platform", str(machine), "--length-lsb", "1e-3")["length_lsb"] == 1e-3
    assert generate("fw-preset", "--platform", "utn-dynamic")["length_lsb"] == 1e-3


def test_report_refuses_a_machine_file_as_platform(tmp_path, capsys):
    """``report --platform MACHINE`` (the report reads a machine with ``--machine``) is one line naming the file
    as written and the option to use, exit 2, before any work: no output folder."""
    from stewart_drake.cli import main
    from stewart_drake.errors import UsageError

    machine = tmp_path / "m.yaml"
    machine.write_text((ROOT / "examples" / "newcomer-210kg.yaml").read_text(encoding="utf-8"))
    rc = main(["report", "--platform", str(machine), "--quick", "--only", "workspace", "--out", str(tmp_path / "r")])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and not (tmp_path / "r").exists()
    assert err.endswith(UsageError.MACHINE_AS_PLATFORM.format(path=machine, use="--machine")) and "\n" not in err
