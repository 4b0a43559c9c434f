"""Everything a run leaves behind, in one call per command.

``flight_outputs(report, reference, rrd=..., out_dir=...)`` (``fdm-awe fly``) and
``cycle_outputs(result_or_file, rrd=..., out_dir=...)`` (``fdm-awe optimize``) write the
recording, and with ``out_dir`` also the PNGs, the CSV and the markdown report. They return
``{"rrd": path, "plots": [paths], "csv": path, "report": path}`` (only what was written, as
strings, ready for the ``--json`` output).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any


def flight_outputs(report: Any, reference: Any = None, *, rrd: str | Path | None = None,
                   out_dir: str | Path | None = None, prefix: str = "flight") -> dict[str, Any]:
    """Recording (``rrd``), and in ``out_dir``: ``<prefix>_3d.png``, ``<prefix>_time.png``,
    ``<prefix>.csv``, ``<prefix>.md``. Works for complete, failed and interrupted flights
    (FlightReport, or a bare FlightResult)."""
    from .csvexport import export_csv
    from .flight import record_flight

    written: dict[str, Any] = {}
    if out_dir is not None and rrd is None:
        rrd = Path(out_dir) / f"{prefix}.rrd"
    if rrd is not None:
        written["rrd"] = str(record_flight(report, reference, rrd))
    if out_dir is not None:
        from .plots import plot_flight
        from .report import flight_markdown

        d = Path(out_dir)
        d.mkdir(parents=True, exist_ok=True)
        written["plots"] = [str(p) for p in plot_flight(report, reference, d, prefix=prefix)]
        written["csv"] = str(export_csv(report, d / f"{prefix}.csv"))
        md = d / f"{prefix}.md"
        md.write_text(flight_markdown(report) + "\n")
        written["report"] = str(md)
    return written


def cycle_outputs(result: Any, *, rrd: str | Path | None = None, out_dir: str | Path | None = None,
                  prefix: str = "cycle") -> dict[str, Any]:
    """Same for an optimised cycle (``ok`` CycleResult, reference-trajectory file or trajectory);
    a failed CycleResult has no trajectory: nothing is written."""
    from .csvexport import export_cycle_csv
    from .flight import record_cycle

    written: dict[str, Any] = {}
    if getattr(result, "ok", True) is False:
        return written
    if out_dir is not None and rrd is None:
        rrd = Path(out_dir) / f"{prefix}.rrd"
    if rrd is not None:
        written["rrd"] = str(record_cycle(result, rrd))
    if out_dir is not None:
        from .plots import plot_cycle
        from .report import cycle_markdown

        d = Path(out_dir)
        d.mkdir(parents=True, exist_ok=True)
        written["plots"] = [str(p) for p in plot_cycle(result, d, prefix=prefix)]
        written["csv"] = str(export_cycle_csv(result, d / f"{prefix}.csv"))
        md = d / f"{prefix}.md"
        md.write_text(cycle_markdown(result) + "\n")
        written["report"] = str(md)
    return written


__all__ = ["cycle_outputs", "flight_outputs"]
