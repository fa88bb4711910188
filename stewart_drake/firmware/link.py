"""The processor-in-the-loop link, host side: the framing and messages of the target's ``sd_link.c`` and
``sd_pil.c`` (``firmware/target/``), byte for byte.

A frame is ``COBS(payload) 0x00``; the payload is ``type u8 | seq u16 LE | body | CRC-16/CCITT-FALSE u16 BE``
(the CRC over type..body: polynomial 0x1021, initial value 0xFFFF, ``binascii.crc_hqx``). Messages:

- ``HELLO`` (host → target): link version u8, format fingerprint u8[8];
- ``HELLO_ACK`` (target → host, the same seq): the target's version, its fingerprint, accepted u8;
- ``SENSOR`` (host → target, once a tick): reference pose words i16[6], measured leg counts i32[6],
  feed-forward words i16[6], flags u8 (bit 0: feed-forward present);
- ``COMMAND`` (target → host, the SENSOR's seq): command words i16[6] (Q15 of the command range), saturated
  legs u8 (bit i: leg i + 1), the target's counters u32[7] (``COUNTERS``), the set-point words i32[6] and the
  clock counts ``sd_tick`` took u32 (``NOT_MEASURED`` where the runtime has no clock);
- ``STATUS`` (host → target, any time): no body;
- ``STATUS_REPLY`` (target → host, the same seq): the counters u32[7] and the most stack used since reset,
  u32 bytes (``NOT_MEASURED`` where the runtime does not paint its stack);
- ``SET_STATE`` (host → target, after the handshake): the controller's state (``sd_state``: integrator
  i32[6], previous measurement i32[6], measurement filter i16[6], set-point i32[6], set-point filter i16[6]),
  answered by a ``STATUS_REPLY`` of the same seq; the tick sequence is unchanged.

The format fingerprint is the first 8 bytes of the SHA-256 of the module's recorded options
(``firmware.fingerprint.fingerprint_line``): a target whose number format, gains or platform differ refuses
the handshake. A receiver acts only on a frame with a good CRC, a known type and size, and a sequence number
after the last one acted on; it counts the others (corrupt, malformed, duplicate, late) and the numbers
skipped (lost).
"""

from __future__ import annotations

import binascii
import hashlib
import os
import select
import struct
import time
from collections.abc import Callable
from dataclasses import dataclass, field

from stewart_drake.errors import FirmwareError

VERSION = 2  # sd_link.h's SD_LINK_VERSION
HELLO, HELLO_ACK, SENSOR, COMMAND, STATUS, STATUS_REPLY, SET_STATE = 1, 2, 3, 4, 5, 6, 7
NOT_MEASURED = 0xFFFFFFFF  # a stack high-water mark or clock count the target's runtime does not measure
MAX_PAYLOAD = 128  # bytes, type to CRC (sd_link.h's SD_LINK_MAX_PAYLOAD)
FINGERPRINT_BYTES = 8
COUNTERS = ("frames", "corrupt", "malformed", "lost", "duplicate", "late", "unexpected")
_SENSOR = struct.Struct("<6h6i6hB")
_COMMAND = struct.Struct(f"<6hB{len(COUNTERS)}I6iI")
_HELLO = struct.Struct(f"<B{FINGERPRINT_BYTES}s")
_HELLO_ACK = struct.Struct(f"<B{FINGERPRINT_BYTES}sB")
_STATUS_REPLY = struct.Struct(f"<{len(COUNTERS)}II")
_SET_STATE = struct.Struct("<6i6i6h6i6h")
BODY_SIZES = {
    HELLO: _HELLO.size,
    HELLO_ACK: _HELLO_ACK.size,
    SENSOR: _SENSOR.size,
    COMMAND: _COMMAND.size,
    STATUS: 0,
    STATUS_REPLY: _STATUS_REPLY.size,
    SET_STATE: _SET_STATE.size,
}


def crc16(data: bytes) -> int:
    """CRC-16/CCITT-FALSE of ``data``."""
    return binascii.crc_hqx(data, 0xFFFF)


def cobs_encode(data: bytes) -> bytes:
    """Consistent Overhead Byte Stuffing: ``data`` with no zero byte, one byte longer per 254 (at least one)."""
    out, block = bytearray(), bytearray()
    for b in data:
        if b == 0:
            out += bytes([len(block) + 1]) + block
            block.clear()
        else:
            block.append(b)
            if len(block) == 254:
                out += b"\xff" + block
                block.clear()
    out += bytes([len(block) + 1]) + block
    return bytes(out)


def cobs_decode(data: bytes) -> bytes | None:
    """The bytes ``cobs_encode`` made ``data`` from, or None for an invalid encoding."""
    out, i, n = bytearray(), 0, len(data)
    while i < n:
        code = data[i]
        i += 1
        if code == 0 or i + code - 1 > n or 0 in data[i : i + code - 1]:
            return None
        out += data[i : i + code - 1]
        i += code - 1
        if code != 0xFF and i < n:
            out.append(0)
    return bytes(out)


def encode_frame(kind: int, seq: int, body: bytes) -> bytes:
    """The frame of one message: COBS of ``kind``, ``seq`` (mod 2**16), ``body`` and their CRC, then 0x00."""
    p = struct.pack("<BH", kind, seq & 0xFFFF) + body
    return cobs_encode(p + struct.pack(">H", crc16(p))) + b"\x00"


@dataclass
class Counters:
    """What a receiver saw: good frames, and those it did not act on, by reason (``COUNTERS``)."""

    frames: int = 0
    corrupt: int = 0
    malformed: int = 0
    lost: int = 0
    duplicate: int = 0
    late: int = 0
    unexpected: int = 0

    def to_dict(self) -> dict:
        return {k: getattr(self, k) for k in COUNTERS}


@dataclass
class Sequence:
    """The sequence check: ``accept(seq)`` is True for a number after the last one accepted (mod 2**16, within
    half the range), counting the numbers skipped as lost; a repeat is a duplicate, an older one late."""

    counters: Counters
    last: int | None = None

    def accept(self, seq: int) -> bool:
        if self.last is None:
            self.last = seq
            return True
        d = (seq - self.last) & 0xFFFF
        if d == 0:
            self.counters.duplicate += 1
            return False
        if d >= 0x8000:
            self.counters.late += 1
            return False
        self.counters.lost += d - 1
        self.last = seq
        return True


@dataclass
class Decoder:
    """Bytes in, messages out: ``feed(data)`` returns the ``(kind, seq, body)`` of each good frame that ends in
    ``data``; corrupt and malformed frames (bad COBS, size, type or body length) are counted and dropped."""

    counters: Counters = field(default_factory=Counters)
    _buf: bytearray = field(default_factory=bytearray)

    def feed(self, data: bytes) -> list[tuple[int, int, bytes]]:
        out = []
        for b in data:
            if b:
                self._buf.append(b)
                continue
            raw, self._buf = bytes(self._buf), bytearray()
            if raw:
                m = self._frame(raw)
                if m is not None:
                    out.append(m)
        return out

    def _frame(self, raw: bytes) -> tuple[int, int, bytes] | None:
        c = self.counters
        p = cobs_decode(raw) if len(raw) <= MAX_PAYLOAD + 1 else None
        if p is None or len(p) < 5:
            c.malformed += 1
            return None
        if crc16(p[:-2]) != struct.unpack(">H", p[-2:])[0]:
            c.corrupt += 1
            return None
        kind, seq = struct.unpack("<BH", p[:3])
        body = p[3:-2]
        if BODY_SIZES.get(kind) != len(body):
            c.malformed += 1
            return None
        c.frames += 1
        return kind, seq, body


def format_fingerprint(fingerprint_line: str) -> bytes:
    """The 8 fingerprint bytes of a module: the SHA-256 of its recorded-options line (``fingerprint_line``)."""
    return hashlib.sha256(fingerprint_line.strip().encode("utf-8")).digest()[:FINGERPRINT_BYTES]


def fingerprint_header(fingerprint: bytes) -> str:
    """``sd_pil_config.h``: the fingerprint the target compares a handshake with."""
    words = ", ".join(f"0x{b:02x}" for b in fingerprint)
    return f"#define SD_FORMAT_FINGERPRINT {{{words}}}\n"


def sensor_body(pose_words, measured, feedforward=None) -> bytes:
    """A SENSOR body: six pose words, six measured counts, six feed-forward words (or none)."""
    ff = (0,) * 6 if feedforward is None else tuple(int(v) for v in feedforward)
    return _SENSOR.pack(*(int(v) for v in pose_words), *(int(v) for v in measured), *ff, feedforward is not None)


@dataclass
class Reply:
    """A COMMAND: the six command words, the saturated legs (bit i: leg i + 1), the target's counters, the
    six set-point words and the clock counts of its ``sd_tick`` (None: not measured)."""

    seq: int
    command: tuple
    saturated: int
    target: dict
    setpoint: tuple = ()
    clock: int | None = None


class LinkHost:
    """The host end of a link: ``handshake()`` then ``tick(...)`` per controller period.

    Args:
        write: sends bytes to the target.
        read: returns the bytes the target has sent within ``timeout`` seconds (``b""`` for none; raises
            ``EOFError`` when the target is gone).
        fingerprint: this host's format fingerprint (``format_fingerprint``).
    """

    def __init__(self, write: Callable[[bytes], None], read: Callable[[float], bytes], fingerprint: bytes):
        self.write, self.read, self.fingerprint = write, read, fingerprint
        self.counters = Counters()
        self.decoder = Decoder(self.counters)
        self.seq = 0
        self._pending: list[tuple[int, int, bytes]] = []

    def _await(self, kind: int, seq: int, timeout: float) -> bytes | None:
        end = time.monotonic() + timeout
        while True:
            while self._pending:
                k, s, body = self._pending.pop(0)
                if k == kind and s == seq:
                    return body
                if k == kind and ((seq - s) & 0xFFFF) < 0x8000:  # a reply to an earlier request, past its deadline
                    self.counters.late += 1
                else:
                    self.counters.unexpected += 1
            left = end - time.monotonic()
            if left <= 0:
                return None
            self._pending += self.decoder.feed(self.read(left))

    def handshake(self, timeout: float = 2.0) -> None:
        """Exchange versions and format fingerprints.

        Raises:
            FirmwareError: no answer in ``timeout`` s, or a target of another link version or format.
        """
        self.seq = (self.seq + 1) & 0xFFFF
        self.write(encode_frame(HELLO, self.seq, _HELLO.pack(VERSION, self.fingerprint)))
        body = self._await(HELLO_ACK, self.seq, timeout)
        if body is None:
            raise FirmwareError(FirmwareError.LINK_SILENT.format(what="the handshake", timeout=timeout))
        version, theirs, accepted = _HELLO_ACK.unpack(body)
        if version != VERSION or theirs != self.fingerprint or not accepted:
            raise FirmwareError(
                FirmwareError.LINK_REFUSED.format(
                    version=version, fingerprint=theirs.hex(), our_version=VERSION, ours=self.fingerprint.hex()
                )
            )

    def send_tick(self, pose_words, measured, feedforward=None, seq: int | None = None) -> int:
        """Send one SENSOR frame with the next sequence number (or with ``seq``, a replay: the host's own count
        unchanged); returns the number sent."""
        if seq is None:
            self.seq = seq = (self.seq + 1) & 0xFFFF
        self.write(encode_frame(SENSOR, seq, sensor_body(pose_words, measured, feedforward)))
        return seq

    def reply(self, seq: int, timeout: float) -> Reply | None:
        """The COMMAND answering ``seq`` within ``timeout`` s, or None (counted lost)."""
        body = self._await(COMMAND, seq, timeout)
        if body is None:
            self.counters.lost += 1
            return None
        v = _COMMAND.unpack(body)
        n = 7 + len(COUNTERS)
        counts = None if v[-1] == NOT_MEASURED else v[-1]
        return Reply(seq, v[:6], v[6], dict(zip(COUNTERS, v[7:n], strict=True)), v[n : n + 6], counts)

    def status(self, timeout: float = 2.0) -> dict:
        """The target's counters and ``stack_bytes``, the most stack it has used since reset (None: not measured).

        Raises:
            FirmwareError: no answer in ``timeout`` s.
        """
        return self._status(STATUS, b"", "a status request", timeout)

    def set_state(self, integ, prev, dfilt, setpoint, vfilt, timeout: float = 2.0) -> dict:
        """Set the target's controller state (six words each, ``sd_state``'s fields); returns its status.

        Raises:
            FirmwareError: no answer in ``timeout`` s.
        """
        words = [int(v) for part in (integ, prev, dfilt, setpoint, vfilt) for v in part]
        return self._status(SET_STATE, _SET_STATE.pack(*words), "the controller state", timeout)

    def _status(self, kind: int, body: bytes, what: str, timeout: float) -> dict:
        self.write(encode_frame(kind, self.seq, body))  # the last tick's number: the ticks' sequence goes on
        body = self._await(STATUS_REPLY, self.seq, timeout)
        if body is None:
            raise FirmwareError(FirmwareError.LINK_SILENT.format(what=what, timeout=timeout))
        v = _STATUS_REPLY.unpack(body)
        return {**dict(zip(COUNTERS, v[:-1], strict=True)), "stack_bytes": None if v[-1] == NOT_MEASURED else v[-1]}

    def tick(self, pose_words, measured, feedforward=None, timeout: float = 1.0) -> Reply | None:
        """One controller period: the sensor frame out, the command frame back (None when it did not come)."""
        return self.reply(self.send_tick(pose_words, measured, feedforward), timeout)


def pipe_reader(fd: int) -> Callable[[float], bytes]:
    """A ``LinkHost`` reader on a file descriptor (a pipe or a socket's ``fileno()``)."""

    def read(timeout: float) -> bytes:
        ready, _, _ = select.select([fd], [], [], max(timeout, 0.0))
        if not ready:
            return b""
        data = os.read(fd, 4096)
        if not data:
            raise EOFError("the target closed the link")
        return data

    return read
