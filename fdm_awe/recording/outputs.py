"""Everything a run leaves behind, in one call per command.

``flight_outputs(report, reference, rrd=..., out_dir=...)`` (``fdm-awe fly``) and
``cycle_outputs(result_or_file, rrd=..., out_dir=...)`` (``fdm-awe optimize``) write the
recording, and with ``out_dir`` also the PNGs, the CSV and the markdown report. They return
``{"rrd": path, "plots": [paths], "csv": path, "report": path}`` (only what was written, as
strings, ready for the ``--json`` output).

:func:`output_files` names the files such a call will write, so that a command checks them
(:func:`fdm_awe.fileio.check_output_file`) before its work starts. Every file is written under
a temporary name and renamed when complete (:mod:`fdm_awe.fileio`): an interruption leaves
the files finished before it and no truncated one.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from ..fileio import atomic_write_text


def output_files(out_dir: str | Path | None, prefix: str, rrd: str | Path | None = None) -> dict[str, Path]:
    """The files :func:`flight_outputs` / :func:`cycle_outputs` write: ``rrd`` (the given path,
    else ``<out_dir>/<prefix>.rrd``) and in ``out_dir`` the two PNGs, the CSV and the report.
    Keys: ``rrd``, ``plot_3d``, ``plot_time``, ``csv``, ``report``."""
    files: dict[str, Path] = {}
    if rrd is not None:
        files["rrd"] = Path(rrd)
    if out_dir is not None:
        from .plots import plot_paths

        d = Path(out_dir)
        files.setdefault("rrd", d / f"{prefix}.rrd")
        files["plot_3d"], files["plot_time"] = plot_paths(d, prefix)
        files.update(csv=d / f"{prefix}.csv", report=d / f"{prefix}.md")
    return files


def flight_outputs(report: Any, reference: Any = None, *, rrd: str | Path | None = None,
                   out_dir: str | Path | None = None, prefix: str = "flight",
                   written: dict[str, Any] | None = None) -> dict[str, Any]:
    """Recording (``rrd``), and in ``out_dir``: ``<prefix>_3d.png``, ``<prefix>_time.png``,
    ``<prefix>.csv``, ``<prefix>.md``. Works for complete, failed and interrupted flights
    (FlightReport, or a bare FlightResult).

    ``written`` (optional) is filled as each file is finished, so a caller interrupted in the
    middle (Ctrl-C) still knows which files exist.
    """
    from .csvexport import export_csv
    from .flight import record_flight

    written = {} if written is None else written
    files = output_files(out_dir, prefix, rrd)
    if "rrd" in files:
        written["rrd"] = str(record_flight(report, reference, files["rrd"]))
    if out_dir is not None:
        from .plots import plot_flight
        from .report import flight_markdown

        d = Path(out_dir)
        d.mkdir(parents=True, exist_ok=True)
        written["plots"] = [str(p) for p in plot_flight(report, reference, d, prefix=prefix)]
        written["csv"] = str(export_csv(report, files["csv"]))
        written["report"] = str(atomic_write_text(files["report"], flight_markdown(report) + "\n"))
    return written


def cycle_outputs(result: Any, *, rrd: str | Path | None = None, out_dir: str | Path | None = None,
                  prefix: str = "cycle", written: dict[str, Any] | None = None) -> dict[str, Any]:
    """Same for an optimised cycle (``ok`` CycleResult, reference-trajectory file or trajectory);
    a failed CycleResult has no trajectory: nothing is written."""
    from .csvexport import export_cycle_csv
    from .flight import record_cycle

    written = {} if written is None else written
    if getattr(result, "ok", True) is False:
        return written
    files = output_files(out_dir, prefix, rrd)
    if "rrd" in files:
        written["rrd"] = str(record_cycle(result, files["rrd"]))
    if out_dir is not None:
        from .plots import plot_cycle
        from .report import cycle_markdown

        d = Path(out_dir)
        d.mkdir(parents=True, exist_ok=True)
        written["plots"] = [str(p) for p in plot_cycle(result, d, prefix=prefix)]
        written["csv"] = str(export_cycle_csv(result, files["csv"]))
        written["report"] = str(atomic_write_text(files["report"], cycle_markdown(result) + "\n"))
    return written


__all__ = ["cycle_outputs", "flight_outputs", "output_files"]
