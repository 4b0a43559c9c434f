"""The bounds that bind at a solved cycle: which constraint, in which phase, where in the cycle,
and IPOPT's multiplier (``lam_x`` for the decision vector's bounds, ``lam_g`` for the constraint
rows).

A bound binds where its multiplier is not zero and the solution sits on it (within
:data:`ON_BOUND`, scaled units). Equality rows (collocation, boundaries, periodicity) always
hold and are not listed; every inequality is: the variable bounds of :func:`fdm_awe.ocp.
constraints.state_bounds` and :func:`~fdm_awe.ocp.constraints.control_bounds` (airspeed, flight
path, ground clearance, angle of attack, bank, thrust, reel-in speed, on-fraction, phase
durations) and the inequality rows (tension, thrust available, slack line, cycle cap ``t_max``,
rates, catch).

Each entry groups the points of one bound in one phase that bind one after another (a span of
the cycle): ``constraint`` (the variable or the row's name without its point tag), ``side``
(``lower``/``upper``), ``phase`` (``generation``, ``recovery`` or ``cycle`` for the rows of the
whole cycle), ``t_start_s``/``t_end_s`` (time from the start of generation [s]; None for a
row of the whole cycle), ``points``,
``multiplier`` (the sum of IPOPT's multipliers over the span, scaled NLP: the objective is
``-P_avg / P_SCALE``), and for the variable bounds, ``t_max`` and ``reel_in`` ``gain_W_per_unit``: the
average power [W] the optimum gains per unit [SI] the bound is relaxed at every point of the
span (first-order sensitivity).
"""

from __future__ import annotations

import re
from typing import Any

import numpy as np

from .collocation import P_SCALE, CycleNLP
from .constraints import REEL_IN_ROW_SCALE
from .layout import CONTROL_SCALE, STATE_SCALE, TIME_SCALE

#: a bound binds when its multiplier exceeds this (scaled NLP)
MIN_MULTIPLIER = 1e-6
#: ... and the solution is this close to it (scaled units)
ON_BOUND = 1e-4
PHASES = ("generation", "recovery")
#: the rows whose scale is known [SI]: their multipliers also give the power per unit relaxed
ROW_SCALES = {"t_max": TIME_SCALE, "reel_in": REEL_IN_ROW_SCALE}
_TAG = re.compile(r"^(?P<name>.+?)_p(?P<ip>[01])_(?:(?P<start>start)|(?P<k>\d+)(?:_(?P<j>\d+))?)$")


def _row_place(nlp: CycleNLP, name: str, t_nodes: list[np.ndarray]) -> tuple[str, int | None, float]:
    """(constraint, phase index or None, time in its phase [s]) of the row called ``name``."""
    m = _TAG.match(name)
    if not m:
        return name, None, 0.0
    ip = int(m["ip"])
    ph = nlp.phases[ip]
    if m["start"]:
        return m["name"], ip, 0.0
    k = int(m["k"])
    tau = 0.5 if m["j"] is None else float(nlp.tau[int(m["j"])])
    return m["name"], ip, float(ph.time(t_nodes[ip], k, tau))


def _spans(items: list[tuple[float, float, float]], gap: float) -> list[list[tuple[float, float, float]]]:
    """Items ``(t, multiplier, gain)`` sorted by time, split where two follow more than ``gap`` [s] apart."""
    items = sorted(items)
    out: list[list[tuple[float, float, float]]] = []
    for it in items:
        if out and it[0] - out[-1][-1][0] <= gap:
            out[-1].append(it)
        else:
            out.append([it])
    return out


def active_bounds(nlp: CycleNLP, w: np.ndarray, lam_x: np.ndarray | None, lam_g: np.ndarray | None,
                  params: np.ndarray) -> list[dict[str, Any]]:
    """The binding bounds of the solution ``w`` with multipliers ``lam_x``, ``lam_g`` (module
    docstring), strongest (largest ``|multiplier|``) first; empty without multipliers."""
    if lam_x is None or lam_g is None:
        return []
    w, lam_x, lam_g = (np.asarray(a, float).ravel() for a in (w, lam_x, lam_g))
    T = [float(w[ph.idx_T] * TIME_SCALE) for ph in nlp.phases]
    t_nodes = [ph.node_times(Ti) for ph, Ti in zip(nlp.phases, T)]
    offset = (0.0, T[0])
    groups: dict[tuple[str, str, str], list[tuple[float, float, float]]] = {}

    def add(constraint: str, side: str, ip: int | None, t: float, lam: float, gain: float) -> None:
        phase = "cycle" if ip is None else PHASES[ip]
        groups.setdefault((constraint, side, phase), []).append((t + (offset[ip] if ip is not None else 0.0), lam, gain))

    # the decision vector's bounds
    for ip, ph in enumerate(nlp.phases):
        places: dict[int, tuple[str, float, float]] = {}
        for k in range(ph.n):
            for j in range(nlp.d + 1):
                t = float(ph.time(t_nodes[ip], k, float(nlp.tau[j])))
                for i, s in enumerate(ph.states):
                    places.setdefault(int(ph.idx_X[k, j, i]), (s, t, STATE_SCALE[s]))
            for c, name in enumerate(ph.controls):
                places[int(ph.idx_U[k, c])] = (name, float(ph.time(t_nodes[ip], k, 0.5)), CONTROL_SCALE[name])
        places[int(ph.idx_T)] = (f"T{ip + 1}", T[ip], TIME_SCALE)
        for idx, (name, t, scale) in places.items():
            lam = float(lam_x[idx])
            if abs(lam) < MIN_MULTIPLIER:
                continue
            side = "upper" if lam > 0 else "lower"
            bound = nlp.ubw[idx] if lam > 0 else nlp.lbw[idx]
            if abs(w[idx] - bound) > ON_BOUND or nlp.lbw[idx] == nlp.ubw[idx]:
                continue
            add(name, side, ip, t, lam, P_SCALE * abs(lam) / scale)
    # the inequality rows
    g = np.asarray(nlp.g_fn(w, params), float).ravel()
    for r, name in enumerate(nlp.g_names):
        lam = float(lam_g[r])
        if nlp.lbg[r] == nlp.ubg[r] or abs(lam) < MIN_MULTIPLIER:
            continue
        bound = nlp.ubg[r] if lam > 0 else nlp.lbg[r]
        if not np.isfinite(bound) or abs(g[r] - bound) > ON_BOUND:
            continue
        constraint, ip, t = _row_place(nlp, name, t_nodes)
        scale = ROW_SCALES.get(constraint)
        gain = P_SCALE * abs(lam) / scale if scale else float("nan")
        add(constraint, "upper" if lam > 0 else "lower", ip, t, lam, gain)

    out = []
    for (constraint, side, phase), items in groups.items():
        ip = PHASES.index(phase) if phase in PHASES else 0
        gap = 1.01 * float(np.max(np.diff(t_nodes[ip]))) if phase != "cycle" else np.inf
        for span in _spans(items, gap):
            whole = phase == "cycle"
            entry: dict[str, Any] = {"constraint": constraint, "side": side, "phase": phase,
                                     "t_start_s": None if whole else round(span[0][0], 3),
                                     "t_end_s": None if whole else round(span[-1][0], 3),
                                     "points": len(span), "multiplier": float(sum(s[1] for s in span))}
            gains = [s[2] for s in span]
            if all(np.isfinite(gains)):
                entry["gain_W_per_unit"] = float(sum(gains))
            out.append(entry)
    out.sort(key=lambda e: -abs(e["multiplier"]))
    return out


def format_active(entries: list[dict[str, Any]], limit: int = 12) -> list[str]:
    """Report lines of the binding bounds (the ``limit`` strongest, then a count of the rest)."""
    lines = []
    for e in entries[:limit]:
        where = ("the whole cycle" if e["t_start_s"] is None else f"t = {e['t_start_s']:.1f} s" if e["t_start_s"] == e["t_end_s"]
                 else f"t = {e['t_start_s']:.1f}..{e['t_end_s']:.1f} s")
        gain = f", {e['gain_W_per_unit']:+.3g} W per unit relaxed" if "gain_W_per_unit" in e else ""
        lines.append(f"    {e['constraint']} ({e['side']}) in {e['phase']}, {where}, {e['points']} point(s): "
                     f"multiplier {e['multiplier']:.3g}{gain}")
    if len(entries) > limit:
        lines.append(f"    ... and {len(entries) - limit} more (the JSON lists all)")
    return lines


#: the bounds of the winch's drive: the reel-in rows (the motor's voltage at full duty, against
#: the line's tension) and the reel-in speed's variable bound, both per m/s of reel-in speed
DRIVE_BOUNDS = ("reel_in", "v_reel")


def drive_gain(entries: list[dict[str, Any]]) -> float:
    """The average power [W] the optimum would gain per m/s of faster reel-in the drive allowed:
    the sum of ``gain_W_per_unit`` over the binding :data:`DRIVE_BOUNDS` (0 where the drive does
    not bind)."""
    return float(sum(e.get("gain_W_per_unit", 0.0) for e in entries if e["constraint"] in DRIVE_BOUNDS))


def binding_names(entries: list[dict[str, Any]]) -> str:
    """The binding bounds in a few words, strongest first, each once: ``constraint side
    phase`` joined by ``"; "`` (empty where nothing binds)."""
    seen: dict[tuple[str, str, str], None] = {}
    for e in entries:
        seen.setdefault((e["constraint"], e["side"], e["phase"]), None)
    return "; ".join(" ".join(k) for k in seen)
