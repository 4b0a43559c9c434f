"""Airframe parameters read from the JSBSim aircraft definitions (the single source of truth).

The point-mass model, the optimiser and the 6-DOF model all read the same numbers from the
same XML files: ``aircraft/glider_unfolded/glider_unfolded.xml`` (unfolded configuration) and
``aircraft/glider_folded/glider_folded.xml`` (folded configuration). Nothing here holds a copy
of an airframe number.

Named values the XML must declare (JSBSim ``<property value="...">NAME</property>``):

- in ``<aerodynamics>``: ``aero/pm/CL0``, ``aero/pm/CLalpha`` [1/rad], ``aero/pm/CLmax``,
  ``aero/pm/CD0``, ``aero/pm/CDalpha1`` [1/rad], ``aero/pm/CDalpha2`` [1/rad^2]
  (paper eqs. 32/46: C_L = C_L0 + C_La a, C_D = C_D0 + C_Da1 a + C_Da2 a^2);
- anywhere (an inline ``<system name="point-mass-propulsion">``): ``propulsion/pm/P0-W``,
  ``propulsion/pm/eta-prop``, ``propulsion/pm/eta-motor``, ``propulsion/pm/disk-area-m2``,
  ``propulsion/pm/paper-PT0``, ``propulsion/pm/paper-PT1``, ``propulsion/pm/paper-PT2``,
  ``propulsion/pm/T-max-N``, ``propulsion/pm/T-avail-c1``, ``propulsion/pm/T-avail-c2``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .. import ROOT
from ..errors import DefinitionError, InputError
from .xmlutil import XmlDoc, element_number, location

#: Configuration name -> JSBSim aircraft name of its static definition.
CONFIG_AIRCRAFT: dict[str, str] = {"unfolded": "glider_unfolded", "folded": "glider_folded"}


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
        """Full-throttle thrust [N] at airspeed ``V`` [m/s]: ``T_max + c1 V + c2 V^2``."""
        return self.T_max + self.T_avail_c1 * V + self.T_avail_c2 * V * V


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


def _mass(doc: XmlDoc) -> MassParams:
    mb = doc.find("mass_balance")
    assert mb is not None
    m_e = doc.number("mass_balance/emptywt", lo=0.0, lo_open=True)
    cg_el = doc.find("mass_balance/location")
    assert cg_el is not None
    cg_e = np.array(location(doc.path, cg_el, "mass_balance/location"))
    ixx = doc.number("mass_balance/ixx", lo=0.0, lo_open=True)
    iyy = doc.number("mass_balance/iyy", lo=0.0, lo_open=True)
    izz = doc.number("mass_balance/izz", lo=0.0, lo_open=True)
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
            raise DefinitionError(doc.path, what, "needs <weight> and <location>")
        m_i = element_number(doc.path, f"{what}/weight", w, lo=0.0)
        masses.append((m_i, np.array(location(doc.path, loc, f"{what}/location")), np.zeros((3, 3))))
    M = sum(m for m, _, _ in masses)
    cg = sum(m * r for m, r, _ in masses) / M
    Jt = np.zeros((3, 3))
    # Structural frame is x aft, y right, z up; body axes flip x and z, which leaves the
    # parallel-axis terms (including the xz product) unchanged.
    flip = np.array([-1.0, 1.0, -1.0])
    for m, r, Ji in masses:
        d = (r - cg) * flip
        Jt += Ji + m * (d @ d * np.eye(3) - np.outer(d, d))
    return MassParams(mass=float(M), cg_structural=tuple(float(v) for v in cg), inertia=tuple(tuple(float(v) for v in row) for row in Jt))


def _aero(doc: XmlDoc) -> AeroParams:
    pv = doc.property_value
    return AeroParams(
        S=doc.number("metrics/wingarea", lo=0.0, lo_open=True),
        b=doc.number("metrics/wingspan", lo=0.0, lo_open=True),
        c=doc.number("metrics/chord", lo=0.0, lo_open=True),
        CL0=pv("aero/pm/CL0", lo=-1.0, hi=1.5),
        CLalpha=pv("aero/pm/CLalpha", lo=0.0, hi=2 * math.pi, lo_open=True),
        CLmax=pv("aero/pm/CLmax", lo=0.0, hi=3.0, lo_open=True),
        CD0=pv("aero/pm/CD0", lo=0.0, hi=1.0, lo_open=True),
        CDalpha1=pv("aero/pm/CDalpha1", lo=-5.0, hi=5.0),
        CDalpha2=pv("aero/pm/CDalpha2", lo=0.0, hi=50.0),
    )


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


def load_airframe_file(path: str | Path, config: str = "custom") -> Airframe:
    """Read one aircraft XML file into an :class:`Airframe` (raises DefinitionError)."""
    doc = XmlDoc.load(path)
    if doc.root.tag != "fdm_config":
        raise DefinitionError(doc.path, doc.root.tag, "root element must be <fdm_config>")
    return Airframe(
        config=config,
        aircraft=doc.root.attrib.get("name", Path(path).stem),
        source=Path(path),
        aero=_aero(doc),
        mass=_mass(doc),
        propulsion=_propulsion(doc),
    )


def load_airframe(config: str = "unfolded", root: Path | None = None) -> Airframe:
    """Airframe of configuration ``config`` (``"unfolded"`` or ``"folded"``)."""
    if config not in CONFIG_AIRCRAFT:
        raise InputError(f"configuration {config!r} unknown (allowed: {', '.join(CONFIG_AIRCRAFT)})")
    return load_airframe_file(aircraft_path(CONFIG_AIRCRAFT[config], root), config)


@dataclass(frozen=True)
class Glider:
    """The foldable glider's two configurations (same mass, same propulsion)."""

    unfolded: Airframe
    folded: Airframe

    def config(self, name: str) -> Airframe:
        return self.unfolded if name == "unfolded" else self.folded


def load_glider(root: Path | None = None) -> Glider:
    """Both configurations; checks that they describe the same vehicle (mass, propulsion)."""
    u = load_airframe("unfolded", root)
    f = load_airframe("folded", root)
    if abs(u.mass.mass - f.mass.mass) > 1e-9 * u.mass.mass:
        raise DefinitionError(f.source, "mass_balance", f"total mass {f.mass.mass:g} kg differs from the unfolded form's {u.mass.mass:g} kg")
    if u.propulsion != f.propulsion:
        raise DefinitionError(f.source, "system point-mass-propulsion", "propulsion values differ from the unfolded form's")
    return Glider(u, f)
