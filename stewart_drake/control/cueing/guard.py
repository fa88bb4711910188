"""The workspace guard: commanded poses that never leave the platform's workspace, by construction.

A cueing law's poses are moved toward home along the whole pose — ``home + c(t) (q(t) − home)``, one scale
``c(t) ∈ [0, 1]`` for the six coordinates together — never leg by leg (clipping one leg turns the plate and
creates false cues). ``c`` is the largest smooth scale below each sample's admissible scale:

1. the admissible scale ``s_k`` of each sample: bisection on the exact inverse kinematics between home (inside)
   and the pose, keeping the inside end, for the stroke less its margin at both ends;
2. ``c`` = ``s`` eroded (a running minimum over ``2W + 1`` samples), its rate limited to ``scale_rate`` (the
   largest such sequence below it) and averaged twice over ``2W + 1`` samples: a mean of values each at most
   ``s_k`` stays at most ``s_k``, and the averages make ``c``'s rate continuous, so the scale adds no step and
   no acceleration spike;
3. leg speed and acceleration (central differences of the exact leg lengths): where a sample exceeds a limit,
   its admissible scale is lowered by the excess ratio and step 2 is redone, a bounded number of times;
4. last, the whole sequence is re-checked with the exact IK; should a limit still be exceeded, ``c`` is scaled
   down as a whole by bisection on that check (``c = 0``, home throughout, passes it).

Joint-angle cones, leg collision and dexterity are checked where a ``workspace.limits.Limits`` gives them (the
platform files give none): the admissible scale and the last check require their margins too.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np
from scipy.ndimage import minimum_filter1d, uniform_filter1d

from stewart_drake.core.argcheck import as_poses
from stewart_drake.core.geometry import Platform
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.errors import CueingError
from stewart_drake.workspace.limits import Limits, limit_margins

STROKE_MARGIN = 0.02  # of the stroke, at each end
SPEED_MARGIN = 0.9  # the guard keeps legs below this share of their speed limit
DEFAULT_MAX_SPEED = 0.5  # m/s: a leg's speed limit where the platform file gives none (an electric cylinder's)
DEFAULT_MAX_ACCEL = 9.80665  # m/s²: a leg's acceleration limit (1 g)
BISECTIONS = 30  # scale resolution 1e-9
SPEED_PASSES = 20


@dataclass(frozen=True, eq=False)
class LimitCheck:
    """The exact-IK check of poses sampled at a step: samples past the stroke ends, the leg speed and the leg
    acceleration limits (counts), the extremes (m, m/s, m/s²), and samples past the ``Limits``' joint cones,
    collision or dexterity bounds."""

    outside_stroke: int
    over_speed: int
    over_accel: int
    min_length: float
    max_length: float
    max_speed: float
    max_accel: float
    outside_joints: int = 0

    @property
    def ok(self) -> bool:
        """No sample past any limit."""
        return self.outside_stroke == 0 and self.over_speed == 0 and self.over_accel == 0 and self.outside_joints == 0


@dataclass(frozen=True, eq=False)
class WorkspaceGuard:
    """Limits a pose sequence to ``platform``'s workspace about ``home``.

    Attributes:
        platform: the platform.
        home: ``(6,)`` the pose the scale moves toward (inside the limits).
        stroke: ``(2,)`` m, the lengths the guard keeps legs within (the stroke less its margins).
        max_speed: m/s, the leg speed the guard keeps below.
        max_accel: m/s², the leg acceleration the guard keeps below.
        scale_rate: 1/s, the largest rate of the scale.
        smoothing: s, the half-width W of the scale's erosion and averages.
        limits: joint cones, leg collision, dexterity (``Limits``, its stroke switched off: the guard's own); None:
            none.
    """

    platform: Platform
    home: np.ndarray
    stroke: np.ndarray
    max_speed: float
    max_accel: float
    scale_rate: float = 0.5
    smoothing: float = 0.25
    limits: Limits | None = None

    @classmethod
    def for_platform(
        cls,
        platform: Platform,
        margin: float = STROKE_MARGIN,
        max_speed: float | None = None,
        max_accel: float = DEFAULT_MAX_ACCEL,
        home=None,
        scale_rate: float = 0.5,
        smoothing: float = 0.25,
        limits: Limits | None = None,
    ) -> WorkspaceGuard:
        """The guard of ``platform``: its stroke less ``margin`` (a share of the stroke) at each end, ``SPEED_MARGIN``
        of ``max_speed`` (default the platform's ``legs.max_speed``, else ``DEFAULT_MAX_SPEED``) and of
        ``max_accel``, the joint cones, collision and dexterity bounds of ``limits``, about ``home`` (default the
        platform's home pose)."""
        for name, value, low in (
            ("margin", margin, 0.0),
            ("scale_rate", scale_rate, 0.0),
            ("smoothing", smoothing, 0.0),
        ):
            if (
                not isinstance(value, (int, float))
                or not math.isfinite(value)
                or value < low
                or (name == "margin" and value >= 0.5)
            ):
                rule = "in [0, 0.5)" if name == "margin" else "a number >= 0"
                raise CueingError(CueingError.PARAM.format(name=name, rule=rule, value=value))
        speed = max_speed if max_speed is not None else (platform.legs.max_speed or DEFAULT_MAX_SPEED)
        for name, value in (("max_speed", speed), ("max_accel", max_accel)):
            if not isinstance(value, (int, float)) or not math.isfinite(value) or value <= 0:
                raise CueingError(CueingError.PARAM.format(name=name, rule="a positive number", value=value))
        lo, hi = platform.stroke
        m = margin * (hi - lo)
        home = platform.home_pose() if home is None else np.asarray(home, dtype=float)
        stroke = np.array([lo + m, hi - m])
        others = None if limits is None else dataclasses.replace(limits, stroke=False)
        guard = cls(
            platform, home, stroke, SPEED_MARGIN * speed, SPEED_MARGIN * max_accel, scale_rate, smoothing, others
        )
        if not guard._inside(np.zeros((1, 6)))[0]:
            raise CueingError(CueingError.HOME_OUTSIDE.format(home=home.tolist(), margin=m))
        return guard

    def check(self, poses, t, stroke=None, max_speed=None, max_accel=None) -> LimitCheck:
        """The exact-IK check of ``poses`` ``(N, 6)`` at times ``t`` ``(N,)`` against the guard's limits (or those
        given: the platform's own stroke and limits, for a report)."""
        q = as_poses(poses)
        L = leg_lengths(self.platform, q)
        dt = float(t[1] - t[0])
        lo, hi = self.stroke if stroke is None else stroke
        v, a = _rates(L, dt)
        vmax = np.max(np.abs(v), axis=1)
        amax = np.max(np.abs(a), axis=1)
        return LimitCheck(
            int(np.sum(np.any((L < lo) | (L > hi), axis=1))),
            int(np.sum(vmax > (self.max_speed if max_speed is None else max_speed))),
            int(np.sum(amax > (self.max_accel if max_accel is None else max_accel))),
            float(L.min()),
            float(L.max()),
            float(vmax.max()),
            float(amax.max()),
            int(np.sum(~self._within_limits(q))),
        )

    def guard(self, poses, t) -> np.ndarray:
        """``(N, 6)`` poses: ``poses`` ``(N, 6)`` (m, rad, ``utn``) at the uniform times ``t`` ``(N,)`` scaled toward
        home until every sample is within the guard's stroke, leg speed and acceleration (see the module)."""
        q = as_poses(poses)
        t = np.asarray(t, dtype=float)
        if q.ndim != 2 or t.shape != (len(q),) or len(q) < 3:
            raise CueingError(CueingError.POSES_TIMES.format(n=q.shape[0] if q.ndim else 1, m=t.size))
        dt = float(t[1] - t[0])
        e = q - self.home
        allowed = self.admissible_scale(e)
        width = max(1, int(round(self.smoothing / dt)))
        c = self._smooth_below(allowed, dt, width)
        for _ in range(SPEED_PASSES):
            L = leg_lengths(self.platform, self.home + c[:, None] * e)
            v, a = _rates(L, dt)
            ratio = np.minimum(
                self.max_speed / np.maximum(np.max(np.abs(v), axis=1), 1e-300),
                np.sqrt(self.max_accel / np.maximum(np.max(np.abs(a), axis=1), 1e-300)),
            )
            over = ratio < 1.0
            if not np.any(over):
                break
            lowered = np.where(over, 0.97 * ratio * c, np.inf)
            allowed = np.minimum(allowed, minimum_filter1d(lowered, 3))  # a rate uses the neighbours: lower them too
            c = self._smooth_below(allowed, dt, width)
        return self.home + self._whole_scale(c, e, t)[:, None] * e

    def admissible_scale(self, e: np.ndarray) -> np.ndarray:
        """``(N,)``: for each excursion ``e`` ``(N, 6)`` from home, a scale in [0, 1] whose pose ``home + s e`` is
        within the guard's stroke and limits (1 when the whole excursion is), by bisection on the exact IK."""
        lo, hi = np.zeros(len(e)), np.ones(len(e))
        inside = self._inside(e)
        lo[inside] = 1.0
        todo = np.flatnonzero(~inside)
        for _ in range(BISECTIONS):
            if todo.size == 0:
                break
            mid = 0.5 * (lo[todo] + hi[todo])
            ok = self._inside(mid[:, None] * e[todo])
            lo[todo[ok]] = mid[ok]
            hi[todo[~ok]] = mid[~ok]
        return lo

    def _inside(self, e: np.ndarray) -> np.ndarray:
        """``(N,)``: the poses ``home + e`` within the guard's stroke and its ``limits``."""
        L = leg_lengths(self.platform, self.home + e)
        return np.all((L >= self.stroke[0]) & (L <= self.stroke[1]), axis=1) & self._within_limits(self.home + e)

    def _within_limits(self, q: np.ndarray) -> np.ndarray:
        """``(N,)``: the poses ``q`` within ``limits`` (all True without)."""
        if self.limits is None or not self.limits.active:
            return np.ones(len(q), dtype=bool)
        margins = limit_margins(self.platform, q, self.limits)
        return np.all([m >= 0 for m, _ in margins.values()], axis=0)  # each margin: the worst leg's

    def _smooth_below(self, allowed: np.ndarray, dt: float, width: int) -> np.ndarray:
        """The largest rate-limited, twice-averaged scale at most ``allowed`` (see the module, step 2)."""
        eroded = minimum_filter1d(np.minimum(allowed, 1.0), 4 * width + 1, mode="nearest")
        step = self.scale_rate * dt
        k = np.arange(len(eroded)) * step
        c = np.minimum.accumulate(eroded - k) + k  # min over j <= i of eroded_j + step (i − j)
        c = np.minimum(c, (np.minimum.accumulate((eroded + k)[::-1]))[::-1] - k)  # and over j >= i
        for _ in range(2):
            c = uniform_filter1d(c, 2 * width + 1, mode="nearest")
        return np.clip(c, 0.0, 1.0)

    def _whole_scale(self, c: np.ndarray, e: np.ndarray, t: np.ndarray) -> np.ndarray:
        """``c`` when its poses pass ``check``; else ``λ c`` with the largest λ that passes (bisection, λ = 0
        passes)."""
        if self.check(self.home + c[:, None] * e, t).ok:
            return c
        lo, hi = 0.0, 1.0
        for _ in range(BISECTIONS):
            mid = 0.5 * (lo + hi)
            if self.check(self.home + (mid * c)[:, None] * e, t).ok:
                lo = mid
            else:
                hi = mid
        return lo * c


def _rates(L: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """``(N, 6)`` leg speeds and accelerations of lengths ``L`` ``(N, 6)``: central differences (ends: one-sided)."""
    v = np.gradient(L, dt, axis=0)
    a = np.zeros_like(L)
    a[1:-1] = (L[2:] - 2 * L[1:-1] + L[:-2]) / dt**2
    a[0], a[-1] = a[1], a[-2]
    return v, a
