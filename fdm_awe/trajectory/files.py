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

def margins_record(bounds: Any) -> dict[str, float]:
    """The margins a cycle keeps, as the reference file records them (metadata ``margins``) from
    its :class:`~fdm_awe.ocp.problem.Bounds`: the tension rating [N], the tension margin and the
    cycle's tension bound ``rating / (1 + margin)`` [N], the stall margin and the share of C_Lmax
    the cycle may use (``1 - stall margin``), and the reel-in speed bound [m/s] where one is set
    (a reel-in margin)."""
    out = {"tension_rating_N": float(bounds.G_max), "tension_margin": float(bounds.tension_margin),
           "tension_bound_N": float(bounds.G_cycle_max), "stall_margin": float(bounds.stall_margin),
           "cl_max_share": float(bounds.cl_margin)}
    if bounds.reel_in_speed_max is not None:  # a reel-in margin: the bound below the drive's fastest [m/s]
        out["reel_in_speed_max_m_s"] = float(bounds.reel_in_speed_max)
    return out


def margins_text(md: dict[str, Any]) -> str:
    """The margins recorded in reference metadata ``md`` in a few words (what ``fdm-awe fly``
    shows when it loads a reference); for files that record none, what their bounds say."""
    m = md.get("margins")
    if not isinstance(m, dict):
        b = md.get("bounds") if isinstance(md.get("bounds"), dict) else {}
        if not b:
            return "margins not recorded (a file written before they were)"
        m = {"tension_rating_N": b.get("G_max", 50.0), "tension_margin": b.get("tension_margin", 0.0),
             "cl_max_share": b.get("cl_margin", 1.0)}
        m["tension_bound_N"] = m["tension_rating_N"] / (1.0 + m["tension_margin"])
        m["stall_margin"] = 1.0 - m["cl_max_share"]
    text = (f"tension <= {m['tension_bound_N']:.3g} N (rating {m['tension_rating_N']:g} N, margin "
            f"{m['tension_margin']:g}), C_L <= {m['cl_max_share']:.3g} C_Lmax (stall margin {m['stall_margin']:.3g})")
    if m.get("reel_in_speed_max_m_s") is not None:
        text += f", reel-in <= {m['reel_in_speed_max_m_s']:.3g} m/s"
    return text


def reference_document(result: Any) -> dict[str, Any]:
    """The JSON document of the reference file of an ``ok`` cycle result
    (:class:`~fdm_awe.ocp.result.CycleResult`): what :func:`write_reference` writes."""
    if not result.ok:
        raise InputError(f"no reference trajectory for a {result.status} result ({result.reason})")
    md = result.metadata()
    pr = getattr(result, "problem", None)
    if pr is not None:
        md["line_model"] = pr.line_model
        md["margins"] = margins_record(pr.bounds)
    return {
        "format": FORMAT, "version": VERSION, "metadata": md,
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
