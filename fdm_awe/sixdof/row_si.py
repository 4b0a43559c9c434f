"""The raw JSBSim row (:mod:`.row`) in SI units, NED frame with the winch at the origin.

Ground frame. The winch stands on the ground (terrain elevation 0) at geodetic latitude
``home_lat_deg``, longitude 0. NED positions map to geodetic coordinates linearly:
north = (lat - lat0) (M0 + 0), east = lon N0 cos(lat0), down = -h, with the WGS84 meridian and
prime-vertical radii M0, N0 at the winch. Down follows the local vertical (gravity), so the
frame departs from a tangent plane by d^2/(2R): 7 mm at 300 m.

:func:`row_si_factors` gives each position of a row its scale and offset, SI value = raw * scale +
offset (as :class:`~.state.SixDofState` converts one row); :func:`convert_rows` turns stacked
rows into named SI series.
"""

from __future__ import annotations

import math

import numpy as np

from ..constants import G0
from ..units import FT, LBF, PSF, SLUG
from .row import ROW

_WGS84_A = 6378137.0
_WGS84_F = 1.0 / 298.257223563
_WGS84_E2 = _WGS84_F * (2.0 - _WGS84_F)
_HP_W = 745.69987158227022


def ground_frame(home_lat_deg: float) -> tuple[float, float, float]:
    """The NED frame about the winch at geodetic latitude ``home_lat_deg`` [deg]: its latitude
    lat0 [rad], the WGS84 meridian radius M0 [m] and N0 cos(lat0) [m] there."""
    lat0 = math.radians(home_lat_deg)
    s2 = math.sin(lat0) ** 2
    m0 = _WGS84_A * (1 - _WGS84_E2) / (1 - _WGS84_E2 * s2) ** 1.5
    n0cos = _WGS84_A / math.sqrt(1 - _WGS84_E2 * s2) * math.cos(lat0)
    return lat0, m0, n0cos


def row_si_factors(n: int, lat0: float, m0: float, n0cos: float) -> tuple[np.ndarray, np.ndarray]:
    """Scale and offset of each of the ``n`` positions of a raw row in the ground frame
    (:func:`ground_frame`: lat0 rad, M0 m, N0 cos(lat0) m): SI value = raw * scale + offset."""
    scale = np.ones(n)
    offset = np.zeros(n)
    scale[ROW.lat], offset[ROW.lat] = m0, -lat0 * m0
    scale[ROW.lon] = n0cos
    scale[ROW.h_sl] = -FT
    scale[ROW.v_north:ROW.v_down + 1] = FT
    scale[ROW.vt] = FT
    scale[ROW.wind_north:ROW.wind_down + 1] = FT
    scale[ROW.fbx:ROW.fbz + 1] = LBF
    scale[ROW.mass] = SLUG
    scale[ROW.qbar] = PSF
    scale[ROW.rho] = SLUG / FT**3
    scale[ROW.thrust] = LBF
    scale[ROW.shaft_hp] = _HP_W
    return scale, offset


def convert_rows(raw: np.ndarray, scale: np.ndarray, offset: np.ndarray, motor_volts: float) -> dict[str, np.ndarray]:
    """SI time series from stacked raw rows (n x len(raw)) with the factors of
    :func:`row_si_factors`, as :class:`~.state.SixDofState` names them; ``motor_volts`` [V] the
    motor's voltage at full throttle (the propeller's electric power)."""
    raw = np.atleast_2d(np.asarray(raw, dtype=float))
    v = raw * scale + offset
    phi, th, psi = raw[:, ROW.phi], raw[:, ROW.theta], raw[:, ROW.psi]
    cr, sr = np.cos(0.5 * phi), np.sin(0.5 * phi)
    cp, sp = np.cos(0.5 * th), np.sin(0.5 * th)
    cy, sy = np.cos(0.5 * psi), np.sin(0.5 * psi)
    quat = np.stack((cr * cp * cy + sr * sp * sy, sr * cp * cy - cr * sp * sy,
                     cr * sp * cy + sr * cp * sy, cr * cp * sy - sr * sp * cy), axis=1)
    mass = v[:, ROW.mass]
    return {
        "t": raw[:, ROW.t], "pos_ned": v[:, ROW.lat:ROW.h_sl + 1], "vel_ned": v[:, ROW.v_north:ROW.v_down + 1],
        "vel_air_ned": v[:, ROW.v_north:ROW.v_down + 1] - v[:, ROW.wind_north:ROW.wind_down + 1],
        "wind_ned": v[:, ROW.wind_north:ROW.wind_down + 1],
        "quat": quat, "euler": raw[:, ROW.phi:ROW.psi + 1], "omega_body": raw[:, ROW.p_rate:ROW.r_rate + 1],
        "airspeed": v[:, ROW.vt],
        "alpha": raw[:, ROW.alpha], "beta": raw[:, ROW.beta], "fold": raw[:, ROW.fold], "thrust_N": v[:, ROW.thrust],
        "prop_power_W": raw[:, ROW.throttle] * motor_volts * raw[:, ROW.current], "shaft_power_W": v[:, ROW.shaft_hp],
        "current_A": raw[:, ROW.current], "accel_body": v[:, ROW.fbx:ROW.fbz + 1] / mass[:, None],
        "load_factor": -v[:, ROW.fbz] / mass / G0, "mass": mass, "qbar": v[:, ROW.qbar], "rho": v[:, ROW.rho],
        "on_ground": raw[:, ROW.wow] > 0.5,
    }
