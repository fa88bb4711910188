"""The other end of a processor-in-the-loop link: the PIL program (``firmware/target/``) built for the
Cortex-M4 and run in QEMU, or a board on a serial port. Each is a byte stream with ``write(data)``,
``read(timeout)`` (``firmware.link``'s reader) and ``close()``.

QEMU runs ``-M mps2-an386`` with the link on its standard input and output (two pipes: no port to choose,
nothing for another process to connect to): ``qemu`` puts the board's UART0 there, the byte-at-a-time path a
board takes; ``qemu:semihosting`` runs the build whose link is the semihosting console, which QEMU reads and
writes on the same pipes (``target/sd_semihost.c``: a frame a call instead of a byte a trip through QEMU's main
loop; the rest of the program is the same). Both run ``-icount shift=0``: each instruction advances the virtual
clock by 1 ns, so the SysTick counts the PIL program reads around ``sd_tick`` (the AN386's 25 MHz processor
clock, 40 ns) are whole instructions / 40: ``INSTRUCTIONS_PER_COUNT``. The process is killed by ``close()``, by
the kernel when this process dies (``PR_SET_PDEATHSIG``) and, as a last resort, when the target object is
collected or the interpreter exits (``weakref.finalize``).

The ELF is cached by the content hash of its sources, the cross compiler's version and the build flags, like
the host's C builds (``system.c_build``).
"""

from __future__ import annotations

import hashlib
import os
import shutil
import subprocess
import tempfile
import termios
import weakref
from pathlib import Path

from stewart_drake.errors import FirmwareError
from stewart_drake.firmware.link import pipe_reader
from stewart_drake.firmware.target_build import C_FLAGS, TARGETS, build_target, cross_tools, program_files
from stewart_drake.system.c_build import cache_dir, intact, store
from stewart_drake.system.processes import die_with_parent

QEMU = "qemu-system-arm"
QEMU_ARGS = ("-M", "mps2-an386", "-nographic", "-monitor", "none", "-icount", "shift=0")
# pil.target -> (the target build it runs, QEMU's arguments that put its link on standard input and output)
QEMU_LINKS = {
    "qemu": ("cortex-m4", ("-serial", "stdio")),
    "qemu:semihosting": (
        "cortex-m4-semihosting",
        ("-serial", "none", "-semihosting-config", "enable=on,target=native"),
    ),
}
INSTRUCTIONS_PER_COUNT = 40  # icount shift=0: 1 ns an instruction; the AN386's SysTick: 25 MHz, 40 ns a count
SERIAL_BAUD = termios.B115200
CLOSE_WAIT_S = 5.0


def target_elf(files: dict, target: str = "cortex-m4") -> Path:
    """The PIL program's ELF for the generated module ``files`` (name -> text), from the cache or built into it.

    Raises:
        FirmwareError: no cross compiler, or a failing build.
    """
    cc = cross_tools(target)[0]
    version = subprocess.run([cc, "--version"], capture_output=True, text=True).stdout.splitlines()[:1]
    h = hashlib.sha256("\0".join([target, *version, *TARGETS[target]["flags"], *C_FLAGS]).encode())
    for name, text in sorted(program_files(files).items()):
        h.update(name.encode() + b"\0" + text.encode() + b"\0")
    root = cache_dir()
    out = root / f"sd-pil-{h.hexdigest()[:32]}.elf"
    if not intact(out):
        with tempfile.TemporaryDirectory(prefix="pil-", dir=root) as work:
            built = build_target(files, Path(work), target)
            store(built.elf, out)
    return out


class QemuTarget:
    """The PIL program in QEMU: ``write``, ``read`` and ``close`` (see the module's docstring).

    Raises:
        FirmwareError: QEMU is not installed or does not start.
    """

    def __init__(self, elf: Path, target: str = "qemu"):
        qemu = shutil.which(QEMU)
        if qemu is None:
            raise FirmwareError(FirmwareError.NO_QEMU.format(target=target, tool=QEMU, package="qemu-system-arm"))
        self.errors = tempfile.TemporaryFile()  # QEMU's messages: the reason it ended, if it ends early
        try:
            self.process = subprocess.Popen(
                [qemu, *QEMU_ARGS, *QEMU_LINKS[target][1], "-kernel", str(elf)],
                stdin=subprocess.PIPE,
                stdout=subprocess.PIPE,
                stderr=self.errors,
                bufsize=0,
                preexec_fn=die_with_parent,
            )
        except OSError as e:
            self.errors.close()
            raise FirmwareError(FirmwareError.PIL_START.format(target=target, what=QEMU, detail=e)) from None
        self.read = pipe_reader(self.process.stdout.fileno())
        self._finalizer = weakref.finalize(self, _stop, self.process, self.errors)

    def ended(self) -> str:
        """Why QEMU ended (its exit status and last message), or "" if it still runs a second after the call (its
        output closed: it is ending)."""
        try:
            status = self.process.wait(1.0)
        except subprocess.TimeoutExpired:
            return ""
        if self.errors.closed:
            return ""
        self.errors.seek(0)
        lines = [ln.strip() for ln in self.errors.read().decode(errors="replace").splitlines() if ln.strip()]
        return f"QEMU exited with status {status}" + (f": {lines[-1]}" if lines else "")

    def write(self, data: bytes) -> None:
        try:
            self.process.stdin.write(data)
        except BrokenPipeError:
            raise EOFError("QEMU closed the link") from None

    def close(self) -> None:
        """Stop QEMU (killed: the UART build never ends by itself) and wait for it."""
        self._finalizer()


def _stop(process: subprocess.Popen, errors) -> None:
    process.kill()
    process.wait(CLOSE_WAIT_S)
    for f in (process.stdin, process.stdout, errors):
        f.close()


class SerialTarget:
    """A board on a serial port (``path``: a tty, or a pseudo-terminal in a test), 8N1 at 115200 baud, raw.

    Raises:
        FirmwareError: the port cannot be opened or set up.
    """

    def __init__(self, path: str):
        try:
            self.fd = os.open(path, os.O_RDWR | os.O_NOCTTY)
            attrs = termios.tcgetattr(self.fd)
            attrs[0] = attrs[1] = attrs[3] = 0  # raw: no input, output or line processing
            attrs[2] = termios.CS8 | termios.CREAD | termios.CLOCAL
            attrs[4] = attrs[5] = SERIAL_BAUD
            attrs[6][termios.VMIN], attrs[6][termios.VTIME] = 0, 0
            termios.tcsetattr(self.fd, termios.TCSANOW, attrs)
            termios.tcflush(self.fd, termios.TCIOFLUSH)
        except OSError as e:
            raise FirmwareError(
                FirmwareError.PIL_START.format(target=f"serial:{path}", what=path, detail=e.strerror or e)
            ) from None
        self.read = pipe_reader(self.fd)

    def write(self, data: bytes) -> None:
        view = memoryview(data)
        while view:
            view = view[os.write(self.fd, view) :]

    def ended(self) -> str:
        """Why the board's end closed (a port has no process to ask): ""."""
        return ""

    def close(self) -> None:
        if self.fd >= 0:
            os.close(self.fd)
            self.fd = -1


def open_target(target: str, files: dict) -> QemuTarget | SerialTarget:
    """The link's other end for ``pil.target`` (``qemu``, ``qemu:semihosting``: the ELF of ``files`` built and
    started in QEMU; ``serial:PATH``: the port, the board already flashed)."""
    if target in QEMU_LINKS:
        return QemuTarget(target_elf(files, QEMU_LINKS[target][0]), target)
    return SerialTarget(target.split(":", 1)[1])
