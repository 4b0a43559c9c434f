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

import numpy as np

from .. import ROOT
from ..errors import DefinitionError
from .xmlutil import XmlDoc

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


def load_electric_drive(aircraft: str = "glider_foldable", root: Path | None = None) -> ElectricDrive:
    """The drive of ``aircraft/NAME/NAME.xml`` from the engine files it names (DefinitionError:
    file, element and allowed range)."""
    root = ROOT if root is None else Path(root)
    adoc = XmlDoc.load(root / "aircraft" / aircraft / f"{aircraft}.xml")
    eng = adoc.find("propulsion/engine")
    thr = adoc.find("propulsion/engine/thruster")
    if "file" not in eng.attrib or "file" not in thr.attrib:
        raise DefinitionError(adoc.path, "propulsion/engine", "engine and thruster need a file attribute")
    mdoc = XmlDoc.load(root / "engine" / f"{eng.attrib['file']}.xml")
    pdoc = XmlDoc.load(root / "engine" / f"{thr.attrib['file']}.xml")
    if mdoc.root.tag != "brushless_dc_motor":
        raise DefinitionError(mdoc.path, mdoc.root.tag, "the point-mass drive model needs a brushless_dc_motor")

    def num(doc: XmlDoc, tag: str, lo: float, hi: float) -> float:
        el = doc.find(tag)
        try:
            v = float((el.text or "").strip())
        except ValueError:
            v = math.nan
        if not (lo < v <= hi):
            raise DefinitionError(doc.path, tag, f"value {el.text!r} out of range (allowed > {lo:g} and <= {hi:g})")
        return v

    d_el = pdoc.find("diameter")
    unit = d_el.attrib.get("unit", "IN").upper()
    scale = {"IN": _IN, "FT": 0.3048, "M": 1.0}.get(unit)
    if scale is None:
        raise DefinitionError(pdoc.path, "diameter", f"unit {unit!r} unknown (allowed IN, FT, M)")
    diameter = num(pdoc, "diameter", 0.0, 100.0) * scale
    return ElectricDrive(
        diameter=diameter, ct=_fit(pdoc, "C_THRUST"), cp=_fit(pdoc, "C_POWER"),
        kv=num(mdoc, "velocityconstant", 0.0, 1e5), resistance=num(mdoc, "coilresistance", 0.0, 100.0),
        no_load_current=num(mdoc, "noloadcurrent", -1e-12, 1000.0), max_volts=num(mdoc, "maxvolts", 0.0, 1e4),
        source=(mdoc.path, pdoc.path))


__all__ = ["ElectricDrive", "FIT_TOL", "J_FIT_MAX", "load_electric_drive"]
