"""The ground station's step and its relations, written once as plain functions of floats
(the drum's in :mod:`.winch`).

Numba compiles these functions when it is available; Python runs the same functions when it
is not (or when ``FDM_AWE_JIT=0`` is set): there is no second copy. A test runs both
executions on the same scenarios and compares every state and ledger term for exact equality
(no fast-math: the compiled code rounds as Python does).

The relations (the modules that describe them in parentheses): :func:`pi_step` (:mod:`.controller`),
:func:`link_coefficients`, the current limits :func:`hold_current` (motor mode) and
:func:`hold_generator` (generator mode) and the tension limit :func:`force_limited_current` (:mod:`.converter`),
:func:`armature_coefficients` and :func:`machine_mode_code` (:mod:`.machine`),
:func:`cross_flow_drag` and :func:`weight_share` (:mod:`.tether`); the drum's (``drum_speed``, ``drum_step``, ``end_stop``) live in :mod:`.winch`;
the sub-step loop :func:`substeps`, one drivetrain step with its ledger :func:`advance`
(:mod:`.drivetrain`) and one :meth:`.station.GroundStation.step` :func:`station_step`.

Numba's on-disk cache (``cache=True``) checks a compiled function only against its own source
file: the compiled :func:`advance` and :func:`station_step` are tied also to :mod:`.winch`
(:func:`fdm_awe.jitcache.follow_sources`). :func:`compiled` / :func:`compiled_station` return
them, or None when numba is missing or ``FDM_AWE_JIT=0``.
"""

from __future__ import annotations

import math
from typing import Any, Callable

from .. import slots
from ..jitcache import compile_cached, compiled_once
from . import winch
from .ledger import FIELDS as LEDGER_FIELDS
from .winch import DRUM_RELATIONS, drum_step, end_stop

#: Event codes (0: none).
EVENTS = (None, "tether_fully_reeled_in", "tether_fully_paid_out", "tether_break")
#: Machine-mode codes of :func:`machine_mode_code`.
MACHINE_MODES = ("idle", "generator", "motor")

#: The drivetrain's states at the head of its state array (``broken``, ``at_stop``, ``motor`` 0/1)
STATE = slots.declare("DrivetrainState", ("length", "omega", "current", "u_link", "integ", "duty", "broken",
                                          "at_stop", "stretch", "motor"))
#: the energy ledger's terms after them (:data:`.ledger.FIELDS`; ``line_drag_work_on_glider`` and
#: ``line_weight_work_on_glider`` also the lumped line's)
LEDGER = slots.declare("DrivetrainLedger", LEDGER_FIELDS, start=slots.size(STATE))

#: The constants array ``c`` of :func:`advance` (from the definitions; fixed for a station)
CONST = slots.declare("DrivetrainConstants", ("r", "B", "Mc", "Jw", "mu", "EA", "Tbreak", "lmin", "lmax", "K", "R",
                                              "L", "two_ud", "Va", "C", "kp", "ki", "d_min", "d_max", "i_lim",
                                              "t_lim", "t_band"))
#: and after them those of :func:`station_step`: the station's wind (N, E, D; m/s), its line-share
#: factors and the code of its line model (:attr:`.linemodels.LineKind.code`, the compiled loop's
#: dispatch); a line model's own constants follow (from ``slots.size(STATION)``)
STATION = slots.declare("StationConstants", (("wind", 3), "drag_c", "drag_on", "weight_c", "g", "line"),
                        start=slots.size(CONST))
#: after the ledger, a work area: the inputs of one :func:`substeps` call that :func:`advance`
#: writes there (SI; ``d0``, ``s0`` the line's start distance and stretch, ``aS = aH s_cpl cu``,
#: ``i_t`` the current that holds the tension limit on the drum; the other names as in
#: :func:`advance` and :mod:`.drivetrain`); a line model's block follows (from ``slots.size(STEP)``)
STEP = slots.declare("SubstepInputs", ("h", "px", "py", "pz", "hvx", "hvy", "hvz", "v_src", "duty", "d0", "s0", "k",
                                       "tB", "J", "Jb", "omega_ref", "fixed_tension", "e_glider", "q", "cu", "aL",
                                       "aH", "aS", "iB", "s_cpl", "RL", "i_t"), start=slots.size(LEDGER))


def pi_step(kp: float, ki: float, d_min: float, d_max: float, err: float, integ: float,
            h: float) -> tuple[float, float]:
    """One PI sample of the T1 duty: ``(duty, new integrator)`` (both -) for the speed error
    ``err`` (rad/s) over the sample ``h`` (s); see :mod:`.controller`."""
    u = kp * err + integ
    if u > d_max:
        duty, hold = d_max, err > 0.0
    elif u < d_min:
        duty, hold = d_min, err < 0.0
    else:
        duty, hold = u, False
    if not hold:  # conditional integration, the integrator kept inside the duty limits
        integ += ki * err * h
        if integ > d_max:
            integ = d_max
        elif integ < d_min:
            integ = d_min
    return duty, integ


def link_coefficients(C: float, RL: float, h: float, s: float) -> tuple[float, float]:
    """Backward-Euler DC-link voltage over one sub-step ``h`` (s) as ``u1 = cu u0 + q i1``.

    ``C (u1 - u0) = h (s i1 - u1 / R_L)`` -> ``cu = C / (C + h/R_L)``, ``q = h s / (C + h/R_L)``.
    ``C`` F, ``RL`` ohm, ``s`` link coupling (-). Returns ``(cu [-], q [V/A])``.
    """
    den = C + h / RL
    return C / den, h * s / den


def armature_coefficients(L: float, R: float, K: float, h: float, s: float, q: float) -> tuple[float, float, float]:
    """Backward-Euler armature current over one sub-step ``h`` (s)::

        i1 = aL i0 + aH (v_src - 2 U_d - s p) + beta omega1     (before the i >= 0 clamp)

    from ``L (i1 - i0) = h (v_src + K omega1 - R i1 - 2 U_d - s u1)`` with the link voltage at the
    end of the sub-step ``u1 = p + q i1`` (:func:`link_coefficients`). ``L`` H, ``R`` ohm, ``K``
    V s/rad, ``s`` link coupling (-). Returns ``(aL [-], aH [A/V], beta [A s/rad])``.
    """
    D = L + h * R + h * s * q
    return L / D, h / D, h * K / D


def hold_current(J: float, Jb: float, w0: float, h: float, B: float, Mc: float, r: float, K: float, hr: float,
                 hK: float, hM: float, tA: float, tB: float, iA: float, iB: float, t_on: bool, aH: float,
                 v_src: float, Va: float, i_lim: float) -> tuple[float, float, float, float]:
    """The converter's current limit ``i_lim`` (A) in motor mode, for a sub-step whose armature
    current ``iA + iB w1`` (:func:`armature_coefficients`, with the source ``v_src`` V) would
    exceed it: the drum's step (:func:`.winch.drum_step`, arguments as there) with the current
    held at ``i_lim``. The source voltage that holds it lies ``(i_lim - iA - iB w1) / aH`` below
    ``v_src`` (``aH`` A/V); down to 0 the T1 duty gives it, below 0 T2 opens too (the current
    returns through D1 and D2 to the supply bus), at most down to ``-Va`` (both switches open).
    Where even ``-Va`` passes more, the current stays above the limit. Returns ``(w1 rad/s,
    M_f N m, a, b)``: the drum's current ``a + b w1`` (A)."""
    w1, mf = drum_step(J, Jb, w0, h, B, Mc, r, K, hr, hK, hM, tA, tB, i_lim, 0.0, t_on, True)
    if v_src + (i_lim - iA - iB * w1) / aH >= -Va:
        return w1, mf, i_lim, 0.0
    iA += aH * (-Va - v_src)  # both switches open
    w1, mf = drum_step(J, Jb, w0, h, B, Mc, r, K, hr, hK, hM, tA, tB, iA, iB, t_on, True)
    return w1, mf, iA, iB


def force_limited_current(i_lim: float, tension: float, t_lim: float, i_t: float, band: float) -> float:
    """The converter's current limit [A] at the measured line tension ``tension`` [N]: the
    armature current limit ``i_lim`` [A], and above the line's tension limit ``t_lim`` [N] the
    current ``i_t`` [A] that holds ``t_lim`` on the drum (``(r_w t_lim - M_c) / K``), falling
    to 0 over the next ``band`` [N] (the upper-force controller: the drum is braked less, it
    pays out faster, the line's pull falls). A ``t_lim`` of infinity turns the force limit off."""
    if tension <= t_lim:
        return i_lim
    f = i_t * (1.0 - (tension - t_lim) / band)
    return min(max(f, 0.0), i_lim)


def hold_generator(J: float, Jb: float, w0: float, h: float, B: float, Mc: float, r: float, K: float, hr: float,
                   hK: float, hM: float, tA: float, tB: float, t_on: bool, i_max: float, i0: float, u0: float,
                   L: float, R: float, two_ud: float, s: float, C: float) -> tuple[float, float, float, float, float,
                                                                                   float]:
    """The converter's current limit ``i_max`` (A) in generator mode, for a sub-step whose
    armature current would exceed it: the drum's step (:func:`.winch.drum_step`, arguments as
    there) with the current held at ``i_max``, the DC link taking the voltage that holds it (the
    converter draws less load current from the link: its load resistance rises above R_L, the
    link charges). ``i0`` A and ``u0`` V the sub-step's starting current and link voltage,
    ``L`` H, ``R`` ohm, ``two_ud`` V, ``s`` the link coupling (1 - T2 duty), ``C`` F. Where the
    link would have to charge faster than the current alone charges it (the load off), the
    load is off and the current is what that leaves (above the limit). Returns ``(w1 rad/s,
    M_f N m, a, b, u1 V, load current A)``: the drum's current ``a + b w1`` (A); ``b`` 0 where
    the current is held (then ``u1`` and the load current are the sub-step's), else the load
    is off and the link voltage follows from the current (``u0 + h s i1 / C``)."""
    w1, mf = drum_step(J, Jb, w0, h, B, Mc, r, K, hr, hK, hM, tA, tB, i_max, 0.0, t_on, True)
    u1 = (K * w1 - R * i_max - two_ud - L * (i_max - i0) / h) / s
    i_load = s * i_max - C * (u1 - u0) / h
    if i_load >= 0.0:
        return w1, mf, i_max, 0.0, u1, i_load
    D = L + h * R + h * h * s * s / C  # the load off: C (u1 - u0) = h s i1
    iA = (L * i0 - h * (two_ud + s * u0)) / D
    iB = h * K / D
    w1, mf = drum_step(J, Jb, w0, h, B, Mc, r, K, hr, hK, hM, tA, tB, iA, iB, t_on, True)
    return w1, mf, iA, iB, 0.0, 0.0


def cross_flow_drag(ux: float, uy: float, uz: float, vax: float, vay: float, vaz: float,
                    c_l: float) -> tuple[float, float, float]:
    """Cross-flow drag of a line (or a segment of it) along the unit vector ``(ux, uy, uz)``,
    NED, N: ``c_l |v_perp| v_perp``, ``v_perp`` the air velocity ``(vax, vay, vaz)`` (m/s) normal
    to it; ``c_l`` kg/m, e.g. the glider's share of the straight line's drag ``-share 0.5 rho
    C_D_perp d_t scale l`` (:mod:`.tether`) or half a lumped segment's (:mod:`.lumped`)."""
    vr = vax * ux + vay * uy + vaz * uz
    px, py, pz = vax - vr * ux, vay - vr * uy, vaz - vr * uz
    c = c_l * math.sqrt(px * px + py * py + pz * pz)
    return c * px, c * py, c * pz


def weight_share(weight_c: float, length: float, g: float) -> float:
    """The glider's share of the line weight, N, down: ``weight_c = share mu`` (kg/m), ``length``
    m, ``g`` m/s^2."""
    return weight_c * length * g


def machine_mode_code(omega: float, current: float, K: float) -> int:
    """Eq. 17 sign rule as an index into :data:`MACHINE_MODES` (see :func:`.machine.machine_mode`):
    the machine torque ``T_e = -sgn(omega) K i`` < 0 -> generator, > 0 -> motor, idle without
    rotation or current."""
    if omega == 0.0 or current <= 0.0:
        return 0
    return 1 if -(1.0 if omega > 0.0 else -1.0) * K * current < 0.0 else 2


def substeps(s, c, n, pi, motor, fixed):  # noqa: C901
    """``n`` backward-Euler sub-steps of line, drum, armature and link (:mod:`.drivetrain`) from the
    states ``s`` (:data:`STATE`, inputs :data:`STEP`; not written) and constants ``c`` (:data:`CONST`).

    ``pi``: the PI runs, else ``v_src`` is the open-loop source; ``fixed``: a prescribed tension
    replaces the line. The converter holds the current at ``i_lim``: in motor mode through the
    source (:func:`hold_current`; the PI's integrator stops where it would push on), in generator
    mode through the link (:func:`hold_generator`), there also below it above the tension limit
    (the last sub-step's tension measured, :func:`force_limited_current`). Returns the end states
    ``(l, omega, i, u_L, integ, duty, broken, at_stop, s, k)``, the event code (:data:`EVENTS`)
    and the energy sums ``(e_glider, e_supply, e_brake, e_stop, e_brk, e_numel, S_load, S_i2, S_i,
    S_fw, S_w2, S_Tw, S_iw, S_dw2, S_di2, S_du2, t_sum)``.

    Over 80 lines on purpose: one loop, its sums in local variables (registers, compiled); split
    under 80 lines, the compiled step took 2 % longer.
    """
    l0, w0, i0, u0 = float(s[STATE.length]), float(s[STATE.omega]), float(s[STATE.current]), float(s[STATE.u_link])
    integ, broken, at_stop = float(s[STATE.integ]), s[STATE.broken] != 0.0, s[STATE.at_stop] != 0.0
    r, B, Mc, K, Va, two_ud = c[CONST.r], c[CONST.B], c[CONST.Mc], c[CONST.K], c[CONST.Va], c[CONST.two_ud]
    lmin, lmax, Tbreak, kp, ki = c[CONST.lmin], c[CONST.lmax], c[CONST.Tbreak], c[CONST.kp], c[CONST.ki]
    d_min, d_max, i_lim, L, R, C = c[CONST.d_min], c[CONST.d_max], c[CONST.i_lim], c[CONST.L], c[CONST.R], c[CONST.C]
    h, px, py, pz, hvx, hvy, hvz = s[STEP.h], s[STEP.px], s[STEP.py], s[STEP.pz], s[STEP.hvx], s[STEP.hvy], s[STEP.hvz]
    v_src, duty, d0, s0, k, tB = s[STEP.v_src], s[STEP.duty], s[STEP.d0], s[STEP.s0], s[STEP.k], s[STEP.tB]
    J, Jb, omega_ref, e_glider = s[STEP.J], s[STEP.Jb], s[STEP.omega_ref], s[STEP.e_glider]
    q, cu, aL, aH, aS, iB = s[STEP.q], s[STEP.cu], s[STEP.aL], s[STEP.aH], s[STEP.aS], s[STEP.iB]
    s_cpl, RL, i_t, t_lim, band = s[STEP.s_cpl], s[STEP.RL], s[STEP.i_t], c[CONST.t_lim], c[CONST.t_band]
    fixed_tension = s[STEP.fixed_tension]
    hr, hK, hM = h * r, h * K, h * Mc
    event = 0
    e_supply = e_brake = e_stop = e_brk = e_numel = t_sum = 0.0
    S_load = S_i2 = S_i = S_fw = S_w2 = S_Tw = S_iw = S_dw2 = S_di2 = S_du2 = 0.0
    line = not (fixed or broken)
    # the tension the converter measured last (the line's stretch at the start, or the prescribed one)
    t_meas = 0.0 if broken else (fixed_tension if fixed else (k * s0 if s0 > 0.0 else 0.0))
    u_h = i_load = d1 = integ0 = va = 0.0
    t_on = i_on = True
    held = False  # the current limit held the last sub-step's current
    for _ in range(n):
        if pi:  # PI sample on the measured drum speed
            integ0 = integ
            duty, integ = pi_step(kp, ki, d_min, d_max, w0 - omega_ref, integ, h)
            v_src = duty * Va
        iA = aL * i0 + aH * (v_src - two_ud) - aS * u0  # armature: i1 = iA + iB w1 before the clamp
        if line:
            px += hvx
            py += hvy
            pz += hvz
            d1 = math.sqrt(px * px + py * py + pz * pz)
            tA = k * (d1 - l0)  # line: T1 = tA - tB w1 before the slack clamp
        elif broken:
            tA = 0.0
        else:
            tA = fixed_tension
        w1, mf = drum_step(J, Jb, w0, h, B, Mc, r, K, hr, hK, hM, tA, tB, iA, iB, t_on, i_on)
        ia, ib = iA, iB  # the current the drum sees: ia + ib w1
        held = motor and iA + iB * w1 > i_lim
        held_g = False
        if not motor and s_cpl > 0.0:
            i_max = force_limited_current(i_lim, t_meas, t_lim, i_t, band)
            held_g = iA + iB * w1 > i_max
        if held:  # the converter's current limit
            w1, mf, ia, ib = hold_current(J, Jb, w0, h, B, Mc, r, K, hr, hK, hM, tA, tB, iA, iB, t_on, aH, v_src, Va,
                                          i_lim)
            if pi and w0 > omega_ref:  # conditional integration: no wind-up against the limit
                integ = integ0
        elif held_g:  # the generator's current limit, through the link
            w1, mf, ia, ib, u_h, i_load = hold_generator(J, Jb, w0, h, B, Mc, r, K, hr, hK, hM, tA, tB, t_on, i_max,
                                                         i0, u0, L, R, two_ud, s_cpl, C)
        l1 = l0 + hr * w1
        if (l1 < lmin and w1 < 0.0) or (l1 > lmax and w1 > 0.0):  # drum end stops
            w1, l1, mf, e = end_stop(J, w0, w1, l0, l1, h, hr, r, B, K, Mc, lmin, lmax, tA, tB, ia, ib)
            if not at_stop:
                event = 1 if l1 < 0.5 * (lmin + lmax) else 2
            at_stop = True
            e_stop += e
            S_dw2 -= (w1 - w0) ** 2  # booked as end-stop loss, not integrator dissipation
        else:
            at_stop = False
        i1 = ia + ib * w1
        i_on = i1 > 0.0
        if not i_on:
            i1 = 0.0
        va = v_src  # the source in effect: held at the limit (ib 0), the one that passes i1; else -V_a
        if held:
            va = v_src + (i1 - iA - iB * w1) / aH if ib == 0.0 else -Va
        if not held_g:
            u1 = cu * u0 + q * i1
            S_load += u1 * u1 / RL
        elif ib == 0.0:  # held at the limit: the link's voltage and load current that hold it
            u1 = u_h
            S_load += u1 * i_load
        else:  # the load off: the current charges the link
            u1 = u0 + h * s_cpl * i1 / C
        T1 = tA - tB * w1
        t_on = T1 > 0.0
        if not t_on:
            T1 = 0.0
        t_meas = T1
        # ledger sums (end-of-sub-step powers, backward-Euler consistent)
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
            if va >= 0.0:
                e_supply += va * i1
            else:  # T2 open too: D1 and D2 return the current to the supply bus, its brake chopper burns it
                e_brake -= va * i1
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
    if held:
        duty = va / Va
    return (l0, w0, i0, u0, integ, duty, broken, at_stop, s0, k, event,
            e_glider, e_supply, e_brake, e_stop, e_brk, e_numel,
            S_load, S_i2, S_i, S_fw, S_w2, S_Tw, S_iw, S_dw2, S_di2, S_du2, t_sum)


def advance(s, c, n, dt, x, y, z, vx, vy, vz, motor, omega_ref, duty_cmd, boost_duty, RL, fixed_tension):
    """One flight step ``dt`` s of the drivetrain in ``n`` sub-steps (:meth:`.drivetrain.Drivetrain.advance`).

    ``s`` the state array (:data:`STATE`, the ledger :data:`LEDGER`, :data:`STEP`; updated in place), ``c``
    the constants (:data:`CONST` first), the glider at ``(x, y, z) + (vx, vy, vz) t`` (m, m/s),
    ``motor`` the converter mode, ``omega_ref`` rad/s, ``duty_cmd`` the open-loop T1 duty (NaN:
    PI), ``boost_duty`` the T2 duty, ``RL`` ohm; ``fixed_tension`` (N) at the drum instead of the
    line (NaN: the line). Returns ``(mean tension N, mean load power W, mean supply power W,
    event code)``. The line stiffness EA/l and the paid-out line inertia mu l r_w^2 are taken at
    the start of the step; the ledger books their change at its end.
    """
    r, B, Mc, Jw, mu, EA = c[CONST.r], c[CONST.B], c[CONST.Mc], c[CONST.Jw], c[CONST.mu], c[CONST.EA]
    K, R, L, two_ud, Va, C = c[CONST.K], c[CONST.R], c[CONST.L], c[CONST.two_ud], c[CONST.Va], c[CONST.C]
    fixed, h = fixed_tension == fixed_tension, dt / n
    if motor != (s[STATE.motor] != 0.0):  # mode switch: the PI integrator restarts at 0
        if motor:
            s[STATE.integ] = 0.0
        s[STATE.motor] = 1.0 if motor else 0.0
    s_cpl = 0.0 if motor else 1.0 - boost_duty  # converter: link coupling (motor: v_src = duty V_a)
    cu, q = link_coefficients(C, RL, h, s_cpl)  # u1 = cu u0 + q i1
    aL, aH, iB = armature_coefficients(L, R, K, h, s_cpl, q)
    l_start, stretch0 = float(s[STATE.length]), float(s[STATE.stretch])
    duty, broken = float(s[STATE.duty]), s[STATE.broken] != 0.0
    J = Jw + mu * l_start * r * r  # drum + paid-out line
    e_glider = 0.0
    k = 0.0 if broken else EA / l_start
    tB = 0.0 if (fixed or broken) else k * (h * r)
    if fixed or broken:
        s0 = d0 = 0.0
        if not broken and stretch0 > 0.0:  # line replaced by a prescribed tension
            e_glider -= 0.5 * k * stretch0 * stretch0
    else:
        d0 = math.sqrt(x * x + y * y + z * z)
        s0 = d0 - l_start
        # the glider's real position differs from the last prediction: work at the line end
        a_ = s0 if s0 > 0.0 else 0.0
        b_ = stretch0 if stretch0 > 0.0 else 0.0
        e_glider += 0.5 * k * (a_ * a_ - b_ * b_)
    v_src = 0.0
    pi = motor and duty_cmd != duty_cmd
    if motor:
        if not pi:
            duty = duty_cmd
            v_src = duty * Va
    else:
        duty = boost_duty
    # the inputs of the sub-step loop, in the work area STEP
    s[STEP.h], s[STEP.px], s[STEP.py], s[STEP.pz], s[STEP.hvx], s[STEP.hvy], s[STEP.hvz] = (
        h, x, y, z, h * vx, h * vy, h * vz)
    s[STEP.v_src], s[STEP.duty], s[STEP.d0], s[STEP.s0], s[STEP.k], s[STEP.tB] = v_src, duty, d0, s0, k, tB
    s[STEP.J], s[STEP.Jb], s[STEP.omega_ref], s[STEP.e_glider] = J, J + h * B, omega_ref, e_glider
    s[STEP.fixed_tension] = fixed_tension if fixed else 0.0
    s[STEP.q], s[STEP.cu], s[STEP.aL], s[STEP.aH], s[STEP.aS], s[STEP.iB] = q, cu, aL, aH, aH * s_cpl * cu, iB
    s[STEP.s_cpl], s[STEP.RL], s[STEP.i_t] = s_cpl, RL, (r * c[CONST.t_lim] - Mc) / K  # i_t: holds the tension limit
    (l0, w0, i0, u0, integ, duty, broken, at_stop, s0, k, ev, e_glider, e_supply, e_brake, e_stop, e_brk, e_numel,
     S_load, S_i2, S_i, S_fw, S_w2, S_Tw, S_iw, S_dw2, S_di2, S_du2, t_sum) = substeps(s, c, n, pi, motor, fixed)
    stretch = s0 if not broken else 0.0  # (0 with a prescribed tension)
    s[STATE.length], s[STATE.omega], s[STATE.current], s[STATE.u_link], s[STATE.integ], s[STATE.duty] = (
        l0, w0, i0, u0, integ, duty)
    s[STATE.broken], s[STATE.at_stop], s[STATE.stretch] = 1.0 if broken else 0.0, 1.0 if at_stop else 0.0, stretch
    s[LEDGER.glider_work] += e_glider
    s[LEDGER.supply] += h * e_supply
    J_end = Jw + mu * l0 * r * r
    s[LEDGER.wound_line_kinetic] += 0.5 * (J_end - J) * w0 * w0
    sp = stretch if stretch > 0.0 else 0.0
    k_end = 0.0 if broken else EA / l0
    s[LEDGER.strain_payout] += 0.5 * (k_end - k) * sp * sp
    s[LEDGER.load] += h * S_load
    s[LEDGER.copper] += h * R * S_i2
    s[LEDGER.semiconductor] += h * two_ud * S_i
    s[LEDGER.brake] += h * e_brake
    s[LEDGER.coulomb] += h * S_fw
    s[LEDGER.viscous] += h * B * S_w2
    s[LEDGER.end_stop], s[LEDGER.break_release] = s[LEDGER.end_stop] + e_stop, s[LEDGER.break_release] + e_brk
    s[LEDGER.numerical] += 0.5 * (J * S_dw2 + L * S_di2 + C * S_du2) + e_numel
    s[LEDGER.drum_work] += h * r * S_Tw
    s[LEDGER.airgap] += h * K * S_iw
    s[LEDGER.stored_kinetic], s[LEDGER.stored_inductor] = 0.5 * J_end * w0 * w0, 0.5 * L * i0 * i0
    s[LEDGER.stored_capacitor], s[LEDGER.stored_elastic] = 0.5 * C * u0 * u0, 0.5 * k_end * sp * sp
    return t_sum / n, S_load / n, e_supply / n, ev


def station_step(s, c, n, dt, x, y, z, vx, vy, vz, motor, omega_ref, duty_cmd, boost_duty, RL):
    """One flight step of :meth:`.station.GroundStation.step`: :func:`advance` on the line, the
    force on the glider (mean tension along the line at the start position, plus the drag and
    weight shares, their work booked in the ledger) and the machine mode.

    Arguments as :func:`advance` (``c``: :data:`CONST` and :data:`STATION`). Returns ``(fx, fy, fz
    N, mean tension N, length m, omega rad/s, current A, duty, u_link V, p_electrical W, event
    code, machine mode code, distance m, slack, broken)``.
    """
    l_start = float(s[STATE.length])
    tmean, pload, psup, ev = advance(s, c, n, dt, x, y, z, vx, vy, vz, motor, omega_ref, duty_cmd, boost_duty,
                                     RL, math.nan)
    broken = float(s[STATE.broken]) != 0.0
    d = math.sqrt(x * x + y * y + z * z)
    if broken and ev != 3:  # no line, no force
        fx = fy = fz = 0.0
    else:
        if d <= 0.0 or c[STATION.drag_on] == 0.0:
            fx = fy = fz = 0.0
        else:
            wind = STATION.wind
            fx, fy, fz = cross_flow_drag(x / d, y / d, z / d, vx - c[wind], vy - c[wind + 1], vz - c[wind + 2],
                                         c[STATION.drag_c] * l_start)
        s[LEDGER.line_drag_work_on_glider] += (fx * vx + fy * vy + fz * vz) * dt
        fw = weight_share(c[STATION.weight_c], l_start, c[STATION.g])
        s[LEDGER.line_weight_work_on_glider] += fw * vz * dt
        fz += fw
        if d > 0.0 and tmean > 0.0:
            ct = -tmean / d
            fx += ct * x
            fy += ct * y
            fz += ct * z
    w, i = float(s[STATE.omega]), float(s[STATE.current])
    return (fx, fy, fz, tmean, float(s[STATE.length]), w, i, float(s[STATE.duty]), float(s[STATE.u_link]),
            pload - psup, ev, machine_mode_code(w, i, c[CONST.K]), d, float(s[STATE.stretch]) <= 0.0, broken)


#: the functions called by :func:`advance` and :func:`station_step` (compiled with them)
CALLED = (pi_step, link_coefficients, armature_coefficients, hold_current, force_limited_current, hold_generator,
           *DRUM_RELATIONS, cross_flow_drag, weight_share,
           machine_mode_code, substeps, advance)


def _njit(f: Callable, sig: str) -> Callable | None:
    """``f`` compiled by numba for ``sig`` (one letter per argument: ``f`` float, ``b`` bool,
    ``a`` float array, ``i`` int), cached on disk and tied also to the drum's relations compiled
    into it, or None (numba missing, ``FDM_AWE_JIT=0``, a broken numba install: the Python
    functions run instead; :func:`fdm_awe.jitcache.compile_cached`)."""
    def signature(nb: Any) -> tuple:
        return tuple({"f": nb.float64, "b": nb.boolean, "a": nb.float64[::1], "i": nb.int64}[ch] for ch in sig)

    return compile_cached(f, signature, CALLED, (winch,), f"fdm_awe.groundstation.substeps ({f.__name__})")


@compiled_once
def compiled() -> Callable | None:
    """:func:`advance` compiled by numba for one explicit signature (when the ground station is
    built, not inside its first step), or None (numba missing, or ``FDM_AWE_JIT=0``)."""
    return _njit(advance, "aaifffffffbfffff")


@compiled_once
def compiled_station() -> Callable | None:
    """:func:`station_step` compiled by numba (cached on disk), or None (as :func:`compiled`)."""
    if compiled() is None:
        return None
    return _njit(station_step, "aaifffffffbffff")


__all__ = ["CONST", "EVENTS", "LEDGER", "MACHINE_MODES", "STATE", "STATION", "STEP", "advance", "compiled",
           "compiled_station", "force_limited_current", "hold_current", "hold_generator", "machine_mode_code",
           "pi_step", "station_step", "substeps"]
