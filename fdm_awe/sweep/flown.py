"""Flown sweep points: every optimised cycle flown in 6-DOF by the autopilot (``sweep --fly``).

A *flight* is one optimised point flown for ``cycles`` pumping cycles in one air condition
(:class:`FlySpec`: ``calm``, or a ``fly --turbulence`` form without its seed, ``light``,
``moderate``, ``iec:A`` ...) with one turbulence seed, on the straight or a lumped line. The
flown reference is the point's own optimised cycle, rebuilt from its stored solution vector
(:func:`point_reference`: the same columns the optimiser would write, bit for bit), so a flight
is deterministic given the point, the air, the seed and the line: its result does not depend
on the worker that flies it or on how many there are. Calm air is flown once (a seed changes
nothing there).

Each flight is one Dask task; its record is written at once to ``OUT/flights/<id>.json``
(:class:`FlightStore`, atomically), so an interrupted ``--fly`` resumes with the missing
flights only. A flight id is a hash of the point id, the air, the seed, the cycle count and
the line model.

Per flight (:func:`run_flight`): status and message, per cycle its net energy [J], duration [s],
net power [W] = net energy / duration, tracking RMS [m] and whether it was complete; peak line
tension [N] and peak armature current [A] with the ratings (line's rated tension, machine's
rated current). Per point (:func:`flown_point`): flown net power per complete cycle (mean,
standard deviation, min, max, count), the mean of each flight's cycles and its standard error
over the flights (seeds are independent; cycles of one flight are not), the completion fraction
(complete cycles over those asked for), the park fraction (flights that ended parked), the
largest peak tension and current against the ratings and the mean tracking RMS.

Only points of the definitions' airframe and line are flown (the 6-DOF model is the aircraft
definition's JSBSim model: a resized wing, folded wing or line exists only in the optimiser);
other points are listed as not flown.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import socket
import sys
import time
import traceback
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

import numpy as np

from ..errors import InputError
from ..fileio import write_json
from .runner import Warm, point_aircraft, point_glider, point_ground_station, point_problem, point_winch, base_glider
from .spec import Point

#: allowed cycles per flight and seeds per air condition
FLY_CYCLES_RANGE = (1, 20)
FLY_SEEDS_RANGE = (1, 100)


@dataclass(frozen=True)
class FlySpec:
    """How every point is flown: ``air`` (``calm`` or a turbulence form without its seed),
    ``seeds`` (1..N; calm air is flown once), ``cycles`` per flight, ``tether`` line model
    (a ``--tether`` form of :data:`fdm_awe.groundstation.linemodels.LINE_MODELS`)."""

    air: str = "light"
    seeds: int = 5
    cycles: int = 3
    tether: str = "straight"

    def validate(self) -> "FlySpec":
        """One-line errors naming the option."""
        lo, hi = FLY_CYCLES_RANGE
        if not (isinstance(self.cycles, int) and lo <= self.cycles <= hi):
            raise InputError(f"--fly-cycles {self.cycles!r}: out of range (allowed integer {lo}..{hi})")
        lo, hi = FLY_SEEDS_RANGE
        if not (isinstance(self.seeds, int) and lo <= self.seeds <= hi):
            raise InputError(f"--fly-seeds {self.seeds!r}: out of range (allowed integer {lo}..{hi})")
        if self.air != "calm":
            from ..turbulence import Turbulence

            if ":" in self.air and self.air.split(":")[0] in ("light", "moderate", "severe"):
                raise InputError(f"--fly-air {self.air!r}: give the form without a seed (the seeds are 1..--fly-seeds)")
            Turbulence.parse(f"{self.air}:1", "--fly-air")
        from ..groundstation.linemodels import parse_tether

        parse_tether(self.tether, "--fly-tether")
        return self

    def seed_list(self) -> list[int | None]:
        """The seeds flown: ``[None]`` in calm air, else 1..``seeds``."""
        return [None] if self.air == "calm" else list(range(1, self.seeds + 1))

    def as_dict(self) -> dict[str, Any]:
        return {"air": self.air, "seeds": self.seeds, "cycles": self.cycles, "tether": self.tether}


def flyable_point(point: Point) -> str | None:
    """Why ``point`` is not flown (None: it is): the 6-DOF model is the definitions' airframe
    and line."""
    if point.folded_span is not None or point.folded_drag_area is not None or point.wing_area is not None:
        return "a glider design other than the definition's (the 6-DOF model is the definition's airframe)"
    if point.line_diameter is not None:
        return "a resized line (the ground station flies the defined line)"
    return None


def flight_id(point_id: str, air: str, seed: int | None, cycles: int, tether: str) -> str:
    """Stable id of one flight (16 hex digits of a SHA-1)."""
    doc = json.dumps({"point": point_id, "air": air, "seed": seed, "cycles": cycles, "tether": tether},
                     sort_keys=True, separators=(",", ":"))
    return hashlib.sha1(doc.encode()).hexdigest()[:16]


def point_result(point: Point, warm: Warm) -> Any:
    """The :class:`~fdm_awe.ocp.result.CycleResult` of ``point`` rebuilt from its stored
    solution ``warm`` (no solve: the NLP's own unpacking of the vector, as after the solve)."""
    from ..ocp.assemble import ok_result
    from ..ocp.build import get_nlp
    from ..ocp.collocation import RawSolution
    from ..pointmass.model import wind_vector

    problem = point_problem(point).validate()
    glider = point_glider(point)
    nlp, _ = get_nlp(problem, None if glider is base_glider(point.aircraft) else glider, point_winch(point))
    params = nlp.params(wind_vector(problem.wind_speed, problem.wind_from_deg)[:2], 1.0, warm.k_wrap, 1.0, 0.0)
    raw = RawSolution("ok", "stored solution", 0, 0.0, warm.w, warm.lam_x, warm.lam_g, 0.0, params)
    return ok_result(problem, nlp, warm.k_wrap, "stored solution", raw, 0.0, 0.0, 0)


def point_reference(point: Point, warm: Warm) -> Any:
    """The :class:`~fdm_awe.autopilot.tracking.TrackingReference` the autopilot flies for
    ``point`` (its optimised cycle, through the reference file's checks, in memory)."""
    from ..autopilot.tracking import TrackingReference
    from ..trajectory.files import reference_from_result

    return TrackingReference.from_ocp(reference_from_result(point_result(point, warm), f"sweep point {point.id}"))


def _ratings(line: str, ground_station: str | None = None) -> tuple[float | None, float | None]:
    """Rated line tension [N] and rated armature current [A] of the ground station (the
    definition file ``ground_station``; None: the package's)."""
    try:
        from .design import line_station

        st = line_station(line, station=point_ground_station(ground_station))
        rated_T = getattr(st.tether, "rated_tension", None)
        if rated_T is None:
            sizing = getattr(st.tether, "sizing", None)
            rated_T = getattr(sizing, "rated_tension", None)
        machine = getattr(st, "machine", None)
        rated_I = getattr(machine, "rated_current", None)
        return (None if rated_T is None else float(rated_T)), (None if rated_I is None else float(rated_I))
    except Exception:  # a rating the definition does not state
        return None, None


def run_flight(point: Point, warm: Warm, air: str, seed: int | None, cycles: int, tether: str) -> dict[str, Any]:
    """Fly ``point`` (its stored solution ``warm``) once; the flight's record (see the module
    docstring). Never raises: an exception becomes a record with status ``error`` and its text."""
    t0 = time.perf_counter()
    rec: dict[str, Any] = {"id": flight_id(point.id, air, seed, cycles, tether), "point_id": point.id,
                           "config": point.config, "wind_mps": point.wind, "air": air, "seed": seed, "cycles": cycles,
                           "tether": tether}
    try:
        from ..sim.flight import fly
        from ..turbulence import Turbulence

        ref = point_reference(point, warm)
        turb = None if air == "calm" else Turbulence.parse(f"{air}:{seed}", "--fly-air")
        rep = fly(ref, config=point.config, cycles=cycles, turbulence=turb,
                  plant="paper" if point.scenario == "paper" else "physical", tether=tether,
                  aircraft=point_aircraft(point.aircraft), ground_station=point_ground_station(point.ground_station))
        cyc = []
        for c in rep.cycles:
            T = float(c.T1_s + c.T2_s)
            cyc.append({"complete": bool(c.complete), "E_net_J": _num(c.E_net_J), "T_s": _num(T),
                        "P_W": _num(c.E_net_J / T) if T > 0 else None, "track_rms_m": _num(c.track_rms_m)})
        tension = np.asarray(rep.result.tension, float) if rep.result is not None else np.zeros(0)
        rated_T, rated_I = _ratings(point.line, point.ground_station)
        rec.update({"status": rep.status, "message": str(rep.message).splitlines()[0] if rep.message else "",
                    "cycle_list": cyc, "peak_tension_N": _num(np.nanmax(tension)) if tension.size else None,
                    "peak_current_A": _num(rep.peak_current_A), "rated_tension_N": rated_T, "rated_current_A": rated_I,
                    "sim_s": _num(rep.sim_time_s)})
    except Exception as exc:  # a flight that could not run is a result: record why
        tb = traceback.extract_tb(exc.__traceback__)
        where = f" at {tb[-1].filename.rsplit('/', 1)[-1]}:{tb[-1].lineno}" if tb else ""
        rec.update({"status": "error", "message": f"{type(exc).__name__}: {exc}{where}".splitlines()[0], "cycle_list": []})
    rec["wall_s"] = round(time.perf_counter() - t0, 4)
    rec["worker"] = f"{socket.gethostname()}:{os.getpid()}"
    return rec


def _num(v: Any) -> float | None:
    return None if v is None or not math.isfinite(float(v)) else float(v)


class FlightStore:
    """The ``flights/`` folder of a sweep output directory: one JSON record per flight. A file
    that is not a usable record of its flight counts as absent (one warning line names it)."""

    def __init__(self, out_dir: str | Path) -> None:
        self.dir = Path(out_dir) / "flights"
        try:
            self.dir.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise InputError(f"output folder {out_dir}: cannot create flights/ ({exc.strerror})") from None

    def path(self, fid: str) -> Path:
        return self.dir / f"{fid}.json"

    def load(self, fid: str) -> dict[str, Any] | None:
        p = self.path(fid)
        try:
            rec = json.loads(p.read_text(encoding="utf-8"))
        except FileNotFoundError:
            return None
        except (OSError, ValueError, RecursionError) as exc:
            print(f"warning: {p}: not a readable flight record ({type(exc).__name__}); the flight is flown again",
                  file=sys.stderr)
            return None
        if not isinstance(rec, dict) or rec.get("id") != fid or not isinstance(rec.get("cycle_list"), list):
            print(f"warning: {p}: not a record of flight {fid}; the flight is flown again", file=sys.stderr)
            return None
        return rec

    def write(self, rec: dict[str, Any]) -> None:
        write_json(self.path(rec["id"]), rec, indent=1)


@dataclass
class FlightTask:
    """One flight to fly: its point, air, seed and id."""

    point: Point
    air: str
    seed: int | None
    id: str


def flight_tasks(points: list[Point], records: dict[str, dict[str, Any]], fly: FlySpec) -> tuple[list[FlightTask], list[tuple[Point, str]]]:
    """The flights of the ``ok`` points among ``points`` (every seed), and the points not flown
    with the reason."""
    tasks, skipped = [], []
    for p in points:
        rec = records.get(p.id)
        if rec is None:
            skipped.append((p, "not optimised"))
            continue
        if rec.get("status") != "ok":
            skipped.append((p, "its optimisation failed"))
            continue
        why = flyable_point(p)
        if why is not None:
            skipped.append((p, why))
            continue
        for s in fly.seed_list():
            tasks.append(FlightTask(p, fly.air, s, flight_id(p.id, fly.air, s, fly.cycles, fly.tether)))
    return tasks, skipped


@dataclass
class FlyRun:
    """What a ``--fly`` run did."""

    n_flights: int
    n_cached: int
    n_flown: int = 0
    errors: list[tuple[str, str]] | None = None
    records: dict[str, dict[str, Any]] | None = None  #: flight id -> record
    skipped: list[tuple[Point, str]] | None = None
    wall_s: float = 0.0
    stopped: bool = False

    @property
    def complete(self) -> bool:
        return self.records is not None and len(self.records) == self.n_flights


def run_flights(points: list[Point], records: dict[str, dict[str, Any]], out_dir: str | Path, fly: FlySpec, *,
                workers: int | None = None, scheduler: str | None = None, progress: bool = True,
                stop_after: int | None = None, on_flight: Callable[[dict[str, Any]], None] | None = None) -> FlyRun:
    """Fly the missing flights of the ``ok`` points (records by point id) on Dask; each record
    written as its task finishes. ``stop_after``: stop after this many new flights (as an
    interruption would)."""
    from .store import PointStore

    fly.validate()
    tasks, skipped = flight_tasks(points, records, fly)
    store = FlightStore(out_dir)
    done = {t.id: r for t in tasks if (r := store.load(t.id)) is not None}
    run = FlyRun(n_flights=len(tasks), n_cached=len(done), errors=[], skipped=skipped)
    pending = [t for t in tasks if t.id not in done]
    if pending:
        from tqdm import tqdm

        from .execute import sigint_ignored, start_client

        pstore = PointStore(out_dir)
        warms: dict[str, Warm] = {}
        for t in pending:
            if t.point.id not in warms:
                w = pstore.load_warm(t.point.id)
                if w is None:
                    raise InputError(f"--out {out_dir}: point {t.point.label()} has no stored solution "
                                     f"(points/{t.point.id}.warm.npz); rerun with --retry-failed or without --fly first")
                warms[t.point.id] = w
        client, cluster, _n = start_client(workers, scheduler)
        t1 = time.perf_counter()
        try:
            from dask.distributed import as_completed

            futs, futures = {}, []
            for t in pending:
                f = client.submit(run_flight, t.point, warms[t.point.id], t.air, t.seed, fly.cycles, fly.tether,
                                  key=f"sweep-flight-{t.id}", pure=False, retries=0)
                futs[f.key] = t
                futures.append(f)
            bar = tqdm(total=len(pending), unit="flight", desc="fly", file=sys.stderr, disable=not progress,
                       dynamic_ncols=True)
            try:
                for fut in as_completed(futures):
                    t = futs[fut.key]
                    try:
                        rec = fut.result()
                    except Exception as exc:  # the task did not run (worker lost, cancelled)
                        run.errors.append((f"{t.point.label()} air={t.air} seed={t.seed}",
                                           f"{type(exc).__name__}: {exc}".splitlines()[0]))
                        bar.update(1)
                        continue
                    store.write(rec)
                    done[t.id] = rec
                    run.n_flown += 1
                    bar.update(1)
                    if on_flight is not None:
                        on_flight(rec)
                    if stop_after is not None and run.n_flown >= stop_after and len(done) < len(tasks):
                        run.stopped = True
                        client.cancel([f for f in futures if not f.done()])
                        break
            finally:
                bar.close()
        finally:
            with sigint_ignored():
                client.close()
                if cluster is not None:
                    cluster.close()
        run.wall_s = time.perf_counter() - t1
    run.records = {t.id: done[t.id] for t in tasks if t.id in done}
    return run


def flown_point(flights: list[dict[str, Any]], cycles: int) -> dict[str, Any]:
    """The flown numbers of one point from its flights' records (see the module docstring).
    Powers [W], tension [N], current [A], tracking [m]; NaN-free (None where undefined)."""
    n = len(flights)
    P = [c["P_W"] for f in flights for c in f["cycle_list"] if c.get("complete") and c.get("P_W") is not None]
    per_flight = [float(np.mean(q)) for f in flights
                  if (q := [c["P_W"] for c in f["cycle_list"] if c.get("complete") and c.get("P_W") is not None])]
    rms = [c["track_rms_m"] for f in flights for c in f["cycle_list"]
           if c.get("complete") and c.get("track_rms_m") is not None]
    peaks_T = [f["peak_tension_N"] for f in flights if f.get("peak_tension_N") is not None]
    peaks_I = [f["peak_current_A"] for f in flights if f.get("peak_current_A") is not None]
    rated_T = next((f.get("rated_tension_N") for f in flights if f.get("rated_tension_N") is not None), None)
    rated_I = next((f.get("rated_current_A") for f in flights if f.get("rated_current_A") is not None), None)
    out: dict[str, Any] = {
        "flights": n, "cycles_asked": n * cycles, "cycles_complete": len(P),
        "completion": (len(P) / (n * cycles)) if n else None,
        "park_fraction": (sum(f.get("status") == "parked" for f in flights) / n) if n else None,
        "P_flown_mean_W": float(np.mean(P)) if P else None,
        "P_flown_std_W": float(np.std(P, ddof=1)) if len(P) > 1 else None,
        "P_flown_min_W": float(np.min(P)) if P else None, "P_flown_max_W": float(np.max(P)) if P else None,
        "P_flight_mean_W": float(np.mean(per_flight)) if per_flight else None,
        "P_flight_se_W": float(np.std(per_flight, ddof=1) / math.sqrt(len(per_flight))) if len(per_flight) > 1 else None,
        "n_flights_with_cycles": len(per_flight),
        "track_rms_m": float(np.mean(rms)) if rms else None,
        "peak_tension_N": float(max(peaks_T)) if peaks_T else None, "rated_tension_N": rated_T,
        "peak_current_A": float(max(peaks_I)) if peaks_I else None, "rated_current_A": rated_I,
        "statuses": ",".join(sorted({str(f.get("status")) for f in flights})),
    }
    return out
