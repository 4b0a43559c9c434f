"""Energy ledger of the ground station: every joule between the glider end of the line and the
electrical terminals, accumulated by the implicit integrator.

Balance (all terms in J, closes to round-off by construction of the discrete powers)::

    glider_work + supply + wound_line_kinetic + strain_payout
      = load + copper + semiconductor + brake + coulomb + viscous + end_stop + break_release + numerical
        + delta(kinetic + inductor + capacitor + elastic)

Inputs
    ``glider_work``  work done by the glider on the line end, ``int T d(d)`` (> 0 generating).
    ``supply``       energy drawn from the DC supply V_a (motor mode), ``int d1 V_a i dt``.
    ``wound_line_kinetic``  kinetic energy handed to / taken from the line as it leaves / returns
                     to the drum (the drum inertia J is constant, the paid-out line's axial mass
                     ``mu l r_w^2`` is not), ``sum 0.5 (J_eff,1 - J_eff,0) omega^2``.
    ``strain_payout`` change of the strain energy 0.5 (EA/l) s^2 caused by the change of the
                     unstretched length l at a given stretch s, ``sum 0.5 (EA/l_1 - EA/l_0) s^2``
                     (< 0 while paying out: strained line leaves the drum; order strain x work).
Outputs / losses
    ``load`` into R_L; ``copper`` R i^2; ``semiconductor`` 2 U_d i (diodes and switches);
    ``brake`` burnt by the supply bus's brake chopper: what the current limit returns through D1
    and D2 in motor mode, both switches open (:func:`.substeps.hold_current`);
    ``coulomb`` M_c |omega|; ``viscous`` B omega^2; ``end_stop`` absorbed by the drum's end stops;
    ``break_release`` strain energy lost when the line breaks; ``numerical`` the backward-Euler
    integrator's own dissipation ``0.5 J dw^2 + 0.5 L di^2 + 0.5 C du^2 + (T ds - dE_el)`` (>= 0,
    reported so its size is visible; small at the default sub-step).
Stored
    ``kinetic`` 0.5 (J + mu l r_w^2) omega^2, ``inductor`` 0.5 L i^2, ``capacitor`` 0.5 C u_L^2,
    ``elastic`` 0.5 (EA/l) (d - l)^2 when taut.
Interface flows (not part of the balance; they cancel inside it)
    ``drum_work`` = int r_w T omega dt (mechanical energy into the drum, > 0 reel-out under load),
    ``airgap`` = int K i omega dt (mechanical -> electrical in the machine, > 0 generating).
Glider-side line forces (work done ON the glider by the line drag/weight shares; these forces
act on the glider, not on the station, and are listed for a whole-system balance)
    ``line_drag_work_on_glider``, ``line_weight_work_on_glider``.
"""

from __future__ import annotations

import numpy as np

INPUTS = ("glider_work", "supply", "wound_line_kinetic", "strain_payout")
LOSSES = ("load", "copper", "semiconductor", "brake", "coulomb", "viscous", "end_stop", "break_release", "numerical")
STORES = ("kinetic", "inductor", "capacitor", "elastic")
INTERFACE = ("drum_work", "airgap", "line_drag_work_on_glider", "line_weight_work_on_glider")
#: Every term, in the order of the ledger's float buffer (``EnergyLedger.buffer``).
FIELDS = INPUTS + LOSSES + INTERFACE + tuple("stored0_" + s for s in STORES) + tuple("stored_" + s for s in STORES)
#: Index of each term in the buffer (the compiled ground-station step adds into it directly).
INDEX = {name: i for i, name in enumerate(FIELDS)}


def _term(i: int) -> property:
    def get(self: "EnergyLedger") -> float:
        return self.buffer.item(i)

    def set_(self: "EnergyLedger", v: float) -> None:
        self.buffer[i] = v

    return property(get, set_, doc=f"{FIELDS[i]}, J")


class Balance:
    """The balance of a ledger whose terms are attributes: ``inputs - losses - delta(stored)``
    over the term names of the class (``_INPUTS``, ``_LOSSES``, ``_STORES``, ``_INTERFACE``;
    ``stored0_<s>`` / ``stored_<s>`` the stored energies at the start and now), J. Shared by the
    ground station's ledger and the lumped line's."""

    __slots__ = ()
    _INPUTS: tuple[str, ...] = ()
    _LOSSES: tuple[str, ...] = ()
    _STORES: tuple[str, ...] = ()
    _INTERFACE: tuple[str, ...] = ()

    def delta_stored(self) -> float:
        """Change of the stored energy since the start, J."""
        return sum(getattr(self, "stored_" + s) - getattr(self, "stored0_" + s) for s in self._STORES)

    def residual(self) -> float:
        """Inputs - losses - change of stored energy, J (0 when every joule is accounted for)."""
        return (sum(getattr(self, k) for k in self._INPUTS) - sum(getattr(self, k) for k in self._LOSSES)
                - self.delta_stored())

    def largest_term(self) -> float:
        """Largest magnitude among the balance terms (flows and stored-energy changes), J."""
        terms = [abs(getattr(self, k)) for k in self._INPUTS + self._LOSSES]
        terms += [abs(getattr(self, "stored_" + s) - getattr(self, "stored0_" + s)) for s in self._STORES]
        return max(terms) if terms else 0.0

    def relative_residual(self) -> float:
        """|residual| / largest term (0 when nothing happened)."""
        big = self.largest_term()
        return abs(self.residual()) / big if big > 0.0 else 0.0

    def as_dict(self) -> dict[str, float]:
        """All terms (J) plus ``delta_<store>``, ``residual`` and ``relative_residual``."""
        d = {k: getattr(self, k) for k in self._INPUTS + self._LOSSES + self._INTERFACE}
        for s in self._STORES:
            d["delta_" + s] = getattr(self, "stored_" + s) - getattr(self, "stored0_" + s)
        d["residual"] = self.residual()
        d["relative_residual"] = self.relative_residual()
        return d


class EnergyLedger(Balance):
    """Accumulated energy terms (J) since the last :meth:`clear`.

    The terms live in one float64 array ``buffer`` (order :data:`FIELDS`); each is also an
    attribute (read as a Python float). ``buffer`` may be a view into a larger array (the
    ground station keeps its states and its ledger in one array for the compiled step)."""

    __slots__ = ("buffer",)
    _INPUTS, _LOSSES, _STORES, _INTERFACE = INPUTS, LOSSES, STORES, INTERFACE

    def __init__(self, buffer: np.ndarray | None = None) -> None:
        if buffer is None:
            buffer = np.zeros(len(FIELDS))
        elif buffer.shape != (len(FIELDS),) or buffer.dtype != np.float64:
            raise ValueError(f"EnergyLedger buffer: need float64 shape ({len(FIELDS)},), got {buffer.dtype} {buffer.shape}")
        self.buffer = buffer
        self.clear()

    def clear(self, stored: dict[str, float] | None = None) -> None:
        """Zero all flows; ``stored`` (kinetic, inductor, capacitor, elastic) sets the start state."""
        for k in INPUTS + LOSSES + INTERFACE:
            setattr(self, k, 0.0)
        for s in STORES:
            v = (stored or {}).get(s, 0.0)
            setattr(self, "stored0_" + s, v)
            setattr(self, "stored_" + s, v)

    def set_stored(self, kinetic: float, inductor: float, capacitor: float, elastic: float) -> None:
        self.stored_kinetic = kinetic
        self.stored_inductor = inductor
        self.stored_capacitor = capacitor
        self.stored_elastic = elastic


for _i, _name in enumerate(FIELDS):
    setattr(EnergyLedger, _name, _term(_i))
del _i, _name
