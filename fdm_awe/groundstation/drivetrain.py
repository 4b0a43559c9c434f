"""Coupled line + drum + DC machine + converter + PI integrator of the ground station.

One flight step ``dt`` is split into ``n = ceil(dt / max_substep)`` equal sub-steps ``h``. Each
sub-step is backward Euler for all states at once -- unstretched line length ``l``, drum speed
``omega``, armature current ``i``, link voltage ``u_L`` -- solved exactly (no iteration):

1. PI controller sample (motor mode) -> T1 duty (:mod:`.controller`).
2. Converter averaged terms (:mod:`.converter`): source voltage, link coupling; link voltage
   ``u1 = p + q i1``.
3. Armature (:mod:`.machine`): ``i1 = max(0, alpha + beta omega1)`` (diodes block reverse current).
4. Line (:mod:`.tether`): ``T1 = max(0, tA - tB omega1)`` with the glider distance at the end of
   the sub-step (glider position advanced linearly with its velocity inside the flight step) and
   ``l1 = l0 + h r_w omega1``; or a prescribed tension at the drum (tests, quasi-static use).
5. Drum (:mod:`.winch`): the piecewise-linear, monotone scalar equation for ``omega1`` with the
   set-valued Coulomb friction, solved exactly (stick-slip without chattering).

Backward Euler is L-stable, so the fast electrical modes (L_a/R ~ 0.4 ms, R_L C ~ 1.5 ms) and a
stiff short line never constrain the flight step; steady states are exact. The integrator's own
dissipation is booked in the ledger (``numerical``) so that the energy balance closes to
round-off and the size of the numerical error is visible.

Speed: the sub-step loop of :meth:`Drivetrain.advance` is the reference implementation; when
numba is installed its compiled twin (:mod:`.substeps`, same operations, identical results,
tested) runs instead (``FDM_AWE_JIT=0`` in the environment keeps the Python loop).
"""

from __future__ import annotations

import math

import numpy as np

from . import controller as _controller
from .controller import pi_update
from .converter import GENERATOR, MOTOR, link_coefficients
from .machine import armature_coefficients
from .definitions import GroundStationParams
from .ledger import FIELDS as LEDGER_FIELDS, EnergyLedger
from .substeps import EVENTS, STATE, compiled as compiled_substeps
from .winch import solve_drum_speed


_NS = len(STATE)
_LI = {name: i for i, name in enumerate(LEDGER_FIELDS)}
(_GLIDER_WORK, _SUPPLY, _WOUND, _STRAIN, _LOAD, _COPPER, _SEMI, _COULOMB, _VISCOUS, _END_STOP, _BREAK, _NUMERICAL,
 _DRUM, _AIRGAP) = (_LI[n] for n in ("glider_work", "supply", "wound_line_kinetic", "strain_payout", "load", "copper",
                                     "semiconductor", "coulomb", "viscous", "end_stop", "break_release", "numerical",
                                     "drum_work", "airgap"))
_STORED = _LI["stored_kinetic"]  # stored_kinetic, _inductor, _capacitor, _elastic follow


def _state_float(i: int, name: str) -> property:
    def get(self: "Drivetrain") -> float:
        return self._s.item(i)

    def set_(self: "Drivetrain", v: float) -> None:
        self._s[i] = v

    return property(get, set_, doc=name)


def _state_bool(i: int, name: str) -> property:
    def get(self: "Drivetrain") -> bool:
        return self._s.item(i) != 0.0

    def set_(self: "Drivetrain", v: bool) -> None:
        self._s[i] = 1.0 if v else 0.0

    return property(get, set_, doc=name)


class Drivetrain:
    """Line, drum, machine, converter and PI controller with their states (SI).

    The states (``length`` m, ``omega`` rad/s, ``current`` A, ``u_link`` V, ``integ`` and
    ``duty`` (-), ``broken``, ``at_stop``, ``stretch`` m, ``mode``) and the energy ledger live in
    one float64 array (layout :data:`fdm_awe.groundstation.substeps.STATE` followed by the
    ledger's terms), so that the compiled ground-station step updates them in place; as
    attributes they read as Python floats, bools and the mode string."""

    length = _state_float(0, "unstretched paid-out line length, m")
    omega = _state_float(1, "drum speed, rad/s (> 0 reel-out)")
    current = _state_float(2, "armature current, A")
    u_link = _state_float(3, "DC-link voltage, V")
    integ = _state_float(4, "PI integrator (duty)")
    duty = _state_float(5, "duty in effect (T1 in motor mode, T2 in generator mode)")
    broken = _state_bool(6, "the line is broken")
    at_stop = _state_bool(7, "the drum is at an end stop")
    stretch = _state_float(8, "d - l at the end of the last sub-step, m")

    @property
    def mode(self) -> str:
        """Converter mode in effect ("generator" / "motor")."""
        return MOTOR if self._s.item(9) != 0.0 else GENERATOR

    @mode.setter
    def mode(self, v: str) -> None:
        self._s[9] = 1.0 if v == MOTOR else 0.0

    def __init__(self, params: GroundStationParams) -> None:
        self.params = params
        self._s = np.zeros(len(STATE) + len(LEDGER_FIELDS))
        tp, wp, mp, cp = params.tether, params.winch, params.machine, params.converter
        self._coef_key: tuple = ()
        self._coef: tuple = ()
        self._const = (wp.radius, wp.viscous_friction, wp.coulomb_friction, wp.inertia,
                       tp.mass_per_length, tp.axial_stiffness, tp.breaking_load, tp.min_length,
                       tp.max_length, mp.k, mp.resistance, mp.inductance,
                       2.0 * cp.device_drop, cp.supply_voltage, cp.link_capacitance)
        self.ledger = EnergyLedger(self._s[len(STATE):])
        self._kernel = compiled_substeps()  # the loop below, compiled (None: run it in Python)
        self._kc: tuple = ()
        self.reset(length=100.0, omega=0.0, mode=GENERATOR)

    # -- state -------------------------------------------------------------------------
    def reset(self, length: float, omega: float, mode: str = GENERATOR,
              load_resistance: float | None = None, boost_duty: float | None = None) -> None:
        """Set the line length (m), drum speed (rad/s) and converter mode; the electrical states
        (and in motor mode the PI integrator) start at their quasi-steady values for that speed
        with no line load; the ledger is cleared."""
        p = self.params
        self.length = float(length)
        self.omega = float(omega)
        self.mode = mode
        RL = p.converter.load_resistance if load_resistance is None else load_resistance
        d2 = p.converter.boost_duty if boost_duty is None else boost_duty
        if mode == GENERATOR:
            s = 1.0 - d2
            i = (p.machine.k * self.omega - 2.0 * p.converter.device_drop) / (p.machine.resistance + s * s * RL)
            self.current = i if i > 0.0 else 0.0
            self.u_link = s * self.current * RL
            self.integ = self.duty = 0.0
        else:
            # reel-in at this speed with no line load: friction current, PI integrator holding
            # the duty that drives it (bumpless start of the speed loop)
            self.u_link = 0.0
            w = -self.omega
            if w > 0.0:
                m, c, wp = p.machine, p.converter, p.winch
                i = (wp.coulomb_friction + wp.viscous_friction * w) / m.k
                d = (m.k * w + m.resistance * i + 2.0 * c.device_drop) / c.supply_voltage
                ctrl = p.controller
                d = min(max(d, ctrl.duty_min), ctrl.duty_max)
                self.current = i if d < ctrl.duty_max else 0.0
                self.integ = self.duty = d
            else:
                self.current = 0.0
                self.integ = self.duty = 0.0
        self.broken = False
        self.at_stop = False
        self.stretch = 0.0  # d - l at the end of the last sub-step (elastic energy bookkeeping)
        self.ledger.clear(stored=self.stored())

    def stiffness(self) -> float:
        return 0.0 if self.broken else self.params.tether.axial_stiffness / self.length

    def stored(self) -> dict[str, float]:
        """Stored energies (J): kinetic (drum + paid-out line), inductor, capacitor, elastic."""
        p = self.params
        r = p.winch.radius
        J = p.winch.inertia + p.tether.mass_per_length * self.length * r * r
        s = self.stretch if self.stretch > 0.0 else 0.0
        return {
            "kinetic": 0.5 * J * self.omega * self.omega,
            "inductor": 0.5 * p.machine.inductance * self.current * self.current,
            "capacitor": 0.5 * p.converter.link_capacitance * self.u_link * self.u_link,
            "elastic": 0.5 * self.stiffness() * s * s,
        }

    # -- integration -------------------------------------------------------------------
    def advance(
        self, dt: float, n: int,
        x: float, y: float, z: float, vx: float, vy: float, vz: float,
        mode: str, omega_ref: float, duty_cmd: float | None, boost_duty: float, RL: float,
        fixed_tension: float | None = None,
    ) -> tuple[float, float, float, str | None]:
        """Advance ``dt`` s in ``n`` sub-steps with the glider at ``(x, y, z) + (vx, vy, vz) t``.

        With ``fixed_tension`` (N) the line is replaced by that tension at the drum.
        Returns ``(mean tension N, mean load power W, mean supply power W, event)``.

        The line stiffness EA/l and the paid-out line inertia mu l r_w^2 are evaluated at the
        start of the flight step (they change by ~1e-4 relative per step); the ledger books the
        change at the step end (``strain_payout``, ``wound_line_kinetic``).
        """
        (r, B, Mc, Jw, mu, EA, Tbreak, lmin, lmax, K, R, L, two_ud, Va, C) = self._const
        h = dt / n
        motor = mode == MOTOR
        st = self._s
        if motor != (st[9] != 0.0):  # mode switch: the PI integrator restarts at 0
            if motor:
                st[4] = 0.0
            st[9] = 1.0 if motor else 0.0
        # the states, read through one list (length, omega, current, u_link, integ, duty, broken,
        # at_stop, stretch)
        l_start, w0, i0, u0, integ, duty, broken, at_stop, stretch0 = st[:9].tolist()
        broken, at_stop = broken != 0.0, at_stop != 0.0
        # converter / armature / drum coefficients, constant while h, R_L and the mode are
        s_cpl = 0.0 if motor else 1.0 - boost_duty  # converter module: v_src = duty V_a in the loop
        key = (h, RL, s_cpl)
        if key != self._coef_key:
            cu, q = link_coefficients(C, RL, h, s_cpl)  # u1 = cu u0 + q i1
            aL, aH, iB = armature_coefficients(L, R, K, h, s_cpl, q)
            # i1 = aL i0 + aH (v_src - 2 U_d) - aS u0 + iB w1   (p = cu u0)
            self._coef = (q, cu, aL, aH, aH * s_cpl * cu, iB, h * r, h * K, h * Mc, h * B)
            self._coef_key = key
            ctrl = self.params.controller
            self._kc = np.array((r, B, Mc, K, Va, two_ud, lmin, lmax, Tbreak) + self._coef[:-1] + (
                ctrl.kp, ctrl.ki, ctrl.duty_min, ctrl.duty_max))  # substeps.CONSTANTS
        q, cu, aL, aH, aS, iB, hr, hK, hM, hB = self._coef
        # drum (winch module): backward Euler with set-valued Coulomb friction
        J = Jw + mu * l_start * r * r
        Jb = J + hB

        l0 = l_start
        event = None
        e_glider = e_supply = e_stop = e_brk = e_numel = 0.0
        S_u2 = S_i2 = S_i = S_fw = S_w2 = S_Tw = S_iw = S_dw2 = S_di2 = S_du2 = 0.0
        t_sum = 0.0
        fixed = fixed_tension is not None
        k = 0.0 if broken else EA / l_start
        tB = 0.0 if (fixed or broken) else k * hr
        if fixed or broken:
            s0 = d0 = 0.0
            if not broken and stretch0 > 0.0:  # line replaced by a prescribed tension
                e_glider -= 0.5 * k * stretch0 * stretch0
        else:
            d0 = math.sqrt(x * x + y * y + z * z)
            s0 = d0 - l0
            # the glider's real position differs from the last prediction: work at the line end
            a_ = s0 if s0 > 0.0 else 0.0
            b_ = stretch0 if stretch0 > 0.0 else 0.0
            e_glider += 0.5 * k * (a_ * a_ - b_ * b_)
        v_src = 0.0
        pi = motor and duty_cmd is None  # controller module: PI sample on the measured drum speed
        pi_call = pi and pi_update is not _controller.pi_update  # a replaced pi_update (tests) is called
        if motor:
            if not pi:
                duty = duty_cmd
                v_src = duty * Va
            ctrl = self.params.controller
            kp, ki, d_min, d_max = ctrl.kp, ctrl.ki, ctrl.duty_min, ctrl.duty_max
        else:
            duty = boost_duty
        if pi_call:
            pi = False
        line = not (fixed or broken)
        t_on = i_on = True
        px, py, pz = x, y, z
        hvx, hvy, hvz = h * vx, h * vy, h * vz
        kernel = self._kernel
        loops = n
        if kernel is not None and not pi_call:  # the compiled twin of the loop below
            (l0, w0, i0, u0, integ, duty, broken, at_stop, s0, k, ev, e_glider, e_supply, e_stop, e_brk, e_numel,
             S_u2, S_i2, S_i, S_fw, S_w2, S_Tw, S_iw, S_dw2, S_di2, S_du2, t_sum) = kernel(
                n, h, px, py, pz, hvx, hvy, hvz, pi, motor, fixed, broken, at_stop, l0, w0, i0, u0, integ,
                float(duty), float(v_src), d0, s0, k, tB, J, Jb, omega_ref,
                0.0 if fixed_tension is None else fixed_tension, e_glider, self._kc)
            event = EVENTS[ev]
            loops = 0  # the Python loop below is skipped
        sqrt = math.sqrt
        d1 = 0.0
        for _ in range(loops):
            if pi_call:
                duty, integ = pi_update(ctrl, w0 - omega_ref, integ, h)
                v_src = duty * Va
            elif pi:  # pi_update (controller module), written out: the same operations in order
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
                d1 = sqrt(px * px + py * py + pz * pz)
                tA = k * (d1 - l0)
            elif broken:
                tA = 0.0
            else:
                tA = fixed_tension
            # fast path: keep the friction sign of w0 and the active tension/current pieces
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
                    w1, mf = solve_drum_speed(J, w0, h, B, Mc, r, tA, tB, K, iA, iB)
            else:
                w1, mf = solve_drum_speed(J, w0, h, B, Mc, r, tA, tB, K, iA, iB)
            l1 = l0 + hr * w1
            if (l1 < lmin and w1 < 0.0) or (l1 > lmax and w1 > 0.0):  # drum end stops
                w1 = ((lmin if w1 < 0.0 else lmax) - l0) / hr
                if w1 * (l1 - l0) <= 0.0:
                    w1 = 0.0
                l1 = l0 + hr * w1
                mf = Mc if w1 > 0.0 else (-Mc if w1 < 0.0 else 0.0)
                if not at_stop:
                    event = "tether_fully_reeled_in" if l1 < 0.5 * (lmin + lmax) else "tether_fully_paid_out"
                at_stop = True
                i1 = iA + iB * w1
                T1 = tA - tB * w1
                tau_stop = J * (w1 - w0) / h - (r * (T1 if T1 > 0.0 else 0.0) - K * (i1 if i1 > 0.0 else 0.0) - B * w1 - mf)
                e_stop += -h * tau_stop * w1 + 0.5 * J * (w1 - w0) ** 2
                S_dw2 -= (w1 - w0) ** 2  # booked as end-stop loss, not integrator dissipation
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
            # ledger sums (end-of-sub-step powers, backward-Euler consistent)
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
                    event = "tether_break"
                    e_brk += 0.5 * k * s1p * s1p
                    s1 = 0.0
                    k = tB = 0.0
                d0, s0 = d1, s1
            elif fixed:
                e_glider += T1 * hr * w1
            t_sum += T1
            l0, w0, i0, u0 = l1, w1, i1, u1

        stretch = s0 if not (fixed or broken) else 0.0
        # states and ledger written through plain lists (one array read and write each)
        st[:9] = (l0, w0, i0, u0, integ, duty, 1.0 if broken else 0.0, 1.0 if at_stop else 0.0, stretch)
        lg = st[_NS:].tolist()  # ledger terms (ledger.FIELDS order)
        lg[_GLIDER_WORK] += e_glider
        lg[_SUPPLY] += h * e_supply
        J_end = Jw + mu * l0 * r * r
        lg[_WOUND] += 0.5 * (J_end - J) * w0 * w0
        sp = stretch if stretch > 0.0 else 0.0
        k_end = 0.0 if broken else EA / l0
        lg[_STRAIN] += 0.5 * (k_end - k) * sp * sp
        lg[_LOAD] += h * S_u2 / RL
        lg[_COPPER] += h * R * S_i2
        lg[_SEMI] += h * two_ud * S_i
        lg[_COULOMB] += h * S_fw
        lg[_VISCOUS] += h * B * S_w2
        lg[_END_STOP] += e_stop
        lg[_BREAK] += e_brk
        lg[_NUMERICAL] += 0.5 * (J * S_dw2 + L * S_di2 + C * S_du2) + e_numel
        lg[_DRUM] += h * r * S_Tw
        lg[_AIRGAP] += h * K * S_iw
        lg[_STORED:] = (0.5 * J_end * w0 * w0, 0.5 * L * i0 * i0, 0.5 * C * u0 * u0, 0.5 * k_end * sp * sp)
        st[_NS:] = lg
        return t_sum / n, S_u2 / (RL * n), e_supply / n, event
