#!/usr/bin/env python
"""The straight line against the lumped-mass line in flown pumping cycles.

Flies each stored 8 m/s reference (the demo cycle: the nominal glider; and the foldable cycle)
with the autopilot, once per line model (``straight``, ``lumped:10``, ``lumped:30``), and
tabulates per flight: the net energy per complete cycle and its parts, the tension peaks (winch
end; glider end for the lumped line), the tracking error, the energy ledgers' residuals, the
line's drag losses (lumped) and the drag and weight shares the glider actually carried.

The shares: over the cycling steps, the line force on the glider normal to the chord (winch to
glider) is fitted in the least-squares sense by ``a D + b W`` with ``D`` the whole line's drag
if every point of it moved like the glider, ``-0.5 rho C_D_perp d_t l |v_perp| v_perp``
(``v_perp`` the glider's air velocity normal to the chord), and ``W`` the normal part of the whole
line's weight ``mu l g``: ``a`` and ``b`` are the drag and weight shares actually carried (the
straight line carries 1/4 and 1/2 by construction, a check of the fit). A second fit adds
the drag of the whole line standing still in the wind, ``0.5 rho C_D_perp d_t l |w_perp| w_perp``
(which the straight line's share, taken from the glider's air velocity, leaves out; a line
standing in a cross wind puts half of it on each end). Writes JSON and a
markdown table (default ``runs/compare_tether.json`` / ``.md``, atomically).

The fixed-weight fit (weight share held at 1/2, drag and wind shares fitted) and the recovery
tension (the reel-in's work per metre reeled in) on ``lumped:30`` over the six stored sized-line
references are the calibrated line model of the optimiser (``tether/calibrated`` of the
ground-station definition)::

    python scripts/compare_tether.py --cycles 2 --models straight,lumped:30 --references \
        ref_physical_nominal_8mps_sized.json,ref_physical_foldable_8mps_sized.json,ref_physical_nominal_10mps_sized.json,\
ref_physical_foldable_10mps_sized.json,ref_physical_nominal_12mps_sized.json,ref_physical_foldable_12mps_sized.json

Usage: python scripts/compare_tether.py [--cycles 2] [--models straight,lumped:10,lumped:30] [--references LIST]
[--json FILE]
"""

from __future__ import annotations

import argparse
import os
import sys

os.environ.setdefault("JSBSIM_DEBUG", "0")

import numpy as np  # noqa: E402

from fdm_awe import ROOT  # noqa: E402
from fdm_awe.fileio import atomic_write_text, write_json  # noqa: E402

REFERENCES = (("demo (nominal)", "ref_physical_nominal_8mps_sized.json"),
              ("foldable", "ref_physical_foldable_8mps_sized.json"))
MODELS = ("straight", "lumped:10", "lumped:30")


def carried_shares(rep) -> tuple[float, ...]:
    """Least-squares drag and weight shares of the line force on the glider over the cycling
    steps (see the module docstring), then the three shares of the fit that adds the drag of
    the whole line standing still in the wind (``0.5 rho C_D_perp d_t l |w_perp| w_perp``), then
    the drag and wind shares of that fit with the weight share held at the straight line's 1/2
    (:func:`fixed_weight_fit`)."""
    from fdm_awe.groundstation import load_ground_station

    res = rep.result
    tp = load_ground_station(line=rep.result_line).tether
    wind = np.asarray(rep.wind_ned, float)
    k = np.isfinite(rep.track_error)
    k[0] = False
    p, v, f, l = res.pos[k], res.vel[k] - wind, res.tether_force[k], res.length[k]
    u = p / np.linalg.norm(p, axis=1)[:, None]

    def perp(a: np.ndarray) -> np.ndarray:
        return a - np.sum(a * u, axis=1)[:, None] * u

    vp = perp(v)
    D = -0.5 * tp.air_density * tp.cd_perpendicular * tp.diameter * l[:, None] * np.linalg.norm(vp, axis=1)[:, None] * vp
    W = perp(np.tile([0.0, 0.0, 1.0], (len(l), 1))) * (tp.mass_per_length * l * tp.gravity)[:, None]
    wp = perp(np.tile(wind, (len(l), 1)))
    Dw = 0.5 * tp.air_density * tp.cd_perpendicular * tp.diameter * l[:, None] * np.linalg.norm(wp, axis=1)[:, None] * wp
    F = perp(f)
    A = np.stack([D.ravel(), W.ravel()], axis=1)
    (a, b), *_ = np.linalg.lstsq(A, F.ravel(), rcond=None)
    A3 = np.stack([D.ravel(), W.ravel(), Dw.ravel()], axis=1)
    (a3, b3, c3), *_ = np.linalg.lstsq(A3, F.ravel(), rcond=None)
    a2, c2 = fixed_weight_fit(D, W, Dw, F, tp.weight_share)
    return float(a), float(b), float(a3), float(b3), float(c3), a2, c2


def fixed_weight_fit(D: np.ndarray, W: np.ndarray, Dw: np.ndarray, F: np.ndarray, weight_share: float) -> tuple[float, float]:
    """Drag and wind shares ``(a, c)`` of the fit ``F = a D + weight_share W + c Dw`` (N, one row
    per step, NED): the weight share held at the straight line's (1/2). Where the glider flies
    downwind of the winch, the normal parts of the line's weight and of its drag in the wind
    point the same way (down and downwind, normal to the line), so the free three-term fit
    trades one against the other (its weight share came out negative); holding the weight's
    moment share at 1/2 leaves the wind term what the straight line leaves out."""
    A = np.stack([D.ravel(), Dw.ravel()], axis=1)
    (a, c), *_ = np.linalg.lstsq(A, (F - weight_share * W).ravel(), rcond=None)
    return float(a), float(c)


def recovery_tension(res) -> float:
    """The line tension at the winch while reeling in [N], as one number: the work of reeling in
    per metre reeled in, ``int G |v| dt / int |v| dt`` over the recovery phases' reel-in (the
    calibrated line model's ``recovery_tension``: the constant tension that costs the reel-in
    the same mechanical work)."""
    rec = (np.asarray(res.phase) == "recovery") & (res.reel_speed < 0.0)
    v = -res.reel_speed[rec]
    return float(np.sum(res.tension[rec] * v) / np.sum(v)) if np.any(v > 0) else float("nan")


def fly_one(ref_file: str, model: str, cycles: int) -> dict:
    from fdm_awe.autopilot.tracking import TrackingReference
    from fdm_awe.sim.flight import fly

    ref = TrackingReference.from_ocp_file(os.path.join(ROOT, "tests", "data", ref_file))
    rep = fly(ref, config=ref.meta["config"], cycles=cycles, tether=model)
    rep.result_line = ref.meta.get("line", "paper")
    rep.wind_ned = ref.meta.get("wind_ned_mps", (0.0, 0.0, 0.0))
    done = [c for c in rep.cycles if c.complete]
    res = rep.result
    k = np.isfinite(rep.track_error)
    a, b, a3, b3, c3, a2, c2 = carried_shares(rep)
    led = rep.ledger
    row = {"recovery_tension_N": recovery_tension(res),
        "model": model, "status": rep.status, "cycles_complete": len(done),
        "E_net_J": float(np.mean([c.E_net_J for c in done])) if done else float("nan"),
        "E_generated_J": float(np.mean([c.E_generated_J for c in done])) if done else float("nan"),
        "E_thrust_J": float(np.mean([c.E_thrust_J for c in done])) if done else float("nan"),
        "E_reel_in_J": float(np.mean([c.E_reel_in_J for c in done])) if done else float("nan"),
        "tension_peak_winch_N": float(np.nanmax(res.tension[k])),
        "force_peak_glider_N": float(np.nanmax(np.linalg.norm(res.tether_force[k], axis=1))),
        "track_rms_m": float(np.sqrt(np.nanmean(rep.track_error[k] ** 2))),
        "track_max_m": float(np.nanmax(rep.track_error[k])),
        "drag_share": a, "weight_share": b, "fit3_drag_share": a3, "fit3_weight_share": b3, "fit3_wind_share": c3,
        "fitw_drag_share": a2, "fitw_wind_share": c2,
        "ledger_residual_rel": rep.ledger_residual_rel,
        "line_drag_loss_J": led.get("line_drag_J"), "line_residual_J": led.get("line_residual_J"),
        "line_hook_work_J": led.get("line_hook_work_J"),
        "drag_work_on_glider_J": led.get("station_line_drag_work_on_glider_J"),
        "realtime_factor": rep.realtime_factor,
    }
    if rep.line_shape is not None and len(rep.line_shape["tension"]):
        row["tension_peak_line_N"] = float(np.nanmax(rep.line_shape["tension"]))
    return row


def markdown(rows: dict, cycles: int) -> str:
    out = [f"Straight line against lumped line, {cycles} cycle(s) per flight (means over complete "
           "cycles). Shares: least-squares fit of the glider's line force normal to the chord; weight 1/2: the fit "
           "with the weight share held at 1/2 (drag / wind); recovery tension: reel-in work per metre reeled in.", "",
           "| cycle | line | status | E_net J | E_gen J | E_thrust J | E_reel-in J | T peak winch N | F peak glider N "
           "| track rms m | track max m | drag share | weight share | 3-term fit: drag / weight / wind | weight 1/2: drag / wind "
           "| recovery tension N | line drag loss J | ledger rel |",
           "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for label, rs in rows.items():
        for r in rs:
            dl = r["line_drag_loss_J"]
            out.append(f"| {label} | {r['model']} | {r['status']} ({r['cycles_complete']}) | {r['E_net_J']:.0f} | "
                       f"{r['E_generated_J']:.0f} | {r['E_thrust_J']:.0f} | {r['E_reel_in_J']:.0f} | "
                       f"{r['tension_peak_winch_N']:.1f} | {r['force_peak_glider_N']:.1f} | {r['track_rms_m']:.2f} | "
                       f"{r['track_max_m']:.1f} | {r['drag_share']:.3f} | {r['weight_share']:.3f} | "
                       f"{r['fit3_drag_share']:.3f} / {r['fit3_weight_share']:.2f} / {r['fit3_wind_share']:.3f} | "
                       f"{r['fitw_drag_share']:.3f} / {r['fitw_wind_share']:.3f} | {r['recovery_tension_N']:.2f} | "
                       f"{'-' if dl is None else f'{dl:.0f}'} | {r['ledger_residual_rel']:.1e} |")
    return "\n".join(out) + "\n"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--cycles", type=int, default=2, help="cycles per flight (1..10, default 2)")
    ap.add_argument("--models", default=",".join(MODELS), help="comma-separated line models")
    ap.add_argument("--references", default=None, metavar="LIST",
                    help="comma-separated reference files of tests/data to fly (default: the two 8 m/s cycles)")
    ap.add_argument("--json", default=os.path.join("runs", "compare_tether.json"),
                    help="output JSON file (default runs/compare_tether.json; its folder is made)")
    a = ap.parse_args(argv)
    if not 1 <= a.cycles <= 10:
        ap.error(f"--cycles {a.cycles} out of range (allowed 1..10)")
    from fdm_awe.groundstation.linemodels import parse_tether

    models = a.models.split(",")
    for m in models:
        parse_tether(m)
    rows: dict[str, list[dict]] = {}
    refs = REFERENCES if a.references is None else [(f, f) for f in a.references.split(",")]
    for label, f in refs:
        rows[label] = []
        for m in models:
            r = fly_one(f, m, a.cycles)
            rows[label].append(r)
            print(f"{label:>15} {m:>10}: {r['status']} net {r['E_net_J']:.0f} J, T peak {r['tension_peak_winch_N']:.1f} N, "
                  f"track rms {r['track_rms_m']:.2f} m, shares drag {r['drag_share']:.3f} weight {r['weight_share']:.3f}, "
                  f"weight 1/2 fixed: drag {r['fitw_drag_share']:.3f} wind {r['fitw_wind_share']:.3f}, "
                  f"recovery tension {r['recovery_tension_N']:.2f} N",
                  flush=True)
    md = markdown(rows, a.cycles)
    print(md)
    os.makedirs(os.path.dirname(os.path.abspath(a.json)), exist_ok=True)
    write_json(a.json, {"cycles": a.cycles, "rows": rows})
    atomic_write_text(os.path.splitext(a.json)[0] + ".md", md)
    print(f"wrote {a.json}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
