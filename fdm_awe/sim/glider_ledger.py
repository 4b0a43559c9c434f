"""Work-energy bookkeeping of the glider's centre-of-gravity motion in JSBSim: the change of its
translational kinetic and potential energy against the work of each force JSBSim reports
(:mod:`fdm_awe.sim.flight` describes the flight's energy ledger)."""

from __future__ import annotations

from typing import Any

from ..units import FT, LBF, SLUG


class GliderLedger:
    """Work-energy bookkeeping of the glider's CG motion from JSBSim's force breakdown."""

    _FORCES = ("aero", "prop", "external", "gear", "weight")

    def __init__(self, glider: Any, ideal_thrust: bool = False) -> None:
        """``ideal_thrust``: the paper plant's body-x force is among JSBSim's external forces;
        its work is booked as thrust work, not tether work."""
        pm = glider.fdm.get_property_manager()
        node = lambda n: pm.get_node(n, False).get_double_value  # noqa: E731
        self._f = {k: [node(f"forces/fb{a}-{k}-lbs") for a in "xyz"] for k in self._FORCES}
        self._v = [node(f"velocities/{a}-fps") for a in "uvw"]
        self._mass = node("inertia/mass-slugs")
        self.work = {k: 0.0 for k in self._FORCES}
        self.work["ideal_thrust"] = 0.0
        self._ti = node("external_reactions/ideal-thrust/magnitude") if ideal_thrust else None
        self._v_prev = self._vel()
        self.ke0 = self._ke()
        self.ke = self.ke0

    def _vel(self) -> tuple[float, float, float]:
        """Body-axis velocity u, v, w [m/s]."""
        return (self._v[0]() * FT, self._v[1]() * FT, self._v[2]() * FT)

    def _ke(self) -> float:
        """Translational kinetic energy [J]."""
        v = self._vel()
        return 0.5 * self._mass() * SLUG * (v[0] ** 2 + v[1] ** 2 + v[2] ** 2)

    def step(self, dt: float) -> None:
        """Add each force's work over the step of ``dt`` [s] just flown (trapezoidal rule on the
        velocity at its two ends)."""
        v = self._vel()
        vm = [(a + b) * 0.5 for a, b in zip(v, self._v_prev)]
        for k, fs in self._f.items():
            self.work[k] += (fs[0]() * vm[0] + fs[1]() * vm[1] + fs[2]() * vm[2]) * LBF * dt
        if self._ti is not None:
            self.work["ideal_thrust"] += self._ti() * vm[0] * LBF * dt
        self._v_prev = v
        self.ke = self._ke()

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
