"""The 6-DOF glider's electric drive from its JSBSim engine files, for the point-mass models.

The aircraft file names the engine (``propulsion/engine@file``, a JSBSim ``brushless_dc_motor``:
Drela's three-constant model) and its propeller (``thruster@file``: diameter and the
``C_THRUST(J)``, ``C_POWER(J)`` tables). The point-mass side needs them in closed form: the
tables are fitted with quadratics in J on the working range ``0 <= J <= J_FIT_MAX`` (the
folding-blade fade beyond is not flown with the motor on), and a fit that misses a table value
by more than ``FIT_TOL`` is an error (the files carry the quadratics they were sampled from,
rounded to 1e-4).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from .. import ROOT
from ..errors import DefinitionError
from .xmlutil import XmlDoc, check_numbers

J_FIT_MAX = 0.95  #: upper end of the fitted advance-ratio range [-]
FIT_TOL = 5e-4  #: largest table residual of the quadratic fits [-]
_IN = 0.0254


@dataclass(frozen=True)
class ElectricDrive:
    """Propeller and motor of the 6-DOF glider (SI).

    ``diameter`` m; ``ct`` and ``cp`` the quadratic coefficients (c0, c1, c2) of
    ``C_T(J) = c0 + c1 J + c2 J^2`` and ``C_P(J)`` (J = V / (n D), n in rev/s); ``kv`` rpm/V;
    ``resistance`` ohm; ``no_load_current`` A; ``max_volts`` V; ``source`` the engine files.
    """

    diameter: float
    ct: tuple[float, float, float]
    cp: tuple[float, float, float]
    kv: float
    resistance: float
    no_load_current: float
    max_volts: float
    source: tuple[Path, Path]

    @property
    def torque_constant(self) -> float:
        """N m per A: 60 / (2 pi Kv)."""
        return 60.0 / (2.0 * math.pi * self.kv)


def _table(doc: XmlDoc, name: str) -> np.ndarray:
    el = doc.find(f"table[@name='{name}']/tableData")
    try:
        rows = np.array([[float(v) for v in line.split()] for line in (el.text or "").strip().splitlines()])
    except ValueError:
        rows = np.zeros((0, 0))
    if rows.ndim != 2 or rows.shape[1] != 2 or len(rows) < 3 or not np.all(np.diff(rows[:, 0]) > 0):
        raise DefinitionError(doc.path, f"table {name}", "need rows 'J value' with J increasing")
    return rows


def _fit(doc: XmlDoc, name: str) -> tuple[float, float, float]:
    rows = _table(doc, name)
    sel = rows[rows[:, 0] <= J_FIT_MAX + 1e-12]
    if len(sel) < 4:
        raise DefinitionError(doc.path, f"table {name}", f"need at least 4 rows with J <= {J_FIT_MAX}")
    c2, c1, c0 = np.polyfit(sel[:, 0], sel[:, 1], 2)
    res = float(np.max(np.abs(c0 + c1 * sel[:, 0] + c2 * sel[:, 0] ** 2 - sel[:, 1])))
    if res > FIT_TOL:
        raise DefinitionError(doc.path, f"table {name}",
                              f"not a quadratic in J on 0..{J_FIT_MAX} (largest residual {res:.2g}, allowed {FIT_TOL:g})")
    return float(c0), float(c1), float(c2)


def motor_constants(doc: XmlDoc) -> dict[str, float]:
    """The Drela constants of a ``brushless_dc_motor`` file, checked (numbers as written: JSBSim
    reads them in rpm/V, ohm, A and V)."""
    if doc.root.tag != "brushless_dc_motor":
        raise DefinitionError(doc.path, doc.root.tag, "root element must be <brushless_dc_motor> (the drive model of the package)")
    num = doc.number
    return {
        "kv": num("velocityconstant", lo=0.0, hi=1e5, lo_open=True, unit="rpm/V", convert=False),
        "resistance": num("coilresistance", lo=0.0, hi=100.0, lo_open=True, unit="ohm", convert=False),
        "no_load_current": num("noloadcurrent", lo=0.0, hi=1000.0, unit="A", convert=False),
        "max_volts": num("maxvolts", lo=0.0, hi=1e4, lo_open=True, unit="V", convert=False),
    }


def _propeller(doc: XmlDoc) -> float:
    """Checks a JSBSim ``propeller`` file (inertia, blades, tables); returns the diameter [m]."""
    if doc.root.tag != "propeller":
        raise DefinitionError(doc.path, doc.root.tag, "root element must be <propeller>")
    doc.number("ixx", lo=0.0, lo_open=True, hi=1.0, unit="kg m2")
    blades = doc.number("numblades", lo=1.0, hi=12.0, convert=False)
    if blades != int(blades):
        raise DefinitionError(doc.path, "numblades", f"value {blades:g} is not a whole number (allowed 1 .. 12 blades)")
    cs = doc.number("constspeed", default=0.0, convert=False)
    if cs not in (0.0, 1.0):
        raise DefinitionError(doc.path, "constspeed", f"value {cs:g} not allowed (allowed 0 or 1)")
    _table(doc, "C_THRUST")
    _table(doc, "C_POWER")
    d_el = doc.find("diameter")
    assert d_el is not None
    unit = d_el.attrib.get("unit", "IN").upper()
    scale = {"IN": _IN, "FT": 0.3048, "M": 1.0}.get(unit)
    if scale is None:
        raise DefinitionError(doc.path, "diameter", f"unit {unit!r} unknown (allowed IN, FT, M)")
    return doc.number("diameter", lo=0.0, hi=100.0, lo_open=True, unit=unit.lower(), convert=False) * scale


def engine_files(adoc: XmlDoc, root: Path | None = None) -> tuple[XmlDoc, XmlDoc]:
    """The motor and propeller files that aircraft file ``adoc`` names (``engine/NAME.xml`` under
    ``root``), both checked field by field (DefinitionError: file, element, allowed range)."""
    root = ROOT if root is None else Path(root)
    eng = adoc.find("propulsion/engine")
    thr = adoc.find("propulsion/engine/thruster")
    assert eng is not None and thr is not None
    if not eng.attrib.get("file") or not thr.attrib.get("file"):
        raise DefinitionError(adoc.origin(eng), "propulsion/engine", "engine and thruster need a file attribute (a file name in engine/)")
    mdoc = XmlDoc.load(root / "engine" / f"{eng.attrib['file']}.xml")
    pdoc = XmlDoc.load(root / "engine" / f"{thr.attrib['file']}.xml")
    for doc in (mdoc, pdoc):
        check_numbers(doc)
    motor_constants(mdoc)
    _propeller(pdoc)
    return mdoc, pdoc


def load_electric_drive(aircraft: Any = None) -> ElectricDrive:
    """The drive of ``aircraft``'s morphing aircraft (:func:`~.catalog.resolve_aircraft`: a table
    name, a definition folder, an :class:`~.catalog.Aircraft`; None: the package's glider) from
    the engine files it names (DefinitionError: file, element and allowed range)."""
    from .catalog import resolve_aircraft

    a = resolve_aircraft(aircraft)
    adoc = XmlDoc.load(a.path("foldable"))
    mdoc, pdoc = engine_files(adoc, a.root)
    return ElectricDrive(diameter=_propeller(pdoc), ct=_fit(pdoc, "C_THRUST"), cp=_fit(pdoc, "C_POWER"), **motor_constants(mdoc),
                         source=(mdoc.path, pdoc.path))


__all__ = ["ElectricDrive", "FIT_TOL", "J_FIT_MAX", "engine_files", "load_electric_drive", "motor_constants"]
