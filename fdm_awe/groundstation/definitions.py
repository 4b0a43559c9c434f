"""Ground-station definition file (``tether/ground_station.xml``) -> typed, SI parameters.

Every value in the file carries a ``unit`` attribute. Units known to
:data:`fdm_awe.units.TO_SI` (``M``, ``FT``, ``KG``, ``N``, ``KG*M2``, ...) are converted there;
the electrical and compound SI unit names used only by the ground station (``OHM``, ``H``,
``F``, ``V``, ``N*M``, ...) are accepted only when they are exactly the SI unit the field
expects (no conversion factor exists outside :mod:`fdm_awe.units`). Range checks and the
one-line errors come from :mod:`fdm_awe.definitions.xmlutil`.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

from .. import ROOT
from ..definitions.xmlutil import XmlDoc, element_number
from ..errors import DefinitionError
from ..units import TO_SI

#: Default ground-station definition file.
DEFAULT_PATH = ROOT / "tether" / "ground_station.xml"


@dataclass(frozen=True)
class TetherParams:
    """Tether line (SI)."""

    mass_per_length: float  #: mu, kg/m
    diameter: float  #: d_t, m
    cd_perpendicular: float  #: C_D of the line in cross flow, -
    axial_stiffness: float  #: EA, N
    breaking_load: float  #: tension at which the line breaks, N
    drag_share: float  #: share of the line drag carried by the glider, -
    weight_share: float  #: share of the line weight carried by the glider, -
    min_length: float  #: end stop when reeling in, m
    max_length: float  #: end stop when reeling out (drum capacity), m
    air_density: float  #: rho for the line drag, kg/m^3
    gravity: float  #: g for the line weight, m/s^2


@dataclass(frozen=True)
class WinchParams:
    """Winch drum (SI)."""

    radius: float  #: r_w, m
    inertia: float  #: J of drum + rotor, kg m^2
    mass: float  #: winch mass (informational), kg
    viscous_friction: float  #: B, N m s
    coulomb_friction: float  #: M_c (counted once), N m


@dataclass(frozen=True)
class DcMachineParams:
    """Permanent-magnet DC machine (SI). ``k`` is both K_e [V s/rad] and K_t [N m/A]."""

    k: float  #: motor constant K_e = K_t
    resistance: float  #: armature resistance R, ohm
    inductance: float  #: armature inductance L_a, H


@dataclass(frozen=True)
class ConverterParams:
    """Asymmetric half-bridge converter (SI)."""

    device_drop: float  #: U_d per diode/switch, V (two devices in every path)
    supply_voltage: float  #: V_a, V
    link_capacitance: float  #: C_Link, F
    load_resistance: float  #: default R_L, ohm
    boost_duty: float  #: default T2 duty in generator mode, - (0 = passive rectifier)


@dataclass(frozen=True)
class SpeedControllerParams:
    """PI controller of the T1 duty on the drum-speed error (SI)."""

    kp: float  #: duty per rad/s
    ki: float  #: duty per rad (per rad/s per s)
    duty_min: float  #: -
    duty_max: float  #: -


@dataclass(frozen=True)
class IntegrationParams:
    """Internal integrator settings."""

    max_substep: float  #: longest implicit sub-step, s


@dataclass(frozen=True)
class GroundStationParams:
    """All ground-station parameters, SI, as read from one definition file."""

    tether: TetherParams
    winch: WinchParams
    machine: DcMachineParams
    converter: ConverterParams
    controller: SpeedControllerParams
    integration: IntegrationParams
    path: str  #: file the parameters came from (for messages)


def _value(doc: XmlDoc, xpath: str, si_unit: str, *, lo: float | None = None,
           hi: float | None = None, lo_open: bool = False) -> float:
    """Number at ``xpath`` in SI. ``si_unit`` is the SI unit name the field expects."""
    el = doc.find(xpath)
    assert el is not None
    unit = el.attrib.get("unit")
    if unit is None:
        raise DefinitionError(doc.path, xpath, f"missing unit attribute (expected unit=\"{si_unit}\")")
    u = unit.strip().upper()
    if u == si_unit:
        bare = ET.Element(el.tag)  # SI already: check number and range without conversion
        bare.text = el.text
        return element_number(doc.path, xpath, bare, lo=lo, hi=hi, lo_open=lo_open)
    if u in TO_SI and si_unit in TO_SI and TO_SI[si_unit] == 1.0 and _same_dimension(u, si_unit):
        return element_number(doc.path, xpath, el, lo=lo, hi=hi, lo_open=lo_open)
    raise DefinitionError(doc.path, xpath, f"unit {unit!r} not allowed here (expected {si_unit})")


# Dimension families of the TO_SI units a ground-station field may use.
_DIMENSION = {
    "M": "L", "FT": "L", "IN": "L",
    "KG": "M", "LBS": "M", "SLUG": "M",
    "N": "F", "LBS_FORCE": "F",
    "KG*M2": "I", "SLUG*FT2": "I",
    "S": "T", "SEC": "T",
    "M/S": "V", "FT/SEC": "V",
}


def _same_dimension(a: str, b: str) -> bool:
    return a in _DIMENSION and _DIMENSION.get(a) == _DIMENSION.get(b)


def load_ground_station(path: str | Path | None = None) -> GroundStationParams:
    """Read and validate a ground-station definition file (default ``tether/ground_station.xml``).

    Raises :class:`fdm_awe.errors.DefinitionError` (one line: file, element, allowed range)
    on a missing file, element, unit or an out-of-range value.
    """
    doc = XmlDoc.load(DEFAULT_PATH if path is None else path)
    if doc.root.tag != "ground_station":
        raise DefinitionError(doc.path, doc.root.tag, "root element must be <ground_station>")
    v = lambda xp, u, **kw: _value(doc, xp, u, **kw)  # noqa: E731

    tether = TetherParams(
        mass_per_length=v("tether/mass_per_length", "KG/M", lo=0.0),
        diameter=v("tether/diameter", "M", lo=0.0, hi=0.05),
        cd_perpendicular=v("tether/cd_perpendicular", "ND", lo=0.0, hi=3.0),
        axial_stiffness=v("tether/axial_stiffness", "N", lo=0.0, lo_open=True),
        breaking_load=v("tether/breaking_load", "N", lo=0.0, lo_open=True),
        drag_share=v("tether/drag_share", "ND", lo=0.0, hi=1.0),
        weight_share=v("tether/weight_share", "ND", lo=0.0, hi=1.0),
        min_length=v("tether/min_length", "M", lo=0.0, lo_open=True),
        max_length=v("tether/max_length", "M", lo=0.0, lo_open=True),
        air_density=v("tether/air_density", "KG/M3", lo=0.0, hi=2.0, lo_open=True),
        gravity=v("tether/gravity", "M/S2", lo=0.0, hi=20.0, lo_open=True),
    )
    if tether.max_length <= tether.min_length:
        raise DefinitionError(doc.path, "tether/max_length",
                              f"value {tether.max_length:g} must exceed tether/min_length {tether.min_length:g}")
    winch = WinchParams(
        radius=v("winch/radius", "M", lo=0.0, lo_open=True, hi=2.0),
        inertia=v("winch/inertia", "KG*M2", lo=0.0, lo_open=True),
        mass=v("winch/mass", "KG", lo=0.0),
        viscous_friction=v("winch/viscous_friction", "N*M*S", lo=0.0),
        coulomb_friction=v("winch/coulomb_friction", "N*M", lo=0.0),
    )
    machine = DcMachineParams(
        k=v("dc_machine/motor_constant", "V*S/RAD", lo=0.0, lo_open=True),
        resistance=v("dc_machine/armature_resistance", "OHM", lo=0.0, lo_open=True),
        inductance=v("dc_machine/armature_inductance", "H", lo=0.0, lo_open=True),
    )
    converter = ConverterParams(
        device_drop=v("converter/device_drop", "V", lo=0.0),
        supply_voltage=v("converter/supply_voltage", "V", lo=0.0, lo_open=True),
        link_capacitance=v("converter/link_capacitance", "F", lo=0.0, lo_open=True),
        load_resistance=v("converter/load_resistance", "OHM", lo=0.0, lo_open=True),
        boost_duty=v("converter/boost_duty", "ND", lo=0.0, hi=1.0),
    )
    if 2.0 * converter.device_drop >= converter.supply_voltage:
        raise DefinitionError(doc.path, "converter/device_drop",
                              f"value {converter.device_drop:g} V out of range (allowed < half the supply voltage "
                              f"{converter.supply_voltage:g} V: every current path holds two devices)")
    controller = SpeedControllerParams(
        kp=v("speed_controller/kp", "S/RAD", lo=0.0),
        ki=v("speed_controller/ki", "1/RAD", lo=0.0),
        duty_min=v("speed_controller/duty_min", "ND", lo=0.0, hi=1.0),
        duty_max=v("speed_controller/duty_max", "ND", lo=0.0, hi=1.0),
    )
    if controller.duty_max <= controller.duty_min:
        raise DefinitionError(doc.path, "speed_controller/duty_max",
                              f"value {controller.duty_max:g} must exceed duty_min {controller.duty_min:g}")
    integration = IntegrationParams(
        max_substep=v("integration/max_substep", "S", lo=1e-6, hi=0.01),
    )
    return GroundStationParams(tether, winch, machine, converter, controller, integration, str(doc.path))
