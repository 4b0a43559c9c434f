"""Small, strict helpers to read numbers out of definition XML files.

Every failure raises :class:`fdm_awe.errors.DefinitionError` whose one-line message names
the file and the element (and the allowed range or form where one applies).

:func:`check_numbers` checks every slot of a JSBSim file (aircraft, engine, propeller) that
JSBSim reads as a number: a file that passes it never makes JSBSim parse a non-number (JSBSim
would stop with a C++ exception and a traceback); the range of each value the package relies
on is checked by the loaders (:mod:`.aircraft`, :mod:`.engine`).

A JSBSim aircraft file may take a section from a file of its own (``<metrics file="NAME">``,
``<system file="NAME">``, ...: :data:`SECTION_FILE_ELEMENTS`). :meth:`XmlDoc.load` reads an
aircraft file the way JSBSim reads it: each such section gets the children of the file it names
after its own, so every reader sees the numbers JSBSim flies; :meth:`XmlDoc.origin` names the
file an element came from, and the messages name that file.
"""

from __future__ import annotations

import math
import os
import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path
from typing import Iterator

from ..errors import DefinitionError
from ..units import TO_SI

#: Leaf elements of JSBSim aircraft, engine and propeller files whose text is a number.
NUMBER_ELEMENTS = frozenset({
    # metrics, locations, orientations, directions
    "wingarea", "wingspan", "chord", "htailarea", "htailarm", "vtailarea", "vtailarm", "wing_incidence",
    "x", "y", "z", "roll", "pitch", "yaw",
    # mass balance
    "ixx", "iyy", "izz", "ixy", "ixz", "iyz", "emptywt", "weight",
    # ground reactions
    "static_friction", "dynamic_friction", "rolling_friction", "spring_coeff", "damping_coeff",
    "damping_coeff_rebound", "max_steer", "retractable",
    # propulsion
    "feed", "sense", "p_factor", "velocityconstant", "coilresistance", "noloadcurrent", "maxvolts", "diameter",
    "numblades", "constspeed", "minpitch", "maxpitch", "minrpm", "maxrpm", "gearratio",
    # functions
    "value",
})
#: Leaf elements whose text is a number or the name of a property (``fcs/...``).
NUMBER_OR_PROPERTY_ELEMENTS = frozenset({"gain", "rate_limit", "min", "max", "bias", "lag", "width"})
#: Sections of a JSBSim aircraft file (``<fdm_config>``) that may name a section file with a
#: ``file`` attribute: JSBSim (``FGModel::Upload``) reads that file, whose root element has the
#: section's name, and appends the root's children to the section after the section's own
#: children, which therefore come first (contacts, channels, properties overriding the file's).
SECTION_FILE_ELEMENTS = frozenset({"metrics", "mass_balance", "ground_reactions", "external_reactions", "buoyant_forces",
                                   "propulsion", "system", "autopilot", "flight_control", "aerodynamics"})
_PROPERTY_NAME = re.compile(r"^-?[A-Za-z_][\w\-]*(\[\d+\])?(/[A-Za-z_][\w\-]*(\[\d+\])?)+$")
_ALLOWED_NUMBER = "allowed: a finite decimal number"


@dataclass(frozen=True)
class XmlDoc:
    """A parsed definition file: its path (for messages) and its root element.

    ``sources`` maps the elements read from section files (``id(element)``) to their file.
    """

    path: Path
    root: ET.Element
    sources: dict[int, Path] = field(default_factory=dict, compare=False, repr=False)

    @classmethod
    def load(cls, path: str | Path) -> "XmlDoc":
        """Parse ``path``; a JSBSim aircraft file (``<fdm_config>``) with the section files it
        names merged in as JSBSim merges them (:func:`include_section_files`)."""
        p = Path(path)
        if not p.is_file():
            raise DefinitionError(p, "file", "not found" if not p.exists() else "not a regular file")
        try:
            root = ET.parse(p).getroot()
        except ET.ParseError as exc:
            raise DefinitionError(p, "xml", f"not well-formed XML ({exc})") from None
        except OSError as exc:
            raise DefinitionError(p, "file", f"cannot read ({exc.strerror or exc})") from None
        doc = cls(p, root)
        if root.tag == "fdm_config":
            include_section_files(doc)
        return doc

    def origin(self, el: ET.Element) -> Path:
        """The file element ``el`` was read from: :attr:`path` or one of its section files."""
        return self.sources.get(id(el), self.path)

    @property
    def section_files(self) -> tuple[Path, ...]:
        """The section files merged into this document, in the order they were read."""
        return tuple(dict.fromkeys(self.sources.values()))

    # -- element access ----------------------------------------------------------
    def find(self, xpath: str, required: bool = True) -> ET.Element | None:
        el = self.root.find(xpath)
        if el is None and required:
            raise DefinitionError(self.path, xpath, "missing element")
        return el

    def number(
        self,
        xpath: str,
        *,
        unit: str | None = None,
        lo: float | None = None,
        hi: float | None = None,
        lo_open: bool = False,
        hi_open: bool = False,
        default: float | None = None,
        convert: bool = True,
    ) -> float:
        """Read the float text of ``xpath``, converted to SI from its ``unit`` attribute.

        ``unit`` names the SI unit the caller expects (for the message); ``lo``/``hi`` bound
        the converted value (``lo_open``/``hi_open`` make a bound strict, e.g. ``> 0``).
        ``convert=False`` reads the number as written (files whose units JSBSim alone
        interprets, e.g. ``OHMS`` of a motor).
        """
        el = self.find(xpath, required=default is None)
        if el is None:
            return float(default)  # type: ignore[arg-type]
        return element_number(self.origin(el), xpath, el, lo=lo, hi=hi, lo_open=lo_open, hi_open=hi_open, unit=unit or "",
                              convert=convert)

    def property_value(
        self,
        name: str,
        *,
        lo: float | None = None,
        hi: float | None = None,
        lo_open: bool = False,
        hi_open: bool = False,
        unit: str = "",
    ) -> float:
        """Value of a JSBSim ``<property value="...">name</property>`` declaration."""
        for el in self.root.iter("property"):
            if (el.text or "").strip() == name and "value" in el.attrib:
                what, path = f"property {name}", self.origin(el)
                return _check(path, what, to_float(path, what, el.attrib["value"]), lo, hi, lo_open, hi_open, unit)
        raise DefinitionError(self.path, f"property {name}", "missing declaration (<property value=...>)")


def to_float(path: Path, what: str, text: str | None) -> float:
    """``text`` as a finite float, else a :class:`DefinitionError` naming ``path`` and ``what``."""
    t = (text or "").strip()
    try:
        v = float(t)
    except ValueError:
        shown = repr(t) if len(t) <= 40 else repr(t[:37] + "...")
        raise DefinitionError(path, what, f"{shown} is not a number ({_ALLOWED_NUMBER})") from None
    if not math.isfinite(v):
        raise DefinitionError(path, what, f"{t!r} is not a finite number ({_ALLOWED_NUMBER})")
    return v


def allowed_range(lo: float | None, hi: float | None, lo_open: bool = False, hi_open: bool = False, unit: str = "") -> str:
    """``"> 0 and <= 10 s"``-style text of an interval (for messages)."""
    u = f" {unit}" if unit else ""
    parts = []
    if lo is not None:
        parts.append(f"{'>' if lo_open else '>='} {lo:g}")
    if hi is not None:
        parts.append(f"{'<' if hi_open else '<='} {hi:g}")
    return " and ".join(parts) + u if parts else "any finite number"


def _check(path: Path, what: str, v: float, lo: float | None, hi: float | None, lo_open: bool,
           hi_open: bool = False, unit: str = "") -> float:
    below = lo is not None and (v <= lo if lo_open else v < lo)
    above = hi is not None and (v >= hi if hi_open else v > hi)
    if below or above:
        u = f" {unit}" if unit else ""
        raise DefinitionError(path, what, f"value {v:g}{u} out of range (allowed {allowed_range(lo, hi, lo_open, hi_open, unit)})")
    return v


def element_number(
    path: Path,
    what: str,
    el: ET.Element,
    *,
    lo: float | None = None,
    hi: float | None = None,
    lo_open: bool = False,
    hi_open: bool = False,
    unit: str = "",
    convert: bool = True,
) -> float:
    """Float text of ``el`` converted to SI with its ``unit`` attribute (as written with
    ``convert=False``), range-checked."""
    v = to_float(path, what, el.text)
    u = el.attrib.get("unit") if convert else None
    if u is not None:
        if u.upper() not in TO_SI:
            raise DefinitionError(path, what, f"unknown unit {u!r} (known: {', '.join(sorted(TO_SI))})")
        v *= TO_SI[u.upper()]
    return _check(path, what, v, lo, hi, lo_open, hi_open, unit)


def location(path: Path, el: ET.Element, what: str) -> tuple[float, float, float]:
    """A JSBSim ``<location unit=..>`` with x, y, z children, in metres."""
    unit = el.attrib.get("unit", "IN").upper()
    if unit not in TO_SI:
        raise DefinitionError(path, what, f"unknown unit {unit!r}")
    out = []
    for axis in ("x", "y", "z"):
        c = el.find(axis)
        if c is None:
            raise DefinitionError(path, f"{what}/{axis}", "missing element")
        out.append(to_float(path, f"{what}/{axis}", c.text) * TO_SI[unit])
    return (out[0], out[1], out[2])


def section_file(aircraft: Path, section: ET.Element) -> Path:
    """The file a section's ``file`` attribute names, looked up as JSBSim looks it up: a relative
    name from the aircraft's folder, ``.xml`` appended unless the name ends in it; a ``<system>``
    file also in the folder's ``Systems`` (``systems``) subfolder and in the JSBSim root's
    ``systems`` folder; an absolute name as it is. Where it is nowhere, the path in the
    aircraft's folder."""
    name = section.attrib["file"].strip()
    if Path(name).is_absolute():
        return Path(name)
    fname = name if name.endswith(".xml") else f"{name}.xml"
    folder = aircraft.parent
    folders = [folder] + ([folder / "Systems", folder / "systems", folder.parent.parent / "systems"]
                          if section.tag == "system" else [])
    found = next((f / fname for f in folders if (f / fname).is_file()), folder / fname)
    return Path(os.path.normpath(found))  # ``aircraft/NAME/../common/x.xml`` -> ``aircraft/common/x.xml``


def include_section_files(doc: XmlDoc) -> None:
    """Merge the section files an aircraft file names into ``doc`` as JSBSim does: the file's
    root must be an element of the section's name; its attributes fill those the section lacks,
    its children follow the section's own. A pre-function written beside a section file (JSBSim
    would ignore it) is refused. DefinitionError: file, element, what is wrong."""
    for section in doc.root:
        if section.tag not in SECTION_FILE_ELEMENTS or "file" not in section.attrib:
            continue
        what = f"{section.tag}[file={section.attrib['file'].strip()}]"
        for fn in section.findall("function"):
            if fn.attrib.get("type", "").strip() != "post":
                raise DefinitionError(doc.path, f"{what}/function[{fn.attrib.get('name', '?')}]",
                                      "JSBSim does not load a pre-function written beside a section file "
                                      "(allowed: type=\"post\", or the function inside the section file)")
        src = section_file(doc.path, section)
        if not src.is_file():
            raise DefinitionError(doc.path, what, f"section file {src} not found")
        inc = XmlDoc.load(src)
        if inc.root.tag != section.tag:
            raise DefinitionError(src, inc.root.tag, f"root element must be <{section.tag}> (the section that includes it)")
        for key, value in inc.root.attrib.items():
            section.attrib.setdefault(key, value)
        for child in list(inc.root):
            section.append(child)
            doc.sources.update((id(el), src) for el in child.iter())


def _walk(el: ET.Element, prefix: str) -> Iterator[tuple[str, ET.Element]]:
    """``(path, element)`` of ``el``'s descendants; a path names elements with a ``name``
    attribute by it (``ground_reactions/contact[NOSE_SKID]/spring_coeff``)."""
    for child in el:
        if not isinstance(child.tag, str):  # comments, processing instructions
            continue
        name = child.attrib.get("name")
        here = f"{prefix}/{child.tag}" if prefix else child.tag
        if name:
            here += f"[{name}]"
        yield here, child
        yield from _walk(child, here)


def check_numbers(doc: XmlDoc) -> None:
    """Every number JSBSim reads from ``doc``: finite decimal numbers in the leaf elements of
    :data:`NUMBER_ELEMENTS` and in ``<property value=...>``, numbers or property names in
    :data:`NUMBER_OR_PROPERTY_ELEMENTS`, and rows of numbers in ``<tableData>``."""
    for where, el in _walk(doc.root, ""):
        tag = el.tag
        path = doc.origin(el)
        if tag == "property" and "value" in el.attrib:
            to_float(path, f"property {(el.text or '').strip()}", el.attrib["value"])
        elif len(el):
            continue  # an element with children (a function's <max>, a <location>) is checked through them
        elif tag in NUMBER_ELEMENTS:
            to_float(path, where, el.text)
        elif tag in NUMBER_OR_PROPERTY_ELEMENTS:
            text = (el.text or "").strip()
            try:
                float(text)
            except ValueError:
                if not _PROPERTY_NAME.match(text):
                    raise DefinitionError(path, where, f"{text!r} is neither a number nor a property name "
                                                          f"(allowed: a finite decimal number or a property such as fcs/name)") from None
            else:
                to_float(path, where, text)
        elif tag == "tableData":
            rows = [line.split() for line in (el.text or "").strip().splitlines() if line.strip()]
            if not rows:
                raise DefinitionError(path, where, "empty table (allowed: rows of finite numbers)")
            for i, row in enumerate(rows):
                for tok in row:
                    to_float(path, f"{where} row {i + 1}", tok)
