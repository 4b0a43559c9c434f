"""The reference-trajectory file: reading it (checked), the document of an optimiser's result,
writing it atomically, and the same reference in memory without a file."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import InputError
from ..fileio import json_text, write_json
from .checks import check_reference, check_reference_document
from .reference import ReferenceTrajectory
from .schema import COLUMN_UNITS, FORMAT, MAX_FILE_BYTES, OPTIONAL_COLUMN_UNITS, VERSION

def reference_document(result: Any) -> dict[str, Any]:
    """The JSON document of the reference file of an ``ok`` cycle result
    (:class:`~fdm_awe.ocp.result.CycleResult`): what :func:`write_reference` writes."""
    if not result.ok:
        raise InputError(f"no reference trajectory for a {result.status} result ({result.reason})")
    return {
        "format": FORMAT, "version": VERSION, "metadata": result.metadata(),
        "units": {k: COLUMN_UNITS.get(k, OPTIONAL_COLUMN_UNITS.get(k, "")) for k in result.columns},
        "columns": {k: [float(v) for v in np.asarray(a, float)] for k, a in result.columns.items()},
    }


def reference_from_result(result: Any, source: str = "the optimised reference") -> ReferenceTrajectory:
    """The reference of an ``ok`` cycle result in memory: exactly what :func:`read_reference`
    returns for the file :func:`write_reference` writes (the same document, through the same
    JSON text and the same checks), without a file. ``source`` names it in messages."""
    return check_reference_document(json.loads(json_text(reference_document(result), indent=None)), source)


def write_reference(result: Any, path: str | Path) -> Path:
    """Write the reference-trajectory JSON file of an ``ok`` result atomically; returns the path.

    The document is checked as :func:`read_reference` checks it before anything is written, so a
    file this function writes always reads back; the file appears complete or not at all
    (temporary name + rename, :func:`fdm_awe.fileio.write_json`).
    """
    doc = reference_document(result)
    p = Path(path)
    check_reference(ReferenceTrajectory(doc["metadata"], {k: np.asarray(v, float) for k, v in doc["columns"].items()},
                                        doc["units"], source=f"{p} (to be written)"))
    write_json(p, doc, indent=None)
    result.trajectory_path = str(p)
    return p


def as_reference(ref: Any) -> ReferenceTrajectory:
    """A :class:`ReferenceTrajectory` from a trajectory (as it is), a file path (read and checked)
    or a cycle result (its columns and metadata as they are, unchecked)."""
    if isinstance(ref, ReferenceTrajectory):
        return ref
    if isinstance(ref, (str, Path)):
        return read_reference(ref)
    if hasattr(ref, "columns") and hasattr(ref, "metadata") and callable(getattr(ref, "metadata")):
        cols = {k: np.asarray(v, float) for k, v in ref.columns.items()}
        return ReferenceTrajectory(ref.metadata(), cols, {k: COLUMN_UNITS.get(k, "") for k in cols})
    raise TypeError(f"not a reference trajectory, file or cycle result: {type(ref).__name__}")


def _load_json(p: Path) -> Any:
    """The parsed JSON of reference file ``p`` (InputError: file and problem, one line)."""
    try:
        if not p.exists():
            raise InputError(f"{p}: reference trajectory file not found")
        if p.is_dir():
            raise InputError(f"{p}: is a folder, not a reference trajectory file")
        if not p.is_file():
            raise InputError(f"{p}: not a regular file (a reference trajectory is a JSON file)")
        size = p.stat().st_size
        if size > MAX_FILE_BYTES:
            raise InputError(f"{p}: {size} bytes, too large for a reference trajectory (allowed <= {MAX_FILE_BYTES} bytes)")
        data = p.read_bytes()
    except OSError as exc:
        raise InputError(f"{p}: cannot read the reference trajectory ({exc.strerror or exc})") from None
    if not data.strip():
        raise InputError(f"{p}: empty file, expected the JSON written by 'fdm-awe optimize'")
    nul = data.find(b"\x00")
    if nul >= 0:
        raise InputError(f"{p}: binary content (NUL byte at offset {nul}), expected the JSON text written by 'fdm-awe optimize'")
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise InputError(f"{p}: not UTF-8 text (byte 0x{data[exc.start]:02x} at offset {exc.start}), "
                         f"expected the JSON text written by 'fdm-awe optimize'") from None
    try:
        return json.loads(text.lstrip("\ufeff"))
    except json.JSONDecodeError as exc:
        raise InputError(f"{p}: invalid JSON at line {exc.lineno} column {exc.colno} ({exc.msg})") from None
    except RecursionError:
        raise InputError(f"{p}: invalid reference trajectory: JSON nested too deeply") from None
    except ValueError as exc:  # e.g. an integer literal beyond Python's digit limit
        raise InputError(f"{p}: invalid JSON ({str(exc).splitlines()[0] if str(exc) else type(exc).__name__})") from None


def read_reference(path: str | Path) -> ReferenceTrajectory:
    """Read and check a reference-trajectory file (its format: :mod:`fdm_awe.trajectory`).

    Every malformed file raises :class:`~fdm_awe.errors.InputError` with one line naming the
    file, the field and the allowed range or form; the returned metadata carries checked
    ``scenario``, ``config``, ``T1_s``, ``T2_s``, ``period_s``, ``wind_mps``, ``wind_from_deg``,
    ``wind_ned_mps`` and ``tether_drag_scale`` (1 when the file predates it); ``line`` is checked
    when present (absent: Table 1's ``paper`` line, as :func:`fdm_awe.sim.flight.fly` reads it).
    """
    p = Path(path)
    return check_reference_document(_load_json(p), str(p))
