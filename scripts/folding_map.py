#!/usr/bin/env python
"""Where folding pays: ``P_foldable - P_nominal`` over line diameter x reel-out range x folded
span x wind, from one or more ``fdm-awe sweep`` output folders, written into a folder:

    folding_map.md                 the table (both powers, their difference, failed points
                                   marked) and the answer in words and numbers
    folding_map.json               the same numbers, every pair with both points' energies
    folding_map_<d0>-<dtf>m.png    heat map of the difference, one per reel-out range

Usage: python scripts/folding_map.py SWEEP_OUT [SWEEP_OUT ...] [--out DIR] [--min-gain 0.5]

Each source is a sweep's ``--out`` folder (its ``points/<id>.json`` records, also of points an
unfinished sweep has written) or a sweep's ``--json`` file (its ``points`` list).

Conventions (SI): powers are cycle-average net powers ``P_avg_W`` [W] (> 0: the cycle gains
energy), ``dP = P_foldable - P_nominal`` [W]; folding *pays* where both points converged and
``dP > min_gain``, *loses* where ``dP < -min_gain``, and the two are *even* in between.

A foldable point is paired with the nominal point of the same plant and operating context:
scenario, propeller model, line weight, collocation mesh, wing area, reel-out range ``d0:d_tf``,
tether line and its swept diameter, wind. Budgets (iteration limits, warm-start fallback, cold
check) are not part of the pairing: they change how hard the optimiser looks, not the problem.
The same point found in several sources (or solved under several budgets) counts once, with
its best converged power (the better local optimum of the same problem).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any, Iterable, Sequence

os.environ.setdefault("JSBSIM_DEBUG", "0")
os.environ.setdefault("MPLBACKEND", "Agg")

from fdm_awe.errors import InputError  # noqa: E402
from fdm_awe.fileio import atomic_path, check_output_dir, write_json, atomic_write_text  # noqa: E402
from fdm_awe.sweep.store import record_problem  # noqa: E402

#: default margin [W] a difference must exceed to count as a gain (or a loss) of folding
MIN_GAIN_W = 0.5
#: energy and timing fields of a point carried into the JSON (per pair, both points)
ENERGY_FIELDS = ("E_net_J", "E_generated_J", "E_thrust_J", "E_reel_in_J", "T1_s", "T2_s")


def _warn(msg: str) -> None:
    print(f"warning: {msg}", file=sys.stderr)


def read_records(source: str | os.PathLike) -> list[dict[str, Any]]:
    """Point records of one sweep output: a ``--out`` folder (``points/*.json``) or a ``--json``
    file. Files that are not usable records are skipped with one warning each."""
    p = Path(source)
    if p.is_dir():
        pdir = p / "points"
        if not pdir.is_dir():
            raise InputError(f"source {p}: not a sweep output folder (no points/ in it)")
        out = []
        for f in sorted(pdir.glob("*.json")):
            try:
                rec = json.loads(f.read_text(encoding="utf-8"))
            except (OSError, ValueError, RecursionError) as exc:
                _warn(f"{f}: skipped, not a readable record ({type(exc).__name__})")
                continue
            why = record_problem(rec, f.stem)
            if why is not None:
                _warn(f"{f}: skipped, not a valid record ({why})")
                continue
            out.append(rec)
        return out
    if p.is_file():
        try:
            doc = json.loads(p.read_text(encoding="utf-8"))
        except (OSError, ValueError, RecursionError) as exc:
            raise InputError(f"source {p}: not a readable sweep JSON file ({type(exc).__name__})") from None
        if not isinstance(doc, dict) or not isinstance(doc.get("points"), list):
            raise InputError(f"source {p}: not a sweep JSON file (no 'points' list; expected the file of 'fdm-awe sweep --json')")
        out = []
        for i, rec in enumerate(doc["points"]):
            why = record_problem(rec, rec.get("id") if isinstance(rec, dict) else "")
            if why is not None:
                _warn(f"{p}: points[{i}] skipped, not a valid record ({why})")
                continue
            out.append(rec)
        return out
    raise InputError(f"source {p}: does not exist (expected a sweep --out folder or its --json file)")


def _f(v: Any) -> float | None:
    return None if v is None else float(v)


def context_key(r: dict[str, Any]) -> tuple:
    """Plant and operating context a foldable point shares with its nominal counterpart."""
    return (r["scenario"], r.get("propeller"), r.get("line_weight"), r.get("mesh"), _f(r.get("wing_area_m2")),
            float(r["d0_m"]), float(r["d_tf_m"]), r.get("line") or "paper", _f(r.get("line_diameter_m")))


def point_key(r: dict[str, Any]) -> tuple:
    """The physical identity of a point: its context, configuration, folded wing, fold time, wind."""
    fold = (None, None, None) if r["config"] == "nominal" else (
        _f(r.get("folded_span_m")), _f(r.get("folded_drag_area_m2")), _f(r.get("fold_time_s")))
    return (context_key(r), r["config"], *fold, float(r["wind_mps"]))


def _better(a: dict[str, Any], b: dict[str, Any]) -> dict[str, Any]:
    """The record to keep of two solutions of the same point: a converged one, the higher power."""
    if (a["status"] == "ok") != (b["status"] == "ok"):
        return a if a["status"] == "ok" else b
    if a["status"] == "ok" and b["P_avg_W"] > a["P_avg_W"]:
        return b
    return a


def merge(records: Iterable[dict[str, Any]]) -> list[dict[str, Any]]:
    """One record per physical point (see :func:`point_key`), the best of its solutions."""
    best: dict[tuple, dict[str, Any]] = {}
    for r in records:
        k = point_key(r)
        best[k] = r if k not in best else _better(best[k], r)
    return list(best.values())


@dataclass
class Pair:
    """One (line diameter, reel-out range, folded span, wind) cell: a foldable point and its
    nominal counterpart. Powers [W] are None where the point failed or has no record."""

    scenario: str
    d0_m: float
    d_tf_m: float
    line: str
    line_d_m: float | None  #: the line's actual diameter [m] (swept or as defined)
    line_diameter_m: float | None  #: the swept diameter [m] (None: the line as defined)
    b_f_m: float | None  #: folded span [m] (None: the definition's)
    drag_area_f_m2: float | None  #: folded drag area C_Dmin,f S_f [m2]
    fold_time_s: float | None
    wind_mps: float
    status_foldable: str  #: ok | failed
    status_nominal: str  #: ok | failed | missing (no nominal record of this context and wind)
    P_foldable_W: float | None
    P_nominal_W: float | None
    id_foldable: str = ""
    id_nominal: str | None = None
    reason_foldable: str | None = None
    reason_nominal: str | None = None
    #: |P_warm - P_cold| [W] of each point's cold check (None: not checked or one side failed):
    #: how far apart the optimiser's two solutions of the same point were
    spread_foldable_W: float | None = None
    spread_nominal_W: float | None = None
    energies_foldable: dict[str, float | None] = field(default_factory=dict)
    energies_nominal: dict[str, float | None] = field(default_factory=dict)

    @property
    def dP_W(self) -> float | None:
        """``P_foldable - P_nominal`` [W] (> 0: folding pays); None unless both converged."""
        if self.P_foldable_W is None or self.P_nominal_W is None:
            return None
        return self.P_foldable_W - self.P_nominal_W

    def verdict(self, min_gain_W: float = MIN_GAIN_W) -> str:
        """``pays`` (dP > min_gain), ``loses`` (dP < -min_gain), ``even``, or why there is no
        difference: ``foldable failed``, ``nominal failed``, ``both failed``, ``no nominal``."""
        d = self.dP_W
        if d is not None:
            return "pays" if d > min_gain_W else ("loses" if d < -min_gain_W else "even")
        if self.status_nominal == "missing":
            return "no nominal"
        if self.status_foldable != "ok" and self.status_nominal != "ok":
            return "both failed"
        return "foldable failed" if self.status_foldable != "ok" else "nominal failed"

    def to_dict(self, min_gain_W: float = MIN_GAIN_W) -> dict[str, Any]:
        return {**asdict(self), "dP_W": self.dP_W, "verdict": self.verdict(min_gain_W)}


def _spread(r: dict[str, Any]) -> float | None:
    pw, pc = r.get("P_warm_W"), r.get("P_cold_W")
    return None if pw is None or pc is None else abs(float(pc) - float(pw))


def _energies(r: dict[str, Any] | None) -> dict[str, float | None]:
    if r is None or r["status"] != "ok":
        return {}
    return {k: _f(r.get(k)) for k in ENERGY_FIELDS}


def pairs(records: Iterable[dict[str, Any]]) -> list[Pair]:
    """Every foldable point with its nominal counterpart (records merged first, :func:`merge`),
    in the order reel-out range, line diameter, folded span, wind."""
    recs = merge(records)
    nominal = {(context_key(r), float(r["wind_mps"])): r for r in recs if r["config"] == "nominal"}
    line_d: dict[tuple, float] = {}  # the actual diameter of each context, from any record that has it
    for r in recs:
        if r.get("line_d_m") is not None:
            line_d.setdefault(context_key(r), float(r["line_d_m"]))
    out = []
    for r in recs:
        if r["config"] != "foldable":
            continue
        ctx = context_key(r)
        n = nominal.get((ctx, float(r["wind_mps"])))
        b_f = r.get("b_f_m") if r.get("b_f_m") is not None else r.get("folded_span_m")
        area = r.get("drag_area_f_m2") if r.get("drag_area_f_m2") is not None else r.get("folded_drag_area_m2")
        out.append(Pair(
            scenario=r["scenario"], d0_m=float(r["d0_m"]), d_tf_m=float(r["d_tf_m"]), line=r.get("line") or "paper",
            line_d_m=line_d.get(ctx), line_diameter_m=_f(r.get("line_diameter_m")), b_f_m=_f(b_f),
            drag_area_f_m2=_f(area), fold_time_s=_f(r.get("fold_time_s")), wind_mps=float(r["wind_mps"]),
            status_foldable=r["status"], status_nominal="missing" if n is None else n["status"],
            P_foldable_W=float(r["P_avg_W"]) if r["status"] == "ok" else None,
            P_nominal_W=float(n["P_avg_W"]) if (n is not None and n["status"] == "ok") else None,
            id_foldable=r["id"], id_nominal=None if n is None else n["id"],
            reason_foldable=None if r["status"] == "ok" else r.get("reason"),
            reason_nominal=None if (n is None or n["status"] == "ok") else n.get("reason"),
            spread_foldable_W=_spread(r), spread_nominal_W=None if n is None else _spread(n),
            energies_foldable=_energies(r), energies_nominal=_energies(n)))
    out.sort(key=_pair_order)
    return out


def _nn(v: float | None) -> float:
    return -1.0 if v is None else v


def _pair_order(p: Pair) -> tuple:
    return (p.scenario, p.d0_m, p.d_tf_m, p.line, _nn(p.line_d_m), _nn(p.b_f_m), _nn(p.drag_area_f_m2),
            _nn(p.fold_time_s), p.wind_mps)


def _where(p: Pair | dict[str, Any]) -> str:
    d = p if isinstance(p, dict) else p.to_dict()
    line = d["line"] + ("" if d["line_d_m"] is None else f" {1e3 * d['line_d_m']:.3g} mm")
    bf = "b_f def" if d["b_f_m"] is None else f"b_f {d['b_f_m']:.3g} m"
    return f"reel-out {d['d0_m']:g}-{d['d_tf_m']:g} m, line {line}, {bf}, wind {d['wind_mps']:g} m/s"


def answer(prs: Sequence[Pair], min_gain_W: float = MIN_GAIN_W) -> dict[str, Any]:
    """Where folding pays, in numbers: counts by verdict, every winning pair, the best and the
    worst comparable pair, the loss range per reel-out range and line, the pairs where only one
    configuration has a cycle."""
    comp = [p for p in prs if p.dP_W is not None]
    by_verdict: dict[str, int] = {}
    for p in prs:
        v = p.verdict(min_gain_W)
        by_verdict[v] = by_verdict.get(v, 0) + 1
    groups: dict[tuple, list[Pair]] = {}
    for p in comp:
        groups.setdefault((p.d0_m, p.d_tf_m, p.line, p.line_d_m), []).append(p)
    ranges = [{"d0_m": k[0], "d_tf_m": k[1], "line": k[2], "line_d_m": k[3], "n": len(v),
               "dP_min_W": min(p.dP_W for p in v), "dP_max_W": max(p.dP_W for p in v),
               "best": _where(max(v, key=lambda p: p.dP_W))} for k, v in groups.items()]

    def d(p: Pair | None) -> dict[str, Any] | None:
        return None if p is None else p.to_dict(min_gain_W)

    return {
        "min_gain_W": min_gain_W, "n_pairs": len(prs), "n_comparable": len(comp), "verdicts": by_verdict,
        "pays": [d(p) for p in comp if p.dP_W > min_gain_W],
        "best": d(max(comp, key=lambda p: p.dP_W) if comp else None),
        "worst": d(min(comp, key=lambda p: p.dP_W) if comp else None),
        "by_context": ranges,
        "only_foldable": [d(p) for p in prs if p.verdict(min_gain_W) == "nominal failed"],
        "only_nominal": [d(p) for p in prs if p.verdict(min_gain_W) == "foldable failed"],
    }


def _mm(d_m: float | None) -> str:
    """A line diameter [m] in mm for tables (``def``: the line as defined)."""
    return "def" if d_m is None else f"{1e3 * d_m:.3g}"


def _pw(v: float | None) -> str:
    return "fail" if v is None else f"{v:+.1f}"


def answer_text(ans: dict[str, Any]) -> str:
    """The answer in a few sentences with numbers."""
    g = ans["min_gain_W"]
    if ans["n_pairs"] == 0:
        return "No foldable points in the sources: nothing to compare."
    if ans["n_comparable"] == 0:
        return (f"{ans['n_pairs']} foldable points, none with a converged nominal counterpart: "
                "the sources cannot say where folding pays.")
    b, w = ans["best"], ans["worst"]
    if ans["pays"]:
        wins = "; ".join(f"{_where(p)} ({p['dP_W']:+.1f} W)" for p in ans["pays"])
        out = (f"Folding pays (gain > {g:g} W) in {len(ans['pays'])} of {ans['n_comparable']} comparable pairs: {wins}.")
    else:
        out = (f"Folding pays (gain > {g:g} W) nowhere: over all {ans['n_comparable']} comparable pairs the foldable "
               f"glider's best margin over the nominal one is {b['dP_W']:+.1f} W.")
    out += (f" Best case: {_where(b)}, {b['P_foldable_W']:+.1f} W foldable vs {b['P_nominal_W']:+.1f} W nominal "
            f"({b['dP_W']:+.1f} W). Worst case: {_where(w)}, {w['P_foldable_W']:+.1f} W vs {w['P_nominal_W']:+.1f} W "
            f"({w['dP_W']:+.1f} W).")
    even = ans["verdicts"].get("even", 0)
    if even:
        out += f" Within +-{g:g} W (even): {even} pairs."
    if ans["only_foldable"]:
        out += (" Only the foldable glider found a cycle (nominal failed) at: "
                + "; ".join(f"{_where(p)} ({p['P_foldable_W']:+.1f} W)" for p in ans["only_foldable"]) + ".")
    if ans["only_nominal"]:
        out += (f" Only the nominal glider found a cycle (foldable failed) in {len(ans['only_nominal'])} pair(s).")
    return out


def _cell(p: Pair, min_gain_W: float) -> str:
    d = p.dP_W
    if d is None:
        return p.verdict(min_gain_W)
    return f"**{d:+.1f}**" if d > min_gain_W else f"{d:+.1f}"


def _star(spread: float | None, tol: float) -> str:
    return "*" if spread is not None and spread > tol else ""


def markdown(prs: Sequence[Pair], ans: dict[str, Any], sources: Sequence[str], images: Sequence[str] = ()) -> str:
    """The report: the answer, a compact map per reel-out range, the full table."""
    g = ans["min_gain_W"]
    out = ["# Where folding pays", "", answer_text(ans), "",
           f"`dP = P_foldable - P_nominal` [W], cycle-average net power; **bold**: folding pays (dP > {g:g} W). "
           "`fail` / `nominal failed` / `foldable failed`: no converged cycle (the optimiser's verdict, not a proof "
           f"that none exists). `*`: that point's warm-started and cold solves differ by more than {g:g} W "
           "(the better one is kept; the problem has several local optima there).", ""]
    winds = sorted({p.wind_mps for p in prs})
    ranges = sorted({(p.d0_m, p.d_tf_m) for p in prs})
    for d0, dtf in ranges:
        sel = [p for p in prs if (p.d0_m, p.d_tf_m) == (d0, dtf)]
        out += [f"## Reel-out {d0:g}-{dtf:g} m: dP [W]", "",
                "| line d [mm] | b_f [m] | " + " | ".join(f"{w:g} m/s" for w in winds) + " |",
                "|---|---|" + "---|" * len(winds)]
        rows: dict[tuple, dict[float, Pair]] = {}
        for p in sel:
            rows.setdefault((_nn(p.line_d_m), _nn(p.b_f_m), p.line, _nn(p.drag_area_f_m2), _nn(p.fold_time_s)), {})[p.wind_mps] = p
        for (ld, bf, *_), by_w in rows.items():
            cells = [("" if by_w.get(w) is None else _cell(by_w[w], g)) for w in winds]
            out.append(f"| {_mm(None if ld < 0 else ld)} | {'def' if bf < 0 else f'{bf:.3g}'} | "
                       + " | ".join(cells) + " |")
        nom: dict[tuple, dict[float, Pair]] = {}
        for p in sel:
            nom.setdefault((_nn(p.line_d_m), p.line), {})[p.wind_mps] = p
        out += ["", "Nominal glider [W]:", "", "| line d [mm] | " + " | ".join(f"{w:g} m/s" for w in winds) + " |",
                "|---|" + "---|" * len(winds)]
        for (ld, _line), by_w in nom.items():
            cells = []
            for w in winds:
                p = by_w.get(w)
                cells.append("" if p is None else ("n/a" if p.status_nominal == "missing" else
                                                   _pw(p.P_nominal_W) + _star(p.spread_nominal_W, g)))
            out.append(f"| {_mm(None if ld < 0 else ld)} | " + " | ".join(cells) + " |")
        out.append("")
    out += ["## Every pair", "",
            "| reel-out [m] | line d [mm] | b_f [m] | wind [m/s] | P_nominal [W] | P_foldable [W] | dP [W] | verdict |",
            "|---|---|---|---|---|---|---|---|"]
    for p in prs:
        pn = "n/a" if p.status_nominal == "missing" else _pw(p.P_nominal_W) + _star(p.spread_nominal_W, g)
        out.append(f"| {p.d0_m:g}-{p.d_tf_m:g} | {_mm(p.line_d_m)} | "
                   f"{'def' if p.b_f_m is None else f'{p.b_f_m:.3g}'} | {p.wind_mps:g} | {pn} | "
                   f"{_pw(p.P_foldable_W)}{_star(p.spread_foldable_W, g)} | "
                   f"{'' if p.dP_W is None else f'{p.dP_W:+.1f}'} | {p.verdict(g)} |")
    split = [p for p in prs if p.dP_W is not None and p.energies_foldable and p.energies_nominal]
    if split:
        out += ["", "## Where the difference comes from (foldable minus nominal, per cycle)", "",
                "E_net = E_generated - E_thrust - E_reel_in [J]; P = E_net / (T1 + T2). A positive dE_thrust or "
                "dE_reel_in is energy the foldable cycle spends more.", "",
                "| reel-out [m] | line d [mm] | b_f [m] | wind [m/s] | dE_generated [J] | dE_thrust [J] | "
                "dE_reel_in [J] | T1 nom/fold [s] | T2 nom/fold [s] | dP [W] |", "|---|---|---|---|---|---|---|---|---|---|"]
        for p in split:
            ef, en = p.energies_foldable, p.energies_nominal

            def dd(k: str) -> str:
                return "" if ef.get(k) is None or en.get(k) is None else f"{ef[k] - en[k]:+.0f}"

            def tt(k: str) -> str:
                return "" if ef.get(k) is None or en.get(k) is None else f"{en[k]:.1f} / {ef[k]:.1f}"

            out.append(f"| {p.d0_m:g}-{p.d_tf_m:g} | {_mm(p.line_d_m)} | {'def' if p.b_f_m is None else f'{p.b_f_m:.3g}'} | "
                       f"{p.wind_mps:g} | {dd('E_generated_J')} | {dd('E_thrust_J')} | {dd('E_reel_in_J')} | "
                       f"{tt('T1_s')} | {tt('T2_s')} | {p.dP_W:+.1f} |")
    if ans["by_context"]:
        out += ["", "## Range of dP per reel-out range and line", "",
                "| reel-out [m] | line d [mm] | pairs | dP min [W] | dP max [W] | best at |", "|---|---|---|---|---|---|"]
        for c in ans["by_context"]:
            out.append(f"| {c['d0_m']:g}-{c['d_tf_m']:g} | {_mm(c['line_d_m'])} | "
                       f"{c['n']} | {c['dP_min_W']:+.1f} | {c['dP_max_W']:+.1f} | {c['best']} |")
    out += ["", "## Sources", ""] + [f"- `{s}`" for s in sources]
    if images:
        out += ["", "## Heat maps", ""] + [f"- `{Path(i).name}`" for i in images]
    return "\n".join(out) + "\n"


def heat_map(prs: Sequence[Pair], path: str | Path, min_gain_W: float = MIN_GAIN_W) -> Path:
    """Colour map of dP [W] for one reel-out range: rows (line diameter, folded span), columns
    wind; blue: folding pays, red: it loses, grey: a point of the pair failed."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np
    from matplotlib.colors import Normalize

    rows = sorted({(_nn(p.line_d_m), _nn(p.b_f_m)) for p in prs})
    winds = sorted({p.wind_mps for p in prs})
    Z = np.full((len(rows), len(winds)), np.nan)
    text = np.full(Z.shape, "", dtype=object)
    for p in prs:
        i, j = rows.index((_nn(p.line_d_m), _nn(p.b_f_m))), winds.index(p.wind_mps)
        if p.dP_W is not None:
            Z[i, j] = p.dP_W
            text[i, j] = f"{p.dP_W:+.1f}"
        else:
            text[i, j] = {"foldable failed": "fold\nfail", "nominal failed": "nom\nfail", "both failed": "both\nfail",
                          "no nominal": "no\nnom"}[p.verdict(min_gain_W)]
    fig, ax = plt.subplots(figsize=(2.8 + 0.9 * len(winds), 1.9 + 0.42 * len(rows)))
    finite = Z[np.isfinite(Z)]
    m = float(max(np.abs(finite).max(), 1.0)) if finite.size else 1.0  # symmetric: a small gain looks small
    ax.set_facecolor("0.8")
    im = ax.imshow(np.ma.masked_invalid(Z), cmap="RdBu", norm=Normalize(-m, m), aspect="auto", origin="lower")
    for i in range(len(rows)):
        for j in range(len(winds)):
            dark = bool(np.isfinite(Z[i, j]) and abs(Z[i, j]) > 0.6 * m)
            ax.text(j, i, text[i, j], ha="center", va="center", fontsize=7, color="w" if dark else "k")
    for i in range(1, len(rows)):  # a line between line diameters
        if rows[i][0] != rows[i - 1][0]:
            ax.axhline(i - 0.5, color="k", lw=1.0)
    ax.set_xticks(range(len(winds)), [f"{w:g}" for w in winds])
    ax.set_yticks(range(len(rows)), [f"d {'def' if ld < 0 else f'{1e3 * ld:.2f}'} mm, b_f {'def' if bf < 0 else f'{bf:.2f}'} m"
                                     for ld, bf in rows], fontsize=7)
    ax.set_xlabel("wind speed [m/s]")
    fig.colorbar(im, ax=ax, label="P_foldable - P_nominal [W]")
    p0 = prs[0]
    ax.set_title(f"where folding pays (> 0, blue): {p0.scenario}, reel-out {p0.d0_m:g}-{p0.d_tf_m:g} m\n"
                 "cycle-average net power, foldable minus nominal [W]; grey: a point failed", fontsize=8)
    fig.tight_layout()
    try:
        with atomic_path(path, suffix=".png") as tmp:
            fig.savefig(tmp, dpi=110, format="png")
    finally:
        plt.close(fig)
    return Path(path)


def write_map(sources: Sequence[str], out_dir: str | Path, min_gain_W: float = MIN_GAIN_W) -> dict[str, Any]:
    """Read ``sources``, write ``folding_map.md``, ``folding_map.json`` and the heat maps into
    ``out_dir``; returns the JSON document."""
    records = [r for s in sources for r in read_records(s)]
    prs = pairs(records)
    ans = answer(prs, min_gain_W)
    out = Path(out_dir)
    images = []
    for d0, dtf in sorted({(p.d0_m, p.d_tf_m) for p in prs}):
        sel = [p for p in prs if (p.d0_m, p.d_tf_m) == (d0, dtf)]
        images.append(str(heat_map(sel, out / f"folding_map_{d0:g}-{dtf:g}m.png", min_gain_W)))
    atomic_write_text(out / "folding_map.md", markdown(prs, ans, list(sources), images))
    doc = {"sources": list(sources), "n_records": len(records), "answer": ans, "answer_text": answer_text(ans),
           "pairs": [p.to_dict(min_gain_W) for p in prs], "images": images}
    write_json(out / "folding_map.json", doc, indent=1)
    return doc


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("sources", nargs="+", metavar="SWEEP_OUT", help="sweep --out folders or --json files")
    ap.add_argument("--out", default="runs/map", help="output folder (default runs/map)")
    ap.add_argument("--min-gain", type=float, default=MIN_GAIN_W,
                    help=f"margin [W] dP must exceed to count as a gain or a loss, 0..100 (default {MIN_GAIN_W:g})")
    args = ap.parse_args(argv)
    try:
        if not (0.0 <= args.min_gain <= 100.0) or math.isnan(args.min_gain):
            raise InputError(f"--min-gain {args.min_gain:g}: allowed 0..100 W")
        check_output_dir(args.out, "--out", inputs=args.sources)
        doc = write_map(args.sources, args.out, args.min_gain)
    except InputError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    print(doc["answer_text"])
    print(f"{len(doc['pairs'])} pairs from {doc['n_records']} records -> {Path(args.out) / 'folding_map.md'}, "
          f"{Path(args.out) / 'folding_map.json'}" + "".join(f", {i}" for i in doc["images"]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
