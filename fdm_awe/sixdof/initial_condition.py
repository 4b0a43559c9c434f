"""Start in flight: JSBSim's initial condition from an air-path state.

The body attitude follows from the air-path angles (climb ``gamma``, heading ``psi`` of the air
velocity, bank ``phi``) and the angle of attack at zero sideslip, C_BN = R2(alpha) R1(phi)
R2(gamma) R3(psi); the ground velocity is the air velocity plus the steady wind; body rates
are zero. JSBSim's actuators (servos, fold) start at their commands.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..errors import InputError
from ..units import FT


def body_attitude(alpha: float, gamma: float, psi: float, phi: float) -> tuple[float, float, float]:
    """Euler angles (roll, pitch, yaw) [rad] of the body at angle of attack ``alpha`` and zero
    sideslip on the air-path angles ``gamma``, ``psi``, ``phi`` [rad]."""
    c_wn = _r1(phi) @ _r2(gamma) @ _r3(psi)
    c_bn = _r2(alpha) @ c_wn
    theta = -math.asin(max(-1.0, min(1.0, c_bn[0, 2])))
    phi_b = math.atan2(c_bn[1, 2], c_bn[2, 2])
    psi_b = math.atan2(c_bn[0, 1], c_bn[0, 0])
    return phi_b, theta, psi_b


def apply_initial_condition(fdm: Any, geodetic: tuple[float, float, float], airspeed: float, gamma: float,
                            psi: float, phi: float, alpha: float, wind_ned: tuple[float, float, float]) -> None:
    """Set and run JSBSim's (``fdm``, an FGFDMExec) initial condition: CG at ``geodetic``
    (latitude rad, longitude rad, height ft over terrain at 0 ft), air-relative speed
    ``airspeed`` [m/s] on the air-path angles ``gamma``, ``psi``, ``phi`` [rad] at ``alpha`` [rad],
    zero body rates, in the steady wind ``wind_ned`` [m/s]. Turbulence is off afterwards and
    JSBSim's wind is horizontal only: the caller restores both. InputError when JSBSim rejects it."""
    phi_b, theta, psi_b = body_attitude(alpha, gamma, psi, phi)
    lat, lon, h_ft = geodetic
    w = wind_ned
    V = airspeed
    v_air = (V * math.cos(gamma) * math.cos(psi), V * math.cos(gamma) * math.sin(psi), -V * math.sin(gamma))
    f = fdm
    f["ic/terrain-elevation-ft"] = 0.0
    f["ic/lat-geod-rad"] = lat
    f["ic/long-gc-rad"] = lon
    f["ic/h-sl-ft"] = h_ft
    f["ic/phi-rad"] = phi_b
    f["ic/theta-rad"] = theta
    f["ic/psi-true-rad"] = psi_b
    f["ic/p-rad_sec"] = 0.0
    f["ic/q-rad_sec"] = 0.0
    f["ic/r-rad_sec"] = 0.0
    f["ic/vw-mag-fps"] = math.hypot(w[0], w[1]) / FT
    f["ic/vw-dir-deg"] = math.degrees(math.atan2(w[1], w[0]))  # JSBSim: 0 = blowing north
    f["ic/vn-fps"] = (v_air[0] + w[0]) / FT
    f["ic/ve-fps"] = (v_air[1] + w[1]) / FT
    f["ic/vd-fps"] = (v_air[2] + w[2]) / FT
    f["atmosphere/turb-type"] = 0  # the Tustin filters give NaN when initialised at dt = 0
    # with the trim flag set, JSBSim's actuators (servos, fold) start at their commands
    # instead of rate-limiting from their previous positions
    f.set_trim_status(True)
    try:
        ok = f.run_ic()
    finally:
        f.set_trim_status(False)
    if not ok:
        raise InputError("reset: JSBSim rejected the initial condition")


def _r1(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, s], [0.0, -s, c]])


def _r2(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, 0.0, -s], [0.0, 1.0, 0.0], [s, 0.0, c]])


def _r3(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])
