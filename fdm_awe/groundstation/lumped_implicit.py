"""The lumped-mass line integrated by linearly implicit Euler steps (``--tether lumped-implicit:N``).

The leapfrog of :mod:`.lumped` must resolve the line's axial waves: ``h omega_max < 2`` with
``omega_max = 2 sqrt(EA / mu) / l_s`` (20 inner steps per 1/120 s flight step at N = 30 on
150 m). Those waves cross the line in a few milliseconds (``sqrt(EA / mu)`` is about 7 km/s), so
at the flight's step rate the line answers them quasi-statically. :func:`implicit_step` takes
one step of the flight's length instead: the stiffness (axial and geometric), the axial damper and
the drag enter linearised, one block-tridiagonal solve per step. The line's low modes and its
sag follow the flight; the axial waves and the transverse modes above the step rate are damped
(by the step, besides the line's drag). Its taut set is the one at the step's end (a segment
caught or let go within the step), and the glider takes the line's mean pull over the step.
:func:`settle_implicit` finds the static shape with the same step used as a Newton step.

Plain Python over floats and arrays, compiled by numba into the line's step (:mod:`.lumped`,
whose on-disk cache follows this file).
"""

from __future__ import annotations

import math

import numpy as np

from .lumped_forces import along, line_forces, segment_end, wind_at
from .lumped_state import LINE, LINE_LEDGER, NODES
from .substeps import CONST, STATE, STATION


def implicit_step(s, c, n: int, h: float, lsa: float, lsb: float, hx1: float, hy1: float, hz1: float,
                  w) -> tuple[float, float, float, float, float, float, float, float, float]:
    """One linearly implicit Euler step of ``h`` s of the interior nodes (``lumped-implicit:N``):
    rest length from ``lsa`` to ``lsb`` m, hook from where its node stands to ``(hx1, ..)`` m; ``w`` a
    scratch array of :func:`scratch_size` floats. The force slots hold the forces at the
    start (:func:`line_forces` at the rest length ``lsa``). Books the line ledger as
    :func:`inner_steps` does and returns its sums for this one step; the force on the glider is
    the line's mean pull over the step, the mean of its pull at the start and at the end (the
    hook's work is booked by the same trapezoid, so the glider takes the work the line books).

    The velocity change ``dv`` of the interior nodes solves ``(m I + h B + sum G) dv - sum G dv'
    = h F + h^2 S (v' - v)`` (``'`` the segment's other node): every taut segment's stiffness
    ``S = k u u^T + (T / d) (I - u u^T)`` (axial and geometric) and axial damper ``c u u^T``
    enter as ``G = h c u u^T + h^2 S``, the drag's linearisation as the scalar ``B`` (its
    largest rate ``2 x 1/2 |c_l| |v_perp|`` of each adjacent half segment), the rest-length
    change as the tension change ``k (lsa - lsb)`` of the taut segments. The system is block
    tridiagonal (3 x 3 blocks, symmetric positive definite): one block-Thomas sweep. The taut
    set is the one at the step's end: a segment that goes taut within the step (the catch after
    a lull) pulls by its length at the end, one that goes slack no more, as backward Euler takes
    the piecewise-linear line; the set is found by solving again while it changes
    (:func:`back_substitute`, at most :data:`ACTIVE_PASSES` solves, one when nothing changes). Then
    ``v += dv``, ``x += h v``. Unconditionally stable for the linear part: the axial waves (a
    few ms along the line) respond quasi-statically, the transverse modes above the step rate
    are damped, the line's low modes and its sag follow the flight."""
    F = NODES + 6 * (n + 1)
    g, mu = c[STATION.g], c[CONST.mu]
    ma, mb = mu * lsa, mu * lsb
    ph = NODES + 3 * n
    # the hook node from where it stands (the last step's prediction) to (hx1, ..): a difference
    # between that prediction and the glider's real position is taken up by this step
    vhx, vhy, vhz = (hx1 - s[ph]) / h, (hy1 - s[ph + 1]) / h, (hz1 - s[ph + 2]) / h
    first = True
    for _ in range(ACTIVE_PASSES):  # the taut set: the segments taut at the step's end
        assemble(s, c, n, h, lsa, lsb, vhx, vhy, vhz, w, first)
        forward_sweep(n, w)
        first = False
        if back_substitute(s, n, h, lsb, vhx, vhy, vhz, w) == 0:
            break
    e_mass = apply_step(s, n, h, ma, mb, g, w)
    fh = F + 3 * n
    fgx, fgy, fgz = s[fh], s[fh + 1], s[fh + 2]
    dhx, dhy, dhz = hx1 - s[ph], hy1 - s[ph + 1], hz1 - s[ph + 2]
    s[ph], s[ph + 1], s[ph + 2] = hx1, hy1, hz1
    e_el, e_old, pay0, p_damp, p_drag, hdx, hdy, hdz, tm = line_forces(s, c, n, lsb, mb, vhx, vhy, vhz, lsa)
    fgx1, fgy1, fgz1 = s[fh], s[fh + 1], s[fh + 2]
    s[LINE_LEDGER.hook_work] -= 0.5 * ((fgx + fgx1) * dhx + (fgy + fgy1) * dhy + (fgz + fgz1) * dhz)
    s[LINE_LEDGER.mass_inflow] += e_mass
    if lsb != lsa:
        s[LINE_LEDGER.payout_work] += 0.5 * (pay0 + e_old - e_el)
    s[LINE_LEDGER.drag] -= h * p_drag
    s[LINE_LEDGER.damping] += h * p_damp
    TT = F + 3 * (n + 1)
    # the glider takes the line's mean pull over the step (the trapezoid of the hook work above)
    fmx, fmy, fmz = 0.5 * (fgx + fgx1), 0.5 * (fgy + fgy1), 0.5 * (fgz + fgz1)
    return (fmx + hdx, fmy + hdy, fmz + hdz + 0.5 * mb * g, hdx, hdy, hdz, 0.5 * mb * g, s[TT + n - 1], tm)


#: most assemblies and solves of one implicit step while its taut set changes (:func:`back_substitute`)
ACTIVE_PASSES = 8


def scratch_size(n: int) -> int:
    """Floats of :func:`implicit_step`'s scratch array for ``n`` segments (:func:`scratch_offsets`)."""
    return 18 * (n + 1)


def scratch_offsets(n: int) -> tuple[int, int, int, int, int, int, int]:
    """Where :func:`implicit_step`'s scratch array keeps, for ``n`` segments: per segment its
    unit vector (3) and ``alpha, beta`` of ``G = alpha u u^T + beta I``; per node the right-hand
    side (3; then ``y`` of the sweep, then the velocity change ``dv``), the diagonal's scalar
    ``m + h B`` and ``D^-1`` (6: xx, yy, zz, xy, xz, yz); per segment its length at the step's
    start and whether it is in the taut set (1.0 / 0.0). Returns the seven starts; the array
    needs :func:`scratch_size` floats."""
    SU = 0
    SG = SU + 3 * n
    R = SG + 2 * n
    BN = R + 3 * (n + 1)
    DI = BN + (n + 1)
    SD = DI + 6 * (n + 1)
    AS = SD + n
    return SU, SG, R, BN, DI, SD, AS


def assemble(s, c, n: int, h: float, lsa: float, lsb: float, vhx: float, vhy: float, vhz: float, w,
             first: bool) -> None:
    """The system of :func:`implicit_step` into ``w`` (:func:`scratch_offsets`): the right-hand
    side ``h F + h^2 S (v' - v)`` with the rest-length change, each taut segment's ``G``, each
    node's ``m + h B``; the hook moving with ``(vhx, vhy, vhz)`` m/s. The taut set: with
    ``first`` the segments longer than ``lsb`` at the start (written into ``w``), else the set
    in ``w`` (:func:`back_substitute`). A segment of the set whose start force is not in ``F``
    (slack at the rest length ``lsa``) enters with its whole force at the start, ``k (d - lsb) +
    c u.(v' - v)``; one outside the set whose start force is in ``F`` has it taken out (its
    tension from the state, its damper at the present velocities): the step's end force is
    then the set's, as backward Euler takes it."""
    P = NODES
    V = P + 3 * (n + 1)
    F = V + 3 * (n + 1)
    TT = F + 3 * (n + 1)
    k = c[CONST.EA] / lsb
    mb = c[CONST.mu] * lsb
    cdamp = 2.0 * c[LINE.zeta] * math.sqrt(k * mb)
    ka = c[CONST.EA] / lsa
    cda = 2.0 * c[LINE.zeta] * math.sqrt(ka * c[CONST.mu] * lsa)
    dk = c[LINE.drag_k] * c[STATION.drag_on]
    sheared = c[LINE.shear_code] != 0.0
    wux, wuy, wuz = c[STATION.wind], c[STATION.wind + 1], c[STATION.wind + 2]
    SU, SG, R, BN, DI, SD, AS = scratch_offsets(n)
    for j in range(n + 1):
        f = F + 3 * j
        r = R + 3 * j
        w[r], w[r + 1], w[r + 2] = h * s[f], h * s[f + 1], h * s[f + 2]
        w[BN + j] = mb
    ax, ay, az = s[P], s[P + 1], s[P + 2]
    vax, vay, vaz = 0.0, 0.0, 0.0
    for i in range(n):
        bx, by, bz, vbx, vby, vbz = segment_end(s, n, i, vhx, vhy, vhz)
        dx, dy, dz = bx - ax, by - ay, bz - az
        d, inv, ux, uy, uz = along(dx, dy, dz)
        su = SU + 3 * i
        w[su], w[su + 1], w[su + 2] = ux, uy, uz
        w[SD + i] = d
        if first:
            w[AS + i] = 1.0 if d > lsb else 0.0
        taut = w[AS + i] != 0.0
        rvx, rvy, rvz = vbx - vax, vby - vay, vbz - vaz
        ur = ux * rvx + uy * rvy + uz * rvz
        sc, gt, alpha = segment_terms(h, k, cdamp, cda, d, inv, lsa, lsb, ur, taut, s[TT + i])
        beta = gt
        if sc != 0.0 or gt != 0.0:  # on node a (+) and node b (-)
            gx = sc * ux + gt * rvx
            gy = sc * uy + gt * rvy
            gz = sc * uz + gt * rvz
            ra, rb = R + 3 * i, R + 3 * i + 3
            w[ra] += gx
            w[ra + 1] += gy
            w[ra + 2] += gz
            w[rb] -= gx
            w[rb + 1] -= gy
            w[rb + 2] -= gz
        w[SG + 2 * i], w[SG + 2 * i + 1] = alpha, beta
        if dk != 0.0:  # the drag's rate on both end nodes (h times it on the diagonal)
            if sheared:
                wx, wy, wz = wind_at(c, az + 0.5 * dz)
            else:
                wx, wy, wz = wux, wuy, wuz
            mx, my, mz = 0.5 * (vax + vbx) - wx, 0.5 * (vay + vby) - wy, 0.5 * (vaz + vbz) - wz
            mr = mx * ux + my * uy + mz * uz
            px, py, pz = mx - mr * ux, my - mr * uy, mz - mr * uz
            bd = h * 0.5 * abs(dk) * d * math.sqrt(px * px + py * py + pz * pz)
            w[BN + i] += bd
            w[BN + i + 1] += bd
        ax, ay, az = bx, by, bz
        vax, vay, vaz = vbx, vby, vbz


def segment_terms(h: float, k: float, cdamp: float, cda: float, d: float, inv: float, lsa: float, lsb: float,
                  ur: float, taut: bool, t0: float) -> tuple[float, float, float]:
    """One segment's terms in :func:`assemble`'s system: ``(sc, gt, alpha)``, its right-hand side
    ``sc u + gt (v' - v)`` on its winch-side node (the opposite on the other) and ``G = alpha u
    u^T + gt I``. Length ``d`` m (``inv`` = 1/d), stretch rate ``ur`` m/s, stiffness ``k`` N/m
    and damper ``cdamp`` N s/m at the rest length ``lsb``, ``cda`` at ``lsa``; ``taut``: in the
    set, ``t0``: its tension at the start (> 0: its start force is in ``F``)."""
    h2 = h * h
    in_f = t0 > 0.0
    if taut:  # its force at the step's end: h^2 S (v_b - v_a) and the rest-length change's tension
        tg = k * (d - lsb) if d > lsb else 0.0
        gt = h2 * tg * inv
        sc = h2 * (k - tg * inv) * ur
        if in_f:
            sc += h * k * (lsa - lsb)
        else:  # caught within the step: its whole force, not in F
            sc += h * (k * (d - lsb) + cdamp * ur)
        return sc, gt, h * cdamp + h2 * k - gt
    if in_f:  # slack by the step's end: its start force out of F
        return -h * (t0 + cda * ur), 0.0, 0.0
    return 0.0, 0.0, 0.0


def forward_sweep(n: int, w) -> None:
    """The block-Thomas forward sweep over the interior nodes ``1 .. n-1`` of the system in
    ``w`` (:func:`assemble`): ``D_j = A_jj - G D_{j-1}^-1 G``, ``y_j = r_j + G D_{j-1}^-1
    y_{j-1}``; keeps ``D_j^-1`` (by cofactors) and ``y_j``."""
    SU, SG, R, BN, DI, SD, AS = scratch_offsets(n)
    # forward sweep over the interior nodes 1 .. n-1: D_j = A_jj - G D_{j-1}^-1 G, y_j = r_j + G D_{j-1}^-1 y_{j-1}
    for j in range(1, n):
        al0, be0 = w[SG + 2 * (j - 1)], w[SG + 2 * (j - 1) + 1]  # the segment j-1 (nodes j-1, j)
        al1, be1 = w[SG + 2 * j], w[SG + 2 * j + 1]  # the segment j (nodes j, j+1)
        s0, s1 = SU + 3 * (j - 1), SU + 3 * j
        u0x, u0y, u0z = w[s0], w[s0 + 1], w[s0 + 2]
        u1x, u1y, u1z = w[s1], w[s1 + 1], w[s1 + 2]
        dg = w[BN + j] + be0 + be1
        axx = dg + al0 * u0x * u0x + al1 * u1x * u1x
        ayy = dg + al0 * u0y * u0y + al1 * u1y * u1y
        azz = dg + al0 * u0z * u0z + al1 * u1z * u1z
        axy = al0 * u0x * u0y + al1 * u1x * u1y
        axz = al0 * u0x * u0z + al1 * u1x * u1z
        ayz = al0 * u0y * u0z + al1 * u1y * u1z
        r = R + 3 * j
        yx, yy, yz = w[r], w[r + 1], w[r + 2]
        if j > 1 and (al0 != 0.0 or be0 != 0.0):
            q = DI + 6 * (j - 1)
            ixx, iyy, izz, ixy, ixz, iyz = w[q], w[q + 1], w[q + 2], w[q + 3], w[q + 4], w[q + 5]
            # p = D^-1 u; G D^-1 G = al^2 (u.p) u u^T + al be (u p^T + p u^T) + be^2 D^-1
            px = ixx * u0x + ixy * u0y + ixz * u0z
            py = ixy * u0x + iyy * u0y + iyz * u0z
            pz = ixz * u0x + iyz * u0y + izz * u0z
            up = u0x * px + u0y * py + u0z * pz
            a2, ab, b2 = al0 * al0 * up, al0 * be0, be0 * be0
            axx -= a2 * u0x * u0x + 2.0 * ab * u0x * px + b2 * ixx
            ayy -= a2 * u0y * u0y + 2.0 * ab * u0y * py + b2 * iyy
            azz -= a2 * u0z * u0z + 2.0 * ab * u0z * pz + b2 * izz
            axy -= a2 * u0x * u0y + ab * (u0x * py + px * u0y) + b2 * ixy
            axz -= a2 * u0x * u0z + ab * (u0x * pz + px * u0z) + b2 * ixz
            ayz -= a2 * u0y * u0z + ab * (u0y * pz + py * u0z) + b2 * iyz
            rp = R + 3 * (j - 1)  # y_{j-1}, then q = D^-1 y_{j-1}, G q
            qx = ixx * w[rp] + ixy * w[rp + 1] + ixz * w[rp + 2]
            qy = ixy * w[rp] + iyy * w[rp + 1] + iyz * w[rp + 2]
            qz = ixz * w[rp] + iyz * w[rp + 1] + izz * w[rp + 2]
            uq = al0 * (u0x * qx + u0y * qy + u0z * qz)
            yx += uq * u0x + be0 * qx
            yy += uq * u0y + be0 * qy
            yz += uq * u0z + be0 * qz
        w[r], w[r + 1], w[r + 2] = yx, yy, yz
        # the symmetric inverse by cofactors
        cxx = ayy * azz - ayz * ayz
        cxy = axz * ayz - axy * azz
        cxz = axy * ayz - axz * ayy
        det = axx * cxx + axy * cxy + axz * cxz
        idet = 1.0 / det
        q = DI + 6 * j
        w[q] = cxx * idet
        w[q + 1] = (axx * azz - axz * axz) * idet
        w[q + 2] = (axx * ayy - axy * axy) * idet
        w[q + 3] = cxy * idet
        w[q + 4] = cxz * idet
        w[q + 5] = (axy * axz - axx * ayz) * idet


def back_substitute(s, n: int, h: float, lsb: float, vhx: float, vhy: float, vhz: float, w) -> int:
    """The back substitution ``dv_j = D_j^-1 (y_j + G_j dv_{j+1})`` of the system in ``w`` (the
    interior nodes' velocity changes ``dv_j`` in place of ``y_j``) and, in the same pass, the
    taut set they give: a segment is in it when its length at the step's end, to first order
    ``d + h u.(v' + dv' - v - dv)``, exceeds the rest length ``lsb`` m (the hook moving with
    ``(vhx, vhy, vhz)`` m/s, the winch node at rest). Rewrites the set in ``w``; returns how
    many segments changed."""
    V = NODES + 3 * (n + 1)
    SU, SG, R, BN, DI, SD, AS = scratch_offsets(n)
    changed = 0
    nx = ny = nz = 0.0  # dv of node j+1 (0 beyond the last interior node)
    bx, by, bz = vhx, vhy, vhz  # the new velocity of node j+1
    for j in range(n - 1, -1, -1):
        if j > 0:
            r = R + 3 * j
            yx, yy, yz = w[r], w[r + 1], w[r + 2]
            if j < n - 1:
                al1, be1 = w[SG + 2 * j], w[SG + 2 * j + 1]
                s1 = SU + 3 * j
                u1x, u1y, u1z = w[s1], w[s1 + 1], w[s1 + 2]
                un = al1 * (u1x * nx + u1y * ny + u1z * nz)
                yx += un * u1x + be1 * nx
                yy += un * u1y + be1 * ny
                yz += un * u1z + be1 * nz
            q = DI + 6 * j
            ixx, iyy, izz, ixy, ixz, iyz = w[q], w[q + 1], w[q + 2], w[q + 3], w[q + 4], w[q + 5]
            nx = ixx * yx + ixy * yy + ixz * yz
            ny = ixy * yx + iyy * yy + iyz * yz
            nz = ixz * yx + iyz * yy + izz * yz
            w[r], w[r + 1], w[r + 2] = nx, ny, nz
            v = V + 3 * j
            ax, ay, az = s[v] + nx, s[v + 1] + ny, s[v + 2] + nz
        else:
            ax = ay = az = 0.0
        # the segment j (nodes j, j+1) at the step's end
        su = SU + 3 * j
        dn = w[SD + j] + h * (w[su] * (bx - ax) + w[su + 1] * (by - ay) + w[su + 2] * (bz - az))
        taut = 1.0 if dn > lsb else 0.0
        if taut != w[AS + j]:
            w[AS + j] = taut
            changed += 1
        bx, by, bz = ax, ay, az
    return changed


def apply_step(s, n: int, h: float, ma: float, mb: float, g: float, w) -> float:
    """The interior nodes' new velocities and positions from the solve in ``w`` (``v += dv``,
    ``x += h v``); returns the energy of the mass paid out with them (node mass ``ma`` -> ``mb``
    kg), J."""
    P = NODES
    V = P + 3 * (n + 1)
    SU, SG, R, BN, DI, SD, AS = scratch_offsets(n)
    e_mass = 0.0
    for j in range(n - 1, 0, -1):
        r = R + 3 * j
        v = V + 3 * j
        pp = P + 3 * j
        vx, vy, vz = s[v] + w[r], s[v + 1] + w[r + 1], s[v + 2] + w[r + 2]
        s[v], s[v + 1], s[v + 2] = vx, vy, vz
        pz = s[pp + 2] + h * vz
        s[pp] += h * vx
        s[pp + 1] += h * vy
        s[pp + 2] = pz
        if mb != ma:
            e_mass += (mb - ma) * (0.5 * (vx * vx + vy * vy + vz * vz) - g * pz)
    return e_mass


def implicit_line(s, c, N: int, n: int, dt: float, l_start: float, x: float, y: float, z: float, vx: float, vy: float,
                  vz: float) -> tuple[float, float, float, float, float, float, float, float, float, int, bool]:
    """The line over a flight step of ``dt`` s after the drum's ``n`` sub-steps: ``m`` implicit
    steps (:func:`implicit_count`), the paid-out length from ``l_start`` m to the drum's, the hook
    from ``(x, y, z)`` m moving with ``(vx, vy, vz)`` m/s. Returns the sums of the leapfrog's
    step over the drum's sub-steps (each implicit step weighs ``n / m``): the force on the
    glider, the glider-end tension, its half-drag and half-weight parts, then the largest
    tension N, the steps and whether the line snapped (above its breaking load: stopped there)."""
    m = implicit_count(c, dt)
    w = np.empty(scratch_size(N))
    l_end = s[STATE.length]
    wt = n / m  # each step's share of the sums over the drum's n sub-steps
    sfx = sfy = sfz = stg = sdx = sdy = sdz = swz = tmax = 0.0
    for q in range(m):
        b = (q + 1) * dt / m
        la = l_start + (l_end - l_start) * q / m
        lb = l_start + (l_end - l_start) * (q + 1) / m
        fx_, fy_, fz_, dx_, dy_, dz_, wz_, tg_, tm_ = implicit_step(s, c, N, dt / m, la / N, lb / N, x + b * vx,
                                                                    y + b * vy, z + b * vz, w)
        sfx += fx_ * wt
        sfy += fy_ * wt
        sfz += fz_ * wt
        stg += tg_ * wt
        sdx += dx_ * wt
        sdy += dy_ * wt
        sdz += dz_ * wt
        swz += wz_ * wt
        if tm_ > tmax:
            tmax = tm_
        if tm_ > c[CONST.Tbreak]:
            return sfx, sfy, sfz, stg, sdx, sdy, sdz, swz, tmax, q + 1, True
    return sfx, sfy, sfz, stg, sdx, sdy, sdz, swz, tmax, m, False


def implicit_count(c, dt: float) -> int:
    """Implicit steps per ``dt`` s: ``dt / h_implicit`` rounded up."""
    return max(1, int(math.ceil(dt / c[LINE.h_implicit] - 1e-9)))


def settle_implicit(s, c, n: int, x: float, y: float, z: float) -> None:
    """The static shape to the hook at ``(x, y, z)`` m by 40 implicit steps of 0.5 s from rest,
    each from the forces at rest: with ``h`` that long the step is a Newton step on the static
    equations (``(m / h^2 + K) dx = F``, the mass term its damping); the ledger is not kept."""
    ls = s[STATE.length] / n
    m = c[CONST.mu] * ls
    w = np.empty(scratch_size(n))
    V = NODES + 3 * (n + 1)
    for _ in range(40):
        for i in range(3 * (n + 1)):
            s[V + i] = 0.0
        line_forces(s, c, n, ls, m, 0.0, 0.0, 0.0, ls)
        implicit_step(s, c, n, 0.5, ls, ls, x, y, z, w)
    for i in range(3 * (n + 1)):
        s[V + i] = 0.0
    line_forces(s, c, n, ls, m, 0.0, 0.0, 0.0, ls)
