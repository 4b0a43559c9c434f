"""Ground-station definition file (``tether/ground_station.xml``) -> typed, SI parameters.

The file holds named tether lines (``<tether><line name="...">``, :data:`.line.LINES`); one of
them is selected per load (default :data:`.line.DEFAULT_LINE`), and every line in the file is
checked whichever is selected. A line either gives its material and sizing (its section derived
by :func:`.line.size_line`) or states its section (Table 1's line). A line's specific strength
and modulus are written in ``N/TEX`` (newton per tex) and converted with :data:`.line.N_PER_TEX`.

Every value in the file carries a ``unit`` attribute. Units known to
:data:`fdm_awe.units.TO_SI` (``M``, ``FT``, ``KG``, ``N``, ``KG*M2``, ...) are converted there;
the electrical and compound SI unit names used only by the ground station (``OHM``, ``H``,
``F``, ``V``, ``N*M``, ...) are accepted only when they are exactly the SI unit the field
expects (no conversion factor exists outside :mod:`fdm_awe.units`). Range checks and the
one-line errors come from :mod:`fdm_awe.definitions.xmlutil`.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from .. import ROOT
from ..constants import G0, RHO0
from ..definitions.xmlutil import XmlDoc, element_number
from ..errors import DefinitionError
from ..units import TO_SI
from .line import DEFAULT_LINE, LINES, N_PER_TEX, LineMaterial, LineSizing, LineSection, check_line, size_line

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
    air_density: float  #: rho for the line drag, kg/m^3 (:data:`fdm_awe.constants.RHO0`)
    gravity: float  #: g for the line weight, m/s^2 (:data:`fdm_awe.constants.G0`)
    name: str = "custom"  #: line name in the definition (:data:`.line.LINES`)
    rated_tension: float | None = None  #: working tension the line is rated for, N
    material: LineMaterial | None = None  #: what a sized line is made of (None: section as stated)
    sizing: LineSizing | None = None  #: what a sized line was sized for (None: section as stated)
    #: the optimiser's calibrated straight-line model (``tether/calibrated``, one per glider
    #: configuration, :mod:`.line`): ``(config, drag share, weight share, wind share, recovery
    #: tension N)`` each: the glider's shares of the line drag from its own air velocity, of the
    #: line weight and of the drag of the still line in the wind, and the line tension at the
    #: winch while reeling in, fitted to flights on the lumped line (none: the straight line's)
    calibrated: tuple[tuple[str, float, float, float, float], ...] = ()

    def calibrated_line(self, config: str) -> tuple[float, float, float, float]:
        """The calibrated model's (drag share, weight share, wind share, recovery tension N) of
        the glider configuration ``config``; the straight line's (1/4, 1/2, 0, 0 N) where the
        definition holds none for it."""
        for c, *values in self.calibrated:
            if c == config:
                return tuple(values)  # type: ignore[return-value]
        return (0.25, 0.5, 0.0, 0.0)

    @property
    def safety_factor(self) -> float | None:
        """Breaking load / rated tension, - (None without a rated tension)."""
        return None if self.rated_tension is None else self.breaking_load / self.rated_tension


@dataclass(frozen=True)
class WinchParams:
    """Winch drum (SI)."""

    radius: float  #: r_w, m
    inertia: float  #: J of drum + rotor, kg m^2
    mass: float  #: winch mass (informational), kg
    viscous_friction: float  #: B, N m s
    coulomb_friction: float  #: M_c (counted once), N m
    #: the reel-in speed the drive is sized for (the glider's fall-back speed), m/s; NaN: not given
    design_reel_in_speed: float = float("nan")


@dataclass(frozen=True)
class DcMachineParams:
    """Permanent-magnet DC machine (SI). ``k`` is both K_e [V s/rad] and K_t [N m/A]."""

    k: float  #: motor constant K_e = K_t
    resistance: float  #: armature resistance R, ohm
    inductance: float  #: armature inductance L_a, H
    rated_current: float  #: rated continuous armature current, A
    peak_current: float  #: armature current allowed for a few seconds, A (>= rated_current)


@dataclass(frozen=True)
class ConverterParams:
    """Asymmetric half-bridge converter (SI)."""

    device_drop: float  #: U_d per diode/switch, V (two devices in every path)
    supply_voltage: float  #: V_a, V
    link_capacitance: float  #: C_Link, F
    load_resistance: float  #: default R_L, ohm
    boost_duty: float  #: default T2 duty in generator mode, - (0 = passive rectifier)
    #: current limit of the motor mode, A (<= the machine's peak current)
    current_limit: float
    #: largest T2 duty in generator mode, - (the bound of the optimiser's boost-duty control)
    boost_duty_max: float = 0.8
    #: the line tension above which the converter lowers its current limit (the upper-force
    #: controller acting on the measured tension every sub-step), N; inf: off
    tension_limit: float = math.inf
    #: the tension above ``tension_limit`` over which that limit falls to 0 A, N
    tension_limit_band: float = 10.0


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
    return _element_value(doc.path, xpath, el, si_unit, lo=lo, hi=hi, lo_open=lo_open)


def _element_value(path: Path, what: str, el: ET.Element, si_unit: str, *, lo: float | None = None,
                   hi: float | None = None, lo_open: bool = False) -> float:
    """Number of element ``el`` (named ``what`` in messages) in SI; see :func:`_value`."""
    unit = el.attrib.get("unit")
    if unit is None:
        raise DefinitionError(path, what, f"missing unit attribute (expected unit=\"{si_unit}\")")
    u = unit.strip().upper()
    if u == si_unit:
        bare = ET.Element(el.tag)  # SI already: check number and range without conversion
        bare.text = el.text
        return element_number(path, what, bare, lo=lo, hi=hi, lo_open=lo_open)
    if u in TO_SI and si_unit in TO_SI and TO_SI[si_unit] == 1.0 and _same_dimension(u, si_unit):
        return element_number(path, what, el, lo=lo, hi=hi, lo_open=lo_open)
    raise DefinitionError(path, what, f"unit {unit!r} not allowed here (expected {si_unit})")


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


#: largest rated or peak armature current, A (a check of the typed number, not a machine's size)
_CURRENT_MAX = 1000.0
#: the largest tension limit and band a converter takes, N
_TENSION_LIMIT_MAX = 1.0e5
#: the section elements a line states when it is not sized from a material (Table 1's line)
_STATED = ("mass_per_length", "diameter", "cd_perpendicular", "axial_stiffness", "breaking_load")
#: largest line diameter, m (stated or derived)
_DIAMETER_MAX = 0.05


def _specific(path: Path, what: str, el: ET.Element, *, hi: float) -> float:
    """A specific strength or modulus written in N/tex (``unit="N/TEX"``), > 0 and <= ``hi``
    N/tex, returned in SI (N m/kg)."""
    return _element_value(path, what, el, "N/TEX", lo=0.0, lo_open=True, hi=hi) * N_PER_TEX


def _line_elements(doc: XmlDoc) -> dict[str, ET.Element]:
    """The ``<line name=...>`` elements of ``<tether>`` by name: every name one of
    :data:`.line.LINES`, each at most once."""
    found: dict[str, ET.Element] = {}
    for el in doc.root.findall("tether/line"):
        name = el.attrib.get("name")
        if name is None:
            raise DefinitionError(doc.path, "tether/line", f"missing name attribute (allowed {', '.join(LINES)})")
        if name not in LINES:
            raise DefinitionError(doc.path, f"tether/line[{name}]", f"line name {name!r} not allowed (allowed {', '.join(LINES)})")
        if name in found:
            raise DefinitionError(doc.path, f"tether/line[{name}]", "defined twice (allowed once per name)")
        found[name] = el
    return found


def _child(path: Path, el: ET.Element, where: str, tag: str) -> ET.Element:
    c = el.find(tag)
    if c is None:
        raise DefinitionError(path, f"{where}/{tag}", "missing element")
    return c


def _read_line(path: Path, name: str, el: ET.Element) -> tuple[LineSection, float, LineMaterial | None, LineSizing | None]:
    """Section, rated tension and (for a sized line) material and sizing of one ``<line>``."""
    where = f"tether/line[{name}]"

    def num(parent: ET.Element, at: str, tag: str, unit: str, **kw: Any) -> float:
        return _element_value(path, f"{at}/{tag}", _child(path, parent, at, tag), unit, **kw)

    sizing_el = el.find("sizing")
    if sizing_el is None:  # the section as stated (Table 1's line)
        section = LineSection(
            mass_per_length=num(el, where, "mass_per_length", "KG/M", lo=0.0),
            diameter=num(el, where, "diameter", "M", lo=0.0, hi=_DIAMETER_MAX),
            axial_stiffness=num(el, where, "axial_stiffness", "N", lo=0.0, lo_open=True),
            breaking_load=num(el, where, "breaking_load", "N", lo=0.0, lo_open=True),
            cd_perpendicular=num(el, where, "cd_perpendicular", "ND", lo=0.0, hi=3.0),
        )
        rated = num(el, where, "rated_tension", "N", lo=0.0, lo_open=True, hi=1e6)
        if section.breaking_load < rated:
            raise DefinitionError(path, f"{where}/breaking_load", f"value {section.breaking_load:g} N out of range "
                                                                  f"(allowed >= {where}/rated_tension {rated:g} N)")
        return section, rated, None, None
    for tag in _STATED + ("rated_tension",):
        if el.find(tag) is not None:
            raise DefinitionError(path, f"{where}/{tag}", "not allowed beside <sizing> (a sized line derives it; "
                                                          "allowed: material + sizing, or the stated section without sizing)")
    mat_el = _child(path, el, where, "material")
    m, z = f"{where}/material", f"{where}/sizing"
    material = LineMaterial(
        fibre_density=num(mat_el, m, "fibre_density", "KG/M3", lo=0.0, lo_open=True, hi=20000.0),
        rated_tenacity=_specific(path, f"{m}/rated_tenacity", _child(path, mat_el, m, "rated_tenacity"), hi=10.0),
        fill_factor=num(mat_el, m, "fill_factor", "ND", lo=0.0, lo_open=True, hi=1.0),
        fibre_modulus=_specific(path, f"{m}/fibre_modulus", _child(path, mat_el, m, "fibre_modulus"), hi=1000.0),
        stiffness_factor=num(mat_el, m, "stiffness_factor", "ND", lo=0.0, lo_open=True, hi=1.0),
        cd_perpendicular=num(mat_el, m, "cd_perpendicular", "ND", lo=0.0, hi=3.0),
    )
    sizing = LineSizing(
        rated_tension=num(sizing_el, z, "rated_tension", "N", lo=0.0, lo_open=True, hi=1e6),
        safety_factor=num(sizing_el, z, "safety_factor", "ND", lo=1.0, hi=20.0),
    )
    section = size_line(material, sizing)
    if section.diameter > _DIAMETER_MAX:
        raise DefinitionError(path, z, f"derived diameter {section.diameter * 1e3:.4g} mm out of range "
                                       f"(allowed <= {_DIAMETER_MAX * 1e3:g} mm)")
    return section, sizing.rated_tension, material, sizing


def load_ground_station(path: str | Path | None = None, line: str | None = None) -> GroundStationParams:
    """Read and validate a ground-station definition file (default ``tether/ground_station.xml``)
    with the tether line ``line`` (one of :data:`.line.LINES`; None = :data:`.line.DEFAULT_LINE`).

    Raises :class:`fdm_awe.errors.InputError` (one line, the allowed names) on an unknown line
    name, before the file is read, and :class:`fdm_awe.errors.DefinitionError` (one line: file,
    element, allowed range) on a missing file, element, unit or an out-of-range value; every
    line of the file is checked, whichever is selected.
    """
    name = DEFAULT_LINE if line is None else check_line(line)
    doc = XmlDoc.load(DEFAULT_PATH if path is None else path)
    if doc.root.tag != "ground_station":
        raise DefinitionError(doc.path, doc.root.tag, "root element must be <ground_station>")
    machine = _read_machine(doc)
    return GroundStationParams(_read_tether(doc, name), _read_winch(doc), machine, _read_converter(doc, machine),
                               _read_controller(doc), _read_integration(doc), str(doc.path))


def _read_tether(doc: XmlDoc, name: str) -> TetherParams:
    """``<tether>`` with the line ``name`` (every line of the file is read and checked)."""
    lines = {n: _read_line(doc.path, n, el) for n, el in _line_elements(doc).items()}
    if name not in lines:
        have = ", ".join(lines) or "none"
        raise DefinitionError(doc.path, f"tether/line[{name}]", f"missing element (lines in this file: {have})")
    section, rated, material, sizing = lines[name]
    tether = TetherParams(
        mass_per_length=section.mass_per_length,
        diameter=section.diameter,
        cd_perpendicular=section.cd_perpendicular,
        axial_stiffness=section.axial_stiffness,
        breaking_load=section.breaking_load,
        drag_share=_value(doc, "tether/drag_share", "ND", lo=0.0, hi=1.0),
        weight_share=_value(doc, "tether/weight_share", "ND", lo=0.0, hi=1.0),
        min_length=_value(doc, "tether/min_length", "M", lo=0.0, lo_open=True),
        max_length=_value(doc, "tether/max_length", "M", lo=0.0, lo_open=True),
        air_density=RHO0,
        gravity=G0,
        name=name,
        rated_tension=rated,
        material=material,
        sizing=sizing,
        calibrated=_calibrated(doc),
    )
    if tether.max_length <= tether.min_length:
        raise DefinitionError(doc.path, "tether/max_length",
                              f"value {tether.max_length:g} must exceed tether/min_length {tether.min_length:g}")
    return tether


#: the glider configurations a ``tether/calibrated`` block names (the reference files' configurations)
CALIBRATED_CONFIGS = ("nominal", "foldable")


def _calibrated(doc: XmlDoc) -> tuple[tuple[str, float, float, float, float], ...]:
    """The ``tether/calibrated`` blocks (optional; at most one per configuration, named by their
    ``config`` attribute): drag, weight and wind shares (0..1 each) and the recovery tension
    (N, >= 0) of the optimiser's calibrated line model."""
    out: list[tuple[str, float, float, float, float]] = []
    for el in doc.root.findall("tether/calibrated"):
        config = el.attrib.get("config")
        where = f"tether/calibrated[{config}]"
        if config not in CALIBRATED_CONFIGS:
            raise DefinitionError(doc.path, "tether/calibrated",
                                  f"config attribute {config!r} not allowed (allowed {', '.join(CALIBRATED_CONFIGS)})")
        if any(c == config for c, *_ in out):
            raise DefinitionError(doc.path, where, "defined twice (allowed once per configuration)")
        values = []
        for tag, unit, hi in (("drag_share", "ND", 1.0), ("weight_share", "ND", 1.0), ("wind_share", "ND", 1.0),
                              ("recovery_tension", "N", 1e4)):
            values.append(_element_value(doc.path, f"{where}/{tag}", _child(doc.path, el, where, tag), unit, lo=0.0, hi=hi))
        out.append((config, *values))  # type: ignore[arg-type]
    return tuple(out)


def _read_winch(doc: XmlDoc) -> WinchParams:
    """``<winch>`` (``design_reel_in_speed`` optional)."""
    return WinchParams(
        radius=_value(doc, "winch/radius", "M", lo=0.0, lo_open=True, hi=2.0),
        inertia=_value(doc, "winch/inertia", "KG*M2", lo=0.0, lo_open=True),
        mass=_value(doc, "winch/mass", "KG", lo=0.0),
        viscous_friction=_value(doc, "winch/viscous_friction", "N*M*S", lo=0.0),
        coulomb_friction=_value(doc, "winch/coulomb_friction", "N*M", lo=0.0),
        design_reel_in_speed=(_value(doc, "winch/design_reel_in_speed", "M/S", lo=0.0, lo_open=True, hi=50.0)
                              if doc.find("winch/design_reel_in_speed") is not None else float("nan")),
    )


def _read_machine(doc: XmlDoc) -> DcMachineParams:
    """``<dc_machine>``: the peak current not below the rated current."""
    machine = DcMachineParams(
        k=_value(doc, "dc_machine/motor_constant", "V*S/RAD", lo=0.0, lo_open=True),
        resistance=_value(doc, "dc_machine/armature_resistance", "OHM", lo=0.0, lo_open=True),
        inductance=_value(doc, "dc_machine/armature_inductance", "H", lo=0.0, lo_open=True),
        rated_current=_value(doc, "dc_machine/rated_current", "A", lo=0.0, lo_open=True, hi=_CURRENT_MAX),
        peak_current=_value(doc, "dc_machine/peak_current", "A", lo=0.0, lo_open=True, hi=_CURRENT_MAX),
    )
    if machine.peak_current < machine.rated_current:
        raise DefinitionError(doc.path, "dc_machine/peak_current",
                              f"value {machine.peak_current:g} A out of range (allowed >= dc_machine/rated_current "
                              f"{machine.rated_current:g} A)")
    return machine


def _read_converter(doc: XmlDoc, machine: DcMachineParams) -> ConverterParams:
    """``<converter>``: the boost duty within its largest value, two device drops below the supply,
    the current limit within the ``machine``'s peak current."""
    converter = ConverterParams(
        device_drop=_value(doc, "converter/device_drop", "V", lo=0.0),
        supply_voltage=_value(doc, "converter/supply_voltage", "V", lo=0.0, lo_open=True),
        link_capacitance=_value(doc, "converter/link_capacitance", "F", lo=0.0, lo_open=True),
        load_resistance=_value(doc, "converter/load_resistance", "OHM", lo=0.0, lo_open=True),
        boost_duty=_value(doc, "converter/boost_duty", "ND", lo=0.0, hi=1.0),
        boost_duty_max=_value(doc, "converter/boost_duty_max", "ND", lo=0.0, hi=0.95),
        current_limit=_value(doc, "converter/current_limit", "A", lo=0.0, lo_open=True, hi=_CURRENT_MAX),
        tension_limit=_value(doc, "converter/tension_limit", "N", lo=0.0, lo_open=True, hi=_TENSION_LIMIT_MAX),
        tension_limit_band=_value(doc, "converter/tension_limit_band", "N", lo=0.0, lo_open=True,
                                  hi=_TENSION_LIMIT_MAX),
    )
    if converter.current_limit > machine.peak_current:
        raise DefinitionError(doc.path, "converter/current_limit",
                              f"value {converter.current_limit:g} A out of range (allowed <= dc_machine/peak_current "
                              f"{machine.peak_current:g} A)")
    if converter.boost_duty > converter.boost_duty_max:
        raise DefinitionError(doc.path, "converter/boost_duty",
                              f"value {converter.boost_duty:g} out of range (allowed 0 .. boost_duty_max "
                              f"{converter.boost_duty_max:g})")
    if 2.0 * converter.device_drop >= converter.supply_voltage:
        raise DefinitionError(doc.path, "converter/device_drop",
                              f"value {converter.device_drop:g} V out of range (allowed < half the supply voltage "
                              f"{converter.supply_voltage:g} V: every current path holds two devices)")
    return converter


def _read_controller(doc: XmlDoc) -> SpeedControllerParams:
    """``<speed_controller>``: the duty range not empty."""
    controller = SpeedControllerParams(
        kp=_value(doc, "speed_controller/kp", "S/RAD", lo=0.0),
        ki=_value(doc, "speed_controller/ki", "1/RAD", lo=0.0),
        duty_min=_value(doc, "speed_controller/duty_min", "ND", lo=0.0, hi=1.0),
        duty_max=_value(doc, "speed_controller/duty_max", "ND", lo=0.0, hi=1.0),
    )
    if controller.duty_max <= controller.duty_min:
        raise DefinitionError(doc.path, "speed_controller/duty_max",
                              f"value {controller.duty_max:g} must exceed duty_min {controller.duty_min:g}")
    return controller


def _read_integration(doc: XmlDoc) -> IntegrationParams:
    """``<integration>``."""
    return IntegrationParams(max_substep=_value(doc, "integration/max_substep", "S", lo=1e-6, hi=0.01))
