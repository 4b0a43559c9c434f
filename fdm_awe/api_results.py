"""The Python API's results (:mod:`fdm_awe.api`): what ``fdm-awe optimize``, ``fly`` and ``sweep``
print and write, as objects. Each holds the document its command's ``--json`` writes
(:meth:`~OptimizeResult.to_dict`, :meth:`~OptimizeResult.to_json`, NaN written as ``null``),
its time series as numpy arrays named as the CSV columns (the unit in every name, e.g.
``tension_N``; :meth:`~FlightResult.arrays`) and makes a pandas ``DataFrame`` on request
(:meth:`~FlightResult.to_dataframe`; pandas is not a dependency of the package). Units are SI.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Mapping

if TYPE_CHECKING:  # pragma: no cover
    import numpy as np

    from .ocp.result import CycleResult
    from .sim.report import FlightReport
    from .trajectory import ReferenceTrajectory


def _arrays(series: Any) -> dict[str, "np.ndarray"]:
    """The columns of a :class:`~fdm_awe.recording.series.Series` as CSV-named arrays
    (``t_s`` first, the unit in every name) and ``phase`` (labels)."""
    import numpy as np

    from .recording.series import csv_name

    out: dict[str, Any] = {"t_s": np.asarray(series.t, float)}
    for name in series.columns:
        out[csv_name(name, series.unit(name))] = np.asarray(series[name], float)
    out["phase"] = np.asarray(series.phase, dtype=object)
    return out


def _dataframe(columns: Mapping[str, Any], what: str) -> Any:
    """``columns`` as a pandas ``DataFrame`` (pandas imported now; a clear error without it)."""
    try:
        import pandas as pd
    except ImportError:
        raise ImportError(f"{what}.to_dataframe() needs pandas, which fdm-awe does not depend on: install it "
                          f"(pip install 'fdm-awe[dataframe]' or pip install pandas), or use {what}.arrays(), a "
                          "dict of numpy arrays") from None
    return pd.DataFrame(dict(columns))


def _write_json(doc: Any, path: str | os.PathLike | None) -> str:
    """``doc`` as the commands write it (NaN as null); written atomically to ``path`` when given."""
    from .fileio import json_text, write_json

    if path is not None:
        write_json(path, doc)
    return json_text(doc)


@dataclass
class OptimizeResult:
    """An optimised pumping cycle: what ``fdm-awe optimize`` prints and writes.

    Attributes
    ----------
    result : CycleResult
        The optimiser's own result (:class:`fdm_awe.ocp.result.CycleResult`).
    document : dict
        The ``--json`` document of ``fdm-awe optimize``: ``status``, ``T1_s``, ``T2_s`` [s],
        ``E_generated_J``, ``E_thrust_J``, ``E_reel_in_J``, ``E_net_J`` [J], ``P_avg_W`` [W], ...

    The summary numbers are attributes too: ``res.E_net_J`` [J], ``res.P_avg_W`` [W],
    ``res.T1_s`` [s] (``None`` when the optimisation failed).
    """

    result: "CycleResult"
    document: dict[str, Any]

    @property
    def ok(self) -> bool:
        """Whether a cycle was found (status ``ok``: IPOPT converged and every constraint holds)."""
        return bool(self.result.ok)

    def __getattr__(self, name: str) -> Any:
        doc = self.__dict__.get("document", {})
        if name in doc:
            return doc[name]
        raise AttributeError(f"{type(self).__name__} has no attribute {name!r}")

    def to_dict(self) -> dict[str, Any]:
        """The ``--json`` document of ``fdm-awe optimize`` (a copy; NaN as in the result)."""
        return dict(self.document)

    def to_json(self, path: str | os.PathLike | None = None) -> str:
        """The ``--json`` text (NaN written as ``null``); also written atomically to ``path``."""
        return _write_json(self.document, path)

    def reference(self) -> "ReferenceTrajectory":
        """The reference trajectory of the cycle: what its ``--trajectory`` file holds."""
        from .trajectory import reference_from_result

        self._require_ok("reference")
        return reference_from_result(self.result, f"the optimised {self.result.scenario} {self.result.config} reference")

    def write_reference(self, path: str | os.PathLike) -> Path:
        """Write the reference-trajectory file (``--trajectory``) atomically; returns its path."""
        from .trajectory import write_reference

        self._require_ok("write_reference")
        return write_reference(self.result, path)

    def arrays(self) -> dict[str, "np.ndarray"]:
        """The cycle's time series [SI units, named with them]: ``t_s``, ``x_m``, ..., ``phase``."""
        from .recording.series import cycle_series

        self._require_ok("arrays")
        return _arrays(cycle_series(self.result))

    def to_dataframe(self) -> Any:
        """:meth:`arrays` as a pandas ``DataFrame`` (needs pandas, not a dependency)."""
        return _dataframe(self.arrays(), "OptimizeResult")

    def _require_ok(self, what: str) -> None:
        if not self.ok:
            from .errors import InputError

            raise InputError(f"{what}: the optimisation found no cycle ({self.result.status}: {self.result.reason})")


@dataclass
class FlightResult:
    """A flight in 6-DOF co-simulation: what ``fdm-awe fly`` prints and writes.

    Attributes
    ----------
    report : FlightReport
        The flight's report (:class:`fdm_awe.sim.report.FlightReport`).
    document : dict
        The ``--json`` document of ``fdm-awe fly``: ``status``, ``cycles`` (one dict per cycle,
        ``index`` from 0, energies [J], times [s], tracking error [m]), ``optimised`` (the
        reference's own energies [J], [W] and phase times [s]), ``realtime_factor`` (measured), ...
    reference : TrackingReference
        The reference flown (:class:`fdm_awe.autopilot.tracking.TrackingReference`).
    exit_code : int
        The command's exit code for this flight (0 every requested cycle flown, 1 otherwise).
    """

    report: "FlightReport"
    document: dict[str, Any]
    reference: Any
    exit_code: int

    @property
    def status(self) -> str:
        """``ok``, ``incomplete``, ``landed``, ``interrupted`` or a ground-station event."""
        return str(self.document["status"])

    @property
    def cycles(self) -> list[dict[str, Any]]:
        """One dict per cycle, as the JSON's ``cycles`` (``index`` from 0)."""
        return list(self.document["cycles"])

    @property
    def optimised(self) -> dict[str, float] | None:
        """The reference's own cycle (energies [J], ``P_avg_W`` [W], ``T1_s``/``T2_s`` [s])."""
        return self.document.get("optimised")

    def to_dict(self) -> dict[str, Any]:
        """The ``--json`` document of ``fdm-awe fly`` (NaN written as ``None``)."""
        return dict(self.document)

    def to_json(self, path: str | os.PathLike | None = None) -> str:
        """The ``--json`` text; also written atomically to ``path``."""
        return _write_json(self.document, path)

    def arrays(self) -> dict[str, "np.ndarray"]:
        """Every recorded quantity [SI, named with its unit, as the CSV]: ``t_s``, ``x_m``,
        ``roll_rad``, ``tension_N``, ..., ``phase``."""
        from .recording.series import flight_series

        return _arrays(flight_series(self.report))

    def to_dataframe(self) -> Any:
        """:meth:`arrays` as a pandas ``DataFrame`` (needs pandas, not a dependency)."""
        return _dataframe(self.arrays(), "FlightResult")


@dataclass
class SweepResult:
    """A sweep of optimised cycles: what ``fdm-awe sweep`` prints and writes.

    Attributes
    ----------
    document : dict
        The ``--json`` document of ``fdm-awe sweep``: ``points`` (one record per point: ``config``,
        ``wind_mps`` [m/s], ``status``, ``P_avg_W`` [W], ``E_net_J`` [J], ...), ``answer``, ``files``.
    out : Path
        The sweep's folder (point files, ``points.csv``, plots, ``summary.md``).
    exit_code : int
        The command's exit code (0 every point has a result, 1 some have none).
    """

    document: dict[str, Any]
    out: Path
    exit_code: int
    points: list[dict[str, Any]] = field(default_factory=list)

    def __post_init__(self) -> None:
        self.points = list(self.document.get("points", []))

    def to_dict(self) -> dict[str, Any]:
        """The ``--json`` document of ``fdm-awe sweep``."""
        return dict(self.document)

    def to_json(self, path: str | os.PathLike | None = None) -> str:
        """The ``--json`` text; also written atomically to ``path``."""
        return _write_json(self.document, path)

    def arrays(self) -> dict[str, "np.ndarray"]:
        """The points as columns (a key of any point's record, its values in point order; a
        missing value is NaN for numbers, ``None`` otherwise): ``wind_mps``, ``P_avg_W``, ..."""
        import numpy as np

        keys: list[str] = []
        for r in self.points:
            keys += [k for k, v in r.items() if k not in keys and not isinstance(v, (dict, list))]
        out: dict[str, Any] = {}
        for k in keys:
            vals = [r.get(k) for r in self.points]
            if all(v is None or isinstance(v, (int, float)) and not isinstance(v, bool) for v in vals):
                out[k] = np.array([np.nan if v is None else float(v) for v in vals])
            else:
                out[k] = np.asarray(vals, dtype=object)
        return out

    def to_dataframe(self) -> Any:
        """:meth:`arrays` as a pandas ``DataFrame`` (needs pandas, not a dependency)."""
        return _dataframe(self.arrays(), "SweepResult")


def tracking_reference(reference: Any) -> Any:
    """A :class:`~fdm_awe.autopilot.tracking.TrackingReference` of an in-memory reference: an
    :class:`OptimizeResult`, a cycle result, a reference trajectory or a tracking reference."""
    from .autopilot.tracking import TrackingReference

    if isinstance(reference, TrackingReference):
        return reference
    if isinstance(reference, OptimizeResult):
        reference._require_ok("fly")
        reference = reference.result
    return TrackingReference.from_ocp(reference)
