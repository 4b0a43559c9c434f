"""Persistence of sweep points: one small JSON file per finished point.

Layout of an output folder::

    points/<id>.json      the point's record (ok or failed), written atomically
    points/<id>.warm.npz  its solution vector and multipliers (warm start of the next point)

A point counts as finished once its JSON file exists; the warm-start file is written first,
so a sweep killed at any moment leaves only complete points behind and a rerun computes
exactly the missing ones (and, from the stored warm starts, the same numbers as an
uninterrupted run).
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import InputError
from .runner import Warm


class PointStore:
    """The ``points/`` folder of a sweep output directory."""

    def __init__(self, out_dir: str | Path) -> None:
        self.root = Path(out_dir)
        self.dir = self.root / "points"
        try:
            self.dir.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise InputError(f"output folder {self.root}: cannot create ({exc.strerror})") from None

    def json_path(self, pid: str) -> Path:
        return self.dir / f"{pid}.json"

    def warm_path(self, pid: str) -> Path:
        return self.dir / f"{pid}.warm.npz"

    def load(self, pid: str) -> dict[str, Any] | None:
        """The record of point ``pid``, or ``None`` if it has not finished (or is unreadable)."""
        p = self.json_path(pid)
        try:
            return json.loads(p.read_text())
        except FileNotFoundError:
            return None
        except (OSError, json.JSONDecodeError):
            return None  # a torn file counts as missing: the point is recomputed

    def records(self, ids: list[str]) -> dict[str, dict[str, Any]]:
        """Finished records among ``ids``."""
        out = {}
        for pid in ids:
            r = self.load(pid)
            if r is not None:
                out[pid] = r
        return out

    def write(self, record: dict[str, Any], warm: Warm | None) -> None:
        """Persist one finished point (warm start first, record last, both atomically)."""
        pid = record["id"]
        if warm is not None and warm.point_id == pid:
            tmp = self.dir / f".{pid}.warm.tmp.npz"
            np.savez(tmp, w=warm.w, lam_x=warm.lam_x, lam_g=warm.lam_g, k_wrap=np.array(warm.k_wrap))
            os.replace(tmp, self.warm_path(pid))
        tmp = self.dir / f".{pid}.json.tmp"
        tmp.write_text(json.dumps(record, indent=1, allow_nan=False))
        os.replace(tmp, self.json_path(pid))

    def load_warm(self, pid: str) -> Warm | None:
        """The stored warm start of point ``pid`` (``None`` if absent or unreadable)."""
        try:
            with np.load(self.warm_path(pid)) as z:
                return Warm(pid, z["w"], z["lam_x"], z["lam_g"], int(z["k_wrap"]))
        except (OSError, KeyError, ValueError):
            return None

    def forget(self, pid: str) -> None:
        """Remove a point's files (used to retry failed points)."""
        for p in (self.json_path(pid), self.warm_path(pid)):
            try:
                p.unlink()
            except FileNotFoundError:
                pass
