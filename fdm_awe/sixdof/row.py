"""The raw JSBSim row: what the adapter reads after every step, one named position per value.

A row holds the JSBSim property values of one step in JSBSim's own units (ft, ft/s, lbf,
slug, ...; angles rad), in the order of :data:`PROPERTIES`. Its layout :data:`ROW` names the
positions (``r[ROW.vt]``), so that code compiled by numba (:mod:`fdm_awe.sim.kernel`) and Python
code index the row with the same names.

:func:`hook_kinematics` is the one place where the tether attachment point's position and
velocity are computed from a row: a plain function that the adapter runs in Python and the
compiled co-simulation step compiles (the same source either way).
"""

from __future__ import annotations

from math import cos, sin

from .. import slots

#: the row's layout (JSBSim units; converted to SI by the adapter)
ROW = slots.declare("JsbsimRow", ("t", "lat", "lon", "h_sl", "v_north", "v_east", "v_down", "phi", "theta", "psi",
                                  "p_rate", "q_rate", "r_rate", "vt", "alpha", "beta", "wind_north", "wind_east",
                                  "wind_down", "fbx", "fby", "fbz", "mass", "qbar", "rho", "thrust", "shaft_hp",
                                  "current", "throttle", "wow", "fold"))

#: the JSBSim property read into each position (``ROW.fold``: None, the aircraft's fold state when it
#: has one, else a constant 0.0)
PROPERTIES: dict[int, str | None] = {
    ROW.t: "simulation/sim-time-sec",
    ROW.lat: "position/lat-geod-rad", ROW.lon: "position/long-gc-rad", ROW.h_sl: "position/h-sl-ft",
    ROW.v_north: "velocities/v-north-fps", ROW.v_east: "velocities/v-east-fps", ROW.v_down: "velocities/v-down-fps",
    ROW.phi: "attitude/phi-rad", ROW.theta: "attitude/theta-rad", ROW.psi: "attitude/psi-rad",
    ROW.p_rate: "velocities/p-rad_sec", ROW.q_rate: "velocities/q-rad_sec", ROW.r_rate: "velocities/r-rad_sec",
    ROW.vt: "velocities/vt-fps", ROW.alpha: "aero/alpha-rad", ROW.beta: "aero/beta-rad",
    ROW.wind_north: "atmosphere/total-wind-north-fps", ROW.wind_east: "atmosphere/total-wind-east-fps",
    ROW.wind_down: "atmosphere/total-wind-down-fps",
    ROW.fbx: "forces/fbx-total-lbs", ROW.fby: "forces/fby-total-lbs", ROW.fbz: "forces/fbz-total-lbs",
    ROW.mass: "inertia/mass-slugs", ROW.qbar: "aero/qbar-psf", ROW.rho: "atmosphere/rho-slugs_ft3",
    ROW.thrust: "propulsion/engine[0]/thrust-lbs", ROW.shaft_hp: "propulsion/engine[0]/power-hp",
    ROW.current: "propulsion/engine[0]/current-amperes", ROW.throttle: "fcs/throttle-pos-norm[0]",
    ROW.wow: "contact/wow",
    ROW.fold: None,
}
#: the fold state's property (position ``ROW.fold``) on the foldable aircraft
FOLD_PROPERTY = "fcs/wing-fold-norm"
#: positions that must stay finite (position, velocity, attitude, rates, airspeed, flow angles):
#: ``row[FINITE_FIRST:FINITE_END]``
FINITE_FIRST, FINITE_END = ROW.lat, ROW.beta + 1

if sorted(PROPERTIES) != list(range(slots.size(ROW))):  # pragma: no cover - a definition error in this module
    raise RuntimeError("fdm_awe.sixdof.row: PROPERTIES must name every position of ROW once")


def si_position(r, scale, offset):
    """The CG position ``(x, y, z)`` [m, NED, winch origin] of a row ``r`` with the adapter's
    per-position SI ``scale`` and ``offset`` (SI value = raw * scale + offset)."""
    return r[ROW.lat] * scale[ROW.lat] + offset[ROW.lat], r[ROW.lon] * scale[ROW.lon], r[ROW.h_sl] * scale[ROW.h_sl]


def si_velocity(r, scale):
    """The ground velocity ``(vn, ve, vd)`` [m/s] of a row ``r`` (``scale`` as :func:`si_position`)."""
    k = scale[ROW.v_north]
    return r[ROW.v_north] * k, r[ROW.v_east] * k, r[ROW.v_down] * k


def si_wind(r, scale):
    """The wind JSBSim applied at the glider in a row ``r`` (steady + turbulence), ``(wn, we, wd)``
    [m/s, NED] (``scale`` as :func:`si_position`)."""
    k = scale[ROW.wind_north]
    return r[ROW.wind_north] * k, r[ROW.wind_east] * k, r[ROW.wind_down] * k


def si_gust(r, scale, sn, se, sd):
    """The gust the glider meets in a row ``r``: its ground velocity less its air-relative
    velocity (ground velocity less :func:`si_wind`, as :class:`~.state.SixDofState` gives
    ``vel_air_ned``), less the steady wind ``(sn, se, sd)`` [m/s, NED]; ``(gn, ge, gd)`` [m/s]."""
    vn, ve, vd = si_velocity(r, scale)
    wn, we, wd = si_wind(r, scale)
    return (vn - (vn - wn)) - sn, (ve - (ve - we)) - se, (vd - (vd - wd)) - sd


def hook_kinematics(r, lat0, m0, n0cos, ft, ox, oy, oz):
    """Tether attachment point from a row ``r``: ``((x, y, z), (vx, vy, vz))``, NED m and m/s,
    winch origin. ``lat0`` home latitude rad, ``m0`` meridian radius m, ``n0cos`` N0 cos(lat0) m
    (the ground frame of :mod:`.adapter`), ``ft`` m per ft, ``(ox, oy, oz)`` the hook's offset
    from the CG in body axes, m: position CG + C_bn o, velocity v_CG + C_bn (omega x o)."""
    x = (r[ROW.lat] - lat0) * m0
    y = r[ROW.lon] * n0cos
    z = -r[ROW.h_sl] * ft
    vx, vy, vz = r[ROW.v_north] * ft, r[ROW.v_east] * ft, r[ROW.v_down] * ft
    if ox == 0.0 and oy == 0.0 and oz == 0.0:
        return (x, y, z), (vx, vy, vz)
    phi, th, psi = r[ROW.phi], r[ROW.theta], r[ROW.psi]
    cf, sf = cos(phi), sin(phi)
    ct, st = cos(th), sin(th)
    cp, sp = cos(psi), sin(psi)
    p, q, rr = r[ROW.p_rate], r[ROW.q_rate], r[ROW.r_rate]
    wx, wy, wz = q * oz - rr * oy, rr * ox - p * oz, p * oy - q * ox  # omega x offset (body)
    m00, m01, m02 = ct * cp, sf * st * cp - cf * sp, cf * st * cp + sf * sp
    m10, m11, m12 = ct * sp, sf * st * sp + cf * cp, cf * st * sp - sf * cp
    m20, m21, m22 = -st, sf * ct, cf * ct
    return ((x + m00 * ox + m01 * oy + m02 * oz, y + m10 * ox + m11 * oy + m12 * oz,
             z + m20 * ox + m21 * oy + m22 * oz),
            (vx + m00 * wx + m01 * wy + m02 * wz, vy + m10 * wx + m11 * wy + m12 * wz,
             vz + m20 * wx + m21 * wy + m22 * wz))


__all__ = ["FINITE_END", "FINITE_FIRST", "FOLD_PROPERTY", "PROPERTIES", "ROW", "hook_kinematics", "si_gust",
           "si_position", "si_velocity", "si_wind"]
