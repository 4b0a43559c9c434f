"""Progress bars (tqdm on stderr) for flights, optimisations and sweeps, with a quiet mode.

``quiet=True`` shows nothing; ``quiet=None`` (default) shows bars only when stderr is a
terminal, so scripts and tests stay silent. Every helper costs next to nothing when quiet.

Flight (simulated seconds, updated every ``every`` steps)::

    with FlightProgress(t_end_s, dt, quiet=args.quiet) as bar:
        report = fly(reference, ..., on_step=bar)

Optimisation (one solve: elapsed time ticking while it runs)::

    with activity("optimise physical/foldable 6 m/s", quiet=args.quiet):
        result = solve_cycle(problem)

Sweeps (one tick per item)::

    for item in bar(items, "sweep", quiet=args.quiet): ...
"""

from __future__ import annotations

import sys
import threading
import time
from typing import Any, Iterable, Iterator, TypeVar

T = TypeVar("T")


def enabled(quiet: bool | None) -> bool:
    """Whether to show progress: never when quiet, always when quiet is False, else on a TTY."""
    if quiet is None:
        return bool(getattr(sys.stderr, "isatty", lambda: False)())
    return not quiet


class FlightProgress:
    """Callable ``on_step(k, state, gs_output)`` that advances a bar in simulated seconds.

    Only every ``every``-th step touches the bar (``every`` = 120: once per simulated second
    at 120 Hz), so the cost per step is one integer modulo.
    """

    def __init__(self, total_s: float, dt: float, *, desc: str = "flight", quiet: bool | None = None,
                 every: int = 120) -> None:
        self.dt = float(dt)
        self.every = max(1, int(every))
        self._done = 0
        self._bar: Any = None
        if enabled(quiet):
            from tqdm import tqdm

            self._bar = tqdm(total=round(float(total_s), 1), desc=desc, unit="s sim", file=sys.stderr,
                             dynamic_ncols=True, bar_format="{l_bar}{bar}| {n:.1f}/{total:.1f} s sim [{elapsed}<{remaining}]")

    def __call__(self, k: int, state: Any = None, gs_output: Any = None) -> None:
        if self._bar is not None and k % self.every == 0:
            self._bar.update(k * self.dt - self._done)
            self._done = k * self.dt

    def close(self, status: str | None = None) -> None:
        if self._bar is not None:
            if status:
                self._bar.set_postfix_str(status)
            self._bar.close()
            self._bar = None

    def __enter__(self) -> "FlightProgress":
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


class activity:
    """Context manager: a ticking elapsed-time line for one long call (an optimisation)."""

    def __init__(self, desc: str, *, quiet: bool | None = None, interval: float = 0.5) -> None:
        self.desc = desc
        self.interval = interval
        self.show = enabled(quiet)
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self._bar: Any = None
        self.elapsed = 0.0

    def __enter__(self) -> "activity":
        self._t0 = time.perf_counter()
        if self.show:
            from tqdm import tqdm

            self._bar = tqdm(total=None, desc=self.desc, file=sys.stderr, bar_format="{desc}: {elapsed}")
            self._thread = threading.Thread(target=self._tick, daemon=True)
            self._thread.start()
        return self

    def _tick(self) -> None:
        while not self._stop.wait(self.interval):
            self._bar.refresh()

    def __exit__(self, exc_type: Any, *exc: object) -> None:
        self.elapsed = time.perf_counter() - self._t0
        self._stop.set()
        if self._thread is not None:
            self._thread.join()
        if self._bar is not None:
            self._bar.set_description_str(f"{self.desc} ({'failed' if exc_type else 'done'})")
            self._bar.close()


def bar(items: Iterable[T], desc: str, *, quiet: bool | None = None, total: int | None = None) -> Iterator[T]:
    """Iterate ``items`` with a bar (plain iteration when quiet)."""
    if not enabled(quiet):
        yield from items
        return
    from tqdm import tqdm

    yield from tqdm(items, desc=desc, total=total, file=sys.stderr, dynamic_ncols=True)


__all__ = ["FlightProgress", "activity", "bar", "enabled"]
