"""Sweep outputs: CSV table, power-curve plot, "where folding pays" map, markdown summary.

All functions take the list of point records (:data:`fdm_awe.sweep.runner.RECORD_FIELDS`).
Plots use matplotlib's Agg backend (no display). Power: cycle-average net power ``P_avg_W``
[W] (> 0 = net gain), winds [m/s], spans [m].

The folding comparison pairs each foldable point with the nominal point of the same scenario,
wind, wing area, tether range and tether line (name and diameter; a record without a line is
from before lines were named: Table 1's ``paper`` line): ``dP = P_foldable - P_nominal`` [W]. Folding *pays* where
both converged and ``dP > 0``.

Files are written under a temporary name and renamed when complete
(:mod:`fdm_awe.fileio`): an interrupted sweep never leaves a truncated table or image.
"""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Sequence

from ..fileio import atomic_path
from .references import ReferenceCurves
from .runner import COLD_CHECK_TOLERANCE_W, RECORD_FIELDS


def write_csv(records: Sequence[dict[str, Any]], path: str | Path) -> Path:
    """Every point, ok or failed, one row each (columns :data:`RECORD_FIELDS`)."""
    p = Path(path)
    rows = sorted(records, key=_order)
    with atomic_path(p) as tmp, tmp.open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(RECORD_FIELDS), extrasaction="ignore")
        w.writeheader()
        for r in rows:
            w.writerow({k: ("" if r.get(k) is None else r.get(k)) for k in RECORD_FIELDS})
    return p


def save_figure(fig: Any, path: str | Path) -> Path:
    """Write ``fig`` as a PNG to ``path`` atomically and close it."""
    import matplotlib.pyplot as plt

    p = Path(path)
    try:
        with atomic_path(p, suffix=".png") as tmp:
            fig.savefig(tmp, dpi=110, format="png")
    finally:
        plt.close(fig)
    return p


def _line(r: dict[str, Any]) -> str:
    """The record's tether line (records from before lines were named: Table 1's ``paper``)."""
    return r.get("line") or "paper"


def _order(r: dict[str, Any]) -> tuple:
    return (r["scenario"], r["config"] != "nominal", _n(r.get("wing_area_m2")), r["d0_m"], r["d_tf_m"], _line(r),
            _n(r.get("line_diameter_m")), _n(r.get("b_f_m")), _n(r.get("drag_area_f_m2")), r["wind_mps"])


def _n(v: Any) -> float:
    return -1.0 if v is None else float(v)


def group_key(r: dict[str, Any]) -> tuple:
    """Operating context shared by a nominal point and its foldable counterparts: scenario, wing
    area, reel-out range, tether line and its diameter (-1: as defined)."""
    return (r["scenario"], _n(r.get("wing_area_m2")), r["d0_m"], r["d_tf_m"], _line(r), _n(r.get("line_diameter_m")))


def _g(v: Any, fallback: Any = None) -> str:
    v = v if v is not None else fallback
    return "def" if v is None else f"{float(v):.3g}"


def line_label(r: dict[str, Any]) -> str:
    """The label of a point's power curve (configuration, design values, line) in plots and tables."""
    if r["config"] == "nominal":
        s = "nominal"
    else:
        s = f"foldable b_f={_g(r.get('b_f_m'), r.get('folded_span_m'))} m"
        if r.get("folded_drag_area_m2") is not None:
            s += f" CdA_f={_g(r.get('drag_area_f_m2'), r.get('folded_drag_area_m2'))} m2"
    if r.get("wing_area_m2") is not None:
        s += f" S={_g(r.get('S_u_m2'), r.get('wing_area_m2'))} m2"
    s += f" line={_line(r)}"
    if r.get("line_diameter_m") is not None:
        s += f" d_t={1e3 * float(r['line_diameter_m']):.3g} mm"
    return s


@dataclass
class FoldingCell:
    """One (folded span, wind) cell of the folding comparison."""

    context: tuple
    b_f: float
    drag_area: float
    wind: float
    P_foldable: float | None
    P_nominal: float | None
    missing: bool = False  #: the nominal counterpart has no record (not swept or not finished)

    @property
    def dP(self) -> float | None:
        if self.P_foldable is None or self.P_nominal is None:
            return None
        return self.P_foldable - self.P_nominal


def folding_cells(records: Sequence[dict[str, Any]]) -> list[FoldingCell]:
    """Pair every foldable point with its nominal counterpart (see the module docstring)."""
    nominal = {(group_key(r), r["wind_mps"]): r for r in records if r["config"] == "nominal"}
    cells = []
    for r in records:
        if r["config"] != "foldable":
            continue
        n = nominal.get((group_key(r), r["wind_mps"]))
        pf = r["P_avg_W"] if r["status"] == "ok" else None
        pn = n["P_avg_W"] if (n is not None and n["status"] == "ok") else None
        b_f = r.get("b_f_m") if r.get("b_f_m") is not None else r.get("folded_span_m")
        area = r.get("drag_area_f_m2") if r.get("drag_area_f_m2") is not None else r.get("folded_drag_area_m2")
        cells.append(FoldingCell(group_key(r), math.nan if b_f is None else float(b_f),
                                 math.nan if area is None else float(area), r["wind_mps"], pf, pn, n is None))
    return cells


def power_curve_plot(records: Sequence[dict[str, Any]], refs: ReferenceCurves | None, path: str | Path,
                     title: str = "", wind_label: str = "wind speed [m/s]") -> Path:
    """Average net power vs wind per line; failed points marked; Loyd and quasi-steady
    reel-out references in the right panel (their scale dwarfs the net cycle power).
    ``wind_label`` the wind axis (a sheared wind's names its reference height)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    lines: dict[tuple, list[dict[str, Any]]] = {}
    for r in sorted(records, key=_order):
        lines.setdefault((group_key(r), line_label(r)), []).append(r)
    fig, axes = plt.subplots(1, 2, figsize=(13, 5.2))
    cmap = plt.get_cmap("viridis")
    fold_labels = sorted({k for k in lines if "foldable" in k[1]}, key=lambda k: k[1])
    for ax in axes:
        for key, rs in lines.items():
            ok = [r for r in rs if r["status"] == "ok"]
            bad = [r for r in rs if r["status"] != "ok"]
            if "nominal" in key[1]:
                style = {"color": "k", "marker": "o", "lw": 2}
            else:
                i = fold_labels.index(key) if key in fold_labels else 0
                style = {"color": cmap(0.15 + 0.7 * i / max(1, len(fold_labels) - 1)), "marker": "s", "lw": 1.5}
            ax.plot([r["wind_mps"] for r in ok], [r["P_avg_W"] for r in ok], label=key[1], ms=4, **style)
            if bad:
                ax.plot([r["wind_mps"] for r in bad], [0.0] * len(bad), "x", color=style["color"], ms=8, mew=2)
        ax.axhline(0.0, color="0.6", lw=0.8)
        ax.set_xlabel(wind_label)
        ax.grid(True, alpha=0.3)
    if refs is not None:
        axes[1].plot(refs.winds, refs.loyd_W, "--", color="tab:red", label=f"Loyd limit (C_L {refs.CL:.2f}, C_D {refs.CD:.3f} incl. tether)")
        axes[1].plot(refs.winds, refs.quasi_steady_W, ":", color="tab:orange", lw=2,
                     label=f"quasi-steady reel-out (elev. {math.degrees(refs.elevation):.0f} deg, f={refs.reel_out_factor:.2f})")
    axes[0].set_ylabel("cycle-average net power [W]")
    axes[0].set_title("optimised pumping cycles (x = failed point)")
    axes[1].set_title("with reel-out references (unfolded wing, same tether)")
    axes[1].set_yscale("symlog", linthresh=10.0)
    axes[1].legend(fontsize=7, loc="upper left")
    axes[0].legend(fontsize=7)
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    return save_figure(fig, path)


def folding_map_plot(cells: Sequence[FoldingCell], path: str | Path, title: str = "") -> Path | None:
    """Colour map of ``dP = P_foldable - P_nominal`` [W] over folded span x wind (first
    context and drag area if several); grey cells: a point of the pair failed (``fail``) or
    has no record (``n/a``)."""
    if not cells:
        return None
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np
    from matplotlib.colors import TwoSlopeNorm

    ctx, area = cells[0].context, cells[0].drag_area
    sel = [c for c in cells if c.context == ctx and c.drag_area == area]
    spans = sorted({c.b_f for c in sel})
    winds = sorted({c.wind for c in sel})
    Z = np.full((len(spans), len(winds)), np.nan)
    text = np.full(Z.shape, "n/a", dtype=object)  # no record for this pair
    for c in sel:
        i, j = spans.index(c.b_f), winds.index(c.wind)
        if c.dP is not None:
            Z[i, j] = c.dP
            text[i, j] = f"{c.dP:+.0f}"
        elif not c.missing:
            text[i, j] = "fail"
    fig, ax = plt.subplots(figsize=(2.5 + 0.75 * len(winds), 2.2 + 0.6 * len(spans)))
    finite = Z[np.isfinite(Z)]
    lo = float(min(finite.min(), -1e-3)) if finite.size else -1.0
    hi = float(max(finite.max(), 1e-3)) if finite.size else 1.0
    ax.set_facecolor("0.8")
    im = ax.imshow(np.ma.masked_invalid(Z), cmap="RdBu", norm=TwoSlopeNorm(0.0, lo, hi), aspect="auto", origin="lower")
    for i in range(len(spans)):
        for j in range(len(winds)):
            ax.text(j, i, text[i, j], ha="center", va="center", fontsize=7)
    ax.set_xticks(range(len(winds)), [f"{w:g}" for w in winds])
    ax.set_yticks(range(len(spans)), [f"{b:.3g}" for b in spans])
    ax.set_xlabel("wind speed [m/s]")
    ax.set_ylabel("folded span b_f [m]")
    fig.colorbar(im, ax=ax, label="P_fold - P_nom [W]")
    line = ctx[4] + ("" if ctx[5] < 0 else f" d_t {1e3 * ctx[5]:.3g} mm")
    ax.set_title(title or f"where folding pays (> 0, blue): {ctx[0]}, tether {ctx[2]:g}-{ctx[3]:g} m, line {line}, "
                          f"CdA_f {area:.3g} m2\ncycle-average net power, foldable minus nominal [W]; fail = a point failed",
                 fontsize=8)
    fig.tight_layout()
    return save_figure(fig, path)


def _line_of(c: FoldingCell) -> dict[str, Any]:
    """The tether line of a cell's context (name, swept diameter in m or None)."""
    return {"line": c.context[4], "line_diameter_m": None if c.context[5] < 0 else c.context[5]}


def answer(cells: Sequence[FoldingCell]) -> dict[str, Any]:
    """Where folding pays, in numbers: winning cells, the best margin, cells not comparable."""
    comparable = [c for c in cells if c.dP is not None]
    wins = sorted((c for c in comparable if c.dP > 0), key=lambda c: (c.b_f, c.wind))
    best = max(comparable, key=lambda c: c.dP) if comparable else None
    return {
        "n_cells": len(cells), "n_comparable": len(comparable), "n_folding_pays": len(wins),
        "folding_pays": [{"b_f_m": c.b_f, "drag_area_f_m2": c.drag_area, "wind_mps": c.wind, "dP_W": c.dP,
                          **_line_of(c)} for c in wins],
        "best": None if best is None else {"b_f_m": best.b_f, "drag_area_f_m2": best.drag_area, "wind_mps": best.wind,
                                           "dP_W": best.dP, "P_foldable_W": best.P_foldable, "P_nominal_W": best.P_nominal,
                                           **_line_of(best)},
        "not_comparable": [{"b_f_m": c.b_f, "wind_mps": c.wind, "foldable_ok": c.P_foldable is not None,
                            "nominal_ok": c.P_nominal is not None} for c in cells if c.dP is None],
    }


def answer_sentence(ans: dict[str, Any], scenario: str) -> str:
    """The answer in one or two sentences with numbers."""
    if ans["n_cells"] == 0:
        return "No foldable points in this sweep: nothing to compare."
    if ans["n_comparable"] == 0:
        return "No foldable/nominal pair converged: the sweep cannot say where folding pays."
    b = ans["best"]
    if ans["n_folding_pays"] == 0:
        return (f"In the `{scenario}` scenario folding pays nowhere in the swept range: over "
                f"{ans['n_comparable']} comparable (folded span, wind) pairs the foldable glider's best margin is "
                f"{b['dP_W']:+.1f} W (b_f = {b['b_f_m']:.3g} m, wind {b['wind_mps']:g} m/s: "
                f"{b['P_foldable_W']:.1f} W foldable vs {b['P_nominal_W']:.1f} W nominal).")
    by_span: dict[float, list[float]] = {}
    for c in ans["folding_pays"]:
        by_span.setdefault(c["b_f_m"], []).append(c["wind_mps"])
    parts = [f"b_f = {s:.3g} m at {', '.join(f'{w:g}' for w in sorted(ws))} m/s" for s, ws in sorted(by_span.items())]
    return (f"In the `{scenario}` scenario the foldable glider beats the nominal one in {ans['n_folding_pays']} of "
            f"{ans['n_comparable']} comparable pairs: {'; '.join(parts)}. Largest gain {b['dP_W']:+.1f} W at "
            f"b_f = {b['b_f_m']:.3g} m, wind {b['wind_mps']:g} m/s ({b['P_foldable_W']:.1f} W vs {b['P_nominal_W']:.1f} W).")


def cold_check_differences(records: Sequence[dict[str, Any]], tol_W: float = COLD_CHECK_TOLERANCE_W) -> dict[str, Any]:
    """The cold check over a sweep: how many points had it, and every point whose warm-started
    and cold solutions differ by more than ``tol_W`` [W] or where only one of them converged
    (both powers [W], which was kept, the kept and the cold start family)."""
    checked = [r for r in records if r.get("kept") is not None or r.get("P_warm_W") is not None
               or r.get("P_cold_W") is not None]
    rows = []
    for r in sorted(checked, key=_order):
        pw, pc = r.get("P_warm_W"), r.get("P_cold_W")
        diff = None if pw is None or pc is None else pc - pw
        if (pw is None) == (pc is None) and (diff is None or abs(diff) <= tol_W):
            continue  # both agree, or both failed (the point's own failure is listed with the failures)
        rows.append({"id": r["id"], "line": line_label(r), "wind_mps": r["wind_mps"], "P_warm_W": pw, "P_cold_W": pc,
                     "cold_minus_warm_W": diff, "kept": r.get("kept"), "family": r.get("family"),
                     "cold_family": r.get("cold_family"), "warm_from": r.get("warm_from")})
    return {"tolerance_W": tol_W, "n_checked": len(checked), "n_different": len(rows), "different": rows}


def _w(v: Any) -> str:
    return "failed" if v is None else f"{float(v):.2f}"


def cold_check_markdown(check: dict[str, Any]) -> list[str]:
    """The summary's section on the cold check (empty when no point had it)."""
    if not check["n_checked"]:
        return []
    out = ["", f"## Warm start vs cold solve (cold check, {check['n_checked']} warm-started points)", ""]
    if not check["different"]:
        return out + [f"Every warm-started point's cold solve agrees within {check['tolerance_W']:g} W (or both failed)."]
    out += [f"{check['n_different']} point(s) where the warm-started and the cold solution differ by more than "
            f"{check['tolerance_W']:g} W or only one converged; the better one is kept (and passed on along the chain):", "",
            "| line | wind [m/s] | warm [W] | cold [W] | cold - warm [W] | kept | family kept | cold family |",
            "|---|---|---|---|---|---|---|---|"]
    for d in check["different"]:
        dd = "" if d["cold_minus_warm_W"] is None else f"{d['cold_minus_warm_W']:+.2f}"
        out.append(f"| {d['line']} | {d['wind_mps']:g} | {_w(d['P_warm_W'])} | {_w(d['P_cold_W'])} | {dd} | "
                   f"{d['kept'] or ''} | {d['family'] or ''} | {d['cold_family'] or ''} |")
    return out


def summary_markdown(records: Sequence[dict[str, Any]], ans: dict[str, Any], scenario: str, refs: ReferenceCurves | None,
                     files: dict[str, str], notes: Sequence[str] = (), n_expected: int | None = None) -> str:
    """Short markdown report: the answer, the power table, failures, references, files."""
    recs = sorted(records, key=_order)
    n_ok = sum(r["status"] == "ok" for r in recs)
    out = [f"# Sweep summary ({scenario} scenario)", "", "## Where folding pays", "", answer_sentence(ans, scenario), ""]
    winds = sorted({r["wind_mps"] for r in recs})
    lines: dict[str, dict[float, dict]] = {}
    for r in recs:
        lines.setdefault(line_label(r) + (f" tether {r['d0_m']:g}-{r['d_tf_m']:g} m"), {})[r["wind_mps"]] = r
    out += ["## Cycle-average net power [W] (`fail` = no converged cycle)", "",
            "| line | " + " | ".join(f"{w:g} m/s" for w in winds) + " |", "|---|" + "---|" * len(winds)]
    for name, by_w in lines.items():
        cells = []
        for w in winds:
            r = by_w.get(w)
            cells.append("" if r is None else (f"{r['P_avg_W']:.1f}" if r["status"] == "ok" else "fail"))
        out.append(f"| {name} | " + " | ".join(cells) + " |")
    if refs is not None:
        out += ["", f"References (unfolded wing, tether d_t {1e3 * refs.tether_diameter:.3g} mm, drag at "
                f"{refs.tether_length:g} m, C_L {refs.CL:.3f}, "
                f"C_D {refs.CD:.4f} incl. C_D,t {refs.CD_tether:.4f}): reel-out power, not cycle averages.", "",
                "| wind [m/s] | " + " | ".join(f"{w:g}" for w in refs.winds) + " |", "|---|" + "---|" * len(refs.winds),
                "| Loyd [W] | " + " | ".join(f"{v:.1f}" for v in refs.loyd_W) + " |",
                "| quasi-steady [W] | " + " | ".join(f"{v:.1f}" for v in refs.quasi_steady_W) + " |"]
    bad = [r for r in recs if r["status"] != "ok"]
    out += ["", f"## Points: {len(recs)} ({n_ok} ok, {len(bad)} failed)", ""]
    if n_expected is not None and n_expected > len(recs):
        out.append(f"- INCOMPLETE: {n_expected - len(recs)} of {n_expected} points have no result yet "
                   "(rerun the same command to compute them; blank cells above)")
    for r in bad:
        out.append(f"- failed: {line_label(r)}, wind {r['wind_mps']:g} m/s: {r['reason']}")
    out += cold_check_markdown(cold_check_differences(recs))
    if notes:
        out += ["", "## Notes", ""] + [f"- {n}" for n in notes]
    out += ["", "## Files", ""] + [f"- {k}: `{v}`" for k, v in files.items()]
    return "\n".join(out) + "\n"
