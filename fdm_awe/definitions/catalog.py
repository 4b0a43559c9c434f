"""Which aircraft a run flies: a name of the package's table or a user's definition folder.

``--aircraft NAME|DIR`` (and the API's ``aircraft=`` keyword) is resolved once, by
:func:`resolve_aircraft`, into one :class:`Aircraft` that every layer takes its vehicle from:
the point-mass airframes (:meth:`Aircraft.glider`), the optimiser's drive and fold time, the
6-DOF adapter's JSBSim root and aircraft name, the autopilot definition, the recording's scene
and ``fdm-awe info``. Nothing else names an aircraft file.

The table (:data:`AIRCRAFT`, as SITL's ``model_constructors``) maps a name to a definition
folder; the package ships its glider as ``glider``. A folder (a JSBSim root) has the package's
own layout, which ``fdm-awe info --export DIR`` writes to start from::

    aircraft/P_foldable/P_foldable.xml   the morphing aircraft the 6-DOF model flies
    aircraft/P_foldable/autopilot.xml    the autopilot's parameters (their defaults and ranges)
    aircraft/P_unfolded/P_unfolded.xml   the unfolded form (generation), point-mass side
    aircraft/P_folded/P_folded.xml       the folded form (recovery), point-mass side
    aircraft/common/...                  section files the aircraft files include (optional)
    engine/MOTOR.xml, engine/PROP.xml    the motor and propeller the aircraft files name

with one prefix ``P`` of the folder's own choice (``glider`` in the package). A folder is
checked when it is resolved: a missing file is a one-line :class:`~fdm_awe.errors.InputError`
naming the option, the file and what it should hold; the files' fields are checked as the
package's own (:func:`~.aircraft.check_aircraft_file`: file, element, allowed range).

:attr:`Aircraft.sha256` hashes the files of the definition (the three aircraft folders,
``aircraft/common`` and ``engine``), so that a reference trajectory records what it was
optimised for (metadata ``aircraft``, :meth:`Aircraft.record`).
"""

from __future__ import annotations

import functools
import hashlib
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from .. import ROOT
from ..errors import InputError

#: The aircraft table: name -> definition folder (a JSBSim root with the layout above).
AIRCRAFT: dict[str, Path] = {"glider": ROOT}
#: The aircraft every command flies unless ``--aircraft`` names another.
DEFAULT_AIRCRAFT = "glider"
#: The three forms of an aircraft folder: form -> the suffix of its JSBSim aircraft name.
FORMS: dict[str, str] = {"foldable": "_foldable", "unfolded": "_unfolded", "folded": "_folded"}
#: What each form's file holds (the error of a missing file says it).
_WHAT = {"foldable": "the morphing aircraft the 6-DOF model flies",
         "unfolded": "the unfolded form, the point-mass side's generation wing",
         "folded": "the folded form, the point-mass side's recovery wing"}
#: The autopilot definition's file name in the morphing aircraft's folder.
AUTOPILOT_FILE = "autopilot.xml"


@dataclass(frozen=True)
class Aircraft:
    """One aircraft definition: its ``name`` (the table's, or the folder as given), its JSBSim
    ``root`` (absolute) and the ``prefix`` of its three JSBSim aircraft names. Compared by
    these three; :attr:`sha256` is computed when first read."""

    name: str
    root: Path
    prefix: str

    @property
    def builtin(self) -> bool:
        """The aircraft is a name of the table (not a user's folder)."""
        return self.name in AIRCRAFT

    def jsbsim_name(self, form: str = "foldable") -> str:
        """The JSBSim aircraft name of ``form`` (:data:`FORMS`), e.g. ``glider_foldable``."""
        if form not in FORMS:
            raise InputError(f"aircraft form {form!r} unknown (allowed: {', '.join(FORMS)})")
        return self.prefix + FORMS[form]

    def path(self, form: str = "foldable") -> Path:
        """The JSBSim aircraft file of ``form``: ``ROOT/aircraft/NAME/NAME.xml``."""
        name = self.jsbsim_name(form)
        return self.root / "aircraft" / name / f"{name}.xml"

    @property
    def autopilot_file(self) -> Path:
        """The autopilot definition (``aircraft/P_foldable/autopilot.xml``)."""
        return self.root / "aircraft" / self.jsbsim_name("foldable") / AUTOPILOT_FILE

    def files(self) -> list[Path]:
        """Every file of the definition, sorted: the three aircraft folders, ``aircraft/common``
        and ``engine`` (what :attr:`sha256` hashes and ``info --export`` copies)."""
        folders = [self.root / "aircraft" / self.jsbsim_name(f) for f in FORMS]
        folders += [self.root / "aircraft" / "common", self.root / "engine"]
        out: list[Path] = []
        for d in folders:
            if d.is_dir():
                out += [p for p in d.rglob("*") if p.is_file() and "__pycache__" not in p.parts]
        return sorted(out)

    @functools.cached_property
    def sha256(self) -> str:
        """SHA-256 of the definition's files (relative path and bytes of each, in sorted order),
        computed when the aircraft is resolved (:func:`resolve_aircraft`)."""
        h = hashlib.sha256()
        for p in self.files():
            h.update(p.relative_to(self.root).as_posix().encode() + b"\0")
            h.update(p.read_bytes())
            h.update(b"\0")
        return h.hexdigest()

    def record(self) -> dict[str, str]:
        """What a reference or flight records of the aircraft: ``name`` (a table name) or
        ``directory`` (a user's folder), and ``sha256``."""
        key = "name" if self.builtin else "directory"
        return {key: self.name if self.builtin else str(self.root), "sha256": self.sha256}

    def label(self) -> str:
        """The aircraft in a few words (a table name, or the folder)."""
        return self.name if self.builtin else str(self.root)

    # ------------------------------------------------------------------ the loaded definitions
    def glider(self) -> Any:
        """Both point-mass forms (:class:`~.aircraft.Glider`), checked."""
        from .aircraft import load_glider

        return load_glider(self)

    def drive(self) -> Any:
        """The 6-DOF glider's electric drive (:class:`~.engine.ElectricDrive`)."""
        from .engine import load_electric_drive

        return load_electric_drive(self)

    def fold_time(self) -> float:
        """The morphing aircraft's full fold travel ``fcs/wing-fold-time-s`` [s], range-checked."""
        from .aircraft import FOLD_TIME_MAX_S
        from .xmlutil import XmlDoc

        doc = XmlDoc.load(self.path("foldable"))
        return doc.property_value("fcs/wing-fold-time-s", lo=0.0, hi=FOLD_TIME_MAX_S, lo_open=True, unit="s")

    def check(self) -> "Aircraft":
        """Check every field of the three aircraft files and of the engine files they name
        (:func:`~.aircraft.check_aircraft_file`), and that the three forms weigh the same (the
        6-DOF model flies the morphing form, the optimiser the static ones): DefinitionError
        naming file, element and allowed range."""
        from ..errors import DefinitionError
        from .aircraft import mass_params, check_aircraft_file

        docs = {form: check_aircraft_file(self.path(form), root=self.root) for form in FORMS}
        m = {form: mass_params(doc).mass for form, doc in docs.items()}
        for form in ("unfolded", "folded"):
            if abs(m[form] - m["foldable"]) > 1e-9 * m["foldable"]:
                raise DefinitionError(self.path(form), "mass_balance",
                                      f"total mass {m[form]:g} kg differs from the morphing form's {m['foldable']:g} kg "
                                      f"({self.path('foldable')}; allowed: the same vehicle in every form)")
        return self


def _prefix(root: Path, option: str, spec: str) -> str:
    """The prefix ``P`` of the one ``aircraft/P_foldable/P_foldable.xml`` of folder ``root``."""
    where = root / "aircraft"
    found = sorted(d.name[: -len(FORMS["foldable"])] for d in where.glob("*" + FORMS["foldable"])
                   if d.is_dir() and d.name != FORMS["foldable"]) if where.is_dir() else []
    if not found:
        raise InputError(f"{option} {spec}: {where / ('P' + FORMS['foldable'])} missing (expected a folder "
                         f"aircraft/P_foldable/ holding P_foldable.xml, {_WHAT['foldable']}; "
                         f"'fdm-awe info --export DIR' writes one to start from)")
    if len(found) > 1:
        raise InputError(f"{option} {spec}: {where} holds {len(found)} morphing aircraft "
                         f"({', '.join(p + FORMS['foldable'] for p in found)}); expected one")
    return found[0]


def _check_files(a: Aircraft, option: str, spec: str) -> None:
    """Every file the layout requires exists (one-line InputError naming option, file, content)."""
    from ..errors import DefinitionError
    from .xmlutil import XmlDoc

    need = [(a.path(f), f"the JSBSim aircraft file of {_WHAT[f]}") for f in FORMS]
    need.append((a.autopilot_file, "the autopilot definition <fdm_awe_autopilot>"))
    for p, what in need:
        if not p.is_file():
            raise InputError(f"{option} {spec}: {p} missing (expected {what})")
    try:
        doc = XmlDoc.load(a.path("foldable"))
    except DefinitionError as exc:
        raise InputError(f"{option} {spec}: {exc}") from None
    eng = doc.find("propulsion/engine", required=False)
    if eng is None:
        return  # check_aircraft_file names the missing element
    named = [("motor", eng.attrib.get("file", ""))]
    thr = eng.find("thruster")
    if thr is not None:
        named.append(("propeller", thr.attrib.get("file", "")))
    for what, name in named:
        p = a.root / "engine" / f"{name}.xml"
        if name and not p.is_file():
            raise InputError(f"{option} {spec}: {p} missing (expected the {what} file {a.jsbsim_name()} names, "
                             f"engine/{name}.xml)")


def _resolve(spec: str, option: str) -> Aircraft:
    if spec in AIRCRAFT:
        root = AIRCRAFT[spec]
        a = Aircraft(spec, root, _prefix(root, option, spec))
        a.sha256  # noqa: B018 - the files' hash as resolved
        return a
    root = Path(os.path.expanduser(spec))
    try:
        exists, folder = root.exists(), root.is_dir()
    except OSError as exc:  # a name the file system cannot hold (too long, ...)
        raise InputError(f"{option} {spec[:60]}{'...' if len(spec) > 60 else ''}: not a folder "
                         f"({exc.strerror or exc})") from None
    if not exists:
        raise InputError(f"{option} {spec}: neither an aircraft of the table (allowed: {', '.join(AIRCRAFT)}) "
                         f"nor a folder")
    if not folder:
        raise InputError(f"{option} {spec}: not a folder (expected an aircraft name, {', '.join(AIRCRAFT)}, or a "
                         f"definition folder holding aircraft/ and engine/)")
    root = root.resolve()
    a = Aircraft(str(root), root, _prefix(root, option, spec))
    _check_files(a, option, spec)
    a.sha256  # noqa: B018 - the files' hash as resolved (and checked)
    return a.check()


def resolve_aircraft(spec: "str | os.PathLike[str] | Aircraft | None" = None, option: str = "--aircraft") -> Aircraft:
    """The :class:`Aircraft` of ``spec``: a name of :data:`AIRCRAFT`, a definition folder (the
    layout of the module docstring, every file checked), an :class:`Aircraft` (as it is) or
    None (:data:`DEFAULT_AIRCRAFT`). Errors name ``option`` (one line)."""
    if isinstance(spec, Aircraft):
        return spec
    if spec is None:
        spec = DEFAULT_AIRCRAFT
    if not isinstance(spec, (str, os.PathLike)):
        raise InputError(f"{option} {spec!r}: expected an aircraft name ({', '.join(AIRCRAFT)}) or a folder")
    text = os.fspath(spec)
    if not text.strip():
        raise InputError(f"{option}: empty (allowed: {', '.join(AIRCRAFT)} or a definition folder)")
    return _resolve(text, option)


def default_aircraft() -> Aircraft:
    """The package's own aircraft (:data:`DEFAULT_AIRCRAFT`)."""
    return resolve_aircraft(None)


__all__ = ["AIRCRAFT", "AUTOPILOT_FILE", "Aircraft", "DEFAULT_AIRCRAFT", "FORMS", "default_aircraft", "resolve_aircraft"]
