"""Read a recording back: verify it with the rerun CLI, list its entities, time ranges and timelines, read values.

:func:`rrd_entities` and :func:`rrd_values` use rerun's own reader (``rerun.chunk.RrdReader``),
also for a file without footer (what ``rerun --save`` writes from a live stream); :func:`rrd_verify`
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


def _chunks(path: str | Path):  # noqa: ANN202 - an iterator of rerun chunks
    """The chunks of the first recording store in ``path`` (a file without footer is read whole)."""
    import warnings

    from rerun.chunk import RrdReader

    with warnings.catch_warnings():  # a file without footer is read below as rerun advises
        warnings.filterwarnings("ignore", message="RRD file has no footer")
        reader = RrdReader(str(path))
    try:
        store = reader.store()
    except RuntimeError:  # no footer: a stream saved by `rerun --save`
        return reader.stream().collect().stream()
    return store.stream()


def _data_columns(rb) -> tuple[str, ...]:  # noqa: ANN001 - a pyarrow RecordBatch
    """Names of the component columns of a chunk's record batch (no row ids, no time indexes)."""
    return tuple(f.name for f in rb.schema if (f.metadata or {}).get(b"rerun:kind") == b"data")


def rrd_entities(path: str | Path, timeline: str = TIMELINE) -> dict[str, EntityInfo]:
    """Entity path -> :class:`EntityInfo` of the recording store in ``path`` (blueprint excluded)."""
    import numpy as np

    out: dict[str, EntityInfo] = {}
    for chunk in _chunks(path):
        info = out.setdefault(str(chunk.entity_path), EntityInfo())
        rb = chunk.to_record_batch()
        info.components = tuple(sorted(set(info.components) | set(_data_columns(rb))))
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


def rrd_values(path: str | Path, entity: str, component: str,
               timeline: str = TIMELINE) -> tuple[list, list[float], list]:
    """The values of one component of one entity: ``(static rows, times [s], rows at those
    times)``, the temporal rows sorted by time; a row is the list of its values (one arrow,
    one scalar: a list of one). ``entity`` as listed by :func:`rrd_entities`
    (``/world/glider``), ``component`` e.g. ``Arrows3D:vectors`` or an ``AnyValues`` name."""
    static: list = []
    rows: list[tuple[float, object]] = []
    for chunk in _chunks(path):
        if str(chunk.entity_path) != entity:
            continue
        rb = chunk.to_record_batch()
        if component not in rb.schema.names:
            continue
        vals = rb.column(component).to_pylist()
        if chunk.is_static:
            static.extend(v for v in vals if v is not None)
            continue
        times = rb.column(timeline).cast("int64").to_pylist()
        rows += [(ns * 1e-9, v) for ns, v in zip(times, vals) if v is not None]
    rows.sort(key=lambda r: r[0])
    return static, [t for t, _ in rows], [v for _, v in rows]


@dataclass
class TimelineInfo:
    """How one entity's temporal rows sit on a timeline: the rows, those with a time on it, and
    the distinct times (raw: a sequence's numbers, a duration's nanoseconds)."""

    rows: int = 0
    on_timeline: int = 0
    values: tuple[int, ...] = ()


def rrd_timeline(path: str | Path, timeline: str) -> dict[str, TimelineInfo]:
    """Entity path -> :class:`TimelineInfo` on ``timeline`` of the temporal rows in ``path``."""
    out: dict[str, TimelineInfo] = {}
    for chunk in _chunks(path):
        if chunk.is_static:
            continue
        info = out.setdefault(str(chunk.entity_path), TimelineInfo())
        rb = chunk.to_record_batch()
        info.rows += int(chunk.num_rows)
        if timeline in rb.schema.names:
            col = rb.column(timeline)
            info.on_timeline += len(col) - col.null_count
            vals = {int(v) for v in col.cast("int64").to_pylist() if v is not None}
            info.values = tuple(sorted(set(info.values) | vals))
    return out


def _view_fields(path: str | Path) -> tuple[dict[str, str], dict[str, list[str]], dict[str, str]]:
    """The views of the default blueprint stored in ``path``, by their entity: display names,
    content queries and view classes."""
    from rerun.chunk import RrdReader

    reader = RrdReader(str(path))
    names: dict[str, str] = {}
    queries: dict[str, list[str]] = {}
    classes: dict[str, str] = {}
    for entry in reader.blueprints():
        for chunk in reader.store(store=entry).stream():
            rb = chunk.to_record_batch()
            ent = str(chunk.entity_path)
            for col in rb.schema.names:
                if col == "ViewBlueprint:display_name":
                    names[ent] = rb.column(col).to_pylist()[-1][0]
                elif col == "ViewContents:query":
                    queries[ent.rsplit("/ViewContents", 1)[0]] = list(rb.column(col).to_pylist()[-1])
                elif col == "ViewBlueprint:class_identifier":
                    classes[ent] = rb.column(col).to_pylist()[-1][0]
    return names, queries, classes


def rrd_views(path: str | Path) -> dict[str, list[str]]:
    """View name -> its content queries, from the default blueprint stored in ``path``."""
    names, queries, _ = _view_fields(path)
    return {name: queries.get(ent, []) for ent, name in names.items()}


def rrd_view_classes(path: str | Path) -> dict[str, str]:
    """View name -> its kind (rerun's view class: ``TimeSeries``, ``TextLog``, ``StateTimeline``,
    ``3D``, ...), from the default blueprint stored in ``path``."""
    names, _, classes = _view_fields(path)
    return {name: classes.get(ent, "") for ent, name in names.items()}


__all__ = ["EntityInfo", "TimelineInfo", "rerun_cli", "rrd_entities", "rrd_stats", "rrd_timeline", "rrd_values",
           "rrd_verify", "rrd_view_classes", "rrd_views"]
