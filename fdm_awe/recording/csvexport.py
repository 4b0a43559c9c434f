"""CSV export of time histories, the unit in every column name (``t_s, x_m, ..., tension_N``).

Columns come from :mod:`fdm_awe.recording.series` (SI units; angles rad; normalised commands
and the fold state carry the unit ``1``); the phase is a text column ``phase``. Missing values
(e.g. the ground-station columns of the initial row) are empty fields. The file is written
under a temporary name and renamed when complete (:func:`fdm_awe.fileio.atomic_path`): an
interrupted export leaves no truncated CSV.
"""

from __future__ import annotations

import csv
from pathlib import Path
from typing import Any

import numpy as np

from ..fileio import atomic_path
from .series import Series, csv_name, cycle_series, flight_series


def write_series_csv(s: Series, path: str | Path, precision: int = 6) -> Path:
    """Write ``s`` as CSV (header ``t_s``, each column ``name_unit``, ``phase``) atomically;
    returns the path."""
    p = Path(path)
    p.parent.mkdir(parents=True, exist_ok=True)
    names = list(s.columns)
    header = ["t_s"] + [csv_name(n, s.unit(n)) for n in names] + ["phase"]
    data = np.column_stack([s.t] + [s[n] for n in names]) if len(s.t) else np.zeros((0, len(header) - 1))
    fmt = f"{{:.{precision}g}}"
    with atomic_path(p) as tmp, tmp.open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(header)
        for i, row in enumerate(data):
            w.writerow([fmt.format(v) if np.isfinite(v) else "" for v in row] + [s.phase[i]])
    return p


def export_csv(flight: Any, path: str | Path) -> Path:
    """Time histories of a flight (FlightReport or FlightResult, complete or cut short)."""
    return write_series_csv(flight_series(flight), path)


def export_cycle_csv(reference: Any, path: str | Path) -> Path:
    """Time histories of an optimised cycle (reference-trajectory file, trajectory or CycleResult)."""
    return write_series_csv(cycle_series(reference), path)


__all__ = ["export_csv", "export_cycle_csv", "write_series_csv"]
