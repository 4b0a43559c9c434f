"""Markdown reports in the style of the paper's Table 3.

Sign convention: energies are magnitudes (>= 0) except the net energy, which is > 0 for a net
gain (``E_net = E_generated - E_thrust - E_reel_in``). The paper's Table 3 prints gains as
negative numbers; every report says so in its note.
"""

from __future__ import annotations

import math
from typing import Any, Iterable, Sequence

SIGN_NOTE = ("Energies in J, all >= 0 except E_net = E_generated - E_thrust - E_reel_in (> 0 = net gain; "
             "the paper's Table 3 prints gains as negative numbers).")


def _f(v: Any, digits: int = 1) -> str:
    if v is None:
        return "-"
    if isinstance(v, bool):
        return "yes" if v else "no"
    if isinstance(v, (int,)) and not isinstance(v, bool):
        return str(v)
    try:
        x = float(v)
    except (TypeError, ValueError):
        return str(v)
    if not math.isfinite(x):
        return "-"
    return f"{x:.{digits}f}"


def _table(header: Sequence[str], rows: Iterable[Sequence[str]]) -> str:
    lines = ["| " + " | ".join(header) + " |", "|" + "|".join("---:" if i else "---" for i in range(len(header))) + "|"]
    lines += ["| " + " | ".join(r) + " |" for r in rows]
    return "\n".join(lines)


def flight_markdown(report: Any, title: str | None = None) -> str:
    """Report of a flight (:class:`fdm_awe.sim.report.FlightReport`): run facts, per-cycle table, ledger.
    A bare FlightResult (no cycles, no ledger) gets the run facts only."""
    r = report
    if not hasattr(r, "cycles"):
        msg = r.event.message if getattr(r, "event", None) is not None else "completed"
        return "\n".join([f"# {title or 'Flight'}", "", f"- status: **{r.status}** ({msg})",
                          f"- simulated {r.sim_time_s:.2f} s in {r.wall_s:.2f} s wall time", ""])
    head = title or f"Flight: scenario {r.scenario}, config {r.config}, wind {r.wind_mps:g} m/s"
    out = [f"# {head}", "",
           f"- status: **{r.status}** ({r.message})",
           f"- simulated {r.sim_time_s:.2f} s in {r.wall_s:.2f} s wall time ({r.realtime_factor:.0f}x real time)",
           f"- energy ledger residual (relative to the largest term): {r.ledger_residual_rel:.2e}"]
    if getattr(r, "control_activity", None) is not None:
        a = r.control_activity
        out.append(f"- control activity (surface command RMS above {a.f_cut_hz:g} Hz, full deflections): aileron "
                   f"{_f(a.aileron, 3)}, elevator {_f(a.elevator, 3)}, rudder {_f(a.rudder, 3)}, total {_f(a.total, 3)}")
    if getattr(r, "plant", None):
        from ..sim.report import PLANT_NOTES

        out.append(f"- plant: {r.plant} ({PLANT_NOTES.get(r.plant, '')})")
    out.append("")
    header = ["cycle", "T1 [s]", "T2 [s]", "E_generated [J]", "E_thrust [J]", "E_reel_in [J]", "E_net [J]",
              "P_avg [W]", "track rms [m]", "track max [m]", "complete"]
    rows = []
    for c in r.cycles:
        P = c.T1_s + c.T2_s
        rows.append([str(c.index), _f(c.T1_s, 2), _f(c.T2_s, 2), _f(c.E_generated_J), _f(c.E_thrust_J),
                     _f(c.E_reel_in_J), _f(c.E_net_J), _f(c.E_net_J / P if P > 0 and c.complete else None, 2),
                     _f(c.track_rms_m), _f(c.track_max_m), _f(bool(c.complete))])
    out += [_table(header, rows) if rows else "(no cycle flown)", "", SIGN_NOTE,
            "P_avg is given for complete cycles only (E_net / (T1 + T2) of the reference period).", ""]
    winds = getattr(r, "wind_estimates", None) or []
    if winds:
        out += ["## Wind", "", "The onboard estimate per cycle (airspeed, attitude, GPS velocity) against the true mean "
                "wind at the glider over the same steps, m/s; with a reference set, the wind of the reference flown.", "",
                _table(["cycle", "estimated", "from [deg]", "true", "error [%]", "mean height [m]", "reference"],
                       [[str(w["cycle"]), _f(w["estimated_at_glider"]["speed_mps"], 2),
                         _f(w["estimated"]["from_deg"], 0), _f(w["true_at_glider"]["speed_mps"], 2),
                         _f(100.0 * w["vector_error_rel"], 1), _f(w["mean_height_m"], 0),
                         _f(w.get("reference_wind_mps"), 1)] for w in winds]), ""]
    ledger = getattr(r, "ledger", None) or {}
    if ledger:
        out += ["## Energy ledger", "", _table(["term", "J"], [[k, _f(v, 3)] for k, v in ledger.items()]), ""]
    return "\n".join(out)


def _cycle_row(d: dict[str, Any]) -> list[str]:
    return [str(d.get("config", "-")), str(d.get("scenario", "-")), _f(d.get("wind_mps"), 1), str(d.get("status", "-")),
            _f(d.get("T1_s"), 2), _f(d.get("T2_s"), 2), _f(d.get("E_generated_J")), _f(d.get("E_thrust_J")),
            _f(d.get("E_reel_in_J")), _f(d.get("E_net_J")), _f(d.get("P_avg_W"), 2)]


CYCLE_HEADER = ["config", "scenario", "wind [m/s]", "status", "T1 [s]", "T2 [s]", "E_generated [J]", "E_thrust [J]",
                "E_reel_in [J]", "E_net [J]", "P_avg [W]"]


def _summary(x: Any) -> dict[str, Any]:
    """Optimisation summary dict from a CycleResult, a summary dict or a reference file/trajectory."""
    if isinstance(x, dict):
        return x
    if hasattr(x, "summary") and callable(x.summary):
        return x.summary()
    from .series import load_reference

    md = load_reference(x).metadata
    d = {k: md.get(k) for k in ("scenario", "config", "wind_mps", "status", "T1_s", "T2_s")}
    d.update(md.get("energies", {}))
    return d


def table3_markdown(runs: Sequence[Any], title: str = "Optimised cycles (Table 3 style)",
                    flights: Sequence[Any] | None = None) -> str:
    """Table-3 style comparison of optimised cycles (CycleResults, ``--json`` dicts or reference
    files), optionally followed by the flown cycles of ``flights`` (FlightReports)."""
    rows = [_cycle_row(_summary(r)) for r in runs]
    out = [f"# {title}", "", _table(CYCLE_HEADER, rows), "", SIGN_NOTE, ""]
    if flights:
        header = ["config", "wind [m/s]", "status", "cycle", "E_generated [J]", "E_thrust [J]", "E_reel_in [J]",
                  "E_net [J]", "track rms [m]", "complete"]
        frows = []
        for f in flights:
            for c in f.cycles:
                frows.append([f.config, _f(f.wind_mps), f.status, str(c.index), _f(c.E_generated_J), _f(c.E_thrust_J),
                              _f(c.E_reel_in_J), _f(c.E_net_J), _f(c.track_rms_m), _f(bool(c.complete))])
            if not f.cycles:
                frows.append([f.config, _f(f.wind_mps), f.status, "-", "-", "-", "-", "-", "-", "no"])
        out += ["## Flown (6-DOF co-simulation)", "", _table(header, frows), ""]
    return "\n".join(out)


def cycle_markdown(result: Any) -> str:
    """Report of one optimised cycle."""
    d = _summary(result)
    return table3_markdown([d], title=f"Optimised cycle: scenario {d.get('scenario')}, config {d.get('config')}, "
                                      f"wind {_f(d.get('wind_mps'))} m/s")


__all__ = ["SIGN_NOTE", "cycle_markdown", "flight_markdown", "table3_markdown"]
