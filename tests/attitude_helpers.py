"""Stand-ins for attitude-law tests: a glider's derivatives, inertia and geometry without
JSBSim, random coefficient vectors, states built from raw rows."""

from __future__ import annotations

import math
import random

import numpy as np

from fdm_awe import slots
from fdm_awe.sixdof import attitude_law as L
from fdm_awe.sixdof import row as R
from fdm_awe.sixdof.state import SixDofState
from fdm_awe.units import SLUG_FT2


def random_coef(rnd: random.Random, invert: bool) -> list[float]:
    """A coefficient vector of a small glider, the unused entries NaN as the law leaves them."""
    c = [math.nan] * slots.size(L.COEF)
    c[L.COEF.cm_de], c[L.COEF.cl_da] = rnd.uniform(-1.5, -0.5), rnd.uniform(0.1, 0.4)
    c[L.COEF.cn_dr] = rnd.uniform(-0.1, -0.02)
    c[L.COEF.cn_beta] = rnd.uniform(0.02, 0.1)
    if invert:
        c[L.COEF.cm0], c[L.COEF.cm_alpha] = rnd.uniform(-0.05, 0.1), rnd.uniform(-2.0, -0.5)
        c[L.COEF.cm_q] = rnd.uniform(-20, -5)
        c[L.COEF.cl_beta], c[L.COEF.cl_p] = rnd.uniform(-0.1, 0.0), rnd.uniform(-0.6, -0.3)
        c[L.COEF.cl_r] = rnd.uniform(0.0, 0.2)
    else:
        c[L.COEF.de_trim] = rnd.uniform(-0.1, 0.1)
    c[L.COEF.ixx], c[L.COEF.iyy], c[L.COEF.izz] = rnd.uniform(0.02, 0.2), rnd.uniform(0.01, 0.1), rnd.uniform(0.03, 0.3)
    c[L.COEF.s], c[L.COEF.b], c[L.COEF.c] = rnd.uniform(0.2, 0.5), rnd.uniform(1.2, 2.5), rnd.uniform(0.15, 0.3)
    c[L.COEF.lim_e], c[L.COEF.lim_a], c[L.COEF.lim_r] = 0.349, 0.349, 0.436
    return c


class Glider:
    """The glider's side of the law: derivatives, inertia, geometry, limits and trim (counted)."""

    surface_limits_rad = {"elevator": 0.349, "aileron": 0.349, "rudder": 0.436}

    def __init__(self) -> None:
        self.reads = 0
        self.fold = 0.0

    def reference_geometry(self) -> tuple[float, float, float]:
        return 0.35, 1.8, 0.2

    def coefficient(self, name: str) -> float:
        """A property of :data:`fdm_awe.sixdof.attitude_law.LAW_PROPERTIES` (the inertia in slug ft^2)."""
        self.reads += 1
        if name.startswith("inertia/"):
            i = "xyz".index(name[9])
            return float(self.inertia()[i, i]) / SLUG_FT2
        base = {"Cm_de": -1.1, "Cl_da": 0.25, "Cn_dr": -0.06, "Cn_beta": 0.05, "Cm0": 0.03, "Cm_alpha": -1.2,
                "Cm_q": -12.0, "Cl_beta": -0.04, "Cl_p": -0.45, "Cl_r": 0.1}[name.rsplit("/", 1)[1]]
        return base * (1.0 + 0.3 * self.fold)

    def inertia(self) -> np.ndarray:
        return np.diag([0.08, 0.05, 0.12]) * (1.0 + 0.1 * self.fold)

    def trim_elevator(self, alpha: float) -> float:
        return -(0.03 - 1.2 * alpha) / -1.1 / 0.349


def state(fold: float, rnd: random.Random) -> SixDofState:
    """A state at fold state ``fold``: random angles and rates, flight values of qbar and
    airspeed, in JSBSim's units with the adapter's scale factors."""
    raw = [rnd.uniform(-0.3, 0.3) for _ in range(slots.size(R.ROW))]
    raw[R.ROW.qbar], raw[R.ROW.vt] = rnd.uniform(1, 8), rnd.uniform(20, 100)
    raw[R.ROW.fold], raw[R.ROW.mass] = fold, 0.05
    scale = [1.0] * slots.size(R.ROW)
    scale[R.ROW.qbar], scale[R.ROW.vt], scale[R.ROW.mass] = 47.88, 0.3048, 14.59
    return SixDofState(raw, scale, [0.0] * slots.size(R.ROW), ((0.0,) * 3, (0.0,) * 3), (0.0, 0.0, 0.0), 12.0)
