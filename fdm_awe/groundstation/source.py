"""Which ground-station definition a run uses: the package's file or a user's.

``--ground-station FILE`` (and the API's ``ground_station=`` keyword) is resolved once, by
:func:`resolve_ground_station`, into one :class:`StationFile` that every layer reads the
station's numbers from: the optimiser's drive bounds and energy model (its problem holds it,
:attr:`fdm_awe.ocp.problem.CycleProblem.ground_station`), the 6-DOF co-simulation's drivetrain
and line, the autopilot's numbers that come from the station (the load resistor, the line's EA,
the drive's fastest reel-in) and ``fdm-awe info``. Nothing else names the definition file.

A user's file has the layout of the package's ``tether/ground_station.xml`` (``fdm-awe info
--export DIR`` writes a copy to start from). It is read and every field checked when it is
resolved (every line of the file, :func:`~.definitions.load_ground_station`): a missing,
unreadable or out-of-range file is one :class:`~fdm_awe.errors.InputError` naming the option,
the file, the field and its allowed range, before any work. :attr:`StationFile.sha256` hashes the
file's bytes as checked, so that a reference and a flight record which station they were made
for (:meth:`StationFile.record`: ``file`` "default" or the path, and ``sha256``).
"""

from __future__ import annotations

import hashlib
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..errors import DefinitionError, InputError
from .definitions import DEFAULT_PATH, GroundStationParams, load_ground_station

#: what a reference or a flight records as the file of the package's own station
DEFAULT_LABEL = "default"


@dataclass(frozen=True)
class StationFile:
    """One ground-station definition: its ``path`` (absolute), whether it is the package's own
    (``builtin``) and the SHA-256 of its bytes as checked. Compared by all three (a file changed
    between two runs is another station)."""

    path: Path
    builtin: bool
    sha256: str

    def load(self, line: str | None = None) -> GroundStationParams:
        """The station's parameters with the tether line ``line`` (None: the definition's
        default line), :func:`~.definitions.load_ground_station`."""
        return load_ground_station(self.path, line=line)

    def record(self) -> dict[str, str]:
        """What a reference or flight records of the station: ``file`` ("default" for the
        package's, else the path) and ``sha256``."""
        return {"file": DEFAULT_LABEL if self.builtin else str(self.path), "sha256": self.sha256}

    def label(self) -> str:
        """The station in a few words ("default", or the file)."""
        return DEFAULT_LABEL if self.builtin else str(self.path)


def _sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _resolve_file(text: str, option: str) -> StationFile:
    p = Path(os.path.expanduser(text))
    try:
        exists, is_file = p.exists(), p.is_file()
    except OSError as exc:  # a name the file system cannot hold (too long, ...)
        raise InputError(f"{option} {text[:60]}{'...' if len(text) > 60 else ''}: not a file ({exc.strerror or exc})") from None
    if not exists:
        raise InputError(f"{option} {text}: file not found (expected a ground-station definition <ground_station>; "
                         f"'fdm-awe info --export DIR' writes DIR/tether/ground_station.xml to start from)")
    if not is_file:
        raise InputError(f"{option} {text}: not a regular file (expected a ground-station definition <ground_station>)")
    p = p.resolve()
    try:
        sha = _sha256(p)
        load_ground_station(p)  # every field of every line checked
    except OSError as exc:
        raise InputError(f"{option} {text}: cannot read ({exc.strerror or exc})") from None
    except DefinitionError as exc:
        raise InputError(f"{option} {text}: <{exc.element}>: {exc.problem}") from None
    return StationFile(p, False, sha)


def resolve_ground_station(spec: "str | os.PathLike[str] | StationFile | None" = None,
                           option: str = "--ground-station") -> StationFile:
    """The :class:`StationFile` of ``spec``: a definition file (read and checked), a
    :class:`StationFile` (as it is) or None (the package's ``tether/ground_station.xml``).
    Errors are one line naming ``option``, the file, the field and its allowed range."""
    if isinstance(spec, StationFile):
        return spec
    if spec is None:
        return StationFile(DEFAULT_PATH, True, _sha256(DEFAULT_PATH))
    if not isinstance(spec, (str, os.PathLike)):
        raise InputError(f"{option} {spec!r}: expected a ground-station definition file")
    text = os.fspath(spec)
    if not text.strip():
        raise InputError(f"{option}: empty (expected a ground-station definition file)")
    return _resolve_file(text, option)


def default_station() -> StationFile:
    """The package's own ground station (``tether/ground_station.xml``)."""
    return resolve_ground_station(None)


def station_params(station: Any = None, line: str | None = None) -> GroundStationParams:
    """The parameters of ``station`` (as :func:`resolve_ground_station` takes it) with the tether
    line ``line`` (None: the definition's default line)."""
    return resolve_ground_station(station, "ground_station").load(line)


__all__ = ["DEFAULT_LABEL", "StationFile", "default_station", "resolve_ground_station", "station_params"]
