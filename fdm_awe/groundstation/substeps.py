"""The drivetrain's sub-step loop as one function of floats, compiled with numba when available.

:meth:`fdm_awe.groundstation.drivetrain.Drivetrain.advance` is the reference: its Python loop
is the model (backward Euler for line, drum, armature and link at once; see that module).
:func:`substeps` is the same loop, the same operations in the same order, written on plain
scalars so that numba compiles it (``cache=True``: compiled once per installation, loaded from
the cache afterwards). Round-off is identical (no fast-math), and a test runs both on the
same scenarios and compares every state and ledger term for exact equality.

:func:`station_step` is the whole :meth:`GroundStation.step` on the line in the same way (the
coefficients, the set-up of :meth:`Drivetrain.advance`, this loop, the ledger accumulation, the
force on the glider and the machine mode): one compiled call per flight step, on the
drivetrain's state array (states and ledger, updated in place). Its reference is the Python
code of ``GroundStation.step`` and ``Drivetrain.advance``; a test compares both bit for bit.

:func:`compiled` / :func:`compiled_station` return the compiled functions, or None when numba
is not installed or ``FDM_AWE_JIT=0`` is set in the environment; the ground station then runs
its Python code.
"""

from __future__ import annotations

import functools
import math
import os
import warnings
from typing import Callable

import numpy as np

#: Event codes returned by :func:`substeps` (0: none).
EVENTS = (None, "tether_fully_reeled_in", "tether_fully_paid_out", "tether_break")


def drum_speed(J: float, w0: float, h: float, B: float, Mc: float, r: float,
               tA: float, tB: float, K: float, iA: float, iB: float) -> tuple[float, float]:
    """:func:`fdm_awe.groundstation.winch.solve_drum_speed` without lists (same operations,
    same results): the drum speed w (rad/s) and friction torque M_f (N m) of one sub-step."""
    hM = h * Mc
    R0 = -J * w0 - h * r * (tA if tA > 0.0 else 0.0) + h * K * (iA if iA > 0.0 else 0.0)
    if R0 + hM < 0.0:
        c, sgn = -hM, 1.0
    elif R0 - hM > 0.0:
        c, sgn = hM, -1.0
    else:
        return 0.0, -R0 / h  # stuck: friction holds the drum, |M_f| <= Mc
    g = w0 if w0 * sgn > 0.0 else sgn * 1e-9
    tg = tA - tB * g > 0.0
    ig = iA + iB * g > 0.0
    w = _piece(J, w0, h, B, r, tA, tB, K, iA, iB, c, tg, ig)
    if w * sgn > 0.0 and (tA - tB * w > 0.0) == tg and (iA + iB * w > 0.0) == ig:
        return w, sgn * Mc
    # kinks of the piecewise-linear residual on the half-line of sgn, ascending
    nk = 0
    k1 = k2 = 0.0
    if tB > 0.0:
        kk = tA / tB
        if kk * sgn > 0.0:
            k1 = kk
            nk = 1
    if iB > 0.0:
        kk = -iA / iB
        if kk * sgn > 0.0:
            if nk == 0:
                k1 = kk
            elif kk < k1:
                k2 = k1
                k1 = kk
            else:
                k2 = kk
            nk += 1
    inf = math.inf
    for j in range(nk + 1):
        if sgn > 0.0:  # edges 0, k1, k2 then +inf
            lo = 0.0 if j == 0 else (k1 if j == 1 else k2)
            hi = inf if j == nk else (k1 if j == 0 else k2)
        else:  # -inf, then edges k1, k2, 0
            lo = -inf if j == 0 else (k1 if j == 1 else k2)
            hi = 0.0 if j == nk else (k1 if j == 0 else k2)
        if lo != -inf and hi != inf:
            m = 0.5 * (lo + hi)
        else:
            m = lo + 1.0 if hi == inf else hi - 1.0
        w = _piece(J, w0, h, B, r, tA, tB, K, iA, iB, c, tA - tB * m > 0.0, iA + iB * m > 0.0)
        if lo - 1e-12 * (1.0 + abs(lo)) <= w <= hi + 1e-12 * (1.0 + abs(hi)):
            return w, sgn * Mc
    return w, sgn * Mc  # unreachable for consistent inputs (monotone residual)


def _piece(J: float, w0: float, h: float, B: float, r: float, tA: float, tB: float, K: float,
           iA: float, iB: float, c: float, t_on: bool, i_on: bool) -> float:
    """Root of the linear piece of R(w) = c with the given active tension/current terms."""
    a = -J * w0
    b = J + h * B
    if t_on:
        a -= h * r * tA
        b += h * r * tB
    if i_on:
        a += h * K * iA
        b += h * K * iB
    return (c - a) / b


def substeps(n, h, px, py, pz, hvx, hvy, hvz, pi, motor, fixed, broken, at_stop,  # noqa: C901
             l0, w0, i0, u0, integ, duty, v_src, d0, s0, k, tB, J, Jb, omega_ref, fixed_tension, e_glider, c):
    """``n`` sub-steps of :meth:`Drivetrain.advance` (see there for the model and the names).

    ``e_glider`` is the glider work booked before the loop (J). ``c`` holds the constants in
    the order of :data:`CONSTANTS` (a float array: the cheapest argument to pass). Returns the end states
    ``(l, omega, i, u_L, integ, duty, broken, at_stop, s, k)``, the event code (index into
    :data:`EVENTS`), and the step's energy sums ``(e_glider, e_supply, e_stop, e_brk, e_numel,
    S_u2, S_i2, S_i, S_fw, S_w2, S_Tw, S_iw, S_dw2, S_di2, S_du2, t_sum)``.
    """
    r, B, Mc, K, Va, two_ud, lmin, lmax = c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7]
    Tbreak, q, cu, aL, aH, aS, iB, hr = c[8], c[9], c[10], c[11], c[12], c[13], c[14], c[15]
    hK, hM, kp, ki, d_min, d_max = c[16], c[17], c[18], c[19], c[20], c[21]
    event = 0
    e_supply = e_stop = e_brk = e_numel = 0.0
    S_u2 = S_i2 = S_i = S_fw = S_w2 = S_Tw = S_iw = S_dw2 = S_di2 = S_du2 = 0.0
    t_sum = 0.0
    line = not (fixed or broken)
    t_on = i_on = True
    d1 = 0.0
    for _ in range(n):
        if pi:  # controller module: PI sample on the measured drum speed
            err = w0 - omega_ref
            u_ = kp * err + integ
            if u_ > d_max:
                duty, hold = d_max, err > 0.0
            elif u_ < d_min:
                duty, hold = d_min, err < 0.0
            else:
                duty, hold = u_, False
            if not hold:
                integ += ki * err * h
                if integ > d_max:
                    integ = d_max
                elif integ < d_min:
                    integ = d_min
            v_src = duty * Va
        iA = aL * i0 + aH * (v_src - two_ud) - aS * u0
        if line:
            px += hvx
            py += hvy
            pz += hvz
            d1 = math.sqrt(px * px + py * py + pz * pz)
            tA = k * (d1 - l0)
        elif broken:
            tA = 0.0
        else:
            tA = fixed_tension
        if w0 != 0.0:
            a_ = -J * w0
            b_ = Jb
            if t_on:
                a_ -= hr * tA
                b_ += hr * tB
            if i_on:
                a_ += hK * iA
                b_ += hK * iB
            if w0 > 0.0:
                w1 = (-hM - a_) / b_
                ok = w1 > 0.0
                mf = Mc
            else:
                w1 = (hM - a_) / b_
                ok = w1 < 0.0
                mf = -Mc
            if not (ok and (tA - tB * w1 > 0.0) == t_on and (iA + iB * w1 > 0.0) == i_on):
                w1, mf = drum_speed(J, w0, h, B, Mc, r, tA, tB, K, iA, iB)
        else:
            w1, mf = drum_speed(J, w0, h, B, Mc, r, tA, tB, K, iA, iB)
        l1 = l0 + hr * w1
        if (l1 < lmin and w1 < 0.0) or (l1 > lmax and w1 > 0.0):  # drum end stops
            w1 = ((lmin if w1 < 0.0 else lmax) - l0) / hr
            if w1 * (l1 - l0) <= 0.0:
                w1 = 0.0
            l1 = l0 + hr * w1
            mf = Mc if w1 > 0.0 else (-Mc if w1 < 0.0 else 0.0)
            if not at_stop:
                event = 1 if l1 < 0.5 * (lmin + lmax) else 2
            at_stop = True
            i1 = iA + iB * w1
            T1 = tA - tB * w1
            tau_stop = J * (w1 - w0) / h - (r * (T1 if T1 > 0.0 else 0.0) - K * (i1 if i1 > 0.0 else 0.0) - B * w1 - mf)
            e_stop += -h * tau_stop * w1 + 0.5 * J * (w1 - w0) ** 2
            S_dw2 -= (w1 - w0) ** 2
        else:
            at_stop = False
        i1 = iA + iB * w1
        i_on = i1 > 0.0
        if not i_on:
            i1 = 0.0
        u1 = cu * u0 + q * i1
        T1 = tA - tB * w1
        t_on = T1 > 0.0
        if not t_on:
            T1 = 0.0
        S_u2 += u1 * u1
        S_i2 += i1 * i1
        S_i += i1
        S_iw += i1 * w1
        S_fw += mf * w1
        S_w2 += w1 * w1
        S_Tw += T1 * w1
        dw = w1 - w0
        di = i1 - i0
        du = u1 - u0
        S_dw2 += dw * dw
        S_di2 += di * di
        S_du2 += du * du
        if motor:
            e_supply += v_src * i1
        if line:
            s1 = d1 - l1
            e_glider += T1 * (d1 - d0)
            s1p = s1 if s1 > 0.0 else 0.0
            s0p = s0 if s0 > 0.0 else 0.0
            e_numel += T1 * (s1 - s0) - 0.5 * k * (s1p * s1p - s0p * s0p)
            if T1 > Tbreak:  # the line breaks at the end of this sub-step
                broken = True
                line = False
                event = 3
                e_brk += 0.5 * k * s1p * s1p
                s1 = 0.0
                k = tB = 0.0
            d0, s0 = d1, s1
        elif fixed:
            e_glider += T1 * hr * w1
        t_sum += T1
        l0, w0, i0, u0 = l1, w1, i1, u1
    return (l0, w0, i0, u0, integ, duty, broken, at_stop, s0, k, event,
            e_glider, e_supply, e_stop, e_brk, e_numel,
            S_u2, S_i2, S_i, S_fw, S_w2, S_Tw, S_iw, S_dw2, S_di2, S_du2, t_sum)


#: Names of the constants tuple ``c`` of :func:`substeps`.
CONSTANTS = ("r", "B", "Mc", "K", "Va", "two_ud", "lmin", "lmax", "Tbreak", "q", "cu", "aL", "aH", "aS",
             "iB", "hr", "hK", "hM", "kp", "ki", "d_min", "d_max")

#: The drivetrain's states at the head of its state array (``broken``, ``at_stop`` 0/1,
#: ``motor`` 1 in motor mode); the energy ledger's terms follow (``ledger.FIELDS`` order).
STATE = ("length", "omega", "current", "u_link", "integ", "duty", "broken", "at_stop", "stretch", "motor")
_NS = len(STATE)
# ledger terms, offsets in the state array (ledger.FIELDS order)
(_GLIDER_WORK, _SUPPLY, _WOUND, _STRAIN, _LOAD, _COPPER, _SEMI, _COULOMB, _VISCOUS, _END_STOP, _BREAK,
 _NUMERICAL, _DRUM, _AIRGAP, _DRAG_W, _WEIGHT_W, _S0K, _S0I, _S0C, _S0E, _SK, _SI, _SC, _SE) = range(_NS, _NS + 24)

#: Names of the constants array ``c`` of :func:`station_step` (from the definitions and the
#: ground station's line-share factors; fixed for a station).
STATION_CONSTANTS = ("r", "B", "Mc", "Jw", "mu", "EA", "Tbreak", "lmin", "lmax", "K", "R", "L", "two_ud", "Va",
                     "C", "kp", "ki", "d_min", "d_max", "wind_n", "wind_e", "wind_d", "drag_c", "drag_on",
                     "weight_c", "g")


def station_step(s, c, n, dt, x, y, z, vx, vy, vz, motor, omega_ref, duty_cmd, boost_duty, RL):  # noqa: C901
    """One flight step of :meth:`fdm_awe.groundstation.station.GroundStation.step` on the line
    (coefficients, :meth:`Drivetrain.advance`'s set-up, the sub-step loop :func:`substeps`, the
    ledger, the force on the glider and the machine mode) in one call, written on scalars for
    numba: the same operations in the same order as the Python reference, identical results.

    ``s`` the state array (:data:`STATE`, then the ledger; updated in place), ``c`` the
    constants (:data:`STATION_CONSTANTS`), ``n`` sub-steps in ``dt`` s, the hook position (m)
    and velocity (m/s) NED, ``motor`` the converter mode, ``omega_ref`` rad/s, ``duty_cmd`` the
    open-loop T1 duty (NaN: PI), ``boost_duty``, ``RL`` ohm. Returns ``(fx, fy, fz, mean tension,
    length, omega, current, duty, u_link, p_electrical, event code, machine mode code (0 idle,
    1 generator, 2 motor), distance, slack, broken)``.
    """
    r, B, Mc, Jw, mu, EA, Tbreak, lmin, lmax = c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7], c[8]
    K, R, L, two_ud, Va, C, kp, ki, d_min, d_max = c[9], c[10], c[11], c[12], c[13], c[14], c[15], c[16], c[17], c[18]
    h = dt / n
    if motor != (s[9] != 0.0):  # mode switch (drivetrain: the PI integrator restarts at 0)
        if motor:
            s[4] = 0.0
        s[9] = 1.0 if motor else 0.0
    # converter / armature coefficients (converter.link_coefficients, machine.armature_coefficients)
    s_cpl = 0.0 if motor else 1.0 - boost_duty
    den = C + h / RL
    cu, q = C / den, h * s_cpl / den
    D = L + h * R + h * s_cpl * q
    aL, aH, iB = L / D, h / D, h * K / D
    kc = np.empty(22)
    kc[0], kc[1], kc[2], kc[3], kc[4], kc[5], kc[6], kc[7], kc[8] = r, B, Mc, K, Va, two_ud, lmin, lmax, Tbreak
    kc[9], kc[10], kc[11], kc[12], kc[13], kc[14] = q, cu, aL, aH, aH * s_cpl * cu, iB
    hr = h * r
    kc[15], kc[16], kc[17] = hr, h * K, h * Mc
    kc[18], kc[19], kc[20], kc[21] = kp, ki, d_min, d_max
    hB = h * B
    l_start = s[0]
    J = Jw + mu * l_start * r * r
    Jb = J + hB
    integ, duty, broken, at_stop = s[4], s[5], s[6] != 0.0, s[7] != 0.0
    e_glider = 0.0
    k = 0.0 if broken else EA / l_start
    tB = 0.0 if broken else k * hr
    if broken:
        s0 = d0 = 0.0
    else:
        d0 = math.sqrt(x * x + y * y + z * z)
        s0 = d0 - l_start
        a_ = s0 if s0 > 0.0 else 0.0
        b_ = s[8] if s[8] > 0.0 else 0.0
        e_glider += 0.5 * k * (a_ * a_ - b_ * b_)
    v_src = 0.0
    pi = motor and duty_cmd != duty_cmd
    if motor:
        if not pi:
            duty = duty_cmd
            v_src = duty * Va
    else:
        duty = boost_duty
    (l0, w0, i0, u0, integ, duty, broken, at_stop, s0, k, ev, e_glider, e_supply, e_stop, e_brk, e_numel,
     S_u2, S_i2, S_i, S_fw, S_w2, S_Tw, S_iw, S_dw2, S_di2, S_du2, t_sum) = substeps(
        n, h, x, y, z, h * vx, h * vy, h * vz, pi, motor, False, broken, at_stop, l_start, s[1], s[2], s[3],
        integ, duty, v_src, d0, s0, k, tB, J, Jb, omega_ref, 0.0, e_glider, kc)
    # Drivetrain.advance: states and ledger
    s[7] = 1.0 if at_stop else 0.0
    s[0], s[1], s[2], s[3] = l0, w0, i0, u0
    s[4], s[5], s[6] = integ, duty, 1.0 if broken else 0.0
    stretch = s0 if not broken else 0.0
    s[8] = stretch
    s[_GLIDER_WORK] += e_glider
    s[_SUPPLY] += h * e_supply
    J_end = Jw + mu * l0 * r * r
    s[_WOUND] += 0.5 * (J_end - J) * w0 * w0
    sp = stretch if stretch > 0.0 else 0.0
    k_end = 0.0 if broken else EA / l0
    s[_STRAIN] += 0.5 * (k_end - k) * sp * sp
    s[_LOAD] += h * S_u2 / RL
    s[_COPPER] += h * R * S_i2
    s[_SEMI] += h * two_ud * S_i
    s[_COULOMB] += h * S_fw
    s[_VISCOUS] += h * B * S_w2
    s[_END_STOP] += e_stop
    s[_BREAK] += e_brk
    s[_NUMERICAL] += 0.5 * (J * S_dw2 + L * S_di2 + C * S_du2) + e_numel
    s[_DRUM] += h * r * S_Tw
    s[_AIRGAP] += h * K * S_iw
    s[_SK], s[_SI], s[_SC], s[_SE] = 0.5 * J_end * w0 * w0, 0.5 * L * i0 * i0, 0.5 * C * u0 * u0, 0.5 * k_end * sp * sp
    tmean, pload, psup = t_sum / n, S_u2 / (RL * n), e_supply / n
    # GroundStation.step: the force on the glider (line tension, drag and weight shares)
    d = math.sqrt(x * x + y * y + z * z)
    if broken and ev != 3:
        fx = fy = fz = 0.0
    else:
        if d <= 0.0 or c[23] == 0.0:
            fx = fy = fz = 0.0
        else:
            vax, vay, vaz = vx - c[19], vy - c[20], vz - c[21]
            ux, uy, uz = x / d, y / d, z / d
            vr = vax * ux + vay * uy + vaz * uz
            px, py, pz = vax - vr * ux, vay - vr * uy, vaz - vr * uz
            cd = c[22] * l_start * math.sqrt(px * px + py * py + pz * pz)
            fx, fy, fz = cd * px, cd * py, cd * pz
        s[_DRAG_W] += (fx * vx + fy * vy + fz * vz) * dt
        fw = c[24] * l_start * c[25]
        s[_WEIGHT_W] += fw * vz * dt
        fz += fw
        if d > 0.0 and tmean > 0.0:
            ct = -tmean / d
            fx += ct * x
            fy += ct * y
            fz += ct * z
    # machine.machine_mode (eq. 17 sign rule)
    if w0 == 0.0 or i0 <= 0.0:
        mm = 0
    elif -(1.0 if w0 > 0.0 else -1.0) * K * i0 < 0.0:
        mm = 1
    else:
        mm = 2
    return (fx, fy, fz, tmean, l0, w0, i0, duty, u0, pload - psup, ev, mm, d, stretch <= 0.0, broken)


@functools.lru_cache(maxsize=None)
def compiled_station() -> Callable | None:
    """:func:`station_step` compiled by numba (cached on disk), or None (as :func:`compiled`)."""
    if compiled() is None:
        return None
    import numba
    from numba.extending import register_jitable
    register_jitable(substeps)
    f8, b1 = numba.float64, numba.boolean
    sig = (f8[::1], f8[::1], numba.int64) + (f8,) * 7 + (b1,) + (f8,) * 4
    try:
        return numba.njit(sig, cache=True)(station_step)
    except Exception as exc:  # a broken numba install must not stop a simulation
        warnings.warn(f"fdm_awe.groundstation.substeps: numba failed ({exc}); the Python step runs instead",
                      RuntimeWarning, stacklevel=2)
        return None


@functools.lru_cache(maxsize=None)
def compiled() -> Callable | None:
    """:func:`substeps` compiled by numba (cached on disk), or None (numba missing, or the
    environment sets ``FDM_AWE_JIT=0``)."""
    if os.environ.get("FDM_AWE_JIT", "1") == "0":
        return None
    try:
        import numba
        from numba.extending import register_jitable
    except ImportError:
        return None
    register_jitable(_piece)
    register_jitable(drum_speed)
    f8, b1 = numba.float64, numba.boolean
    # one explicit signature: compiled (or loaded from the cache) here, when the ground station
    # is built, not inside the first co-simulation step; other argument types are converted
    sig = (numba.int64,) + (f8,) * 7 + (b1,) * 5 + (f8,) * 16 + (f8[::1],)
    try:
        return numba.njit(sig, cache=True)(substeps)
    except Exception as exc:  # a broken numba install must not stop a simulation
        warnings.warn(f"fdm_awe.groundstation.substeps: numba failed ({exc}); the Python loop runs instead",
                      RuntimeWarning, stacklevel=2)
        return None


__all__ = ["CONSTANTS", "EVENTS", "STATE", "STATION_CONSTANTS", "compiled", "compiled_station", "drum_speed",
           "station_step", "substeps"]
