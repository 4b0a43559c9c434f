"""The raw JSBSim row: what the adapter reads after every step, one named position per value.

A row holds the JSBSim property values of one step in JSBSim's own units (ft, ft/s, lbf,
slug, ...; angles rad), in the order of :data:`PROPERTIES`. The integer constants below name its
positions; they are plain module-level ints, so that code compiled by numba
(:mod:`fdm_awe.sim.kernel`) and Python code index the row with the same names.

:func:`hook_kinematics` is the one place where the tether attachment point's position and
velocity are computed from a row: a plain function that the adapter runs in Python and the
compiled co-simulation step compiles (the same source either way).
"""

from __future__ import annotations

from math import cos, sin

# positions in the row (JSBSim units; converted to SI by the adapter)
(T, LAT, LON, H_SL, V_NORTH, V_EAST, V_DOWN, PHI, THETA, PSI, P_RATE, Q_RATE, R_RATE, VT, ALPHA, BETA,
 WIND_NORTH, WIND_EAST, WIND_DOWN, FBX, FBY, FBZ, MASS, QBAR, RHO, THRUST, SHAFT_HP, CURRENT, THROTTLE, WOW,
 FOLD) = range(31)
#: values per row
N_ROW = 31

#: the JSBSim property read into each position (``FOLD``: None, the aircraft's fold state when it
#: has one, else a constant 0.0)
PROPERTIES: dict[int, str | None] = {
    T: "simulation/sim-time-sec",
    LAT: "position/lat-geod-rad", LON: "position/long-gc-rad", H_SL: "position/h-sl-ft",
    V_NORTH: "velocities/v-north-fps", V_EAST: "velocities/v-east-fps", V_DOWN: "velocities/v-down-fps",
    PHI: "attitude/phi-rad", THETA: "attitude/theta-rad", PSI: "attitude/psi-rad",
    P_RATE: "velocities/p-rad_sec", Q_RATE: "velocities/q-rad_sec", R_RATE: "velocities/r-rad_sec",
    VT: "velocities/vt-fps", ALPHA: "aero/alpha-rad", BETA: "aero/beta-rad",
    WIND_NORTH: "atmosphere/total-wind-north-fps", WIND_EAST: "atmosphere/total-wind-east-fps",
    WIND_DOWN: "atmosphere/total-wind-down-fps",
    FBX: "forces/fbx-total-lbs", FBY: "forces/fby-total-lbs", FBZ: "forces/fbz-total-lbs",
    MASS: "inertia/mass-slugs", QBAR: "aero/qbar-psf", RHO: "atmosphere/rho-slugs_ft3",
    THRUST: "propulsion/engine[0]/thrust-lbs", SHAFT_HP: "propulsion/engine[0]/power-hp",
    CURRENT: "propulsion/engine[0]/current-amperes", THROTTLE: "fcs/throttle-pos-norm[0]", WOW: "contact/wow",
    FOLD: None,
}
#: the fold state's property (position ``FOLD``) on the foldable aircraft
FOLD_PROPERTY = "fcs/wing-fold-norm"
#: positions that must stay finite (position, velocity, attitude, rates, airspeed, flow angles):
#: ``row[FINITE_FIRST:FINITE_END]``
FINITE_FIRST, FINITE_END = LAT, BETA + 1

if sorted(PROPERTIES) != list(range(N_ROW)):  # pragma: no cover - a definition error in this module
    raise RuntimeError("fdm_awe.sixdof.row: PROPERTIES must name every position 0 .. N_ROW-1 once")


def si_position(r, scale, offset):
    """The CG position ``(x, y, z)`` [m, NED, winch origin] of a row ``r`` with the adapter's
    per-position SI ``scale`` and ``offset`` (SI value = raw * scale + offset)."""
    return r[LAT] * scale[LAT] + offset[LAT], r[LON] * scale[LON], r[H_SL] * scale[H_SL]


def si_velocity(r, scale):
    """The ground velocity ``(vn, ve, vd)`` [m/s] of a row ``r`` (``scale`` as :func:`si_position`)."""
    k = scale[V_NORTH]
    return r[V_NORTH] * k, r[V_EAST] * k, r[V_DOWN] * k


def hook_kinematics(r, lat0, m0, n0cos, ft, ox, oy, oz):
    """Tether attachment point from a row ``r``: ``((x, y, z), (vx, vy, vz))``, NED m and m/s,
    winch origin. ``lat0`` home latitude rad, ``m0`` meridian radius m, ``n0cos`` N0 cos(lat0) m
    (the ground frame of :mod:`.adapter`), ``ft`` m per ft, ``(ox, oy, oz)`` the hook's offset
    from the CG in body axes, m: position CG + C_bn o, velocity v_CG + C_bn (omega x o)."""
    x = (r[LAT] - lat0) * m0
    y = r[LON] * n0cos
    z = -r[H_SL] * ft
    vx, vy, vz = r[V_NORTH] * ft, r[V_EAST] * ft, r[V_DOWN] * ft
    if ox == 0.0 and oy == 0.0 and oz == 0.0:
        return (x, y, z), (vx, vy, vz)
    phi, th, psi = r[PHI], r[THETA], r[PSI]
    cf, sf = cos(phi), sin(phi)
    ct, st = cos(th), sin(th)
    cp, sp = cos(psi), sin(psi)
    p, q, rr = r[P_RATE], r[Q_RATE], r[R_RATE]
    wx, wy, wz = q * oz - rr * oy, rr * ox - p * oz, p * oy - q * ox  # omega x offset (body)
    m00, m01, m02 = ct * cp, sf * st * cp - cf * sp, cf * st * cp + sf * sp
    m10, m11, m12 = ct * sp, sf * st * sp + cf * cp, cf * st * sp - sf * cp
    m20, m21, m22 = -st, sf * ct, cf * ct
    return ((x + m00 * ox + m01 * oy + m02 * oz, y + m10 * ox + m11 * oy + m12 * oz,
             z + m20 * ox + m21 * oy + m22 * oz),
            (vx + m00 * wx + m01 * wy + m02 * wz, vy + m10 * wx + m11 * wy + m12 * wz,
             vz + m20 * wx + m21 * wy + m22 * wz))


__all__ = ["FINITE_END", "FINITE_FIRST", "FOLD_PROPERTY", "N_ROW", "PROPERTIES", "hook_kinematics", "si_position",
           "si_velocity"]
