"""What ``fdm-awe fly`` prints of a flight: the run, its status with the measured real-time
factor, the turbulence met, a row per cycle beside the optimised reference's net energy, the
wind estimated per cycle, and the list of the files written."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any


def _fmt(v: float, spec: str) -> str:
    """``v`` formatted with ``spec``, or ``-`` right-aligned when it is not a finite number."""
    if v is None or not math.isfinite(v):
        width = "".join(ch for ch in spec.split(".")[0] if ch.isdigit())
        return "-".rjust(int(width or 1))
    return format(v, spec)


def _turbulence_line(t: dict) -> str:
    """One line on the flight's turbulence: the form, the target at the hub height and what the
    glider met (``FlightReport.turbulence``)."""
    tg, m = t["target"], t["measured"]

    def f(v: Any, spec: str) -> str:
        return "-" if v is None or not math.isfinite(v) else format(v, spec)

    hub = f"{f(tg['sigma_u_mps'], '.2f')} m/s at {f(t['hub_height_m'], '.0f')} m"
    return (f"turbulence {t['text']}: target sigma_u {hub}, intensity {f(tg['intensity'], '.3f')}; met over "
            f"{f(m['duration_s'], '.0f')} s: sigma_u/v/w {f(m['sigma_u_mps'], '.2f')}/{f(m['sigma_v_mps'], '.2f')}/"
            f"{f(m['sigma_w_mps'], '.2f')} m/s, intensity {f(m['intensity'], '.3f')}")


def realtime_text(rtf: float) -> str:
    """The measured real-time factor (simulated / wall seconds) as printed: two significant
    digits below 10 (``0.58x``), whole numbers above (``12x``)."""
    if not math.isfinite(rtf):
        return "-"
    return f"{rtf:.2g}x" if rtf < 10 else f"{rtf:.0f}x"


def print_summary(report, ref_label: str, optimised: dict[str, float] | None = None) -> None:
    """The flight in a few lines: the run, the status with the measured real-time factor, and
    one row per cycle (numbered from 0, as the JSON's ``index`` and ``flight.md``) with the
    optimised reference's net energy beside the flown one."""
    print(f"{report.scenario} / {report.config} / wind {report.wind_mps:g} m/s  reference {ref_label}  plant {report.plant}"
          f"  line drag x {report.tether_drag_scale:g}  tether {report.tether}")
    print(f"status {report.status}: {report.message}; {report.sim_time_s:.1f} s simulated in {report.wall_s:.1f} s "
          f"({realtime_text(report.realtime_factor)} real time, measured); energy ledger residual "
          f"{report.ledger_residual_rel:.2e}")
    if report.turbulence is not None:
        print(_turbulence_line(report.turbulence))
    opt = math.nan if optimised is None else optimised["E_net_J"]
    print(f"{'cycle':>5} {'T1 s':>6} {'T2 s':>6} {'gen J':>8} {'thrust J':>9} {'reel-in J':>9} {'net J':>8} "
          f"{'opt net J':>9} {'rms m':>7} {'max m':>7}")
    for c in report.cycles:
        flag = "" if c.complete else "  (incomplete)"
        print(f"{c.index:>5} {_fmt(c.T1_s, '6.2f')} {_fmt(c.T2_s, '6.2f')} {_fmt(c.E_generated_J, '8.1f')} "
              f"{_fmt(c.E_thrust_J, '9.1f')} {_fmt(c.E_reel_in_J, '9.1f')} {_fmt(c.E_net_J, '8.1f')} "
              f"{_fmt(opt, '9.1f')} {_fmt(c.track_rms_m, '7.2f')} {_fmt(c.track_max_m, '7.2f')}{flag}")
    if optimised is not None:
        print(f"optimised: net {optimised['E_net_J']:.1f} J per cycle ({optimised.get('P_avg_W', math.nan):.2f} W), "
              f"the reference's own (cycles are numbered from 0)")
    if report.wind_estimates:
        print("wind at the glider per cycle, estimated (true) m/s: " + ", ".join(
            f"{w['cycle']}: {w['estimated_at_glider']['speed_mps']:.2f} ({w['true_at_glider']['speed_mps']:.2f})"
            + (f" on the {w['reference_wind_mps']:g} m/s reference" if "reference_wind_mps" in w else "")
            for w in report.wind_estimates))


def written_files(written: dict[str, object], ref_written: Path | None, json_path: str | None) -> list[str]:
    """Every file the run wrote, in order: the optimised reference (``ref_written``, into
    ``--out``), the outputs of :func:`fdm_awe.recording.flight_outputs` and ``--json``."""
    files: list[str] = [] if ref_written is None else [str(ref_written)]
    for v in written.values():
        if isinstance(v, str):
            files.append(v)
        elif isinstance(v, (list, tuple)):
            files.extend(str(x) for x in v)
    if json_path:
        files.append(str(json_path))
    return files
