"""Work-energy bookkeeping of the glider's centre-of-gravity motion in JSBSim: the change of its
translational kinetic and potential energy against the work of each force JSBSim reports
(:mod:`fdm_awe.sim.flight` describes the flight's energy ledger).

One step of it is :func:`ledger_step`, a plain function on arrays that :class:`GliderLedger`
runs in Python and a compiled loop can compile (the same source either way). Its inputs are the
JSBSim properties of :data:`LEDGER_PROPERTIES`, read after the step, in that order.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .. import slots
from ..units import FT, LBF, SLUG

#: the forces booked, in the order of the work array (then the paper plant's ideal thrust)
FORCES = ("aero", "prop", "external", "gear", "weight")
#: the work array, J: each force's, then the paper plant's ideal thrust's
WORK = slots.declare("GliderWork", FORCES + ("ideal_thrust",))
#: the properties one step reads: each force's body components (lbf), the body velocity (ft/s),
#: the mass (slug); the ideal thrust (lbf) is read only for the paper plant (else 0)
LEDGER_PROPERTIES = tuple(f"forces/fb{a}-{k}-lbs" for k in FORCES for a in "xyz") + (
    "velocities/u-fps", "velocities/v-fps", "velocities/w-fps", "inertia/mass-slugs")
IDEAL_THRUST_PROPERTY = "external_reactions/ideal-thrust/magnitude"
#: their values as one step reads them (each force's three body components from ``fb_<force>``)
VALS = slots.declare("LedgerValues", tuple(("fb_" + k, 3) for k in FORCES) + ("u", "v", "w", "mass"))


def ledger_step(vals: Any, ideal_thrust: float, work: np.ndarray, v_prev: np.ndarray, dt: float, ft: float,
                lbf: float) -> None:
    """Add each force's work over the step of ``dt`` [s] just flown to ``work`` [J] (trapezoidal
    rule on the velocity at its two ends): ``vals`` the step's :data:`LEDGER_PROPERTIES` (JSBSim
    units), ``ideal_thrust`` the paper plant's ideal thrust [lbf] (0 without), ``v_prev`` the
    body velocity [m/s] at the step's start (replaced by the end's), ``ft`` m per ft, ``lbf``
    N per lbf."""
    u, v, w = vals[VALS.u] * ft, vals[VALS.v] * ft, vals[VALS.w] * ft
    m0, m1, m2 = (u + v_prev[0]) * 0.5, (v + v_prev[1]) * 0.5, (w + v_prev[2]) * 0.5
    for j in range(5):  # the forces: fb_aero .. fb_weight, three slots each, in WORK's order
        a = VALS.fb_aero + 3 * j
        work[WORK.aero + j] += (vals[a] * m0 + vals[a + 1] * m1 + vals[a + 2] * m2) * lbf * dt
    work[WORK.ideal_thrust] += ideal_thrust * m0 * lbf * dt
    v_prev[0], v_prev[1], v_prev[2] = u, v, w


def kinetic_energy(v: Any, mass_slug: float, slug: float) -> float:
    """Translational kinetic energy [J] of body velocity ``v`` [m/s] and mass ``mass_slug`` [slug]
    (``slug`` kg per slug)."""
    return 0.5 * mass_slug * slug * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2])


class GliderLedger:
    """Work-energy bookkeeping of the glider's CG motion from JSBSim's force breakdown."""

    _FORCES = FORCES

    def __init__(self, glider: Any, ideal_thrust: bool = False) -> None:
        """``ideal_thrust``: the paper plant's body-x force is among JSBSim's external forces;
        its work is booked as thrust work, not tether work."""
        pm = glider.fdm.get_property_manager()
        self._get = [pm.get_node(n, False).get_double_value for n in LEDGER_PROPERTIES]
        self._ti = pm.get_node(IDEAL_THRUST_PROPERTY, False).get_double_value if ideal_thrust else None
        self.ideal_thrust = bool(ideal_thrust)  #: the paper plant's ideal thrust is booked apart
        #: works [J] (:data:`FORCES`, then the ideal thrust), updated by every step
        self.work_array = slots.new(WORK)
        vals = self._read()
        self.v_prev = np.array((vals[VALS.u] * FT, vals[VALS.v] * FT, vals[VALS.w] * FT))  #: body velocity [m/s]
        self._mass = vals[VALS.mass]
        self.ke0 = kinetic_energy(self.v_prev, self._mass, SLUG)

    def _read(self) -> list[float]:
        return [g() for g in self._get]

    def step(self, dt: float) -> None:
        """Add each force's work over the step of ``dt`` [s] just flown (:func:`ledger_step`)."""
        vals = self._read()
        self._mass = vals[VALS.mass]
        ledger_step(vals, 0.0 if self._ti is None else self._ti(), self.work_array, self.v_prev, dt, FT, LBF)

    def set_mass(self, mass_slug: float) -> None:
        """The mass [slug] read by the last step when a compiled loop ran the steps
        (:func:`ledger_step` on :attr:`work_array` and :attr:`v_prev`)."""
        self._mass = mass_slug

    @property
    def ke(self) -> float:
        """Translational kinetic energy after the last step [J]."""
        return kinetic_energy(self.v_prev, self._mass, SLUG)

    @property
    def work(self) -> dict[str, float]:
        """The works [J] by force name (and ``ideal_thrust``)."""
        w = self.work_array.tolist()
        return dict(zip(slots.names(WORK), w))

    def terms(self) -> dict[str, float]:
        """J: kinetic change, potential change (= -weight work), works of the other forces."""
        w = self.work
        return {"delta_kinetic": self.ke - self.ke0, "delta_potential": -w["weight"],
                "aero_work": w["aero"], "thrust_work": w["prop"] + w["ideal_thrust"],
                "tether_work": w["external"] - w["ideal_thrust"], "ground_work": w["gear"]}

    def residual(self) -> tuple[float, float]:
        """(energy change minus the work of every force, the largest term's magnitude) [J]."""
        t = self.terms()
        res = t["delta_kinetic"] + t["delta_potential"] - t["aero_work"] - t["thrust_work"] - t["tether_work"] - t["ground_work"]
        largest = max(abs(v) for v in t.values())
        return res, largest
