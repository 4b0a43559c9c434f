"""What a sweep is: its axes, its points, and how points chain for warm starts.

A :class:`SweepSpec` holds the axes (SI units):

- ``winds`` [m/s], the power-curve axis;
- ``configs``: ``nominal`` (the wing stays unfolded) and/or ``foldable`` (folds for recovery);
- ``folded_spans`` [m], ``folded_drag_areas`` [m^2] (foldable points only; ``None`` = the
  folded definition's value);
- ``wing_areas`` [m^2] (``None`` = the definition's);
- ``tether_ranges``: reel-out range ``(d0, d_tf)`` [m];
- ``fold_times`` [s]: how long the foldable glider takes to fold (and to unfold) its wing
  (:attr:`fdm_awe.ocp.problem.CycleProblem.fold_time`); ``None`` = the aircraft definition's
  (``fcs/wing-fold-time-s``, resolved to its number so the point's id and record name it),
  ``0`` = the instantaneous switch of sweeps made before fold transitions existed (their ids are
  unchanged). Nominal points never fold: their fold time is 0;
- ``lines``: tether lines of the ground-station definition by name (not the warm-start *lines*
  below; :data:`fdm_awe.groundstation.line.LINES`; ``None`` = the scenario's default line,
  :data:`fdm_awe.ocp.problem.PLANT_DEFAULTS`);
- ``line_diameters`` [m]: the ``sized`` line resized to these diameters (``None`` = as sized in
  the definition). The material stays, so the section scales as the sizing function
  (:func:`fdm_awe.groundstation.line.size_line`) scales it: mass per length, breaking load and
  EA all in proportion to ``d^2`` (:func:`fdm_awe.sweep.design.resized_line`). Points on Table
  1's ``paper`` line (a stated section, no material) are not repeated over this axis; a
  diameter whose breaking load falls below the rated tension is refused;
- ``scenario`` (``physical`` default, ``paper``), the collocation ``mesh``;
- the plant model of every point: ``propeller`` and ``line_weight`` (``None`` = the scenario's
  default: in ``physical`` the glider's own drive and the line's weight on the glider);
- the per-point solver budget: ``max_iter`` IPOPT iterations per solve
  (:data:`DEFAULT_MAX_ITER`), ``max_iter_total`` over all solves of the point
  (:data:`DEFAULT_MAX_ITER_TOTAL`), and ``warm_fallback``, what follows a failed warm start
  (``all``: the whole cold strategy, default; ``one``: one cold solve from the first start;
  ``none``: the point fails at once). The cheaper fallbacks bound the cost of points that
  cannot converge, at the risk of missing a cycle only a later start finds;
- ``anchor_every``: chain layout (below);
- ``cold_check``: every warm-started point is also solved cold with the optimiser's global
  strategy and keeps the better of the two solutions (``solve_cycle(..., cold_check=True)``);
  the record holds both powers, which was kept and the winning start family. The kept
  solution is what the chain passes on, so a warm chain that sits on a worse local optimum
  than a cold solve finds is brought back to the better one at that point (no jump in the
  power curve where a cold anchor and a warm chain would disagree). After a failed warm start
  the cold solve is the fallback (``warm_fallback`` is not used then). Anchors are cold
  solves anyway. Off (``--no-cold-check``), a point has the id it had before the check
  existed.

Nominal points do not depend on the folded-wing axes, so they are not repeated over them.

Every :class:`Point` has a stable id (a hash of its parameters, the scenario and the mesh),
used as its file name: a rerun with the same (or an overlapping) sweep finds finished points.

Point ids: fields added to :class:`Point` after the first stores were written enter the id only
when they differ from their value before they existed (:data:`_ID_DEFAULTS`: momentum propeller,
no line weight, Table 1's line, its own diameter, no cold check), so a point of an earlier sweep keeps its id
and a stored sweep resumes; a point of today's physical defaults (sized line, engine, line
weight) is another problem and has another id.

Points that differ only in wind form a *line*. Each line is solved as warm-start chains: an
*anchor* starts cold, then two branches walk up and down in wind, each point warm-started from
the previous successful one. By default (``anchor_every = 0``) a line has one anchor, the wind
nearest :data:`ANCHOR_WIND`. With ``anchor_every = n`` every n-th wind of the line counted from
that one is an anchor too, and every other point joins its nearest anchor (on a tie the one
nearer the main anchor): more, shorter chains that several workers can share, but more cold
starts, which may land on other local optima than a warm start would. The chain structure
depends only on the spec, never on the number of workers, so results do not either.
"""

from __future__ import annotations

import hashlib
import json
import math
from dataclasses import asdict, dataclass, field

from ..errors import InputError
from ..groundstation.line import LINES
from ..trajectory.schema import CONFIGS, PROPELLERS, SCENARIOS
from ..ocp.problem import PLANT_DEFAULTS, Mesh

#: IPOPT iteration limit per solve in a sweep. It replaces the optimiser's CPU-time limit, so
#: whether a point converges never depends on how busy the machine is (reproducible results).
DEFAULT_MAX_ITER = 1000

#: IPOPT iterations over all solves of one point (the cycle optimiser's default)
DEFAULT_MAX_ITER_TOTAL = 3000

#: what may follow a failed warm start (see the module docstring)
WARM_FALLBACKS = ("all", "one", "none")

#: allowed ranges (inclusive) of the integer settings of a sweep
MAX_ITER_RANGE = (10, 100000)
MAX_ITER_TOTAL_RANGE = (10, 1000000)
ANCHOR_EVERY_RANGE = (0, 1000)

#: allowed wind speeds of a sweep [m/s] (the cycle optimiser's range)
WIND_RANGE = (0.0, 25.0)

#: allowed diameters of the ``--line-diameter`` axis [m] (0.01 .. 5 mm)
LINE_DIAMETER_RANGE = (1e-5, 5e-3)

#: Point fields added after the first stores were written: they enter the point id only when
#: they differ from these values (each field's meaning before it existed), so finished points
#: of earlier sweeps keep their ids
_ID_DEFAULTS = {"max_iter_total": DEFAULT_MAX_ITER_TOTAL, "warm_fallback": "all", "propeller": None,
                "line_weight": False, "line": "paper", "line_diameter": None, "cold_check": False,
                "wind_profile": "uniform", "tension_margin": 0.0, "stall_margin": 0.0, "line_model": "straight",
                "bounds": "table3", "aircraft": None, "aircraft_sha256": None, "ground_station": None,
                "ground_station_sha256": None}

#: bounds a point is optimised with: ``table3`` (the optimiser's own, Table 3) or ``flyable``
#: (``fdm-awe fly``'s: |bank| at most 0.8 rad and the point's margins, by default fly's C_L at most
#: 0.85 C_Lmax and tension at most the rating / 1.25; what ``sweep --fly`` flies)
BOUNDS = ("table3", "flyable")

#: wind speed [m/s] at which a line's cold-started anchor sits (mid-range: easy cold solves)
ANCHOR_WIND = 8.0


@dataclass(frozen=True)
class Point:
    """One sweep point: a periodic-cycle OCP. ``None`` design values = the definitions'."""

    scenario: str
    config: str
    wind: float  #: [m/s]
    d0: float  #: [m]
    d_tf: float  #: [m]
    folded_span: float | None = None  #: [m]
    folded_drag_area: float | None = None  #: [m^2]
    wing_area: float | None = None  #: [m^2]
    fold_time: float = 0.0  #: [s]
    mesh: tuple[int, int, int] = (60, 20, 4)  #: (n_gen, n_rec, degree); sweeps set it from their Mesh
    max_iter: int = DEFAULT_MAX_ITER  #: IPOPT iteration limit per solve
    max_iter_total: int = DEFAULT_MAX_ITER_TOTAL  #: IPOPT iterations over all solves of the point
    warm_fallback: str = "all"  #: after a failed warm start: all / one / none (cold solves); one/none: a single cold solve after a failed neighbour without warm start
    #: optimiser's propeller model (physical: None = momentum, the model before the choice
    #: existed, or "engine"; paper: None)
    propeller: str | None = None
    line_weight: bool = False  #: the glider carries its share of the line's weight (CycleProblem.line_weight)
    line: str = "paper"  #: tether line (CycleProblem.line; "paper", Table 1's line, before lines were named)
    line_diameter: float | None = None  #: [m] the sized line resized to this diameter (None: as defined)
    #: a warm-started point is also solved cold (the optimiser's global strategy) and keeps the
    #: better solution (False: the warm start alone, as before the cold check existed)
    cold_check: bool = False
    #: wind speed over height (:meth:`fdm_awe.wind.WindProfile.label`: ``uniform``, ``log:Z0@H``
    #: or ``power:ALPHA@H``); ``wind`` is the speed at the reference height H
    wind_profile: str = "uniform"
    #: the cycle's margins (:class:`fdm_awe.ocp.problem.Bounds`): tension bound rating / (1 +
    #: ``tension_margin``), C_L at most (1 - ``stall_margin``) C_Lmax; 0: none (as before them)
    tension_margin: float = 0.0
    stall_margin: float = 0.0
    #: the optimiser's line model (:data:`fdm_awe.groundstation.line.LINE_MODELS`)
    line_model: str = "straight"
    bounds: str = "table3"  #: :data:`BOUNDS` the cycle is optimised with
    #: the glider (``--aircraft``: a table name or a definition folder; None: the package's
    #: glider) and the content hash of its files (part of the id: a changed folder is a new point)
    aircraft: str | None = None
    aircraft_sha256: str | None = None
    #: the ground-station definition file (``--ground-station``; None: the package's) and the
    #: hash of its bytes (part of the id: a changed file is a new point)
    ground_station: str | None = None
    ground_station_sha256: str | None = None

    @property
    def id(self) -> str:
        """Stable identifier (16 hex digits of a SHA-1 of the canonical parameters)."""
        d = asdict(self)
        for k, v in _ID_DEFAULTS.items():
            if d[k] == v:
                del d[k]
        doc = json.dumps(d, sort_keys=True, separators=(",", ":"))
        return hashlib.sha1(doc.encode()).hexdigest()[:16]

    @property
    def line_key(self) -> tuple:
        """Everything but the wind: points with equal keys form one warm-start line."""
        d = asdict(self)
        d.pop("wind")
        return tuple(sorted(d.items()))

    def label(self) -> str:
        parts = [self.config, f"v={self.wind:g}"]
        if self.config == "foldable":
            parts.append(f"b_f={'def' if self.folded_span is None else f'{self.folded_span:g}'}")
            if self.folded_drag_area is not None:
                parts.append(f"CdA_f={self.folded_drag_area:g}")
        if self.wing_area is not None:
            parts.append(f"S={self.wing_area:g}")
        parts.append(f"d={self.d0:g}-{self.d_tf:g}")
        parts.append(f"line={self.line}" + ("" if self.line_diameter is None else f"@{self.line_diameter * 1e3:.3g}mm"))
        if self.wind_profile != "uniform":
            parts.append(f"wind={self.wind_profile}")
        if self.tension_margin or self.stall_margin:
            parts.append(f"margins={self.tension_margin:g}/{self.stall_margin:g}")
        if self.line_model != "straight":
            parts.append(f"line_model={self.line_model}")
        if self.bounds != "table3":
            parts.append(f"bounds={self.bounds}")
        return " ".join(parts)


@dataclass(frozen=True)
class SweepSpec:
    """The axes of a sweep (see the module docstring)."""

    winds: tuple[float, ...]
    configs: tuple[str, ...] = ("nominal", "foldable")
    folded_spans: tuple[float | None, ...] = (None,)
    folded_drag_areas: tuple[float | None, ...] = (None,)
    wing_areas: tuple[float | None, ...] = (None,)
    tether_ranges: tuple[tuple[float, float], ...] = ((200.0, 250.0),)
    fold_times: tuple[float | None, ...] = (None,)  #: [s] None: the aircraft definition's fold time
    scenario: str = "physical"
    mesh: Mesh = field(default_factory=Mesh)
    max_iter: int = DEFAULT_MAX_ITER
    max_iter_total: int = DEFAULT_MAX_ITER_TOTAL
    warm_fallback: str = "all"
    anchor_every: int = 0
    propeller: str | None = None  #: CycleProblem.propeller of every point (physical; None: the scenario's)
    line_weight: bool | None = None  #: CycleProblem.line_weight of every point (physical; None: the scenario's)
    lines: tuple[str | None, ...] = (None,)  #: tether lines (None: the scenario's default line)
    line_diameters: tuple[float | None, ...] = (None,)  #: [m] diameters of the resized sized line (None: as defined)
    #: warm-started points also solved cold, the better kept (``fdm-awe sweep`` turns it on unless
    #: ``--no-cold-check`` or ``--cold``; off here so that library callers keep their point ids)
    cold_check: bool = False
    #: wind profile of every point (:meth:`fdm_awe.wind.WindProfile.label`; ``winds`` are the
    #: speeds at its reference height)
    wind_profile: str = "uniform"
    #: every point's margins and line model (:class:`Point`)
    tension_margin: float = 0.0
    stall_margin: float = 0.0
    line_model: str = "straight"
    bounds: str = "table3"  #: :data:`BOUNDS` of every point
    #: every point's glider and the hash of its files (:class:`Point`; None: the package's glider)
    aircraft: str | None = None
    aircraft_sha256: str | None = None
    #: every point's ground-station file and the hash of its bytes (:class:`Point`; None: the package's)
    ground_station: str | None = None
    ground_station_sha256: str | None = None

    def plant(self) -> dict[str, object]:
        """The propeller and line weight of every point: the spec's, else the scenario's default."""
        d = PLANT_DEFAULTS.get(self.scenario, {})
        return {"propeller": d.get("propeller") if self.propeller is None else self.propeller,
                "line_weight": d.get("line_weight") if self.line_weight is None else self.line_weight}

    def line_names(self) -> tuple[str, ...]:
        """The lines of the sweep by name (None replaced by the scenario's default), no repeats."""
        default = PLANT_DEFAULTS.get(self.scenario, {}).get("line", "paper")
        return tuple(dict.fromkeys(default if n is None else n for n in self.lines))

    def validate(self) -> "SweepSpec":
        if self.scenario not in SCENARIOS:
            raise InputError(f"scenario {self.scenario!r} unknown (allowed: {', '.join(SCENARIOS)})")
        if not self.configs:
            raise InputError("config: at least one of nominal, foldable")
        for c in self.configs:
            if c not in CONFIGS:
                raise InputError(f"config {c!r} unknown (allowed: {', '.join(CONFIGS)})")
        if not self.winds:
            raise InputError("wind: at least one wind speed")
        lo, hi = WIND_RANGE
        for v in self.winds:
            if not (math.isfinite(v) and lo <= v <= hi):
                raise InputError(f"wind speed {v!r} m/s out of range (allowed {lo:g}..{hi:g} m/s)")
        for d0, dtf in self.tether_ranges:
            if not (math.isfinite(d0) and math.isfinite(dtf) and 0 < d0 < dtf):
                raise InputError(f"tether range {d0!r}:{dtf!r} m invalid (allowed 0 < d0 < d_tf)")
        from ..definitions.aircraft import FOLD_TIME_MAX_S

        if not self.fold_times:
            raise InputError("fold time: at least one value (or none given: the aircraft definition's)")
        for t in self.fold_times:
            if t is not None and not (isinstance(t, (int, float)) and math.isfinite(t) and 0.0 <= t <= FOLD_TIME_MAX_S):
                raise InputError(f"fold time {t!r} s out of range (allowed 0..{FOLD_TIME_MAX_S:g} s; 0 = instantaneous)")
        self.mesh.validate()
        for name, (lo, hi) in (("max_iter", MAX_ITER_RANGE), ("max_iter_total", MAX_ITER_TOTAL_RANGE)):
            v = getattr(self, name)
            if not (isinstance(v, int) and lo <= v <= hi):
                raise InputError(f"{name} = {v!r} out of range (allowed integer {lo}..{hi})")
        if self.warm_fallback not in WARM_FALLBACKS:
            raise InputError(f"warm fallback {self.warm_fallback!r} unknown (allowed: {', '.join(WARM_FALLBACKS)})")
        if self.propeller is not None and self.propeller not in PROPELLERS:
            raise InputError(f"propeller {self.propeller!r} unknown (allowed: {', '.join(PROPELLERS)})")
        if (self.propeller is not None or self.line_weight) and self.scenario != "physical":
            raise InputError("propeller / line weight: only the physical scenario has these choices")
        if self.line_weight is not None and not isinstance(self.line_weight, bool):
            raise InputError(f"line weight {self.line_weight!r} invalid (allowed true or false)")
        if not isinstance(self.cold_check, bool):
            raise InputError(f"cold check {self.cold_check!r} invalid (allowed true or false)")
        if not self.lines:
            raise InputError(f"line: at least one of {', '.join(LINES)}")
        for n in self.lines:
            if n is not None and n not in LINES:
                raise InputError(f"line {n!r} unknown (allowed: {', '.join(LINES)})")
        if not self.line_diameters:
            raise InputError("line diameter: at least one value (or none given: the line as defined)")
        lo, hi = LINE_DIAMETER_RANGE
        for d in self.line_diameters:
            if d is not None and not (isinstance(d, (int, float)) and math.isfinite(d) and lo <= d <= hi):
                raise InputError(f"line diameter {d!r} m out of range (allowed {lo:g}..{hi:g} m, i.e. "
                                 f"{lo * 1e3:g}..{hi * 1e3:g} mm)")
        if any(d is not None for d in self.line_diameters) and "sized" not in self.line_names():
            raise InputError("line diameter: only the sized line is resized (from its material); the sweep's lines are "
                             f"{', '.join(self.line_names())} (add sized to the lines)")
        from ..wind import WindProfile

        prof = WindProfile.parse(self.wind_profile, option="wind profile")
        if prof.label() != self.wind_profile:
            raise InputError(f"wind profile {self.wind_profile!r} not canonical (allowed e.g. uniform, log:0.1@10, power:0.143@10)")
        if self.scenario == "paper" and not prof.uniform:
            raise InputError(f"wind profile {self.wind_profile!r}: the paper scenario's wind is uniform (allowed uniform)")
        from ..groundstation.line import check_line_model
        from ..ocp.problem import STALL_MARGIN_MAX, TENSION_MARGIN_MAX

        for name, hi in (("tension_margin", TENSION_MARGIN_MAX), ("stall_margin", STALL_MARGIN_MAX)):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and 0.0 <= v <= hi):
                raise InputError(f"{name} = {v!r} out of range (allowed 0 .. {hi:g})")
        check_line_model(self.line_model)
        if self.line_model != "straight" and self.scenario != "physical":
            raise InputError(f"line_model {self.line_model!r}: only the physical scenario has a line model (allowed straight)")
        if self.bounds not in BOUNDS:
            raise InputError(f"bounds {self.bounds!r} unknown (allowed: {', '.join(BOUNDS)})")
        lo, hi = ANCHOR_EVERY_RANGE
        if not (isinstance(self.anchor_every, int) and lo <= self.anchor_every <= hi):
            raise InputError(f"anchor_every = {self.anchor_every!r} out of range (allowed integer {lo}..{hi}; 0 = one anchor per line)")
        return self

    def points(self) -> list[Point]:
        """All points, without duplicates, in a stable order."""
        self.validate()
        mesh = (self.mesh.n_gen, self.mesh.n_rec, self.mesh.degree)
        out: list[Point] = []
        seen: set[str] = set()
        plant = self.plant()
        # the Point's propeller None is momentum theory in the physical scenario (see Point)
        prop = None if plant["propeller"] == "momentum" else plant["propeller"]
        line_axes = [(n, d) for n in self.line_names()
                     for d in (self.line_diameters if n == "sized" else (None,))]
        fold_times = tuple(dict.fromkeys(self._fold_time(t) for t in self.fold_times))
        for cfg in self.configs:
            fold_axes = ([(b, a, t) for b in self.folded_spans for a in self.folded_drag_areas for t in fold_times]
                         if cfg == "foldable" else [(None, None, 0.0)])
            for S in self.wing_areas:
                for d0, dtf in self.tether_ranges:
                    for line, dl in line_axes:
                        for b, a, t in fold_axes:
                            for v in sorted(self.winds):
                                p = Point(self.scenario, cfg, float(v), float(d0), float(dtf), b, a, S, t, mesh,
                                          self.max_iter, self.max_iter_total, self.warm_fallback, propeller=prop,
                                          line_weight=bool(plant["line_weight"]), line=line,
                                          line_diameter=None if dl is None else float(dl),
                                          cold_check=bool(self.cold_check), wind_profile=self.wind_profile,
                                          tension_margin=float(self.tension_margin),
                                          stall_margin=float(self.stall_margin), line_model=self.line_model,
                                          bounds=self.bounds, aircraft=self.aircraft,
                                          aircraft_sha256=self.aircraft_sha256, ground_station=self.ground_station,
                                          ground_station_sha256=self.ground_station_sha256)
                                if p.id not in seen:
                                    seen.add(p.id)
                                    out.append(p)
        return out

    def _fold_time(self, t: float | None) -> float:
        """``t`` [s], or the aircraft definition's fold time for None."""
        if t is not None:
            return float(t)
        from ..ocp.model import definition_fold_time

        return float(definition_fold_time(self.aircraft))

    def to_dict(self) -> dict:
        d = asdict(self)
        # the package's glider and ground station: as before the options
        for k in ("aircraft", "aircraft_sha256", "ground_station", "ground_station_sha256"):
            if d[k] is None:
                del d[k]
        d["mesh"] = {"n_gen": self.mesh.n_gen, "n_rec": self.mesh.n_rec, "degree": self.mesh.degree}
        return d


@dataclass(frozen=True)
class Chain:
    """Points solved one after another, each warm-started from the last successful one.

    ``after`` is the index of the chain whose first point seeds this one's first point
    (``None`` = cold start).
    """

    points: tuple[Point, ...]
    after: int | None = None


def anchors(n: int, main: int, every: int = 0) -> list[int]:
    """Indices of the anchors among ``n`` winds of a line (ascending): ``main`` and, when
    ``every`` > 0, every ``every``-th index counted from it."""
    if every <= 0:
        return [main]
    return [i for i in range(n) if (i - main) % every == 0]


def chains(points: list[Point], anchor_every: int = 0, anchor_wind: float = ANCHOR_WIND) -> list[Chain]:
    """Warm-start chains of ``points``: per anchor of a line (see :func:`anchors` and the module
    docstring) an upward chain (the anchor, then its points above it in wind) and a downward
    chain seeded by the anchor (its points below it, downwards)."""
    lines: dict[tuple, list[Point]] = {}
    for p in points:
        lines.setdefault(p.line_key, []).append(p)
    out: list[Chain] = []
    for pts in lines.values():
        pts = sorted(pts, key=lambda p: p.wind)
        ia = min(range(len(pts)), key=lambda i: (abs(pts[i].wind - anchor_wind), pts[i].wind))
        anc = anchors(len(pts), ia, anchor_every)
        # every point joins its nearest anchor; a tie goes to the anchor nearer the main one
        owner = [min(anc, key=lambda a: (abs(a - i), abs(a - ia))) for i in range(len(pts))]
        for a in sorted(anc, key=lambda a: (abs(a - ia), a)):  # the main anchor's chains first
            out.append(Chain(tuple(pts[i] for i in range(a, len(pts)) if owner[i] == a)))
            below = tuple(pts[i] for i in range(a - 1, -1, -1) if owner[i] == a)
            if below:
                out.append(Chain(below, after=len(out) - 1))
    return out


def _items(text: str, what: str, allowed: str) -> list[str]:
    """The comma-separated items of ``text``; an empty item (``3,,5``, ``3,``) is an error."""
    items = [x.strip() for x in text.split(",")]
    if any(not x for x in items):
        raise InputError(f"{what} {text!r} invalid: empty list item (allowed: {allowed})")
    return items


def _range_text(lo: float | None, hi: float | None, lo_open: bool, hi_open: bool, unit: str) -> str:
    """``lo``..``hi`` [``unit``] as the errors write it (``0.01..2 m2``, ``> 0 and < 0.1 m2``)."""
    if lo is not None and hi is not None and not lo_open and not hi_open:
        return f"{lo:g}..{hi:g} {unit}"
    parts = ([f"{'>' if lo_open else '>='} {lo:g}"] if lo is not None else []) + (
        [f"{'<' if hi_open else '<='} {hi:g}"] if hi is not None else [])
    return f"{' and '.join(parts)} {unit}"


def parse_floats(text: str, what: str, unit: str, lo: float | None = None, hi: float | None = None, *,
                 lo_open: bool = False, hi_open: bool = False) -> tuple[float, ...]:
    """``"3:12:1"`` (start:stop:step, stop included) or ``"0.22,0.4"`` -> floats.

    Every value must be finite and, where given, within ``lo``..``hi`` [``unit``] (an end
    excluded where ``lo_open``/``hi_open``); empty list items are refused. ``what`` names the
    option in the one-line error.
    """
    text = text.strip()
    rng = "" if lo is None and hi is None else f", each {_range_text(lo, hi, lo_open, hi_open, unit)}"
    allowed = f"START:STOP:STEP with STEP > 0, or a comma list, in {unit}{rng}"
    try:
        if ":" in text:
            parts = [float(x) for x in text.split(":")]
            if len(parts) != 3 or not all(math.isfinite(v) for v in parts) or parts[2] <= 0 or parts[1] < parts[0]:
                raise ValueError
            a, b, s = parts
            n = int(math.floor((b - a) / s + 1e-9)) + 1
            if n > 10000:
                raise ValueError
            vals = tuple(round(a + i * s, 10) for i in range(n))
        else:
            vals = tuple(float(x) for x in _items(text, what, allowed))
            if not all(math.isfinite(v) for v in vals):
                raise ValueError
    except ValueError:
        raise InputError(f"{what} {text!r} invalid (allowed: {allowed})") from None
    for v in vals:
        below = lo is not None and (v <= lo if lo_open else v < lo)
        above = hi is not None and (v >= hi if hi_open else v > hi)
        if below or above:
            raise InputError(f"{what} {text!r}: {v:g} {unit} out of range (allowed: {allowed})")
    return vals


def parse_names(text: str, what: str, allowed: tuple[str, ...]) -> tuple[str, ...]:
    """``"nominal,foldable"`` -> names, each one of ``allowed``, without repeats; empty items
    and unknown names are refused."""
    names = _items(text, what, ", ".join(allowed))
    for n in names:
        if n not in allowed:
            raise InputError(f"{what} {text!r}: {n!r} unknown (allowed: {', '.join(allowed)})")
    return tuple(dict.fromkeys(names))


def parse_tether_ranges(text: str, what: str = "--tether-range") -> tuple[tuple[float, float], ...]:
    """``"200:250,150:250"`` -> ((200, 250), (150, 250)) [m]; empty items, other forms and
    ranges outside ``0 < d0 < d_tf`` (finite) are refused naming ``what``, as
    :meth:`SweepSpec.validate` would refuse them."""
    allowed = "D0:DTF in m with 0 < D0 < DTF, e.g. 200:250, comma separated"
    out = []
    for item in _items(text, what, allowed):
        try:
            a, b = (float(x) for x in item.split(":"))
        except ValueError:
            raise InputError(f"{what} {item!r} invalid (allowed {allowed})") from None
        if not (math.isfinite(a) and math.isfinite(b) and 0 < a < b):
            raise InputError(f"{what} {text!r}: {item} m out of range (allowed {allowed})")
        out.append((a, b))
    return tuple(out)
