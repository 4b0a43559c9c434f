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
6. Motor mode: where the current would exceed the converter's limit, the drum is solved again
   with the current held at the limit and the duty follows from the armature equation
   (:mod:`.converter`; below duty 0 the braking path through D1, D2).

Backward Euler is L-stable, so the fast electrical modes (L_a/R ~ 0.4 ms, R_L C ~ 1.5 ms) and a
stiff short line never constrain the flight step; steady states are exact. The integrator's own
dissipation is booked in the ledger (``numerical``) so that the energy balance closes to
round-off and the size of the numerical error is visible.

The relations and the loop are written once, in :mod:`.substeps`; numba compiles them when it
is installed, and Python runs the same functions otherwise (``FDM_AWE_JIT=0`` in the
environment keeps Python).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .. import slots
from ..jitcache import jit_off

from .converter import GENERATOR, MOTOR
from .definitions import GroundStationParams
from .ledger import EnergyLedger
from .substeps import CONST, EVENTS, LEDGER, STATE, STEP, advance, compiled

_NAN = float("nan")
#: a compiled step not asked for yet
_PENDING = object()


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
    ledger's terms, :data:`fdm_awe.groundstation.substeps.LEDGER`, and the sub-step loop's work
    area, :data:`fdm_awe.groundstation.substeps.STEP`), so that the compiled ground-station step
    updates them in place; as attributes they read as Python floats, bools and the mode string."""

    length = _state_float(STATE.length, "unstretched paid-out line length, m")
    omega = _state_float(STATE.omega, "drum speed, rad/s (> 0 reel-out)")
    current = _state_float(STATE.current, "armature current, A")
    u_link = _state_float(STATE.u_link, "DC-link voltage, V")
    integ = _state_float(STATE.integ, "PI integrator (duty)")
    duty = _state_float(STATE.duty, "duty in effect (T1 in motor mode, below 0 under the current limit's braking; T2 in "
                           "generator mode)")
    broken = _state_bool(STATE.broken, "the line is broken")
    at_stop = _state_bool(STATE.at_stop, "the drum is at an end stop")
    stretch = _state_float(STATE.stretch, "d - l at the end of the last sub-step, m")

    @property
    def mode(self) -> str:
        """Converter mode in effect ("generator" / "motor")."""
        return MOTOR if self._s.item(STATE.motor) != 0.0 else GENERATOR

    @mode.setter
    def mode(self, v: str) -> None:
        self._s[STATE.motor] = 1.0 if v == MOTOR else 0.0

    def __init__(self, params: GroundStationParams, line_state: int = 0) -> None:
        self.params = params
        n = slots.size(STEP)
        #: the state array of a station's step: the drivetrain's states and ledger, then
        #: ``line_state`` slots of the line model's block (:mod:`.linemodels`)
        self._all = np.zeros(n + line_state)
        self._s = self._all[:n]
        tp, wp, mp, cp, ctrl = params.tether, params.winch, params.machine, params.converter, params.controller
        c = self._c = slots.new(CONST)  # the constants of :func:`.substeps.advance` (compiled)
        c[CONST.r], c[CONST.B], c[CONST.Mc], c[CONST.Jw] = (wp.radius, wp.viscous_friction, wp.coulomb_friction,
                                                            wp.inertia)
        c[CONST.mu], c[CONST.EA], c[CONST.Tbreak] = tp.mass_per_length, tp.axial_stiffness, tp.breaking_load
        c[CONST.lmin], c[CONST.lmax] = tp.min_length, tp.max_length
        c[CONST.K], c[CONST.R], c[CONST.L] = mp.k, mp.resistance, mp.inductance
        c[CONST.two_ud], c[CONST.Va], c[CONST.C] = 2.0 * cp.device_drop, cp.supply_voltage, cp.link_capacitance
        c[CONST.kp], c[CONST.ki], c[CONST.d_min], c[CONST.d_max] = ctrl.kp, ctrl.ki, ctrl.duty_min, ctrl.duty_max
        c[CONST.i_lim], c[CONST.t_lim], c[CONST.t_band] = (cp.current_limit, cp.tension_limit,
                                                           cp.tension_limit_band)
        #: and as Python floats (the Python step)
        self._cl = c.tolist()
        self.ledger = EnergyLedger(self._s[slots.start(LEDGER):slots.size(LEDGER)])
        # substeps.advance compiled at the first step or question that needs it (None: Python
        # runs it): a flight whose loop compiles the whole co-simulation step never compiles it
        self._kernel: Any = _PENDING if jit_off() is None else None
        self.reset(length=100.0, omega=0.0, mode=GENERATOR)

    # -- state -------------------------------------------------------------------------
    @property
    def state(self) -> np.ndarray:
        """The states, the ledger's terms and the work area in one float64 array (layout above),
        then the line model's block (``line_state`` slots): the array the steps update in place,
        not a copy."""
        return self._all

    @property
    def constants(self) -> list[float]:
        """The constants of :func:`.substeps.advance` (layout ``substeps.CONST``) as Python
        floats (a copy)."""
        return list(self._cl)

    @property
    def is_compiled(self) -> bool:
        """Its step runs compiled (numba); False: the same function runs in Python. Asking
        compiles the step (or loads it from numba's cache) when that has not happened yet."""
        return self._advance() is not None

    @property
    def may_compile(self) -> bool:
        """Whether compiled code may run for it (numba present, ``FDM_AWE_JIT`` not 0), without
        compiling anything: a compiled loop that holds the step itself needs no more."""
        return self._kernel is not None

    def _advance(self) -> Any:
        """The compiled :func:`.substeps.advance` (compiled now if pending), or None."""
        k = self._kernel
        if k is _PENDING:
            k = self._kernel = compiled()
        return k

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
        """Advance ``dt`` s in ``n`` sub-steps with the glider at ``(x, y, z) + (vx, vy, vz) t``
        (m, m/s); ``omega_ref`` rad/s, ``duty_cmd`` open-loop T1 duty (None: PI), ``RL`` ohm.

        With ``fixed_tension`` (N) the line is replaced by that tension at the drum.
        Returns ``(mean tension N, mean load power W, mean supply power W, event)``
        (:func:`.substeps.advance`, compiled when numba is available).
        """
        args = (n, dt, x, y, z, vx, vy, vz, mode == MOTOR, omega_ref, _NAN if duty_cmd is None else duty_cmd,
                boost_duty, RL, _NAN if fixed_tension is None else fixed_tension)
        kern = self._kernel if self._kernel is not _PENDING else self._advance()
        if kern is not None:
            tmean, pload, psup, ev = kern(self._s, self._c, *args)
        else:
            tmean, pload, psup, ev = advance(self._s, self._cl, *args)
        return tmean, pload, psup, EVENTS[ev]
