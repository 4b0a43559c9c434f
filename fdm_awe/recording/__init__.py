"""Recordings (rerun ``.rrd``), plots (PNG), reports (markdown) and CSV export of runs.

One-line entry points for the commands::

    flight_outputs(report, reference, rrd=path_or_None, out_dir=dir_or_None)   # all of the below
    cycle_outputs(result_or_reference_file, rrd=path_or_None, out_dir=dir_or_None)

    record_flight(report, reference, "run.rrd")        # 6-DOF flight, complete or cut short
    record_cycle("reference.json", "cycle.rrd")       # optimised cycle (file, trajectory or CycleResult)
    plot_flight(report, reference, "outdir")           # Fig. 7 / Fig. 8 style PNGs
    plot_cycle("reference.json", "outdir")
    export_csv(report, "run.csv")                      # time histories, units in the column names
    flight_markdown(report)                            # Table-3 style report

``FlightRecording`` (step callback + context manager) records the steps flown even when an
exception escapes the flight loop. rerun and matplotlib are imported only when a recording or plot is made.
"""

from __future__ import annotations

from typing import Any

_EXPORTS = {
    "record_flight": ".flight", "record_cycle": ".flight", "describe": ".flight",
    "flight_series": ".series", "cycle_series": ".series", "Series": ".series", "csv_name": ".series",
    "export_csv": ".csvexport", "export_cycle_csv": ".csvexport",
    "plot_flight": ".plots", "plot_cycle": ".plots", "plot_compare": ".plots", "plot_summary": ".plots",
    "flight_markdown": ".report", "cycle_markdown": ".report", "table3_markdown": ".report",
    "FlightRecording": ".live",
    "flight_outputs": ".outputs", "cycle_outputs": ".outputs",
    "rrd_verify": ".inspect", "rrd_stats": ".inspect", "rrd_entities": ".inspect", "rrd_views": ".inspect",
    "rrd_values": ".inspect", "flight_forces": ".forces", "LiveFlight": ".stream",
}


def __getattr__(name: str) -> Any:
    mod = _EXPORTS.get(name)
    if mod is None:
        raise AttributeError(name)
    import importlib

    return getattr(importlib.import_module(mod, __name__), name)


__all__ = sorted(_EXPORTS)
