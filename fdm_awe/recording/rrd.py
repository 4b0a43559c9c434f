"""A rerun recording written to an ``.rrd`` file, always finalised; the logging helpers of any sink.

:class:`RecordingSink` holds the helpers every recording uses (static data, one row at a
time, whole columns); :class:`RrdFile` (this module) writes to a file and
:class:`~fdm_awe.recording.stream.ViewerSink` streams to a viewer.

:class:`RrdFile` wraps one ``rerun.RecordingStream`` with a file sink. The stream writes to a
temporary file beside ``path``, renamed onto ``path`` when the recording is closed and
finalised (footer written), so a reader never sees a recording being written. Used as a
context manager it closes the file even when the code inside raises or the user presses
Ctrl-C: by default whatever was sent before is kept as a valid (shorter) recording;
``keep_on_error=False`` (what :func:`~fdm_awe.recording.flight.record_flight` and
:func:`~fdm_awe.recording.flight.record_cycle` use) discards it instead and leaves ``path`` as
it was, so a recording cut short while being written never passes for a whole one. Whole
time series go out in one ``send_columns`` call each (a per-row ``log`` costs ~100 us).

All time stamps are simulation time on the timeline :data:`TIMELINE` (a duration in seconds);
every temporal row also carries the pumping-cycle index on the sequence timeline
:data:`CYCLE_TIMELINE` (0-based; :class:`CycleClock`). No wall-clock timeline is logged.
"""

from __future__ import annotations

import contextlib
import uuid
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from ..fileio import atomic_path

#: Name of the simulation-time timeline (durations in s).
TIMELINE = "sim_time"
#: Name of the pumping-cycle timeline (a sequence: the cycle index, 0-based).
CYCLE_TIMELINE = "cycle"
APPLICATION_ID = "fdm-awe"


def new_stream() -> Any:
    """A ``rerun.RecordingStream`` of this application whose timelines are :data:`TIMELINE` and
    :data:`CYCLE_TIMELINE` (set by :class:`RecordingSink`)."""
    import rerun as rr

    rec = rr.RecordingStream(APPLICATION_ID, recording_id=uuid.uuid4())
    # simulation time and the cycle are the only timelines: no wall-clock or log-call counters
    rec.set_log_time_enabled(False)
    rec.set_log_tick_enabled(False)
    return rec


class CycleClock:
    """The pumping-cycle index over simulation time, a step function built from the rows as they
    come (:meth:`extend`): a row flown outside a cycle (label < 0, e.g. in RECOVER after the
    last cycle) belongs to the cycle before it, rows before the first cycle to cycle 0, the
    cycle's rows as :func:`fdm_awe.sim.cycles.segment_cycles` counts them."""

    def __init__(self) -> None:
        self._t = np.zeros(0)  #: simulation time [s] at which a cycle begins
        self._k = np.zeros(0, dtype=np.int64)  #: that cycle's index
        self._t_last = -np.inf

    def extend(self, t: np.ndarray, cycle: np.ndarray) -> None:
        """Rows at times ``t`` [s] (increasing, after those given before) flown in ``cycle``."""
        t = np.asarray(t, dtype=np.float64)
        c = np.asarray(cycle, dtype=np.float64)
        ok = (t >= self._t_last) & (c >= 0)  # NaN labels are no cycle either
        t, k = t[ok], c[ok].astype(np.int64)
        if not len(t):
            return
        change = np.r_[not len(self._k) or k[0] != self._k[-1], k[1:] != k[:-1]]
        self._t = np.r_[self._t, t[change]]
        self._k = np.r_[self._k, k[change]]
        self._t_last = float(t[-1])

    def __call__(self, t: np.ndarray) -> np.ndarray:
        """Cycle index (int64) at times ``t`` [s]."""
        t = np.asarray(t, dtype=np.float64)
        if not len(self._k):
            return np.zeros(t.shape, dtype=np.int64)
        i = np.searchsorted(self._t, t, side="right") - 1
        return np.where(i >= 0, self._k[np.maximum(i, 0)], 0)

    @property
    def cycles(self) -> list[int]:
        """The cycle indices begun so far."""
        return self._k.tolist()


class RecordingSink:
    """Logging helpers over ``self.rec`` (a ``rerun.RecordingStream``); ``self.rr`` is the rerun
    module. Times are simulation time [s] on :data:`TIMELINE`; every temporal row also gets its
    cycle on :data:`CYCLE_TIMELINE` from :attr:`clock` (fed by the flight's rows)."""

    rr: Any
    rec: Any

    @property
    def clock(self) -> CycleClock:
        """The cycle index over simulation time of what this sink records."""
        c = self.__dict__.get("_clock")
        if c is None:
            c = self.__dict__["_clock"] = CycleClock()
        return c

    def static(self, entity: str, archetype: Any) -> None:
        self.rec.log(entity, archetype, static=True)

    def at(self, entity: str, t: float, archetype: Any) -> None:
        """Log one archetype at simulation time ``t`` [s] (and its cycle)."""
        self.rec.set_time(TIMELINE, duration=float(t))
        self.rec.set_time(CYCLE_TIMELINE, sequence=int(self.clock(np.array([t]))[0]))
        self.rec.log(entity, archetype)

    def time_columns(self, t: np.ndarray) -> list[Any]:
        """The index columns of rows at times ``t`` [s]: simulation time and cycle."""
        t = np.asarray(t, dtype=np.float64)
        return [self.rr.TimeColumn(TIMELINE, duration=t), self.rr.TimeColumn(CYCLE_TIMELINE, sequence=self.clock(t))]

    def scalars(self, entity: str, t: np.ndarray, values: np.ndarray, *, name: str | None = None,
                color: Sequence[int] | None = None) -> int:
        """A whole scalar series (non-finite samples dropped); returns the rows sent."""
        v = np.asarray(values, dtype=np.float64)
        t = np.asarray(t, dtype=np.float64)
        ok = np.isfinite(v) & np.isfinite(t)
        if name is not None or color is not None:
            self.static(entity, self.rr.SeriesLines(names=name, colors=None if color is None else [tuple(color)]))
        if not ok.any():
            return 0
        self.rec.send_columns(entity, indexes=self.time_columns(t[ok]), columns=self.rr.Scalars.columns(scalars=v[ok]))
        return int(ok.sum())

    def columns(self, entity: str, t: np.ndarray, columns: Any) -> None:
        """Send prepared component columns (``Archetype.columns(...)``) over times ``t`` [s]."""
        if len(t):
            self.rec.send_columns(entity, indexes=self.time_columns(t), columns=columns)


class RrdFile(RecordingSink):
    """Write a recording to ``path``; ``blueprint`` becomes the file's default layout.

    ``keep_on_error``: when the ``with`` block ends with an exception, keep what was sent as a
    finalised recording at ``path`` (True, default) or discard it (False; ``path`` unchanged).
    """

    def __init__(self, path: str | Path, *, name: str | None = None, blueprint: Any = None,
                 keep_on_error: bool = True) -> None:
        import rerun as rr

        self.rr = rr
        self.path = Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self.keep_on_error = keep_on_error
        self._file = contextlib.ExitStack()
        self._tmp = self._file.enter_context(atomic_path(self.path, suffix=".rrd"))
        try:
            self.rec = new_stream()
            self.rec.save(str(self._tmp), default_blueprint=blueprint)
            if name:
                self.rec.send_recording_name(name)
        except BaseException as exc:
            self._file.__exit__(type(exc), exc, exc.__traceback__)  # removes the temporary file
            raise
        self._open = True

    # ---- context manager: always finalise
    def __enter__(self) -> "RrdFile":
        return self

    def __exit__(self, exc_type: Any, exc: Any, tb: Any) -> None:
        if exc_type is not None and not self.keep_on_error:
            self.close(discard=(exc_type, exc, tb))
        else:
            self.close()

    def close(self, discard: tuple[Any, Any, Any] | None = None) -> None:
        """Flush everything, close the file and rename it onto ``path`` (idempotent).

        ``discard``: the ``(type, value, traceback)`` of an exception; the temporary file is
        removed instead and ``path`` left as it was.
        """
        if self._open:
            self._open = False
            try:
                try:
                    self.rec.flush()
                finally:
                    self.rec.disconnect()
            except BaseException as exc:
                self._file.__exit__(type(exc), exc, exc.__traceback__)
                raise
            if discard is not None:
                self._file.__exit__(*discard)
            else:
                self._file.close()  # rename onto path


def segments_by_label(points: np.ndarray, labels: Sequence[str]) -> list[tuple[str, np.ndarray]]:
    """Split a path (n, 3) into runs of equal label; neighbouring runs share their joint point
    so the drawn line has no gaps. Rows with non-finite points are dropped."""
    pts = np.asarray(points, float)
    ok = np.all(np.isfinite(pts), axis=1)
    out: list[tuple[str, np.ndarray]] = []
    start = None
    for i in range(len(pts) + 1):
        if start is not None and (i == len(pts) or labels[i] != labels[start] or not ok[i]):
            end = min(i + 1, len(pts)) if (i < len(pts) and ok[i]) else i
            seg = pts[start:end]
            seg = seg[np.all(np.isfinite(seg), axis=1)]
            if len(seg) >= 2:
                out.append((labels[start], seg))
            start = None
        if i < len(pts) and start is None and ok[i]:
            start = i
    return out


__all__ = ["APPLICATION_ID", "CYCLE_TIMELINE", "CycleClock", "RecordingSink", "RrdFile", "new_stream", "TIMELINE",
           "segments_by_label"]
