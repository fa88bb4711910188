"""Vehicle motions for tests and examples: a ship in a sea state, a car's manoeuvres, an aircraft's turns.

- **Ship**: the wave elevation of a JONSWAP spectrum (γ = 3.3) with the significant height and modal period of
  the sea state (``SEA_STATES``: NATO STANAG 4194's open-ocean table, mean Hs and most probable Tp), synthesised
  as a sum of cosines on the record's own frequency grid (amplitudes √(2 S Δω), random phases from ``seed``),
  through a stated ship response model (``SHIP``): heave, roll and pitch each a second-order system driven by the
  elevation (heave) or the deep-water wave slope k η = ω²/g η resolved along the ship's heading (roll, pitch).
  The rider sits at ``SHIP.head`` from the centre of motion (linearised lever arm).
- **Car**: the linear single-track (bicycle) model at constant speed (``CAR``), steered for a lane change or a
  slalom, and a straight braking stop; the head at the centre of mass, no body roll or pitch.
- **Aircraft**: a coordinated level turn (ball centred, altitude held) at constant airspeed with a smooth bank
  profile: turn rate ψ̇ = g tan φ / V, specific force ``n g`` along the body z with n = 1/cos φ.

Every drive is in the head frame of ``drive.Drive`` (x forward, y left, z up) with its attitude as roll, pitch,
yaw in the ``zyx`` convention (Drake's ``RollPitchYaw``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import partial

import numpy as np
from scipy import signal

from stewart_drake.control.cueing.drive import GRAVITY, Drive
from stewart_drake.core.rotations import angular_velocity_map, rotation_matrix
from stewart_drake.errors import DriveError

# sea state -> (significant wave height Hs m, modal period Tp s): STANAG 4194, open ocean, North Atlantic
SEA_STATES = {3: (0.88, 7.5), 4: (1.88, 8.8), 5: (3.25, 9.7), 6: (5.0, 12.4)}
JONSWAP_GAMMA = 3.3
MAX_DURATION = 14_400.0  # s: four hours, 1.4 M samples at 100 Hz
RATES = (1.0, 1000.0)  # Hz


@dataclass(frozen=True)
class ShipModel:
    """A ship's heave, roll and pitch response to waves: each ``ω_n² / (ω_n² − ω² + 2 i ζ ω_n ω)`` times its
    excitation (heave: the elevation; roll: the wave slope times sin(heading); pitch: the slope times
    cos(heading)), with ``heading`` the waves' direction from the bow (rad) and ``head`` (m) the rider's place
    from the centre of motion (x forward, y left, z up). Natural frequencies rad/s, damping ratios."""

    heave: tuple[float, float] = (1.0, 0.3)  # ω_n rad/s (6.3 s period), ζ
    roll: tuple[float, float] = (0.5, 0.1)  # 12.6 s, lightly damped
    pitch: tuple[float, float] = (1.0, 0.3)
    heading: float = math.radians(30.0)
    head: tuple[float, float, float] = (10.0, 0.0, 8.0)  # a bridge 10 m forward of and 8 m above the centre

    def rao(self, omega) -> np.ndarray:
        """``(3, n)`` complex: heave (m), roll and pitch (rad) per metre of wave elevation at ``omega`` (n,)
        rad/s."""
        w = np.asarray(omega, dtype=float)
        slope = 1j * w**2 / GRAVITY  # deep water: k = ω²/g, a quarter period ahead of the elevation
        gains = (1.0, slope * math.sin(self.heading), slope * math.cos(self.heading))
        out = []
        for (wn, zeta), g in zip((self.heave, self.roll, self.pitch), gains):
            out.append(g * wn**2 / (wn**2 - w**2 + 2j * zeta * wn * w))
        return np.array(out)


SHIP = ShipModel()


@dataclass(frozen=True)
class CarModel:
    """A car's single-track model: mass kg, yaw inertia kg·m², axle distances from the centre of mass m,
    cornering stiffness of each axle N/rad."""

    mass: float = 1500.0
    yaw_inertia: float = 2500.0
    lf: float = 1.2
    lr: float = 1.4
    cf: float = 80_000.0
    cr: float = 90_000.0

    @property
    def understeer(self) -> float:
        """The understeer gradient K, rad per m/s²: steer δ = L/R + K a_y in a steady turn."""
        L = self.lf + self.lr
        return self.mass * (self.lr * self.cr - self.lf * self.cf) / (L * self.cf * self.cr)

    def state_space(self, speed: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Continuous ``(A, B, C, D)``: state (lateral velocity m/s, yaw rate rad/s), input the road-wheel steer
        (rad), outputs (lateral acceleration m/s², yaw rate rad/s) at ``speed`` m/s."""
        m, iz, a, b, cf, cr, u = self.mass, self.yaw_inertia, self.lf, self.lr, self.cf, self.cr, speed
        A = np.array(
            [
                [-(cf + cr) / (m * u), -(a * cf - b * cr) / (m * u) - u],
                [-(a * cf - b * cr) / (iz * u), -(a * a * cf + b * b * cr) / (iz * u)],
            ]
        )
        B = np.array([[cf / m], [a * cf / iz]])
        C = np.array([A[0] + [0.0, u], [0.0, 1.0]])  # a_y = v̇_y + u r
        D = np.array([B[0], [0.0]])
        return A, B, C, D


CAR = CarModel()


def jonswap(omega, hs: float, tp: float, gamma: float = JONSWAP_GAMMA) -> np.ndarray:
    """The JONSWAP spectrum S(ω) (m²·s/rad) at ``omega`` (rad/s) with significant height ``hs`` (m, = 4 √m0),
    modal period ``tp`` (s) and peak enhancement ``gamma`` (σ = 0.07 below the peak, 0.09 above)."""
    w = np.asarray(omega, dtype=float)
    wp = 2 * math.pi / tp

    def shape(x):
        x = np.maximum(x, 1e-9)
        sigma = np.where(x <= wp, 0.07, 0.09)
        peak = gamma ** np.exp(-((x - wp) ** 2) / (2 * sigma**2 * wp**2))
        return x**-5 * np.exp(-1.25 * (wp / x) ** 4) * peak

    grid = np.linspace(0.2 * wp, 20 * wp, 20001)  # m0 of the shape: the tail beyond 20 ωp holds < 1e-5 of it
    m0 = np.sum(shape(grid)) * (grid[1] - grid[0])
    return np.where(w > 0, shape(w) * (hs / 4) ** 2 / m0, 0.0)


def _times(duration, rate) -> np.ndarray:
    duration = _positive(duration, "duration")
    if not isinstance(rate, (int, float)) or not RATES[0] <= rate <= RATES[1]:
        raise DriveError(DriveError.RATE.format(low=RATES[0], high=RATES[1], value=rate))
    return np.arange(int(math.floor(duration * rate + 1e-9)) + 1) / rate


def _positive(value, name) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not 0 < value <= MAX_DURATION:
        raise DriveError(DriveError.DURATION.format(name=name, limit=MAX_DURATION, value=value))
    return float(value)


def wave_spectrum_lines(sea_state: int, n: int, dt: float, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """``(omega (n//2 + 1,), complex amplitudes)`` of the wave elevation of ``n`` samples at ``dt`` s: the
    record's FFT lines ω_k = 2π k / (n dt) with amplitude √(2 S(ω_k) Δω) and a random phase (``seed``)."""
    if sea_state not in SEA_STATES:
        raise DriveError(DriveError.SEA_STATE.format(valid=", ".join(map(str, SEA_STATES)), value=sea_state))
    hs, tp = SEA_STATES[sea_state]
    omega = 2 * math.pi * np.fft.rfftfreq(n, dt)
    amplitude = np.sqrt(2 * jonswap(omega, hs, tp) * (omega[1] - omega[0]))
    phase = np.random.default_rng(seed).uniform(0, 2 * math.pi, omega.shape)
    return omega, amplitude * np.exp(1j * phase)


def _series(lines: np.ndarray, n: int) -> np.ndarray:
    """The real series Σ |c_k| cos(ω_k t + arg c_k) of complex line amplitudes ``lines`` (last axis)."""
    return np.fft.irfft(lines * (n / 2), n)


def wave_elevation(sea_state: int, duration: float, rate: float = 100.0, seed: int = 0) -> np.ndarray:
    """``(N,)`` m: the wave elevation at the ship, sampled at ``rate`` Hz over ``duration`` s."""
    t = _times(duration, rate)
    _, lines = wave_spectrum_lines(sea_state, len(t), 1.0 / rate, seed)
    return _series(lines, len(t))


def ship_drive(sea_state: int, duration: float, rate: float = 100.0, seed: int = 0, ship: ShipModel = SHIP) -> Drive:
    """A ship's motion at its rider's head in sea state ``sea_state`` (3..6), ``duration`` s at ``rate`` Hz."""
    t = _times(duration, rate)
    n = len(t)
    omega, lines = wave_spectrum_lines(sea_state, n, 1.0 / rate, seed)
    motion = ship.rao(omega) * lines  # (3, n//2+1): heave, roll, pitch
    heave, roll, pitch = _series(motion, n)
    heave_acc, roll_acc, pitch_acc = _series(-(omega**2) * motion, n)
    roll_rate, pitch_rate = _series(1j * omega * motion[1:], n)
    angles = np.column_stack([roll, pitch, 0 * t])
    rates = np.column_stack([roll_rate, pitch_rate, 0 * t])
    # linearised lever arm: the head's acceleration is the heave plus (angular acceleration) × head
    acc = np.column_stack([0 * t, 0 * t, heave_acc]) + np.cross(
        np.column_stack([roll_acc, pitch_acc, 0 * t]), ship.head
    )
    return _drive(f"ship-ss{sea_state}", t, angles, rates, acc)


def _drive(name: str, t, angles, rates, acc) -> Drive:
    """The ``Drive`` of a vehicle with attitude ``angles`` (zyx), their ``rates`` and the head's world
    acceleration ``acc``, all ``(N, 3)``."""
    R = rotation_matrix(angles, "zyx")
    f = np.einsum("nji,nj->ni", R, acc + [0.0, 0.0, GRAVITY])
    w = np.einsum("nji,nj->ni", R, np.einsum("nij,nj->ni", angular_velocity_map(angles, "zyx"), rates))
    return Drive(name, t, f, w, angles)


def _smooth_step(t, start: float, length: float) -> np.ndarray:
    """0 before ``start``, 1 after ``start + length``, a half cosine between (continuous rate)."""
    s = np.clip((np.asarray(t) - start) / length, 0.0, 1.0)
    return 0.5 - 0.5 * np.cos(math.pi * s)


CAR_MANOEUVRES = ("lane-change", "braking", "slalom")
CAR_DURATIONS = {"lane-change": 10.0, "braking": 8.0, "slalom": 20.0}


def car_drive(manoeuvre: str, duration: float | None = None, rate: float = 100.0, car: CarModel = CAR) -> Drive:
    """A car's motion at the driver's head (``CAR``'s single-track model):

    - ``lane-change``: 3.5 m to the left in 3 s at 25 m/s (steer a one-period sine from t = 2 s, sized by the
      steady-state gain for a lateral acceleration peak of 2π·3.5/3² = 2.4 m/s²);
    - ``slalom``: 15 m/s, a 0.5 Hz steering sine (cones 15 m apart) for a 4 m/s² lateral peak, faded in and out
      over 2 s;
    - ``braking``: from 25 m/s, 7 m/s² of deceleration reached in 0.5 s from t = 1 s, eased off over the last
      0.5 s before the stop (no stop jerk), then at rest.
    """
    if manoeuvre not in CAR_MANOEUVRES:
        raise DriveError(DriveError.MANOEUVRE.format(vehicle="car", name=manoeuvre, valid=", ".join(CAR_MANOEUVRES)))
    t = _times(CAR_DURATIONS[manoeuvre] if duration is None else duration, rate)
    zero = 0 * t
    if manoeuvre == "braking":
        peak, u0, t0, ramp = 7.0, 25.0, 1.0, 0.5
        # deceleration d(t): ramp up (half cosine) to peak, hold, ramp down: speed lost u0 over its integral
        hold = (u0 - peak * ramp) / peak  # ramp up and down each lose peak·ramp/2
        decel = peak * (_smooth_step(t, t0, ramp) - _smooth_step(t, t0 + ramp + hold, ramp))
        acc = np.column_stack([-decel, zero, zero])
        return _drive(f"car-{manoeuvre}", t, np.zeros((len(t), 3)), np.zeros((len(t), 3)), acc)
    u = 15.0 if manoeuvre == "slalom" else 25.0
    gain = u**2 / ((car.lf + car.lr) + car.understeer * u**2)  # steady a_y per rad of steer
    if manoeuvre == "lane-change":
        T, offset = 3.0, 3.5
        steer = (
            (2 * math.pi * offset / T**2) / gain * np.sin(2 * math.pi * (t - 2.0) / T) * ((t >= 2.0) & (t <= 2.0 + T))
        )
    else:
        envelope = _smooth_step(t, 1.0, 2.0) - _smooth_step(t, t[-1] - 3.0, 2.0)
        steer = 4.0 / gain * envelope * np.sin(2 * math.pi * 0.5 * (t - 1.0))
    ay, r = single_track(car, u, steer, t)
    yaw = np.concatenate([[0.0], np.cumsum(0.5 * (r[1:] + r[:-1]) * np.diff(t))])
    angles = np.column_stack([zero, zero, yaw])
    # the head's world acceleration: lateral a_y along the body's y, turned by the heading
    acc = np.column_stack([-np.sin(yaw) * ay, np.cos(yaw) * ay, zero])
    return _drive(f"car-{manoeuvre}", t, angles, np.column_stack([zero, zero, r]), acc)


def single_track(car: CarModel, speed: float, steer, t) -> tuple[np.ndarray, np.ndarray]:
    """``(lateral acceleration m/s², yaw rate rad/s)``, each ``(N,)``, of ``car`` at ``speed`` m/s steered
    ``steer`` (N,) rad at times ``t`` (N,) s, from rest (straight ahead); exact for a steer linear between
    samples (``scipy.signal.lsim``)."""
    _, y, _ = signal.lsim(car.state_space(speed), np.asarray(steer, dtype=float), t)
    return y[:, 0], y[:, 1]


AIRCRAFT_MANOEUVRES = ("turn-entry", "turn-reversal")
AIRSPEED = 100.0  # m/s


def aircraft_drive(manoeuvre: str, duration: float | None = None, rate: float = 100.0) -> Drive:
    """An aircraft in a coordinated level turn at ``AIRSPEED``: ``turn-entry`` rolls from wings level into a 30°
    right bank over 3 s from t = 2 s; ``turn-reversal`` from a 30° right bank to a 30° left one over 4 s from
    t = 2 s. 15 s by default."""
    if manoeuvre not in AIRCRAFT_MANOEUVRES:
        raise DriveError(
            DriveError.MANOEUVRE.format(vehicle="aircraft", name=manoeuvre, valid=", ".join(AIRCRAFT_MANOEUVRES))
        )
    t = _times(15.0 if duration is None else duration, rate)
    bank = math.radians(30.0)
    if manoeuvre == "turn-entry":
        phi, phi_rate = bank * _smooth_step(t, 2.0, 3.0), bank * _smooth_rate(t, 2.0, 3.0)
    else:
        phi, phi_rate = bank * (1 - 2 * _smooth_step(t, 2.0, 4.0)), -2 * bank * _smooth_rate(t, 2.0, 4.0)
    return coordinated_turn(f"aircraft-{manoeuvre}", t, phi, phi_rate, AIRSPEED)


def _smooth_rate(t, start: float, length: float) -> np.ndarray:
    """The time derivative of ``_smooth_step``, 1/s."""
    s = (np.asarray(t) - start) / length
    return np.where((s > 0) & (s < 1), 0.5 * math.pi / length * np.sin(math.pi * np.clip(s, 0, 1)), 0.0)


def coordinated_turn(name: str, t, phi, phi_rate, airspeed: float) -> Drive:
    """A coordinated level turn at ``airspeed`` m/s with bank ``phi`` (N,) rad (positive: right wing down, a
    turn to the right) and its rate ``phi_rate`` rad/s: heading rate −g tan φ / V (z up), centripetal
    acceleration V ψ̇ across the track."""
    psi_rate = -GRAVITY * np.tan(phi) / airspeed
    dt = t[1] - t[0]
    psi = np.concatenate([[0.0], np.cumsum(0.5 * (psi_rate[1:] + psi_rate[:-1]) * dt)])
    zero = 0 * t
    angles = np.column_stack([phi, zero, psi])
    rates = np.column_stack([phi_rate, zero, psi_rate])
    acc = airspeed * psi_rate[:, None] * np.column_stack([-np.sin(psi), np.cos(psi), zero])
    return _drive(name, t, angles, rates, acc)


DRIVES = {
    **{f"ship-ss{s}": partial(ship_drive, s, 60.0) for s in SEA_STATES},
    **{f"car-{m}": partial(car_drive, m) for m in CAR_MANOEUVRES},
    **{f"aircraft-{m}": partial(aircraft_drive, m) for m in AIRCRAFT_MANOEUVRES},
}  # the shipped drives by name: each a callable of no arguments (or ``rate=``) returning its Drive


def shipped_drive(name: str) -> Drive:
    """The shipped drive ``name`` (a key of ``DRIVES``); ``DriveError`` listing them otherwise."""
    if name not in DRIVES:
        raise DriveError(DriveError.UNKNOWN.format(name=name, names=", ".join(DRIVES)))
    return DRIVES[name]()
