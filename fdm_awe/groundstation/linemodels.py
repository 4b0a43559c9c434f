"""The ground station's line models, one registry entry each (``--tether``).

An entry (:class:`LineKind`) holds everything the rest of the package needs of a line model:

- its ``name`` and ``code`` (the number the compiled co-simulation step dispatches on: the
  station's constants array carries it in the slot ``line`` of :data:`.substeps.STATION`, :func:`line_step`);
- its forms of ``--tether`` (``forms``, in words; ``example``, one that parses), a line of
  ``doc`` for the help, and ``parse``, the spec's tail after the name to the model's one integer
  parameter (the lumped line's segment count; 0 where the model takes none; None: not a form);
- the length of its block in the ground station's state array after the drivetrain's
  (``state_size``) and its constants after :data:`.substeps.STATION` (``constants``);
- its step, the plain Python function (``step``, the arguments and returns of
  :func:`.substeps.station_step`), the same function compiled (``compiled``), and what the
  kernels compile into themselves (``called``: the functions, ``sources``: the files numba's
  on-disk cache is tied to);
- its views of the state array: the line's own energy ledger (``ledger``), node positions and
  segment tensions (``nodes``, ``tensions``; None where the line has no shape);
- ``unstretched``: the paid-out length that carries a tension at a distance (the start of a
  flight), and ``reset``: what a :meth:`.station.GroundStation.reset` does to the line's block;
- ``kinematic_winch``: whether it flies with the paper plant's kinematic winch (no line there);
- ``python_cost``: wall seconds a flight on this line takes per simulated second when its step
  runs as plain Python, as a function of the parameter (measured, one cycle of a stored
  reference, ``FDM_AWE_JIT=0 fdm-awe fly --cycles 1 --tether FORM``; a flight of a fresh install
  weighs it against compiling the kernels, :mod:`fdm_awe.sim.first_use`).

:func:`parse_tether` turns ``--tether`` into a :class:`TetherModel` (entry and parameter) once,
at the command line or the API; the flight and the ground station take that object. The one
error names ``--tether`` and every allowed form. ``docs/architecture.md`` ("Adding a line
model") lists the steps of a new entry.
"""

from __future__ import annotations

import sys
from dataclasses import dataclass, field
from types import ModuleType
from typing import Any, Callable

import numpy as np

from .. import slots
from ..errors import InputError
from . import lumped, lumped_state, rigid, substeps, winch
from .lumped import lumped_station_step
from .rigid import rigid_station_step
from .substeps import station_step


def _none(*_: Any) -> None:
    return None


def _no_param(tail: str) -> int | None:
    """A model without a parameter: only its bare name (``tail`` empty) parses, to 0."""
    return 0 if tail == "" else None


def _elastic_unstretched(tp: Any, param: int, distance: float, tension: float) -> float:
    """Unstretched length (m) of an elastic line of stiffness EA/l carrying ``tension`` (N) at ``distance`` (m)."""
    return distance / (1.0 + tension / tp.axial_stiffness)


@dataclass(frozen=True)
class LineKind:
    """One line model (see the module docstring for each field)."""

    name: str
    code: int
    forms: str
    example: str
    doc: str
    step: Callable
    compiled: Callable[[], Callable | None]
    called: Callable[[], tuple]
    sources: Callable[[], tuple[ModuleType, ...]]
    parse: Callable[[str], int | None] = _no_param
    state_size: Callable[[int], int] = lambda p: 0
    constants: Callable[[int, Any, float], list[float]] = lambda p, tp, drag_scale: []
    ledger: Callable[[np.ndarray], Any] = _none
    nodes: Callable[[np.ndarray, int], np.ndarray | None] = _none
    tensions: Callable[[np.ndarray, int], np.ndarray | None] = _none
    prepare: Callable[[np.ndarray, int], None] = _none
    reset: Callable[[np.ndarray], None] = _none
    unstretched: Callable[[Any, int, float, float], float] = _elastic_unstretched
    kinematic_winch: bool = True
    python_cost: Callable[[int], float] = lambda p: 0.04


@dataclass(frozen=True)
class TetherModel:
    """A parsed ``--tether``: the registry entry ``kind`` and its parameter ``param`` (the lumped
    line's segments; 0 for a model without one)."""

    kind: LineKind
    param: int = 0
    spec: str = field(default="", compare=False)

    def __str__(self) -> str:
        return self.spec or (self.kind.name if not self.param else f"{self.kind.name}:{self.param}")

    @property
    def name(self) -> str:
        return self.kind.name

    @property
    def code(self) -> int:
        return self.kind.code

    @property
    def has_shape(self) -> bool:
        """Whether the line has nodes (a shape to sample, its own ledger)."""
        return self.kind.nodes is not _none

    def state_size(self) -> int:
        """Length of the line's block in the state array after the drivetrain's."""
        return self.kind.state_size(self.param)

    def check_plant(self, paper: bool, why: str = "", what: str = "--tether") -> "TetherModel":
        """Itself, or a one-line :class:`InputError` naming the option ``what`` when the plant is
        the paper scenario's (``paper``, chosen by ``why``) whose winch is kinematic and the
        model needs the physical plant's line."""
        if paper and not self.kind.kinematic_winch:
            reason = f" ({why})" if why else ""
            allowed = ", ".join(k.forms for k in LINE_MODELS if k.kinematic_winch)
            raise InputError(f"{what} {self}: the {self.kind.name} line needs the physical plant; the paper "
                             f"plant{reason} has a kinematic winch (allowed with it: {allowed})")
        return self


def _lumped_parse(tail: str) -> int | None:
    t = tail[1:] if tail.startswith(":") else None
    if t is not None and t.isdigit() and lumped_state.N_MIN <= int(t) <= lumped_state.N_MAX:
        return int(t)
    return None


def _lumped_constants(scheme: str) -> Callable[[int, Any, float], list[float]]:
    """The constants of the lumped line integrated by ``scheme`` (:data:`.lumped_state.SCHEMES`)."""
    def constants(n: int, tp: Any, drag_scale: float) -> list[float]:
        return lumped_state.line_constants(n, tp.air_density, tp.cd_perpendicular, tp.diameter,
                                           drag_scale if tp.drag_share > 0.0 else 0.0, scheme=scheme)
    return constants


def _lumped_prepare(s: np.ndarray, n: int) -> None:
    s[lumped_state.HEAD.nseg] = n


def _lumped_reset(s: np.ndarray) -> None:
    s[lumped_state.HEAD.ready] = 0.0  # the line takes its static shape to the hook on the first step


def _straight_called() -> tuple:
    return substeps.CALLED + (station_step,)


def _lumped_kind(name: str, code: int, example: str, doc: str, scheme: str,
                 python_cost: Callable[[int], float]) -> "LineKind":
    """A registry entry of the lumped line (one step and state, the integrator ``scheme``)."""
    return LineKind(name, code, f"{name}:N (N {lumped_state.N_MIN} .. {lumped_state.N_MAX})", example, doc,
                    lumped_station_step, lumped.compiled_lumped, lambda: _straight_called() + lumped.CALLED
                    + (lumped_station_step,), lambda: (substeps, winch, lumped, lumped_state) + lumped.SOURCES,
                    parse=_lumped_parse,
                    state_size=lambda n: lumped_state.state_size(n) - slots.start(lumped_state.HEAD),
                    constants=_lumped_constants(scheme), ledger=lumped_state.LineLedger, nodes=lumped_state.nodes,
                    tensions=lumped_state.tensions, prepare=_lumped_prepare, reset=_lumped_reset,
                    kinematic_winch=False, python_cost=python_cost)


#: the registry, ``code`` = position
LINE_MODELS: tuple[LineKind, ...] = (
    LineKind("straight", 0, "straight", "straight",
             "the straight elastic line, the glider carrying 1/4 of its drag and 1/2 of its weight",
             station_step, substeps.compiled_station, _straight_called, lambda: (substeps, winch)),
    _lumped_kind("lumped", 1, "lumped:10",
                 "N elastic segments with mass, weight and drag; the recording shows its nodes and tensions",
                 "leapfrog", lambda n: 0.04 + 0.027 * n),
    LineKind("rigid", 2, "rigid", "rigid",
             "the straight line without elasticity, its length the distance when taut (the optimiser's line)",
             rigid_station_step, rigid.compiled_rigid, lambda: _straight_called() + (rigid.stiffness, rigid_station_step),
             lambda: (substeps, winch, rigid), constants=rigid.constants, unstretched=rigid.unstretched,
             kinematic_winch=False),
    _lumped_kind("lumped-implicit", 3, "lumped-implicit:30",
                 "the lumped line integrated by linearly implicit Euler steps of one flight step (faster at large N)",
                 "implicit", lambda n: 0.05 + 0.005 * n),
)


def line_step(code, s, c, n, dt, x, y, z, vx, vy, vz, motor, omega_ref, duty_cmd, boost_duty, RL):
    """The step of the line model ``code`` (:attr:`LineKind.code`; the arguments and returns of
    :func:`.substeps.station_step`): the compiled co-simulation step's one dispatch."""
    if code == 1 or code == 3:
        return lumped_station_step(s, c, n, dt, x, y, z, vx, vy, vz, motor, omega_ref, duty_cmd, boost_duty, RL)
    if code == 2:
        return rigid_station_step(s, c, n, dt, x, y, z, vx, vy, vz, motor, omega_ref, duty_cmd, boost_duty, RL)
    return station_step(s, c, n, dt, x, y, z, vx, vy, vz, motor, omega_ref, duty_cmd, boost_duty, RL)


def kernel_called() -> tuple:
    """The functions a compiled kernel holds to run every line model (:func:`line_step` last)."""
    out: list = []
    for k in LINE_MODELS:
        out += [f for f in k.called() if f not in out]
    return tuple(out) + (line_step,)


def kernel_sources() -> tuple[ModuleType, ...]:
    """The source files of every line model's step (a compiled kernel's cache is tied to them)."""
    out: list = [sys.modules[__name__]]
    for k in LINE_MODELS:
        out += [m for m in k.sources() if m not in out]
    return tuple(out)


def allowed_forms() -> str:
    """The allowed forms of ``--tether``, for messages and help."""
    return ", ".join(k.forms for k in LINE_MODELS)


def parse_tether(spec: object, what: str = "--tether") -> TetherModel:
    """``spec`` (``"straight"``, ``"lumped:N"``, or a :class:`TetherModel`, returned
    as it is) as a :class:`TetherModel`; else a one-line :class:`InputError` naming ``what`` and
    every allowed form."""
    if isinstance(spec, TetherModel):
        return spec
    if isinstance(spec, str):
        for kind in LINE_MODELS:
            if spec == kind.name or spec.startswith(kind.name + ":"):
                p = kind.parse(spec[len(kind.name):])
                if p is not None:
                    return TetherModel(kind, p, spec)
    raise InputError(f"{what} {spec!r} not allowed (allowed: {allowed_forms()})")


if [k.code for k in LINE_MODELS] != list(range(len(LINE_MODELS))):  # pragma: no cover - a definition error
    raise RuntimeError("fdm_awe.groundstation.linemodels: the codes must be the entries' positions")

__all__ = ["LINE_MODELS", "LineKind", "TetherModel", "allowed_forms", "line_step", "parse_tether"]
