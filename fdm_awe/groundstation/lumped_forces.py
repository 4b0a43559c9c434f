"""The forces of the lumped-mass line (:mod:`.lumped`): the wind along it, a segment's pull, every
node's force with the line's energies and powers, the nodes' kinetic and potential energy.

Plain Python over floats and arrays, compiled by numba into the line's step (:mod:`.lumped`,
whose on-disk cache follows this file); the state's layout is :mod:`.lumped_state`'s.
"""

from __future__ import annotations

import math

from ..wind import shear_factor
from .lumped_state import LINE, NODES
from .substeps import CONST, STATION, cross_flow_drag


def wind_at(c, z: float) -> tuple[float, float, float]:
    """Wind at the height ``-z`` m (NED ``z``), m/s NED, the one place the line reads the wind:
    the station's uniform wind (``wind`` of :data:`.substeps.STATION`), or with a wind profile the wind at the reference
    height scaled to this height (:func:`fdm_awe.wind.shear_factor`); plus the gust of the
    moment (the turbulence the glider meets, taken as uniform along the line)."""
    code = c[LINE.shear_code]
    if code == 0.0:  # uniform: the gust is already in the station's wind (GroundStation.set_line_wind)
        return c[STATION.wind], c[STATION.wind + 1], c[STATION.wind + 2]
    f = shear_factor(code, c[LINE.shear_param], c[LINE.shear_href], c[LINE.shear_floor], -z)
    return c[LINE.wref_n] * f + c[LINE.gust_n], c[LINE.wref_e] * f + c[LINE.gust_e], c[LINE.gust_d]


def set_gust(c, wn: float, we: float, wd: float, gn: float, ge: float, gd: float) -> None:
    """The gust of the moment ``(gn, ge, gd)`` m/s NED into the line's constants ``c`` (read by
    :func:`wind_at`): its own slots, and with the uniform profile the station's wind ``(wn, we,
    wd)`` plus the gust in the station's wind slots (plain Python on a list or an array, compiled
    into the autopilot's blocks too)."""
    c[LINE.gust_n], c[LINE.gust_e], c[LINE.gust_d] = gn, ge, gd
    if c[LINE.shear_code] == 0.0:
        c[STATION.wind], c[STATION.wind + 1], c[STATION.wind + 2] = wn + gn, we + ge, wd + gd


def segment_pull(k: float, cd: float, d: float, ls: float, ux: float, uy: float, uz: float, rvx: float, rvy: float,
                 rvz: float) -> tuple[float, float, float, float]:
    """The pull of one segment along itself: tension only (stiffness ``k`` N/m, rest length
    ``ls`` m, length ``d`` m) and, while taut, the damper ``cd`` N s/m on its stretch rate (the
    velocity ``(rvx, rvy, rvz)`` m/s of its far end relative to its near end, along ``(ux, uy,
    uz)``). Returns ``(force N, elastic tension N, elastic energy J, damper power W)``, zeros
    when slack."""
    st = d - ls
    f = T = e = p = 0.0
    if st > 0.0:
        T = k * st
        e = 0.5 * k * st * st
        f = T
        if cd != 0.0:
            rate = ux * rvx + uy * rvy + uz * rvz
            f += cd * rate
            p = cd * rate * rate
    return f, T, e, p


def segment_end(s, n: int, i: int, vhx: float, vhy: float, vhz: float) -> tuple[float, float, float, float, float,
                                                                            float]:
    """The far end (node ``i + 1``) of segment ``i`` of ``n``: its position m and velocity m/s
    NED from the state ``s``, the hook's velocity ``(vhx, vhy, vhz)`` for the last segment."""
    b = NODES + 3 * i + 3
    if i == n - 1:
        return s[b], s[b + 1], s[b + 2], vhx, vhy, vhz
    vb = NODES + 3 * (n + 1) + 3 * i + 3
    return s[b], s[b + 1], s[b + 2], s[vb], s[vb + 1], s[vb + 2]


def along(dx: float, dy: float, dz: float) -> tuple[float, float, float, float, float]:
    """Length m of the vector ``(dx, dy, dz)``, its inverse 1/m (0 for a zero vector) and its unit vector."""
    d = math.sqrt(dx * dx + dy * dy + dz * dz)
    inv = 1.0 / d if d > 0.0 else 0.0
    return d, inv, dx * inv, dy * inv, dz * inv


def line_forces(s, c, n: int, ls: float, m: float, vhx: float, vhy: float, vhz: float,
                ls_old: float) -> tuple[float, float, float, float, float, float, float, float, float]:
    """Forces on every node (written into the force slots) from the positions and velocities
    in ``s`` with rest length ``ls`` m and interior node mass ``m`` kg; the hook node moves with
    ``(vhx, vhy, vhz)`` m/s. Slot N gets the force of the last segment on the hook (elastic +
    damper), the tensions their elastic part. Returns ``(elastic energy J, elastic energy at
    the rest length ``ls_old`` J, payout energy at the start positions J, damper power W,
    drag power on the interior nodes W, half-drag on the hook x, y, z N, largest tension N)``.
    The second and third terms belong to a rest-length change from ``ls_old`` to ``ls`` m (0
    when ``ls_old == ls``): the elastic energy of the new positions at the old rest length, and
    the elastic energy the change takes from the segments at their old positions (their lengths
    from the tensions still in the slots, exact for taut segments; read before they are
    overwritten).

    One pass over the segments: each node's force is summed in registers from its two segments
    (the winch side first, in the order of the sums it replaces) and stored once."""
    P = NODES
    V = P + 3 * (n + 1)
    F = V + 3 * (n + 1)
    TT = F + 3 * (n + 1)
    EA, g = c[CONST.EA], c[STATION.g]
    k = EA / ls
    cd = 2.0 * c[LINE.zeta] * math.sqrt(k * m)
    dk = c[LINE.drag_k] * c[STATION.drag_on]
    sheared = c[LINE.shear_code] != 0.0  # a wind profile: each segment's wind at its own height
    wux, wuy, wuz = c[STATION.wind], c[STATION.wind + 1], c[STATION.wind + 2]
    moved = ls_old != ls
    k_old = EA / ls_old if moved else k
    mg = m * g
    e_el = e_old = pay0 = p_damp = p_drag = 0.0
    hdx = hdy = hdz = 0.0
    tmax = 0.0
    # node i's force so far (its weight, then its winch-side segment's pull and half drag)
    gx, gy, gz = 0.0, 0.0, mg
    ax, ay, az = s[P], s[P + 1], s[P + 2]
    vax, vay, vaz = s[V], s[V + 1], s[V + 2]
    for i in range(n):
        bx, by, bz, vbx, vby, vbz = segment_end(s, n, i, vhx, vhy, vhz)
        dx, dy, dz = bx - ax, by - ay, bz - az
        d, inv, ux, uy, uz = along(dx, dy, dz)
        f, T, e, p = segment_pull(k, cd, d, ls, ux, uy, uz, vbx - vax, vby - vay, vbz - vaz)
        e_el += e
        p_damp += p
        if moved:
            so = d - ls_old
            if so > 0.0:
                e_old += 0.5 * k_old * so * so
            T0 = s[TT + i]  # the tension at the old rest length and the old positions
            if T0 > 0.0:
                sb = T0 / k_old + ls_old - ls
                pay0 += 0.5 * T0 * T0 / k_old - (0.5 * k * sb * sb if sb > 0.0 else 0.0)
        s[TT + i] = T
        if T > tmax:
            tmax = T
        fx, fy, fz = f * ux, f * uy, f * uz
        qx = qy = qz = 0.0
        if dk != 0.0:  # drag of the segment from its mid-point air velocity normal to it, half to each end node
            if sheared:
                wx, wy, wz = wind_at(c, az + 0.5 * dz)
            else:  # the uniform wind, read once (keeps the loop as fast as without a profile)
                wx, wy, wz = wux, wuy, wuz
            qx, qy, qz = cross_flow_drag(ux, uy, uz, 0.5 * (vax + vbx) - wx, 0.5 * (vay + vby) - wy,
                                         0.5 * (vaz + vbz) - wz, 0.5 * dk * d)
        fa = F + 3 * i
        s[fa] = gx + (fx + qx)
        s[fa + 1] = gy + (fy + qy)
        s[fa + 2] = gz + (fz + qz)
        if i > 0:
            p_drag += qx * vax + qy * vay + qz * vaz
        gx, gy, gz = 0.0 - fx, 0.0 - fy, mg - fz
        if i < n - 1:
            gx += qx
            gy += qy
            gz += qz
            p_drag += qx * vbx + qy * vby + qz * vbz
        else:
            hdx, hdy, hdz = qx, qy, qz
        ax, ay, az = bx, by, bz
        vax, vay, vaz = vbx, vby, vbz
    # the hook slot: the line's force on the hook only (its half mass and half drag are the glider's)
    fh = F + 3 * n
    s[fh], s[fh + 1], s[fh + 2] = gx, gy, gz - mg
    return e_el, e_old, pay0, p_damp, p_drag, hdx, hdy, hdz, tmax


def line_energies(s, n: int, m: float, g: float) -> tuple[float, float]:
    """Kinetic and potential energy of the interior nodes, J (NED: height ``-z``)."""
    P = NODES
    V = P + 3 * (n + 1)
    ek = ep = 0.0
    for i in range(1, n):
        v = V + 3 * i
        ek += 0.5 * m * (s[v] * s[v] + s[v + 1] * s[v + 1] + s[v + 2] * s[v + 2])
        ep -= m * g * s[P + 3 * i + 2]
    return ek, ep
