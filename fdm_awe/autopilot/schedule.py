"""A set of references, each optimised for one wind, and the choice among them by the wind met.

A reference set is a folder of reference files (``fdm-awe optimize --trajectory``, or
``scripts/reference_set.py`` for a whole set). Each file records the wind it was optimised for
in its metadata: ``wind_mps`` at the height of its ``wind_profile`` (uniform: at every height)
from ``wind_from_deg``. The set must be one cycle family: the same scenario, configuration,
line, generator, wind profile and wind direction in every file (a one-line error names the
file and the field that differs), and no two files for the same wind.

The choice (:meth:`ReferenceSet.nearest`) is the reference whose wind is nearest the estimated
wind at the profile's reference height (:mod:`.wind_estimate`; in a uniform set the wind at the
glider), not an interpolation between references: two optimal cycles of different winds
differ in period, phase times, loop sizes and motor plan, and a cycle interpolated between them
is neither optimal nor checked flyable, while every file of the set is. The set's spacing is
then the resolution of the choice (half the spacing at most off the met wind). A tie keeps the
reference flown (no switching back and forth on an estimate midway between two winds).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

from ..errors import InputError
from ..wind import WindProfile
from .tracking import TrackingReference

#: the metadata every reference of a set must share (field -> what it is)
SHARED_FIELDS = {"scenario": "scenario", "config": "configuration", "line": "line", "generator": "generator"}
#: two winds closer than this [m/s] are one wind (a duplicate)
SAME_WIND_MPS = 1e-6
#: largest difference of two references' wind directions [deg]
DIRECTION_TOL_DEG = 1.0


@dataclass(frozen=True)
class ScheduledReference:
    """One reference of a set: the wind it was optimised for (``wind_mps`` at the profile's
    reference height, m/s), the reference and where it came from."""

    wind_mps: float
    reference: TrackingReference
    source: str


class ReferenceSet:
    """References of one cycle family, ordered by wind (module doc); ``entries`` as
    :class:`ScheduledReference`, at least one."""

    def __init__(self, entries: list[ScheduledReference]) -> None:
        if not entries:
            raise InputError("reference set: no reference (allowed: one or more reference files)")
        self.entries = sorted(entries, key=lambda e: e.wind_mps)
        first = self.entries[0]
        m0 = first.reference.meta
        self.profile = WindProfile.from_dict(m0.get("wind_profile"), f"{first.source}: metadata.wind_profile")
        self.wind_from_deg = float(m0.get("wind_from_deg", 180.0))
        for e in self.entries[1:]:
            m = e.reference.meta
            for key, what in SHARED_FIELDS.items():
                if m.get(key) != m0.get(key):
                    raise InputError(f"{e.source}: metadata.{key} {m.get(key)!r} is not the set's {what} "
                                     f"{m0.get(key)!r} ({first.source}; allowed: one {what} per set)")
            prof = WindProfile.from_dict(m.get("wind_profile"), f"{e.source}: metadata.wind_profile")
            if prof != self.profile:
                raise InputError(f"{e.source}: metadata.wind_profile {prof.label()} is not the set's "
                                 f"{self.profile.label()} ({first.source}; allowed: one profile per set)")
            d = float(m.get("wind_from_deg", 180.0))
            if abs((d - self.wind_from_deg + 180.0) % 360.0 - 180.0) > DIRECTION_TOL_DEG:
                raise InputError(f"{e.source}: metadata.wind_from_deg {d:g} is not the set's {self.wind_from_deg:g} "
                                 f"({first.source}; allowed: one wind direction per set, within "
                                 f"{DIRECTION_TOL_DEG:g} deg)")
        for a, b in zip(self.entries, self.entries[1:]):
            if abs(a.wind_mps - b.wind_mps) < SAME_WIND_MPS:
                raise InputError(f"{b.source}: metadata.wind_mps {b.wind_mps:g} is also the wind of {a.source} "
                                 f"(allowed: one reference per wind)")

    @classmethod
    def from_folder(cls, folder: str | Path, option: str = "--references") -> "ReferenceSet":
        """The set of every ``*.json`` reference file in ``folder`` (not hidden ones) (checked as a reference
        file each, then as a set; one-line :class:`InputError` naming ``option`` or the file)."""
        p = Path(folder)
        if not p.is_dir():
            raise InputError(f"{option} {folder}: not a folder (allowed: a folder of reference files)")
        # not hidden files: the temporary file of a write in progress is ``.<name>...part.json``
        files = sorted(f for f in p.glob("*.json") if not f.name.startswith("."))
        if not files:
            raise InputError(f"{option} {folder}: no reference file (*.json) in it")
        return cls([scheduled(TrackingReference.from_ocp_file(f), str(f)) for f in files])

    @property
    def winds(self) -> list[float]:
        """The set's winds [m/s], ascending."""
        return [e.wind_mps for e in self.entries]

    @property
    def longest_period(self) -> float:
        """The longest cycle of the set [s]."""
        return max(e.reference.period for e in self.entries)

    def nearest(self, wind_mps: float, current: int | None = None) -> int:
        """The index of the reference whose wind is nearest ``wind_mps`` [m/s]; on a tie the
        reference ``current`` (the one flown) when it is among the nearest; a wind that is not a
        number keeps ``current`` (else the lowest wind's)."""
        if not math.isfinite(wind_mps):
            return 0 if current is None else current
        d = [abs(w - wind_mps) for w in self.winds]
        best = min(d)
        near = [i for i, di in enumerate(d) if di <= best + 1e-12]
        return current if current in near else near[0]


def scheduled(reference: TrackingReference, source: str) -> ScheduledReference:
    """``reference`` (from ``source``) as a member of a set: its ``wind_mps`` checked."""
    w = reference.meta.get("wind_mps")
    if not isinstance(w, (int, float)) or isinstance(w, bool) or not math.isfinite(w) or w < 0.0:
        raise InputError(f"{source}: metadata.wind_mps {w!r} (allowed: the wind it was optimised for, >= 0 m/s)")
    return ScheduledReference(float(w), reference, source)
