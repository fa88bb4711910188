"""Processor in the loop: the fixed-point law whose tick is computed by the firmware on a target (``pil.target``:
the Cortex-M4 build in QEMU, or a board on a serial port), one SENSOR/COMMAND exchange of the link
(``firmware.link``) per tick, in lock step with the plant.

The host does what ``sd_host_tick`` does on its side of a tick (``firmware.sil``): the reference pose's words,
the leg lengths rounded to sensor counts, the feed-forward words, and, from the reply, the command
(``word / 32768 · range``), the set-point (``word · LSB``) and the saturated legs, with the same IEEE
operations: the logs equal the host-C loop's bit for bit. The controller's state lives on the target: the
state the loop starts from (``initial_pid_state``, a held pose) is sent once before the first tick
(``SET_STATE``); the loop's own copy then stays that initial state.

A tick whose command does not come within ``pil.timeout`` (a frame lost, corrupted, delayed: the link's
counters say which) gets the reaction ``pil.on_fault``: ``hold`` keeps the last command, ``stop`` commands
zero force from then on without asking the target again. ``pil.fault`` injects such faults into the SENSOR
frames the host sends (``PilFaults``).
"""

from __future__ import annotations

import struct
import time

import numpy as np

from stewart_drake.control.gains import ControllerConfig
from stewart_drake.control.laws import FixedPointLaw
from stewart_drake.core.geometry import Platform
from stewart_drake.errors import FirmwareError
from stewart_drake.firmware.fingerprint import DEFAULTS, platform_hash, stamp
from stewart_drake.firmware.generate import generate
from stewart_drake.firmware.link import (
    SENSOR,
    LinkHost,
    cobs_encode,
    crc16,
    encode_frame,
    format_fingerprint,
    sensor_body,
)
from stewart_drake.firmware.pil_target import INSTRUCTIONS_PER_COUNT, QEMU_LINKS, open_target
from stewart_drake.fixedpoint.generic import pose_words
from stewart_drake.spec.machine import PilSpec

HANDSHAKE_S = 30.0  # QEMU boots in about a second; a loaded machine, or a board being reset, may take longer
# the stated cycle model of the Cortex-M4 estimate: one cycle an instruction (most Thumb-2 ALU, multiply and
# multiply-accumulate instructions; loads, taken branches and divisions take 2-12, so it is a lower bound),
# no memory wait states (the AN386's SSRAM; an STM32F405's flash at 168 MHz hides its 5 through the ART cache)
M4_CYCLES_PER_INSTRUCTION = 1.0
M4_CLOCKS_HZ = {"stm32f405_168mhz": 168e6, "an386_25mhz": 25e6}


def program_module(platform: Platform, config: ControllerConfig, generated=None) -> dict:
    """The generated module (name -> text) the target runs for ``platform`` and ``config``, with its options
    recorded (``fingerprint.stamp``: the link's handshake compares their fingerprint); ``generated``: the
    ``generate(platform, config)`` result if the caller has it."""
    g = generated if generated is not None else generate(platform, config)
    ik, t = config.ik_format, config.timing
    options = {**DEFAULTS, "platform": platform.name, "platform_hash": platform_hash(platform)}
    options |= {"word_bits": ik.word_bits, "length_lsb": ik.length_lsb, "trig": ik.trig}
    options |= {
        "convention": config.convention,
        "rate": 1.0 / t.sample_period,
        "sensor_resolution": t.sensor_resolution,
    }
    return stamp(g.files, options)


class PilFaults:
    """The faults ``pil.fault`` injects: at the ticks it names, or each tick with its rate (drawn from
    ``seed``: the same run, the same faults)."""

    def __init__(self, spec: PilSpec, seed: int):
        self.kind, self.rate, self.ticks = spec.fault_plan() if spec.fault else (None, None, ())
        self.rng = np.random.default_rng(seed)

    def at(self, tick: int) -> str | None:
        """The fault of tick ``tick`` (from 1), or None."""
        if self.kind is None:
            return None
        hit = self.rng.random() < self.rate if self.rate is not None else tick in self.ticks
        return self.kind if hit else None


class PilLaw(FixedPointLaw):
    """``FixedPointLaw`` whose ``step`` is one link exchange with the firmware on ``spec.target``
    (see the module's docstring); ``close()`` ends the link (QEMU stopped). ``seed``: the faults' draws."""

    def __init__(self, platform: Platform, config: ControllerConfig | None, spec: PilSpec, seed: int = 0):
        super().__init__(platform, config)
        if not spec.target:
            raise ValueError("PilLaw without pil.target")  # a caller's bug: the spec chooses this law
        self.spec, self.faults = spec, PilFaults(spec, seed)
        self.tick_count = 0  # before the handshake: a target gone during it is reported at tick 0
        self.generated = generate(self.platform, self.config)
        self.files = program_module(self.platform, self.config, self.generated)
        self.target = open_target(spec.target, self.files)
        try:
            fp = format_fingerprint(self.files["sd_firmware.h"].splitlines()[0])
            self.host = LinkHost(self.target.write, self.target.read, fp)
            self._guard(self.host.handshake, HANDSHAKE_S)
        except BaseException:
            self.target.close()
            raise
        self._words: dict[bytes, np.ndarray] = {}
        self._state_sent = False
        self._last = None  # the last (command, setpoint, saturated) applied
        self._delayed: bytes | None = None
        # each tick with a command: its number (from 1), round trip (s, SENSOR written to COMMAND read) and the
        # clock counts of the target's sd_tick (None: no clock)
        self.answered: list[int] = []
        self.latencies: list[float] = []
        self.clock_counts: list[int | None] = []
        self.events: list[dict] = []  # each injected fault and each tick without a command
        self.stopped_at: int | None = None

    def _guard(self, call, *args):
        try:
            return call(*args)
        except EOFError:
            why = self.target.ended()
            raise FirmwareError(
                FirmwareError.PIL_GONE.format(tick=self.tick_count) + (f" ({why})" if why else "")
            ) from None

    def prime(self, poses) -> None:
        """The pose words of ``(n, 6)`` reference poses in one batch (speed only; ``CFixedPointLaw.prime``)."""
        poses = np.ascontiguousarray(np.asarray(poses, dtype=float).reshape(-1, 6))
        for q, w in zip(poses, pose_words(poses, self.config.ik_format)):
            self._words[q.tobytes()] = w

    def initial_pid_state(self, lengths, forces, rates=None):
        """``FixedPointLaw``'s, sent to the target before the next tick; the command held until the first reply
        comes from its integrator."""
        pid = super().initial_pid_state(lengths, forces, rates)
        self._state_sent = False
        self._last = (self.command_from_integrator(pid[:6]), pid[18:24] * self.config.ik_format.length_lsb, np.zeros(6))
        return pid

    def step(self, state, reference, measured, feedforward=None):
        """One tick on the target (see ``FixedPointLaw.step``); the returned state is the one given."""
        self.tick_count += 1
        if self.stopped_at is not None:
            return np.zeros(6), self._last[1], state, np.zeros(6)
        if not self._state_sent:
            st = np.asarray(state, dtype=np.int64)
            self._guard(self.host.set_state, st[:6], st[6:12], st[12:18], st[18:24], st[24:30], self.spec.timeout)
            self._state_sent = True
        ref = np.ascontiguousarray(reference, dtype=float)
        words = self._words.get(ref.tobytes())
        if words is None:
            words = pose_words(ref, self.config.ik_format)
        t = self.timing
        counts = np.rint(np.asarray(measured, dtype=float) / float(t.sensor_resolution))
        if not np.all(np.abs(counts) <= 2147483647.0):
            raise FirmwareError(FirmwareError.SENSOR_COUNTS.format(value=np.asarray(measured).tolist()))
        ff = None
        if feedforward is not None:
            ff = np.clip(np.rint(np.asarray(feedforward, dtype=float) / t.command_range * 32768.0), -32768, 32767)
        sent = time.perf_counter()
        reply = self._guard(self._exchange, words, counts, ff)
        if reply is None:
            return self._react(state)
        self.latencies.append(time.perf_counter() - sent)
        self.answered.append(self.tick_count)
        self.clock_counts.append(reply.clock)
        command = np.asarray(reply.command, dtype=float) / 32768.0 * float(t.command_range)
        setpoint = np.asarray(reply.setpoint, dtype=float) * float(self.config.ik_format.length_lsb)
        saturated = np.array([(reply.saturated >> i) & 1 for i in range(6)], dtype=float)
        self._last = (command, setpoint, saturated)
        return command, setpoint, state, saturated

    def _exchange(self, words, counts, ff):
        """The SENSOR frame out (with this tick's fault) and its COMMAND back, or None."""
        host, k = self.host, self.tick_count
        fault = self.faults.at(k)
        host.seq = seq = (host.seq + 1) & 0xFFFF
        body = sensor_body(words, counts, ff)
        frame = encode_frame(SENSOR, seq, body)
        if fault is not None:
            self.events.append({"tick": k, "fault": fault})
        if fault == "corrupt":  # one bit of the body flipped after its CRC was computed: a CRC-16 always sees it
            p = struct.pack("<BH", SENSOR, seq) + body
            frame = cobs_encode(p[:3] + bytes([p[3] ^ 1]) + p[4:] + struct.pack(">H", crc16(p))) + b"\x00"
        if fault not in ("drop", "delay"):
            host.write(frame)
        if fault == "duplicate":
            host.write(frame)
        if self._delayed is not None:  # the frame held back a tick: it arrives after this one
            host.write(self._delayed)
            self._delayed = None
        if fault == "delay":
            self._delayed = frame
        return host.reply(seq, self.spec.timeout)

    def _react(self, state):
        """A tick without a command: ``pil.on_fault``'s reaction."""
        self.events.append({"tick": self.tick_count, "no_command": self.spec.on_fault})
        command, setpoint, saturated = self._last
        if self.spec.on_fault == "stop":
            self.stopped_at = self.tick_count
            command = np.zeros(6)
        return command, setpoint, state, saturated

    def report(self) -> dict:
        """The link's counters (host and target), the faults and reactions, the round trips (and ``per_tick``:
        each answered tick's number, round trip and clock counts), and
        ``sd_tick``'s measured time: in QEMU instructions (from the clock counts, ``INSTRUCTIONS_PER_COUNT``)
        worst and mean over the run and the Cortex-M4 cycles of the stated model, on a board the cycles its
        SysTick counted; their share of the period at each of ``M4_CLOCKS_HZ``, beside the DSP56800E's estimate
        of the generated tick (``GeneratedFirmware.tick_cycles``) at its clock (None: no clock, the host build)."""
        target = None
        if self.stopped_at is None:
            try:
                target = self.host.status(self.spec.timeout)
            except (FirmwareError, EOFError):
                target = None
        counts = [c for c in self.clock_counts if c is not None]
        timing = None
        if counts:
            T, dsp = self.timing.sample_period, float(self.generated.tick_cycles)
            if self.spec.target in QEMU_LINKS:  # counts of 40 instructions (-icount), cycles by the stated model
                worst, mean = max(counts) * INSTRUCTIONS_PER_COUNT, float(np.mean(counts)) * INSTRUCTIONS_PER_COUNT
                cycles, resolution, cpi = (
                    worst * M4_CYCLES_PER_INSTRUCTION,
                    INSTRUCTIONS_PER_COUNT,
                    M4_CYCLES_PER_INSTRUCTION,
                )
            else:  # a board: SysTick counts the core's own clock cycles
                worst, mean, cycles, resolution, cpi = None, None, float(max(counts)), 1, None
            timing = {
                "instructions_worst": worst,
                "instructions_mean": mean,
                "instructions_resolution": resolution,
                "cortex_m4_cycles_worst": cycles,
                "cortex_m4_cycles_per_instruction": cpi,
                "period_share": {k: cycles / hz / T for k, hz in M4_CLOCKS_HZ.items()},
                "dsp56800e_cycles": dsp,
                "dsp56800e_clock_hz": self.timing.clock_hz,
                "dsp56800e_period_share": dsp / self.timing.clock_hz / T,
            }
        return {
            "target": self.spec.target,
            "ticks": self.tick_count,
            "fault": self.spec.fault,
            "on_fault": self.spec.on_fault,
            "events": self.events,
            "ticks_without_command": sum(1 for e in self.events if "no_command" in e),
            "stopped_at_tick": self.stopped_at,
            "host_counters": self.host.counters.to_dict(),
            "target_counters": target,
            "timing": timing,
            "round_trip_s": None
            if not self.latencies
            else {
                "median": float(np.median(self.latencies)),
                "p99": float(np.percentile(self.latencies, 99)),
                "max": float(np.max(self.latencies)),
            },
            "per_tick": {"tick": self.answered, "round_trip_s": self.latencies, "clock_counts": self.clock_counts},
        }

    def close(self) -> None:
        """End the link (QEMU stopped; the serial port closed)."""
        self.target.close()
