"""What a motion program does, as a library: a ``Motion`` collects moves and waits, turns them into a
time-stamped pose trajectory (quintic, rest-to-rest between waypoints, so velocity and acceleration
exist and are continuous), and ``evaluate`` runs inverse kinematics and inverse dynamics on it.

Both the interpreter and the Python emitted by ``compile --emit python`` call this module, so the two
produce the same trajectory. Program values are in the program's units (``units`` statement; default
mm and degrees, as in seed 004's example); everything stored here is SI (metres, radians, seconds).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import partial

import numpy as np

from stewart_drake.core.dynamics import MAX_CONDITION, jacobian_condition, leg_forces
from stewart_drake.core.geometry import Platform
from stewart_drake.core.kinematics import check_stroke, leg_lengths
from stewart_drake.core.rotations import ANGLE_UNITS, LENGTH_UNITS, angle_scale, length_scale
from stewart_drake.core.sanity import above_base, has_plate, plate_anchor_heights
from stewart_drake.core.trajectory import Trajectory
from stewart_drake.errors import (
    SCRIPT_BELOW_BASE,
    SCRIPT_DURATION,
    SCRIPT_FOR_STEP_ZERO,
    SCRIPT_MORE_UNREACHABLE,
    SCRIPT_MOVE_ARITY,
    SCRIPT_MOVE_DUPLICATE_ARG,
    SCRIPT_MOVE_UNKNOWN_ARG,
    SCRIPT_NOT_A_NUMBER,
    SCRIPT_NOT_FINITE,
    SCRIPT_SEGMENT_SAMPLES,
    SCRIPT_SINGULAR,
    SCRIPT_START_OUT_OF_REACH,
    SCRIPT_TOO_MANY_MOVES,
    SCRIPT_TOO_MANY_SAMPLES,
    SCRIPT_TOO_SHORT,
    SCRIPT_TWO_UNITS,
    SCRIPT_UNIT,
    SCRIPT_UNREACHABLE,
    SCRIPT_WAIT,
    OptionError,
    SingularPoseError,
)
from stewart_drake.script.errors import Loc, ScriptError, as_loc, raise_all

ARG_NAMES = ("x", "y", "z", "alpha", "beta", "gama")
ARG_ALIASES = {"gamma": "gama"}
DEFAULT_UNITS = ("mm", "deg")
DEFAULT_DURATION = 1.0  # s, a move without "en"/"in"
DEFAULT_RATE = 100.0  # Hz, trajectory samples
MAX_SAMPLES = 2_000_000
# Moves and waits one program may make: each costs ~0.2 ms to sample, check, evaluate and write, so the
# limit keeps a run under ~30 s.
MAX_SEGMENTS = 100_000
# The shortest move (s): a Stewart platform's actuators cannot resolve a faster one, and the quintic's
# acceleration (~5.8 Δ / d²) overflows for absurd durations.
MIN_MOVE_DURATION = 1e-3
MAX_REPORTED = 10  # unreachable moves listed in one diagnostic batch

# Functions usable in expressions: name -> (number of arguments, implementation, Python spelling).
FUNCTIONS = {
    "sin": (1, math.sin, "math.sin"),
    "cos": (1, math.cos, "math.cos"),
    "tan": (1, math.tan, "math.tan"),
    "asin": (1, math.asin, "math.asin"),
    "acos": (1, math.acos, "math.acos"),
    "atan": (1, math.atan, "math.atan"),
    "atan2": (2, math.atan2, "math.atan2"),
    "sqrt": (1, math.sqrt, "math.sqrt"),
    "abs": (1, abs, "abs"),
    "min": (2, min, "min"),
    "max": (2, max, "max"),
}
CONSTANTS = {"pi": (math.pi, "math.pi")}


def quintic(tau):
    """Rest-to-rest quintic blend s(τ) = 10τ³ − 15τ⁴ + 6τ⁵ on τ ∈ [0, 1] and its first two derivatives
    ``(s, ds/dτ, d²s/dτ²)``; s' and s'' vanish at both ends."""
    tau = np.asarray(tau, dtype=float)
    s = tau**3 * (10 - 15 * tau + 6 * tau**2)
    ds = 30 * tau**2 * (1 - tau) ** 2
    dds = 60 * tau * (1 - tau) * (1 - 2 * tau)
    return s, ds, dds


@dataclass(frozen=True)
class Segment:
    """One timed piece of a program: a move (``ordinal`` = 1, 2, ...) or a wait (``ordinal`` None).
    ``q0``/``q1`` are SI poses (6,); ``values`` the move's six arguments in ``units`` as resolved."""

    kind: str
    q0: np.ndarray
    q1: np.ndarray
    duration: float
    at: Loc | None
    ordinal: int | None = None
    keyword: str = "mover"
    values: tuple = ()
    units: tuple = DEFAULT_UNITS

    def describe(self) -> str:
        """``mover #2 to (100, 120, 300 mm; 25, 10, 0 deg)`` / ``wait``."""
        if self.kind != "move":
            return "wait"
        return f"{self.keyword} #{self.ordinal} to ({pose_text(self.values, self.units)})"


def fmt_number(v: float) -> str:
    """Shortest faithful text of a number: ``100``, ``2.5``, ``1e-07``."""
    v = float(v)
    if v == int(v) and abs(v) < 1e15:
        return str(int(v))
    return f"{v:.15g}"


def pose_text(values, units) -> str:
    """Six pose values as the program wrote them: "x, y, z <length unit>; a, b, g <angle unit>"."""
    v = [fmt_number(x) for x in values]
    return f"{', '.join(v[:3])} {units[0]}; {', '.join(v[3:])} {units[1]}"


def segments_pose(segments: tuple, start, t) -> np.ndarray:
    """``(..., 6)`` pose at any times ``(...)`` (s) along a program's ``segments`` (their quintics, not
    samples): ``start`` (6,) before the first segment's start and without segments, the final pose after
    the end."""
    t = np.asarray(t, dtype=float)
    if not segments:
        return np.broadcast_to(start, t.shape + (6,)).copy()
    d = np.array([s.duration for s in segments])
    ends = np.cumsum(d)
    k = np.clip(np.searchsorted(ends, t, side="left"), 0, len(d) - 1)
    tau = np.clip((t - (ends[k] - d[k])) / d[k], 0.0, 1.0)
    q0 = np.array([s.q0 for s in segments])[k]
    q1 = np.array([s.q1 for s in segments])[k]
    return q0 + quintic(tau)[0][..., None] * (q1 - q0)


def _check_finite(value, what: str, at) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ScriptError(SCRIPT_NOT_A_NUMBER.format(what=what, value=value), at) from None
    if not math.isfinite(v):
        raise ScriptError(SCRIPT_NOT_FINITE.format(what=what, value=v), at)
    return v


class Motion:
    """Builds a program's motion: ``units``, ``move``/``mover`` and ``wait`` calls, in order.

    ``start``: (6,) SI pose the platform starts from (usually ``platform.home_pose()``).
    """

    def __init__(self, start, units=DEFAULT_UNITS, default_duration: float = DEFAULT_DURATION):
        self.start = np.array(start, dtype=float).reshape(6)
        self.pose = self.start.copy()
        self.segments: list[Segment] = []
        self.length_unit, self.angle_unit = DEFAULT_UNITS
        self.units(*units)
        self.default_duration = float(default_duration)
        self._moves = 0

    @classmethod
    def at_home(cls, platform: Platform, **kw) -> Motion:
        """A motion starting at the platform's home pose."""
        return cls(platform.home_pose(), **kw)

    # -- statements
    def units(self, *names, at=None) -> None:
        """Set the length unit (``mm``/``m``) and/or angle unit (``deg``/``rad``/``pi``) of later moves."""
        at = as_loc(at)
        seen = set()
        for n in names:
            if n in LENGTH_UNITS:
                kind = "length"
            elif n in ANGLE_UNITS:
                kind = "angle"
            else:
                raise ScriptError(
                    SCRIPT_UNIT.format(name=n, lengths=" or ".join(LENGTH_UNITS), angles=" or ".join(ANGLE_UNITS)),
                    at,
                )
            if kind in seen:
                raise ScriptError(SCRIPT_TWO_UNITS.format(kind=kind), at)
            seen.add(kind)
            if kind == "length":
                self.length_unit = n
            else:
                self.angle_unit = n

    def _scale(self) -> np.ndarray:
        return np.r_[np.full(3, length_scale(self.length_unit)), np.full(3, angle_scale(self.angle_unit))]

    def resolve(self, args, kwargs, keyword: str = "mover", at=None) -> tuple:
        """The six target values (program units) of a move: positional ``args`` fill x, y, z, alpha,
        beta, gama in order, keywords name them; with keywords, omitted coordinates keep their value."""
        at = as_loc(at)
        if len(args) > 6 or (not kwargs and len(args) != 6):
            raise ScriptError(SCRIPT_MOVE_ARITY.format(kw=keyword, n=len(args) + len(kwargs)), at)
        current = self.pose / self._scale()
        values = {n: float(v) for n, v in zip(ARG_NAMES, current)}
        given = {}
        for name, v in zip(ARG_NAMES, args):
            given[name] = v
        for name, v in kwargs.items():
            canon = ARG_ALIASES.get(name, name)
            if canon not in ARG_NAMES:
                raise ScriptError(SCRIPT_MOVE_UNKNOWN_ARG.format(kw=keyword, name=name), at)
            if canon in given:
                raise ScriptError(SCRIPT_MOVE_DUPLICATE_ARG.format(kw=keyword, name=canon), at)
            given[canon] = v
        for name, v in given.items():
            values[name] = _check_finite(v, f"{keyword} argument {name}", at)
        return tuple(values[n] for n in ARG_NAMES)

    def move(self, *args, duration=None, at=None, keyword: str = "move", **kwargs) -> Segment:
        """Move to a pose over ``duration`` seconds (default 1 s), quintic rest-to-rest."""
        at = as_loc(at)
        values = self.resolve(args, kwargs, keyword, at)
        d = self.default_duration if duration is None else _check_finite(duration, f"{keyword} duration", at)
        if d <= 0:
            raise ScriptError(SCRIPT_DURATION.format(keyword=keyword, value=fmt_number(d)), at)
        if d < MIN_MOVE_DURATION:
            raise ScriptError(
                SCRIPT_TOO_SHORT.format(keyword=keyword, value=fmt_number(d), limit=fmt_number(MIN_MOVE_DURATION)), at
            )
        self._check_segments(at)
        q1 = np.array(values) * self._scale()
        self._moves += 1
        seg = Segment(
            "move", self.pose.copy(), q1, d, at, self._moves, keyword, values, (self.length_unit, self.angle_unit)
        )
        self.segments.append(seg)
        self.pose = q1
        return seg

    def mover(self, *args, duration=None, at=None, **kwargs) -> Segment:
        """``move`` under the seed's Spanish name."""
        return self.move(*args, duration=duration, at=at, keyword="mover", **kwargs)

    def wait(self, duration, at=None) -> Segment | None:
        """Hold the current pose for ``duration`` seconds (>= 0)."""
        at = as_loc(at)
        d = _check_finite(duration, "wait duration", at)
        if d < 0:
            raise ScriptError(SCRIPT_WAIT.format(value=fmt_number(d)), at)
        if d == 0:
            return None
        self._check_segments(at)
        seg = Segment("wait", self.pose.copy(), self.pose.copy(), d, at)
        self.segments.append(seg)
        return seg

    def _check_segments(self, at) -> None:
        if len(self.segments) >= MAX_SEGMENTS:
            raise ScriptError(SCRIPT_TOO_MANY_MOVES.format(limit=MAX_SEGMENTS), at)

    # -- result
    def trajectory(self, rate: float = DEFAULT_RATE) -> Trajectory:
        """Sample every segment at ``rate`` Hz (each segment's end is a sample; t = 0 is the start)."""
        if not (math.isfinite(rate) and rate > 0):
            raise OptionError(OptionError.POSITIVE.format(option="trajectory rate", unit="Hz", value=rate))
        for s in self.segments:  # each segment's samples, in floating point first (a huge wait overflows int)
            if s.duration * rate > MAX_SAMPLES:
                raise ScriptError(
                    SCRIPT_SEGMENT_SAMPLES.format(
                        what=s.describe(),
                        duration=fmt_number(s.duration),
                        limit=MAX_SAMPLES,
                        rate=fmt_number(rate),
                        seconds=fmt_number(MAX_SAMPLES / rate),
                    ),
                    s.at,
                )
        counts = [max(1, math.ceil(s.duration * rate - 1e-9)) for s in self.segments]
        total = 1 + sum(counts)
        if total > MAX_SAMPLES:
            seconds = sum(s.duration for s in self.segments)
            raise ScriptError(
                SCRIPT_TOO_MANY_SAMPLES.format(
                    total=total, seconds=fmt_number(seconds), rate=fmt_number(rate), limit=MAX_SAMPLES
                ),
                self.segments[-1].at,
            )
        t, q, qd, qdd, seg = [np.zeros(1)], [self.start[None]], [np.zeros((1, 6))], [np.zeros((1, 6))], [np.array([-1])]
        t0 = 0.0
        for k, (s, n) in enumerate(zip(self.segments, counts)):
            tau = np.arange(1, n + 1) / n
            p, dp, ddp = quintic(tau)
            delta = s.q1 - s.q0
            t.append(t0 + tau * s.duration)
            q.append(s.q0 + p[:, None] * delta)
            qd.append(dp[:, None] * delta / s.duration)
            qdd.append(ddp[:, None] * delta / s.duration**2)
            seg.append(np.full(n, k))
            t0 += s.duration
        t, q = np.concatenate(t), np.vstack(q)
        segments = tuple(self.segments)
        return Trajectory(
            "program",
            partial(segments_pose, segments, q[0].copy()),
            float(t[-1]),
            t=t,
            q=q,
            qd=np.vstack(qd),
            qdd=np.vstack(qdd),
            segment=np.concatenate(seg),
            segments=segments,
        )


@dataclass(frozen=True)
class Result:
    """A program's outcome: the trajectory, leg lengths ``L`` (n, 6) m and leg forces ``F`` (n, 6) N
    (None when inverse dynamics is unavailable; ``notes`` says why)."""

    trajectory: Trajectory
    L: np.ndarray
    F: np.ndarray | None
    platform: str
    convention: str
    notes: tuple = ()


def check_reachable(platform: Platform, traj: Trajectory, convention: str = "utn") -> np.ndarray:
    """``(n, 6)`` leg lengths (m) of every sample; raise ``ScriptError``(s) naming each move whose path
    leaves the stroke: which move, which leg, by how much and when (the worst sample of that move)."""
    L = leg_lengths(platform, traj.q, convention)
    _check_above_base(platform, traj, convention)
    chk = check_stroke(platform, L)
    bad = ~chk.within
    if not np.any(bad):
        return L
    errors = []
    excess = np.maximum(chk.below, chk.above)  # (n, 6) m
    for k in np.unique(traj.segment[bad]):
        if k < 0 or traj.segments[k].kind != "move":
            continue  # a wait holds the pose its move reached (reported there) or the start pose (below)
        s = traj.segments[k]
        idx = np.flatnonzero((traj.segment == k) & bad)
        i, leg = np.unravel_index(np.argmax(excess[idx]), (len(idx), 6))
        n = idx[i]
        below = bool(chk.below[n, leg] > 0)
        errors.append(
            ScriptError(
                SCRIPT_UNREACHABLE.format(
                    what=s.describe(),
                    platform=platform.name,
                    leg=leg + 1,
                    excess=excess[n, leg] * 1e3,
                    side="below" if below else "above",
                    bound="minimum" if below else "maximum",
                    limit=(platform.L_min if below else platform.L_max) * 1e3,
                    length=L[n, leg] * 1e3,
                    t=traj.t[n],
                    where="" if n == np.flatnonzero(traj.segment == k)[-1] else ", on the way there",
                ),
                s.at,
            )
        )
    if not errors:  # only the start pose (and waits holding it) is out of stroke
        leg = int(np.argmax(excess[0]))
        raise ScriptError(
            SCRIPT_START_OUT_OF_REACH.format(
                platform=platform.name,
                leg=leg + 1,
                length_mm=L[0, leg] * 1e3,
                lo_mm=platform.L_min * 1e3,
                hi_mm=platform.L_max * 1e3,
            )
        )
    if len(errors) > MAX_REPORTED:
        more = len(errors) - MAX_REPORTED
        errors = errors[:MAX_REPORTED] + [
            ScriptError(SCRIPT_MORE_UNREACHABLE.format(more=more), errors[MAX_REPORTED].at)
        ]
    raise_all(errors)
    return L  # pragma: no cover


def _check_above_base(platform: Platform, traj: Trajectory, convention: str) -> None:
    """``ScriptError`` at the first move whose path puts a plate anchor at or below the base plane
    (``sanity.above_base``), with the time and the anchor's height."""
    ok = above_base(platform, traj.q, convention)
    if np.all(ok):
        return
    n = int(np.argmin(ok))
    k = traj.segment[n]
    seg = traj.segments[k] if k >= 0 else None
    z = plate_anchor_heights(platform, traj.q[n], convention)
    leg = int(np.argmin(z))
    what = seg.describe() if seg is not None else "the start pose"
    raise ScriptError(
        SCRIPT_BELOW_BASE.format(
            what=what,
            where="in" if z[leg] == 0 else "below",
            platform=platform.name,
            leg=leg + 1,
            z_mm=z[leg] * 1e3,
            t=traj.t[n],
        ),
        seg.at if seg is not None else None,
    )


def _singular_error(platform: Platform, traj: Trajectory, convention: str, err) -> ScriptError:
    """A ``SingularPoseError`` from the dynamics, restated at the move whose path crosses the singularity."""
    k = jacobian_condition(platform, traj.q, convention)
    bad = np.flatnonzero(~(k <= MAX_CONDITION))
    if not len(bad):
        return ScriptError(str(err))
    n = int(bad[0])
    seg = traj.segments[traj.segment[n]] if traj.segment[n] >= 0 else None
    what = seg.describe() if seg is not None else "the start pose"
    return ScriptError(
        SCRIPT_SINGULAR.format(what=what, t=traj.t[n], cond=k[n], limit=MAX_CONDITION),
        seg.at if seg is not None else None,
    )


def evaluate(
    platform: Platform, traj: Trajectory, convention: str = "utn", coriolis: bool = True, gravity: float = 9.81
) -> Result:
    """Inverse kinematics (with the stroke check) and inverse dynamics on a trajectory."""
    L = check_reachable(platform, traj, convention)
    notes = []
    if not has_plate(platform):  # a massless plate would give every force as 0
        return Result(
            traj,
            L,
            None,
            platform.name,
            convention,
            (f"leg forces not computed: platform {platform.name!r} has no plate mass properties (YAML key 'plate')",),
        )
    try:
        F = np.asarray(
            leg_forces(platform, traj.q, traj.qd, traj.qdd, convention=convention, coriolis=coriolis, gravity=gravity)
        )
    except SingularPoseError as e:
        raise _singular_error(platform, traj, convention, e) from None
    return Result(traj, L, F, platform.name, convention, tuple(notes))


def for_count(start, stop, step=1.0, at=None) -> int:
    """How many values ``for_range`` yields (0 when the loop does not run), without running it."""
    start = _check_finite(start, "FOR start", at)
    stop = _check_finite(stop, "FOR limit", at)
    step = _check_finite(step, "FOR step", at)
    if step == 0:
        raise ScriptError(SCRIPT_FOR_STEP_ZERO, as_loc(at))
    n = (stop - start) / step
    if not n > -1e-9:
        return 0
    return int(math.floor(n + 1e-9)) + 1 if math.isfinite(n) and n < 1e18 else 10**18


def for_range(start, stop, step=1.0, at=None):
    """The values of ``FOR i := start TO stop BY step``: start + k·step while not past ``stop`` (bounds
    and step evaluated once, as in Modula-2; a relative 1e-9 of a step is allowed for rounding, so
    ``0 TO 1 BY 0.1`` ends at 1). A zero step is an error."""
    start = _check_finite(start, "FOR start", at)
    stop = _check_finite(stop, "FOR limit", at)
    step = _check_finite(step, "FOR step", at)
    if step == 0:
        raise ScriptError(SCRIPT_FOR_STEP_ZERO, as_loc(at))
    k = 0
    while (stop - (start + k * step)) / step > -1e-9:
        yield start + k * step
        k += 1
