"""A flight's onboard wind estimate per cycle, and the reference chosen for the next cycle.

:class:`CycleWind` keeps the glider's logged rows of the cycle being flown in AUTO (the same
raw rows whether a step ran in Python or in a compiled block, so both paths estimate alike).
At each cycle boundary (:attr:`fdm_awe.autopilot.autopilot.Autopilot.on_cycle`) it estimates the
cycle's wind from the sensed quantities only (pitot airspeed, AHRS attitude, GPS ground
velocity, the heights for the profile: :func:`fdm_awe.autopilot.wind_estimate.estimate_wind`),
records it beside the true mean wind at the glider (JSBSim's total wind over the same rows,
read for the record only, never by the estimate), notes it in the autopilot's log and, with a
reference set, names the reference of the next cycle (:class:`fdm_awe.autopilot.schedule.ReferenceSet`).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..autopilot.schedule import ReferenceSet
from ..autopilot.wind_estimate import WindEstimate, estimate_wind
from ..wind import WindProfile


#: the rate of the estimate's samples [Hz]: every step whose index is a multiple of the steps
#: in 1/SENSE_HZ (ArduPilot's EKF fuses airspeed at about this rate; a cycle gives hundreds)
SENSE_HZ = 10.0


class CycleWind:
    """The wind estimate of each cycle of a flight of ``glider`` (its ``convert_raw``) with
    steps of ``dt`` [s], with the onboard wind profile ``profile`` (the references'), and the
    reference set ``refs`` (None: no scheduling) whose member ``current`` is flown first."""

    def __init__(self, glider: Any, dt: float, profile: WindProfile, refs: ReferenceSet | None = None,
                 current: int = 0) -> None:
        self.glider = glider
        self.stride = max(1, int(round(1.0 / (SENSE_HZ * dt))))  #: steps between samples
        self.profile = profile
        self.refs = refs
        self.current = current
        self.records: list[dict[str, Any]] = []  #: one per cycle estimated (:meth:`close`)
        self.last: WindEstimate | None = None  #: the latest estimate
        self._chunks: list[np.ndarray] = []
        self._rows: list[tuple] = []

    def add(self, k: int, raw: Any) -> None:
        """Logged row ``k`` (a raw JSBSim row, :mod:`fdm_awe.sixdof.row`) of the cycle flown,
        kept when ``k`` is a sample's step."""
        if k % self.stride == 0:
            self._rows.append(tuple(raw))

    def add_block(self, k0: int, rows: np.ndarray) -> None:
        """The rows ``k0 + 1 ..`` of a compiled block (n x raw row), those of the samples' steps."""
        if self._rows:
            self._chunks.append(np.array(self._rows, float))
            self._rows = []
        first = (-(k0 + 1)) % self.stride
        self._chunks.append(np.array(rows[first::self.stride], float))

    def peek(self) -> np.ndarray | None:
        """The rows kept since the last cycle boundary (kept), None without any."""
        if self._rows:
            self._chunks.append(np.array(self._rows, float))
            self._rows = []
        return np.vstack(self._chunks) if self._chunks else None

    def _take(self) -> np.ndarray | None:
        """The rows kept since the last cycle boundary (then forgotten), None without any."""
        rows = self.peek()
        self._chunks = []
        return rows

    def close(self, cycle: int, t: float, complete: bool = True) -> dict[str, Any] | None:
        """Estimate the wind of cycle ``cycle`` (ended at ``t`` [s]) from its rows; returns its
        record (also kept in :attr:`records`), None when it had too few rows."""
        rows = self._take()
        if rows is None:
            return None
        si = self.glider.convert_raw(rows)
        h = -si["pos_ned"][:, 2]
        est = estimate_wind(si["vel_ned"], si["airspeed"], si["euler"], h,
                            None if self.profile.uniform else self.profile.factor)
        if est is None:
            return None
        true = np.mean(si["vel_ned"][:, :2] - si["vel_air_ned"][:, :2], axis=0)
        true_speed = float(np.hypot(*true))
        scale = est.at_glider / est.speed if est.speed > 0.0 else 1.0  # the profile's mean factor
        at = np.array([est.north, est.east]) * scale
        rec: dict[str, Any] = {
            "cycle": int(cycle), "t_s": float(t), "complete": bool(complete), "samples": est.samples,
            "estimated": est.as_dict(),
            "estimated_at_glider": {"north_mps": float(at[0]), "east_mps": float(at[1]), "speed_mps": est.at_glider},
            "true_at_glider": {"north_mps": float(true[0]), "east_mps": float(true[1]), "speed_mps": true_speed,
                               "from_deg": math.degrees(math.atan2(-true[1], -true[0])) % 360.0},
            "speed_error_rel": (est.at_glider - true_speed) / true_speed if true_speed > 0.0 else math.nan,
            "vector_error_rel": float(np.hypot(*(at - true))) / true_speed if true_speed > 0.0 else math.nan,
            "mean_height_m": float(np.mean(h)),
        }
        if self.refs is not None:
            rec["reference_wind_mps"] = self.refs.entries[self.current].wind_mps
        self.records.append(rec)
        self.last = est
        return rec

    def next_reference(self, est: WindEstimate) -> Any:
        """With a set: the reference for the estimate ``est`` when it is another than the one
        flown (the set's member then becomes :attr:`current`), else None."""
        if self.refs is None:
            return None
        i = self.refs.nearest(est.speed, self.current)
        if i == self.current:
            return None
        self.current = i
        return self.refs.entries[i].reference


def note_text(rec: dict[str, Any]) -> str:
    """The autopilot's note of a cycle's wind record."""
    e, tr = rec["estimated"], rec["true_at_glider"]
    return (f"wind estimate cycle {rec['cycle']}: {e['speed_mps']:.2f} m/s from {e['from_deg']:.0f} deg "
            f"({rec['estimated_at_glider']['speed_mps']:.2f} m/s at the glider; true mean {tr['speed_mps']:.2f} m/s "
            f"from {tr['from_deg']:.0f} deg)")
