"""A reference trajectory in memory: the file's metadata, columns and units, sampled by the
file's rules (:data:`REFERENCE_RULES`)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from .sampler import HELD, LINEAR, CycleSampler

#: How a reference file's columns are sampled (:meth:`ReferenceTrajectory.sample`): the states and
#: what follows from them linear in time within a phase, the optimiser's controls held per interval
#: as stored; a column not named here is linear.
REFERENCE_RULES: dict[str, str] = {
    "x": LINEAR, "y": LINEAR, "z": LINEAR, "V": LINEAR, "gamma": LINEAR, "psi": LINEAR,
    "alpha": HELD, "phi": HELD, "T": HELD, "tension": LINEAR, "tether_length": LINEAR, "reel_speed": LINEAR,
    "fold": HELD, "p_generated_W": LINEAR, "p_thrust_W": LINEAR, "p_reel_in_W": LINEAR,
    "motor_on": HELD, "boost_duty": HELD,
}


@dataclass
class ReferenceTrajectory:
    """A reference trajectory read back from its file (``source``: the file, for messages)."""

    metadata: dict[str, Any]
    columns: dict[str, np.ndarray]
    units: dict[str, str]
    source: str = "reference trajectory"

    @property
    def period(self) -> float:
        return float(self.metadata["period_s"])

    def __getitem__(self, name: str) -> np.ndarray:
        return self.columns[name]

    def sampler(self) -> CycleSampler:
        """The :class:`CycleSampler` of every column but ``t`` and ``phase``, by :data:`REFERENCE_RULES`."""
        c = self.columns
        key = (tuple((k, id(a)) for k, a in c.items()), self.metadata.get("T1_s"), self.metadata.get("period_s"))
        cached = self.__dict__.get("_sampler")
        if cached is None or cached[0] != key:
            cols = {k: a for k, a in c.items() if k not in ("t", "phase")}
            s = CycleSampler(c["t"], c["phase"], cols, {k: REFERENCE_RULES.get(k, LINEAR) for k in cols},
                             float(self.metadata["T1_s"]), self.period)
            cached = self.__dict__["_sampler"] = (key, s)
        return cached[1]

    def sample(self, t: float) -> dict[str, float]:
        """All columns at time ``t`` [s] (the cycle repeated), by :data:`REFERENCE_RULES`:
        ``{"phase", "t" (the cycle time), column: value, ...}``."""
        s = self.sampler().sample(t)
        out: dict[str, float] = {"phase": float(s.phase), "t": s.t_cycle}
        for k in self.columns:
            if k not in ("t", "phase"):
                out[k] = float(s[k])
        return out
