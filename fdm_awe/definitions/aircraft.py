"""Airframe parameters read from the JSBSim aircraft definitions (the single source of truth).

The point-mass model, the optimiser and the 6-DOF model all read the same numbers from the
same XML files of one aircraft (:class:`~.catalog.Aircraft`, ``--aircraft``; the package's
``glider``: ``aircraft/glider_unfolded/glider_unfolded.xml``, the unfolded configuration, and
``aircraft/glider_folded/glider_folded.xml``, the folded one). Nothing here holds a copy
of an airframe number. What the forms share (metrics but span and area, skids, tether hook,
drive, point-mass propulsion values, control surfaces, the aerodynamic model) the aircraft files
take from JSBSim section files in ``aircraft/common/``; :class:`~.xmlutil.XmlDoc` merges them in
as JSBSim does, so the loaders read each file as JSBSim flies it.

Named values the XML must declare (JSBSim ``<property value="...">NAME</property>``):

- in ``<aerodynamics>`` (beside the shared model ``aircraft/common/aerodynamics.xml``):
  ``aero/pm/CL0``, ``aero/pm/CLalpha`` [1/rad], ``aero/pm/CLmax``,
  ``aero/pm/CD0``, ``aero/pm/CDalpha1`` [1/rad], ``aero/pm/CDalpha2`` [1/rad^2]
  (paper eqs. 32/46: C_L = C_L0 + C_La a, C_D = C_D0 + C_Da1 a + C_Da2 a^2) and the stability
  and control derivatives ``aero/coef/NAME`` (:data:`COEF_RANGES`);
- anywhere (the system ``aircraft/common/point_mass_propulsion.xml``): ``propulsion/pm/P0-W``,
  ``propulsion/pm/eta-prop``, ``propulsion/pm/eta-motor``, ``propulsion/pm/disk-area-m2``,
  ``propulsion/pm/paper-PT0``, ``propulsion/pm/paper-PT1``, ``propulsion/pm/paper-PT2``,
  ``propulsion/pm/T-max-N``, ``propulsion/pm/T-avail-c1``, ``propulsion/pm/T-avail-c2``.

The morphing aircraft ``aircraft/glider_foldable/glider_foldable.xml`` (flown by the 6-DOF
model) declares both coefficient sets, ``aero/unfolded/NAME`` and ``aero/folded/NAME`` (the
polar above and the stability derivatives ``aero/coef/NAME`` of the static forms), the fold
ratios ``aero/fold/S-ratio``, ``aero/fold/b-ratio`` and the fold time ``fcs/wing-fold-time-s``,
and blends the sets into ``aero/pm/*`` and ``aero/coef/*`` with the fold state.
:func:`check_aircraft_file` checks any of the three files field by field before JSBSim loads
it (the 6-DOF adapter calls it): every number JSBSim reads, then the ranges of
:data:`PM_RANGES`, :data:`COEF_RANGES`, mass and inertia, and (:mod:`.airframe_checks`)
controls, contacts and their ground-contact flag (:data:`.airframe_checks.GROUND_CONTACT`),
tether hook and the engine feeds; then the engine files.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..constants import G0, RHO0
from .. import ROOT
from ..errors import DefinitionError, InputError
from .airframe_checks import airframe_checks
from .xmlutil import XmlDoc, check_numbers, element_number, location

#: The static configurations (each an aircraft form of :data:`~.catalog.FORMS`).
CONFIGS = ("unfolded", "folded")

#: Allowed range ``(lo, hi, lo_open, hi_open)`` of each point-mass polar coefficient (one
#: configuration, normalised with its own S): ``C_L = CL0 + CLalpha a``, ``C_D = CD0 + CDalpha1 a
#: + CDalpha2 a^2`` [1/rad, 1/rad^2]; the lift slope at most the thin-airfoil 2 pi.
PM_RANGES: dict[str, tuple[float, float, bool, bool]] = {
    "CL0": (-1.0, 1.5, False, False), "CLalpha": (0.0, 2 * math.pi, True, False), "CLmax": (0.0, 3.0, True, False),
    "CD0": (0.0, 1.0, True, False), "CDalpha1": (-5.0, 5.0, False, False), "CDalpha2": (0.0, 50.0, False, False),
}
#: Largest magnitude of a stability or control derivative [per rad, rate derivatives per
#: normalised rate] (the folded form's Cm_q is about -51).
COEF_MAX = 1000.0
_ANY = (-COEF_MAX, COEF_MAX, False, False)
#: Allowed range of each stability and control derivative. Signs follow the sign conventions
#: of the aircraft files (elevator trailing edge down, right roll, rudder trailing edge left are
#: positive): static stability in pitch and yaw, damping in pitch, roll and yaw, and control
#: derivatives of the sign the stabiliser (:mod:`fdm_awe.sixdof.stabilizer`) divides by.
COEF_RANGES: dict[str, tuple[float, float, bool, bool]] = {
    "Cm0": _ANY, "Cm_alpha": (-COEF_MAX, 0.0, False, True), "Cm_q": (-COEF_MAX, 0.0, False, True), "Cm_adot": _ANY,
    "Cm_de": (-COEF_MAX, 0.0, False, True), "CL_q": _ANY, "CL_adot": _ANY, "CL_de": _ANY,
    "CY_beta": (-COEF_MAX, 0.0, False, False), "CY_dr": _ANY, "Cl_beta": (-COEF_MAX, 0.0, False, False),
    "Cl_p": (-COEF_MAX, 0.0, False, True), "Cl_r": _ANY, "Cl_da": (0.0, COEF_MAX, True, False), "Cl_dr": _ANY,
    "Cn_beta": (0.0, COEF_MAX, False, False), "Cn_p": _ANY, "Cn_r": (-COEF_MAX, 0.0, False, True), "Cn_da": _ANY,
    "Cn_dr": (-COEF_MAX, 0.0, False, True),
}
#: Longest full fold (``fcs/wing-fold-time-s``) of the morphing aircraft [s].
FOLD_TIME_MAX_S = 60.0


def stall_speed(mass: float, rho: float, g: float, s_clmax: float) -> float:
    """The 1 g stall speed [m/s], ``sqrt(2 m g / (rho S CLmax))``, of a wing with ``s_clmax`` =
    S CLmax [m^2] carrying ``mass`` [kg] (air density ``rho`` [kg/m^3], gravity ``g`` [m/s^2]).
    A plain function of floats: the autopilot's compiled step runs it on the blended polar of
    the current fold state."""
    return math.sqrt(2.0 * mass * g / (rho * s_clmax))


@dataclass(frozen=True)
class AeroParams:
    """Wing geometry and the paper's polynomial aerodynamics of one configuration (SI)."""

    S: float  #: reference wing area [m^2]
    b: float  #: span [m]
    c: float  #: mean aerodynamic chord [m]
    CL0: float  #: lift coefficient at alpha = 0 [-]
    CLalpha: float  #: lift-curve slope [1/rad]
    CLmax: float  #: maximum lift coefficient (stall) [-]
    CD0: float  #: drag coefficient at alpha = 0 [-]
    CDalpha1: float  #: linear drag term [1/rad]
    CDalpha2: float  #: quadratic drag term [1/rad^2]

    @property
    def aspect_ratio(self) -> float:
        return self.b * self.b / self.S

    @property
    def alpha_max_lift(self) -> float:
        """Angle of attack [rad] at which the linear lift reaches ``CLmax``."""
        return (self.CLmax - self.CL0) / self.CLalpha

    def stall_speed(self, mass: float, rho: float = RHO0, g: float = G0) -> float:
        """Airspeed [m/s] at which the wing's ``CLmax`` just carries the weight of ``mass`` [kg]
        in level flight (air density ``rho`` [kg/m^3], gravity ``g`` [m/s^2]):
        :func:`stall_speed` of ``S CLmax``."""
        return stall_speed(mass, rho, g, self.S * self.CLmax)


@dataclass(frozen=True)
class MassParams:
    """Total mass [kg], CG in the JSBSim structural frame [m] and inertia matrix about the CG
    in body axes (x forward, y right, z down) [kg m^2], as in the paper's Table 2."""

    mass: float
    cg_structural: tuple[float, float, float]
    inertia: tuple[tuple[float, float, float], ...]

    @property
    def inertia_matrix(self) -> np.ndarray:
        return np.array(self.inertia, dtype=float)


@dataclass(frozen=True)
class PropulsionParams:
    """Propeller power models: ``physical`` momentum-theory form and the paper's eq. 39 fit."""

    P0: float  #: constant electrical power (avionics, ESC) [W]
    eta_prop: float  #: propeller efficiency on top of the ideal induced power [-]
    eta_motor: float  #: motor + ESC efficiency [-]
    disk_area: float  #: propeller disk area [m^2]
    PT0: float  #: paper eq. 39 constant [W]
    PT1: float  #: paper eq. 39 linear term [W/N]
    PT2: float  #: paper eq. 39 quadratic term [W/N^2]
    T_max: float  #: maximum (static) thrust [N]
    T_avail_c1: float = 0.0  #: linear fall of full-throttle thrust with airspeed [N/(m/s)]
    T_avail_c2: float = 0.0  #: quadratic fall of full-throttle thrust with airspeed [N/(m/s)^2]

    def thrust_available(self, V):  # noqa: ANN001,ANN201 - floats and CasADi symbols alike
        """Full-throttle thrust [N] at airspeed ``V`` [m/s]: ``max(T_max + c1 V + c2 V^2, 0)``.

        Never negative: above the speed where the fit crosses zero (27.35 m/s for the 9x5
        propeller) the running propeller gives no thrust, and a stopped one limits nothing, so
        the bound ``T <= T_avail(V)`` only holds the thrust at zero there and caps no airspeed."""
        T = self.T_max + self.T_avail_c1 * V + self.T_avail_c2 * V * V
        if isinstance(T, (int, float)):
            return max(float(T), 0.0)
        if type(T).__module__.startswith("casadi"):
            import casadi

            return casadi.fmax(T, 0.0)
        return T.clip(min=0.0)  # NumPy arrays and scalars


@dataclass(frozen=True)
class Airframe:
    """Everything the point-mass side needs about one configuration of the glider."""

    config: str
    aircraft: str
    source: Path
    aero: AeroParams
    mass: MassParams
    propulsion: PropulsionParams


def aircraft_path(name: str, root: Path | None = None) -> Path:
    """Path of the JSBSim aircraft file ``aircraft/NAME/NAME.xml`` under ``root``."""
    return (root or ROOT) / "aircraft" / name / f"{name}.xml"


def mass_params(doc: XmlDoc) -> MassParams:
    mb = doc.find("mass_balance")
    assert mb is not None
    m_e = doc.number("mass_balance/emptywt", lo=0.0, lo_open=True, unit="kg")
    cg_el = doc.find("mass_balance/location")
    assert cg_el is not None
    cg_e = np.array(location(doc.origin(cg_el), cg_el, "mass_balance/location"))
    ixx = doc.number("mass_balance/ixx", lo=0.0, lo_open=True, unit="kg m2")
    iyy = doc.number("mass_balance/iyy", lo=0.0, lo_open=True, unit="kg m2")
    izz = doc.number("mass_balance/izz", lo=0.0, lo_open=True, unit="kg m2")
    ixy = doc.number("mass_balance/ixy", default=0.0)
    ixz = doc.number("mass_balance/ixz", default=0.0)
    iyz = doc.number("mass_balance/iyz", default=0.0)
    # JSBSim: with negated_crossproduct_inertia="true" (its default) the <ixy>/<ixz>/<iyz>
    # values are the inertia matrix's off-diagonal ELEMENTS in the structural frame; with
    # "false" they are the products of inertia, i.e. the elements negated. Into body axes
    # (x and z opposite to the structural frame's) the xy and yz elements flip sign, xz not.
    if mb.attrib.get("negated_crossproduct_inertia", "true").strip().lower() != "true":
        ixy, ixz, iyz = -ixy, -ixz, -iyz
    J = np.array([[ixx, -ixy, ixz], [-ixy, iyy, -iyz], [ixz, -iyz, izz]])
    masses = [(m_e, cg_e, J)]
    for i, pm in enumerate(mb.findall("pointmass")):
        what = f"mass_balance/pointmass[{i}]"
        w = pm.find("weight")
        loc = pm.find("location")
        if w is None or loc is None:
            raise DefinitionError(doc.origin(pm), what, "needs <weight> and <location>")
        m_i = element_number(doc.origin(w), f"{what}/weight", w, lo=0.0, unit="kg")
        masses.append((m_i, np.array(location(doc.origin(loc), loc, f"{what}/location")), np.zeros((3, 3))))
    M = sum(m for m, _, _ in masses)
    cg = sum(m * r for m, r, _ in masses) / M
    Jt = np.zeros((3, 3))
    # Structural frame is x aft, y right, z up; body axes flip x and z, which leaves the
    # parallel-axis terms (including the xz product) unchanged.
    flip = np.array([-1.0, 1.0, -1.0])
    for m, r, Ji in masses:
        d = (r - cg) * flip
        Jt += Ji + m * (d @ d * np.eye(3) - np.outer(d, d))
    # a physical body: principal moments positive, each at most the sum of the other two
    pm = np.linalg.eigvalsh(0.5 * (Jt + Jt.T))
    tol = 1e-9 * float(np.max(np.abs(pm)))
    if not (np.all(np.isfinite(pm)) and pm[0] > 0.0 and pm[2] <= pm[0] + pm[1] + tol):
        raise DefinitionError(doc.path, "mass_balance",
                              f"inertia about the CG is not a physical body's (principal moments "
                              f"{', '.join(f'{v:.4g}' for v in pm)} kg m2; allowed: all > 0, each <= the sum of the other two)")
    return MassParams(mass=float(M), cg_structural=tuple(float(v) for v in cg), inertia=tuple(tuple(float(v) for v in row) for row in Jt))


def _geometry(doc: XmlDoc) -> tuple[float, float, float]:
    """Reference wing area [m^2], span [m] and chord [m] (``<metrics>``); the tail sizes JSBSim
    reads are checked too (>= 0 when given)."""
    S = doc.number("metrics/wingarea", lo=0.0, lo_open=True, unit="m2")
    b = doc.number("metrics/wingspan", lo=0.0, lo_open=True, unit="m")
    c = doc.number("metrics/chord", lo=0.0, lo_open=True, unit="m")
    for tail, unit in (("htailarea", "m2"), ("htailarm", "m"), ("vtailarea", "m2"), ("vtailarm", "m")):
        doc.number(f"metrics/{tail}", lo=0.0, default=0.0, unit=unit)
    return S, b, c


def _pm_coefficients(doc: XmlDoc, prefix: str = "aero/pm") -> dict[str, float]:
    """The point-mass polar (:data:`PM_RANGES`) declared as ``<property>`` ``PREFIX/NAME``."""
    vals = {k: doc.property_value(f"{prefix}/{k}", lo=lo, hi=hi, lo_open=lo_open, hi_open=hi_open)
            for k, (lo, hi, lo_open, hi_open) in PM_RANGES.items()}
    if vals["CLmax"] <= vals["CL0"]:
        raise DefinitionError(doc.path, f"property {prefix}/CLmax",
                              f"value {vals['CLmax']:g} out of range (allowed > {prefix}/CL0 = {vals['CL0']:g}: "
                              f"the wing reaches CLmax at a positive angle of attack)")
    return vals


def _stability(doc: XmlDoc, prefix: str = "aero/coef") -> dict[str, float]:
    """The stability and control derivatives (:data:`COEF_RANGES`) declared as ``PREFIX/NAME``."""
    return {k: doc.property_value(f"{prefix}/{k}", lo=lo, hi=hi, lo_open=lo_open, hi_open=hi_open)
            for k, (lo, hi, lo_open, hi_open) in COEF_RANGES.items()}


def _aero(doc: XmlDoc) -> AeroParams:
    S, b, c = _geometry(doc)
    return AeroParams(S=S, b=b, c=c, **_pm_coefficients(doc, "aero/pm"))


def _propulsion(doc: XmlDoc) -> PropulsionParams:
    pv = doc.property_value
    return PropulsionParams(
        P0=pv("propulsion/pm/P0-W", lo=0.0, hi=1000.0),
        eta_prop=pv("propulsion/pm/eta-prop", lo=0.0, hi=1.0, lo_open=True),
        eta_motor=pv("propulsion/pm/eta-motor", lo=0.0, hi=1.0, lo_open=True),
        disk_area=pv("propulsion/pm/disk-area-m2", lo=0.0, hi=10.0, lo_open=True),
        PT0=pv("propulsion/pm/paper-PT0", lo=0.0),
        PT1=pv("propulsion/pm/paper-PT1", lo=0.0),
        PT2=pv("propulsion/pm/paper-PT2", lo=0.0),
        T_max=pv("propulsion/pm/T-max-N", lo=0.0, hi=1000.0, lo_open=True),
        T_avail_c1=pv("propulsion/pm/T-avail-c1", lo=-10.0, hi=0.0),
        T_avail_c2=pv("propulsion/pm/T-avail-c2", lo=-1.0, hi=0.0),
    )


def _load_aircraft_doc(path: str | Path) -> XmlDoc:
    """Parse an aircraft file and check every number JSBSim reads from it (:func:`check_numbers`)."""
    doc = XmlDoc.load(path)
    if doc.root.tag != "fdm_config":
        raise DefinitionError(doc.path, doc.root.tag, "root element must be <fdm_config>")
    check_numbers(doc)
    return doc


def is_foldable(doc: XmlDoc) -> bool:
    """Whether ``doc`` is the morphing aircraft (declares the two coefficient sets ``aero/unfolded/*``
    and ``aero/folded/*`` blended by the fold state)."""
    return any((el.text or "").strip().startswith(("aero/unfolded/", "aero/folded/")) for el in doc.root.iter("property"))


def _foldable(doc: XmlDoc) -> None:
    """The morphing aircraft: both coefficient sets (each form's own normalisation, the ranges
    of the static forms), the fold ratios of area and span (0 .. 1] and the fold time."""
    for form in ("unfolded", "folded"):
        _pm_coefficients(doc, f"aero/{form}")
        _stability(doc, f"aero/{form}")
    for ratio in ("S-ratio", "b-ratio"):
        doc.property_value(f"aero/fold/{ratio}", lo=0.0, hi=1.0, lo_open=True)
    doc.property_value("fcs/wing-fold-time-s", lo=0.0, hi=FOLD_TIME_MAX_S, lo_open=True, unit="s")
    if doc.find(".//actuator[@name='fcs/wing-fold-actuator']", required=False) is None:
        raise DefinitionError(doc.path, "flight_control/actuator[fcs/wing-fold-actuator]", "missing element (the fold actuator)")


def check_aircraft_file(path: str | Path, root: Path | None = None) -> XmlDoc:
    """Check a JSBSim aircraft file field by field before JSBSim loads it; returns it parsed.

    Every number JSBSim reads is a finite number (:func:`~.xmlutil.check_numbers`); geometry,
    mass (``<emptywt>`` > 0, inertia of a physical body), point-mass propulsion, controls,
    contacts and tether hook are range-checked; the aerodynamics of the static forms
    (``aero/pm/*``, ``aero/coef/*``) or, for the morphing aircraft, of both forms
    (``aero/unfolded/*``, ``aero/folded/*``), the fold ratios and the fold time; and the engine
    and propeller files it names (``engine/`` under ``root``, default the file's
    ``../../..``). Raises :class:`~fdm_awe.errors.DefinitionError` (file, element, allowed range).
    """
    from .engine import engine_files

    doc = _load_aircraft_doc(path)
    _geometry(doc)
    mass_params(doc)
    _propulsion(doc)
    airframe_checks(doc)
    if is_foldable(doc):
        _foldable(doc)
    else:
        _pm_coefficients(doc, "aero/pm")
        _stability(doc, "aero/coef")
    engine_files(doc, Path(path).resolve().parents[2] if root is None else Path(root))
    return doc


def load_airframe_file(path: str | Path, config: str = "custom") -> Airframe:
    """Read one static aircraft XML file into an :class:`Airframe`, checked as
    :func:`check_aircraft_file` checks it except for the engine files (DefinitionError: file,
    element, allowed range)."""
    doc = _load_aircraft_doc(path)
    if is_foldable(doc):
        raise DefinitionError(doc.path, "property aero/pm/CL0",
                              "a morphing aircraft (aero/unfolded/*, aero/folded/*) has no single static form; "
                              "load the unfolded or the folded form")
    airframe = Airframe(
        config=config,
        aircraft=doc.root.attrib.get("name", Path(path).stem),
        source=Path(path),
        aero=_aero(doc),
        mass=mass_params(doc),
        propulsion=_propulsion(doc),
    )
    _stability(doc, "aero/coef")
    airframe_checks(doc)
    return airframe


def load_airframe(config: str = "unfolded", aircraft: Any = None) -> Airframe:
    """Airframe of configuration ``config`` (``"unfolded"`` or ``"folded"``) of ``aircraft``
    (:func:`~.catalog.resolve_aircraft`: a table name, a definition folder, an
    :class:`~.catalog.Aircraft`; None: the package's glider)."""
    from .catalog import resolve_aircraft

    if config not in CONFIGS:
        raise InputError(f"configuration {config!r} unknown (allowed: {', '.join(CONFIGS)})")
    return load_airframe_file(resolve_aircraft(aircraft).path(config), config)


@dataclass(frozen=True)
class Glider:
    """The foldable glider's two configurations (same mass, same propulsion)."""

    unfolded: Airframe
    folded: Airframe

    def config(self, name: str) -> Airframe:
        return self.unfolded if name == "unfolded" else self.folded


def load_glider(aircraft: Any = None) -> Glider:
    """Both configurations of ``aircraft`` (as :func:`load_airframe`); checks that they describe
    the same vehicle (mass, propulsion)."""
    from .catalog import resolve_aircraft

    a = resolve_aircraft(aircraft)
    u = load_airframe("unfolded", a)
    f = load_airframe("folded", a)
    if abs(u.mass.mass - f.mass.mass) > 1e-9 * u.mass.mass:
        raise DefinitionError(f.source, "mass_balance", f"total mass {f.mass.mass:g} kg differs from the unfolded form's {u.mass.mass:g} kg")
    if u.propulsion != f.propulsion:
        raise DefinitionError(f.source, "system point-mass-propulsion", "propulsion values differ from the unfolded form's")
    return Glider(u, f)
