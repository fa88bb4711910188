"""The leg-position PID laws as plain classes: one controller tick, no Drake.

A law maps (state, reference, measured, feed-forward) to (command, set-point, new state, saturated):

1. the measured leg lengths are quantised to the sensor resolution (integer counts, as the firmware's
   position words);
2. the leg set-points come from the inverse kinematics of the reference pose (fixed point: the
   ``fixedpoint`` package's Q15 IK, integer millimetres; float: the closed-form IK in float64);
3. a PID per leg (fixed point: Q15 gains, Q31 accumulators, saturating intrinsics; float: the same law in
   float64) plus the model-based force feed-forward word, with command saturation and anti-windup by
   conditional integration.

The PID state is a ``(30,)`` float vector: integrator, previous measurement, its filtered difference,
previous set-point, its filtered difference (6 each), in the law's own number format (newtons and metres
for ``FloatLaw``, the firmware's integer words for ``FixedPointLaw``). ``STATUS`` is the layout of the
status a controller reports over a run (``drake.systems.ControllerSystem``).
"""

from __future__ import annotations

import numpy as np

from stewart_drake.control.gains import DIFF_SHIFT, ControllerConfig, FixedGains, counts_per_lsb
from stewart_drake.core.geometry import Platform
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.errors import FirmwareError
from stewart_drake.fixedpoint import fixed_point_leg_lengths, q15

# Layout of a controller's ``status``: tick count, time of the last tick, time of the last release of a
# command, saturated ticks in total, then per leg (6) saturated ticks.
STATUS = ("ticks", "last_tick_time", "last_release_time", "saturations") + tuple(
    f"saturations_{i}" for i in range(1, 7)
)
CONTROLLER_KINDS = ("fixed", "float")


def check_no_sensor_gains(platform: Platform) -> None:
    """Refuse a platform whose sensors have gains (``legs.length_gain`` ≠ 1): the laws, the firmware and the
    simulated sensor model an offset per leg, not a scale."""
    if platform.has_sensor_gains:
        raise FirmwareError(
            FirmwareError.SENSOR_GAINS.format(name=platform.name, gains=[float(g) for g in platform.length_gain])
        )


class FloatLaw:
    """The PID law in float64 (SI) for ``platform`` with ``config`` (default: designed for the platform;
    the timing is refused if infeasible)."""

    def __init__(self, platform: Platform, config: ControllerConfig | None = None):
        self.platform = platform
        self.config = config or ControllerConfig.for_platform(platform)
        self.timing = self.config.timing.check()
        self._limit = self.timing.command_range
        check_no_sensor_gains(platform)
        self._offset = platform.length_offset  # (6,) m: joint-to-joint length = reading + offset
        self._cache: dict[bytes, np.ndarray] = {}
        # (6,) metres added to every set-point (None: nothing). A probe, not a feature: a constant offset
        # from t = 0 is a set-point step on the legs, whose length response measures the loop's gain from
        # set-point errors to length errors (``drake.simulation.setpoint_step_gain``).
        self.setpoint_offset = None

    def quantise(self, L):
        r = self.timing.sensor_resolution
        return np.round(np.asarray(L) / r) * r

    def prime(self, poses) -> None:
        """Evaluate the IK for ``(n, 6)`` poses in one batch and remember the results, so that a tick whose
        reference is bit-identical to one of them looks it up (same numbers: the IK is elementwise over
        poses). A speed-up only; a miss computes the IK for that pose."""
        poses = np.ascontiguousarray(np.asarray(poses, dtype=float).reshape(-1, 6))
        for q, L in zip(poses, leg_lengths(self.platform, poses, self.config.convention)):
            self._cache[q.tobytes()] = L

    def setpoints(self, ref) -> np.ndarray:
        """``(..., 6)`` leg set-points (m) of the poses ``ref`` (..., 6) (one pose from the primed cache, else
        computed), plus the probe's offset: the one home of that rule (the compiled loop's table is this of its
        ticks' poses, ``firmware.loop_kernel``)."""
        ref = np.ascontiguousarray(ref, dtype=float)
        sp = self._cache.get(ref.tobytes())
        if sp is None:
            sp = leg_lengths(self.platform, ref, self.config.convention)
        return sp if self.setpoint_offset is None else sp + self.setpoint_offset

    def initial_pid_state(self, lengths, forces, rates=None):
        """PID state holding ``lengths`` (m) with integrator ``forces`` (N), legs moving at ``rates`` (m/s)."""
        lengths = np.asarray(lengths, float)
        d = np.zeros(6) if rates is None else np.asarray(rates, float) * self.timing.sample_period
        m = self.quantise(lengths - d) + self._offset
        L = lengths + self._offset
        return np.concatenate([np.clip(forces, -self._limit, self._limit), m, d, L - d, d])

    def command_from_integrator(self, integ, ff=None):
        """The command (N) of the integrator alone plus the feed-forward ``ff`` (N), saturated."""
        u = np.asarray(integ, dtype=float) + (0.0 if ff is None else np.asarray(ff, dtype=float))
        return np.clip(u, -self._limit, self._limit)

    def step(self, state, reference, measured, feedforward=None):
        """One tick: ``(command (6,) N, set-point (6,) m, new PID state (30,), saturated (6,) 0/1)`` for the
        PID ``state``, the ``reference`` pose (6,), the true leg lengths ``measured`` (6,) m and the force
        feed-forward ``feedforward`` (6,) N (None: none)."""
        g, T, lim = self.config.gains, self.timing.sample_period, self._limit
        sp = self.setpoints(reference)
        m = self.quantise(measured) + self._offset  # readings -> joint-to-joint lengths
        st = np.asarray(state, dtype=float)
        integ, prev, dfilt, sp_prev, vfilt = st[:6], st[6:12], st[12:18], st[18:24], st[24:]  # views, not np.split's
        e = sp - m
        dfilt = dfilt + g.derivative_filter * ((m - prev) - dfilt)
        vfilt = vfilt + g.feedforward_filter * ((sp - sp_prev) - vfilt)
        u_raw = g.kp * e + integ - g.kd / T * dfilt + g.kv / T * vfilt
        if feedforward is not None:
            u_raw = u_raw + np.asarray(feedforward, dtype=float)
        u = np.minimum(np.maximum(u_raw, -lim), lim)  # np.clip's numbers, without its wrapper's cost per tick
        saturated = u_raw != u
        # anti-windup: integrate unless the output is saturated and the error pushes further into it
        grow = ~((u_raw > lim) & (e > 0) | (u_raw < -lim) & (e < 0))
        integ = np.where(grow, np.minimum(np.maximum(integ + g.ki * T * e, -lim), lim), integ)
        return u, sp, np.concatenate([integ, m, dfilt, sp, vfilt]), saturated.astype(float)


class FixedPointLaw:
    """The PID law in the firmware's fixed-point arithmetic (bit-exact Q15/Q31 intrinsics): Q15 IK
    (integer mm), Q15 gains (``FixedGains``), Q31 accumulators."""

    def __init__(self, platform: Platform, config: ControllerConfig | None = None):
        self.platform = platform
        self.config = config or ControllerConfig.for_platform(platform)
        self.timing = self.config.timing.check()
        self.gains = FixedGains.from_si(self.config.gains, self.timing)
        self._counts_per_lsb = counts_per_lsb(self.config)
        check_no_sensor_gains(platform)
        # legs.length_offset in sensor counts: the firmware adds them to the readings (``generate.offset_counts``)
        self._offset_counts = np.round(platform.length_offset / self.timing.sensor_resolution).astype(np.int64)
        g = self.gains
        self._alphas = np.array([[g.alpha], [g.alpha_ff]], dtype=np.int64)
        self._mantissas = np.array([[k.mantissa] for k in (g.kp, g.kd, g.kv, g.ki)], dtype=np.int64)
        self._shifts = np.array([[k.shift] for k in (g.kp, g.kd, g.kv, g.ki)], dtype=np.int64)  # >= 0 (``q15_gain``)
        self._cache: dict[bytes, np.ndarray] = {}
        self.cache_misses = 0

    def prime(self, poses) -> None:
        """Evaluate the fixed-point IK for ``(n, 6)`` poses in one batch and remember the results, so
        that a tick whose reference is bit-identical to one of them looks it up (same words: the IK is
        elementwise). A speed-up only; a miss computes the IK for that pose."""
        poses = np.ascontiguousarray(np.asarray(poses, dtype=float).reshape(-1, 6))
        words = self.ik_words(poses)
        for q, w in zip(poses, words):
            self._cache[q.tobytes()] = w

    def ik_words(self, poses) -> np.ndarray:
        """``(..., 6)`` int64 set-point words (units of the IK's length LSB) for ``(..., 6)`` poses."""
        return fixed_point_leg_lengths(
            self.platform, poses, self.config.ik_format, self.config.convention, return_words=True
        )

    def quantise(self, L) -> np.ndarray:
        """Sensor counts (int64) of true lengths ``L`` (metres), rounded to nearest."""
        return np.round(np.asarray(L, dtype=float) / self.timing.sensor_resolution).astype(np.int64)

    def setpoint_words(self, ref) -> np.ndarray:
        """``(6,)`` int64 set-point words of the pose ``ref`` (from the primed cache or computed)."""
        ref = np.ascontiguousarray(ref, dtype=float)
        w = self._cache.get(ref.tobytes())
        if w is None:
            self.cache_misses += 1
            w = self.ik_words(ref)
        return w

    def initial_pid_state(self, lengths, forces, rates=None):
        """PID state words holding ``lengths`` (m) with integrator ``forces`` (N), legs moving at ``rates``
        (m/s): the previous measurement and set-point one sample back, both difference filters at the
        per-sample difference (counts·2^DIFF_SHIFT)."""
        frac = np.clip(np.asarray(forces) / self.timing.command_range, -1.0, 1.0 - 2.0**-31)
        integ = q15.sat32(np.round(frac * 2.0**31).astype(np.int64))
        lengths = np.asarray(lengths, dtype=float)
        d = np.zeros(6) if rates is None else np.asarray(rates, float) * self.timing.sample_period
        sp = np.round((lengths + self.platform.length_offset - d) / self.config.ik_format.length_lsb).astype(np.int64)
        filt = q15.sat16(np.round(d / self.timing.sensor_resolution).astype(np.int64) * 2**DIFF_SHIFT)
        return np.concatenate([integ, self.quantise(lengths - d) + self._offset_counts, filt, sp, filt]).astype(float)

    def command_from_integrator(self, integ, ff=None):
        """The command (N) of the integrator word alone plus the feed-forward's table word, saturated."""
        u32 = np.asarray(integ, dtype=np.int64)
        if ff is not None:
            u32 = q15.L_add(u32, q15.L_deposit_h(self.feedforward_words(ff)))
        return q15.extract_h(u32) / 32768.0 * self.timing.command_range

    def feedforward_words(self, ff) -> np.ndarray:
        """``(6,)`` Q15 command words of feed-forward forces ``ff`` (N), as the host writes the table:
        rounded to the nearest LSB of the command range, saturated to the word."""
        return q15.sat16(np.round(np.asarray(ff, dtype=float) / self.timing.command_range * 32768.0).astype(np.int64))

    def step(self, state, reference, measured, feedforward=None):
        """One tick in the firmware's arithmetic (see ``FloatLaw.step``); ``feedforward`` (N) enters as its
        table word (``feedforward_words``) added to the Q31 sum. The state holds integer words."""
        q = q15
        sp = self.setpoint_words(reference)
        m = self.quantise(measured) + self._offset_counts
        st = np.asarray(state).astype(np.int64)
        integ, prev, dfilt, sp_prev, vfilt = st[:6], st[6:12], st[12:18], st[18:24], st[24:]
        # The same elementwise intrinsics as the firmware's per-leg code, on stacked rows (one numpy call per
        # operation for all rows): row 0 the measurement difference and its filter, row 1 the set-point's.
        # Every shift here is by a constant n >= 0, where shl(a, n) = sat16(a << n) and L_shl(a, n) =
        # sat32(a << n) (``q15.shl``, ``q15.L_shl``): written so, without their run-time sign dispatch.
        diff = q.sat16(
            q.sat16(np.stack([m - prev, (sp - sp_prev) * self._counts_per_lsb])) << DIFF_SHIFT
        )  # Word16, ·2^DIFF_SHIFT
        # first-order filters of the differences: f += alpha·(d − f), rounded Q15 multiplies
        filt = np.stack([dfilt, vfilt])
        dfilt, vfilt = q.add(filt, q.mult_r(self._alphas, q.sub(diff, filt)))
        e = q.sat16(sp * self._counts_per_lsb - m)  # Word16 error, counts
        # the P, D, V terms and the integrator's increment: Q31 products shifted by each gain's exponent
        P, D, V, dI = q.sat32(q.L_mult(self._mantissas, np.stack([e, dfilt, vfilt, e])) << self._shifts)
        u32 = q.L_add(q.L_sub(q.L_add(P, integ), D), V)
        if feedforward is not None:
            u32 = q.L_add(u32, q.L_deposit_h(self.feedforward_words(feedforward)))
        # saturation: the command is a Q15 word; the sum saturated if it hit the Q31 rails
        saturated = (u32 >= q.MAX32) | (u32 <= q.MIN32)
        u16 = q.extract_h(u32)
        grow = ~(((u32 >= q.MAX32) & (e > 0)) | ((u32 <= q.MIN32) & (e < 0)))
        integ = np.where(grow, q.L_add(integ, dI), integ)
        command = u16 / 32768.0 * self.timing.command_range
        new_state = np.concatenate([integ, m, dfilt, sp, vfilt]).astype(float)
        return command, sp * self.config.ik_format.length_lsb, new_state, saturated.astype(float)
