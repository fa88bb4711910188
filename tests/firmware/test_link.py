"""The PIL link: the Python framing (``firmware.link``) and the target's C (``firmware/target/sd_link.c``,
``sd_pil.c``, compiled for the host with -Werror and run behind a pipe) agree byte for byte; the target acts on
each good, new sensor frame exactly as ``sd_tick`` does, and never on a corrupt, malformed, lost-and-found,
duplicated or late one, which it counts."""

import os
import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from stewart_drake.api.firmware import controller_config, machine_format
from stewart_drake.core.geometry import load_platform
from stewart_drake.errors import FirmwareError
from stewart_drake.firmware import link
from stewart_drake.firmware.fingerprint import DEFAULTS, stamp
from stewart_drake.firmware.generate import generate
from stewart_drake.firmware.module import TickRunner, compile_generated
from stewart_drake.firmware.target_build import build_host
from tests.firmware.firmware_cache import firmware_cache  # noqa: F401

CC = shutil.which("cc") or shutil.which("gcc")
needs_cc = pytest.mark.skipif(CC is None, reason="no host C compiler (cc or gcc)")
# a reply from a process on the same machine comes in well under this; a frame the target drops gets none
REPLY_S = 5.0
SILENT_S = 0.3


def test_crc16_is_ccitt_false():
    # the CRC catalogue's check value of CRC-16/CCITT-FALSE (poly 0x1021, init 0xFFFF) over "123456789"
    assert link.crc16(b"123456789") == 0x29B1


@pytest.mark.parametrize("n", [0, 1, 253, 254, 255, 600])
def test_cobs_round_trip(n):
    rng = np.random.default_rng(n)
    data = bytes(rng.integers(0, 4, n, dtype=np.uint8))  # many zeros
    enc = link.cobs_encode(data)
    assert 0 not in enc
    assert len(enc) <= n + n // 254 + 1  # COBS's overhead: one byte per 254, at least one
    assert link.cobs_decode(enc) == data


def test_cobs_rejects_a_code_past_the_end():
    assert link.cobs_decode(b"\x05ab") is None


@pytest.fixture(scope="module")
def target(tmp_path_factory):
    """(the host-built PIL program, the module's files, a TickRunner on the same module)."""
    if CC is None:
        pytest.skip("no host C compiler (cc or gcc)")
    p = load_platform("utn-dynamic")
    g = generate(p, controller_config(p, machine_format(p, {})[1]))
    files = stamp(g.files, dict(DEFAULTS))
    exe = build_host(files, tmp_path_factory.mktemp("pil"), compiler=CC)
    return exe, files, g


def fingerprint(files):
    return link.format_fingerprint(files["sd_firmware.h"].splitlines()[0])


class Pipe:
    def __init__(self, exe):
        self.p = subprocess.Popen([str(exe)], stdin=subprocess.PIPE, stdout=subprocess.PIPE, bufsize=0)
        self.read = link.pipe_reader(self.p.stdout.fileno())

    def write(self, data: bytes) -> None:
        self.p.stdin.write(data)

    def close(self):
        self.p.stdin.close()
        self.p.wait(timeout=10)
        self.p.stdout.close()


@pytest.fixture
def pipe(target):
    p = Pipe(target[0])
    yield p
    p.close()


def ticks(n, seed=0):
    rng = np.random.default_rng(seed)
    return rng.integers(-60, 60, (n, 6)), rng.integers(40_000, 60_000, (n, 6)), rng.integers(-900, 900, (n, 6))


def reference(g, pose, measured, ff):
    """The commands ``sd_tick`` gives for these ticks, called directly (cffi)."""
    r = TickRunner(compile_generated(g))
    return [r.tick(pose[k], measured[k], ff[k]) for k in range(len(pose))]


@needs_cc
def test_ticks_through_the_pipe_equal_sd_tick(target, pipe):
    exe, files, g = target
    host = link.LinkHost(pipe.write, pipe.read, fingerprint(files))
    host.handshake(REPLY_S)
    pose, measured, ff = ticks(40)
    want = reference(g, pose, measured, ff)
    for k in range(40):
        r = host.tick(pose[k], measured[k], ff[k], timeout=REPLY_S)
        assert r is not None
        assert list(r.command) == list(want[k]), k
    assert r.target == {**dict.fromkeys(link.COUNTERS, 0), "frames": 41}
    assert host.counters.to_dict() == {**dict.fromkeys(link.COUNTERS, 0), "frames": 41}


@needs_cc
def test_bad_frames_are_counted_and_never_acted_on(target, pipe):
    exe, files, g = target
    host = link.LinkHost(pipe.write, pipe.read, fingerprint(files))
    host.handshake(REPLY_S)
    pose, measured, ff = ticks(4, seed=1)
    want = reference(g, pose, measured, ff)  # the commands of the four good ticks, in order
    got = [host.tick(pose[0], measured[0], ff[0], timeout=REPLY_S)]
    s0 = host.seq

    # corrupt: one bit of the body flipped after framing (the CRC no longer matches)
    frame = bytearray(link.encode_frame(link.SENSOR, s0 + 1, link.sensor_body(pose[1], measured[1], ff[1])))
    frame[10] ^= 0x04
    pipe.write(bytes(frame))
    assert host.reply(s0 + 1, SILENT_S) is None
    # malformed: a good CRC over a body one byte short, and bytes that are no COBS encoding
    pipe.write(link.encode_frame(link.SENSOR, s0 + 1, link.sensor_body(pose[1], measured[1], ff[1])[:-1]))
    pipe.write(b"\x09\x01\x00")
    assert host.reply(s0 + 1, SILENT_S) is None
    # lost: seq s0 + 1 never arrives; s0 + 2 is acted on
    host.seq += 1
    got.append(host.tick(pose[1], measured[1], ff[1], timeout=REPLY_S))
    # duplicate: s0 + 2 again (a tick the target has acted on), with other data
    host.send_tick(pose[3], measured[3], ff[3], seq=s0 + 2)
    assert host.reply(s0 + 2, SILENT_S) is None
    # late: s0 + 1 arrives after s0 + 2
    host.send_tick(pose[3], measured[3], ff[3], seq=s0 + 1)
    assert host.reply(s0 + 1, SILENT_S) is None
    got.append(host.tick(pose[2], measured[2], ff[2], timeout=REPLY_S))
    got.append(host.tick(pose[3], measured[3], ff[3], timeout=REPLY_S))
    assert all(r is not None for r in got)
    assert [list(r.command) for r in got] == [list(w) for w in want]
    assert got[-1].target == {
        "frames": 1 + 4 + 2,  # the handshake, the four ticks, the duplicate and the late one (good CRCs)
        "corrupt": 1,
        "malformed": 2,
        "lost": 1,
        "duplicate": 1,
        "late": 1,
        "unexpected": 0,
    }


@needs_cc
def test_an_overlong_frame_is_malformed_and_the_next_one_is_read(target, pipe):
    exe, files, g = target
    host = link.LinkHost(pipe.write, pipe.read, fingerprint(files))
    host.handshake(REPLY_S)
    pipe.write(b"\x01" * (3 * link.MAX_PAYLOAD) + b"\x00")  # longer than any frame: no delimiter lost in it
    pose, measured, ff = ticks(1, seed=4)
    r = host.tick(pose[0], measured[0], ff[0], timeout=REPLY_S)
    assert r is not None and list(r.command) == list(reference(g, pose, measured, ff)[0])
    assert (r.target["malformed"], r.target["frames"]) == (1, 2)


@needs_cc
def test_status_reports_the_counters_without_breaking_the_tick_sequence(target, pipe):
    exe, files, g = target
    host = link.LinkHost(pipe.write, pipe.read, fingerprint(files))
    host.handshake(REPLY_S)
    pose, measured, ff = ticks(2, seed=5)
    first = host.tick(pose[0], measured[0], ff[0], timeout=REPLY_S)
    st = host.status(REPLY_S)
    assert st == {**first.target, "frames": 3, "stack_bytes": None}  # the host build does not paint its stack
    second = host.tick(pose[1], measured[1], ff[1], timeout=REPLY_S)
    assert second.target == {**first.target, "frames": 4}  # nothing lost between the ticks
    assert list(second.command) == list(reference(g, pose, measured, ff)[1])


@needs_cc
def test_a_reply_after_its_deadline_is_late_on_the_host(target, pipe):
    exe, files, g = target
    host = link.LinkHost(pipe.write, pipe.read, fingerprint(files))
    host.handshake(REPLY_S)
    pose, measured, ff = ticks(2, seed=2)
    first = host.send_tick(pose[0], measured[0], ff[0])
    assert host.reply(first, 0.0) is None  # the deadline passed before the target answered
    r = host.tick(pose[1], measured[1], ff[1], timeout=REPLY_S)
    assert r is not None and r.seq == first + 1
    assert (host.counters.lost, host.counters.late) == (1, 1)


@needs_cc
def test_a_handshake_of_another_format_is_refused_and_ticks_are_not_acted_on(target, pipe):
    exe, files, g = target
    other = bytes(b ^ 0xFF for b in fingerprint(files))
    host = link.LinkHost(pipe.write, pipe.read, other)
    with pytest.raises(FirmwareError, match=r"refused the handshake of this host \(version 2, fingerprint "):
        host.handshake(REPLY_S)
    pose, measured, ff = ticks(1)
    assert host.tick(pose[0], measured[0], ff[0], timeout=SILENT_S) is None
    host.fingerprint = fingerprint(files)
    host.handshake(REPLY_S)
    r = host.tick(pose[0], measured[0], ff[0], timeout=REPLY_S)
    assert r is not None and r.target["unexpected"] == 1


def test_host_decoder_counts_what_it_drops():
    d = link.Decoder()
    good = link.encode_frame(link.COMMAND, 7, bytes(link.BODY_SIZES[link.COMMAND]))
    bad = bytearray(good)
    bad[3] ^= 0x10
    out = d.feed(bytes(bad) + b"\x00\x00" + b"\x02\x00" + good)
    assert out == [(link.COMMAND, 7, bytes(link.BODY_SIZES[link.COMMAND]))]
    assert d.counters.to_dict() == {**dict.fromkeys(link.COUNTERS, 0), "frames": 1, "corrupt": 1, "malformed": 1}


def test_sequence_wraps_at_16_bits():
    c = link.Counters()
    s = link.Sequence(c, last=0xFFFE)
    assert s.accept(0xFFFF) and s.accept(0x0001)
    assert not s.accept(0xFFFF)
    assert (c.lost, c.late) == (1, 1)


def test_pipe_reader_reports_the_end():
    r, w = os.pipe()
    os.close(w)
    with pytest.raises(EOFError):
        link.pipe_reader(r)(1.0)
    os.close(r)


def test_the_docs_tables_are_the_protocol():
    text = (Path(__file__).parents[2] / "docs" / "pil-link.md").read_text()
    types = dict((int(n), name) for n, name in re.findall(r"^\| (\d) `(\w+)` \|", text, re.M))
    names = ("HELLO", "HELLO_ACK", "SENSOR", "COMMAND", "STATUS", "STATUS_REPLY", "SET_STATE")
    assert types == {getattr(link, n): n for n in names}
    sizes = {"u8": 1, "i16": 2, "i32": 4, "u32": 4}
    for n, name in types.items():  # the body a row lists, field by field, has the size the code sends
        row = re.search(rf"^\| {n} `{name}` \|[^|]*\|([^|]*)\|", text, re.M).group(1)
        fields = re.findall(r"`(u8|i16|i32|u32)(?:\[(\d)\])?`", row)
        assert sum(sizes[t] * int(k or 1) for t, k in fields) == link.BODY_SIZES[n], name
    counters = re.findall(r"^\| `(\w+)` \| (?:decoded|has|is|\(|repeats|carries)", text, re.M)
    assert tuple(counters) == link.COUNTERS


def test_a_silent_target_is_one_line_naming_the_wait():
    host = link.LinkHost(lambda data: None, lambda timeout: b"", bytes(link.FINGERPRINT_BYTES))
    with pytest.raises(FirmwareError, match=r"^PIL link: no answer to the handshake within 0\.05 s$"):
        host.handshake(0.05)
    with pytest.raises(FirmwareError, match=r"^PIL link: no answer to a status request within 0\.05 s$"):
        host.status(0.05)
