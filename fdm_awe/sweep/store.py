"""Persistence of sweep points: one small JSON file per finished point.

Layout of an output folder::

    points/<id>.json      the point's record (ok or failed)
    points/<id>.warm.npz  its solution vector and multipliers (warm start of the next point)

Both files are written atomically (:mod:`fdm_awe.fileio`: temporary name + rename), the
warm-start file first: a point counts as finished once its JSON file exists, so a sweep killed
at any moment leaves only complete points behind and a rerun computes exactly the missing ones
(and, from the stored warm starts, the same numbers as an uninterrupted run).

The folder is the store's own cache. A file in it that cannot be used (a record that is not
valid JSON, not an object, lacks a field or names another point; a warm-start file that is
truncated, not an ``.npz`` archive, lacks an array or holds non-finite numbers) counts as absent:
one warning line names it, the point is computed again and its files are overwritten then.
Nothing is deleted otherwise.
"""

from __future__ import annotations

import io
import json
import math
import sys
import zipfile
import zlib
from pathlib import Path
from typing import Any, Callable

import numpy as np

from ..errors import InputError
from ..fileio import atomic_write_bytes, write_json
from .runner import RECORD_FIELDS, Warm

#: Record fields the sweep's outputs index directly, with the JSON types they must have.
REQUIRED_FIELDS: dict[str, tuple[type, ...]] = {
    "id": (str,), "scenario": (str,), "config": (str,), "wind_mps": (int, float), "d0_m": (int, float),
    "d_tf_m": (int, float), "status": (str,),
}
#: Record fields holding text (or null); :data:`BOOL_FIELDS` are booleans; every other field of
#: :data:`~fdm_awe.sweep.runner.RECORD_FIELDS` is a number or null (records written before a
#: field existed lack it: read as null).
TEXT_FIELDS = frozenset({"id", "scenario", "config", "mesh", "warm_fallback", "propeller", "line", "status", "reason", "worker",
                         "warm_from", "start", "kept", "family", "cold_family", "wind_profile",
                         "line_model", "bounds", "binding"})
#: Record fields holding a boolean (or null).
BOOL_FIELDS = frozenset({"line_weight", "cold_check"})
#: Arrays of a warm-start file.
WARM_ARRAYS = ("w", "lam_x", "lam_g", "k_wrap")


def _warn(path: Path, why: str) -> None:
    print(f"warning: {path}: {why}; the point is computed again", file=sys.stderr)


def _number(v: Any) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def record_problem(record: Any, pid: str) -> str | None:
    """Why ``record`` (parsed JSON) is not a usable record of point ``pid``, or None."""
    if not isinstance(record, dict):
        return f"not a JSON object (a {type(record).__name__})"
    for key, types in REQUIRED_FIELDS.items():
        v = record.get(key)
        if v is None:
            return f"field {key!r} missing"
        if not isinstance(v, types) or isinstance(v, bool):
            return f"field {key!r} = {v!r:.40} has the wrong type"
    if record["id"] != pid:
        return f"record of point {record['id']!r:.40}, expected {pid!r}"
    if record["status"] not in ("ok", "failed"):
        return f"field 'status' = {record['status']!r:.40} (allowed ok, failed)"
    if record["status"] == "ok" and not (_number(record.get("P_avg_W")) and math.isfinite(record["P_avg_W"])):
        return "an ok record without a finite 'P_avg_W'"
    for key in RECORD_FIELDS:
        v = record.get(key)
        if v is None:
            continue
        if key in TEXT_FIELDS:
            ok = isinstance(v, str)
        elif key in BOOL_FIELDS:
            ok = isinstance(v, bool)
        else:
            ok = _number(v)
        if not ok:
            return f"field {key!r} = {v!r:.40} has the wrong type"
    return None


class PointStore:
    """The ``points/`` folder of a sweep output directory.

    ``warn(path, why)`` reports a file that is treated as absent (default: one line on stderr).
    """

    def __init__(self, out_dir: str | Path, warn: Callable[[Path, str], None] = _warn) -> None:
        self.root = Path(out_dir)
        self.dir = self.root / "points"
        self._warn = warn
        try:
            self.dir.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise InputError(f"output folder {self.root}: cannot create ({exc.strerror})") from None

    def json_path(self, pid: str) -> Path:
        return self.dir / f"{pid}.json"

    def warm_path(self, pid: str) -> Path:
        return self.dir / f"{pid}.warm.npz"

    def load(self, pid: str) -> dict[str, Any] | None:
        """The record of point ``pid``, or ``None`` if it has not finished or its file is not a
        usable record (then one warning names the file)."""
        p = self.json_path(pid)
        try:
            rec = json.loads(p.read_text(encoding="utf-8"))
        except FileNotFoundError:
            return None
        except OSError as exc:
            self._warn(p, f"cannot read ({exc.strerror or exc})")
            return None
        except RecursionError:
            self._warn(p, "JSON nested too deeply")
            return None
        except ValueError as exc:  # invalid JSON, not UTF-8: a torn or foreign file
            self._warn(p, f"not a valid record ({str(exc).splitlines()[0] if str(exc) else type(exc).__name__})")
            return None
        why = record_problem(rec, pid)
        if why is not None:
            self._warn(p, f"not a valid record ({why})")
            return None
        return rec

    def records(self, ids: list[str]) -> dict[str, dict[str, Any]]:
        """Finished records among ``ids``. An ``ok`` record whose warm-start file exists but
        cannot be read counts as unfinished (the point is computed again, which writes the warm
        start its chain needs)."""
        out = {}
        for pid in ids:
            r = self.load(pid)
            if r is None:
                continue
            if r["status"] == "ok" and self.warm_path(pid).exists() and self.load_warm(pid) is None:
                continue
            out[pid] = r
        return out

    def write(self, record: dict[str, Any], warm: Warm | None) -> None:
        """Persist one finished point (warm start first, record last, both atomically)."""
        pid = record["id"]
        if warm is not None and warm.point_id == pid:
            buf = io.BytesIO()
            np.savez(buf, w=warm.w, lam_x=warm.lam_x, lam_g=warm.lam_g, k_wrap=np.array(warm.k_wrap))
            atomic_write_bytes(self.warm_path(pid), buf.getvalue())
        write_json(self.json_path(pid), record, indent=1)

    def load_warm(self, pid: str) -> Warm | None:
        """The stored warm start of point ``pid``; ``None`` if absent, or if unreadable (then
        one warning names the file)."""
        p = self.warm_path(pid)
        try:
            with np.load(p, allow_pickle=False) as z:
                missing = [k for k in WARM_ARRAYS if k not in z.files]
                if missing:
                    self._warn(p, f"not a warm-start file (arrays missing: {', '.join(missing)})")
                    return None
                arrays = {k: np.asarray(z[k]) for k in WARM_ARRAYS}
        except FileNotFoundError:
            return None
        except (OSError, EOFError, ValueError, KeyError, zipfile.BadZipFile, zlib.error) as exc:
            self._warn(p, f"not a readable warm-start file ({type(exc).__name__}: {str(exc).splitlines()[0] if str(exc) else ''})")
            return None
        for k in ("w", "lam_x", "lam_g"):
            a = arrays[k]
            if a.ndim != 1 or a.dtype.kind not in "fiu" or not np.all(np.isfinite(a)):
                self._warn(p, f"not a warm-start file (array {k!r} is not a vector of finite numbers)")
                return None
        kw = arrays["k_wrap"]
        if kw.shape != () or kw.dtype.kind not in "iu":
            self._warn(p, "not a warm-start file (k_wrap is not an integer)")
            return None
        return Warm(pid, arrays["w"].astype(float), arrays["lam_x"].astype(float), arrays["lam_g"].astype(float), int(kw))

    def forget(self, pid: str) -> None:
        """Remove a point's files (used to retry failed points)."""
        for p in (self.json_path(pid), self.warm_path(pid)):
            try:
                p.unlink()
            except FileNotFoundError:
                pass
