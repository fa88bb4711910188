"""A compiled firmware module — generated (``generate``) or a user's C implementing the ABI — loaded
with cffi: batch IK, traced IK, and the controller tick on an ``sd_state``."""

from __future__ import annotations

import hashlib
import os
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from stewart_drake.errors import FirmwareError
from stewart_drake.firmware.generate import GAIN_WORDS, OPS, TRACE_WORDS, GeneratedFirmware
from stewart_drake.firmware.loop_kernel import CDEF as LOOP_CDEF
from stewart_drake.system.c_build import Compiler, Source, build, instance, library_sources, load
from stewart_drake.system.input_stream import decode_text, read_input

# the closed loop's kernel (``loop_kernel``), linked with the host glue of the tick: its fixed-point law calls
# sd_host_tick; -ffp-contract=off keeps its float arithmetic numpy's (the firmware's own code is integer)
LOOP_SOURCES, LOOP_HEADERS, LOOP_DEFINES, LOOP_FLAGS = (
    ("sd_loop.c",),
    ("sd_loop.h",),
    ("SD_LOOP_FIXED",),
    ("-ffp-contract=off",),
)
ABI_NAMES = ("sd_ik", "sd_init", "sd_tick", "sd_ik_trace")
MAX_SOURCE_BYTES = 16_000_000  # a firmware source file; the generated one is ~15 kB
# The host's optimisation of generated firmware. Its C is integer arithmetic, and the loop's float code keeps
# numpy's roundings at every level (-ffp-contract=off), so every level gives the same words
# (tests/firmware/test_host_gains.py compares this build with -O3's); -O1 compiles in about half the CPU of
# -O3, which a first run on a fresh machine pays per library, at a small cost per tick beside the plant's step.
# A caller timing the batch IK's throughput asks for -O3.
HOST_OPT = "-O1"


def _cdef(word: str, counting: bool, gains_table: bool = False) -> str:
    s = f"""
typedef {word} sd_word;
typedef int32_t sd_count;
typedef struct {{ int32_t integ[6]; sd_count prev[6]; int16_t dfilt[6]; sd_word setpoint[6]; int16_t vfilt[6]; int16_t saturated[6]; }} sd_state;
int sd_ik(const sd_word pose[6], sd_word lengths[6]);
int sd_ik_trace(const sd_word pose[6], int32_t trace[{TRACE_WORDS}]);
int sd_fk(const sd_count measured[6], sd_word pose[6]);
void sd_init(sd_state *s);
int sd_tick(sd_state *s, const sd_word pose[6], const sd_count measured[6], const int16_t feedforward[6], int16_t command[6]);
void sd_ik_batch(const sd_word *poses, long n, sd_word *lengths, int32_t *nsat);
int sd_host_tick(sd_state *s, const sd_word pose[6], const double L[6], double res, const double *ff, double range,
                 double lsb, double state[30], double out[18]);
"""
    s += LOOP_CDEF  # the closed loop's kernel, linked with the tick (``loop_kernel``)
    if counting:
        s += f"extern long sd_op_counts[{len(OPS)}];\n"
    if gains_table:
        s += f"extern int32_t sd_gains[{len(GAIN_WORDS)}];\n"
    return s


@dataclass
class FirmwareModule:
    """A loaded firmware: ``ffi``, ``lib``, the library ``path``, ``word_dtype`` of ``sd_word``, the C file it
    was built from (``source``, a user's firmware; None for the generated module) and which optional ABI
    functions it defines (``has_tick``, ``has_trace``)."""

    ffi: object
    lib: object
    path: Path
    word: str
    counting: bool = False
    source: str | None = None

    @property
    def word_dtype(self):
        return np.int16 if self.word == "int16_t" else np.int32

    def _has(self, name: str) -> bool:
        try:
            getattr(self.lib, name)
            return True
        except (AttributeError, NotImplementedError):
            return False

    @property
    def has_tick(self) -> bool:
        return self._has("sd_tick") and self._has("sd_init")

    @property
    def has_trace(self) -> bool:
        return self._has("sd_ik_trace")

    def ik(self, words) -> tuple[np.ndarray, np.ndarray]:
        """``(lengths (..., 6) int64, saturation counts (...) int64)`` of ``(..., 6)`` pose words."""
        w = np.asarray(words)
        flat = np.ascontiguousarray(w.reshape(-1, 6), dtype=self.word_dtype)
        out = np.empty_like(flat)
        nsat = np.empty(len(flat), dtype=np.int32)
        f = self.ffi
        self.lib.sd_ik_batch(
            f.from_buffer(f"{self.word}[]", flat),
            len(flat),
            f.from_buffer(f"{self.word}[]", out),
            f.from_buffer("int32_t[]", nsat),
        )
        return out.astype(np.int64).reshape(w.shape), nsat.astype(np.int64).reshape(w.shape[:-1])

    def ik_raw(self, words: np.ndarray, out: np.ndarray) -> None:
        """``sd_ik`` over ``(n, 6)`` C-contiguous ``word_dtype`` pose words into ``out`` (same shape and
        dtype), no conversions: the batch call the throughput benchmark times."""
        f = self.ffi
        self.lib.sd_ik_batch(
            f.from_buffer(f"{self.word}[]", words), len(words), f.from_buffer(f"{self.word}[]", out), f.NULL
        )

    def ik_trace(self, pose_words) -> np.ndarray:
        """``(TRACE_WORDS,)`` int64 intermediate words of one pose (see ``generate.TRACE_FIELDS``)."""
        p = np.ascontiguousarray(pose_words, dtype=self.word_dtype).reshape(6)
        tr = np.zeros(TRACE_WORDS, dtype=np.int32)
        self.lib.sd_ik_trace(self.ffi.from_buffer(f"{self.word}[]", p), self.ffi.from_buffer("int32_t[]", tr))
        return tr.astype(np.int64)

    def new_state(self):
        s = self.ffi.new("sd_state *")
        self.lib.sd_init(s)
        return s

    def op_counts(self) -> dict:
        """The instrumented build's counters (name -> calls since the last ``reset_op_counts``)."""
        return {n: int(self.lib.sd_op_counts[k]) for k, n in enumerate(OPS) if self.lib.sd_op_counts[k]}

    def reset_op_counts(self) -> None:
        for k in range(len(OPS)):
            self.lib.sd_op_counts[k] = 0


def compile_generated(
    g: GeneratedFirmware,
    compiler: Compiler | None = None,
    counting: bool = False,
    opt: str = HOST_OPT,
    constants: bool = False,
) -> FirmwareModule:
    """Compile the generated module (strict flags: -Wall -Wextra -Werror -pedantic) with the host batch glue.

    The host's build (``g.host_files``) reads its gains from the table ``sd_gains``, filled here after
    loading: firmware that differs only in its gains compiles once, and each set of gains is loaded from a
    copy of that library of its own (``c_build.instance``: a process maps a file's globals once), so that
    modules with different gains live side by side. ``constants``: compile ``g.files``, the C a target
    compiles (its gains compile-time constants), as it is. Both give the same words bit for bit, at any
    optimisation ``opt``."""
    files = g.files if constants else g.host_files
    sources = [
        Source("sd_firmware.c", files["sd_firmware.c"]),
        *library_sources("sd_host.c", "sd_host_tick.c", *LOOP_SOURCES),
    ]
    headers = [Source("sd_firmware.h", files["sd_firmware.h"]), *library_sources(*LOOP_HEADERS)]
    path = build(
        sources,
        headers=headers,
        compiler=compiler,
        strict=True,
        defines=(*LOOP_DEFINES, *(("SD_COUNT_OPS",) if counting else ())),
        opt=opt,
        flags=("-lm", *LOOP_FLAGS),
    )
    word = "int16_t"
    if constants:
        ffi, lib = load(path, _cdef(word, counting))
    else:
        path = instance(path, "g" + hashlib.sha256(repr(g.gain_words).encode()).hexdigest()[:16])
        ffi, lib = load(path, _cdef(word, counting, gains_table=True))
        lib.sd_gains[0 : len(GAIN_WORDS)] = g.gain_words
    return FirmwareModule(ffi, lib, path, word, counting)


def compile_user(path: Path, g: GeneratedFirmware, compiler: Compiler | None = None) -> FirmwareModule:
    """Compile a user's C file implementing the ABI (``#include "sd_firmware.h"``; the header generated for
    the same platform and format is on the include path, and so is ``dsp56800e.h``). The compiler's
    messages name the user's file and line; raises build.CompileError."""
    path = check_source(path)
    sources = [Source(path.name, path=path.resolve()), *library_sources("sd_host.c", "dsp56800e.c")]
    headers = [Source("sd_firmware.h", g.files["sd_firmware.h"])]
    m = _load_user(build(sources, headers=headers, compiler=compiler, flags=("-lm",)), path)
    if m.has_tick:  # then link the tick's host glue too (it calls sd_tick)
        lib_path = build(
            sources + library_sources("sd_host_tick.c", *LOOP_SOURCES),
            headers=headers + library_sources(*LOOP_HEADERS),
            compiler=compiler,
            defines=LOOP_DEFINES,
            flags=("-lm",),
        )
        m = _load_user(lib_path, path)
    return m


def check_source(path, what: str = "firmware file") -> Path:
    """``path`` (as the user wrote it) as a ``Path`` if it names a regular file, else a ``FirmwareError``
    naming ``what`` and the value: no name at all (``""`` would be the current folder), missing, a folder,
    or not a regular file (a device or FIFO the compiler would block on)."""
    text = os.fspath(path)
    if not text.strip():
        raise FirmwareError(FirmwareError.FILE_NO_NAME.format(what=what, path=text))
    p = Path(text)
    if p.is_dir():
        raise FirmwareError(FirmwareError.FILE_FOLDER.format(what=what, path=text))
    if not p.exists():
        raise FirmwareError(FirmwareError.FILE_MISSING.format(what=what, path=text))
    if not p.is_file():
        raise FirmwareError(FirmwareError.FILE_SPECIAL.format(what=what, path=text))
    # C source is text: a binary file is one line naming it, not a codec error from the compiler's messages
    decode_text(read_input(p, kind="C source", limit=MAX_SOURCE_BYTES), text, "C source")
    return p


def _load_user(lib_path: Path, path: Path) -> FirmwareModule:
    """Load the library built from the user's ``path``. A shared library links with undefined symbols, so a
    function the file lacks (``sd_ik``, which the host glue calls) or misspells shows only here, as the
    loader's "undefined symbol": that becomes a ``FirmwareError`` naming the file and the symbol."""
    word = "int16_t"
    try:
        ffi, lib = load(lib_path, _cdef(word, False))
    except OSError as e:
        missing = re.search(r"undefined symbol: (\w+)", str(e))
        if missing is None:
            raise
        if missing.group(1) == "sd_ik":
            raise FirmwareError(FirmwareError.NO_IK.format(path=path)) from None
        raise FirmwareError(FirmwareError.UNDEFINED.format(path=path, symbol=missing.group(1))) from None
    return FirmwareModule(ffi, lib, lib_path, word, source=str(path))


class TickRunner:
    """Calls ``sd_tick`` with the controller's state held as the 30-word vector of ``control.FixedPointLaw``
    (integrator, previous measurement, its filtered difference, previous set-point, its filtered
    difference): the vector goes into a C ``sd_state`` and comes back out, with numpy views on one buffer.
    ``state_ptr`` is the cffi ``sd_state *`` on that buffer, for callers that run the C tick themselves
    (``firmware.sil``)."""

    FIELDS = (
        ("integ", np.int32),
        ("prev", np.int32),
        ("dfilt", np.int16),
        ("setpoint", None),
        ("vfilt", np.int16),
        ("saturated", np.int16),
    )

    def __init__(self, module: FirmwareModule):
        if not module.has_tick:
            raise FirmwareError(FirmwareError.NO_TICK.format(name=module.source or module.path.name))
        self.module = m = module
        ffi = m.ffi
        self._buf = bytearray(ffi.sizeof("sd_state"))
        self.state_ptr = ffi.from_buffer("sd_state *", self._buf)
        m.lib.sd_init(self.state_ptr)
        self.views = {
            name: np.frombuffer(self._buf, dtype=dt or m.word_dtype, count=6, offset=ffi.offsetof("sd_state", name))
            for name, dt in self.FIELDS
        }
        self.pose = np.zeros(6, dtype=m.word_dtype)
        self.measured = np.zeros(6, dtype=np.int32)
        self.feedforward = np.zeros(6, dtype=np.int16)
        self.command = np.zeros(6, dtype=np.int16)
        self._p = (
            ffi.from_buffer(f"{m.word}[]", self.pose),
            ffi.from_buffer("int32_t[]", self.measured),
            ffi.from_buffer("int16_t[]", self.feedforward),
            ffi.from_buffer("int16_t[]", self.command),
        )
        self._tick = m.lib.sd_tick
        self._null = ffi.NULL

    def set_state(self, state) -> None:
        st = np.asarray(state)
        v = self.views
        v["integ"][:] = st[0:6]
        v["prev"][:] = st[6:12]
        v["dfilt"][:] = st[12:18]
        v["setpoint"][:] = st[18:24]
        v["vfilt"][:] = st[24:30]

    def state(self) -> np.ndarray:
        """The 30-word state vector (int64)."""
        v = self.views
        return np.concatenate([v["integ"], v["prev"], v["dfilt"], v["setpoint"], v["vfilt"]]).astype(np.int64)

    def tick(self, pose_words, measured, feedforward_words=None) -> np.ndarray:
        """One ``sd_tick`` on the held state; returns the six Q15 command words (int16 view, copied)."""
        self.pose[:] = pose_words
        self.measured[:] = measured
        p_pose, p_meas, p_ff, p_cmd = self._p
        if feedforward_words is not None:
            self.feedforward[:] = feedforward_words
        self._tick(self.state_ptr, p_pose, p_meas, p_ff if feedforward_words is not None else self._null, p_cmd)
        return self.command.copy()
