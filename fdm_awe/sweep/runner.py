"""Solve one sweep point: build its glider variant and problem, run the cycle optimiser.

:func:`run_point` is what a Dask worker executes. It takes the point and the output of the
previous point of its warm-start chain (or a :class:`Warm` loaded from disk, or ``None``) and
returns ``(record, warm_for_next)``: the point's record (a flat JSON-ready dict, see
:data:`RECORD_FIELDS`) and the warm start the next point should use (this point's solution
if it succeeded, otherwise the one it was given). It never raises: an exception inside the
optimiser becomes a ``failed`` record carrying the exception text as its reason.

The cold check (``Point.cold_check``, warm-started points only) adds to the record: ``kept``
(``warm`` or ``cold``), ``P_warm_W`` and ``P_cold_W`` (each solution's power [W], None when
it failed), ``cold_family`` (the start family that won the cold solve). ``family`` is the
start family of the kept solution: the global strategy's winner for a cold solve, and for a
warm start the family its chain's solution came from (passed along in :class:`Warm`).
"""

from __future__ import annotations

import functools
import math
import os
import re
import socket
import time
import traceback
from dataclasses import dataclass
from typing import Any

from .. import defaults as D

import numpy as np

from .design import Design, describe, describe_line, design_glider, line_station
from .spec import Point

#: columns of a point record, in table order
RECORD_FIELDS = (
    "id", "scenario", "config", "wind_mps", "d0_m", "d_tf_m", "folded_span_m", "folded_drag_area_m2", "wing_area_m2",
    "fold_time_s", "mesh", "max_iter", "max_iter_total", "warm_fallback", "propeller", "line_weight", "line",
    "line_diameter_m", "status", "reason", "P_avg_W", "E_net_J", "E_generated_J", "E_thrust_J", "E_reel_in_J",
    "T1_s", "T2_s", "iterations", "solve_s", "build_s", "wall_s", "cpu_s", "worker", "warm_from", "start", "max_violation",
    "S_u_m2", "b_u_m", "chord_m", "S_f_m2", "b_f_m", "AR_f", "CLalpha_f", "CD0_f", "drag_area_f_m2",
    "line_d_m", "line_mu_kg_per_m", "line_breaking_load_N",
    "cold_check", "kept", "P_warm_W", "P_cold_W", "family", "cold_family", "wind_profile",
    "tension_margin", "stall_margin", "line_model", "bounds", "supply_voltage_V", "drive_gain_W_per_mps", "binding",
)

#: |warm - cold| [W] above which a point's two solutions count as different in the summary
#: (the optimiser's :data:`fdm_awe.ocp.strategy.COLD_CHECK_W`)
COLD_CHECK_TOLERANCE_W = 0.5


@dataclass
class Warm:
    """What a warm start needs from a solved point (scaled NLP vector, multipliers, heading wrap)."""

    point_id: str
    w: np.ndarray
    lam_x: np.ndarray
    lam_g: np.ndarray
    k_wrap: int
    family: str | None = None  #: start family of the solution (e.g. ``loop +1/-1``; None: unknown)

    def as_result(self, problem: Any) -> Any:
        """A minimal ``CycleResult`` accepted by ``solve_cycle(warm=...)`` for ``problem``."""
        from ..ocp.result import CycleResult
        from ..ocp.build import structure_key

        return CycleResult(problem.scenario, problem.config, problem.wind_speed, problem.wind_from_deg, "ok", "warm",
                           0.0, 0.0, 0, k_wrap=self.k_wrap, w=self.w, lam_x=self.lam_x, lam_g=self.lam_g,
                           key=structure_key(problem))


@dataclass
class FailedUpstream:
    """The previous point of the chain failed (read back from disk on a resumed sweep): the
    warm start it passes on (its own input, possibly ``None``) and the fact that it failed."""

    warm: Warm | None


def upstream_input(upstream: Any) -> tuple[Warm | None, bool]:
    """``(warm start, previous point failed)`` from what :func:`run_point` receives: the previous
    task's ``(record, warm)``, a :class:`Warm` or :class:`FailedUpstream` from disk, or ``None``."""
    if isinstance(upstream, tuple):
        return upstream[1], upstream[0].get("status") != "ok"
    if isinstance(upstream, FailedUpstream):
        return upstream.warm, True
    return upstream, False


@functools.lru_cache(maxsize=4)
def point_aircraft(aircraft: str | None = None) -> Any:
    """The :class:`~fdm_awe.definitions.catalog.Aircraft` of a point's or spec's ``aircraft``
    (None: the package's glider), resolved once per process."""
    from ..definitions.catalog import resolve_aircraft

    return resolve_aircraft(aircraft, "--aircraft")


@functools.lru_cache(maxsize=4)
def point_ground_station(ground_station: str | None = None) -> Any:
    """The :class:`~fdm_awe.groundstation.source.StationFile` of a point's or spec's
    ``ground_station`` (None: the package's), resolved once per process."""
    from ..groundstation.source import resolve_ground_station

    return resolve_ground_station(ground_station, "--ground-station")


@functools.lru_cache(maxsize=4)
def base_glider(aircraft: str | None = None) -> Any:
    """The definitions' own glider of ``aircraft`` (:func:`point_aircraft`)."""
    from ..definitions.aircraft import load_glider

    return load_glider(point_aircraft(aircraft))


def canonical_spec(spec: Any) -> Any:
    """``spec`` with design values equal to the definitions' replaced by ``None`` (so they share
    point ids and the optimiser's cached NLP with the unchanged glider and line)."""
    from dataclasses import replace

    g = base_glider(spec.aircraft)
    f, u = g.folded.aero, g.unfolded.aero
    from .design import polar_constants

    area_f = polar_constants(f).CD_min * f.S

    def same(v: Any, ref: float) -> Any:
        return None if v is not None and abs(v - ref) <= 1e-9 * max(1.0, abs(ref)) else v

    station = point_ground_station(spec.ground_station)
    d_sized = line_station("sized", station=station).tether.diameter
    out = replace(spec, folded_spans=tuple(dict.fromkeys(same(v, f.b) for v in spec.folded_spans)),
                  folded_drag_areas=tuple(dict.fromkeys(same(v, area_f) for v in spec.folded_drag_areas)),
                  wing_areas=tuple(dict.fromkeys(same(v, u.S) for v in spec.wing_areas)),
                  line_diameters=tuple(dict.fromkeys(same(v, d_sized) for v in spec.line_diameters)))
    for d in out.line_diameters:  # a diameter the sized line cannot have (breaks below its rating): refused now
        if d is not None and "sized" in out.line_names():
            line_station("sized", d, station)
    # refuse impossible designs now (InputError naming the value), not point by point later
    for S in out.wing_areas:
        for b in out.folded_spans if "foldable" in out.configs else (None,):
            for a in out.folded_drag_areas if "foldable" in out.configs else (None,):
                Design(b, a, S).validate(g)
    return out


def point_design(point: Point) -> Design:
    return Design(point.folded_span if point.config == "foldable" else None,
                  point.folded_drag_area if point.config == "foldable" else None, point.wing_area)


def point_glider(point: Point) -> Any:
    """The glider variant of ``point`` (the definitions' own glider when nothing changes)."""
    return design_glider(base_glider(point.aircraft), point_design(point))


#: the margins of a ``flyable`` point where the sweep gives none: ``fdm-awe fly``'s defaults
#: (``FLY_TENSION_MARGIN``, ``FLY_STALL_MARGIN`` of :mod:`fdm_awe.commands._fly_optimise`; a test holds them equal)
FLYABLE_TENSION_MARGIN = D.FLYABLE_TENSION_MARGIN
FLYABLE_STALL_MARGIN = D.FLYABLE_STALL_MARGIN


def flyable_bounds(tension_margin: float = FLYABLE_TENSION_MARGIN, stall_margin: float = FLYABLE_STALL_MARGIN) -> Any:
    """The :class:`~fdm_awe.ocp.problem.Bounds` of a ``flyable`` point: those ``fdm-awe fly``
    optimises a reference with (|bank| at most 0.8 rad, C_L at most (1 - ``stall_margin``)
    C_Lmax, the tension at most the rating / (1 + ``tension_margin``); at the defaults
    ``fdm_awe.commands._fly_optimise.flyable_bounds()``, a higher layer; a test holds them equal)."""
    from ..ocp.problem import Bounds

    return Bounds(cl_margin=1.0 - stall_margin, phi_max=0.8, tension_margin=tension_margin)


def point_problem(point: Point) -> Any:
    """The :class:`~fdm_awe.ocp.problem.CycleProblem` of ``point`` (a resized line's numbers are
    in :func:`point_winch`, not in the problem)."""
    from ..ocp.problem import Bounds, CycleProblem, Mesh
    from ..wind import WindProfile

    n_gen, n_rec, deg = point.mesh
    margins = {} if not (point.tension_margin or point.stall_margin) else {
        "bounds": Bounds(tension_margin=point.tension_margin, cl_margin=1.0 - point.stall_margin)}
    if point.bounds == "flyable":  # the bounds fdm-awe fly optimises a reference to fly with
        margins["bounds"] = flyable_bounds(point.tension_margin, point.stall_margin)
    # a point's propeller None is momentum theory in the physical scenario (the model before the choice)
    prop = point.propeller or ("momentum" if point.scenario == "physical" else None)
    return CycleProblem(scenario=point.scenario, config=point.config, wind_speed=point.wind, d0=point.d0,
                        d_tf=point.d_tf, mesh=Mesh(n_gen=n_gen, n_rec=n_rec, degree=deg), propeller=prop,
                        line_weight=point.line_weight, line=point.line,
                        fold_time=point.fold_time if point.config == "foldable" else None,
                        wind_profile=WindProfile.parse(point.wind_profile, option="point wind profile"),
                        line_model=point.line_model, aircraft=point_aircraft(point.aircraft),
                        ground_station=point_ground_station(point.ground_station), **margins)


@functools.lru_cache(maxsize=16)
def point_station(line: str, diameter: float | None, ground_station: str | None = None) -> Any:
    """Ground-station parameters of a point's tether line in the definition ``ground_station``
    (None: the package's; :func:`~.design.line_station`)."""
    return line_station(line, diameter, point_ground_station(ground_station))


def point_winch(point: Point) -> Any:
    """The :class:`~fdm_awe.ocp.energy.WinchElectrics` of ``point`` when its line is resized
    (``line_diameter``), else None (the optimiser loads the problem's line itself)."""
    if point.line_diameter is None:
        return None
    from ..ocp.energy import WinchElectrics

    return WinchElectrics.from_ground_station(point_station(point.line, point.line_diameter, point.ground_station))


def base_record(point: Point) -> dict[str, Any]:
    """The parameter part of a record (no results yet)."""
    rec: dict[str, Any] = {k: None for k in RECORD_FIELDS}
    rec.update({"id": point.id, "scenario": point.scenario, "config": point.config, "wind_mps": point.wind,
                "d0_m": point.d0, "d_tf_m": point.d_tf, "folded_span_m": point.folded_span,
                "folded_drag_area_m2": point.folded_drag_area, "wing_area_m2": point.wing_area,
                "fold_time_s": point.fold_time, "mesh": "x".join(str(v) for v in point.mesh),
                "max_iter": point.max_iter, "max_iter_total": point.max_iter_total,
                "warm_fallback": point.warm_fallback,
                "propeller": point.propeller or ("momentum" if point.scenario == "physical" else "paper"),
                "line_weight": point.line_weight, "line": point.line, "line_diameter_m": point.line_diameter,
                "wind_profile": point.wind_profile, "tension_margin": point.tension_margin,
                "stall_margin": point.stall_margin, "line_model": point.line_model, "bounds": point.bounds})
    return rec


def _num(v: Any) -> float | None:
    return None if v is None or not math.isfinite(float(v)) else float(v)


def _winner_family(strategy: dict[str, Any] | None) -> str | None:
    """The start family that won a global-strategy solve (None: not a global solve)."""
    win = (strategy or {}).get("winner")
    return win.get("family") if isinstance(win, dict) else None


def _label_family(start: Any) -> str | None:
    """The start family named in a start's label (``loops ... turns=+1/-1`` -> ``loop +1/-1``;
    a solve that was not the global strategy's records only the label)."""
    m = re.search(r"\b(loop|eight)s\b.*?\bturns=([+-]\d)/([+-]\d)", str(start or ""))
    return f"{m.group(1)} {m.group(2)}/{m.group(3)}" if m else None


def _family_fields(res: Any, warm_in: Warm | None, cold_check: bool) -> dict[str, Any]:
    """The cold-check and start-family fields of a point's record from its ``CycleResult``."""
    st = res.strategy or {}
    out: dict[str, Any] = {"cold_check": bool(cold_check)}
    chk = st.get("cold_check")
    if isinstance(chk, dict):
        out["kept"] = chk.get("kept")
        out["P_warm_W"] = _num(chk.get("warm_P_avg_W"))
        out["P_cold_W"] = _num(chk.get("cold_P_avg_W"))
        cold_st = st if chk.get("kept") == "cold" else None
        out["cold_family"] = _winner_family(cold_st) if cold_st is not None else None
    if not res.ok:
        return out
    own = _winner_family(st) or _label_family(res.start)
    if own is not None:  # a cold global solve (an anchor, a cold point, or the cold check's winner)
        out["family"] = own
    elif warm_in is not None and str(res.start or "").startswith(("warm start", "from a previous solution")):
        out["family"] = warm_in.family  # the chain's solution, carried on
    if out.get("kept") == "cold":
        out["cold_family"] = out.get("family")
    return out


def run_point(point: Point, upstream: Any = None) -> tuple[dict[str, Any], Warm | None]:
    """Solve ``point`` warm-started from ``upstream`` (see the module docstring)."""
    t0 = time.perf_counter()
    c0 = time.process_time()
    warm_in, upstream_failed = upstream_input(upstream)
    rec = base_record(point)
    try:
        glider = point_glider(point)
        rec.update(describe(glider))
        station = point_station(point.line, point.line_diameter, point.ground_station)
        rec.update(describe_line(station.tether))
        rec["supply_voltage_V"] = float(station.converter.supply_voltage)  # the drive (docs/folding_map.md)
        if point.config == "nominal":  # the folded wing plays no part
            for k in ("S_f_m2", "b_f_m", "AR_f", "CLalpha_f", "CD0_f", "drag_area_f_m2"):
                rec[k] = None
        from ..ocp.solve import solve_cycle

        problem = point_problem(point)
        warm = warm_in.as_result(problem) if warm_in is not None else None
        custom = glider is not base_glider(point.aircraft)
        # the iteration limit decides failures; the CPU-time limit is lifted so that a busy
        # machine cannot change a result
        opts = {"ipopt.max_iter": int(point.max_iter), "ipopt.max_cpu_time": 1e6}
        # after a failed neighbour that leaves no warm start, a cheap failure policy
        # (warm_fallback one / none) also bounds this point's cold search: one cold solve
        cold = "one" if upstream_failed and warm is None and point.warm_fallback != "all" else "all"
        check = bool(point.cold_check) and warm is not None
        # with the cold check the cold global-strategy solve is the fallback of a failed warm start
        res = solve_cycle(problem, warm=warm, glider=glider if custom else None, winch=point_winch(point), ipopt_options=opts,
                          max_iter_total=int(point.max_iter_total), warm_fallback="none" if check else point.warm_fallback,
                          cold=cold, cold_check=check)
        rec.update(_family_fields(res, warm_in, point.cold_check))
        s = res.summary()
        rec.update({"status": "ok" if res.ok else "failed", "reason": str(res.reason), "iterations": int(res.iterations),
                    "solve_s": _num(res.solve_s), "build_s": _num(res.build_s), "start": res.start or None,
                    "max_violation": _num(res.max_violation), "warm_from": warm_in.point_id if warm_in else None})
        for k in ("P_avg_W", "E_net_J", "E_generated_J", "E_thrust_J", "E_reel_in_J", "T1_s", "T2_s"):
            rec[k] = _num(s.get(k)) if res.ok else None
        if res.ok:  # what binds the optimum (fdm_awe.ocp.active): the drive's gain per m/s and every bound
            from ..ocp.active import binding_names, drive_gain

            rec["drive_gain_W_per_mps"] = _num(drive_gain(res.active_bounds))
            rec["binding"] = binding_names(res.active_bounds) or None
        if res.ok and res.w is not None:
            warm_out: Warm | None = Warm(point.id, np.asarray(res.w, float), np.asarray(res.lam_x, float),
                                         np.asarray(res.lam_g, float), int(res.k_wrap), rec.get("family"))
        else:
            warm_out = warm_in
    except Exception as exc:  # a failed point is a result: record why
        tb = traceback.extract_tb(exc.__traceback__)
        where = f" at {tb[-1].filename.rsplit('/', 1)[-1]}:{tb[-1].lineno}" if tb else ""
        rec.update({"status": "failed", "reason": f"{type(exc).__name__}: {exc}{where}".splitlines()[0],
                    "warm_from": warm_in.point_id if warm_in else None})
        warm_out = warm_in
    rec["wall_s"] = round(time.perf_counter() - t0, 4)
    rec["cpu_s"] = round(time.process_time() - c0, 4)  # CPU time of the worker process for this point
    rec["worker"] = f"{socket.gethostname()}:{os.getpid()}"  # which worker process solved it
    return rec, warm_out
