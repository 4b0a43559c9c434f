"""The onboard wind estimate: the wind the glider meets, from what a real autopilot measures.

Sensors (no true wind): the true airspeed of the pitot ``TAS`` [m/s], the attitude of the AHRS
(roll, pitch, yaw [rad]) and the ground velocity of the GPS ``v`` [m/s, NED]. The angle of
attack is not measured (no vane), so the body axis is not the air velocity's direction.

The method is ArduPilot EKF3's wind estimation (``AP_NavEKF3``: a horizontal wind of two states,
no vertical wind, fused with the airspeed magnitude and a synthetic sideslip of zero), solved
as a batch least-squares problem over a window instead of recursively: over the samples ``i``
of the window, the horizontal wind ``w = (w_n, w_e)`` minimises the sum of

- ``|v_i - f_i w| - TAS_i`` (the airspeed: the air velocity's magnitude is what the pitot reads;
  ``f_i`` the wind profile's factor at the sample's height, 1 in a uniform wind), and
- ``(v_i - f_i w) . y_i`` (the sideslip: the air velocity has no component along the body's
  y-axis ``y_i`` from the AHRS, the synthetic sideslip measurement EKF3 fuses for a
  fixed-wing aircraft without a sideslip sensor),

both in m/s, weighted alike, by Gauss-Newton from ArduPilot's DCM estimate (``AP_AHRS_DCM``:
the ground velocity less the airspeed along the body x-axis, averaged). Why a batch over a
window: the scheduler needs the wind the next cycle will meet, the mean over the last cycle,
not the gusts; the least-squares estimate over a cycle is that mean (to within the wind's
variation along the path), and with the heading turning through the cycle's loops the two
unknowns are well determined. A recursive filter with a time constant of a cycle would give
the same mean with a lag. The sideslip term makes the estimate independent of the angle of
attack, which the DCM estimate's body-axis direction is not (sample by sample it is off by
``TAS sin(alpha)`` turned into the horizontal by the bank, 1-3 m/s in the cycle's turns; that
averages out only over whole turns at one bank, not over a pumping cycle's path); the synthetic
sideslip is itself a model: the yaw damper keeps the glider's sideslip small but not zero.

With a wind profile (``factor``), the unknown is the wind at the profile's reference height
and the samples' heights scale it: a reference set optimised in a profile is then chosen by
the same quantity its references record (``wind_mps`` at the reference height).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

#: Gauss-Newton: at most this many iterations, stopped when a step is below STEP_TOL [m/s]
MAX_ITERATIONS = 30
STEP_TOL = 1e-9
#: fewest samples of an estimate (below: none)
MIN_SAMPLES = 10


@dataclass(frozen=True)
class WindEstimate:
    """A wind estimate over a window of samples.

    ``north``, ``east``: the horizontal wind [m/s, NED, the air's velocity] at the profile's
    reference height (the wind at the glider in a uniform wind); ``at_glider``: the mean wind
    speed [m/s] over the window's samples at their heights (``|w| mean(f_i)``); ``rms``: the
    residuals' root mean square [m/s] (airspeed and sideslip together); ``sigma``: the standard
    error of each wind component [m/s] from the residuals (how well the window determines
    it); ``samples``: how many samples; ``iterations``: Gauss-Newton's."""

    north: float
    east: float
    at_glider: float
    rms: float
    sigma: float
    samples: int
    iterations: int

    @property
    def speed(self) -> float:
        """Horizontal wind speed at the reference height [m/s]."""
        return math.hypot(self.north, self.east)

    @property
    def direction_from_deg(self) -> float:
        """The direction the wind blows from [deg, 0..360, 0 = north, 90 = east]."""
        return math.degrees(math.atan2(-self.east, -self.north)) % 360.0

    def at_glider_ned(self) -> tuple[float, float, float]:
        """The mean wind at the glider's heights [m/s, NED]: the estimate's direction with
        :attr:`at_glider`'s speed (no vertical wind)."""
        s = self.speed
        f = self.at_glider / s if s > 0.0 else 1.0
        return (self.north * f, self.east * f, 0.0)

    def as_dict(self) -> dict[str, float | int]:
        """The estimate's numbers (JSON)."""
        return {"north_mps": self.north, "east_mps": self.east, "speed_mps": self.speed,
                "from_deg": self.direction_from_deg, "at_glider_mps": self.at_glider, "rms_mps": self.rms,
                "sigma_mps": self.sigma, "samples": self.samples}


def body_axes(euler: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The body x- and y-axes in NED (n x 3 each) of the attitudes ``euler`` (n x 3: roll,
    pitch, yaw [rad]; the direction cosines of :func:`fdm_awe.sixdof.row.hook_kinematics`)."""
    phi, th, psi = euler[:, 0], euler[:, 1], euler[:, 2]
    cf, sf, ct, st, cp, sp = np.cos(phi), np.sin(phi), np.cos(th), np.sin(th), np.cos(psi), np.sin(psi)
    x = np.stack((ct * cp, ct * sp, -st), axis=1)
    y = np.stack((sf * st * cp - cf * sp, sf * st * sp + cf * cp, sf * ct), axis=1)
    return x, y


def estimate_wind(vel_ned: np.ndarray, airspeed: np.ndarray, euler: np.ndarray, heights: np.ndarray | None = None,
                  factor: Callable[[Any], Any] | None = None) -> WindEstimate | None:
    """The wind estimate (module doc) from ``n`` samples: ground velocity ``vel_ned`` (n x 3,
    m/s), true airspeed ``airspeed`` (n, m/s), attitude ``euler`` (n x 3: roll, pitch, yaw,
    rad), heights ``heights`` (n, m above the winch) and the wind profile's ``factor(h)``
    (:meth:`fdm_awe.wind.WindProfile.factor`; None: uniform). Samples that are not finite or
    slower than 1 m/s in the air are left out; None with fewer than :data:`MIN_SAMPLES`, or when
    the samples do not determine the wind (the normal equations singular)."""
    v = np.asarray(vel_ned, float).reshape(-1, 3)
    tas = np.asarray(airspeed, float).reshape(-1)
    eu = np.asarray(euler, float).reshape(-1, 3)
    if factor is None or heights is None:
        f = np.ones(len(tas))
    else:
        f = np.asarray(factor(np.asarray(heights, float)), float) * np.ones(len(tas))
    ok = np.isfinite(v).all(axis=1) & np.isfinite(tas) & np.isfinite(eu).all(axis=1) & np.isfinite(f) & (tas > 1.0)
    v, tas, eu, f = v[ok], tas[ok], eu[ok], f[ok]
    n = len(tas)
    if n < MIN_SAMPLES:
        return None
    bx, by = body_axes(eu)
    # DCM's start: the ground velocity less the airspeed along the body axis, over the mean factor
    w = np.mean(v[:, :2] - tas[:, None] * bx[:, :2], axis=0) / np.mean(f)
    it = 0
    for it in range(1, MAX_ITERATIONS + 1):
        r, J = _residuals(v, tas, by, f, w)
        step = -_solve2(J.T @ J, J.T @ r)
        w = w + step
        if not float(np.max(np.abs(step))) >= STEP_TOL:  # converged (or no step: NaN)
            break
    if not np.all(np.isfinite(w)):  # singular: the samples do not tell the two components apart
        return None
    r, J = _residuals(v, tas, by, f, w)
    rms = float(np.sqrt(np.mean(r * r)))
    inv = _solve2(J.T @ J, np.eye(2)) * float(r @ r) / max(len(r) - 2, 1)
    sigma = float(np.sqrt(max(inv[0, 0], inv[1, 1], 0.0)))
    return WindEstimate(float(w[0]), float(w[1]), float(np.hypot(*w) * np.mean(f)), rms, sigma, n, it)


def _solve2(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``a^-1 b`` for a 2 x 2 matrix ``a`` (the normal equations' two unknowns; NaN when singular)."""
    det = a[0, 0] * a[1, 1] - a[0, 1] * a[1, 0]
    inv = np.array([[a[1, 1], -a[0, 1]], [-a[1, 0], a[0, 0]]]) / det if det != 0.0 else np.full((2, 2), np.nan)
    return inv @ b


def _residuals(v: np.ndarray, tas: np.ndarray, by: np.ndarray, f: np.ndarray,
               w: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The airspeed and sideslip residuals [m/s] (2n) at the wind ``w`` and their Jacobian (2n x 2)."""
    a = v.copy()
    a[:, 0] -= f * w[0]
    a[:, 1] -= f * w[1]
    va = np.linalg.norm(a, axis=1)
    r = np.concatenate((va - tas, np.sum(a * by, axis=1)))
    J = np.concatenate((-(f / va)[:, None] * a[:, :2], -f[:, None] * by[:, :2]))
    return r, J


#: the wind before a failsafe (:func:`wind_before`): the window [s] before it, the slices [s]
#: whose lowest estimate it names, and the share of the cycle's wind below which a slice is a lull
LULL_WINDOW, LULL_SLICE, LULL_SHARE = 20.0, 5.0, 0.75


def wind_before(t: np.ndarray, vel_ned: np.ndarray, airspeed: np.ndarray, euler: np.ndarray, heights: np.ndarray,
                factor: Callable[[Any], Any] | None, t_end: float, wind_cycle: float) -> dict[str, float] | None:
    """The onboard wind estimate (:func:`estimate_wind`, sensed quantities only) over the
    :data:`LULL_WINDOW` before time ``t_end`` [s] of the samples at times ``t`` [s] (the other
    arguments as :func:`estimate_wind`'s): ``window_s``, ``at_glider_mps`` (the window's mean wind
    at the glider), ``lowest_mps`` (the lowest of its :data:`LULL_SLICE` slices), ``lull_s``
    (how long the slices were below :data:`LULL_SHARE` of ``wind_cycle`` [m/s], the wind the
    cycle flown was made for) and ``threshold_mps``; None without enough samples. What made a
    failsafe: a lull (the wind below what the cycle flies in) or not (a gust, a turn of the wind)."""
    t = np.asarray(t, float)
    sel = (t > t_end - LULL_WINDOW) & (t <= t_end)

    def est(m: np.ndarray) -> WindEstimate | None:
        return estimate_wind(vel_ned[m], airspeed[m], euler[m], heights[m], factor)

    whole = est(sel)
    if whole is None:
        return None
    lows = []
    for a in np.arange(t_end - LULL_WINDOW, t_end - 1e-9, LULL_SLICE):
        e = est(sel & (t > a) & (t <= a + LULL_SLICE))
        if e is not None:
            lows.append(e.at_glider)
    threshold = LULL_SHARE * wind_cycle
    return {"window_s": LULL_WINDOW, "at_glider_mps": whole.at_glider,
            "lowest_mps": min(lows) if lows else whole.at_glider,
            "lull_s": LULL_SLICE * sum(w < threshold for w in lows), "threshold_mps": threshold}


def wind_before_text(w: dict[str, float], wind_cycle: float) -> str:
    """The failsafe's wind (:func:`wind_before`) in words: a lull named by its wind and length, or none."""
    head = (f"onboard wind {w['at_glider_mps']:.1f} m/s at the glider over the {w['window_s']:.0f} s before "
            f"(the cycle's {wind_cycle:g} m/s), {w['lowest_mps']:.1f} m/s at its lowest")
    if w["lull_s"] > 0.0:
        return f"a lull: {head}, below {w['threshold_mps']:.1f} m/s for {w['lull_s']:.0f} s"
    return f"no lull: {head}"
