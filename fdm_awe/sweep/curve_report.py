"""The power-curve report of a sweep: optimised and flown curves, cut-in and rated winds, the
flown foldable-minus-nominal difference, and the energy yield (``sweep --fly`` / ``--yield``).

Files (in ``OUT``, each written atomically):

- ``power_curve.csv``: one row per point, units in the column names: wind [m/s], optimised
  power [W], flown mean, standard deviation, min and max per complete cycle [W], the count of
  complete cycles, the mean over flights and its standard error [W], completion and park
  fractions, tracking RMS [m], peak tension and its rating [N], peak current and its rating
  [A], Loyd and quasi-steady reel-out powers [W];
- ``power_curve_flown.png``: optimised and flown curves per configuration, the flown mean with
  bands of one standard deviation and of min-max, Loyd and quasi-steady (right panel);
- ``power_curve.md``: the table, cut-in and rated winds of each curve, foldable minus nominal
  flown (with its standard error over the flights), and the yield table when asked for;
- ``yield.csv``: curve x distribution: mean power [W], AEP [kWh/yr], capacity factor,
  masses outside the range and not operated.

Flown power per cycle = the cycle's net energy / its duration (``fdm_awe.sweep.flown``).
The flown curve's mean counts complete cycles only; its completion fraction says how many of
the cycles asked for were flown to their end.
"""

from __future__ import annotations

import csv
import math
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from ..fileio import atomic_path
from .energy_yield import Distribution, YieldResult, cut_in_wind, energy_yield, rated_wind
from .flown import FlySpec, flown_point
from .outputs import group_key, line_label, save_figure

#: columns of ``power_curve.csv``
CURVE_FIELDS = ("curve", "config", "wind_mps", "P_opt_W", "P_flown_mean_W", "P_flown_std_W", "P_flown_min_W",
                "P_flown_max_W", "cycles_complete", "cycles_asked", "P_flight_mean_W", "P_flight_se_W", "completion",
                "park_fraction", "track_rms_m", "peak_tension_N", "rated_tension_N", "peak_current_A",
                "rated_current_A", "P_loyd_W", "P_quasi_steady_W", "flights_status", "point_id")
#: columns of ``yield.csv``
YIELD_FIELDS = ("curve", "source", "distribution", "height_m", "mean_power_W", "aep_kWh_per_yr", "capacity_factor",
                "rated_power_W", "mass_below_range", "mass_above_range", "mass_not_operated", "outside_mass", "clip")


def curve_files(out_dir: str | Path) -> dict[str, Path]:
    out = Path(out_dir)
    return {"curve_table": out / "power_curve.csv", "curve_plot": out / "power_curve_flown.png",
            "curve_report": out / "power_curve.md", "yield_table": out / "yield.csv"}


def curve_rows(records: Sequence[dict[str, Any]], flights: dict[str, list[dict[str, Any]]], fly: FlySpec | None,
               refs: Any) -> list[dict[str, Any]]:
    """One row per point (``flights``: point id -> its flight records; ``refs``: the reference
    curves of the sweep, or None)."""
    loyd = {} if refs is None else dict(zip(map(float, refs.winds), map(float, refs.loyd_W)))
    qs = {} if refs is None else dict(zip(map(float, refs.winds), map(float, refs.quasi_steady_W)))
    rows = []
    for r in records:
        row = {k: None for k in CURVE_FIELDS}
        row.update({"curve": _curve(r), "config": r["config"], "wind_mps": float(r["wind_mps"]), "point_id": r["id"],
                    "P_opt_W": r.get("P_avg_W") if r.get("status") == "ok" else None,
                    "P_loyd_W": loyd.get(float(r["wind_mps"])), "P_quasi_steady_W": qs.get(float(r["wind_mps"]))})
        fl = flights.get(r["id"])
        if fly is not None and fl:
            s = flown_point(fl, fly.cycles)
            for k in CURVE_FIELDS:
                if k in s:
                    row[k] = s[k]
            row["flights_status"] = s["statuses"]
        rows.append(row)
    rows.sort(key=lambda x: (x["curve"], x["wind_mps"]))
    return rows


def _curve(r: dict[str, Any]) -> str:
    """The curve a record belongs to: its configuration and design, tether range."""
    return f"{line_label(r)} {r['d0_m']:g}-{r['d_tf_m']:g} m"


def _curves(rows: list[dict[str, Any]], key: str) -> dict[str, tuple[list[float], list[float]]]:
    """Curve name -> (winds, powers) of the rows where ``key`` has a value."""
    out: dict[str, tuple[list[float], list[float]]] = {}
    for r in rows:
        if r.get(key) is not None:
            v, p = out.setdefault(r["curve"], ([], []))
            v.append(r["wind_mps"])
            p.append(float(r[key]))
    return out


def write_curve_csv(rows: list[dict[str, Any]], path: Path) -> Path:
    with atomic_path(path) as tmp, tmp.open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(CURVE_FIELDS))
        w.writeheader()
        for r in rows:
            w.writerow({k: ("" if r.get(k) is None else r[k]) for k in CURVE_FIELDS})
    return path


def curve_plot(rows: list[dict[str, Any]], path: Path, title: str, wind_label: str) -> Path:
    """Optimised and flown curves (bands: one standard deviation, min-max) and the references."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(12, 5))
    names = list(dict.fromkeys(r["curve"] for r in rows))
    for i, name in enumerate(names):
        g = [r for r in rows if r["curve"] == name]
        col = f"C{i % 10}"
        o = [(r["wind_mps"], r["P_opt_W"]) for r in g if r["P_opt_W"] is not None]
        if o:
            ax.plot(*zip(*o), "--", color=col, marker="o", mfc="none", label=f"{name}: optimised")
        f = [r for r in g if r["P_flown_mean_W"] is not None]
        if f:
            v = np.array([r["wind_mps"] for r in f])
            m = np.array([r["P_flown_mean_W"] for r in f])
            sd = np.array([r["P_flown_std_W"] or 0.0 for r in f])
            ax.plot(v, m, "-", color=col, marker="s", label=f"{name}: flown mean")
            ax.fill_between(v, m - sd, m + sd, color=col, alpha=0.25, lw=0)
            ax.fill_between(v, [r["P_flown_min_W"] for r in f], [r["P_flown_max_W"] for r in f], color=col, alpha=0.1,
                            lw=0)
    ax.axhline(0.0, color="k", lw=0.6)
    ax.set_xlabel(wind_label)
    ax.set_ylabel("cycle-average net electrical power [W]")
    ax.set_title("optimised vs flown (band: 1 std, light band: min-max)", fontsize=9)
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)
    ref = sorted({(r["wind_mps"], r["P_loyd_W"], r["P_quasi_steady_W"]) for r in rows if r["P_loyd_W"] is not None})
    if ref:
        v, lo, qs = zip(*ref)
        ax2.plot(v, lo, "k-", label="Loyd (reel-out, no losses)")
        ax2.plot(v, qs, "k--", label="quasi-steady reel-out")
    for i, name in enumerate(names):
        f = [(r["wind_mps"], r["P_flown_mean_W"]) for r in rows if r["curve"] == name and r["P_flown_mean_W"] is not None]
        if f:
            ax2.plot(*zip(*f), "-", color=f"C{i % 10}", marker="s", label=f"{name}: flown mean")
    ax2.set_xlabel(wind_label)
    ax2.set_ylabel("power [W]")
    ax2.set_title("upper references", fontsize=9)
    ax2.legend(fontsize=7)
    ax2.grid(alpha=0.3)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    return save_figure(fig, path)


def _f(v: Any, fmt: str = ".1f") -> str:
    return "-" if v is None or (isinstance(v, float) and not math.isfinite(v)) else format(v, fmt)


#: the flown mean agrees with the optimised power within this fraction where the optimum is above
#: :data:`AGREEMENT_MIN_W`
AGREEMENT_REL = 0.10
AGREEMENT_MIN_W = 10.0


def agreement_lines(rows: list[dict[str, Any]]) -> list[str]:
    """Where the flown mean is within :data:`AGREEMENT_REL` of an optimum above
    :data:`AGREEMENT_MIN_W`, and for every other flown point what its flights say (completion,
    parking, tracking, peaks against the ratings)."""
    ok, other = [], []
    for r in rows:
        if r["P_flown_mean_W"] is None or r["P_opt_W"] is None:
            continue
        d = r["P_flown_mean_W"] - r["P_opt_W"]
        if r["P_opt_W"] > AGREEMENT_MIN_W and abs(d) <= AGREEMENT_REL * r["P_opt_W"]:
            ok.append(f"{r['curve']} {r['wind_mps']:g} m/s")
            continue
        why = []
        if r["completion"] is not None and r["completion"] < 1:
            why.append(f"completion {r['completion']:.2f}")
        if r["park_fraction"]:
            why.append(f"parked {r['park_fraction']:.2f}")
        if r["track_rms_m"] is not None:
            why.append(f"tracking RMS {r['track_rms_m']:.1f} m")
        if r["peak_tension_N"] is not None and r["rated_tension_N"] and r["peak_tension_N"] > r["rated_tension_N"]:
            why.append(f"peak tension {r['peak_tension_N']:.0f} N over the rated {r['rated_tension_N']:g} N")
        if r["P_opt_W"] <= AGREEMENT_MIN_W:
            why.insert(0, f"optimum at most {AGREEMENT_MIN_W:g} W (outside the {100 * AGREEMENT_REL:g} % criterion)")
        other.append(f"- {r['curve']} {r['wind_mps']:g} m/s: flown {r['P_flown_mean_W']:.1f} W against "
                     f"{r['P_opt_W']:.1f} W optimised ({d:+.1f} W); " + ", ".join(why))
    head = (f"Within {100 * AGREEMENT_REL:g} % of an optimum above {AGREEMENT_MIN_W:g} W: "
            + (", ".join(ok) if ok else "none") + ".")
    return [head] + (["", "Elsewhere (what the flights say):", ""] + other if other else [])


def fold_differences(rows: list[dict[str, Any]], records: Sequence[dict[str, Any]]) -> list[dict[str, Any]]:
    """Flown foldable minus nominal per wind (pairs as the folding map pairs them), with the
    standard error sqrt(se_f^2 + se_n^2) of the flights' means (None with one flight each)."""
    by_id = {r["id"]: r for r in records}
    nominal = {(group_key(by_id[r["point_id"]]), r["wind_mps"]): r for r in rows if r["config"] == "nominal"}
    out = []
    for r in rows:
        if r["config"] != "foldable":
            continue
        n = nominal.get((group_key(by_id[r["point_id"]]), r["wind_mps"]))
        if n is None or r["P_flight_mean_W"] is None or n["P_flight_mean_W"] is None:
            continue
        se = (math.hypot(r["P_flight_se_W"], n["P_flight_se_W"])
              if r["P_flight_se_W"] is not None and n["P_flight_se_W"] is not None else None)
        d_opt = (r["P_opt_W"] - n["P_opt_W"]) if r["P_opt_W"] is not None and n["P_opt_W"] is not None else None
        out.append({"curve": r["curve"], "wind_mps": r["wind_mps"], "dP_flown_W": r["P_flight_mean_W"] - n["P_flight_mean_W"],
                    "se_W": se, "dP_opt_W": d_opt})
    return out


def yields(rows: list[dict[str, Any]], dists: Sequence[Distribution], *, clip: bool, rated_power_W: float | None,
           height_ratio: float) -> list[tuple[str, str, YieldResult]]:
    """(curve, source, result) for every curve (optimised, and flown where flown) and distribution."""
    out = []
    for source, key in (("optimised", "P_opt_W"), ("flown", "P_flown_mean_W")):
        for name, (v, p) in _curves(rows, key).items():
            for d in dists:
                out.append((name, source, energy_yield(v, p, d, clip=clip, rated_power_W=rated_power_W,
                                                       height_ratio=height_ratio)))
    return out


def write_yield_csv(ys: list[tuple[str, str, YieldResult]], height: float, path: Path) -> Path:
    with atomic_path(path) as tmp, tmp.open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(YIELD_FIELDS))
        w.writeheader()
        for name, source, y in ys:
            w.writerow({"curve": name, "source": source, "distribution": y.distribution, "height_m": height,
                        "mean_power_W": y.mean_power_W, "aep_kWh_per_yr": y.aep_kWh,
                        "capacity_factor": "" if y.capacity_factor is None else y.capacity_factor,
                        "rated_power_W": "" if y.rated_power_W is None else y.rated_power_W,
                        "mass_below_range": y.mass_below, "mass_above_range": y.mass_above,
                        "mass_not_operated": y.mass_not_operated, "outside_mass": y.outside_mass, "clip": y.clip})
    return path


def curve_markdown(rows: list[dict[str, Any]], records: Sequence[dict[str, Any]], fly: FlySpec | None,
                   ys: list[tuple[str, str, YieldResult]] | None, yield_note: str, skipped: Sequence[str],
                   rated_power_W: float | None) -> str:
    """The report's markdown (see the module docstring)."""
    L = ["# Power curve" + (" (optimised and flown)" if fly else ""), ""]
    if fly is not None:
        seeds = "calm air, one flight" if fly.air == "calm" else f"{fly.air} turbulence, seeds 1..{fly.seeds}"
        L += [f"Flown: every optimised point of the definitions' airframe, {fly.cycles} cycles per flight, {seeds}, "
              f"{fly.tether} line. Flown power per cycle = net energy / cycle duration, complete cycles only; "
              "std, min and max over all complete cycles; SE = standard error of the flights' means (seeds "
              "independent, cycles of one flight not).", ""]
    L += ["| curve | wind [m/s] | optimised [W] | flown mean [W] | std [W] | min [W] | max [W] | cycles | "
          "completion | parked | tracking RMS [m] | peak tension / rated [N] | peak current / rated [A] | "
          "Loyd [W] | quasi-steady [W] |", "|" + "---|" * 15]
    for r in rows:
        L.append(f"| {r['curve']} | {r['wind_mps']:g} | {_f(r['P_opt_W'])} | {_f(r['P_flown_mean_W'])} | "
                 f"{_f(r['P_flown_std_W'])} | {_f(r['P_flown_min_W'])} | {_f(r['P_flown_max_W'])} | "
                 f"{r['cycles_complete'] if r['cycles_complete'] is not None else '-'}"
                 f"{'' if r['cycles_asked'] is None else ' of ' + str(r['cycles_asked'])} | "
                 f"{_f(r['completion'], '.2f')} | {_f(r['park_fraction'], '.2f')} | {_f(r['track_rms_m'])} | "
                 f"{_f(r['peak_tension_N'])} / {_f(r['rated_tension_N'], 'g')} | "
                 f"{_f(r['peak_current_A'])} / {_f(r['rated_current_A'], 'g')} | {_f(r['P_loyd_W'])} | "
                 f"{_f(r['P_quasi_steady_W'])} |")
    L += ["", "## Cut-in and rated wind", "",
          "Cut-in: the wind from which the curve stays positive (zero crossing interpolated). Rated: the lowest wind "
          "at which the curve reaches " + (f"the rated power {rated_power_W:g} W" if rated_power_W is not None
                                            else "its largest power") + ".", "",
          "| curve | source | cut-in [m/s] | rated [m/s] |", "|---|---|---|---|"]
    for source, key in (("optimised", "P_opt_W"), ("flown", "P_flown_mean_W")):
        for name, (v, p) in _curves(rows, key).items():
            ci = cut_in_wind(v, p)
            vr, top = rated_wind(v, p, rated_power_W)
            rated_txt = "-" if vr is None else (f">= {vr:g} (still rising)" if top else f"{vr:.1f}")
            if vr is None and top:
                rated_txt = f"> {max(v):g} (not reached)"
            L.append(f"| {name} | {source} | {'-' if ci is None else f'{ci:.1f}'} | {rated_txt} |")
    if fly is not None:
        diffs = fold_differences(rows, records)
        if diffs:
            L += ["", "## Foldable minus nominal, flown", "",
                  "Mean of the flights' mean powers, foldable minus nominal, with its standard error (flights "
                  "with at least one complete cycle).", "",
                  "| curve | wind [m/s] | flown dP [W] | SE [W] | optimised dP [W] |", "|---|---|---|---|---|"]
            for d in diffs:
                L.append(f"| {d['curve']} | {d['wind_mps']:g} | {d['dP_flown_W']:+.1f} | {_f(d['se_W'])} | "
                         f"{'-' if d['dP_opt_W'] is None else format(d['dP_opt_W'], '+.1f')} |")
    if fly is not None:
        L += ["", "## Flown against optimised", ""] + agreement_lines(rows)
    if skipped:
        L += ["", "## Not flown", ""] + [f"- {s}" for s in skipped]
    if ys:
        L += ["", "## Energy yield", "", yield_note, "",
              "| curve | source | distribution | mean power [W] | AEP [kWh/yr] | capacity factor | below range | "
              "above range | not operated (P <= 0) |", "|---|---|---|---|---|---|---|---|---|"]
        for name, source, y in ys:
            flag = " (curve outside the distribution's mass)" if y.outside_mass else ""
            L.append(f"| {name} | {source} | {y.distribution}{flag} | {y.mean_power_W:.3f} | {y.aep_kWh:.2f} | "
                     f"{_f(y.capacity_factor, '.3f')} | {y.mass_below:.3f} | {y.mass_above:.3f} | "
                     f"{y.mass_not_operated:.3f} |")
        if any(y.outside_mass for _, _, y in ys):
            L += ["", "A curve marked outside the distribution's mass covers less than 1 % of the site's wind: its "
                      "yield says little about the site."]
    return "\n".join(L) + "\n"
