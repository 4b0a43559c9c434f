"""Autopilot definition file (``aircraft/<name>/autopilot.xml``) -> a :class:`ParamStore`.

Every ``<param id unit min max doc>value</param>`` becomes one MAVLink-visible parameter,
range-checked at load (one-line DefinitionError naming file and element) and on every change.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

from .. import ROOT
from ..definitions.xmlutil import XmlDoc, _to_float
from ..errors import DefinitionError
from .params import ParamStore

DEFAULT_FILE = ROOT / "aircraft" / "glider_foldable" / "autopilot.xml"


@dataclass(frozen=True)
class ParamDef:
    id: str
    value: float
    lo: float
    hi: float
    unit: str
    doc: str


def load_autopilot_definition(path: str | Path | None = None) -> list[ParamDef]:
    """The parameters of an autopilot definition file (root element ``<fdm_awe_autopilot>``, the
    package's own: JSBSim's ``<autopilot>`` is a section of an aircraft file), range-checked."""
    doc = XmlDoc.load(path or DEFAULT_FILE)
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
        lo = _to_float(doc.path, f"{what} min", el.attrib.get("min"))
        hi = _to_float(doc.path, f"{what} max", el.attrib.get("max"))
        v = _to_float(doc.path, what, el.text)
        if not (lo <= v <= hi) or not math.isfinite(v):
            raise DefinitionError(doc.path, what, f"value {v:g} out of range (allowed {lo:g} .. {hi:g})")
        out.append(ParamDef(pid, v, lo, hi, el.attrib.get("unit", ""), el.attrib.get("doc", "")))
    if not out:
        raise DefinitionError(doc.path, "param", "no parameters defined")
    return out


def autopilot_params(path: str | Path | None = None, store: ParamStore | None = None) -> ParamStore:
    """Declare the definition file's parameters in ``store`` (a new one if None)."""
    ps = store if store is not None else ParamStore()
    for d in load_autopilot_definition(path):
        ps.add(d.id, d.value, d.lo, d.hi, doc=f"{d.doc} [{d.unit}]" if d.unit else d.doc)
    return ps
