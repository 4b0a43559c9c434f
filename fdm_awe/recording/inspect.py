"""Read a recording back: verify it with the rerun CLI and list its entities and time ranges.

:func:`rrd_entities` uses rerun's own reader (``rerun.chunk.RrdReader``); :func:`rrd_verify`
and :func:`rrd_stats` run ``rerun rrd verify`` / ``rerun rrd stats`` (the CLI installed next to
the Python interpreter, else on ``PATH``) with a time limit.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

from .rrd import TIMELINE


@dataclass
class EntityInfo:
    """What one entity path holds: rows over time, whether it has static data, and the
    simulation-time range [s] of its temporal rows (None when it has none)."""

    rows: int = 0
    static: bool = False
    components: tuple[str, ...] = ()
    t_min: float | None = None
    t_max: float | None = None


def rerun_cli() -> str:
    """Path of the ``rerun`` executable (next to this interpreter first)."""
    here = Path(sys.executable).parent / "rerun"
    if here.exists():
        return str(here)
    found = shutil.which("rerun")
    if found is None:
        raise FileNotFoundError("the rerun command-line program was not found (pip install rerun-sdk)")
    return found


def _run(args: list[str], timeout: float) -> subprocess.CompletedProcess:
    env = dict(os.environ, RUST_LOG="warn")
    return subprocess.run([rerun_cli(), *args], capture_output=True, text=True, timeout=timeout, env=env)


def rrd_verify(path: str | Path, timeout: float = 60.0) -> tuple[bool, str]:
    """``rerun rrd verify`` (footers checked): (ok, combined output)."""
    p = _run(["rrd", "verify", str(path)], timeout)
    return p.returncode == 0, (p.stdout + p.stderr).strip()


def rrd_stats(path: str | Path, timeout: float = 60.0) -> str:
    """``rerun rrd stats`` text (raises CalledProcessError on failure)."""
    p = _run(["rrd", "stats", str(path)], timeout)
    if p.returncode != 0:
        raise subprocess.CalledProcessError(p.returncode, "rerun rrd stats", p.stdout, p.stderr)
    return p.stdout


def rrd_entities(path: str | Path, timeline: str = TIMELINE) -> dict[str, EntityInfo]:
    """Entity path -> :class:`EntityInfo` of the recording store in ``path`` (blueprint excluded)."""
    import numpy as np
    from rerun.chunk import RrdReader

    out: dict[str, EntityInfo] = {}
    for chunk in RrdReader(str(path)).store().stream():
        info = out.setdefault(str(chunk.entity_path), EntityInfo())
        rb = chunk.to_record_batch()
        comps = tuple(n for n in rb.schema.names if ":" in n)
        info.components = tuple(sorted(set(info.components) | set(comps)))
        if chunk.is_static:
            info.static = True
            continue
        info.rows += int(chunk.num_rows)
        if timeline in rb.schema.names:
            col = rb.column(timeline)
            v = np.asarray(col.cast("int64").to_numpy(zero_copy_only=False), dtype=float) * 1e-9
            if len(v):
                info.t_min = float(v.min()) if info.t_min is None else min(info.t_min, float(v.min()))
                info.t_max = float(v.max()) if info.t_max is None else max(info.t_max, float(v.max()))
    return out


def rrd_views(path: str | Path) -> dict[str, list[str]]:
    """View name -> its content queries, from the default blueprint stored in ``path``."""
    from rerun.chunk import RrdReader

    reader = RrdReader(str(path))
    names: dict[str, str] = {}
    queries: dict[str, list[str]] = {}
    for entry in reader.blueprints():
        for chunk in reader.store(store=entry).stream():
            rb = chunk.to_record_batch()
            ent = str(chunk.entity_path)
            for col in rb.schema.names:
                if col == "ViewBlueprint:display_name":
                    names[ent] = rb.column(col).to_pylist()[-1][0]
                elif col == "ViewContents:query":
                    queries[ent.rsplit("/ViewContents", 1)[0]] = list(rb.column(col).to_pylist()[-1])
    return {name: queries.get(ent, []) for ent, name in names.items()}


__all__ = ["EntityInfo", "rerun_cli", "rrd_entities", "rrd_stats", "rrd_verify", "rrd_views"]
