"""Autopilot definition file (``aircraft/<name>/autopilot.xml`` of the aircraft flown,
:attr:`fdm_awe.definitions.catalog.Aircraft.autopilot_file`) -> a :class:`ParamStore`.

Every ``<param id unit min max doc kind>value</param>`` becomes one MAVLink-visible parameter,
range-checked at load (one-line DefinitionError naming file and element) and on every change.
``kind`` is ``float`` (the default), ``int`` (whole numbers in ``min .. max``) or ``bool``
(an on/off switch: 0 or 1); a ground station's 0.5 for a switch is refused, the old value kept.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

from ..definitions.catalog import default_aircraft
from ..definitions.xmlutil import XmlDoc, to_float
from ..errors import DefinitionError
from .params import KINDS, ParamStore

@dataclass(frozen=True)
class ParamDef:
    id: str
    value: float
    lo: float
    hi: float
    unit: str
    doc: str
    kind: str = "float"


def load_autopilot_definition(path: str | Path | None = None) -> list[ParamDef]:
    """The parameters of an autopilot definition file (root element ``<fdm_awe_autopilot>``, the
    package's own: JSBSim's ``<autopilot>`` is a section of an aircraft file), range-checked;
    None: the package's glider's."""
    doc = XmlDoc.load(path or default_aircraft().autopilot_file)
    if doc.root.tag != "fdm_awe_autopilot":
        raise DefinitionError(doc.path, doc.root.tag, "root element must be <fdm_awe_autopilot>")
    out: list[ParamDef] = []
    seen: set[str] = set()
    for i, el in enumerate(doc.root.findall("param")):
        pid = el.attrib.get("id", "")
        what = f"param[{i}] {pid}".strip()
        if not pid or len(pid) > 16:
            raise DefinitionError(doc.path, what, "needs an id of 1..16 characters")
        if pid in seen:
            raise DefinitionError(doc.path, what, "declared twice")
        seen.add(pid)
        lo = to_float(doc.path, f"{what} min", el.attrib.get("min"))
        hi = to_float(doc.path, f"{what} max", el.attrib.get("max"))
        v = to_float(doc.path, what, el.text)
        kind = el.attrib.get("kind", "float")
        if kind not in KINDS:
            raise DefinitionError(doc.path, f"{what} kind", f"{kind!r} (allowed {', '.join(KINDS)})")
        if kind == "bool" and (lo, hi) != (0.0, 1.0):
            raise DefinitionError(doc.path, what, f"a bool has min 0 and max 1 (found {lo:g} .. {hi:g})")
        if not (lo <= v <= hi) or not math.isfinite(v):
            raise DefinitionError(doc.path, what, f"value {v:g} out of range (allowed {lo:g} .. {hi:g})")
        if kind != "float" and v != int(v):
            raise DefinitionError(doc.path, what, f"value {v:g} is not a whole number ({kind})")
        out.append(ParamDef(pid, v, lo, hi, el.attrib.get("unit", ""), el.attrib.get("doc", ""), kind))
    if not out:
        raise DefinitionError(doc.path, "param", "no parameters defined")
    return out


def autopilot_params(path: str | Path | None = None, store: ParamStore | None = None) -> ParamStore:
    """Declare the definition file's parameters in ``store`` (a new one if None); DefinitionError
    naming the store's parameter file when it holds a value out of range or of the wrong kind, or
    an id the definition does not declare (:meth:`ParamStore.check_saved`)."""
    ps = store if store is not None else ParamStore()
    for d in load_autopilot_definition(path):
        ps.add(d.id, d.value, d.lo, d.hi, kind=d.kind, doc=f"{d.doc} [{d.unit}]" if d.unit else d.doc)
    ps.check_saved()
    return ps
