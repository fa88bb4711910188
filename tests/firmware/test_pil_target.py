"""The PIL program's ELF for a module is built once and then read from the cache, keyed by its sources'
content (``firmware.pil_target.target_elf``), like the host's C builds."""

import shutil

import pytest

from stewart_drake.control.gains import ControllerConfig
from stewart_drake.core.geometry import load_platform
from stewart_drake.errors import MachineError
from stewart_drake.firmware.pil import program_module
from stewart_drake.firmware.pil_target import target_elf
from stewart_drake.spec.machine import PilSpec

needs_cross = pytest.mark.skipif(shutil.which("arm-none-eabi-gcc") is None, reason="no arm-none-eabi-gcc")


@needs_cross
def test_the_elf_is_cached_by_the_content_of_its_sources(tmp_path, monkeypatch):
    monkeypatch.setenv("STEWART_DRAKE_CACHE", str(tmp_path))
    p = load_platform("utn-dynamic")
    files = program_module(p, ControllerConfig.for_platform(p))
    first = target_elf(files)
    stamp = first.stat().st_mtime_ns
    assert target_elf(files) == first and first.stat().st_mtime_ns == stamp  # not rebuilt
    other = dict(files, **{"sd_firmware.c": files["sd_firmware.c"] + "\n/* another module */\n"})
    assert target_elf(other) != first
    assert sorted(f.suffix for f in tmp_path.glob("sd-pil-*")) == [".elf", ".elf", ".sha256", ".sha256"]


@pytest.mark.parametrize(
    "field, value, message",
    [
        ("target", "qemu2", "pil.target must be one of qemu, qemu:semihosting, serial:PATH, got qemu2"),
        ("target", "qemu:semihost", "pil.target must be one of qemu, qemu:semihosting, serial:PATH, got qemu:semihost"),
        ("target", "serial:", "pil.target must be one of qemu, qemu:semihosting, serial:PATH, got serial:"),
        ("fault", "drop:1.5", "pil.fault must be KIND:RATE"),
        ("fault", "flip:0.1", "pil.fault must be KIND:RATE"),
        ("fault", "drop:@0", "pil.fault must be KIND:RATE"),
        ("on_fault", "retry", "pil.on_fault must be one of hold, stop, got retry"),
        ("timeout", 0.0, "pil.timeout must be > 0 s, got 0"),
    ],
)
def test_pil_spec_names_the_bad_field(field, value, message):
    with pytest.raises(MachineError, match="^" + message.replace("(", r"\(").replace(")", r"\)")):
        PilSpec(**{field: value})
