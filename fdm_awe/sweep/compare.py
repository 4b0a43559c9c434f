"""Compare two sweep output folders point by point (``fdm-awe sweep --compare``,
``scripts/compare_sweeps.py``).

A sweep should reproduce itself: a second run with another number of workers, a run that
solves every point cold (``--cold``) or one with the cold check off should give the same
cycle-average power at every point, or the difference should have a reason in the records.

Points are matched by their *physical identity* (:data:`PHYSICAL_FIELDS`: scenario,
configuration, wind, reel-out range, glider design, fold time, mesh, propeller, line weight,
tether line and its diameter, wind profile), not by their id: the id also holds solver settings (iteration
limits, warm fallback, cold check) that may differ between the two runs. For every matched
pair the comparison gives both powers ``P_avg_W`` [W] and ``P_b - P_a``; a pair is *flagged*
when the difference exceeds the tolerance (:data:`TOLERANCE_W`, 0.5 W) or only one of the two
converged. Each flagged pair gets the explanations its records hold (:func:`explain`): a
failed point and its reason, an iteration limit, different start families of the kept
solutions, a warm-started against a cold-solved point, a cold check whose other solution
matches the other run, different solver settings. A flagged pair without any of these is
*unexplained* (a run whose own warm and cold solutions differ is noted, not counted as a
reason).

The outcome is ``ok`` (exit 0) when every matched pair agrees within the tolerance or is
explained and every point has a partner; points found in one folder only are listed.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

from ..errors import InputError
from ..fileio import write_json
from .store import PointStore

#: [W] two runs' powers of one point agree when they differ by at most this
TOLERANCE_W = 0.5

#: record fields that make a point's physical identity (the problem solved, not how)
PHYSICAL_FIELDS = ("scenario", "config", "wind_mps", "d0_m", "d_tf_m", "folded_span_m", "folded_drag_area_m2",
                   "wing_area_m2", "fold_time_s", "mesh", "propeller", "line_weight", "line", "line_diameter_m",
                   "wind_profile", "tension_margin", "stall_margin", "line_model", "bounds")
#: record fields that say how a point was solved (a difference is an explanation)
SOLVER_FIELDS = ("max_iter", "max_iter_total", "warm_fallback", "cold_check")
#: what a record lacks when it was written before the field existed
_LEGACY = {"line": "paper", "line_weight": False, "fold_time_s": 0.0, "cold_check": False, "wind_profile": "uniform",
           "tension_margin": 0.0, "stall_margin": 0.0, "line_model": "straight", "bounds": "table3"}


def _field(r: dict[str, Any], k: str) -> Any:
    v = r.get(k)
    if v is None:
        v = _LEGACY.get(k)
    return round(float(v), 9) if isinstance(v, (int, float)) and not isinstance(v, bool) else v


def physical_key(r: dict[str, Any]) -> tuple:
    """The physical identity of a record (see the module docstring)."""
    return tuple(_field(r, k) for k in PHYSICAL_FIELDS)


def load_folder(out_dir: str | Path) -> dict[tuple, dict[str, Any]]:
    """Every usable point record of a sweep output folder by physical identity (unusable files
    are warned about and skipped, as a sweep would). A one-line error when the folder has no
    ``points/``."""
    root = Path(out_dir)
    if not (root / "points").is_dir():
        raise InputError(f"compare: {root} is not a sweep output folder (no points/ in it)")
    store = PointStore(root)
    out: dict[tuple, dict[str, Any]] = {}
    for p in sorted(store.dir.glob("*.json")):
        if p.name.startswith("."):  # the temporary file of a write in progress (or cut by a kill)
            continue
        r = store.load(p.stem)
        if r is not None:
            out[physical_key(r)] = r
    return out


def _ok(r: dict[str, Any]) -> bool:
    return r.get("status") == "ok" and isinstance(r.get("P_avg_W"), (int, float)) and math.isfinite(r["P_avg_W"])


def _how(r: dict[str, Any]) -> str:
    """How a record's kept solution was found: ``cold`` or ``warm`` (from ``warm_from``)."""
    if r.get("kept") in ("warm", "cold"):
        return r["kept"]
    return "warm" if r.get("warm_from") else "cold"


def _budget(r: dict[str, Any]) -> bool:
    reason = str(r.get("reason") or "").lower()
    return "iteration" in reason or "maximum number" in reason or "budget" in reason


def explain(a: dict[str, Any], b: dict[str, Any], tol_W: float = TOLERANCE_W) -> list[str]:
    """Reasons in the two records why their powers differ (empty: none found)."""
    why: list[str] = []
    for name, r in (("A", a), ("B", b)):
        if not _ok(r):
            why.append(f"{name} failed: {str(r.get('reason') or 'no reason recorded')[:160]}")
            if _budget(r):
                why.append(f"{name} reached its iteration limit")
    fa, fb = a.get("family"), b.get("family")
    if _ok(a) and _ok(b) and fa and fb and fa != fb:
        why.append(f"different start families: A {fa}, B {fb}")
    ha, hb = _how(a), _how(b)
    if ha != hb:
        why.append(f"A kept a {ha} solution, B a {hb} one")
    for name, r, o in (("A", a, b), ("B", b, a)):
        pw, pc = r.get("P_warm_W"), r.get("P_cold_W")
        if pw is None and pc is None:
            continue
        other = r.get("P_cold_W") if r.get("kept") == "warm" else r.get("P_warm_W")
        alt = "cold" if r.get("kept") == "warm" else "warm"
        if other is not None and _ok(o) and abs(other - o["P_avg_W"]) <= tol_W:
            why.append(f"{name}'s {alt} solution ({other:.2f} W) matches the other run; {name} kept its "
                       f"{r.get('kept')} solution")
    for k in SOLVER_FIELDS:
        va, vb = _field(a, k), _field(b, k)
        if va != vb:
            why.append(f"solver setting {k}: A {va}, B {vb}")
    return why


def notes(a: dict[str, Any], b: dict[str, Any], tol_W: float = TOLERANCE_W) -> list[str]:
    """What the records say besides the explanations: a run whose warm and cold solutions of
    the point differ (several local optima there; not by itself a reason for the two runs to
    differ)."""
    out = []
    for name, r in (("A", a), ("B", b)):
        pw, pc = r.get("P_warm_W"), r.get("P_cold_W")
        if pw is not None and pc is not None and abs(pw - pc) > tol_W:
            out.append(f"{name}'s warm and cold solutions differ ({pw:.2f} W / {pc:.2f} W; kept {r.get('kept')})")
    return out


def compare_folders(dir_a: str | Path, dir_b: str | Path, tol_W: float = TOLERANCE_W) -> dict[str, Any]:
    """The point-by-point comparison of two sweep output folders (see the module docstring) as
    a JSON-ready document."""
    ra, rb = load_folder(dir_a), load_folder(dir_b)
    rows = []
    for key in [k for k in ra if k in rb]:
        a, b = ra[key], rb[key]
        pa = a["P_avg_W"] if _ok(a) else None
        pb = b["P_avg_W"] if _ok(b) else None
        diff = None if pa is None or pb is None else pb - pa
        flagged = (pa is None) != (pb is None) or (diff is not None and abs(diff) > tol_W)
        why = explain(a, b, tol_W) if flagged else []
        rows.append({"config": a["config"], "wind_mps": a["wind_mps"], "line": a.get("line") or "paper",
                     "folded_span_m": a.get("folded_span_m"), "wing_area_m2": a.get("wing_area_m2"),
                     "d0_m": a["d0_m"], "d_tf_m": a["d_tf_m"], "id_a": a["id"], "id_b": b["id"],
                     "status_a": a["status"], "status_b": b["status"], "P_a_W": pa, "P_b_W": pb, "diff_W": diff,
                     "flagged": flagged, "explained": bool(why) if flagged else None, "explanation": why,
                     "notes": notes(a, b, tol_W),
                     "family_a": a.get("family"), "family_b": b.get("family"), "kept_a": _how(a), "kept_b": _how(b)})
    rows.sort(key=lambda r: (r["line"], r["config"] != "nominal", str(r["folded_span_m"]), r["d0_m"], r["d_tf_m"],
                             r["wind_mps"]))
    diffs = [abs(r["diff_W"]) for r in rows if r["diff_W"] is not None]
    only_a = sorted((ra[k] for k in set(ra) - set(rb)), key=lambda r: (r["config"], r["wind_mps"]))
    only_b = sorted((rb[k] for k in set(rb) - set(ra)), key=lambda r: (r["config"], r["wind_mps"]))
    flagged = [r for r in rows if r["flagged"]]
    unexplained = [r for r in flagged if not r["explained"]]
    return {"a": str(dir_a), "b": str(dir_b), "tolerance_W": tol_W, "n_matched": len(rows),
            "n_both_ok": len(diffs), "max_abs_diff_W": max(diffs) if diffs else None,
            "n_flagged": len(flagged), "n_explained": len(flagged) - len(unexplained), "n_unexplained": len(unexplained),
            "only_in_a": [{"id": r["id"], "config": r["config"], "wind_mps": r["wind_mps"]} for r in only_a],
            "only_in_b": [{"id": r["id"], "config": r["config"], "wind_mps": r["wind_mps"]} for r in only_b],
            "ok": not unexplained and not only_a and not only_b and bool(rows), "points": rows}


def _p(v: Any) -> str:
    return "failed" if v is None else f"{v:.2f}"


def comparison_text(doc: dict[str, Any]) -> str:
    """The comparison as a plain-text table (one line per matched point, flagged ones with their
    explanations) and a closing verdict."""
    out = [f"A: {doc['a']}", f"B: {doc['b']}",
           f"{'config':9} {'line':6} {'b_f':>5} {'wind':>5} {'P_A [W]':>9} {'P_B [W]':>9} {'B-A [W]':>8}  flag"]
    for r in doc["points"]:
        d = "" if r["diff_W"] is None else f"{r['diff_W']:+.3f}"
        bf = "" if r["folded_span_m"] is None else f"{r['folded_span_m']:.3g}"
        flag = "" if not r["flagged"] else ("EXPLAINED" if r["explained"] else "UNEXPLAINED")
        out.append(f"{r['config']:9} {r['line']:6} {bf:>5} {r['wind_mps']:5g} {_p(r['P_a_W']):>9} {_p(r['P_b_W']):>9} "
                   f"{d:>8}  {flag}")
        for w in r["explanation"]:
            out.append(f"    - {w}")
        if r["flagged"]:
            out += [f"    (note: {w})" for w in r["notes"]]
    for side in ("a", "b"):
        for r in doc[f"only_in_{side}"]:
            out.append(f"only in {side.upper()}: {r['config']} wind {r['wind_mps']:g} m/s ({r['id']})")
    mx = doc["max_abs_diff_W"]
    out.append(f"{doc['n_matched']} points matched, {doc['n_both_ok']} converged in both; max |B-A| "
               f"{'n/a' if mx is None else f'{mx:.3f} W'}; {doc['n_flagged']} beyond {doc['tolerance_W']:g} W or failed "
               f"in one ({doc['n_explained']} explained, {doc['n_unexplained']} unexplained); "
               f"{len(doc['only_in_a']) + len(doc['only_in_b'])} without a partner")
    out.append("reproduced" if doc["ok"] else "NOT reproduced")
    return "\n".join(out)


def run_compare(dir_a: str | Path, dir_b: str | Path, json_path: str | Path | None = None,
                tol_W: float = TOLERANCE_W) -> int:
    """Print the comparison, write its JSON (atomically) when asked; 0 when reproduced, else 1."""
    if not (isinstance(tol_W, (int, float)) and math.isfinite(tol_W) and tol_W >= 0):
        raise InputError(f"compare tolerance {tol_W!r} W out of range (allowed >= 0 W)")
    doc = compare_folders(dir_a, dir_b, tol_W)
    print(comparison_text(doc))
    if json_path is not None:
        write_json(json_path, json.loads(json.dumps(doc, default=str)), indent=1)
    return 0 if doc["ok"] else 1
