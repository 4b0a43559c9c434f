"""Where the lumped-mass line lives in the ground station's arrays, and how it is read.

The line (:mod:`.lumped`, ``tether="lumped:N"``) keeps its state and its energy ledger in the
ground station's state array after the drivetrain's: a head (:data:`HEAD`), the ledger
(:data:`FIELDS`, layout :data:`LINE_LEDGER`), then from :data:`NODES` the node positions
(N+1)x3, velocities (N+1)x3, forces (N+1)x3 m, m/s, N NED and the segment tensions N. Its
constants follow :data:`.substeps.STATION` in the constants array (:data:`LINE`;
:func:`line_constants`).

Here too: the state array's length (:func:`state_size`) and views of the state (:func:`nodes`, :func:`velocities`,
:func:`tensions`, :class:`LineLedger`). The indices are compiled into the line's step as
constants (its on-disk cache is tied to this file).
"""

from __future__ import annotations

import numpy as np

from .. import slots
from .ledger import Balance
from .substeps import STATION, STEP

#: allowed segment counts
N_MIN, N_MAX = 2, 200
#: inner-step fraction of the leapfrog stability limit 2 / omega_max
CFL = 0.8
#: axial damping ratio of a segment in flight (of its own k-m mode)
ZETA = 0.05

#: head of the line's block in the ground station's state array, after the drivetrain's block:
#: initialised flag, segments, mean glider-end tension of the last step N, largest segment
#: tension of the last step N, inner steps per drivetrain sub-step, force-on-glider terms of the
#: last step (drag part, weight part, N NED)
HEAD = slots.declare("LumpedHead", ("ready", "nseg", "tension_glider", "tension_max", "inner", "drag_x", "drag_y",
                                    "drag_z", "weight_z"), start=slots.size(STEP))
#: the line's ledger (J; :mod:`.lumped` explains each term)
INPUTS = ("hook_work", "mass_inflow")
LOSSES = ("payout_work", "drag", "damping", "break_release")
STORES = ("kinetic", "elastic", "potential")
INTERFACE = ("drum_handover",)
FIELDS = INPUTS + LOSSES + INTERFACE + tuple("stored0_" + s for s in STORES) + tuple("stored_" + s for s in STORES)
#: its place after the head
LINE_LEDGER = slots.declare("LumpedLedger", FIELDS, start=slots.size(HEAD))
#: first node coordinate: positions (N+1)x3, velocities (N+1)x3, forces (N+1)x3, tensions N
NODES = slots.size(LINE_LEDGER)
#: the line's constants after the station's (:data:`.substeps.STATION`): segments, drag factor,
#: damping ratio, inner-step fraction of the stability limit; the wind field along the line
#: (:func:`.lumped_forces.wind_at`): profile numbers of fdm_awe.wind.shear_factor (code 0: the station's
#: uniform wind), the wind at the profile's reference height, and the gust of the moment
#: (turbulence, NED)
LINE = slots.declare("LumpedConstants", ("nseg", "drag_k", "zeta", "cfl", "shear_code", "shear_param", "shear_href",
                                         "shear_floor", "wref_n", "wref_e", "gust_n", "gust_e", "gust_d", "scheme",
                                         "h_implicit"),
                     start=slots.size(STATION))
#: the line's integrators (the constant ``scheme``): leapfrog sub-stepped below the axial
#: stability limit (``lumped:N``), linearly implicit Euler steps of at most ``h_implicit`` s
#: (``lumped-implicit:N``)
SCHEMES = ("leapfrog", "implicit")
#: longest step of the implicit integrator, s (one step per 1/120 s flight step)
H_IMPLICIT = 1.0 / 120.0


def state_size(n: int) -> int:
    """Length of the ground station's state array with an ``n``-segment line."""
    return NODES + 9 * (n + 1) + n


def line_constants(nseg: int, rho: float, cd: float, diameter: float, scale: float, zeta: float = ZETA,
                   cfl: float = CFL, scheme: str = "leapfrog", h_implicit: float = H_IMPLICIT) -> list[float]:
    """The constants after the station's (:data:`LINE`): segments, ``-0.5 rho C_D_perp
    d_t scale`` (kg/m^2), damping ratio, inner-step fraction of the stability limit, the wind
    slots (set per flight), the integrator (one of :data:`SCHEMES`) and the implicit step, s."""
    return ([float(nseg), -0.5 * rho * cd * diameter * scale, float(zeta), float(cfl)] + [0.0] * 9
            + [float(SCHEMES.index(scheme)), float(h_implicit)])


def nodes(s: np.ndarray, n: int) -> np.ndarray:
    """Node positions (n+1, 3) m NED (a copy)."""
    return s[NODES:NODES + 3 * (n + 1)].reshape(n + 1, 3).copy()


def velocities(s: np.ndarray, n: int) -> np.ndarray:
    """Node velocities (n+1, 3) m/s NED (a copy; the hook's is not kept)."""
    a = NODES + 3 * (n + 1)
    return s[a:a + 3 * (n + 1)].reshape(n + 1, 3).copy()


def tensions(s: np.ndarray, n: int) -> np.ndarray:
    """Segment tensions (n,) N, winch end first (a copy)."""
    a = NODES + 9 * (n + 1)
    return s[a:a + n].copy()


class LineLedger(Balance):
    """The line's energy ledger (J) as a view of the ground station's state array."""

    _INPUTS, _LOSSES, _STORES, _INTERFACE = INPUTS, LOSSES, STORES, INTERFACE

    def __init__(self, s: np.ndarray) -> None:
        self._s = s

    def __getattr__(self, name: str) -> float:
        if name in FIELDS:
            return float(self._s[getattr(LINE_LEDGER, name)])
        raise AttributeError(name)

    def clear(self) -> None:
        for f in FIELDS:
            if not f.startswith("stored"):
                self._s[getattr(LINE_LEDGER, f)] = 0.0
        led = LINE_LEDGER
        self._s[led.stored0_kinetic], self._s[led.stored0_elastic], self._s[led.stored0_potential] = (
            self._s[led.stored_kinetic], self._s[led.stored_elastic], self._s[led.stored_potential])

    def as_dict(self) -> dict[str, float]:
        """The balance's terms (:meth:`Balance.as_dict`) and ``coupling``, the drum's one-sub-step
        lag: the elastic energy the line handed over minus what the drum booked, J."""
        d = super().as_dict()
        d["coupling"] = self.payout_work - self.drum_handover
        return d
