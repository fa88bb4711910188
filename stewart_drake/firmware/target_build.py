"""The generated firmware built for a microcontroller, with the runtime of ``firmware/target/`` (start-up,
vector table, linker script, polled UART, the PIL link around ``sd_tick``) and no vendor SDK or C library;
and the same program built for the host, its link on stdin/stdout.

``build_target(files, work, target)`` compiles each source with ``-fstack-usage -fcallgraph-info=su``, links
an ELF with its map, and measures the code and data sizes (``arm-none-eabi-size``) and the worst-case stack
depth: the deepest path of the static call graph from the reset handler, each function's frame from GCC's
``.su`` records. A call through a pointer, recursion or a dynamic frame leaves the depth unbounded (None).
"""

from __future__ import annotations

import re
import shutil
import subprocess
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

from stewart_drake.errors import FirmwareError
from stewart_drake.firmware.link import fingerprint_header, format_fingerprint

C_FLAGS = ("-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic")
# Cortex-M4 cores (GNU Arm toolchain, soft float): what every target shares
CORTEX_M4 = {
    "cc": "arm-none-eabi-gcc",
    "size": "arm-none-eabi-size",
    "readelf": "arm-none-eabi-readelf",
    "objdump": "arm-none-eabi-objdump",
    "package": "gcc-arm-none-eabi",
    "flags": ("-mcpu=cortex-m4", "-mthumb", "-mfloat-abi=soft"),
    "entry": "Reset_Handler",
}
TARGETS = {
    "cortex-m4": {
        **CORTEX_M4,
        "board": "mps2-an386",
        "linker_script": "mps2_an386.ld",
        "runtime": ("sd_startup.c", "sd_uart_cmsdk.c"),
    },
    "cortex-m4-semihosting": {  # the same board, the link on the semihosting console: QEMU or a debug probe
        **CORTEX_M4,
        "board": "mps2-an386",
        "linker_script": "mps2_an386.ld",
        "runtime": ("sd_startup.c", "sd_semihost.c"),
    },
    "stm32f405": {  # the STM32F4 Discovery and other STM32F405/F407 boards: flash at 0x08000000, USART2
        **CORTEX_M4,
        "board": "stm32f4",
        "linker_script": "stm32f405.ld",
        "runtime": ("sd_startup.c", "sd_usart_stm32f4.c"),
    },
}
LINK_SOURCES = ("sd_link.c", "sd_pil.c")
HEADERS = ("sd_link.h", "sd_pil.h")
HOST_SOURCES = ("sd_pil_stdio.c",)
FIRMWARE_SOURCES = ("sd_firmware.c",)
ABI = ("sd_ik", "sd_tick", "sd_fk")  # linked whether or not the PIL program calls them
TOOL_TIMEOUT_S = 300  # one compiler or size run; the whole program is a few thousand lines


def runtime_text(name: str) -> str:
    """A file of the runtime (``firmware/target/NAME``)."""
    return resources.files("stewart_drake.firmware").joinpath("target", name).read_text()


def check_target(target: str) -> dict:
    """The target's description (``TARGETS``).

    Raises:
        FirmwareError: an unknown target name.
    """
    if target not in TARGETS:
        raise FirmwareError(FirmwareError.TARGET.format(valid=", ".join(TARGETS), value=target))
    return TARGETS[target]


def cross_tools(target: str) -> tuple[str, ...]:
    """The paths of the target's compiler, size, symbol-table and disassembler tools.

    Raises:
        FirmwareError: the cross compiler is not installed.
    """
    t = check_target(target)
    found = []
    for tool in (t["cc"], t["size"], t["readelf"], t["objdump"]):
        path = shutil.which(tool)
        if path is None:
            raise FirmwareError(FirmwareError.NO_CROSS.format(target=target, tool=tool, package=t["package"]))
        found.append(path)
    return tuple(found)


def program_files(files: dict) -> dict:
    """The generated module (``files``: name -> text, with its fingerprint line) with the runtime and the
    ``sd_pil_config.h`` holding its format fingerprint: every source of the PIL program, name -> text."""
    header = files["sd_firmware.h"]
    first = header.splitlines()[0] if header.startswith("/*") else ""
    out = {n: files[n] for n in ("sd_firmware.h", *FIRMWARE_SOURCES)}
    out["sd_pil_config.h"] = fingerprint_header(format_fingerprint(first))
    for name in (*LINK_SOURCES, *HEADERS, *HOST_SOURCES, *(s for t in TARGETS.values() for s in t["runtime"])):
        out[name] = runtime_text(name)
    for t in TARGETS.values():
        out[t["linker_script"]] = runtime_text(t["linker_script"])
    return out


def _run(argv: list[str], cwd: Path, target: str, step: str) -> str:
    try:
        r = subprocess.run(argv, cwd=cwd, capture_output=True, text=True, timeout=TOOL_TIMEOUT_S)
    except (OSError, subprocess.TimeoutExpired) as e:
        raise FirmwareError(FirmwareError.CROSS_FAILED.format(target=target, step=step, detail=e)) from e
    if r.returncode != 0:
        lines = (r.stderr or r.stdout).strip().splitlines()
        first = next((ln for ln in lines if "error" in ln), lines[0] if lines else f"exit status {r.returncode}")
        raise FirmwareError(FirmwareError.CROSS_FAILED.format(target=target, step=step, detail=first.strip()))
    return r.stdout


@dataclass
class TargetBuild:
    """A target build: the ELF and its map, the bytes of code (``.text``, vectors and constants: flash) and of
    data (``.data`` initialised, ``.bss`` zeroed: RAM), and the worst-case stack depth in bytes with its call
    path from the entry (``stack_bytes`` None: unbounded, ``stack_path`` naming why); ``functions``: for each ABI
    function (``ABI``), the code bytes of it and of every function it calls, and its own stack depth."""

    target: str
    elf: Path
    map: Path
    text: int
    data: int
    bss: int
    stack_bytes: int | None
    stack_path: tuple[str, ...]
    functions: dict

    def to_dict(self) -> dict:
        return {
            "target": self.target,
            "board": TARGETS[self.target]["board"],
            "elf": self.elf.name,
            "map": self.map.name,
            "code_bytes": self.text,
            "data_bytes": self.data,
            "bss_bytes": self.bss,
            "stack_bytes": self.stack_bytes,
            "stack_path": list(self.stack_path),
            "functions": self.functions,
        }


def build_target(files: dict, work: Path, target: str = "cortex-m4", name: str = "sd_pil") -> TargetBuild:
    """Cross-compile the PIL program (``program_files(files)``) in the folder ``work``.

    Returns:
        The ELF ``work/NAME.elf``, its map ``work/NAME.map``, sizes and stack depth.

    Raises:
        FirmwareError: no cross compiler, or a compile, link or size step that fails (its first error line).
    """
    t = check_target(target)
    cc, size, readelf, objdump = cross_tools(target)
    work.mkdir(parents=True, exist_ok=True)
    for n, text in program_files(files).items():
        (work / n).write_text(text)
    sources = (*FIRMWARE_SOURCES, *LINK_SOURCES, *t["runtime"])
    flags = [*t["flags"], *C_FLAGS, "-Os", "-ffreestanding", "-ffunction-sections", "-fdata-sections"]
    objects = []
    for src in sources:
        obj = Path(src).with_suffix(".o").name
        _run(
            [cc, *flags, "-fstack-usage", "-fcallgraph-info=su", "-c", src, "-o", obj], work, target, f"compiling {src}"
        )
        objects.append(obj)
    elf, map_ = work / f"{name}.elf", work / f"{name}.map"
    link = [cc, *t["flags"], "-nostdlib", "-T", t["linker_script"], "-Wl,--gc-sections", f"-Wl,-Map={map_.name}"]
    keep = [f"-Wl,--undefined={f}" for f in ABI]
    _run([*link, *keep, *objects, "-lgcc", "-o", elf.name], work, target, "linking")
    sections = _sections(_run([size, "-A", elf.name], work, target, "measuring"))
    linked = _functions(_run([readelf, "-sW", elf.name], work, target, "listing symbols"))
    frames, calls = call_graph(work)
    asm_frames, asm_calls = machine_frames(
        _run([objdump, "-d", "--no-show-raw-insn", elf.name], work, target, "disassembling")
    )
    for fn in linked:  # GCC's frames for the compiled code; the machine code's bound for a library routine
        frames.setdefault(fn, asm_frames.get(fn))
        calls[fn] = sorted(set(calls.get(fn, ())) | set(asm_calls.get(fn, ())))
    depth, path = stack_depth(frames, calls, t["entry"])
    functions = {
        f: {
            "code_bytes": sum(linked.get(g, 0) for g in reach(calls, f)),
            "stack_bytes": stack_depth(frames, calls, f)[0],
        }
        for f in ABI
    }
    return TargetBuild(
        target,
        elf,
        map_,
        text=sections.get(".text", 0) + sections.get(".ARM.exidx", 0),
        data=sections.get(".data", 0),
        bss=sections.get(".bss", 0),
        stack_bytes=depth,
        stack_path=path,
        functions=functions,
    )


def build_host(files: dict, work: Path, compiler: str = "cc", name: str = "sd_pil_host") -> Path:
    """The PIL program for the host (its link on stdin and stdout), compiled with the strict flags in ``work``.

    Raises:
        FirmwareError: the compile fails.
    """
    work.mkdir(parents=True, exist_ok=True)
    for n, text in program_files(files).items():
        (work / n).write_text(text)
    sources = (*FIRMWARE_SOURCES, *LINK_SOURCES, *HOST_SOURCES)
    _run([compiler, *C_FLAGS, "-O2", *sources, "-o", name], work, "host", "compiling")
    return work / name


def _sections(text: str) -> dict:
    out = {}
    for line in text.splitlines():
        parts = line.split()
        if len(parts) >= 2 and parts[0].startswith(".") and parts[1].isdigit():
            out[parts[0]] = int(parts[1])
    return out


def _functions(symbols: str) -> dict:
    """The functions of a ``readelf -sW`` symbol table: name -> code bytes."""
    rows = (ln.split() for ln in symbols.splitlines())
    return {p[7]: int(p[2], 0) for p in rows if len(p) == 8 and p[3] == "FUNC"}


_INSN = re.compile(r"^\s+[0-9a-f]+:\s+(\S+)\s*(.*)$")
_FUNC = re.compile(r"^[0-9a-f]+ <([^>]+)>:$")
_CALL = re.compile(r"^(bl|b|b\.w|b\.n)$")
_TARGET = re.compile(r"<([^>+]+)>$")
_REGS = re.compile(r"\{([^}]*)\}")


def _reg_count(operands: str, width: int) -> int:
    """Bytes a register list ``{r4, r5-r7, lr}`` takes on the stack, ``width`` bytes a register."""
    m = _REGS.search(operands)
    n = 0
    for r in m.group(1).split(",") if m else ():
        lo, _, hi = r.strip().partition("-")
        n += int(hi.lstrip("rdsq")) - int(lo.lstrip("rdsq")) + 1 if hi else 1
    return n * width


def machine_frames(disassembly: str) -> tuple[dict, dict]:
    """Each function's stack bound and callees read from its Thumb-2 machine code (``objdump -d``): the sum of
    every push, pre-decrementing store and ``sub sp`` in it (each path pushes at most that); ``UNBOUNDED`` for
    a write to ``sp`` from a register or a call through one."""
    frames: dict = {}
    calls: dict = {}
    fn = None
    for line in disassembly.splitlines():
        f = _FUNC.match(line)
        if f:
            fn = f.group(1)
            frames[fn], calls[fn] = 0, []
            continue
        m = _INSN.match(line)
        if fn is None or not m or frames[fn] == UNBOUNDED:
            continue
        op, args = m.group(1).split(".")[0], m.group(2).split("@")[0].split(";")[0].strip()
        if op == "push" or (op == "stmdb" and args.startswith("sp!")):
            frames[fn] += _reg_count(args, 4)
        elif op == "vpush":
            frames[fn] += _reg_count(args, 8 if "d" in args else 4)
        elif args.endswith("]!") and "[sp, #-" in args:
            frames[fn] += int(args.rsplit("#-", 1)[1].rstrip("]!"), 0)
        elif op in ("sub", "subw") and args.startswith("sp,"):
            imm = args.rsplit("#", 1)
            frames[fn] = frames[fn] + int(imm[1], 0) if len(imm) == 2 else UNBOUNDED
        elif op == "mov" and args.startswith("sp,") or op == "blx":
            frames[fn] = UNBOUNDED
        elif _CALL.match(m.group(1)):
            t = _TARGET.search(args)
            if t and t.group(1) != fn:
                calls[fn].append(t.group(1))
    return frames, calls


_NODE = re.compile(r'node: \{ title: "([^"]+)" label: "[^"]*\\n(\d+) bytes \((\w+)[^"]*"')
_EXTERN = re.compile(r'node: \{ title: "([^"]+)" label: "[^"]*" shape : ellipse')
_EDGE = re.compile(r'edge: \{ sourcename: "([^"]+)" targetname: "([^"]+)"')
UNBOUNDED = "__unbounded__"


def call_graph(work: Path) -> tuple[dict, dict]:
    """The frames (function -> bytes; ``UNBOUNDED`` for a dynamic one) and calls (function -> callees) that
    GCC's ``-fcallgraph-info=su`` records (``*.ci``) in ``work``; a static function by its bare name (two of
    one name: the larger frame and both callee lists)."""
    frames: dict = {}
    calls: dict = {}
    bare = lambda name: name.rsplit(":", 1)[-1]  # noqa: E731
    for ci in sorted(work.glob("*.ci")):
        text = ci.read_text()
        for fn, nbytes, kind in _NODE.findall(text):
            own = int(nbytes) if kind == "static" else UNBOUNDED
            old = frames.get(bare(fn), 0)
            frames[bare(fn)] = UNBOUNDED if UNBOUNDED in (own, old) else max(own, old)
        for a, b in _EDGE.findall(text):
            calls.setdefault(bare(a), []).append(bare(b))
    return frames, calls


def reach(calls: dict, entry: str) -> set:
    """``entry`` and every function its calls reach."""
    seen, todo = set(), [entry]
    while todo:
        f = todo.pop()
        if f not in seen:
            seen.add(f)
            todo += calls.get(f, ())
    return seen


def stack_depth(frames: dict, calls: dict, entry: str) -> tuple[int | None, tuple[str, ...]]:
    """The deepest stack from ``entry``: (bytes, the call path), or (None, the path to a function without a
    known frame, a dynamic frame or a recursion)."""
    memo: dict = {}

    def deepest(fn: str, stack: tuple[str, ...]) -> tuple[int | None, tuple[str, ...]]:
        if fn in stack:
            return None, (*stack, fn, "(recursion)")
        if fn in memo:
            return memo[fn]
        own = frames.get(fn)
        if own is None or own == UNBOUNDED:
            return None, (*stack, fn, "(frame unknown)" if own is None else "(dynamic frame)")
        best: tuple[int | None, tuple[str, ...]] = (own, (fn,))
        for callee in calls.get(fn, ()):
            d, p = deepest(callee, (*stack, fn))
            if d is None:
                return None, p
            if own + d > best[0]:
                best = (own + d, (fn, *p))
        memo[fn] = best
        return best

    return deepest(entry, ())
