"""The drivetrain's sub-step loop as one function of floats, compiled with numba when available.

:meth:`fdm_awe.groundstation.drivetrain.Drivetrain.advance` is the reference: its Python loop
is the model (backward Euler for line, drum, armature and link at once; see that module).
:func:`substeps` is the same loop, the same operations in the same order, written on plain
scalars so that numba compiles it (``cache=True``: compiled once per installation, loaded from
the cache afterwards). Round-off is identical (no fast-math), and a test runs both on the
same scenarios and compares every state and ledger term for exact equality.

:func:`compiled` returns the compiled loop, or None when numba is not installed or
``FDM_AWE_JIT=0`` is set in the environment; the drivetrain then runs its Python loop.
"""

from __future__ import annotations

import functools
import math
import os
import warnings
from typing import Callable

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


__all__ = ["CONSTANTS", "EVENTS", "compiled", "drum_speed", "substeps"]
