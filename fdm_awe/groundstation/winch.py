"""Winch drum dynamics (paper eq. 14) with the implicit, set-valued Coulomb friction.

Drum equation (reel-out positive, omega = reel speed / r_w):

    (J + mu l r_w^2) domega/dt = r_w T - K_t i - B omega - M_c sgn(omega)

- ``J`` is Table 1's total inertia (drum + rotor); the paid-out line adds ``mu l r_w^2``.
- ``M_c`` is Table 1's Coulomb friction, counted once (docs/design.md 4.8: eq. 14's M_c and eq. 16's
  T_f are the same term); ``B`` the viscous friction; ``K_t i`` the machine torque, which acts in
  the reel-in direction only (the asymmetric half-bridge carries one current direction).
- Stick-slip without chattering: friction is the set-valued law ``M_f in M_c Sign(omega)``
  solved implicitly (backward Euler) every sub-step. When the driving torque cannot overcome
  M_c the drum sticks exactly (omega = 0, friction = whatever holds it, |M_f| <= M_c): no
  switching at zero speed, no smoothing velocity (equivalent to Karnopp's stick band shrunk to
  the exact stick condition).

The drum's relations of one backward-Euler sub-step: :func:`drum_speed` (the exact solve),
:func:`drum_step` (its fast path) and :func:`end_stop`. They are plain functions of floats that
the ground station's step (:mod:`.substeps`) calls; numba compiles them into it (its on-disk
cache follows this file too), Python runs the same source otherwise.
"""

from __future__ import annotations

import math


def drum_speed(J: float, w0: float, h: float, B: float, Mc: float, r: float,
               tA: float, tB: float, K: float, iA: float, iB: float) -> tuple[float, float]:
    """One backward-Euler step of the drum speed with set-valued Coulomb friction: solves
    ``J (w - w0) = h [r T(w) - K i(w) - B w - M_f]``, ``M_f in Mc Sign(w)``, ``T(w) = max(0, tA -
    tB w)`` (N, tB >= 0), ``i(w) = max(0, iA + iB w)`` (A, iB >= 0). The residual is continuous,
    piecewise linear and strictly increasing (a unique solution): the stick condition at w = 0,
    then the linear pieces between the kinks. Returns ``(w rad/s, M_f N m)`` (> 0 opposes reel-out).
    """
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


def drum_step(J: float, Jb: float, w0: float, h: float, B: float, Mc: float, r: float, K: float,
              hr: float, hK: float, hM: float, tA: float, tB: float, iA: float, iB: float,
              t_on: bool, i_on: bool) -> tuple[float, float]:
    """:func:`drum_speed` with a fast path: the friction sign of ``w0`` and the tension/current
    pieces active in the last sub-step (``t_on``, ``i_on``) are tried first (``Jb = J + h B``,
    ``hr = h r``, ``hK = h K``, ``hM = h Mc``). Returns ``(w rad/s, M_f N m)``."""
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
        if ok and (tA - tB * w1 > 0.0) == t_on and (iA + iB * w1 > 0.0) == i_on:
            return w1, mf
    return drum_speed(J, w0, h, B, Mc, r, tA, tB, K, iA, iB)


def end_stop(J: float, w0: float, w1: float, l0: float, l1: float, h: float, hr: float, r: float, B: float,
             K: float, Mc: float, lmin: float, lmax: float, tA: float, tB: float, iA: float,
             iB: float) -> tuple[float, float, float, float]:
    """The drum stopped at the end stop (length ``lmin``/``lmax`` m) that the free sub-step
    (``w1`` rad/s, ``l1`` m) would pass: ``(w1 rad/s, l1 m, M_f N m, energy absorbed J)``."""
    w1 = ((lmin if w1 < 0.0 else lmax) - l0) / hr
    if w1 * (l1 - l0) <= 0.0:
        w1 = 0.0
    l1 = l0 + hr * w1
    mf = Mc if w1 > 0.0 else (-Mc if w1 < 0.0 else 0.0)
    i1 = iA + iB * w1
    T1 = tA - tB * w1
    tau_stop = J * (w1 - w0) / h - (r * (T1 if T1 > 0.0 else 0.0) - K * (i1 if i1 > 0.0 else 0.0) - B * w1 - mf)
    return w1, l1, mf, -h * tau_stop * w1 + 0.5 * J * (w1 - w0) ** 2


#: One backward-Euler step of the drum speed with set-valued Coulomb friction:
#: ``solve_drum_speed(J, w0, h, B, Mc, r, tA, tB, K, iA, iB) -> (w rad/s, M_f N m)``
#: (:func:`drum_speed`).
solve_drum_speed = drum_speed

#: the functions compiled into the ground station's step
DRUM_RELATIONS = (drum_speed, _piece, drum_step, end_stop)

__all__ = ["DRUM_RELATIONS", "drum_speed", "drum_step", "end_stop", "solve_drum_speed"]
